/* contact.c -- the stick: Hunt-Crossley contact with an energy-consistent
 * discretisation, and the stroke it plays on a membrane.
 *
 * Force law (contact.h; Hunt & Crossley, lambda in N s / m^(alpha+1)):
 *     F = k x^a + lambda x^a dx/dt   for x > 0, and F >= 0.
 * Discretised over one sample (x0 -> x1) as
 *     F = max(0, (V(x1) - V(x0)) / (x1 - x0) + lambda h (x1 - x0) / T),
 *     V(x) = k x+^(a+1) / (a+1),  h = (x0+^a + x1+^a) / 2 >= 0.
 * The first term is a discrete gradient (its work over the step equals the change
 * of V exactly), the second term can only remove energy, and clamping F at 0 only
 * acts while the damping term is negative, i.e. while x decreases, where the spring
 * term's work is <= 0 too. With the stick and the modes on the midpoint rule the
 * discrete total energy therefore never grows (docs/membrane.md).
 *
 * The stick sits on one of the membrane's coupling points (membrane_internal.h):
 * the membrane computes the shapes and folds the force into the modes; the stroke
 * (landing, the implicit solve of the force, touch and release, the report) is
 * here, called by the membrane through contact_point_ops.
 */
#include "contact.h"
#include "membrane_internal.h"
#include "stick_tip.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#define CONTACT_FORCE_CAP MEMBRANE_FORCE_MAX /* N, as the membrane's force input */

struct contact {
    membrane_point point; /* first: a membrane_point * is a contact * (contact_point_ops) */
    double mass_kg, stiffness, alpha, damping, stretch;
    double stretch_force; /* N, the stretching's force on the head in the last sample */
    double hit_velocity; /* m/s, of the hit waiting to land (point.move_pending) */
    double hit_mass_kg;  /* the stick's mass from that hit on; 0: unchanged */
    /* Hits after that one, in the order of their samples: a block longer than the gap
     * between two hits (block~ 2048 holds 43 ms) lands them all on their samples. Offsets
     * count from the start of the last block processed; queue_shift is that block's
     * length, taken off at the next block's start. */
    struct queued_hit {
        double velocity, mass_kg, r_over_a, theta_deg;
        int offset;
    } queue[CONTACT_HIT_QUEUE];
    int queued, queue_shift;
    /* Stroke state (double: the contact law is stiff and nonlinear). */
    int touching, ever_touched;
    double stick_x, stick_v;   /* m, m/s, positive into the membrane */
    double compression;        /* m */
    double compression_before; /* m, a sample earlier (the solve's first guess) */
    double force;              /* N, during the last sample */
    /* The force law linearised at the last sample's solution (the next solve's
     * first guess): F ~ lin_f + lin_d0 (x0 - lin_x0) + lin_d1 (x1 - lin_u). */
    int lin_valid;
    double lin_x0, lin_u, lin_f, lin_d0, lin_d1;
    long stroke_samples;
    double first_touch, last_release; /* samples since the stroke began (interpolated) */
    double peak_force, impulse;
    /* Finished strokes not yet taken (contact_take_report), oldest first: a long block
     * may end several. */
    contact_report reports[CONTACT_REPORT_QUEUE];
    int reports_ready;
    float *force_out;
    int force_cap;
};

static const membrane_point_ops contact_point_ops;

contact *contact_new(void)
{
    contact *c = calloc(1, sizeof(*c));
    if (!c)
        return NULL;
    c->mass_kg = CONTACT_DEFAULT_MASS;
    c->stiffness = CONTACT_DEFAULT_STIFFNESS;
    c->alpha = CONTACT_DEFAULT_ALPHA;
    c->damping = CONTACT_DEFAULT_DAMPING;
    c->stretch = CONTACT_DEFAULT_STRETCH;
    c->point.ops = &contact_point_ops;
    c->point.static_correction = 1;
    c->point.r_over_a = 0.3;
    return c;
}

ictus_status contact_set_tip(contact *c, const char *name)
{
    const stick_tip *tip = stick_tip_find(name);
    if (!c || !tip)
        return ICTUS_CLAMPED;
    c->alpha = tip->alpha;
    c->stiffness = tip->stiffness;
    c->damping = tip->mu * tip->stiffness;
    return ICTUS_OK;
}

