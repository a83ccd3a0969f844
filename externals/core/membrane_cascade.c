/* membrane_cascade.c -- a plate's von Karman cascade in the modal loop (plate_cascade.h;
 * docs/plates.md, "The cascade").
 *
 * The scheme: the nonlinear force -dV/dY on the coupled modes is written as -g psi with
 * psi an auxiliary variable, psi^2 / 2 = V + floor, and g = dV/dY / sqrt(2 (V + floor))
 * (the scalar auxiliary variable method: X. Yang,
 * J. Comput. Phys. 327, 2016; for modal plates M. Ducceschi, S. Bilbao, "Simulation of
 * the geometrically exact nonlinear string via energy quadratisation", JSV 534, 2022).
 * Over one sample the force is -g (psi + psi+) / 2 and psi+ = psi + g . (Y+ - Y), g taken
 * at Y + (Y - Y-) / 2 (second order: the backbone of test_plate_cascade.cpp). The
 * linear step is the kernel's midpoint rule, in which a force f held over the sample
 * moves Y by b f more (b = h^2 cd) and does the work f . (Y+ - Y); psi^2 / 2 changes by
 * exactly minus that work. So the linear energy plus psi^2 / 2 is conserved by the
 * coupling whatever g is, and only the modes' damping and the stick change it: no
 * energy is created at any amplitude. The force is solved in closed form (one scalar
 * equation) and folded into the state after the kernel's step, like a stick's force;
 * its direct path to the pickups and to the sticks' displacements goes with it. */
#include "membrane_internal.h"
#include "plate_cascade.h"

#include <math.h>
#include <stdlib.h>

/* The reduced model: the lowest CASCADE_MODES transverse modes, the in-plane modes with
 * zeta below CASCADE_ZETA_MAX, every entry of H the selection rule allows (CASCADE_TOL 0). */
#define CASCADE_MODES    32
#define CASCADE_ZETA_MAX 8.0
#define CASCADE_TOL      0.0
/* kg/m^3: cymbal bronze, for the thickness h = density / rho of E h (docs/plates.md) */
#define CASCADE_BRONZE_RHO 8600.0

void membrane_cascade_free_(membrane *m)
{
    if (m->pc) {
        plate_cascade_free(m->pc);
        free(m->pc);
        m->pc = NULL;
    }
    m->vk_on = 0;
}

/* Y of the coupled modes from the stored state, the auxiliary variable from V there,
 * and g for the next sample. */
static void anchor(membrane *m)
{
    plate_cascade *c = m->pc;
    const float h = (float)m->coef_h;
    for (int k = 0; k < c->modes; k++)
        c->y[k] = h * m->sc[k] * m->q[k];
    double v = plate_cascade_potential(c, c->y, c->g);
    c->psi = sqrt(2.0 * (v + c->floor));
    for (int k = 0; k < c->modes; k++)
        c->g[k] = (float)(c->g[k] / c->psi);
}

void membrane_cascade_refresh_(membrane *m)
{
    m->vk_on = 0;
    if (!m->plate || !(m->von_karman > 0.0) || m->modes < CASCADE_MODES || !m->table.plate)
        return;
    if (!m->pc) {
        plate_cascade *c = calloc(1, sizeof(plate_cascade));
        if (!c || plate_cascade_build(c, &m->table, CASCADE_MODES, CASCADE_ZETA_MAX, CASCADE_TOL) !=
                      ICTUS_OK) {
            free(c);
            return;
        }
        m->pc = c;
    }
    if (m->kernel == membrane_kernel_generic) /* ICTUS_MEMBRANE_KERNEL=generic: portable too */
        m->pc->potential = plate_cascade_potential_generic;
    /* E h from D = E h^3 / (12 (1 - nu^2)) and h = density / rho */
    const double nu = MODE_TABLE_PLATE_NU, h = m->density / CASCADE_BRONZE_RHO;
    const double eh = 12.0 * (1.0 - nu * nu) * m->bending / (h * h);
    plate_cascade_set_scale(m->pc, m->von_karman * eh, m->radius, m->density);
    anchor(m);
    m->vk_on = 1;
}

void membrane_cascade_cleared_(membrane *m)
{
    if (m->vk_on)
        anchor(m);
}

/* The band-level cascade rescaled some modes between samples, conserving their linear
 * energy but not V: Y follows the new state and psi is anchored to V(Y) again, so that the
 * coupling's force stays -dV/dY (keeping psi instead leaves it off by what each rescaling
 * changed V, and after a second it had the wrong sign). Re-anchoring removes energy when V
 * fell; when V rose by dV, the coupled modes first give up dV of their own (scaled), so the
 * scheme's energy (linear + psi^2 / 2) never grows. */
