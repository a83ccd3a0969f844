/* contact.c -- Hunt-Crossley stick contact with an energy-consistent discretisation.
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
 */
#include "membrane_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CONTACT_FORCE_CAP 1.0e12 /* N */

contact *contact_new(void)
{
    contact *c = calloc(1, sizeof(*c));
    if (!c)
        return NULL;
    c->mass_kg = CONTACT_DEFAULT_MASS;
    c->stiffness = CONTACT_DEFAULT_STIFFNESS;
    c->alpha = CONTACT_DEFAULT_ALPHA;
    c->damping = CONTACT_DEFAULT_DAMPING;
    c->r_over_a = 0.3;
    return c;
}

void contact_free(contact *c)
{
    if (!c)
        return;
    if (c->owner)
        membrane_detach_contact(c->owner, c);
    free(c->psi);
    free(c->psi_next);
    free(c->gq);
    free(c->gp);
    free(c->wd);
    free(c);
}

ictus_status contact_set_mass(contact *c, double v)
{
    ictus_status s = ictus_clamp(&v, CONTACT_MASS_MIN, CONTACT_MASS_MAX, CONTACT_DEFAULT_MASS);
    c->mass_kg = v;
    return s;
}

ictus_status contact_set_stiffness(contact *c, double v)
{
    ictus_status s =
        ictus_clamp(&v, CONTACT_STIFFNESS_MIN, CONTACT_STIFFNESS_MAX, CONTACT_DEFAULT_STIFFNESS);
    c->stiffness = v;
    return s;
}

ictus_status contact_set_alpha(contact *c, double v)
{
    ictus_status s = ictus_clamp(&v, CONTACT_ALPHA_MIN, CONTACT_ALPHA_MAX, CONTACT_DEFAULT_ALPHA);
    c->alpha = v;
    return s;
}

ictus_status contact_set_damping(contact *c, double v)
{
    ictus_status s =
        ictus_clamp(&v, CONTACT_DAMPING_MIN, CONTACT_DAMPING_MAX, CONTACT_DEFAULT_DAMPING);
    c->damping = v;
    return s;
}

double contact_get_mass(const contact *c)
{
    return c->mass_kg;
}
double contact_get_stiffness(const contact *c)
{
    return c->stiffness;
}
double contact_get_alpha(const contact *c)
{
    return c->alpha;
}
double contact_get_damping(const contact *c)
{
    return c->damping;
}

ictus_status contact_hit(contact *c, double velocity_mps, double r_over_a, double theta_deg,
                         int sample_offset)
{
    ictus_status s = ictus_clamp(&velocity_mps, 0.0, CONTACT_VELOCITY_MAX, 1.0);
    if (ictus_clamp(&r_over_a, 0.0, 1.0, 0.0) != ICTUS_OK)
        s = ICTUS_CLAMPED;
    if (!isfinite(theta_deg)) {
        theta_deg = 0.0;
        s = ICTUS_CLAMPED;
    }
    theta_deg = fmod(theta_deg, 360.0);
    if (theta_deg < 0.0)
        theta_deg += 360.0;
    if (sample_offset < 0) {
        sample_offset = 0;
        s = ICTUS_CLAMPED;
    }
    c->hit_velocity = velocity_mps;
    c->hit_r = r_over_a;
    c->hit_theta = theta_deg;
    c->hit_offset = sample_offset;
    c->hit_pending = 1;
    /* The weights of the new point are computed here, in the message handler,
     * so that landing the hit in the audio loop costs O(modes) only. */
    if (c->owner)
        membrane_mode_shapes_(c->owner, r_over_a, theta_deg, c->psi_next);
    return s;
}

void contact_set_force_output(contact *c, float *buffer, int capacity)
{
    c->force_out = capacity > 0 ? buffer : NULL;
    c->force_cap = buffer ? capacity : 0;
}

int contact_is_active(const contact *c)
{
    return c->active || c->hit_pending;
}