void contact_free(contact *c)
{
    if (!c)
        return;
    membrane_point_free_(&c->point);
    free(c);
}

/* Indexed by contact_param: name (as the Pd message), unit, range, and the double it
 * is kept in. */
/* clang-format off */
#define RANGE(P) {CONTACT_##P##_MIN, CONTACT_##P##_MAX, CONTACT_DEFAULT_##P}
/* clang-format on */
static const ictus_param_def contact_param_def[CONTACT_PARAM_COUNT] = {
    [CONTACT_PARAM_MASS] = {"mass", "kg", RANGE(MASS), offsetof(contact, mass_kg), NULL},
    [CONTACT_PARAM_STIFFNESS] = {"stiffness", "N/m^alpha", RANGE(STIFFNESS),
                                 offsetof(contact, stiffness), NULL},
    [CONTACT_PARAM_ALPHA] = {"alpha", "", RANGE(ALPHA), offsetof(contact, alpha), NULL},
    [CONTACT_PARAM_DAMPING] = {"damping", "N s/m^(alpha+1)", RANGE(DAMPING),
                               offsetof(contact, damping), NULL},
    [CONTACT_PARAM_STRETCH] = {"stretch", "N/m^3", RANGE(STRETCH), offsetof(contact, stretch),
                               NULL},
};
#undef RANGE

const ictus_param_table contact_params = {contact_param_def, CONTACT_PARAM_COUNT};

ictus_status contact_hit(contact *c, double velocity_mps, double r_over_a, double theta_deg,
                         int sample_offset)
{
    return contact_hit_mass(c, velocity_mps, r_over_a, theta_deg, sample_offset, 0.0);
}

ictus_status contact_hit_mass(contact *c, double velocity_mps, double r_over_a, double theta_deg,
                              int sample_offset, double mass_kg)
{
    ictus_status s = ictus_clamp(&velocity_mps, 0.0, CONTACT_VELOCITY_MAX, 1.0);
    if (membrane_clamp_point_(&r_over_a, &theta_deg) != ICTUS_OK)
        s = ICTUS_CLAMPED;
    if (sample_offset < 0) {
        sample_offset = 0;
        s = ICTUS_CLAMPED;
    }
    if (mass_kg != 0.0 &&
        ictus_clamp(&mass_kg, CONTACT_MASS_MIN, CONTACT_MASS_MAX, CONTACT_DEFAULT_MASS) != ICTUS_OK)
        s = ICTUS_CLAMPED;
    if (c->point.owner && c->point.move_pending && sample_offset > c->point.move_offset) {
        /* After the hit waiting to land: it waits behind it. A later hit on the same
         * sample or before one queued replaces those (as it replaces a pending one). */
        int at = sample_offset + c->queue_shift;
        while (c->queued > 0 && c->queue[c->queued - 1].offset >= at)
            c->queued--;
        if (c->queued == CONTACT_HIT_QUEUE)
            return ICTUS_ENOMEM;
        struct queued_hit *h = &c->queue[c->queued++];
        h->velocity = velocity_mps;
        h->mass_kg = mass_kg;
        h->r_over_a = r_over_a;
        h->theta_deg = theta_deg;
        h->offset = at;
        /* Its shapes into the membrane's cache now, so that landing finds them. */
        membrane_impulse_shape_(c->point.owner, r_over_a, theta_deg);
        return s;
    }
    c->queued = 0; /* they all came after the one this hit replaces */
    c->hit_velocity = velocity_mps;
    c->hit_mass_kg = mass_kg;
    membrane_point_move_(&c->point, r_over_a, theta_deg, sample_offset);
    return s;
}

int contact_hits_waiting(const contact *c)
{
    return c->point.move_pending + c->queued;
}

void contact_set_force_output(contact *c, float *buffer, int capacity)
{
    c->force_out = capacity > 0 ? buffer : NULL;
    c->force_cap = buffer ? capacity : 0;
}

int contact_is_active(const contact *c)
{
    return c->point.active || c->point.move_pending;
}

int contact_take_report(contact *c, contact_report *report)
{
    if (c->reports_ready == 0)
        return 0;
    if (report)
        *report = c->reports[0];
    c->reports_ready--;
    memmove(c->reports, c->reports + 1, sizeof(c->reports[0]) * (size_t)c->reports_ready);
    return 1;
}

