/* posedrop/tolerances.h: the tolerances and limits that shape what posedrop
 * answers, the ones a user reasons about: what counts as one vertex, one
 * facet, a knife edge, a tie, a symmetry, a simultaneous contact, and which
 * inputs are accepted. The solvers' internal tolerances live beside their
 * code (src/<layer>/<layer>_tol.h, or the one file that uses them), with the
 * same conventions.
 *
 * Lengths are relative to the part's size L, the diagonal of the bounding box
 * of its (welded) vertices, so that scaling a part by 1e-3 or 1e3, moving it or
 * rotating it changes no decision the library takes. Absolute tolerances are
 * PD_TOL_..._REL * L. Probabilities are compared relatively. Angles are in
 * radians; comments give degrees.
 *
 * The values sit between two bounds that each comment names: above the
 * round-off of the computation they guard (a few 1e-16 relative for double
 * precision on the operations involved), and below the smallest genuine
 * feature the library must keep apart. */
#ifndef POSEDROP_TOLERANCES_H
#define POSEDROP_TOLERANCES_H

/* --- mesh input ------------------------------------------------------------ */

/* Vertices closer than this are one vertex (welding of triangle soups).
 * Why 1e-6: binary STL stores float32 (6e-8 relative) and many ASCII exporters
 * print six significant digits (up to 5e-7 relative), so the copies of one
 * vertex written by different triangles can differ by that much. Smaller: such
 * files stay open soups and are refused. Larger: would merge features of a
 * millionth of the part's size, far below anything manufactured. */
#define PD_TOL_WELD_REL 1e-6

/* --- convex hull ----------------------------------------------------------- */

/* Hull triangles whose vertices lie within this distance of a common plane are
 * merged into one polygonal facet, and a hull vertex that ends up on fewer than
 * three facets (a point on an edge) is dropped. Also the distance below which
 * input points count as coplanar or collinear (a sheet thinner than this has
 * no volume the hull can resolve), and how far inside every facet plane the
 * centre of mass must lie.
 * Why 1e-7: the hull's triangles are exact, but the files are not. Binary STL
 * stores float32 (6e-8 relative) and CAD exporters print 6 to 9 digits, so the
 * four corners of a face that is flat in the designer's model scatter off one
 * plane by up to ~1e-7 L; shipped parts/cap.off (9 digits) splits its conical
 * faces at 1e-9. A face split by that noise becomes two facets, the centre of
 * mass lands on the crease as a knife edge, and a symmetric part's poses stop
 * being symmetric. Larger: on a tessellated curved surface, neighbouring
 * triangles within 1e-6 L of one plane already merge by the hundreds
 * (10^4 points on an ellipsoid); merging there changes no probability beyond
 * 1e-6, but it departs from the exact hull for no gain. Smaller: print noise
 * splits faces again. Facets meeting at 1e-7 rad merge (their poses differ by
 * less than any drop can show); at 1e-5 rad over a facet of size 0.1 L they
 * stay two. */
#define PD_TOL_PLANE_REL 1e-7

/* --- static estimators ----------------------------------------------------- */

/* Knife edge: the centre of mass projects within this distance of a facet's
 * boundary. Stability means "strictly inside", so such a facet topples across
 * that boundary when a facet beyond it lies lower (with none lower it is
 * stable, as it exactly is), and a warning counts it. Why 1e-11: the projection carries round-off of a few
 * 1e-16 L, from the centre of mass and the facet plane; the tests move the
 * centre 1e-9 L to either side of an edge and must see stable and unstable,
 * so the tolerance must stay well below 1e-9. */
#define PD_TOL_KNIFE_REL 1e-11

/* Two probabilities tie when they differ by at most this fraction of the larger.
 * Ties decide PQS transfers (a tie does not transfer, or a symmetric part would
 * lose its symmetry) and the order of poses (ties go by normal).
 * Why 1e-4: our own round-off is a few 1e-16, but the files are coarser. The
 * sides of a 32-gon prism, printed with 9, 7 (about float32) and 6 significant
 * digits, have solid angles spread by 6e-9, 1.0e-6 and 5.5e-6 relative
 * (measured). PQS's "strictly less probable" rule is discontinuous: a tie
 * below that spread hands a symmetric part an asymmetric answer decided by how
 * its file was printed (a band of a whole side jumps to its neighbour). 1e-4
 * leaves a margin of 18 over 6-digit files. Larger: genuinely different
 * facets would stop exchanging bands; but telling two probabilities of ~0.01
 * apart by 1e-4 relative takes ~1e10 drops, so no measurement can see it. */
#define PD_TOL_PROB_TIE_REL 1e-4

/* Pose classes (src/symmetry/symmetry.c): a rotation about the centre of mass
 * maps the hull onto itself when every vertex lands within this distance
 * (times L) of a vertex; the candidate rotations are found by matching
 * distances from the centre and between two reference vertices to the same
 * accuracy, and two poses of one class must rest at heights this close.
 * Why 1e-5: a symmetric part read from a file carries the file's print noise,
 * up to 5e-7 L per coordinate for 6 significant digits (see
 * PD_TOL_PROB_TIE_REL), and its computed centre of mass a similar amount;
 * distances between two such points and the rotation they define add a few
 * of these, and a reference pair that is close to collinear with the centre
 * amplifies them a few times more: 1e-5 leaves a margin of ~5 over that. A
 * genuine asymmetry of 1e-5 L (1 um on a 10 cm part) is below what is
 * manufactured or what any drop could tell apart. Larger: features that
 * differ by a hundredth of a millimetre would be merged as symmetric.
 * Smaller: 6-digit files of symmetric parts would lose their symmetry. */
