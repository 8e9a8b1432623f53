/* posedrop/sim.h: the dynamic estimator: Monte Carlo drops of the part on a
 * flat floor (paper, section 5).
 *
 * Each drop releases the part above the floor and follows it through flight
 * and frictional collisions until its outcome can no longer change: its total
 * energy is below the lowest energy barrier of the basin it is in, so the
 * stable pose of that basin is where it ends. Drops are independent: drop i
 * draws from its own random stream derived from (seed, i), so results do not
 * depend on the number of threads or their scheduling. */
#ifndef POSEDROP_SIM_H
#define POSEDROP_SIM_H

#include <stddef.h>
#include <stdint.h>
#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/part.h"
#include "posedrop/static.h"
#include "posedrop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum pd_restitution_law {
    PD_RESTITUTION_POISSON = 0, /* normal impulse at maximum compression times (1 + e) */
    PD_RESTITUTION_ENERGETIC    /* Stronge: restitution work = e^2 compression work */
} pd_restitution_law;

typedef enum pd_initial {
    PD_INITIAL_UNIFORM = 0, /* orientation uniform over SO(3) */
    PD_INITIAL_BOOTSTRAP,   /* the paper's: resting poses drawn from the running estimate */
    PD_INITIAL_STATIONARY   /* the long-run distribution of the estimated pose-to-pose
                               chain (see pd_sim_run) */
} pd_initial;

/* The scene parameters that take a range as well as a value, in this order
 * (the columns of --trials and the rows of a sensitivity). gravity, the
 * restitution law and the initial mode take one value each. */
typedef enum pd_scene_param {
    PD_PARAM_HEIGHT = 0,
    PD_PARAM_BELT_SPEED,
    PD_PARAM_MU,
    PD_PARAM_RESTITUTION,
    PD_PARAM_VIBRATION,
    PD_PARAM_CONTACT_TIME,
    PD_PARAM_TUMBLE,
    PD_NPARAMS
} pd_scene_param;

/* How a parameter is given. */
typedef enum pd_dist_kind {
    PD_DIST_FIXED = 0,  /* the scene field's own value, for every drop */
    PD_DIST_UNIFORM,    /* each drop draws uniformly from [lo, hi] */
    PD_DIST_LOG_UNIFORM /* each drop draws log uniformly from [lo, hi], 0 < lo:
                           for a quantity known to within a factor (the
                           contact time) */
} pd_dist_kind;

/* A parameter's distribution. lo and hi are in the field's stored unit (m,
 * m/s, rad for vibration and rad/s for tumble, s for contact_time) and obey
 * the field's range; lo <= hi, and lo == hi draws lo for every drop, the same
 * run, byte for byte, as the fixed value lo. */
typedef struct pd_dist {
    pd_dist_kind kind;
    double lo, hi;
    int auto_multiple; /* contact_time only: lo and hi are multiples of the
                          PD_CONTACT_TIME_AUTO duration of the part, 1e-3 to
                          1e3 (written 0.3x:3x) */
} pd_dist;

/* What a drop is made of. Filled by pd_scene_default, then edited. */
typedef struct pd_scene {
    double height;          /* m, lowest point of the part above the floor at release; 0.12 */
    double belt_speed;      /* m/s, horizontal velocity at release (along x); 0.05 */
    double mu;              /* Coulomb friction part-floor; 0.3 */
    double restitution;     /* coefficient of restitution e in [0, 1]; 0.3 */
    pd_restitution_law law; /* PD_RESTITUTION_POISSON */
    double vibration;       /* rad: each initial pose turned by up to this about a random axis; 1.5 deg */
    pd_initial initial;     /* PD_INITIAL_UNIFORM */
    double gravity;         /* m/s^2; 9.81 */
    double contact_time;    /* s: how long one contact takes to compress and
                               restore, a property of the materials and of the
                               part's size. With more than one vertex on the
                               floor at once or within this time, the impulse
                               simulator's impact is compliant (a Hunt-Crossley
                               law at each, with friction); one vertex alone
                               keeps the rigid law, its limit. 0: rigid
                               throughout (the paper's model).
                               PD_CONTACT_TIME_AUTO (the default): a plastic part
                               on a rubber belt, pd_contact_time_auto() */
    double tumble;          /* rad/s: the part's angular speed at release, about
                               an axis uniform over the sphere, drawn for each
                               drop (a part tipping over a belt's edge, a
                               tossed die); 0 */
    pd_dist range[PD_NPARAMS]; /* per parameter: PD_DIST_FIXED (pd_scene_default)
                               uses the field above; a range replaces it, each
                               drop drawing its own value from (seed, drop,
                               parameter), a stream apart from the drop's
                               orientation, so results do not depend on threads,
                               shards or engine, and a scene without ranges
                               runs exactly as it would without this field */
} pd_scene;

