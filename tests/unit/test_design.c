/* test_design.c: the exact QS/PQS sensitivities against closed forms and
 * central differences, the changes' geometry, the drops' paired
 * differences, and the design run against an independently built part. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "check.h"
#include "cli_run.h"
#include "posedrop/design.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "static/tangent.h"
#include "suites.h"

/* A stepped solid of revolution about z, an n-gon in section: a flange of
 * radius r1 from z = 0 to t1 and a body of radius r2 < r1 up to t1 + t2. */
static pd_mesh *mesh_stepped(int n, double r1, double t1, double r2, double t2)
{
    pd_mesh *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->nverts = 4 * n + 2;
    m->ntris = 8 * n;
    m->verts = malloc(sizeof *m->verts * (size_t)m->nverts);
    m->tris = malloc(sizeof *m->tris * (size_t)m->ntris);
    if (!m->verts || !m->tris) {
        pd_mesh_free(m);
        return NULL;
    }
    double z[4] = {0.0, t1, t1, t1 + t2}, r[4] = {r1, r1, r2, r2};
    for (int ring = 0; ring < 4; ring++)
        for (int i = 0; i < n; i++) {
            double a = 2.0 * M_PI * i / n;
            m->verts[ring * n + i] = (pd_vec3){r[ring] * cos(a), r[ring] * sin(a), z[ring]};
        }
    int bot = 4 * n, top = 4 * n + 1, t = 0;
    m->verts[bot] = (pd_vec3){0, 0, 0};
    m->verts[top] = (pd_vec3){0, 0, t1 + t2};
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        int tri[8][3] = {{bot, j, i},
                         {i, j, n + j}, {i, n + j, n + i},                 /* flange side */
                         {n + i, n + j, 2 * n + j}, {n + i, 2 * n + j, 2 * n + i}, /* shoulder */
                         {2 * n + i, 2 * n + j, 3 * n + j}, {2 * n + i, 3 * n + j, 3 * n + i},
                         {top, 3 * n + i, 3 * n + j}};
        for (int k = 0; k < 8; k++)
            memcpy(m->tris[t++], tri[k], sizeof tri[k]);
    }
    return m;
}

/* An address no failed call may write through: the result stays it. */
static char sentinel_byte;
#define SENTINEL_RESULT ((pd_design_result *)(void *)&sentinel_byte)

static pd_part *part_from(pd_mesh *m, const pd_vec3 *com)
{
    pd_part *p = NULL;
    pd_part_options o;
    pd_part_options_default(&o);
    if (com) {
        o.com_given = 1;
        o.com = *com;
    }
    if (m && pd_part_build(m, &o, &p, NULL) != PD_OK)
        p = NULL;
    pd_mesh_free(m);
    return p;
}

/* The solid angle's derivative against central differences of the
 * function itself: step 1e-6 of the corners' size, so truncation (h^2 ~
 * 1e-12) and round-off (1e-16 / h ~ 1e-10) both stay below the 1e-7
 * allowed. */
static void test_triangle_derivative(void)
{
    test_rng r = {7};
    double worst = 0.0;
    for (int trial = 0; trial < 200; trial++) {
        pd_vec3 a = rng_unit_vector(&r), b = rng_unit_vector(&r), c = rng_unit_vector(&r);
        pd_vec3 da = rng_unit_vector(&r), db = rng_unit_vector(&r), dc = rng_unit_vector(&r);
        double d, h = 1e-6;
        double w = pd_solid_angle_triangle_d(a, b, c, da, db, dc, &d);
        CHECK_NEAR(w, pd_solid_angle_triangle(a, b, c), 1e-15, "the same formula");
        pd_vec3 ap = {a.x + h * da.x, a.y + h * da.y, a.z + h * da.z};
        pd_vec3 bp = {b.x + h * db.x, b.y + h * db.y, b.z + h * db.z};
        pd_vec3 cp = {c.x + h * dc.x, c.y + h * dc.y, c.z + h * dc.z};
        pd_vec3 am = {a.x - h * da.x, a.y - h * da.y, a.z - h * da.z};
        pd_vec3 bm = {b.x - h * db.x, b.y - h * db.y, b.z - h * db.z};
        pd_vec3 cm = {c.x - h * dc.x, c.y - h * dc.y, c.z - h * dc.z};
        double wp = pd_solid_angle_triangle(ap, bp, cp), wm = pd_solid_angle_triangle(am, bm, cm);
        if (fabs(wp - wm) > M_PI)
            continue; /* the triangle passes through a half sphere: atan2 wraps */
        double fd = (wp - wm) / (2 * h);
        worst = fmax(worst, fabs(fd - d) / fmax(1.0, fabs(d)));
    }
    CHECK_NEAR(worst, 0.0, 1e-7, "central difference: h^2 truncation + eps/h round-off");
}