double contact_stick_position(const contact *c)
{
    return c->stick_x;
}
double contact_stick_velocity(const contact *c)
{
    return c->stick_v;
}
double contact_compression(const contact *c)
{
    return c->compression;
}
double contact_residual_compliance(const contact *c)
{
    return c->point.owner ? c->point.residual_compliance : 0.0;
}
double contact_last_force(const contact *c)
{
    return c->force;
}

/* x+^a for the solver's inner loop: the common exponents (whole or half
 * integers: 1, 1.5, 2, 2.5, ...) by products and one sqrt, which costs a
 * fraction of pow(). */
static double fast_pos_pow(double x, double a, int half_steps)
{
    if (!(x > 0.0))
        return 0.0;
    if (half_steps < 0)
        return pow(x, a);
    double r = (half_steps & 1) ? sqrt(x) : 1.0;
    for (int i = 0; i < half_steps / 2; i++)
        r *= x;
    return r;
}

/* x^a and x^(a-1) for x > 0: the same x^a as fast_pos_pow() (the same products in
 * the same order), and x^(a-1) without a division when a >= 1 is a half integer. */
static double fast_pow_and_below(double x, double a, int half_steps, double *below)
{
    if (half_steps >= 2) {
        double r = (half_steps & 1) ? sqrt(x) : 1.0;
        for (int i = 0; i < half_steps / 2 - 1; i++)
            r *= x;
        *below = r;
        return r * x;
    }
    double xa = fast_pos_pow(x, a, half_steps);
    *below = xa / x;
    return xa;
}

/* What stays fixed while one sample's equation is solved: the start compression
 * x0 and its powers, so that each trial x1 costs one pow(). */
typedef struct contact_step {
    double k, a, k_over_a1, damping_over_dt, x0, x0a, v0, dh0;
    int half_steps; /* 2a when that is a whole number, else -1 */
} contact_step;

static contact_step step_begin(const contact *c, double x0, double dt)
{
    contact_step st;
    st.k = c->stiffness;
    st.a = c->alpha;
    st.k_over_a1 = st.k / (st.a + 1.0); /* V(x) = k_over_a1 x^(a+1): no division per trial */
    st.damping_over_dt = c->damping / dt;
    double twice = 2.0 * st.a;
    st.half_steps = (twice == floor(twice) && twice <= 8.0) ? (int)twice : -1;
    st.x0 = x0;
    st.x0a = fast_pos_pow(x0, st.a, st.half_steps);
    st.v0 = x0 > 0.0 ? st.k_over_a1 * st.x0a * x0 : 0.0; /* V(x0) */
    st.dh0 = x0 > 0.0 ? 0.5 * st.a * st.x0a / x0 : 0.0;  /* dh/dx0 */
    return st;
}

/* Force for the step x0 -> x1 and, when dforce is not NULL, dF/dx1 and
 * dforce_x0[0] = dF/dx0 (for the next sample's first guess only). Inlined: the
 * derivatives then stay in registers on the solve's dependency chain. */
