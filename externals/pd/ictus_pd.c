/* ictus_pd.c -- setup of the ictus Pd library (libictus_pd.so). */
#include "ictus_pd.h"

static int ictus_pd_done;

static void ictus_pd_addcreator(t_newmethod maker, const char *name)
{
    /* Pd names a class by the file it was loaded from too ("ictus/membrane~"),
     * but only for the file being loaded; the other class, created in the same
     * setup, gets its long name here. */
    t_symbol *s = gensym(name);
    if (!zgetfn(&pd_objectmaker, s))
        class_addcreator(maker, s, A_GIMME, 0);
}

void ictus_pd_setup(void)
{
    if (ictus_pd_done)
        return;
    ictus_pd_done = 1;
    ictus_membrane_tilde_setup();
    ictus_contact_tilde_setup();
    ictus_pd_addcreator((t_newmethod)zgetfn(&pd_objectmaker, gensym("membrane~")),
                        "ictus/membrane~");
    ictus_pd_addcreator((t_newmethod)zgetfn(&pd_objectmaker, gensym("contact~")), "ictus/contact~");
}
