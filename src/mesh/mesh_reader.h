/* mesh_reader.h (private): what the OFF, STL and OBJ readers share beyond
 * the text cursor (base/text.h): the mesh builder, the exact vertex map and
 * the readers' entry points. */
#ifndef PD_MESH_READER_H
#define PD_MESH_READER_H

#include <stddef.h>
#include "posedrop/mesh.h"
#include "base/fail.h"
#include "base/text.h"

/* --- reading a file -------------------------------------------------------- */

/* The most bytes pd_mesh_read takes from a file or pipe, so that an endless
 * input (/dev/zero, a pipe that never ends) is refused instead of read until
 * memory runs out. 1 GiB holds a binary STL of 21 million triangles, or an
 * ASCII one of about 4 million: above the largest CAD meshes users feed to a
 * pose estimator, and well within a machine's memory. */
#define PD_MESH_MAX_BYTES ((size_t)1 << 30)

/* pd_mesh_read with another byte limit (the tests' small one). */
pd_status pd_mesh_read_capped(const char *path, const pd_mesh_read_options *options,
                              size_t max_bytes, pd_mesh **mesh, pd_diag *diag);

/* --- mesh builder ----------------------------------------------------------- */

/* Growable vertex and triangle arrays. Sizes never pass PD_MAX_ELEMENTS, so
 * no size computation can overflow. */
typedef struct pd_build {
    pd_vec3 *verts;
    int nverts, cverts;
    int (*tris)[3];
    int ntris, ctris;
} pd_build;

/* Capacity for counts already checked against PD_MAX_ELEMENTS; PD_ERR_NOMEM. */
pd_status pd_build_reserve(pd_build *b, long long nverts, long long ntris);
/* PD_ERR_RANGE past PD_MAX_ELEMENTS, PD_ERR_NOMEM. */
pd_status pd_build_vert(pd_build *b, pd_vec3 v);
pd_status pd_build_tri(pd_build *b, int i0, int i1, int i2);
/* Hands the arrays over to a new pd_mesh (and empties b); PD_ERR_NOMEM. */
pd_status pd_build_finish(pd_build *b, pd_mesh **mesh);
void pd_build_free(pd_build *b);

/* --- exact vertex map --------------------------------------------------------- */

/* Hash set of vertex indices keyed on the exact bit pattern of the three
 * coordinates (-0.0 counted as +0.0): finds bit-identical vertices in O(1). */
typedef struct pd_vmap {
    int *slot;   /* vertex index or -1 */
    size_t mask; /* capacity - 1, capacity a power of two */
    size_t count;
} pd_vmap;

pd_status pd_vmap_init(pd_vmap *m, size_t expected);
/* The first vertex bit-identical to verts[i] among those added, or i after
 * adding it; -1 if out of memory. verts must hold every index added. */
int pd_vmap_find_or_add(pd_vmap *m, const pd_vec3 *verts, int i);
void pd_vmap_free(pd_vmap *m);

/* --- vertex lines -------------------------------------------------------------- */

/* The rest of a vertex line after its three coordinates: OFF's colour,
 * normal and texture coordinates, OBJ's weight or colour, all numbers the
 * readers ignore. One rule for both formats: each must read as a finite
 * number (base/number.c), or the line is refused with its token ('abc',
 * 'nan', '1e999'), as a bad coordinate is. */
pd_status pd_vertex_rest(pd_text *t, pd_diag *diag);

/* --- readers ------------------------------------------------------------------ */

/* 1 if the token is an OFF header keyword ([ST][C][N][4][n]OFF). */
int pd_off_is_keyword(const char *s, size_t n);
/* 1 if the token is a keyword that starts OBJ lines (v, f, vt, g, ...). */
int pd_obj_is_keyword(const char *s, size_t n);
/* 1 if the token is "solid", also with a UTF-8 byte-order mark glued to it
 * (one after a comment line, where the text cursor does not skip it). */
int pd_stl_is_solid(const char *s, size_t n);
/* 1 if the data must be read as binary STL rather than ASCII. */
int pd_stl_is_binary(const unsigned char *data, size_t size);

/* The checks each reader makes first, on the first n bytes (head) of a file
 * of size bytes, so that a file whose start is already wrong (1 GiB of NUL
 * bytes) is refused without reading the rest: OFF's header keyword, OBJ's
 * first keyword, binary STL's triangle count against the size. Each refuses
 * only what the whole file's reading would refuse, with the same message;
 * PD_OK otherwise (the rest is then read). */
pd_status pd_off_check_head(const char *head, size_t n, const char *name, pd_diag *diag);
pd_status pd_obj_check_head(const char *head, size_t n, const char *name, pd_diag *diag);
pd_status pd_stl_check_head(const unsigned char *head, size_t n, size_t size, const char *name,
                            pd_diag *diag);

/* Each reads the whole input, scaling coordinates by scale. On failure *mesh
 * is untouched and diag says what and where. */
pd_status pd_off_read(const char *data, size_t size, const char *name, double scale,
                      pd_mesh **mesh, pd_diag *diag,
                      pd_cancel_flag *cancel);
pd_status pd_stl_read(const unsigned char *data, size_t size, const char *name, double scale,
                      pd_mesh **mesh, pd_diag *diag,
                      pd_cancel_flag *cancel);
pd_status pd_obj_read(const char *data, size_t size, const char *name, double scale,
                      pd_mesh **mesh, pd_diag *diag,
                      pd_cancel_flag *cancel);

#endif
