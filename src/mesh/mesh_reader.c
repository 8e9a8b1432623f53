/* mesh_reader.c: the mesh builder and exact vertex map shared by the mesh
 * readers (see mesh_reader.h). */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "mesh/mesh_reader.h"
#include "posedrop/tolerances.h"

/* --- mesh builder ----------------------------------------------------------- */

/* Grows *p to hold need elements; capacity doubles so pushes are amortised O(1). */
static pd_status grow(void **p, int *cap, long long need, size_t elem)
{
    if (need <= *cap)
        return PD_OK;
    if (need > PD_MAX_ELEMENTS)
        return PD_ERR_RANGE;
    long long c = *cap < 64 ? 64 : 2LL * *cap;
    if (c < need)
        c = need;
    if (c > PD_MAX_ELEMENTS)
        c = PD_MAX_ELEMENTS;
    if ((size_t)c > SIZE_MAX / elem)
        return PD_ERR_NOMEM;
    void *q = realloc(*p, (size_t)c * elem);
    if (!q)
        return PD_ERR_NOMEM;
    *p = q;
    *cap = (int)c;
    return PD_OK;
}

pd_status pd_build_reserve(pd_build *b, long long nverts, long long ntris)
{
    void *v = b->verts, *t = b->tris;
    pd_status st = grow(&v, &b->cverts, nverts, sizeof *b->verts);
    b->verts = v;
    if (st == PD_OK)
        st = grow(&t, &b->ctris, ntris, sizeof *b->tris);
    b->tris = t;
    return st;
}

pd_status pd_build_vert(pd_build *b, pd_vec3 v)
{
    if (b->nverts == b->cverts) {
        void *p = b->verts;
        pd_status st = grow(&p, &b->cverts, (long long)b->nverts + 1, sizeof *b->verts);
        b->verts = p;
        if (st != PD_OK)
            return st;
    }
    b->verts[b->nverts++] = v;
    return PD_OK;
}

pd_status pd_build_tri(pd_build *b, int i0, int i1, int i2)
{
    if (b->ntris == b->ctris) {
        void *p = b->tris;
        pd_status st = grow(&p, &b->ctris, (long long)b->ntris + 1, sizeof *b->tris);
        b->tris = p;
        if (st != PD_OK)
            return st;
    }
    b->tris[b->ntris][0] = i0;
    b->tris[b->ntris][1] = i1;
    b->tris[b->ntris][2] = i2;
    b->ntris++;
    return PD_OK;
}

pd_status pd_build_finish(pd_build *b, pd_mesh **mesh)
{
    pd_mesh *m = malloc(sizeof *m);
    if (!m)
        return PD_ERR_NOMEM;
    m->nverts = b->nverts;
    m->verts = b->verts;
    m->ntris = b->ntris;
    m->tris = b->tris;
    memset(b, 0, sizeof *b);
    *mesh = m;
    return PD_OK;
}

void pd_build_free(pd_build *b)
{
    free(b->verts);
    free(b->tris);
    memset(b, 0, sizeof *b);
}

/* --- exact vertex map --------------------------------------------------------- */

static uint64_t coord_bits(double c)
{
    /* Adding +0.0 turns -0.0 into +0.0 and changes nothing else, so the two
     * zeros, which compare equal, also hash and match alike. */
    double z = c + 0.0;
    uint64_t u;
    memcpy(&u, &z, sizeof u);
    return u;
}

static size_t vert_hash(pd_vec3 v)
{
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    uint64_t k[3] = {coord_bits(v.x), coord_bits(v.y), coord_bits(v.z)};
    for (int i = 0; i < 3; i++) {
        h ^= k[i];
        h *= 0xbf58476d1ce4e5b9ULL;
        h ^= h >> 31;
    }
    return (size_t)h;
}

static int same_bits(pd_vec3 a, pd_vec3 b)
{
    return coord_bits(a.x) == coord_bits(b.x) && coord_bits(a.y) == coord_bits(b.y) &&
           coord_bits(a.z) == coord_bits(b.z);
}

static int *new_slots(size_t cap)
{
    int *s = malloc(cap * sizeof *s);
    if (s)
        memset(s, 0xff, cap * sizeof *s); /* all -1 */
    return s;
}

pd_status pd_vmap_init(pd_vmap *m, size_t expected)
{
    /* At most half full: linear probes stay short. */
    size_t cap = 64;
    while (cap / 2 < expected && cap < SIZE_MAX / 4 / sizeof(int))
        cap *= 2;
    m->slot = new_slots(cap);
    m->mask = cap - 1;
    m->count = 0;
    return m->slot ? PD_OK : PD_ERR_NOMEM;
}

static void insert(int *slot, size_t mask, const pd_vec3 *verts, int i)
{
    size_t h = vert_hash(verts[i]) & mask;
    while (slot[h] >= 0)
        h = (h + 1) & mask;
    slot[h] = i;
}

int pd_vmap_find_or_add(pd_vmap *m, const pd_vec3 *verts, int i)
{
    size_t h = vert_hash(verts[i]) & m->mask;
    for (; m->slot[h] >= 0; h = (h + 1) & m->mask)
        if (same_bits(verts[m->slot[h]], verts[i]))
            return m->slot[h];
    if (2 * (m->count + 1) > m->mask + 1) {
        size_t cap = 2 * (m->mask + 1);
        int *s = new_slots(cap);
        if (!s)
            return -1;
        for (size_t k = 0; k <= m->mask; k++)
            if (m->slot[k] >= 0)
                insert(s, cap - 1, verts, m->slot[k]);
        free(m->slot);
        m->slot = s;
        m->mask = cap - 1;
    }
    insert(m->slot, m->mask, verts, i);
    m->count++;
    return i;
}

void pd_vmap_free(pd_vmap *m)
{
    free(m->slot);
    m->slot = NULL;
}

/* --- vertex lines -------------------------------------------------------------- */

pd_status pd_vertex_rest(pd_text *t, pd_diag *diag)
{
    const char *s;
    size_t n;
    char shown[48];
    while (pd_text_token(t, &s, &n)) {
        double ignored;
        int rc = pd_parse_double(s, n, &ignored);
        if (rc == PD_NUM_BAD)
            return pd_text_fail(t, diag, PD_ERR_PARSE, "expected a number after the vertex's "
                                "coordinates (a colour, weight or normal), found %s",
                                pd_text_show(shown, sizeof shown, s, n));
        if (rc == PD_NUM_NONFINITE)
            return pd_text_fail(t, diag, PD_ERR_NONFINITE, "non-finite number %s after the "
                                "vertex's coordinates", pd_text_show(shown, sizeof shown, s, n));
    }
    return PD_OK;
}
