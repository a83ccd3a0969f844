/* contact.c -- Hunt-Crossley stick contact with an energy-consistent discretisation.
 *
 * Force law (contact.h; lambda is Hunt & Crossley's damping per unit stiffness,
 * in s/m, so that F = k x^alpha (1 + lambda dx/dt)):
 *     F = k x^a + lambda k x^a dx/dt   for x > 0, and F >= 0.
 * Discretised over one sample (x0 -> x1) as
 *     F = max(0, (V(x1) - V(x0)) / (x1 - x0) + lambda k h (x1 - x0) / T),
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

static ictus_status clamp_range(double *v, double lo, double hi, double fallback)
{
    if (isnan(*v)) {
        *v = fallback;
        return ICTUS_CLAMPED;
    }
    if (*v < lo) {
        *v = lo;
        return ICTUS_CLAMPED;
    }
    if (*v > hi) {
        *v = hi;
        return ICTUS_CLAMPED;
    }
    return ICTUS_OK;
}

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
    free(c);
}

ictus_status contact_set_mass(contact *c, double v)
{
    ictus_status s = clamp_range(&v, CONTACT_MASS_MIN, CONTACT_MASS_MAX, CONTACT_DEFAULT_MASS);
    c->mass_kg = v;
    return s;
}

ictus_status contact_set_stiffness(contact *c, double v)
{
    ictus_status s =
        clamp_range(&v, CONTACT_STIFFNESS_MIN, CONTACT_STIFFNESS_MAX, CONTACT_DEFAULT_STIFFNESS);
    c->stiffness = v;
    return s;
}

ictus_status contact_set_alpha(contact *c, double v)
{
    ictus_status s = clamp_range(&v, CONTACT_ALPHA_MIN, CONTACT_ALPHA_MAX, CONTACT_DEFAULT_ALPHA);
    c->alpha = v;
    return s;
}

ictus_status contact_set_damping(contact *c, double v)
{
    ictus_status s =
        clamp_range(&v, CONTACT_DAMPING_MIN, CONTACT_DAMPING_MAX, CONTACT_DEFAULT_DAMPING);
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
    ictus_status s = clamp_range(&velocity_mps, 0.0, CONTACT_VELOCITY_MAX, 1.0);
    if (clamp_range(&r_over_a, 0.0, 1.0, 0.0) != ICTUS_OK)
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

static double pos_pow(double x, double a)
{
    return x > 0.0 ? pow(x, a) : 0.0;
}

double contact_force_law_(const contact *c, double x0, double x1, double dt)
{
    const double k = c->stiffness, a = c->alpha;
    double dx = x1 - x0;
    double scale = fabs(x0) > fabs(x1) ? fabs(x0) : fabs(x1);
    double spring;
    if (x0 <= 0.0 && x1 <= 0.0) {
        spring = 0.0;
    } else if (fabs(dx) > 1.0e-5 * scale) {
        spring = k * (pos_pow(x1, a + 1.0) - pos_pow(x0, a + 1.0)) / ((a + 1.0) * dx);
    } else {
        /* Secant of V would cancel catastrophically: its midpoint value equals it
         * to O(dx^2/x^2) < 1e-10 relative here. */
        spring = k * pos_pow(0.5 * (x0 + x1), a);
    }
    double h = 0.5 * (pos_pow(x0, a) + pos_pow(x1, a));
    double f = spring + c->damping * k * h * dx / dt;
    /* Safety net for absurd states (e.g. 1e3 N s strikes on a 3 mg head): no
     * drumstick pushes with a teranewton, and a capped force stays finite. */
    if (!(f < CONTACT_FORCE_CAP))
        return isnan(f) ? 0.0 : CONTACT_FORCE_CAP;
    return f > 0.0 ? f : 0.0;
}

double contact_solve_(const contact *c, double x0, double x_free, double compliance, double dt,
                      double *x1)
{
    /* Root of r(u) = u - x_free + C F(x0, u); r(x_free) = C F >= 0. */
    double f_hi = contact_force_law_(c, x0, x_free, dt);
    if (f_hi == 0.0) {
        *x1 = x_free;
        return 0.0;
    }
    double hi = x_free, r_hi = compliance * f_hi;
    double d = fabs(x_free) > fabs(x0) ? fabs(x_free) : fabs(x0);
    if (d < 1.0e-12)
        d = 1.0e-12;
    double lo = x_free - d, r_lo = lo - x_free + compliance * contact_force_law_(c, x0, lo, dt);
    for (int i = 0; i < 200 && r_lo >= 0.0; i++) {
        /* F -> 0 as u -> -inf, so r eventually turns negative. */
        d *= 4.0;
        lo = x_free - d;
        r_lo = lo - x_free + compliance * contact_force_law_(c, x0, lo, dt);
    }
    /* Illinois regula falsi with a bisection fallback: bounded, never leaves the bracket. */
    double u = hi;
    int side = 0;
    double tol = 1.0e-15 * (fabs(x_free) + fabs(x0) + compliance * f_hi) + 1.0e-300;
    for (int it = 0; it < 100 && hi - lo > tol; it++) {
        u = (lo * r_hi - hi * r_lo) / (r_hi - r_lo);
        if (!(u > lo && u < hi) || it % 8 == 7)
            u = 0.5 * (lo + hi);
        double r = u - x_free + compliance * contact_force_law_(c, x0, u, dt);
        if (r == 0.0) {
            lo = hi = u;
            break;
        }
        if (r > 0.0) {
            hi = u;
            r_hi = r;
            if (side == 1)
                r_lo *= 0.5;
            side = 1;
        } else {
            lo = u;
            r_lo = r;
            if (side == -1)
                r_hi *= 0.5;
            side = -1;
        }
    }
    u = 0.5 * (lo + hi);
    double f = contact_force_law_(c, x0, u, dt);
    /* Report the compression the stick and membrane updates will really produce. */
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
    double x = 0.0, v = velocity_mps, peak = 0.0, impulse = 0.0;
    long steps = (long)(max_seconds * sample_rate_hz);
    for (long s = 0; s < steps; s++) {
        double x1;
        double f = contact_solve_(c, x, x + T * v, C, T, &x1);
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
