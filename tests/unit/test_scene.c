/* test_scene.c: scene defaults, settings by name, scene files, ranges and
 * their draws. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "posedrop/sim.h"
#include "shapes.h"
#include "suites.h"

/* The automatic contact time of a box a x b x c (m). */
static double box_contact_time(double a, double b, double c)
{
    pd_mesh *m = mesh_box(a, b, c);
    pd_part *p = NULL;
    CHECK_STATUS(pd_part_build(m, NULL, &p, NULL), PD_OK);
    pd_mesh_free(m);
    double t = p ? pd_contact_time_auto_part(p) : 0.0;
    pd_part_free(p);
    return t;
}

/* Hertz's (m^2 / R)^(1/5), the mass from the volume, R in proportion to the
 * size: a cube's is the size's; similar parts' in proportion; a needle's from
 * its volume, not its length (a 1 m needle 1 mm thick: 5e-4 (1.73 cm /
 * 1 m)^(1/5) = 2.2e-4 s, where its length alone gave 29 ms). */
static void contact_time_of_parts(void)
{
    CHECK_REL(box_contact_time(0.01, 0.01, 0.01), 5e-4, 1e-14, "round-off");
    CHECK_REL(box_contact_time(3.0, 3.0, 3.0), pd_contact_time_auto(3.0 * sqrt(3.0)), 1e-14,
              "round-off");
    /* Below the cap on the static sink (sizes under 1.2 m). */
    CHECK_REL(box_contact_time(0.1, 0.2, 0.3), 10.0 * box_contact_time(0.01, 0.02, 0.03), 1e-14,
              "round-off");
    double L = sqrt(1.0 + 2e-6);
    CHECK_REL(box_contact_time(1.0, 1e-3, 1e-3), 5e-4 * pow(0.01 * sqrt(3.0) / L, 0.2), 1e-14,
              "round-off");
}

/* The Kolmogorov-Smirnov statistic of the n draws of parameter `param`
 * against the range's own distribution (pd_scene_quantile is its cdf). */
static double ks_statistic(const pd_scene *s, pd_scene_param param, double size, int n)
{
    double *q = malloc(sizeof *q * (size_t)n);
    if (!q)
        return 1.0;
    for (int i = 0; i < n; i++) {
        double v[PD_NPARAMS];
        pd_scene_draw(s, size, 7, i, v, NULL);
        q[i] = pd_scene_quantile(s, param, size, v[param]);
    }
    /* Insertion sort would be n^2; a counting pass over a fine grid of the
     * cdf bounds D to within the grid's step, 1e-5 here. */
    enum { GRID = 100000 };
    int *count = calloc(GRID + 1, sizeof *count);
    double d = 1.0;
    if (count) {
        for (int i = 0; i < n; i++)
            count[(int)(q[i] * GRID)]++;
        long below = 0;
        d = 0.0;
        for (int g = 0; g <= GRID; g++) {
            below += count[g];
            d = fmax(d, fabs((double)below / n - (double)(g + 1) / GRID));
        }
    }
    free(count);
    free(q);
    return d;
}