void membrane_cascade_rescaled_(membrane *m)
{
    if (!m->vk_on)
        return;
    plate_cascade *c = m->pc;
    const float h = (float)m->coef_h;
    for (int k = 0; k < c->modes; k++)
        c->y[k] = h * m->sc[k] * m->q[k];
    double v = plate_cascade_potential(c, c->y, c->g);
    const double rise = v + c->floor - 0.5 * c->psi * c->psi;
    if (rise > 0.0) {
        double ec = 0.0; /* the coupled modes' linear energy (the kernel's e_k) */
        for (int k = 0; k < c->modes; k++) {
            const double x = h * m->wm[k] * m->sc[k] * m->q[k], p = m->sc[k] * m->p[k];
            ec += 0.5 * (x * x + p * p);
        }
        const float s = (float)sqrt(rise < ec ? (ec - rise) / ec : 0.0);
        for (int k = 0; k < c->modes; k++) {
            m->q[k] *= s;
            m->p[k] *= s;
            c->y[k] = h * m->sc[k] * m->q[k];
        }
        v = plate_cascade_potential(c, c->y, c->g);
    }
    c->psi = sqrt(2.0 * (v + c->floor));
    for (int k = 0; k < c->modes; k++)
        c->g[k] = (float)(c->g[k] / c->psi);
}

void membrane_cascade_step_(membrane *m, membrane_kernel_args *a, int input, double *extra,
                            int picks)
{
    plate_cascade *c = m->pc;
    const int n = c->modes;
    const float h = (float)m->coef_h;
    const double b0 = m->coef_h * m->coef_h;
    double num = 0.0, den = 0.0;
    for (int k = 0; k < n; k++) {
        c->dy[k] = h * m->sc[k] * m->q[k] - c->y[k];
        num += (double)c->g[k] * c->dy[k];
        den += b0 * m->cd[k] * c->g[k] * c->g[k];
    }
    const double psibar = (c->psi + 0.5 * num) / (1.0 + 0.5 * den);
    const float fh = (float)(-psibar * m->coef_h);
    double ex[MEMBRANE_PICKUPS] = {0}, w[MEMBRANE_MAX_POINTS] = {0};
    for (int k = 0; k < n; k++) {
        const float u = fh * c->g[k] * m->sc[k]; /* f coef_h sc, into stored q and p */
        m->q[k] += u;
        m->p[k] += u;
        const float y = h * m->sc[k] * m->q[k];
        c->dy[k] = y + 0.5f * (y - c->y[k]); /* Y extrapolated half a sample on */
        c->y[k] = y;
        for (int j = 0; j < picks; j++)
            ex[j] += (double)a->psi_pick[j][k] * u;
        for (int p = 0; p < a->points; p++)
            w[p] += (double)a->point_psi[p][k] * u;
    }
    for (int j = 0; j < picks; j++)
        extra[j] += ex[j];
    for (int p = 0; p < a->points; p++)
        a->point_w[p] += w[p];
    c->psi = 2.0 * psibar - c->psi;
    /* An input (a stroke) changed the state from outside the scheme: psi follows V, but
     * only down (never above sqrt(2 (V + floor)), never below 0): raised to V it would
     * add energy that no force gave, every sample a stick presses (a thin plate's stick
     * came back faster than it came). */
    if (input) {
        const double top = sqrt(2.0 * (plate_cascade_potential(c, c->y, NULL) + c->floor));
        c->psi = c->psi > top ? top : c->psi > 0.0 ? c->psi : 0.0;
    }
    /* g for the next sample at the state half a sample on (second order in time) */
    const double v = plate_cascade_potential(c, c->dy, c->g);
    const double s = sqrt(2.0 * (v + c->floor));
    if (!isfinite(c->psi) || !isfinite(v)) {
        c->psi = sqrt(2.0 * c->floor);
        for (int k = 0; k < n; k++)
            c->g[k] = 0.0f;
        return;
    }
    const float is = (float)(1.0 / s);
    for (int k = 0; k < n; k++)
        c->g[k] *= is;
}

double membrane_cascade_energy(const membrane *m)
{
    if (!m->vk_on)
        return 0.0;
    return 0.5 * m->pc->psi * m->pc->psi - m->pc->floor;
}