#define PD_TOL_SYMMETRY_REL 1e-5

/* --- output ----------------------------------------------------------------- */

/* Printed unit-normal components and probabilities smaller than this in
 * magnitude are written as 0: an axis-aligned normal carries round-off
 * components of ~1e-17 and they would print as noise (or as -0). 1e-12 is far
 * below any printed digit that matters (10 significant digits are printed). */
#define PD_PRINT_ZERO 1e-12

/* --- drops ------------------------------------------------------------------ */

/* At impact, every hull vertex within this height of the floor belongs to the
 * contact set handed to the (multi-contact) collision resolver. Why 1e-6: a
 * face landing flat touches with all its corners at once, and a face landing
 * within 1e-6 rad (6e-5 deg) of flat is resolved as flat, instead of as a
 * cascade of micro-collisions a few 1e-7 s apart that each cost a search.
 * Must stay above the impact search's own height tolerance (1e-9 L: the
 * lowest vertex itself may sit that high). Larger (1e-4, i.e. 0.006 deg):
 * corners genuinely apart would be struck together and the bounce would
 * change. Smaller: the cascade above. */
#define PD_TOL_CONTACT_REL 1e-6

/* Resting contact that no contact phase or compliant impact takes (hand-overs,
 * chatter; faces too with contact_time 0) is simulated as microcollisions: a
 * vertex pressed on the floor falls this far (times L), meets it at the speed
 * of that fall, is stopped dead (e = 0: a resting contact does not bounce, and
 * the Zeno cascade of ever smaller bounces that e > 0 would start is skipped)
 * and is put back onto the floor (src/sim/drop.c). Why
 * 1e-4: the cost of rocking contact is one collision per fall, so it scales
 * as 1/sqrt(this) (1e-6 made a 32-gon cap take 5000 collisions a drop); the
 * energy test adds this depth to the energy. Stopping the fall damps the
 * motion a little, so the results move with this value (docs/validation.md,
 * "Rest fall"). Larger: more damping; smaller: slower for a point or less. */
#define PD_TOL_REST_FALL_REL 1e-4

/* --- initial stationary (src/sim/montecarlo.c, src/sim/markov.c) ------------ */

/* Fewest drops started resting on each stable pose. Each row of the
 * estimated transition matrix rests on this many drops, and a transition the
 * drops never show is taken to be impossible: one of probability 0.2 is
 * missed with probability 0.8^m, 11% at m = 10 and 33% at m = 5, and a missed
 * transition can split the chain into closed classes that do not exist
 * (wrongly trapping the long-run mass). Below 10 a row is little more than a
 * guess; larger would refuse -n 2000 on parts of more than ~200 stable poses
 * (the paper's insulator cap has 98, so it gets 20 drops per pose). */
#define PD_STATIONARY_MIN_POSE_DROPS 10

/* Redrawn chains behind each stationary 95% interval (a percentile
 * interval: its ends are the 2.5% and 97.5% points of the redrawn long-run
 * probabilities). Why 1000: the usual minimum for percentile intervals
 * (Efron and Tibshirani 1993, ch. 13); each end then sits on ~25 draws, and
 * for a normal spread its own Monte Carlo error is 0.085 standard errors,
 * 4% of the interval's half-width. More costs time linearly: each redraw
 * solves the chain, O(k^3) for k poses. */
#define PD_STATIONARY_RESAMPLES 1000

/* --- limits ---------------------------------------------------------------- */

/* Largest vertex or face count a file may declare. Counts are also checked
 * against the bytes left in the file before any allocation, so a lying header
 * fails with a parse error, not an out-of-memory. 2^26 = 67M elements is ten
 * times the largest CAD meshes users feed to a pose estimator. */
#define PD_MAX_ELEMENTS (1 << 26)

/* Largest polygon a mesh face may have (vertex count of one OFF/OBJ face). */
#define PD_MAX_FACE_VERTICES 65536

/* The symmetry search tries every image of a reference pair of hull vertices
 * among the vertices at the same distances from the centre of mass: |A| x |B|
 * pairs, and checks each pair that also matches their distance apart on all
 * vertices. Past this many pairs the search is skipped with a warning and the
 * poses are not grouped (only the identity). The worst case within the limit
 * is a regular polygon prism, all of whose vertices sit at one radius: a
 * 4000-gon (8000 vertices, 6.4e7 pairs) is grouped in a fraction of a second
 * (docs/performance.md), but the scan of candidate pairs grows as the square
 * of the vertex count. Larger: the search
 * could run for minutes on a finely tessellated body of revolution. Smaller:
 * such parts of a few thousand vertices would lose their grouping for no
 * need. */
#define PD_SYMMETRY_MAX_PAIRS (1L << 26)

#endif