/* contact_time's default: the duration a Hertz contact of a plastic part on a
 * rubber belt takes at the drop's speed, 5e-4 s for a 1 cm cube, in
 * proportion to the part's size for geometrically similar parts (Hertz: the
 * duration goes as (m^2 / (R E^2 v))^(1/5), with the mass m from the part's
 * volume and the corner radius R ~ L: as L for similar parts;
 * pd_contact_time_auto_part). docs/contact.md. */
#define PD_CONTACT_TIME_AUTO (-1.0)

/* The duration PD_CONTACT_TIME_AUTO stands for, for a part of size L (the
 * bounding-box diagonal, m): 5e-4 s times L over a 1 cm cube's diagonal, up
 * to pi sqrt(1e-3 L / 9.81 m/s^2), the duration at which the part's weight
 * would press a contact 1e-3 of its size into the floor (it binds above
 * L = 1.2 m: 0.1 s for a 10 m part, 1.3 s for a 1000 m cube). */
PD_API double pd_contact_time_auto(double size);

/* The duration PD_CONTACT_TIME_AUTO stands for, for part: Hertz's
 * (m^2 / R)^(1/5) with the mass from the part's volume and the corner
 * radius in proportion to its size, 5e-4 s (V / 1 cm^3)^(2/5) (1.73 cm /
 * L)^(1/5), with pd_contact_time_auto's cap for its size L;
 * pd_contact_time_auto(L) for a cube, in proportion to L for geometrically
 * similar parts below the cap. 0 for a NULL part. */
PD_API double pd_contact_time_auto_part(const pd_part *part);

/* The length whose pd_contact_time_auto is the part's own,
 * pd_contact_time_auto_part(part) / pd_contact_time_auto(1): what
 * pd_scene_draw, pd_scene_quantile and pd_sim_sensitivity take as
 * part_size (the part's size for a cube). 0 for a NULL part. */
PD_API double pd_contact_time_auto_size(const pd_part *part);

PD_API void pd_scene_default(pd_scene *scene);

/* Sets one setting by name, as in a scene file or on a command line:
 * height, belt_speed, mu, restitution, restitution_law
 * (poisson|energetic), vibration (degrees), initial
 * (uniform|bootstrap|stationary), gravity, contact_time (s, or auto),
 * tumble (rad/s). A plain value sets the field and makes it fixed. Every
 * parameter of pd_scene_param also takes a range "LO:HI", optionally
 * followed by "uniform" or "log" (log uniform; the default for contact_time,
 * which spans decades, uniform for the others); contact_time's range may be
 * multiples of auto, "0.3x:3x". PD_ERR_USAGE for an unknown key, PD_ERR_PARSE
 * for a bad value, PD_ERR_RANGE for a value out of range; the scene is
 * unchanged on failure. Its ranges are those of pd_scene_check, the one
 * validator of a scene. */
PD_API pd_status pd_scene_set(pd_scene *scene, const char *key, const char *value, pd_diag *diag);

/* The name of a parameter ("height", ..., "tumble"), NULL out of range. */
PD_API const char *pd_scene_param_name(pd_scene_param param);

/* A parameter's setting as text pd_scene_set reads, in its text's unit
 * (degrees for vibration), each number the shortest text that reads back
 * to the same value: "0.3", "0.2:0.5", "0.3x:3x log", "auto". Returns buf. */
PD_API const char *pd_scene_format(const pd_scene *scene, pd_scene_param param, char *buf,
                                   size_t size);

/* Whether parameter param of scene is a range of nonzero width, so that
 * drops draw different values of it. A range of zero width is its one
 * value: the drops run as with that value fixed, byte for byte. */
PD_API int pd_scene_varies(const pd_scene *scene, pd_scene_param param);

/* Whether any parameter of scene varies (pd_scene_varies). */
PD_API int pd_scene_ranged(const pd_scene *scene);

