/* suites.h: the table of suites, one per module (tests/test_<module>.c). */
#ifndef PD_TEST_SUITES_H
#define PD_TEST_SUITES_H

#define PD_SUITES   \
    PD_SUITE(status) \
    PD_SUITE(api)    \
    PD_SUITE(nullargs) \
    PD_SUITE(mesh)   \
    PD_SUITE(hull)   \
    PD_SUITE(mass)   \
    PD_SUITE(part)   \
    PD_SUITE(static) \
    PD_SUITE(limits) \
    PD_SUITE(basin)  \
    PD_SUITE(descent_map) \
    PD_SUITE(rng)    \
    PD_SUITE(stats)  \
    PD_SUITE(number) \
    PD_SUITE(input)  \
    PD_SUITE(fuzz_replay) \
    PD_SUITE(scene)  \
    PD_SUITE(flight) \
    PD_SUITE(impact) \
    PD_SUITE(drop)   \
    PD_SUITE(flat_rest) \
    PD_SUITE(contact_phase) \
    PD_SUITE(contact_pivot) \
    PD_SUITE(compliant) \
    PD_SUITE(sim)    \
    PD_SUITE(ranges) \
    PD_SUITE(sensitivity) \
    PD_SUITE(markov) \
    PD_SUITE(fit)    \
    PD_SUITE(design) \
    PD_SUITE(drop_step) \
    PD_SUITE(engine_ode) \
    PD_SUITE(engine_bullet) \
    PD_SUITE(engine_extreme) \
    PD_SUITE(engine_contact) \
    PD_SUITE(hard_parts) \
    PD_SUITE(symmetry) \
    PD_SUITE(cli)    \
    PD_SUITE(batch)  \
    PD_SUITE(viz)    \
    PD_SUITE(golden)

#define PD_SUITE(name) void suite_##name(void);
PD_SUITES
#undef PD_SUITE

#endif