static void test_ranges(void)
{
    pd_scene s, before;
    pd_diag d;
    pd_diag_init(&d);
    pd_scene_default(&s);
    CHECK(!pd_scene_ranged(&s));
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.2:0.5", &d), PD_OK);
    CHECK(s.range[PD_PARAM_MU].kind == PD_DIST_UNIFORM && s.range[PD_PARAM_MU].lo == 0.2 &&
          s.range[PD_PARAM_MU].hi == 0.5 && pd_scene_ranged(&s));
    CHECK(s.mu == 0.3); /* the value stays for when the range goes */
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.4", &d), PD_OK);
    CHECK(s.range[PD_PARAM_MU].kind == PD_DIST_FIXED && s.mu == 0.4 && !pd_scene_ranged(&s));
    /* contact_time spans decades: log uniform unless told; multiples of auto. */
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "1e-4:1e-3", &d), PD_OK);
    CHECK(s.range[PD_PARAM_CONTACT_TIME].kind == PD_DIST_LOG_UNIFORM &&
          !s.range[PD_PARAM_CONTACT_TIME].auto_multiple);
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "1e-4:1e-3 uniform", &d), PD_OK);
    CHECK(s.range[PD_PARAM_CONTACT_TIME].kind == PD_DIST_UNIFORM);
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "0.3x:3x", &d), PD_OK);
    CHECK(s.range[PD_PARAM_CONTACT_TIME].kind == PD_DIST_LOG_UNIFORM &&
          s.range[PD_PARAM_CONTACT_TIME].auto_multiple == 1 &&
          s.range[PD_PARAM_CONTACT_TIME].lo == 0.3 && s.range[PD_PARAM_CONTACT_TIME].hi == 3.0);
    /* One multiple alone: the zero-width range, each drop 3 times its part's
     * auto (exact: a log-uniform draw over [3, 3] is 3), formatted back as
     * given. */
    pd_scene m = s;
    CHECK_STATUS(pd_scene_set(&m, "contact_time", "3x", &d), PD_OK);
    CHECK(m.range[PD_PARAM_CONTACT_TIME].auto_multiple == 1 &&
          m.range[PD_PARAM_CONTACT_TIME].lo == 3.0 && m.range[PD_PARAM_CONTACT_TIME].hi == 3.0);
    double mv[PD_NPARAMS];
    pd_scene_draw(&m, 0.01, 1, 7, mv, NULL);
    CHECK_REL(mv[PD_PARAM_CONTACT_TIME], 3.0 * pd_contact_time_auto(0.01), 1e-15, "round-off");
    char mt[64];
    CHECK(strcmp(pd_scene_format(&m, PD_PARAM_CONTACT_TIME, mt, sizeof mt), "3x") == 0);
    CHECK_STATUS(pd_scene_set(&m, "contact_time", "3000x", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&m, "mu", "3x", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "restitution", "0.1:0.5:log", &d), PD_OK);
    CHECK(s.range[PD_PARAM_RESTITUTION].kind == PD_DIST_LOG_UNIFORM);
    CHECK_STATUS(pd_scene_set(&s, "vibration", "0:3", &d), PD_OK);
    CHECK_NEAR(s.range[PD_PARAM_VIBRATION].hi, 3 * M_PI / 180, 1e-17, "degrees to radians");
    CHECK_STATUS(pd_scene_set(&s, "tumble", "5", &d), PD_OK);
    CHECK(s.tumble == 5.0);
    CHECK_STATUS(pd_scene_check(&s, &d), PD_OK);
    /* Refused, with the scene unchanged: an end out of range, ends in the
     * wrong order, a log range from 0, a range for gravity, multiples of
     * auto for anything but contact_time or on one end only, an unknown
     * kind. */
    before = s;
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.2:11", &d), PD_ERR_RANGE);
    CHECK(strstr(d.message, "from 0 to 10") != NULL);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.5:0.2", &d), PD_ERR_RANGE);
    CHECK(strstr(d.message, "low end is above") != NULL);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0:0.5 log", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&s, "gravity", "9:10", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.3x:3x", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "0.3x:3e-4", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "0.3x:3000x", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.2:0.5 normal", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.2:1e-320", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&s, "tumble", "-1", &d), PD_ERR_RANGE);
    CHECK(memcmp(&before, &s, sizeof s) == 0);
    /* A program's scene gets the same checks (one validator). */
    pd_scene bad = s;
    bad.range[PD_PARAM_MU] = (pd_dist){PD_DIST_UNIFORM, 0.5, 0.2, 0};
    CHECK_STATUS(pd_scene_check(&bad, NULL), PD_ERR_RANGE);
    bad = s;
    bad.range[PD_PARAM_MU] = (pd_dist){(pd_dist_kind)7, 0.2, 0.5, 0};
    CHECK_STATUS(pd_scene_check(&bad, NULL), PD_ERR_RANGE);
    bad = s;
    bad.range[PD_PARAM_MU] = (pd_dist){PD_DIST_UNIFORM, 0.2, NAN, 0};
    CHECK_STATUS(pd_scene_check(&bad, NULL), PD_ERR_NONFINITE);
    bad = s;
    bad.range[PD_PARAM_HEIGHT] = (pd_dist){PD_DIST_UNIFORM, 0.1, 0.2, 1};
    CHECK_STATUS(pd_scene_check(&bad, NULL), PD_ERR_RANGE);
    /* 1e-320 is refused in a program's scene as in the text. */
    const char *const tiny_keys[] = {"height", "mu", "restitution", "contact_time", "tumble"};
    for (int k = 0; k < 5; k++) {
        pd_scene t;
        pd_scene_default(&t);
        CHECK_STATUS(pd_scene_set(&t, tiny_keys[k], "1e-320", &d), PD_ERR_RANGE);
    }
    bad = s;
    bad.height = 1e-320;
    CHECK_STATUS(pd_scene_check(&bad, &d), PD_ERR_RANGE);
    CHECK(strstr(d.message, "smallest normal double") != NULL);
    bad = s;
    bad.mu = -1e-320;
    CHECK_STATUS(pd_scene_check(&bad, NULL), PD_ERR_RANGE);
    bad = s;
    bad.range[PD_PARAM_RESTITUTION] = (pd_dist){PD_DIST_UNIFORM, 1e-320, 0.5, 0};
    CHECK_STATUS(pd_scene_check(&bad, NULL), PD_ERR_RANGE);
    /* A scene file takes ranges too. */
    pd_scene f;
    pd_scene_default(&f);
    const char *text = "mu = 0.2:0.6\ncontact_time = 1e-4:1e-3 log\n";
    char path[] = "/tmp/posedrop-range-XXXXXX";
    int fd = mkstemp(path);
    FILE *fp = fd >= 0 ? fdopen(fd, "w") : NULL;
    CHECK(fp != NULL);
    if (fp) {
        fputs(text, fp);
        fclose(fp);
        CHECK_STATUS(pd_scene_read(path, &f, &d), PD_OK);
        CHECK(f.range[PD_PARAM_MU].hi == 0.6 && f.range[PD_PARAM_CONTACT_TIME].lo == 1e-4);
        remove(path);
    }

    /* The draws. Zero width: the end itself, for uniform and log alike. */
    pd_scene z;
    pd_scene_default(&z);
    CHECK_STATUS(pd_scene_set(&z, "restitution", "0.3:0.3 log", &d), PD_OK);
    CHECK_STATUS(pd_scene_set(&z, "mu", "0.3:0.3", &d), PD_OK);
    for (long i = 0; i < 100; i++) {
        double v[PD_NPARAMS];
        pd_scene drawn;
        pd_scene_draw(&z, 0.01, 3, i, v, &drawn);
        CHECK(v[PD_PARAM_RESTITUTION] == 0.3 && v[PD_PARAM_MU] == 0.3 && drawn.mu == 0.3 &&
              !pd_scene_ranged(&drawn));
        CHECK_REL(v[PD_PARAM_CONTACT_TIME], pd_contact_time_auto(0.01), 0.0, "auto resolved");
    }
    /* Uniform and log uniform over their ranges: the Kolmogorov-Smirnov
     * statistic of 20000 draws below its 0.1% critical value 1.95 /
     * sqrt(n), plus the counting grid's step (a false alarm once in a
     * thousand seeds; the seed is fixed). */
    pd_scene r;
    pd_scene_default(&r);
    CHECK_STATUS(pd_scene_set(&r, "mu", "0.2:0.6", &d), PD_OK);
    CHECK_STATUS(pd_scene_set(&r, "contact_time", "0.3x:3x", &d), PD_OK);
    CHECK_STATUS(pd_scene_set(&r, "height", "0.001:1 log", &d), PD_OK);
    const int n = 20000;
    double bound = 1.95 / sqrt((double)n) + 2e-5;
    CHECK(ks_statistic(&r, PD_PARAM_MU, 0.01, n) < bound);
    CHECK(ks_statistic(&r, PD_PARAM_CONTACT_TIME, 0.01, n) < bound);
    CHECK(ks_statistic(&r, PD_PARAM_HEIGHT, 0.01, n) < bound);
    /* The test can fail: log-uniform draws are far from uniform on the same
     * range. */
    pd_scene wrong = r;
    wrong.range[PD_PARAM_HEIGHT].kind = PD_DIST_UNIFORM;
    double dl = 0.0;
    for (int i = 0; i < 2000; i++) {
        double v[PD_NPARAMS];
        pd_scene_draw(&r, 0.01, 7, i, v, NULL);
        dl += pd_scene_quantile(&wrong, PD_PARAM_HEIGHT, 0.01, v[PD_PARAM_HEIGHT]) / 2000;
    }
    CHECK(dl < 0.25); /* a uniform's mean quantile is 0.5; log uniform over 3 decades: 0.14 */
    /* Each parameter's draw depends on its own index only: ranging another
     * parameter leaves it as it was. */
    pd_scene r2 = r;
    CHECK_STATUS(pd_scene_set(&r2, "restitution", "0.1:0.5", &d), PD_OK);
    int same = 1;
    for (long i = 0; i < 100; i++) {
        double v1[PD_NPARAMS], v2[PD_NPARAMS];
        pd_scene_draw(&r, 0.01, 9, i, v1, NULL);
        pd_scene_draw(&r2, 0.01, 9, i, v2, NULL);
        same &= v1[PD_PARAM_MU] == v2[PD_PARAM_MU] && v1[PD_PARAM_HEIGHT] == v2[PD_PARAM_HEIGHT];
    }
    CHECK(same);
    CHECK(strcmp(pd_scene_param_name(PD_PARAM_TUMBLE), "tumble") == 0);
    CHECK(pd_scene_param_name(PD_NPARAMS) == NULL);
}