/* The values drop `drop` of a run seeded `seed` uses, one per parameter
 * (values[PD_NPARAMS], stored units; contact_time resolved for a part of
 * auto size part_size, pd_contact_time_auto_size: never
 * PD_CONTACT_TIME_AUTO when it is ranged), and *drawn,
 * the scene with every range replaced by that drop's value (fixed). Fixed
 * parameters keep their field's value. The draw of parameter i depends on
 * (seed, drop, i) only. drawn may be NULL; scene must pass pd_scene_check. */
PD_API void pd_scene_draw(const pd_scene *scene, double part_size, uint64_t seed, long drop,
                          double values[PD_NPARAMS], pd_scene *drawn);

/* Where value v of parameter param falls in its distribution: its
 * cumulative probability in [0, 1] (0.5 for a fixed or zero-width one).
 * For a contact_time range in multiples of auto, v is in s and part_size
 * the part's pd_contact_time_auto_size. */
PD_API double pd_scene_quantile(const pd_scene *scene, pd_scene_param param, double part_size,
                                double v);

/* Reads "key = value" lines ('#' comments, blank lines) into scene, on top of
 * what it holds; a key set twice is refused. Errors name the file and line. */
PD_API pd_status pd_scene_read(const char *path, pd_scene *scene, pd_diag *diag);

/* Whether every field of a scene is one pd_scene_set would accept: height 0
 * to 1000 m, belt_speed -1000 to 1000 m/s, mu 0 to 10, restitution 0 to 1,
 * vibration 0 to pi rad (180 degrees), gravity 0.001 to 1000 m/s^2,
 * contact_time 0 to 1 s or PD_CONTACT_TIME_AUTO, tumble 0 to 10^4 rad/s, no
 * value non-zero below the smallest normal double (2.2e-308), law and
 * initial one of their enum values, and every range valid (its kind, both
 * ends in the field's range, lo <= hi, lo > 0 for log uniform, multiples of
 * auto for contact_time only). The one validator of a scene: pd_scene_set,
 * pd_sim_run and the command all use it.
 * PD_ERR_NONFINITE for a NaN or infinity, PD_ERR_RANGE for a value out of
 * range; the message names the field. pd_sim_run calls it first. */
PD_API pd_status pd_scene_check(const pd_scene *scene, pd_diag *diag);

/* How a drop ended. */
typedef enum pd_drop_end {
    PD_END_SETTLED = 0,  /* energy below its basin's barrier: outcome final */
    PD_END_TIME_LIMIT,   /* simulated time ran out: counted, never classified */
    PD_END_COLLISION_LIMIT, /* too many collisions (a Zeno-like cascade) */
    PD_END_FAILED        /* a solver could not go on: which one is the trial's
                            stage, and how its status (counted) */
} pd_drop_end;

/* Where a failed drop (PD_END_FAILED) failed; PD_STAGE_NONE for any other
 * end. The names pd_drop_stage_name gives are stable: the command prints
 * them in the end column of --trials (docs/cli.md). */
typedef enum pd_drop_stage {
    PD_STAGE_NONE = 0,
    PD_STAGE_SETTLE,        /* "settle": whether the drop is decided (energy
                               barriers, the descent map) */
    PD_STAGE_FLIGHT,        /* "flight": the torque-free flight between contacts */
    PD_STAGE_IMPACT_SEARCH, /* "impact_search": the time of the next impact */
    PD_STAGE_COLLISION,     /* "collision": the rigid frictional impulse law */
    PD_STAGE_COMPLIANT,     /* "compliant": a compliant impact */
    PD_STAGE_CONTACT_PHASE, /* "contact_phase": lasting contact on a vertex or an edge */
    PD_STAGE_ENGINE_RESET,  /* "engine_reset": the stepping engine refused the release */
    PD_STAGE_ENGINE_STEP,   /* "engine_step": a step of the stepping engine (ODE's
                               internal error, a non-finite state) */
    PD_STAGE_COUNT
} pd_drop_stage;

/* "settle", "flight", ... as above; "none" for PD_STAGE_NONE, "unknown" out
 * of range. Never NULL. */
PD_API const char *pd_drop_stage_name(pd_drop_stage stage);

typedef enum pd_engine_kind {
    PD_ENGINE_IMPULSE = 0, /* posedrop's own: closed-form flight, frictional impulses */
    PD_ENGINE_ODE,         /* the Open Dynamics Engine, fixed step */
    PD_ENGINE_BULLET       /* Bullet Physics, fixed step */
} pd_engine_kind;

