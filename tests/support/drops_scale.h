/* drops_scale.h: DROPS_SCALE, by which the sanitizer build divides the drops
 * of statistical tests (their bounds keep their level at any count). */
#ifndef PD_TEST_DROPS_SCALE_H
#define PD_TEST_DROPS_SCALE_H

#if defined(__SANITIZE_ADDRESS__)
#define DROPS_SCALE 4
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DROPS_SCALE 4
#endif
#endif
#ifndef DROPS_SCALE
#define DROPS_SCALE 1
#endif

#endif