/* Checks every row of the part's sensitivities against central differences
 * of pd_static_estimate on parts built at value +- h (h = 1e-5 of a factor,
 * 1e-5 of the size for offsets): the error is h^2 p''' (~1e-10) plus
 * 1e-15 / h (1e-10), so 1e-6 per unit leaves a margin of 1e4; a kink
 * (a structure change within h) would show as an O(1) disagreement. */
static void check_against_differences(const pd_part *part, const pd_change *ch, int n,
                                      const char *what, int symmetric)
{
    pd_static_result *res = NULL;
    pd_design_sens *s = NULL;
    CHECK_STATUS(pd_static_estimate(part, NULL, &res, NULL), PD_OK);
    CHECK_STATUS(pd_design_sensitivity(part, res, NULL, ch, n, NULL, 0, NULL, NULL, &s, NULL),
                 PD_OK);
    if (!res || !s) {
        pd_static_result_free(res);
        pd_design_sens_free(s);
        return;
    }
    double worst = 0.0;
    int kinks = 0, pqs_kinks = 0;
    for (int k = 0; k < n; k++) {
        double value[PD_DESIGN_MAX_CHANGES];
        for (int j = 0; j < n; j++)
            value[j] = ch[j].kind == PD_CHANGE_SCALE ? 1.0 : 0.0;
        double h = ch[k].kind == PD_CHANGE_SCALE ? 1e-5 : 1e-5 * part->size;
        double pq[2][64] = {{0}}, pp[2][64] = {{0}};
        for (int side = 0; side < 2; side++) {
            value[k] = (ch[k].kind == PD_CHANGE_SCALE ? 1.0 : 0.0) + (side ? -h : h);
            pd_part *q = NULL;
            pd_static_result *qr = NULL;
            CHECK_STATUS(pd_design_apply(part, ch, n, value, &q, NULL), PD_OK);
            if (q)
                CHECK_STATUS(pd_static_estimate(q, NULL, &qr, NULL), PD_OK);
            /* Poses of q named by res's: the facet of the same normal's
             * neighbourhood (the changes here turn no facet by more than
             * h rad). */
            for (int j = 0; qr && j < qr->nposes; j++)
                for (int i = 0; i < res->nposes && i < 64; i++) {
                    pd_vec3 a = qr->poses[j].normal, b = res->poses[i].normal;
                    if (a.x * b.x + a.y * b.y + a.z * b.z > 1.0 - 1e-6) {
                        pq[side][i] += qr->poses[j].p_qs;
                        pp[side][i] += qr->poses[j].p_pqs;
                    }
                }
            pd_static_result_free(qr);
            pd_part_free(q);
        }
        for (int i = 0; i < res->nposes && i < 64; i++) {
            const pd_design_sens_row *row = &s->rows[i * n + k];
            double fq = (pq[0][i] - pq[1][i]) / (2 * h), fp = (pp[0][i] - pp[1][i]) / (2 * h);
            double scale = ch[k].kind == PD_CHANGE_SCALE ? 1.0 : 1.0 / part->size;
            kinks += row->qs_kink;
            pqs_kinks += row->pqs_kink;
            worst = fmax(worst, fmax(fabs(fq - row->d_qs), fabs(fp - row->d_pqs)) / scale);
        }
    }
    pd_note("design: %s: worst |exact - central difference| %.3g per unit, %d QS kinks, %d PQS "
            "kinks\n", what, worst, kinks, pqs_kinks);
    CHECK_NEAR(worst, 0.0, 1e-6, "central difference, h = 1e-5: h^2 p''' + 1e-15/h");
    /* No QS kink on these parts; PQS ties (relative 1e-4) between
     * symmetric facets break at a step of 1e-4 when a change breaks the
     * symmetry, and only then: a step of 1e-5 stays within the tie. */
    CHECK_INT(kinks, 0);
    CHECK(symmetric ? pqs_kinks > 0 : pqs_kinks == 0);
    pd_design_sens_free(s);
    pd_static_result_free(res);
}