/* One state of a traced drop (pd_sim_options.trace), the same fields for
 * every engine, so that two engines' runs of the same drop can be laid side
 * by side. The orientation is that of the part's principal frame (the
 * engines' body frame), whose origin is the centre of mass. */
typedef struct pd_trace_row {
    double t;          /* s since the release */
    double x[3];       /* centre of mass, world, m (z up, the floor at 0) */
    double q[4];       /* principal frame -> world, w x y z */
    double v[3];       /* centre of mass velocity, m/s */
    double w[3];       /* angular velocity, world frame, rad/s */
    double energy;     /* kinetic plus potential energy over the weight: the
                          height the centre of mass could reach, m */
    double depth;      /* the lowest hull vertex's depth below the floor, m
                          (negative: its height above it) */
    int contacts;      /* hull vertices below the floor or within
                          PD_TOL_REST_FALL_REL of the size above it (the
                          depth a soft contact lets a resting part sink) */
    const char *event; /* what the state follows: "release", "step" (a
                          stepping engine's), "flight" (the impulse engine's
                          closed-form flight or rest step), "impact",
                          "compliant" (a compliant impact's end), "phase" (a
                          contact phase's end), "end" */
} pd_trace_row;

/* Defaults after the field's meaning; pd_sim_run refuses values outside the
 * stated ranges. */
typedef struct pd_sim_options {
    pd_engine_kind engine;  /* PD_ENGINE_IMPULSE */
    double dt;              /* s, fixed step of ODE and Bullet, at most 0.01; 0
                               (automatic): 20 steps per contact time, at most
                               a tenth of the thickness travelled per step
                               (docs/engines.md) */
    long ndrops;            /* drops to run (with ci_halfwidth: at least these), >= 0; 2000 */
    uint64_t seed;          /* 1 */
    int threads;            /* 0: all cores; at most 256 are used */
    double ci_halfwidth;    /* in (0, 0.5): keep dropping until every pose's 95%
                               interval is at most this wide on each side; 0 */
    long max_drops;         /* cap for ci_halfwidth runs, >= 0 (ndrops run
                               even when more): the run stops there whether
                               or not the intervals are that narrow; 10^7 */
    double time_limit;      /* s of simulated time per drop, > 0, or
                               PD_TIME_LIMIT_AUTO (0, the default):
                               pd_time_limit_auto for the part and scene,
                               which the impulse engine extends by the time
                               a drop spins on one vertex under drilling
                               friction (a top), up to the longest such
                               spin the drop's energy allows
                               (docs/limits.md, "Tops") */
    int max_collisions;     /* per drop, >= 1; 100000 */
    int keep_trials;        /* 1: fill result->trials (one record per drop); 0 */
    pd_cancel_flag *cancel; /* may be NULL; see below */
    int nshards;            /* 0: the whole run. N >= 1: only the drops of one
                               shard of N (pd_shard_of), to be summed with the
                               other shards' by pd_sim_result_add; not with
                               ci_halfwidth or PD_INITIAL_BOOTSTRAP, whose later
                               drops depend on earlier outcomes */
    int shard;              /* 0 .. nshards - 1: which shard; 0 */
    void (*progress)(void *user, long done, long total); /* may be NULL: called
                               from the calling thread after each of its drops
                               with the drops done so far (of the shard) and
                               those planned; must return quickly */
    void *progress_user;
    double effect_halfwidth; /* in (0, 0.5): with a scene parameter that
                               varies and keep_trials, keep dropping (after
                               ndrops, in rounds sized from the widest
                               interval so far, up to max_drops) until every
                               effect's 95% interval (pd_sim_sensitivity, per
                               pose) is at most this wide on each side; 0 */
    const int *effect_class_of; /* NULL, or with effect_halfwidth the effects
                               are those of effect_nclasses classes of poses
                               (pd_pose_classes' class_of, one per pose) */
    int effect_nclasses;
    /* May be NULL. Else drop trace_drop (numbered as in the run, >= 0) calls
     * it with every state it passes through, in order, from the thread
     * running that drop: a stepping engine's after every step, the impulse
     * engine's at every event (docs/engines.md, "Tracing a drop"). */
    void (*trace)(void *user, const pd_trace_row *row);
    void *trace_user;
    long trace_drop;        /* 0 */
    int stationary_by_class; /* 1 (PD_INITIAL_STATIONARY only; pd_sim_run, not
                               shards): the chain's states are the classes of
                               poses a rotation of the part maps onto each other
                               (pd_pose_classes) instead of the poses; see
                               pd_sim_run. 0 */
} pd_sim_options;

