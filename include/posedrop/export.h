/* posedrop/export.h: PD_API marks the functions libposedrop exports.
 *
 * The library is compiled with -fvisibility=hidden, so its internal functions
 * stay out of the shared library's symbol table: a program can link only
 * against what the public headers declare, and the internals can change
 * without breaking it. Every function declared in include/posedrop/ carries
 * PD_API. */
#ifndef POSEDROP_EXPORT_H
#define POSEDROP_EXPORT_H

#if defined(__GNUC__) || defined(__clang__)
#define PD_API __attribute__((visibility("default")))
#else
#define PD_API
#endif

#endif