static inline __attribute__((always_inline)) double step_force(const contact_step *st, double x1,
                                                               double *dforce, double *dforce_x0)
{
    const double k = st->k, a = st->a, x0 = st->x0;
    double x1a_below = 0.0; /* x1^(a-1), for dh */
    const double x1a = x1 > 0.0 ? fast_pow_and_below(x1, a, st->half_steps, &x1a_below) : 0.0;
    const double dx = x1 - x0;
    const double scale = fabs(x0) > fabs(x1) ? fabs(x0) : fabs(x1);
    double spring, dspring, dspring0;
    if (x0 <= 0.0 && x1 <= 0.0) {
        spring = dspring = dspring0 = 0.0;
    } else if (fabs(dx) > 1.0e-5 * scale) {
        /* Discrete gradient: the secant of V. */
        double v1 = x1 > 0.0 ? st->k_over_a1 * x1a * x1 : 0.0;
        double inv_dx = 1.0 / dx;
        spring = (v1 - st->v0) * inv_dx;
        dspring = (k * x1a - spring) * inv_dx;
        dspring0 = (spring - k * st->x0a) * inv_dx;
    } else {
        /* The secant would cancel catastrophically: its midpoint value equals it
         * to O(dx^2/x^2) < 1e-10 relative here. */
        double mid = 0.5 * (x0 + x1);
        double mida = fast_pos_pow(mid, a, st->half_steps);
        spring = k * mida;
        dspring = mid > 0.0 ? 0.5 * k * a * mida / mid : 0.0;
        dspring0 = dspring;
    }
    double h = 0.5 * (st->x0a + x1a);
    double dh = x1 > 0.0 ? 0.5 * a * x1a_below : 0.0;
    double f = spring + st->damping_over_dt * h * dx;
    double df = dspring + st->damping_over_dt * (h + dh * dx);
    double df0 = dspring0 + st->damping_over_dt * (st->dh0 * dx - h);
    /* Safety net for absurd states (e.g. 1e3 N s strikes on a 3 mg head): no
     * drumstick pushes with a teranewton, and a capped force stays finite. */
    if (!(f < CONTACT_FORCE_CAP)) {
        f = isnan(f) ? 0.0 : CONTACT_FORCE_CAP;
        df = df0 = 0.0;
    } else if (f <= 0.0) {
        f = 0.0;
        df = df0 = 0.0;
    }
    if (dforce)
        *dforce = isfinite(df) ? df : 0.0;
    if (dforce_x0)
        *dforce_x0 = isfinite(df0) ? df0 : 0.0;
    return f;
}

/* The residual (m) at which the solve below stops, for a trial force f (N). */
static double residual_tol(double x0, double x_free, double compliance, double f)
{
    return 1.0e-12 * (fabs(x_free) + fabs(x0) + compliance * f) + 1.0e-300;
}

/* Solves x1 = x_free - compliance * F(x0, x1) for the compression x1 (m) at the
 * end of one sample of dt seconds; returns F (N). force_guess (e.g. the last
 * sample's force, or 0) and u_guess (a compression, or <= 0 for none) only speed
 * it up: where the solve stops depends on the residual alone. */
/* What contact_solve() leaves for the next sample's guess: the last trial point,
 * its force and the force's derivatives there (valid = 0: none). */
typedef struct contact_lin {
    int valid;
    double u, f, d0, d1;
} contact_lin;

