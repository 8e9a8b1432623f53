/* markov.h (private): the long-run pose distribution of a drop process that
 * starts from mu0 and moves between stable poses by a transition matrix P
 * (--initial stationary).
 *
 * A part on the paper's belt is dropped again and again: its first drop
 * starts from an unknown (uniform) orientation, every later one resting on
 * the pose the previous drop ended in. Its pose after t drops has the
 * distribution mu0 P^t, and what a feeder sees over a long run is the Cesaro
 * limit pi = lim (1/T) sum_{t<T} mu0 P^t. That limit exists for every chain,
 * reducible or periodic; it is the unique stationary distribution when P has
 * one closed class, and otherwise weighs each closed class's stationary
 * distribution by the probability of being absorbed into it from mu0. */
#ifndef PD_MARKOV_H
#define PD_MARKOV_H

#include <stdint.h>
#include "posedrop/status.h"

typedef struct pd_markov_work pd_markov_work;

/* Where drop i (of the whole run) of a stationary run starts: -1 for a
 * uniform orientation, or the pose it rests on. The first (k + 1)
 * pose_drops drops go round uniform, pose 0, ..., pose k - 1; the rest
 * (fewer than k + 1) are uniform (montecarlo.c runs them so). */
int pd_stationary_start(long i, long pose_drops, int k);

/* Scratch for chains of up to k states (O(k^2) doubles); NULL if out of
 * memory. One work area serves any number of calls. */
pd_markov_work *pd_markov_work_alloc(int k);
void pd_markov_work_free(pd_markov_work *work);

/* pi (k) = the Cesaro limit of mu0 P^t. P is k x k row-major; only the rows
 * of states reachable from mu0 (through entries > 0) are read, and each of
 * those must sum to 1 (a row of zeros there is PD_ERR_USAGE: the chain is
 * undefined where it matters). mu0 (k) sums to 1. *nclosed receives the
 * number of closed communicating classes reachable from mu0 (1 when pi is the
 * unique stationary distribution of that part of the chain). Exact up to
 * round-off: no iteration. PD_ERR_INTERNAL if a step that the theory
 * guarantees fails (a bug). */
pd_status pd_markov_limit(pd_markov_work *work, const double *P, const double *mu0, double *pi,
                          int *nclosed);

/* The chain the drops estimate: first[k] counts how many uniform drops
 * ended in each pose (mu0 = first / their sum), C[k * k] row-major how many
 * drops started resting on pose i ended in pose j (P = C with each row
 * divided by its sum). */
typedef struct pd_markov_counts {
    int k;
    const long *first;
    const long *C;
} pd_markov_counts;

/* What pd_markov_estimate reports, per class of poses. */
typedef struct pd_markov_summary {
    double *p;       /* nclasses: pi summed over each class's poses (caller's arrays) */
    double *lo, *hi; /* nclasses: its 95% interval */
    int nclosed;     /* closed classes of the estimated chain reachable from mu0;
                        0: the counts do not define pi (no uniform drop settled,
                        or a pose the chain reaches has no settled drop started
                        on it), and p, lo, hi are untouched */
    double shift;    /* total variation between mu0 and pi, over the classes */
} pd_markov_summary;

/* pi of the estimated chain and its 95% intervals, summed over the classes
 * class_of[0..k) (values in [0, nclasses)); class_of NULL means each pose is
 * its own class (nclasses = k). Rows of poses the chain never reaches may be
 * empty. The intervals are a parametric bootstrap (see markov.c):
 * PD_STATIONARY_RESAMPLES chains redrawn from the counts, on streams derived
 * from seed that no drop uses, so the same counts and seed give the same
 * bytes; each interval holds its p. PD_ERR_RANGE for a row of more than UINT_MAX drops, PD_ERR_NOMEM,
 * PD_ERR_INTERNAL. */
pd_status pd_markov_estimate(const pd_markov_counts *counts, const int *class_of, int nclasses,
                             uint64_t seed, pd_markov_summary *out);

#endif
