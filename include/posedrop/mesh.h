/* posedrop/mesh.h: reading part meshes (OFF, STL, OBJ) and welding them.
 *
 * A pd_mesh is a list of vertices in metres and of triangles indexing them;
 * polygons of OFF and OBJ files are fan-triangulated from their first vertex,
 * which keeps every surface integral of a planar polygon exact. */
#ifndef POSEDROP_MESH_H
#define POSEDROP_MESH_H

#include <stddef.h>
#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum pd_mesh_format {
    PD_FORMAT_AUTO = 0, /* decide by content, then by file extension */
    PD_FORMAT_OFF,
    PD_FORMAT_STL,      /* ASCII or binary, told apart by content */
    PD_FORMAT_OBJ
} pd_mesh_format;

typedef enum pd_units { PD_UNITS_M = 0, PD_UNITS_CM, PD_UNITS_MM, PD_UNITS_IN } pd_units;

/* Metres per unit: 1, 0.01, 0.001, 0.0254; 0 for a value that is none of
 * pd_units'. */
PD_API double pd_units_scale(pd_units units);
/* "m", "cm", "mm", "in" -> units. PD_ERR_USAGE for anything else. */
PD_API pd_status pd_units_parse(const char *text, pd_units *units);
/* Whether a part of this size (bounding-box diagonal, m) read in these
 * units is one dropped on a feeder, a belt or a bin: 0.5 mm to 2 m across
 * (a file in millimetres read as metres is a thousand times too large).
 * 1 if so, or if size is not a number; 0 if not, with *suggest (NULL
 * allowed) the unit that, given instead, would make the file's numbers a
 * plausible part (millimetres first for a part too large), or units itself
 * when none would. The command, posedrop fit and the Python binding warn
 * with it; the library itself accepts any size. */
PD_API int pd_units_plausible(double size, pd_units units, pd_units *suggest);

typedef struct pd_mesh {
    int nverts;
    pd_vec3 *verts;   /* metres */
    int ntris;
    int (*tris)[3];   /* vertex indices, counter-clockwise seen from outside
                         when the file is consistently oriented */
} pd_mesh;

typedef struct pd_mesh_read_options {
    pd_mesh_format format; /* default PD_FORMAT_AUTO */
    pd_units units;        /* unit of the file's coordinates; default metres */
    pd_cancel_flag *cancel; /* may be NULL (the default); see pd_mesh_read */
} pd_mesh_read_options;

PD_API void pd_mesh_read_options_default(pd_mesh_read_options *options);

/* Reads a mesh file. options may be NULL (defaults); a format or units that
 * is none of its enum's values is PD_ERR_USAGE. On success *mesh is a new
 * mesh owned by the caller (pd_mesh_free). Returns PD_ERR_IO, PD_ERR_FORMAT,
 * PD_ERR_PARSE (malformed or truncated content, wrong counts), PD_ERR_NONFINITE,
 * PD_ERR_RANGE (index out of range, count too large), PD_ERR_NOMEM; the diag
 * message names the file and, for text formats, the line. PD_ERR_CANCELLED
 * when options->cancel is set (non-zero, by another thread or a signal
 * handler) before the mesh is read: text formats read it every few
 * thousand lines. */
PD_API pd_status pd_mesh_read(const char *path, const pd_mesh_read_options *options,
                              pd_mesh **mesh, pd_diag *diag);

/* As pd_mesh_read, from memory. name is used in messages and, with
 * PD_FORMAT_AUTO, its extension breaks ties between formats. */
PD_API pd_status pd_mesh_parse(const void *data, size_t size, const char *name,
                               const pd_mesh_read_options *options, pd_mesh **mesh,
                               pd_diag *diag);

/* A deep copy; NULL if out of memory, or if mesh is NULL or has a negative
 * count. */
PD_API pd_mesh *pd_mesh_clone(const pd_mesh *mesh);

/* Welds vertices closer than tol (metres): bit-identical vertices always, near
 * duplicates by distance (tol 0: bit-identical only). Triangles are re-indexed;
 * triangles that collapse (two corners welded) are removed; unused vertices
 * are dropped. Deterministic: the survivor of a cluster is its first vertex in
 * input order. *nmerged (may be NULL) receives the number of vertices removed.
 * Returns PD_OK; PD_ERR_USAGE for a NULL mesh, a negative count or missing
 * arrays, or a tol that is negative, NaN or infinite; PD_ERR_RANGE for a
 * vertex index out of range; PD_ERR_NONFINITE for a non-finite coordinate;
 * PD_ERR_NOMEM. The mesh is unchanged on failure. */
PD_API pd_status pd_mesh_weld(pd_mesh *mesh, double tol, int *nmerged);

/* Makes the faces of a welded mesh consistently oriented with outward normals.
 * Works shell by shell (connected components): flips the faces that disagree
 * with their neighbours, then turns each shell so that it encloses positive
 * volume if it lies inside an even number of other shells (an outer surface)
 * and negative volume otherwise (a void). *nflipped (may be NULL) receives the
 * number of faces flipped. PD_ERR_NOT_CLOSED if an edge is not shared by exactly
 * two faces (boundary or non-manifold), PD_ERR_ORIENTATION if no consistent
 * orientation exists. The mesh is unchanged on failure. */
PD_API pd_status pd_mesh_orient(pd_mesh *mesh, int *nflipped, pd_diag *diag);

/* Diagonal of the bounding box of the vertices: the part's length scale. */
PD_API double pd_mesh_size(const pd_mesh *mesh);

PD_API void pd_mesh_free(pd_mesh *mesh);

#ifdef __cplusplus
}
#endif
#endif