static double contact_solve(const contact *c, double x0, double x_free, double compliance,
                            double dt, double force_guess, double u_guess, double *x1,
                            contact_lin *lin)
{
    /* Root of r(u) = u - x_free + C F(x0, u) with r(x_free) = C F >= 0: Newton on
     * r, kept inside a bracket [lo, hi] and replaced by bisection whenever it
     * leaves it or stalls, so it is both fast (2-4 force evaluations) and bounded. */
    contact_step st = step_begin(c, x0, dt);
    double df, df0 = 0.0, f, u, r;
    if (lin)
        lin->valid = 0;
    double hi = x_free, lo = 0.0; /* r(x_free) = C F(x_free) >= 0 without evaluating it */
    int have_lo = 0;
    if (force_guess > 0.0) {
        /* The force is continuous from sample to sample: start where the last
         * sample's force would put the compression (usually 2 evaluations). */
        u = x_free - compliance * force_guess;
        /* Pressed on: the compression moves smoothly, its linear extrapolation
         * (when given and below x_free, where r >= 0 is known) lands closer. */
        if (u_guess > 0.0 && u_guess < x_free)
            u = u_guess;
        f = step_force(&st, u, &df, &df0);
        r = u - x_free + compliance * f;
        /* The bracket's side, without a branch: the sign of r is a coin toss from
         * sample to sample, and a mispredicted branch here lengthens the chain. */
        hi = r > 0.0 ? u : hi;
        lo = r > 0.0 ? lo : u;
        have_lo = !(r > 0.0);
    } else {
        f = step_force(&st, x_free, &df, &df0);
        if (f == 0.0) {
            *x1 = x_free; /* not touching during this sample */
            return 0.0;
        }
        u = x_free;
        r = compliance * f;
    }
    double dr = 1.0 + compliance * df;
    /* Residual (m) small enough that F and the compression agree to ~1e-12: far
     * below the float rounding of the modal state the energy balance lives with.
     * Scaled by the force at the trial point, not by the first trial's: F(x_free)
     * can exceed the force at the root by many orders (1e12 N against 1 N with a
     * 10 kg stick, lambda 1e13 on a 3 mg head), and a tolerance of C * 1e12 N let
     * the loop stop metres away from the root. */
    double tol = residual_tol(x0, x_free, compliance, f);
    for (int it = 0; it < 100 && fabs(r) > tol; it++) {
        double next = dr > 0.0 ? u - r / dr : -HUGE_VAL;
        if (!(next < hi) || (have_lo && !(next > lo)) || (!have_lo && !isfinite(next))) {
            if (!have_lo) {
                /* Find a lower end: F -> 0 as u -> -inf, so r turns negative. */
                double d = fabs(x_free) > fabs(x0) ? fabs(x_free) : fabs(x0);
                if (d < 1.0e-12)
                    d = 1.0e-12;
                for (int i = 0; i < 200; i++) {
                    lo = x_free - d;
                    if (lo - x_free + compliance * step_force(&st, lo, NULL, NULL) < 0.0)
                        break;
                    d *= 4.0;
                }
                have_lo = 1;
            }
            next = 0.5 * (lo + hi);
        }
        u = next;
        f = step_force(&st, u, &df, &df0);
        r = u - x_free + compliance * f;
        dr = 1.0 + compliance * df;
        hi = r > 0.0 ? u : hi;
        lo = r > 0.0 ? lo : u;
        have_lo |= !(r > 0.0);
        tol = residual_tol(x0, x_free, compliance, f);
        if (have_lo && hi - lo <= 1e-3 * tol)
            break;
    }
    if (have_lo && fabs(r) > tol) {
        /* Stopped by the bracket, not by the residual: F is so steep here (lambda / dt
         * up to 1e18) that no double u brings r below tol, and F(x0, u) at the last
         * trial point can be far from the force at the root (1e7 N instead of 1 N,
         * which threw the stick and the head metres apart and broke passivity). The
         * root's compression is pinned by [lo, hi], and the force the stick and the
         * membrane then see, (x_free - u) / C, is within (hi - lo) / C of the root's:
         * the energy error is that times the step, not F's jump across the bracket. */
        u = 0.5 * (lo + hi);
        *x1 = u;
        return (x_free - u) / compliance;
    }
    if (lin && f > 0.0) {
        lin->valid = 1;
        lin->u = u;
        lin->f = f;
        lin->d0 = df0;
        lin->d1 = df;
    }
    /* f = F(x0, u) at the last trial point. Report the compression the stick and membrane updates
     * will really produce. */
    *x1 = x_free - compliance * f;
    return f;
}

/* ---------------------------------------------------------------- the stroke
 * Called by the membrane through contact_point_ops (membrane_internal.h). */

static contact *point_contact(membrane_point *pt)
{
    return (contact *)pt; /* the point is the contact's first member */
}

/* A hit lands: the stick starts at the surface (compression 0) at the displacement
 * the membrane has there, closing in at the hit's velocity relative to the head there.
 * The hit's velocity is the physics' impact speed, measured against a head at rest; on
 * a head still moving from an earlier stroke the stick meets it at that speed, on the
 * sample the strike names, as the physics' stick does (docs/contact.md). */
static void contact_landed(membrane_point *pt, double displacement_m, double velocity_mps)
{
    contact *c = point_contact(pt);
    c->stick_x = displacement_m;
    c->stick_v = c->hit_velocity + (isfinite(velocity_mps) ? velocity_mps : 0.0);
    if (c->hit_mass_kg > 0.0)
        c->mass_kg = c->hit_mass_kg;
    c->compression = c->compression_before = 0.0;
    c->lin_valid = 0;
    c->force = 0.0;
    c->stretch_force = 0.0;
    c->point.active = 1;
    c->touching = 0;
    c->ever_touched = 0;
    c->stroke_samples = 0;
    c->first_touch = c->last_release = 0.0;
    c->peak_force = c->impulse = 0.0;
    if (c->queued > 0 && pt->owner) {
        /* The next hit waits for its own sample, later in this block or a later one. */
        struct queued_hit next = c->queue[0];
        c->queued--;
        memmove(c->queue, c->queue + 1, sizeof(c->queue[0]) * (size_t)c->queued);
        c->hit_velocity = next.velocity;
        c->hit_mass_kg = next.mass_kg;
        membrane_point_move_(pt, next.r_over_a, next.theta_deg, next.offset);
    }
}

