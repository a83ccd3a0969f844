/* ictus_error -- an abstraction's error line that Pd's "Find Last Error" finds.
 *
 * [print error: ...] writes a line that looks like an error but is not one to
 * Pd: Find > Find Last Error then says "no findable error yet". This object
 * formats what it receives exactly as [print PREFIX] would ("PREFIX: 3",
 * "PREFIX: symbol a", "PREFIX: set 1 2") and posts it with pd_error(), whose
 * object is the box of the innermost abstraction that holds it, so Find Last
 * Error opens the patch that uses that abstraction and selects its box (the one
 * given the bad argument or message); outside any abstraction, the subpatch
 * that holds it, else itself. Only its own messages, at message time: nothing on the audio thread.
 */
#include <stdio.h>
#include <string.h>

#include "m_pd.h"
#include "g_canvas.h"

#include "ictus_export.h"

static t_class *ictus_error_class;

typedef struct ictus_error {
    t_object x_obj;
    t_symbol *prefix;
    const void *owner; /* what pd_error names: the enclosing box, else this object */
} ictus_error;

/* Appends the atoms' text to text (len chars already there), each after a space
 * unless text is empty; truncated at cap - 1 chars. Returns the new length. */
static size_t join_atoms(char *text, size_t cap, size_t len, int argc, const t_atom *argv)
{
    for (int i = 0; i < argc && len + 2 < cap; i++) {
        if (len > 0)
            text[len++] = ' ';
        atom_string(argv + i, text + len, (unsigned)(cap - len)); /* NUL-terminated, cut */
        len += strlen(text + len);
    }
    return len;
}

/* Posts "PREFIX: HEAD ATOMS..." (HEAD may be NULL) as an error of x->owner. */
static void ictus_error_post(ictus_error *x, const char *head, int argc, t_atom *argv)
{
    char text[MAXPDSTRING] = "";
    if (head)
        snprintf(text, sizeof(text), "%s", head);
    join_atoms(text, sizeof(text), strlen(text), argc, argv);
    pd_error(x->owner, "%s: %s", x->prefix->s_name, text);
}

static void ictus_error_bang(ictus_error *x)
{
    ictus_error_post(x, "bang", 0, NULL);
}

static void ictus_error_float(ictus_error *x, t_floatarg f)
{
    t_atom a;
    SETFLOAT(&a, f);
    ictus_error_post(x, NULL, 1, &a);
}

static void ictus_error_symbol(ictus_error *x, t_symbol *s)
{
    t_atom a;
    SETSYMBOL(&a, s);
    ictus_error_post(x, "symbol", 1, &a);
}

/* As [print]: a list that starts with a number prints bare; one that starts with
 * a symbol is named "list" (or "symbol", "bang" for one or no atom). */
static void ictus_error_list(ictus_error *x, t_symbol *s, int argc, t_atom *argv)
{
    (void)s;
    if (argc && argv->a_type != A_SYMBOL)
        ictus_error_post(x, NULL, argc, argv);
    else
        ictus_error_post(x, argc > 1 ? "list" : (argc == 1 ? "symbol" : "bang"), argc, argv);
}

static void ictus_error_anything(ictus_error *x, t_symbol *s, int argc, t_atom *argv)
{
    ictus_error_post(x, s->s_name, argc, argv);
}

static void *ictus_error_new(t_symbol *s, int argc, t_atom *argv)
{
    (void)s;
    ictus_error *x = (ictus_error *)pd_new(ictus_error_class);
    /* the arguments, as [print]'s name: their text joined by spaces */
    char prefix[MAXPDSTRING] = "";
    if (join_atoms(prefix, sizeof(prefix), 0, argc, argv) == 0)
        strcpy(prefix, "ictus_error");
    x->prefix = gensym(prefix);
    /* the innermost abstraction that holds it, else the subpatch, else itself */
    t_canvas *holder = canvas_getcurrent(), *c = holder;
    while (c && !canvas_isabstraction(c))
        c = c->gl_owner;
    if (c && c->gl_owner)
        x->owner = c;
    else if (holder && holder->gl_owner)
        x->owner = holder;
    else
        x->owner = x;
    return x;
}

ICTUS_EXPORT void ictus_error_setup(void)
{
    ictus_error_class = class_new(gensym("ictus_error"), (t_newmethod)ictus_error_new, 0,
                                  sizeof(ictus_error), CLASS_DEFAULT, A_GIMME, 0);
    class_addbang(ictus_error_class, ictus_error_bang);
    class_addfloat(ictus_error_class, ictus_error_float);
    class_addsymbol(ictus_error_class, ictus_error_symbol);
    class_addlist(ictus_error_class, ictus_error_list);
    class_addanything(ictus_error_class, ictus_error_anything);
}