/* Cancelling a run: point options->cancel at an atomic_int holding 0 and
 * store non-zero into it (atomic_store) from any thread, or from a signal
 * handler (atomic_int is lock-free wherever posedrop builds, which C11 asks
 * of an object a handler touches). The drops under way stop too (each reads
 * the flag between its steps, whatever the part), no new one starts, and
 * pd_sim_run returns PD_OK with result->partial set and the first
 * result->n drops of the run counted, each whole (a drop stopped part way is
 * not counted, nor any drop after it), each the drop it would be in a full
 * run, whatever the thread count. The flag is only read, never reset: clear
 * it before the next run. */

/* time_limit's default: each drop's limit is pd_time_limit_auto's. */
#define PD_TIME_LIMIT_AUTO 0.0

/* The automatic limit, in units of the drop's own times: the part's natural
 * time sqrt(L/g) (how long it takes to topple over its own size) plus the
 * fall from the drop height, sqrt(2 h / g). The slowest drops measured to
 * rest on ordinary parts (cubes, boxes and coins from 1 mm to 10 m, the
 * shipped caps, on all three engines) took 37 of these units; 100 leaves
 * them a margin of more than 2.5 (docs/limits.md). For a 1 cm cube dropped
 * 0.12 m it is 19.8 s; for a 1000 m cube, 1345 s. */
#define PD_TIME_LIMIT_UNITS 100.0

/* PD_TIME_LIMIT_UNITS (sqrt(size / g) + sqrt(2 height / g)) in s, for a part
 * of that size (m, the bounding-box diagonal, pd_part.size) dropped in that
 * scene (its height, the top of its range if it has one, and gravity);
 * scene NULL: the default scene's. */
PD_API double pd_time_limit_auto(double size, const pd_scene *scene);

PD_API void pd_sim_options_default(pd_sim_options *options);

/* Whether every field of options is within the range given with it (the
 * engine one of pd_engine_kind's, shard below nshards, no ci_halfwidth with
 * shards): PD_ERR_NONFINITE for a NaN or infinity, PD_ERR_USAGE otherwise,
 * the message naming the field. Whether the engine is linked is
 * pd_engine_available's question. pd_sim_run calls it first. */
PD_API pd_status pd_sim_options_check(const pd_sim_options *options, pd_diag *diag);

/* 1 if pd_sim_run can run that engine in this program: the impulse engine and
 * ODE always, Bullet once pd_bullet_register (posedrop/bullet.h) was called. */
PD_API int pd_engine_available(pd_engine_kind engine);

/* The table behind a stepping engine; private to posedrop's libraries. */
typedef struct pd_engine pd_engine;

/* For posedrop's own engine libraries, not for programs: pd_bullet_register
 * calls it to hand over Bullet's table. version is the PD_VERSION_STRING the
 * engine library was built with; the table's layout is private, so another
 * version than this library's gets PD_ERR_UNAVAILABLE. */
PD_API pd_status pd_engine_register(pd_engine_kind kind, const pd_engine *engine,
                                    const char *version);

/* One drop, for --trials. */
typedef struct pd_trial {
    double q0[4];       /* initial orientation, unit quaternion (w, x, y, z), part to world */
    int pose;           /* index into the static result's poses, -1 if not settled */
    int collisions;     /* impulses applied (impulse engine; 0 for stepping engines) */
    double time;        /* simulated s */
    pd_drop_end end;
    pd_drop_stage stage; /* PD_END_FAILED: where it failed, else PD_STAGE_NONE */
    pd_status status;    /* PD_END_FAILED: how (e.g. PD_ERR_NO_CONVERGENCE), else PD_OK */
    double param[PD_NPARAMS]; /* the scene values this drop used (pd_scene_draw) */
} pd_trial;