/* The stroke is over. A stick that touched the head (a force, if only within one
 * sample) is reported; one that never did is not: landing on a head that comes at it
 * faster than the hit, and draws back before the stick reaches it, it goes off at the
 * head's speed it was given on landing (contact_landed), which is no rebound, and
 * there is no contact to report (docs/contact.md). */
static void finish_stroke(contact *c, double dt)
{
    if (c->ever_touched || c->peak_force > 0.0) {
        if (c->reports_ready == CONTACT_REPORT_QUEUE) { /* none taken for long: keep the newest */
            c->reports_ready--;
            memmove(c->reports, c->reports + 1, sizeof(c->reports[0]) * (size_t)c->reports_ready);
        }
        contact_report *r = &c->reports[c->reports_ready++];
        r->duration_ms = (c->ever_touched ? (c->last_release - c->first_touch) * dt * 1000.0 : 0.0);
        r->peak_force_n = c->peak_force;
        r->rebound_velocity_mps = c->stick_v < 0.0 ? -c->stick_v : 0.0;
        r->impulse_ns = c->impulse;
    }
    c->point.active = 0;
    c->touching = 0;
}

/* The head's stretching k3 under this stick: a membrane's; a plate (membrane_set_plate)
 * has none. */
static double head_k3(const contact *c)
{
    return c->point.owner && c->point.owner->plate ? 0.0 : c->stretch;
}

/* The stretching's force on the head under the stick over a step of its depth
 * s0 -> s1 (m): the discrete gradient of U(s) = k3 s+^4 / 4, so that its work is
 * U's change. */
static double stretch_step_force(double k3, double s0, double s1)
{
    if (!(k3 > 0.0) || (s0 <= 0.0 && s1 <= 0.0))
        return 0.0;
    double a = s0 > 0.0 ? s0 : 0.0, b = s1 > 0.0 ? s1 : 0.0;
    if (fabs(b - a) > 1.0e-9 * (a + b)) {
        double a2 = a * a, b2 = b * b;
        return 0.25 * k3 * (b2 * b2 - a2 * a2) / (s1 - s0);
    }
    double m = 0.5 * (a + b);
    return k3 * m * m * m;
}

/* One stick alone: the scalar solve of its compression, and (stretch > 0) the
 * stretching's force G on the head under it, made consistent with the head's new
 * depth there by re-solving until that depth stops moving (2-3 solves). The head
 * takes F - G, so the compression is x_free - C F + K G. Returns F; *g gets G. */
static double contact_solve_one(contact *c, double xfree, double K, double T, double *x1, double *g)
{
    double C = T * T / (2.0 * c->mass_kg) + K;
    double w0 = c->stick_x - c->compression;               /* the head's depth under the stick */
    double wfree = c->stick_x + T * c->stick_v - xfree;    /* ... without this sample's forces */
    double w1 = wfree + K * (c->force - c->stretch_force); /* with the last sample's */
    double G = 0.0, F = 0.0;
    for (int pass = 0; pass < 4; pass++) {
        G = stretch_step_force(head_k3(c), w0, w1);
        double ug = -1.0;
        if (c->force > 0.0 && c->lin_valid && pass == 0) {
            /* The last sample's force law, linearised, in x1 = x_free - C F: the
             * membrane's part of the move (x_free) is exact, the law's curvature
             * is the error. */
            double Cd1 = C * c->lin_d1;
            ug = (xfree + K * G - C * (c->lin_f + c->lin_d0 * (c->compression - c->lin_x0)) +
                  Cd1 * c->lin_u) /
                 (1.0 + Cd1);
        } else if (c->force > 0.0 && c->compression > 0.0 && c->compression_before > 0.0) {
            ug = 2.0 * c->compression - c->compression_before;
        }
        contact_lin lin = {0, 0.0, 0.0, 0.0, 0.0};
        double x0 = c->compression;
        F = contact_solve(c, x0, xfree + K * G, C, T, c->force, ug, x1, &lin);
        c->lin_valid = lin.valid;
        c->lin_x0 = x0;
        c->lin_u = lin.u;
        c->lin_f = lin.f;
        c->lin_d0 = lin.d0;
        c->lin_d1 = lin.d1;
        double w_new = wfree + K * (F - G);
        double moved = fabs(w_new - w1);
        w1 = w_new;
        if (!(head_k3(c) > 0.0) || moved <= 1.0e-13 + 1.0e-10 * fabs(w1))
            break;
    }
    *g = G;
    return F;
}

