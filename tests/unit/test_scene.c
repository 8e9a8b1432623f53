/* test_scene.c: scene defaults, settings by name, scene files. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "posedrop/sim.h"
#include "suites.h"

void suite_scene(void)
{
    pd_scene s;
    pd_scene_default(&s);
    /* The paper's section 5.2. */
    CHECK(s.height == 0.12 && s.belt_speed == 0.05 && s.mu == 0.3 && s.restitution == 0.3);
    CHECK_NEAR(s.vibration, 1.5 * M_PI / 180, 1e-17, "1.5 degrees");
    CHECK(s.law == PD_RESTITUTION_POISSON && s.initial == PD_INITIAL_UNIFORM);
    CHECK(s.contact_time == 5e-4); /* a plastic part on a rubber belt */

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
    pd_scene before = s;
    CHECK_STATUS(pd_scene_set(&s, "contact_time", "-1e-4", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&s, "restitution", "1.5", &d), PD_ERR_RANGE);
    CHECK_STATUS(pd_scene_set(&s, "mu", "nan", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "mu", "0.3x", &d), PD_ERR_PARSE);
    CHECK_STATUS(pd_scene_set(&s, "colour", "red", &d), PD_ERR_USAGE);
    CHECK(strstr(d.message, "colour") != NULL);
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
    remove(path);
    CHECK_STATUS(pd_scene_read("/nonexistent/scene", &s, &d), PD_ERR_IO);
}
