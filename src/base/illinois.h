/* illinois.h (private): the bookkeeping of regula falsi's Illinois variant,
 * shared by the contact layer's bracketed root searches (a slide's direction
 * from rest, a pivot's force event). After a trial replaced one end of the
 * bracket, the value kept at the other end is halved when the same end was
 * replaced the time before too, so that both ends close in (superlinearly)
 * instead of one end staying put as in plain regula falsi. The caller moves
 * the end itself; side carries which end moved last (0 before the first). */
#ifndef PD_ILLINOIS_H
#define PD_ILLINOIS_H

static inline void pd_illinois_moved(int moved_lo, int *side, double *flo, double *fhi)
{
    if (moved_lo) {
        if (*side == -1)
            *fhi *= 0.5;
        *side = -1;
    } else {
        if (*side == 1)
            *flo *= 0.5;
        *side = 1;
    }
}

#endif