int contact_take_report(contact *c, contact_report *report)
{
    if (!c->report_ready)
        return 0;
    if (report)
        *report = c->report;
    c->report_ready = 0;
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

/* What stays fixed while one sample's equation is solved: the start compression
 * x0 and its powers, so that each trial x1 costs one pow(). */
typedef struct contact_step {
    double k, a, damping_over_dt, x0, x0a, v0;
    int half_steps; /* 2a when that is a whole number, else -1 */
} contact_step;

static contact_step step_begin(const contact *c, double x0, double dt)
{
    contact_step st;
    st.k = c->stiffness;
    st.a = c->alpha;
    st.damping_over_dt = c->damping / dt;
    double twice = 2.0 * st.a;
    st.half_steps = (twice == floor(twice) && twice <= 8.0) ? (int)twice : -1;
    st.x0 = x0;
    st.x0a = fast_pos_pow(x0, st.a, st.half_steps);
    st.v0 = x0 > 0.0 ? st.k * st.x0a * x0 / (st.a + 1.0) : 0.0; /* V(x0) */
    return st;
}

/* Force for the step x0 -> x1 and, when dforce is not NULL, dF/dx1. */
static double step_force(const contact_step *st, double x1, double *dforce)
{
    const double k = st->k, a = st->a, x0 = st->x0;
    const double x1a = fast_pos_pow(x1, a, st->half_steps);
    const double dx = x1 - x0;
    const double scale = fabs(x0) > fabs(x1) ? fabs(x0) : fabs(x1);
    double spring, dspring;
    if (x0 <= 0.0 && x1 <= 0.0) {
        spring = dspring = 0.0;
    } else if (fabs(dx) > 1.0e-5 * scale) {
        /* Discrete gradient: the secant of V. */
        double v1 = x1 > 0.0 ? k * x1a * x1 / (a + 1.0) : 0.0;
        spring = (v1 - st->v0) / dx;
        dspring = (k * x1a - spring) / dx;
    } else {
        /* The secant would cancel catastrophically: its midpoint value equals it
         * to O(dx^2/x^2) < 1e-10 relative here. */
        double mid = 0.5 * (x0 + x1);
        double mida = fast_pos_pow(mid, a, st->half_steps);
        spring = k * mida;
        dspring = mid > 0.0 ? 0.5 * k * a * mida / mid : 0.0;
    }
    double h = 0.5 * (st->x0a + x1a);
    double dh = x1 > 0.0 ? 0.5 * a * x1a / x1 : 0.0;
    double f = spring + st->damping_over_dt * h * dx;
    double df = dspring + st->damping_over_dt * (h + dh * dx);
    /* Safety net for absurd states (e.g. 1e3 N s strikes on a 3 mg head): no
     * drumstick pushes with a teranewton, and a capped force stays finite. */
    if (!(f < CONTACT_FORCE_CAP)) {
        f = isnan(f) ? 0.0 : CONTACT_FORCE_CAP;
        df = 0.0;
    } else if (f <= 0.0) {
        f = 0.0;
        df = 0.0;
    }
    if (dforce)
        *dforce = isfinite(df) ? df : 0.0;
    return f;
}

double contact_force_law_(const contact *c, double x0, double x1, double dt)
{
    contact_step st = step_begin(c, x0, dt);
    return step_force(&st, x1, NULL);
}

double contact_solve_(const contact *c, double x0, double x_free, double compliance, double dt,
                      double force_guess, double *x1)
{
    /* Root of r(u) = u - x_free + C F(x0, u) with r(x_free) = C F >= 0: Newton on
     * r, kept inside a bracket [lo, hi] and replaced by bisection whenever it
     * leaves it or stalls, so it is both fast (2-4 force evaluations) and bounded. */
    contact_step st = step_begin(c, x0, dt);
    double df, f, u, r;
    double hi = x_free, lo = 0.0; /* r(x_free) = C F(x_free) >= 0 without evaluating it */
    int have_lo = 0;
    if (force_guess > 0.0) {
        /* The force is continuous from sample to sample: start where the last
         * sample's force would put the compression (usually 2 evaluations). */
        u = x_free - compliance * force_guess;
        f = step_force(&st, u, &df);
        r = u - x_free + compliance * f;
        if (r > 0.0) {
            hi = u;
        } else {
            lo = u;
            have_lo = 1;
        }
    } else {
        f = step_force(&st, x_free, &df);
        if (f == 0.0) {
            *x1 = x_free; /* not touching during this sample */
            return 0.0;
        }
        u = x_free;
        r = compliance * f;
    }
    double dr = 1.0 + compliance * df;
    /* Residual (m) small enough that F and the compression agree to ~1e-12: far
     * below the float rounding of the modal state the energy balance lives with. */
    const double tol =
        1.0e-12 * (fabs(x_free) + fabs(x0) + compliance * (f > force_guess ? f : force_guess)) +
        1.0e-300;
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
                    if (lo - x_free + compliance * step_force(&st, lo, NULL) < 0.0)
                        break;
                    d *= 4.0;
                }
                have_lo = 1;
            }
            next = 0.5 * (lo + hi);
        }
        u = next;
        f = step_force(&st, u, &df);
        r = u - x_free + compliance * f;
        dr = 1.0 + compliance * df;
        if (r > 0.0) {
            hi = u;
        } else {
            lo = u;
            have_lo = 1;
        }
        if (have_lo && hi - lo <= 1e-3 * tol)
            break;
    }
    /* f = F(x0, u) at the last trial point. Report the compression the stick and membrane updates
     * will really produce. */
    *x1 = x_free - compliance * f;
    return f;
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
        double f = contact_solve_(c, x, x + T * v, C, T, last_force, &x1);
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