static void test_static_sensitivities(void)
{
    pd_change all[6] = {{PD_CHANGE_SCALE, 0, 0, 0, 0, 0.5, 2}, {PD_CHANGE_SCALE, 1, 0, 0, 0, 0.5, 2},
                        {PD_CHANGE_SCALE, 2, 0, 0, 0, 0.5, 2}, {PD_CHANGE_COM, 0, 0, 0, 0, -1, 1},
                        {PD_CHANGE_COM, 1, 0, 0, 0, -1, 1}, {PD_CHANGE_COM, 2, 0, 0, 0, -1, 1}};
    /* A box of three different sides: every facet stable, PQS bands on
     * every edge. */
    pd_part *box = part_from(mesh_box(1.0, 1.3, 1.7), NULL);
    CHECK(box != NULL);
    if (box)
        check_against_differences(box, all, 6, "box 1 x 1.3 x 1.7", 0);
    /* Loaded off every axis: the centre of mass given off the middle. */
    pd_vec3 com = {0.11, -0.07, 0.13};
    pd_part *loaded = part_from(mesh_box(1.0, 1.3, 1.7), &com);
    if (loaded)
        check_against_differences(loaded, all, 6, "loaded box", 0);
    /* A hexagonal prism: facets of six corners, unstable facets toppling
     * into stable ones (the tall prism's caps). */
    pd_part *prism = part_from(mesh_prism(6, 0.5, 2.5), NULL);
    if (prism)
        check_against_differences(prism, all, 6, "tall hexagonal prism", 1);
    /* The bushing: its flange and its body stretched apart (slabs cut
     * at the shoulder), with a 12-gon section. */
    pd_part *bush = part_from(mesh_stepped(12, 10e-3, 3e-3, 6e-3, 15e-3), NULL);
    pd_change slabs[3] = {{PD_CHANGE_SCALE, 2, 1, 0.0, 3e-3, 0.7, 1.5},
                          {PD_CHANGE_SCALE, 2, 1, 3e-3, 18e-3, 0.7, 1.5},
                          {PD_CHANGE_COM, 0, 0, 0, 0, -1e-3, 1e-3}};
    CHECK(bush != NULL);
    if (bush)
        check_against_differences(bush, slabs, 3, "bushing slabs", 1);
    pd_part_free(box);
    pd_part_free(loaded);
    pd_part_free(prism);
    pd_part_free(bush);
}

/* A cube of edge a, its static estimate and its sensitivities to ch (with
 * drops when so is given); 0 and everything NULL on failure. */
static int cube_sens(double a, const pd_change *ch, int n, const pd_sim_options *so,
                     pd_part **cube, pd_static_result **res, pd_design_sens **s)
{
    *res = NULL;
    *s = NULL;
    *cube = part_from(mesh_box(a, a, a), NULL);
    if (*cube)
        CHECK_STATUS(pd_static_estimate(*cube, NULL, res, NULL), PD_OK);
    if (*res)
        CHECK_STATUS(pd_design_sensitivity(*cube, *res, NULL, ch, n, NULL, 0, NULL, so, s, NULL),
                     PD_OK);
    return *s != NULL;
}

