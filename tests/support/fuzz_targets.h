/* fuzz_targets.h: what each fuzz target does with one input, shared by the
 * libFuzzer entry points (tests/fuzz/, make fuzz) and the unit test that
 * replays the inputs kept in tests/fuzz/regressions/ (test_fuzz_replay.c). */
#ifndef PD_FUZZ_TARGETS_H
#define PD_FUZZ_TARGETS_H

#include <stddef.h>
#include <stdint.h>

/* Each returns 1 when the library's answer was well-formed (a status of the
 * documented set, a message on failure, a valid result on success), 0 when
 * it was not; a crash or sanitizer report is the other way to fail. */
int pd_fuzz_off(const uint8_t *data, size_t size);
int pd_fuzz_stl(const uint8_t *data, size_t size);
int pd_fuzz_obj(const uint8_t *data, size_t size);
int pd_fuzz_scene(const uint8_t *data, size_t size);
int pd_fuzz_part(const uint8_t *data, size_t size);
/* A program of library calls (see fuzz_targets.c). */
int pd_fuzz_api(const uint8_t *data, size_t size);
/* The readers of two files the command takes, fed through a file: posedrop
 * fit's measured counts (viz_measured_read, also --measured) and posedrop
 * merge's shards (shard_read). */
int pd_fuzz_measured(const uint8_t *data, size_t size);
int pd_fuzz_shard(const uint8_t *data, size_t size);

#endif