/* Joint implicit solve of every active contact for this sample (Gauss-Seidel
 * over contacts, up to 30 sweeps; a single contact needs none). */
static void contact_solve_points(membrane_point *const *pts, int na, const double *w_free,
                                 const double (*K)[MEMBRANE_MAX_POINTS], double T, int sample,
                                 double out_extra[MEMBRANE_PICKUPS])
{
    double xfree[MEMBRANE_MAX_POINTS], F[MEMBRANE_MAX_POINTS] = {0}, x1[MEMBRANE_MAX_POINTS];
    for (int i = 0; i < na; i++) {
        contact *c = point_contact(pts[i]);
        /* Free compression: stick coasting, membrane without this sample's force. */
        xfree[i] = c->stick_x + T * c->stick_v - w_free[i];
        x1[i] = xfree[i];
    }
    double G[MEMBRANE_MAX_POINTS] = {0};
    if (na == 1) {
        /* One stick, the common case: the scalar solve is exact, nothing to sweep. */
        F[0] = contact_solve_one(point_contact(pts[0]), xfree[0], K[0][0], T, &x1[0], &G[0]);
    } else {
        for (int i = 0; i < na; i++) {
            /* The stretching at the head's depth the last sample's forces predict. */
            contact *c = point_contact(pts[i]);
            double w0 = c->stick_x - c->compression;
            double w1 = w_free[i] + K[i][i] * (c->force - c->stretch_force);
            G[i] = stretch_step_force(head_k3(c), w0, w1);
            xfree[i] += K[i][i] * G[i];
        }
        for (int s = 0; s < 30; s++) {
            double change = 0.0;
            for (int i = 0; i < na; i++) {
                contact *c = point_contact(pts[i]);
                double xf = xfree[i];
                for (int j = 0; j < na; j++)
                    if (j != i)
                        xf -= K[i][j] * (F[j] - G[j]);
                double C = T * T / (2.0 * c->mass_kg) + K[i][i];
                double Fi =
                    contact_solve(c, c->compression, xf, C, T, c->force, -1.0, &x1[i], NULL);
                c->lin_valid = 0;
                change += fabs(Fi - F[i]);
                F[i] = Fi;
            }
            if (change <= 1.0e-12 * (1.0 + fabs(F[0])))
                break;
        }
    }
    for (int i = 0; i < na; i++) {
        contact *c = point_contact(pts[i]);
        double Fi = F[i];
        /* Midpoint rule for the stick: m (v+ - v) = -T F, x+ = x + T (v + v+) / 2; the
         * head takes F - G. */
        double v1 = c->stick_v - T * Fi / c->mass_kg;
        c->stretch_force = G[i];
        c->stick_x += 0.5 * T * (c->stick_v + v1);
        c->stick_v = v1;
        double xw = x1[i], xprev = c->compression;
        c->force = Fi;
        c->point.force_pending = Fi - G[i];
        c->stroke_samples++;
        double t_end = (double)c->stroke_samples, t_start = t_end - 1.0;
        /* Touching = compressed at the end of the sample; the sample in which x
         * crosses zero (force may still be > 0 in it) holds the interpolated
         * touch or release instant. */
        int now_touching = xw > 0.0;
        if (now_touching && !c->touching) {
            /* Touch: interpolate where the compression crossed zero. */
            double t = xprev < 0.0 && xw > 0.0 ? t_start + (-xprev) / (xw - xprev) : t_start;
            if (!c->ever_touched)
                c->first_touch = t;
            c->ever_touched = 1;
        } else if (!now_touching && c->touching) {
            c->last_release = xprev > 0.0 && xw < 0.0 ? t_start + xprev / (xprev - xw) : t_end;
        }
        c->touching = now_touching;
        c->compression_before = c->compression;
        c->compression = xw;
        if (Fi > c->peak_force)
            c->peak_force = Fi;
        c->impulse += Fi * T;
        for (int j = 0; j < MEMBRANE_PICKUPS; j++)
            out_extra[j] += (Fi - G[i]) * c->point.pick_coupling[j];
        /* Release: away from the surface and moving away, and either clear of it
         * (5 mm) or 50 ms after the last touch; before the first touch the stroke
         * waits (a stick moving away from the start never touches: 50 ms). */
        if (!c->touching) {
            double since = c->stroke_samples - (c->ever_touched ? c->last_release : 0.0);
            int moving_away = c->stick_v <= 0.0;
            if ((c->ever_touched && moving_away && (-xw > 0.005 || since * T > 0.05)) ||
                (!c->ever_touched && moving_away && since * T > 0.05))
                finish_stroke(c, T);
        }
        /* The force outlet reads 0 from the sample the stroke ends in. */
        if (c->force_out && sample < c->force_cap)
            c->force_out[sample] = c->point.active ? (float)Fi : 0.0f;
    }
}