/* Closed forms on a cube of edge a: its bottom face is a square seen from
 * height h = a/2, solid angle 4 asin(1 / (1 + 4 h^2 / a^2)); every face
 * stable, so p_qs(-z) is that over 4 pi, and
 *   d p / d h = -(1/pi) (1 / sqrt(1 - x^2)) 8 (h/a^2) / (1 + 4h^2/a^2)^2,
 * x = 1/2 at h = a/2: -(2/(pi a)) / sqrt(3) ... = -0.36755 / a.
 * Moving the centre of mass up by d raises h by d; stretching z by s
 * raises it by a/2 per unit of s. */
static void test_closed_forms(void)
{
    double a = 0.02;
    pd_part *cube;
    pd_static_result *res;
    pd_design_sens *s;
    pd_change ch[2] = {{PD_CHANGE_COM, 2, 0, 0, 0, -1, 1}, {PD_CHANGE_SCALE, 2, 0, 0, 0, 0.5, 2}};
    if (cube_sens(a, ch, 2, NULL, &cube, &res, &s)) {
        double dpdh = -(1.0 / M_PI) * (1.0 / sqrt(1.0 - 0.25)) * 8.0 * (0.5 / a) / 4.0;
        int bottom = -1;
        for (int i = 0; i < res->nposes; i++)
            if (res->poses[i].normal.z < -0.5)
                bottom = i;
        CHECK(bottom >= 0);
        if (bottom >= 0) {
            CHECK_REL(s->rows[bottom * 2 + 0].d_qs, dpdh, 1e-12, "closed form, round-off");
            CHECK_REL(s->rows[bottom * 2 + 1].d_qs, dpdh * a / 2, 1e-12, "closed form, round-off");
        }
        /* Probabilities sum to 1 whatever the change: derivatives to 0. */
        for (int k = 0; k < 2; k++) {
            double sq = 0.0, sp = 0.0;
            for (int i = 0; i < res->nposes; i++) {
                sq += s->rows[i * 2 + k].d_qs;
                sp += s->rows[i * 2 + k].d_pqs;
            }
            CHECK_NEAR(sq, 0.0, 1e-12 / a, "conservation of probability, round-off");
            CHECK_NEAR(sp, 0.0, 1e-12 / a, "conservation of probability, round-off");
        }
    }
    /* The stretched part is the box it should be: volume s V exactly to
     * round-off, centre of mass where it was. */
    double v = 1.7;
    pd_part *q = NULL;
    if (cube)
        CHECK_STATUS(pd_design_apply(cube, ch + 1, 1, &v, &q, NULL), PD_OK);
    if (q) {
        CHECK_REL(q->mass.volume, 1.7 * a * a * a, 1e-13, "affine map of a box, round-off");
        CHECK_NEAR(q->com.z + q->origin.z, cube->com.z + cube->origin.z, 1e-15, "anchor");
    }
    /* An offset that leaves the part is refused. */
    pd_part *bad = NULL;
    double far = a;
    CHECK(pd_design_apply(cube, ch, 1, &far, &bad, NULL) != PD_OK && bad == NULL);
    pd_part_free(q);
    pd_design_sens_free(s);
    pd_static_result_free(res);
    pd_part_free(cube);
}

/* The drops' paired differences: the probabilities' derivatives sum to 0
 * exactly when every drop settles, and lowering a cube's centre of mass
 * toward its bottom face raises that face (QS: 0.368 / a per m; the
 * interval of 1500 paired drops is about +-0.2 of it). */
