/* fuzz_targets.c: the fuzz targets' bodies (see fuzz_targets.h). */
#include <math.h>
#include <string.h>
#include "fuzz_targets.h"
#include "posedrop/posedrop.h"
#include "sim/scene.h"

/* A reader's answer: on success a mesh whose indices are in range and whose
 * coordinates are finite; on failure no mesh and a message. */
static int check_mesh(pd_status st, const pd_mesh *m, const pd_diag *d)
{
    if (st != PD_OK)
        return m == NULL && d->message[0] != '\0' &&
               (pd_status_is_input_error(st) || st == PD_ERR_NOMEM);
    if (!m || m->nverts <= 0 || m->ntris <= 0)
        return 0;
    for (int t = 0; t < m->ntris; t++)
        for (int c = 0; c < 3; c++)
            if (m->tris[t][c] < 0 || m->tris[t][c] >= m->nverts)
                return 0;
    for (int v = 0; v < m->nverts; v++)
        if (!isfinite(m->verts[v].x) || !isfinite(m->verts[v].y) || !isfinite(m->verts[v].z))
            return 0;
    return 1;
}

static int read_as(const uint8_t *data, size_t size, pd_mesh_format format, const char *name)
{
    pd_mesh_read_options ro;
    pd_mesh_read_options_default(&ro);
    ro.format = format;
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_mesh_parse(data, size, name, &ro, &m, &d);
    int ok = check_mesh(st, m, &d);
    pd_mesh_free(m);
    return ok;
}

int pd_fuzz_off(const uint8_t *data, size_t size)
{
    return read_as(data, size, PD_FORMAT_OFF, "fuzz.off");
}

int pd_fuzz_stl(const uint8_t *data, size_t size)
{
    return read_as(data, size, PD_FORMAT_STL, "fuzz.stl");
}

int pd_fuzz_obj(const uint8_t *data, size_t size)
{
    return read_as(data, size, PD_FORMAT_OBJ, "fuzz.obj");
}

/* A scene: accepted values within their ranges, or the scene untouched. */
int pd_fuzz_scene(const uint8_t *data, size_t size)
{
    pd_scene s, before;
    pd_scene_default(&s);
    before = s;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_scene_parse(data, size, "fuzz.scene", &s, &d);
    if (st != PD_OK)
        return memcmp(&s, &before, sizeof s) == 0 && d.message[0] != '\0';
    return s.height >= 0 && s.height <= 1e3 && s.mu >= 0 && s.mu <= 10 && s.restitution >= 0 &&
           s.restitution <= 1 && s.gravity > 0 && isfinite(s.belt_speed) && s.vibration >= 0 &&
           (s.contact_time >= 0 || s.contact_time == PD_CONTACT_TIME_AUTO) &&
           pd_scene_check(&s, NULL) == PD_OK;
}

/* Mesh in (any format, by content), part model out, then its static
 * estimate: probabilities that sum to one, or a clear refusal. */
int pd_fuzz_part(const uint8_t *data, size_t size)
{
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_mesh_parse(data, size, "fuzz", NULL, &m, &d);
    if (st != PD_OK)
        return check_mesh(st, m, &d);
    pd_part *part = NULL;
    pd_static_result *res = NULL;
    pd_part_options po;
    pd_part_options_default(&po);
    st = pd_part_build(m, &po, &part, &d);
    if (st == PD_OK)
        st = pd_static_estimate(part, NULL, &res, &d);
    int ok = st == PD_OK ? res != NULL : d.message[0] != '\0';
    if (st == PD_OK && res) {
        double qs = 0.0, pqs = 0.0;
        for (int i = 0; i < res->nposes; i++) {
            qs += res->poses[i].p_qs;
            pqs += res->poses[i].p_pqs;
            ok &= isfinite(res->poses[i].normal.x) && res->poses[i].area >= 0;
        }
        /* A distribution over the poses, to round-off of the sum. */
        ok &= res->nposes >= 1 && fabs(qs - 1.0) < 1e-9 && fabs(pqs - 1.0) < 1e-9;
    }
    pd_static_result_free(res);
    pd_part_free(part);
    pd_mesh_free(m);
    return ok;
}
