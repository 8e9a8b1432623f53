/* sincos.h (private): sine and cosine of one angle together, inline, for the
 * flight's evaluations (flight.c, flight_theta.c), which need two pairs each.
 *
 * Why not libm's sincos: with its call it costs 115 to 150 instructions
 * (the more the larger the angle), two of them a third of an asymmetric
 * top's evaluation; this costs 60 within pi/4 and 78 beyond. It is also the
 * same on every platform (plain IEEE double arithmetic, no FMA contraction
 * under the build's -ffp-contract=off), where libm's results may differ by
 * an ulp between versions.
 *
 * Method: x = k pi/2 + r, |r| <= pi/4, k the nearest integer to x 2/pi (by
 * adding and subtracting 1.5 * 2^52), with pi/2 in two parts (Cody and
 * Waite): P1, its first 33 bits, so that k P1 is exact and x - k P1 too
 * (Sterbenz), and P2, the rest rounded, P1 + P2 = pi/2 to 3.5e-27; r's
 * rounding error is kept as tail (exact while |x - k P1| >= |k P2|). So
 * the reduction errs by at most |k| 1e-26 absolute (k P2's rounding and P1
 * + P2's error), 7e-22 at the largest |k| taken here (6.4e4). Then Taylor
 * series in r through r^17 and r^16, whose remainders (r^19/19!, r^18/18!)
 * stay below 1e-19 and 3e-18 relative for |r| <= pi/4; the cosine's 1 -
 * r^2/2 is summed with its rounding error recovered, as it carries most of
 * the value. Measured against long double sinl/cosl over 10^7 arguments
 * in [-1e5, 1e5]: at most 0.92 ulp for either where the value exceeds 1e-3
 * (libm's: 0.52), mean 0.25; absolute error at most 1e-16 everywhere.
 * Beyond |x| = 1e5, or not finite: libm's. */
#ifndef PD_SINCOS_H
#define PD_SINCOS_H

#include <math.h>

static inline void pd_sincos(double x, double *s, double *c)
{
    double kd = 0.0, r = x, tail = 0.0;
    if (!(fabs(x) <= 0x1.921fb54442d18p-1)) { /* pi/4 */
        if (!(fabs(x) <= 1e5)) {
            *s = sin(x);
            *c = cos(x);
            return;
        }
        const double SHIFT = 0x1.8p52, TWO_OVER_PI = 0x1.45f306dc9c883p-1;
        const double P1 = 0x1.921fb544p+0, P2 = 0x1.0b4611a626331p-34;
        kd = (x * TWO_OVER_PI + SHIFT) - SHIFT;
        double r1 = x - kd * P1, t = kd * P2;
        r = r1 - t;
        tail = (r1 - r) - t;
    }
    double z = r * r;
    double sp = r + (tail + r * z *
                             (-1.0 / 6.0 +
                              z * (1.0 / 120.0 +
                                   z * (-1.0 / 5040.0 +
                                        z * (1.0 / 362880.0 +
                                             z * (-1.0 / 39916800.0 +
                                                  z * (1.0 / 6227020800.0 +
                                                       z * (-1.0 / 1307674368000.0 +
                                                            z * (1.0 / 355687428096000.0)))))))));
    double hz = 0.5 * z, w = 1.0 - hz, lo = (1.0 - w) - hz;
    double cp = w + (lo - r * tail +
                     z * z *
                         (1.0 / 24.0 +
                          z * (-1.0 / 720.0 +
                               z * (1.0 / 40320.0 +
                                    z * (-1.0 / 3628800.0 +
                                         z * (1.0 / 479001600.0 +
                                              z * (-1.0 / 87178291200.0 +
                                                   z * (1.0 / 20922789888000.0))))))));
    switch ((long)kd & 3) {
    case 0:
        *s = sp, *c = cp;
        break;
    case 1:
        *s = cp, *c = -sp;
        break;
    case 2:
        *s = -sp, *c = -cp;
        break;
    default:
        *s = -cp, *c = sp;
        break;
    }
}

#endif
