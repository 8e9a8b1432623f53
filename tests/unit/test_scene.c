/* test_scene.c: scene defaults, settings by name, scene files. */
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
    CHECK_REL(box_contact_time(10.0, 20.0, 30.0), 1e3 * box_contact_time(0.01, 0.02, 0.03), 1e-14,
              "round-off");
    double L = sqrt(1.0 + 2e-6);
    CHECK_REL(box_contact_time(1.0, 1e-3, 1e-3), 5e-4 * pow(0.01 * sqrt(3.0) / L, 0.2), 1e-14,
              "round-off");
}

void suite_scene(void)
{
    contact_time_of_parts();
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
