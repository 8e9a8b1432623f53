/* contact_pivot.c: two sticking contacts as a rotation about the edge
 * through them (see contact_pivot.h).
 *
 * Both contacts at rest fix the line through them, so the part can only
 * turn about it: one angle a, with I_e a'' = gravity's torque about the
 * edge (the contact forces act on the axis and have none), a pendulum. The
 * state and the forces are explicit functions of a, a' and a'', so the
 * phase integrates two unknowns instead of thirteen and solves no force
 * system: the forces follow from the motion, the total force from the
 * centre's acceleration and the moment from Euler's equations, split
 * between the contacts with no squeeze along the edge, as the phase's
 * least-norm solve splits them (phase_forces.c). Sticking contacts do no
 * work, so the energy is constant up to the integration error. */
#include <math.h>
#include "contact/contact_pivot.h"
#include "base/quat.h"
#include "base/vec3.h"

int pd_pivot_init(pd_pivot *pv, const pd_phase *p, const pd_state *s0)
{
    if (p->nc != 2 || p->mode[0] != PD_PHASE_STICK || p->mode[1] != PD_PHASE_STICK)
        return 0;
    const pd_body *b = p->b;
    pd_vec3 r0 = quat_rotate(s0->q, p->r[0]), r1 = quat_rotate(s0->q, p->r[1]);
    pd_vec3 edge = v3_sub(r1, r0);
    double len = v3_norm(edge);
    if (!(len > 0.0))
        return 0;
    pv->p = p;
    pv->len = len;
    pv->p0 = v3_add(s0->x, r0);
    pv->e = v3_scale(edge, 1.0 / len);
    pv->eb = v3_scale(v3_sub(p->r[1], p->r[0]), 1.0 / len);
    pd_vec3 u = v3_neg(r0);
    pv->u_par = v3_scale(pv->e, v3_dot(u, pv->e));
    pv->u_perp = v3_sub(u, pv->u_par);
    pv->e_u = v3_cross(pv->e, pv->u_perp);
    pv->q0 = s0->q;
    pv->Ieb = v3(b->moment[0] * pv->eb.x, b->moment[1] * pv->eb.y, b->moment[2] * pv->eb.z);
    pv->gyro = v3_cross(pv->eb, pv->Ieb);
    pv->Ie = v3_dot(pv->eb, pv->Ieb) + b->mass * v3_dot(pv->u_perp, pv->u_perp);
    /* The centre's height over p0 is u_par.z + cos a u_perp.z + sin a e_u.z:
     * its torque is minus m g times the height's derivative. */
    double mg = b->mass * p->g;
    pv->k_sin = mg * pv->u_perp.z / pv->Ie;
    pv->k_cos = -mg * pv->e_u.z / pv->Ie;
    return 1;
}

double pd_pivot_rate_of(const pd_pivot *pv, const pd_state *s)
{
    /* The angular momentum about the axis over the moment about it: the
     * body's own (I w along eb, body frame) and the centre's orbit
     * (u x m v, u the arm from the axis). */
    pd_vec3 u = v3_add(pv->u_par, pv->u_perp);
    double orbit = pv->p->b->mass * v3_dot(pv->e, v3_cross(u, s->v));
    return (v3_dot(pv->Ieb, s->w) + orbit) / pv->Ie;
}

/* cos a and sin a from the half angle's, which the orientation needs too. */
static void turn(double a, double *ch, double *sh, double *c, double *s)
{
    *ch = cos(0.5 * a), *sh = sin(0.5 * a);
    *c = 1.0 - 2.0 * *sh * *sh;
    *s = 2.0 * *sh * *ch;
}

double pd_pivot_accel(const pd_pivot *pv, double a)
{
    double ch, sh, c, s;
    turn(a, &ch, &sh, &c, &s);
    return pv->k_sin * s + pv->k_cos * c;
}

double pd_pivot_state(const pd_pivot *pv, double a, double w, pd_state *st, pd_phase_forces *F)
{
    const pd_phase *p = pv->p;
    const pd_body *b = p->b;
    double ch, sh, c, s;
    turn(a, &ch, &sh, &c, &s);
    double alpha = pv->k_sin * s + pv->k_cos * c;
    pd_vec3 arm = v3_add(v3_scale(pv->u_perp, c), v3_scale(pv->e_u, s)); /* across the axis */
    pd_vec3 d = v3_add(pv->u_par, arm);
    pd_vec3 across = v3_cross(pv->e, arm);                                /* e x arm */
    st->x = v3_add(pv->p0, d);
    st->q = quat_normalize(quat_mul(quat(ch, sh * pv->e.x, sh * pv->e.y, sh * pv->e.z), pv->q0));
    st->v = v3_scale(across, w);
    st->w = v3_scale(pv->eb, w);
    pd_vec3 acc = v3_sub(v3_scale(across, alpha), v3_scale(arm, w * w));
    /* Contact forces f0 + f1 = m (acc + g z) and, about the centre,
     * r0 x f0 + r1 x f1 = R (I wdot + w x I w): f1 eliminated, the edge D
     * crossed with f0 is given, which fixes f0 across the edge, and no
     * squeeze shares the force along it equally. */
    pd_vec3 sum = v3_scale(v3(acc.x, acc.y, acc.z + p->g), b->mass);
    pd_vec3 torque = quat_rotate(st->q, v3_add(v3_scale(pv->Ieb, alpha), v3_scale(pv->gyro, w * w)));
    pd_vec3 r1 = v3_sub(v3_scale(pv->e, pv->len), d);
    pd_vec3 cvec = v3_sub(torque, v3_cross(r1, sum));
    pd_vec3 f[2];
    f[0] = v3_add(v3_scale(v3_cross(pv->e, cvec), 1.0 / pv->len),
                  v3_scale(pv->e, 0.5 * v3_dot(sum, pv->e)));
    f[1] = v3_sub(sum, f[0]);
    F->acc = acc;
    F->wdot = v3_scale(pv->eb, alpha);
    for (int j = 0; j < 2; j++) {
        F->fn[j] = f[j].z;
        F->cone[j] = p->mu * f[j].z - sqrt(f[j].x * f[j].x + f[j].y * f[j].y);
        F->slip[j] = 0.0; /* on the axis */
    }
    return alpha;
}