typedef struct pd_sim_result {
    int nposes;             /* as in the static result */
    long n;                 /* drops run */
    long *count;            /* per pose: drops that settled there */
    double *p, *ci_lo, *ci_hi; /* count / n and its 95% Wilson interval */
    long unsettled;         /* drops that hit a limit or failed (not in any count):
                               the sum of the next three */
    long time_limited;      /* drops that ended at the time limit */
    long collision_limited; /* drops that ended at the collision limit */
    long failed;            /* drops that failed (PD_END_FAILED) */
    long first_failed;      /* the first failed drop's number in the run (from 0),
                               -1 if none */
    pd_drop_stage failed_stage; /* where it failed */
    pd_status failed_status;    /* and how */
    double time_limit;      /* s: the limit the drops ran with (options->time_limit,
                               or pd_time_limit_auto's) */
    long energy_gain;       /* collisions that would have added energy: under
                               Poisson's law with friction (resolved with the
                               energetic law instead), or by a compliant impact's
                               step error (its velocities scaled back) */
    long fallbacks;         /* collisions whose sliding integration could not
                               finish (a stiff approach to sticking), resolved
                               by stopping the contact within the friction cone */
    long collisions;        /* over all drops */
    int partial;            /* 1 if cancelled before the requested drops ran */
    int bootstrap_rounds;   /* rounds run (PD_INITIAL_BOOTSTRAP) */
    double stationarity;    /* bootstrap: total-variation distance between the
                               last rounds' initial and final distributions */
    pd_trial *trials;       /* n records when options->keep_trials, else NULL */
    /* PD_INITIAL_STATIONARY only (otherwise 0 and NULL): */
    long first_drops;       /* drops that start from uniform orientations */
    long pose_drops;        /* drops that start resting on each pose. Interleaved
                               from the start: drop i < (nposes + 1) pose_drops
                               is uniform when i mod (nposes + 1) is 0 and rests
                               on pose i mod (nposes + 1) - 1 otherwise; the
                               drops after those are uniform */
    long *first_count;      /* nposes: uniform drops that settled in each pose (mu0's counts) */
    long *transitions;      /* nposes * nposes, row-major: [i * nposes + j] = drops started
                               resting on pose i that settled in pose j */
    int closed_classes;     /* closed communicating classes of the estimated chain that
                               mu0 reaches (1: pi is its unique stationary distribution);
                               0: p is count / n with Wilson intervals, because the counts
                               do not define the chain (a cancelled run, or a pose the
                               chain reaches without one settled drop started on it) */
    double stationary_shift; /* total variation between mu0 and pi */
    int chain_states;       /* the chain's states: nposes, or with
                               options->stationary_by_class the classes of
                               symmetric poses; first_count, transitions and
                               pose_drops are over them (read nposes for states
                               where the field above says nposes) */
    int *chain_class_of;    /* with stationary_by_class: each pose's state
                               (nposes entries); else NULL */
    uint64_t seed;          /* the run's seed (options->seed) */
    int nshards, shard;     /* as in the options: a shard's result holds its own
                               drops only; trials[t] is the run's drop
                               shard + t * nshards; p is count / n with Wilson
                               intervals even for PD_INITIAL_STATIONARY, whose
                               chain is estimated once the shards are summed */
    uint64_t run_fingerprint; /* the run it belongs to: a hash of the part and
                               pose table (the static result's), the scene and
                               the options that change outcomes (not threads,
                               keep_trials or the shard); pd_sim_result_add
                               refuses a shard whose own differs */
    /* A sum (pd_sim_result_new): the split of the shards added (their
     * nshards, 1 for whole runs; 0 before the first) and which of them were
     * added, so that pd_sim_result_add refuses a shard added twice or one of
     * another split, either of which would count drops twice. The library's
     * bookkeeping: read it, never write it. NULL in any other result. */
    int added_nshards;
    unsigned char *added;
} pd_sim_result;

/* Drop i (from 0) of a sharded run belongs to shard i mod nshards: every
 * shard gets the same mix of drops (for PD_INITIAL_STATIONARY, of phases and
 * starting poses), so shards take about as long as each other. 0 when
 * nshards < 1 (the whole run), -1 for a negative drop. */
PD_API int pd_shard_of(long drop, int nshards);

/* How many of a run's ndrops drops shard (0-based) of nshards runs: ndrops
 * when nshards < 1, 0 for a shard outside 0 .. nshards - 1 or a negative
 * ndrops. */
PD_API long pd_shard_drops(long ndrops, int shard, int nshards);

