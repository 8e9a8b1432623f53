/* posedrop/types.h: the plain value types shared by the public headers. */
#ifndef POSEDROP_TYPES_H
#define POSEDROP_TYPES_H

/* A point or direction in 3-D. Lengths are in metres everywhere in the
 * library: mesh readers scale to metres on input. */
typedef struct pd_vec3 {
    double x, y, z;
} pd_vec3;

#endif