static void test_drop_differences(void)
{
    double a = 0.01;
    pd_part *cube;
    pd_static_result *res;
    pd_design_sens *s;
    pd_change ch = {PD_CHANGE_COM, 2, 0, 0, 0, -1, 1};
    pd_sim_options so;
    pd_sim_options_default(&so);
    so.ndrops = 1500;
    so.threads = 1;
    if (cube_sens(a, &ch, 1, &so, &cube, &res, &s)) {
        double sum = 0.0;
        int bottom = -1;
        for (int i = 0; i < res->nposes; i++) {
            sum += s->rows[i].d_p;
            if (res->poses[i].normal.z < -0.5)
                bottom = i;
            CHECK(s->rows[i].lo <= s->rows[i].d_p && s->rows[i].d_p <= s->rows[i].hi);
        }
        CHECK_NEAR(sum, 0.0, 1e-9 / a, "every drop settles in some pose: round-off");
        if (bottom >= 0) {
            pd_note("design: cube com_z: d p(-z) drops %.4g [%.4g, %.4g] /m, QS %.4g\n", s->rows[bottom].d_p,
                    s->rows[bottom].lo, s->rows[bottom].hi, s->rows[bottom].d_qs);
            CHECK(s->rows[bottom].hi < 0.0);
        }
    }
    pd_design_sens_free(s);
    pd_static_result_free(res);
    pd_part_free(cube);
}


/* The static design against parts built independently at its answer: a
 * target met to the least-squares solver's precision (objective 1e-20,
 * residuals 1e-10; 1e-8 allowed), an equalisation whose answer is known in
 * closed form (the six faces of a box equally likely: a cube), a maximum
 * on a range's bound. */
static pd_design_options static_only(pd_design_model model)
{
    pd_design_options o;
    pd_design_options_default(&o);
    o.model = model;
    o.sim.ndrops = 0;
    o.check_drops = 0;
    return o;
}

static void test_static_design(void)
{
    double a = 0.01;
    pd_part *cube = part_from(mesh_box(a, a, a), NULL);
    pd_change ch = {PD_CHANGE_SCALE, 2, 0, 0, 0, 0.1, 3.0};
    pd_design_target t[6] = {{{0, 0, 1}, 1.0 / 3}, {{0, 0, -1}, 1.0 / 3}, {{1, 0, 0}, 1.0 / 12},
                             {{-1, 0, 0}, 1.0 / 12}, {{0, 1, 0}, 1.0 / 12}, {{0, -1, 0}, 1.0 / 12}};
    for (int model = 0; model < 2 && cube; model++) {
        pd_design_options o = static_only((pd_design_model)model);
        pd_design_result *r = NULL;
        CHECK_STATUS(pd_design_run(cube, &ch, 1, PD_GOAL_TARGET, t, 6, &o, &r, NULL), PD_OK);
        if (!r)
            continue;
        pd_part *box = part_from(mesh_box(a, a, a * r->value[0]), NULL);
        pd_static_result *res = NULL;
        if (box)
            CHECK_STATUS(pd_static_estimate(box, NULL, &res, NULL), PD_OK);
        for (int i = 0; res && i < res->nposes; i++)
            if (fabs(res->poses[i].normal.z) > 0.5)
                CHECK_NEAR(model ? res->poses[i].p_pqs : res->poses[i].p_qs, 1.0 / 3, 1e-8,
                           "least squares converged: residual ~1e-10");
        CHECK_NEAR(r->targets[0].pqs_after, model ? 1.0 / 3 : r->targets[0].pqs_after, 1e-8,
                   "the model searched meets the target");
        CHECK(r->value[0] < 1.0 && r->targets[0].vanished == 0 && r->poses_after == 6);
        pd_note("design: three-sided die, %s: scale_z %.6f, %d static evaluations\n",
                model ? "PQS" : "QS", r->value[0], r->static_evals);
        pd_static_result_free(res);
        pd_part_free(box);
        pd_design_result_free(r);
    }
    /* Equalise a 1 x 1.3 x 1.7 box's six faces by stretching y and z: a
     * cube, y by 1/1.3 and z by 1/1.7. */
    pd_part *box = part_from(mesh_box(a, 1.3 * a, 1.7 * a), NULL);
    pd_change yz[2] = {{PD_CHANGE_SCALE, 1, 0, 0, 0, 0.3, 2.0}, {PD_CHANGE_SCALE, 2, 0, 0, 0, 0.3, 2.0}};
    pd_design_options o = static_only(PD_DESIGN_QS);
    pd_design_result *r = NULL;
    if (box)
        CHECK_STATUS(pd_design_run(box, yz, 2, PD_GOAL_EQUALISE, t, 6, &o, &r, NULL), PD_OK);
    if (r) {
        CHECK_NEAR(r->value[0], 1.0 / 1.3, 1e-6, "closed form (a cube); solver's precision");
        CHECK_NEAR(r->value[1], 1.0 / 1.7, 1e-6, "closed form (a cube); solver's precision");
        CHECK_NEAR(r->targets[5].qs_after, 1.0 / 6, 1e-9, "a cube's faces");
    }
    pd_design_result_free(r);
    /* The bottom face's share grows as the centre of mass sinks toward it:
     * the maximum lies at the range's lower end. */
    pd_change low = {PD_CHANGE_COM, 2, 0, 0, 0, -0.3 * a, 0.2 * a};
    r = NULL;
    if (cube)
        CHECK_STATUS(pd_design_run(cube, &low, 1, PD_GOAL_MAXIMISE, t + 1, 1, &o, &r, NULL),
                     PD_OK);
    if (r) {
        CHECK_NEAR(r->value[0], -0.3 * a, 1e-12 * a, "a monotone share: the range's bound");
        CHECK(r->targets[0].qs_after > r->targets[0].qs_before);
    }
    pd_design_result_free(r);
    /* A normal no facet has, and two targets of one facet, are refused. */
    pd_design_target bad[2] = {{{1, 1, 0}, 0.5}, {{0, 0, 1}, 0.5}};
    r = SENTINEL_RESULT;
    CHECK_STATUS(pd_design_run(cube, &ch, 1, PD_GOAL_TARGET, bad, 1, &o, &r, NULL), PD_ERR_USAGE);
    pd_design_target twice[2] = {{{0, 0, 1}, 0.5}, {{0, 0.01, 1}, 0.5}};
    CHECK_STATUS(pd_design_run(cube, &ch, 1, PD_GOAL_TARGET, twice, 2, &o, &r, NULL),
                 PD_ERR_USAGE);
    CHECK(r == SENTINEL_RESULT);
    pd_part_free(box);
    pd_part_free(cube);
}