/* Runs the drops. static_result gives the pose table the outcomes map onto
 * (same numbering as its poses). options and scene may be NULL (defaults).
 * A scene with ranges has each drop draw its own values (pd_scene_draw, kept
 * in its trial record): p is then over the ranges; posedrop/sensitivity.h
 * says which parameter moves which pose. A contact_time range whose high end
 * is above 1 s for this part is PD_ERR_RANGE.
 *
 * PD_INITIAL_STATIONARY estimates the belt's pose-to-pose chain: with k
 * poses, m = ndrops / (k + 1) drops start resting on each pose (on its facet,
 * turned at random about the vertical, with the scene's vibration, as the
 * bootstrap starts them) and give the rows of the transition matrix P; the
 * other ndrops - k m drops (at least m) start from uniform orientations and
 * give mu0, the distribution of a first drop. p is then the long-run
 * distribution pi = lim (1/T) sum_{t<T} mu0 P^t, exact (closed classes,
 * their stationary distributions, absorption from mu0), and ci_lo, ci_hi its
 * 95% parametric-bootstrap percentile interval (PD_STATIONARY_RESAMPLES
 * redraws of mu0 and every row of P, each multinomial from its own counts);
 * count and n still count the drops, over both phases. Even drops for every
 * pose because every row of P enters pi; uniform drops as many because mu0
 * matters only when P has several closed classes. m must be at least
 * PD_STATIONARY_MIN_POSE_DROPS, and ci_halfwidth 0 (the split is fixed in
 * advance): PD_ERR_USAGE otherwise. A cancelled run gives pi of the drops run
 * when they define the chain, else count / n (closed_classes = 0).
 *
 * With options->stationary_by_class the chain's states are the classes of
 * pd_pose_classes: a rotation that maps the part onto itself maps a drop from
 * one pose of a class onto a drop from another, so every pose of a class
 * moves to each class with the same probabilities, and the chain of classes
 * has as its long-run distribution the pose chain's summed over the classes
 * (the chain is lumpable: Kemeny and Snell 1960, Finite Markov Chains, 6.3).
 * With K classes, m = ndrops / (K + 1) drops start resting on each class, on
 * its poses in turn, and the minimum is (K + 1) PD_STATIONARY_MIN_POSE_DROPS:
 * the insulator cap's 98 poses in 5 classes need 60 drops instead of 990,
 * and every row rests on ndrops / (K + 1) drops instead of ndrops / 99.
 * p of a pose is its class's share divided equally among the class's poses
 * (equal by the same symmetry), as are ci_lo and ci_hi.
 *
 * Every field of scene and options is checked before any drop runs (scene:
 * pd_scene_check; options: the ranges given with each field). Returns
 * PD_ERR_NONFINITE (a NaN or infinity in scene or options), PD_ERR_RANGE (a
 * scene value out of range), PD_ERR_USAGE (NULL argument, an option out of
 * range), PD_ERR_UNAVAILABLE (PD_ENGINE_BULLET without pd_bullet_register),
 * PD_ERR_NOMEM; diag's message names the field. A cancelled run returns PD_OK
 * with result->partial set. On success *result is owned by the caller. */
PD_API pd_status pd_sim_run(const pd_part *part, const pd_static_result *static_result,
                            const pd_scene *scene, const pd_sim_options *options,
                            pd_sim_result **result, pd_diag *diag);

PD_API void pd_sim_result_free(pd_sim_result *result);

/* Summing shards. pd_sim_result_new makes an empty result for the whole run
 * of static_result's poses that scene and options describe (its nshards
 * ignored);
 * pd_sim_result_add adds one shard's counts to it (drops, counts, unsettled,
 * collisions and corrections, the stationary estimator's counts; partial if
 * the shard was); pd_sim_result_finish then computes p and its intervals from
 * the sums exactly as pd_sim_run does, so the shards 0..N-1 of a run summed
 * give the unsharded run's result, byte for byte (trials aside: none are
 * kept). scene and options may be NULL (defaults). PD_ERR_USAGE for a NULL
 * static_result, result, sum or shard, or a shard of another run (its
 * run_fingerprint: another part, pose table, scene, seed or drop count), a
 * shard added before, one of another split (another nshards) or sum itself
 * (each would count drops twice), PD_ERR_NOMEM. */
PD_API pd_status pd_sim_result_new(const pd_static_result *static_result,
                                   const pd_scene *scene, const pd_sim_options *options,
                                   pd_sim_result **result, pd_diag *diag);
PD_API pd_status pd_sim_result_add(pd_sim_result *sum, const pd_sim_result *shard,
                                   pd_diag *diag);
PD_API pd_status pd_sim_result_finish(pd_sim_result *result, pd_diag *diag);

#ifdef __cplusplus
}
#endif
#endif