/* Samples without a stroke carry no force: the solve overwrites the others. */
static void contact_block_begin(membrane_point *pt, int n)
{
    contact *c = point_contact(pt);
    for (int i = 0; i < c->queued; i++)
        c->queue[i].offset -= c->queue_shift;
    c->queue_shift = n;
    int have = n < c->force_cap ? n : c->force_cap;
    if (c->force_out && have > 0)
        memset(c->force_out, 0, sizeof(float) * (size_t)have);
}

static void contact_cleared(membrane_point *pt)
{
    contact *c = point_contact(pt);
    c->point.active = c->touching = 0;
    c->force = 0.0;
    c->stick_v = c->stick_x = c->compression = c->compression_before = 0.0;
    c->lin_valid = 0;
    c->queued = 0;
}

static void contact_detached(membrane_point *pt)
{
    contact *c = point_contact(pt);
    c->point.active = c->touching = 0;
    c->force = 0.0;
    c->queued = 0; /* their offsets were the old membrane's */
    c->queue_shift = 0;
}

static const membrane_point_ops contact_point_ops = {
    contact_landed,  contact_solve_points, contact_block_begin,
    contact_cleared, contact_detached,     NULL,
};

ictus_status membrane_attach_contact(membrane *m, contact *c)
{
    if (!m || !c)
        return ICTUS_CLAMPED;
    if (c->point.owner == m)
        return ICTUS_OK;
    ictus_status s = membrane_point_attach_(m, &c->point);
    if (s == ICTUS_OK) {
        /* A stroke in progress elsewhere is over; a hit not yet landed will land here. */
        c->point.active = c->touching = 0;
        c->force = 0.0;
    }
    return s;
}

void membrane_detach_contact(membrane *m, contact *c)
{
    if (c)
        membrane_point_detach_(m, &c->point);
}

int contact_simulate_rigid(const contact *c, double velocity_mps, double sample_rate_hz,
                           double max_seconds, contact_report *report)
{
    if (!isfinite(velocity_mps) || !isfinite(sample_rate_hz) || !isfinite(max_seconds) ||
        sample_rate_hz <= 0.0 || velocity_mps <= 0.0)
        return 0;
    if (velocity_mps > CONTACT_VELOCITY_MAX)
        velocity_mps = CONTACT_VELOCITY_MAX;
    const double T = 1.0 / sample_rate_hz, C = T * T / (2.0 * c->mass_kg);
    double x = 0.0, v = velocity_mps, peak = 0.0, impulse = 0.0, last_force = 0.0;
    long steps = (long)(max_seconds * sample_rate_hz);
    for (long s = 0; s < steps; s++) {
        double x1;
        double f = contact_solve(c, x, x + T * v, C, T, last_force, -1.0, &x1, NULL);
        last_force = f;
        double v1 = v - T * f / c->mass_kg;
        if (f > peak)
            peak = f;
        impulse += f * T;
        if (x1 < 0.0 && s > 0) {
            /* Released during this sample: interpolate the zero crossing. */
            double frac = x / (x - x1);
            if (report) {
                report->duration_ms = (s + frac) * T * 1000.0;
                report->peak_force_n = peak;
                report->rebound_velocity_mps = v1 < 0.0 ? -v1 : 0.0;
                report->impulse_ns = impulse;
            }
            return 1;
        }
        x = x1;
        v = v1;
    }
    return 0;
}