/* Drops: a short refinement and check whose numbers hang together (the
 * fresh estimate inside its interval, every drop counted). */
static void test_drop_design(void)
{
    double a = 0.01;
    pd_part *cube = part_from(mesh_box(a, a, a), NULL);
    pd_change ch = {PD_CHANGE_SCALE, 2, 0, 0, 0, 0.1, 3.0};
    pd_design_target t[2] = {{{0, 0, 1}, 2.0 / 3}, {{1, 0, 0}, 1.0 / 3}};
    pd_design_options o;
    pd_design_options_default(&o);
    o.group = 1;
    o.sim.ndrops = 300;
    o.sim.threads = 1;
    o.max_evals = 3;
    o.check_drops = 300;
    pd_design_result *r = NULL;
    if (cube)
        CHECK_STATUS(pd_design_run(cube, &ch, 1, PD_GOAL_TARGET, t, 2, &o, &r, NULL), PD_OK);
    if (r) {
        CHECK(r->drop_evals >= 1 && r->drop_evals <= 3);
        CHECK_INT(r->drops, 300L * (r->drop_evals + 1));
        for (int i = 0; i < 2; i++)
            CHECK(r->targets[i].lo <= r->targets[i].p_after &&
                  r->targets[i].p_after <= r->targets[i].hi);
        /* Grouped: the caps are one class, the four sides another. */
        CHECK_NEAR(r->targets[0].pqs_after + r->targets[1].pqs_after, 1.0, 1e-12,
                   "two classes hold every pose");
    }
    pd_design_result_free(r);
    /* Cancelled before the first drop: the static answer comes back, marked
     * partial and unchecked. */
    pd_cancel_flag stop = 1;
    o.sim.cancel = &stop;
    r = NULL;
    if (cube)
        CHECK_STATUS(pd_design_run(cube, &ch, 1, PD_GOAL_TARGET, t, 2, &o, &r, NULL), PD_OK);
    if (r) {
        CHECK_INT(r->partial, 1);
        CHECK_INT(r->drop_evals, 1);
        CHECK(r->targets[0].p_after == 0.0 && r->value[0] == r->value_static[0]);
    }
    pd_design_result_free(r);
    pd_part_free(cube);
}

