/* compliant_law.h (private): the normal law of one compliant contact.
 *
 * A contact of penetration d >= 0 pushes with the linear Hunt-Crossley force
 *     F = max(0, k d (1 + chi d' / v0)),
 * k the contact's stiffness, v0 its approach speed when it touched and chi a
 * damping ratio. Why this law and not a linear spring-dashpot: its force
 * starts and ends at zero (a dashpot's jumps to c v0 at touch and pulls the
 * part down at the end), and scaled by its own units (d by v0 / omega, time
 * by 1 / omega, omega^2 = k / m) it becomes
 *     s'' = -max(0, s (1 + chi s')),   s(0) = 0, s'(0) = 1,
 * with no parameter but chi: the restitution e (rebound speed over approach
 * speed) depends on chi alone, so one chi gives the scene's e at every
 * approach speed, and the contact lasts tau(chi) / omega whatever v0 is.
 * The law is the pair (e, T) a user states: chi from e, then omega from the
 * duration T of one contact, omega = tau / T, and k = m omega^2 for each
 * contact's effective mass m. */
#ifndef PD_COMPLIANT_LAW_H
#define PD_COMPLIANT_LAW_H

#include "contact/contact_tol.h"
#include "posedrop/status.h"

typedef struct pd_compliant_law {
    double e;       /* restitution the law gives (the scene's, at least PD_COMPLIANT_E_MIN) */
    double T;       /* s: duration of one contact */
    double chi;     /* damping ratio of the scaled law */
    double tau;     /* duration of one contact in scaled time */
    double s_peak;  /* the deepest scaled penetration (at step ends: an estimate) */
    double step;    /* the step with one contact in scaled time (omega h):
                       pd_compliant_law_step's */
    double omega;   /* rad/s: tau / T; k = m omega^2 */
} pd_compliant_law;

/* The law for restitution e in [0, 1] and contact duration T > 0 (s):
 * chi by regula falsi on e(chi) (compliant_law.c), tau by integrating the scaled law to
 * PD_COMPLIANT_LAW_TOL. PD_ERR_RANGE for e or T outside their ranges,
 * PD_ERR_NO_CONVERGENCE, PD_ERR_NOMEM. */
pd_status pd_compliant_law_init(double e, double T, pd_compliant_law *law);

/* One contact of the scaled law with damping ratio chi >= 0: its
 * restitution *e, duration *tau (scaled time) and deepest penetration
 * *s_peak (at the integrator's step ends). Integrated by GSL's rk8pd
 * to relative error tol, the end located on s = 0 exactly by a step in s
 * (Henon's trick). PD_ERR_NO_CONVERGENCE, PD_ERR_NOMEM. */
pd_status pd_compliant_law_contact(double chi, double tol, double *e, double *tau,
                                   double *s_peak);

/* The step of compliant.c's integration (semi-implicit Euler: the force
 * from the penetration and its rate at the step's start, then the position
 * from the new velocity) for the scaled law with damping ratio chi, in
 * scaled time: the shortest at which, going up from steps far inside it,
 * the rebound leaves PD_COMPLIANT_E_TOL of the law's own restitution e
 * (the worst of PD_COMPLIANT_STEP_PHASES touches spread evenly over a
 * step), found to PD_COMPLIANT_STEP_REL, and at most PD_COMPLIANT_STEP_MAX
 * over the law's fastest rate (1 + chi s_peak). PD_ERR_NO_CONVERGENCE if
 * even PD_COMPLIANT_STEP_TRIES halvings do not meet it. */
pd_status pd_compliant_law_step(double chi, double e, double s_peak, double *step);

/* 1 if the scaled step h rebounds within PD_COMPLIANT_E_TOL of e from
 * every touch pd_compliant_law_step tries. */
int pd_compliant_law_step_meets(double chi, double e, double h);

/* The laws for the restitutions of a range [e_lo, e_hi], for runs whose
 * restitution each drop draws (a law costs about 2M instructions, a drop of a small part
 * less): exact at PD_COMPLIANT_TABLE_NODES restitutions evenly spaced in
 * log e, cubic interpolation between them. */
enum { PD_COMPLIANT_TABLE_NODES = 65 };
typedef struct pd_compliant_table {
    int n;          /* nodes (1 when the range is one restitution) */
    pd_compliant_law one; /* n == 1: the exact law, for T = 1 */
    double x_lo, dx; /* log of the lowest restitution, the nodes' step in log e */
    double y[4][PD_COMPLIANT_TABLE_NODES]; /* chi e / (1 - e), log tau, s_peak and log step
                                              at the nodes */
} pd_compliant_table;

pd_status pd_compliant_table_init(double e_lo, double e_hi, pd_compliant_table *table);

/* The law for restitution e in the table's range and duration T > 0. */
void pd_compliant_table_law(const pd_compliant_table *table, double e, double T,
                            pd_compliant_law *law);

#endif
