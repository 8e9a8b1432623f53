/* posedrop/types.h: the plain value types shared by the public headers. */
#ifndef POSEDROP_TYPES_H
#define POSEDROP_TYPES_H

/* A point or direction in 3-D. Lengths are in metres everywhere in the
 * library: mesh readers scale to metres on input. */
typedef struct pd_vec3 {
    double x, y, z;
} pd_vec3;

/* A cancel flag (pd_sim_options, pd_part_options, pd_static_options,
 * pd_mesh_read_options): a C11 atomic_int, which C++23 spells
 * std::atomic<int> (the same object, so a C++ caller can share it). The
 * extern "C++" keeps <atomic> working when a caller wraps this header in
 * extern "C". */
#ifdef __cplusplus
extern "C++" {
#include <atomic>
}
typedef std::atomic<int> pd_cancel_flag;
#else
#include <stdatomic.h>
typedef atomic_int pd_cancel_flag;
#endif

#endif
