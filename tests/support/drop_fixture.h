/* drop_fixture.h: a part with its pose table, drop model and work area, for
 * tests that call the drop simulator's internals (drop.h) directly. */
#ifndef PD_TEST_DROP_FIXTURE_H
#define PD_TEST_DROP_FIXTURE_H

#include "sim/drop.h"
#include "posedrop/posedrop.h"

typedef struct {
    pd_part *part;
    pd_static_result *poses;
    pd_sim_model *model;
    pd_drop_work *work;
} drop_fixture;

/* Builds everything from mesh (consumed) for scene sc; counts a check and
 * returns 0 if any step fails. */
int drop_setup(drop_fixture *fx, pd_mesh *mesh, const pd_scene *sc);
void drop_teardown(drop_fixture *fx);

/* The fixture of the 1 x 2 x 3 cm box in the default scene with friction mu
 * (sc is filled in); its body, or NULL (a check counted) on failure. */
const pd_body *drop_setup_box(drop_fixture *fx, pd_scene *sc, double mu);

/* The body vertices within 1e-12 of the lowest with the body turned by q. */
int lowest_vertices(const pd_body *b, pd_quat q, int *out);

double kinetic_energy(const pd_body *b, const pd_state *s);

/* The shortest turn taking unit vector n onto the world's down, -z (a half
 * turn about x when n is up). */
pd_quat quat_onto_down(pd_vec3 n);

/* Kinetic plus potential energy under gravity g, J. */
double total_energy(const pd_body *b, double g, const pd_state *s);

/* The largest differences between pairs of states of one body, in its
 * units: position per L, velocity per sqrt(g L), quaternion components,
 * rate of turn per 1/sqrt(L/g), energy (gravity g) per m g L. */
typedef struct {
    double x, v, q, w, E;
} state_gap;

void state_gap_add(state_gap *gap, const pd_body *b, double g, const pd_state *a,
                   const pd_state *r);

/* Checks every component of gap against tol (the same tolerance in each
 * unit: the callers' sources are errors relative to the part's scales). */
void state_gap_check(const state_gap *gap, double tol);

#endif