/* The command: a design written and read back, and bad input refused with
 * file and line. */
static void test_command(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/posedrop-design-XXXXXX");
    if (!mkdtemp(tmpdir)) {
        CHECK(!"no scratch directory");
        return;
    }
    char target[160], off[160], sens[160], cmd[1024], *out = NULL, *err = NULL;
    snprintf(target, sizeof target, "%s/t.csv", tmpdir);
    snprintf(off, sizeof off, "%s/d.off", tmpdir);
    snprintf(sens, sizeof sens, "%s/s.csv", tmpdir);
    write_file(target, "nx,ny,nz,p\n0,0,1,0.6666666667\n1,0,0,0.3333333333\n");
    snprintf(cmd, sizeof cmd, "design --group --vary scale_z=0.1:3 --target %s -n 0 --check 0 "
             "--out %s --sensitivity %s --sensitivity-drops 0 parts/canonical/cube.off", target,
             off, sens);
    CHECK_INT(run(cmd, &out, &err), 0);
    CHECK(out && strncmp(out, "pose,nx,ny,nz,p_target,", 23) == 0 && !strstr(out, "nan"));
    CHECK(err && strstr(err, "scale_z = ") && strstr(err, "shortened"));
    char *s = slurp(sens);
    const char *head = "pose,nx,ny,nz,parameter,d_p_qs,d_p_pqs,d_p,ci_lo,ci_hi,";
    CHECK(s && strncmp(s, head, strlen(head)) == 0);
    free(s);
    free(out);
    free(err);
    /* The written part, estimated by the plain command: PQS meets the
     * target (caps 2/3, sides 1/3). */
    snprintf(cmd, sizeof cmd, "--group %s", off);
    CHECK_INT(run(cmd, &out, &err), 0);
    CHECK(out && strstr(out, ",0.6666666") && strstr(out, ",0.3333333"));
    free(out);
    free(err);
    /* With classes, naming the two caps of the box apart asks one class's
     * probability twice. */
    write_file(target, "nx,ny,nz,p\n0,0,1,0.3\n0,0,-1,0.3\n");
    snprintf(cmd, sizeof cmd, "design --group --vary scale_z=0.1:3 --target %s -n 0 --check 0 "
             "--out %s parts/canonical/cube.off", target, off);
    expect_failure(cmd, 2, "name one pose class");
    write_file(target, "nx,ny,nz,p\n0,0,1,0.5\n0,0,x,0.5\n");
    snprintf(cmd, sizeof cmd, "design --vary scale_z=0.1:3 --target %s --out %s "
             "parts/canonical/cube.off", target, off);
    expect_failure(cmd, 2, "t.csv:3: column nz");
    expect_failure("design --vary scale_q=1:2 --target x.csv --out y.off parts/canonical/cube.off",
                   2, "unknown change");
    expect_failure("design --vary scale_z=2:1 --sensitivity y.csv parts/canonical/cube.off", 2,
                   "LO < HI");
    expect_failure("design --vary scale_z=0.5:2 parts/canonical/cube.off", 2, "give a goal");
    snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
    if (system(cmd) != 0)
        printf("     could not remove %s\n", tmpdir);
}

void suite_design(void)
{
    test_command();
    test_static_design();
    test_drop_design();
    test_triangle_derivative();
    test_closed_forms();
    test_static_sensitivities();
    test_drop_differences();
}