void suite_scene(void)
{
    contact_time_of_parts();
    test_ranges();
    pd_scene s;
    pd_scene_default(&s);
    /* The paper's section 5.2. */
    CHECK(s.height == 0.12 && s.belt_speed == 0.05 && s.mu == 0.3 && s.restitution == 0.3);
    CHECK_NEAR(s.vibration, 1.5 * M_PI / 180, 1e-17, "1.5 degrees");
    CHECK(s.law == PD_RESTITUTION_POISSON && s.initial == PD_INITIAL_UNIFORM);
    CHECK(s.contact_time == PD_CONTACT_TIME_AUTO); /* a plastic part on a rubber belt */
    /* 5e-4 s for a 1 cm cube (diagonal sqrt(3) cm), in proportion to size. */
    CHECK_REL(pd_contact_time_auto(0.01 * sqrt(3.0)), 5e-4, 1e-15, "round-off");
    CHECK_REL(pd_contact_time_auto(1.0), 1e2 * pd_contact_time_auto(0.01), 1e-15, "linear");
    /* Above 1.2 m, capped where the weight presses a contact 1e-3 of the
     * size into the floor: g (T / pi)^2 = 1e-3 L at the estimate's gravity;
     * just below 1.2 m still the proportional one. */
    for (double L = 10.0; L <= 1e6; L *= 100.0) {
        double T = pd_contact_time_auto(L);
        CHECK_REL(9.81 * (T / M_PI) * (T / M_PI), 1e-3 * L, 1e-14, "the cap, round-off");
    }
    CHECK_REL(pd_contact_time_auto(1.19), 119.0 * pd_contact_time_auto(0.01), 1e-15, "linear");
    CHECK_STATUS(pd_scene_check(&s, NULL), PD_OK);

    pd_diag d;
    pd_diag_init(&d);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.5", &d), PD_OK);
    CHECK(s.mu == 0.5);
    CHECK_STATUS(pd_scene_set(&s, "vibration", "90", &d), PD_OK);
    CHECK_NEAR(s.vibration, M_PI / 2, 1e-16, "degrees to radians");
    CHECK_STATUS(pd_scene_set(&s, "restitution_law", "energetic", &d), PD_OK);
    CHECK(s.law == PD_RESTITUTION_ENERGETIC);
    CHECK_STATUS(pd_scene_set(&s, "initial", "bootstrap", &d), PD_OK);
    CHECK(s.initial == PD_INITIAL_BOOTSTRAP);
    CHECK_STATUS(pd_scene_set(&s, "initial", "stationary", &d), PD_OK);
    CHECK(s.initial == PD_INITIAL_STATIONARY);
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "1e-4", &d), PD_OK);
    CHECK(s.contact_time == 1e-4);
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "auto", &d), PD_OK);
    CHECK(s.contact_time == PD_CONTACT_TIME_AUTO);
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "1e-4", &d), PD_OK);
    {
        pd_scene bad = s;
        bad.contact_time = -0.5; /* only the marker itself is "auto" */
        CHECK_STATUS(pd_scene_check(&bad, NULL), PD_ERR_RANGE);
    }
    pd_scene before = s;
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "-1e-4", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&s, "restitution", "1.5", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&s, "mu", "nan", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.3x", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "colour", "red", &d), PD_ERR_USAGE);
    CHECK(strstr(d.message, "colour") != NULL);
    /* The numbers of every key read as everywhere else (base/number.c):
     * underflow refused, blanks at either end alike, the range stated. */
    CHECK_STATUS(pd_scene_set(&s, "mu", "1e-400", &d), PD_ERR_RANGE);
    CHECK(strstr(d.message, "from 0 to 10") != NULL);
    CHECK_STATUS(pd_scene_set(&s, "height", "1e-400", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&s, "belt_speed", "1e308", &d), PD_ERR_RANGE);
    CHECK(strstr(d.message, "from -1000 to 1000") != NULL);
    /* "v" was an undocumented second name of belt_speed: one name each. */
    CHECK_STATUS(pd_scene_set(&s, "v", "0.1", &d), PD_ERR_USAGE);
    CHECK(memcmp(&before, &s, sizeof s) == 0);
    CHECK_STATUS(pd_scene_set(&s, "mu", " 0.25", &d), PD_OK);
    CHECK(s.mu == 0.25);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.35 ", &d), PD_OK);
    CHECK(s.mu == 0.35);
    s = before;
    CHECK(memcmp(&before, &s, sizeof s) == 0);

    /* A file: comments, blanks, spaces; an error names file and line and
     * changes nothing. */
    char path[] = "/tmp/posedrop-scene-XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    FILE *f = fdopen(fd, "w");
    fputs("# feeder belt\n\nheight = 0.2   # metres\n  mu=0.7\nrestitution_law = poisson\n", f);
    fclose(f);
    pd_scene_default(&s);
    CHECK_STATUS(pd_scene_read(path, &s, &d), PD_OK);
    CHECK(s.height == 0.2 && s.mu == 0.7 && s.law == PD_RESTITUTION_POISSON);
    f = fopen(path, "w");
    fputs("height = 0.3\nmu 0.4\n", f);
    fclose(f);
    before = s;
    CHECK_STATUS(pd_scene_read(path, &s, &d), PD_ERR_PARSE);
    char where[64];
    snprintf(where, sizeof where, "%s:2:", path);
    CHECK(strstr(d.message, where) != NULL);
    CHECK(memcmp(&before, &s, sizeof s) == 0);

    /* A key set twice is refused, naming both lines. */
    f = fopen(path, "w");
    fputs("mu = 0.4\nheight = 0.1\nmu = 0.6\n", f);
    fclose(f);
    CHECK_STATUS(pd_scene_read(path, &s, &d), PD_ERR_PARSE);
    snprintf(where, sizeof where, "%s:3: mu is set a second time (first on line 1)", path);
    CHECK(strstr(d.message, where) != NULL);
    CHECK(memcmp(&before, &s, sizeof s) == 0);

    /* A UTF-8 byte-order mark is no part of the first key; a NUL byte is
     * named with its line. */
    f = fopen(path, "w");
    fputs("\xEF\xBB\xBFmu = 0.45\n", f);
    fclose(f);
    CHECK_STATUS(pd_scene_read(path, &s, &d), PD_OK);
    CHECK(s.mu == 0.45);
    f = fopen(path, "wb");
    fwrite("mu = 0.4\nheight\0 = 0.1\n", 1, 24, f);
    fclose(f);
    CHECK_STATUS(pd_scene_read(path, &s, &d), PD_ERR_PARSE);
    snprintf(where, sizeof where, "%s:2: a NUL byte", path);
    CHECK(strstr(d.message, where) != NULL);
    remove(path);
    CHECK_STATUS(pd_scene_read("/nonexistent/scene", &s, &d), PD_ERR_IO);
    CHECK_STATUS(pd_scene_read("/tmp", &s, &d), PD_ERR_IO);
    CHECK(strstr(d.message, "/tmp: is a directory") != NULL);
    /* An endless input ends at the size limit. */
    CHECK_STATUS(pd_scene_read("/dev/zero", &s, &d), PD_ERR_RANGE);
    CHECK(strstr(d.message, "longer than") != NULL);
}
