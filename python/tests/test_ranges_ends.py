"""Scene ranges, tumble, how each drop ended, the time limit and the
sensitivity: Python's numbers against the command's files and messages for
the same part, options and seed, compared as the command prints them."""
import math

import numpy as np
import pytest

import posedrop
from posedrop import InputError, Status
from conftest import PARTS, g10, g17, pose_rows, read_csv, run_cli

CAP = PARTS / "cap.off"

# Every parameter that takes a range, each in the form the command and the
# scene text take: -h, --mu, --vibration (degrees, as --trials prints it),
# --contact-time in multiples of auto (log uniform), --tumble.
RANGES = [("-h", "height", "0.08:0.16"), ("--mu", "mu", "0.2:0.5"),
          ("--vibration", "vibration", "1:3"), ("--contact-time", "contact_time", "0.3x:3x"),
          ("--tumble", "tumble", "0:20")]


def range_args():
    return [x for option, _, value in RANGES for x in (option, value)]


def range_kwargs():
    return {key: value for _, key, value in RANGES}


def trial_rows(t):
    """The rows of --trials (write_trials in src/cli/command.c) from Python's arrays, of a
    whole run (partial 0)."""
    return [[str(i + 1), *map(g17, t.q0[i]), str(t.pose[i] + 1), str(t.collisions[i]),
             g10(t.time[i]), t.end_text[i], *(g17(v[i]) for v in t.params.values()),
             "0"]
            for i in range(len(t))]


def sensitivity_rows(s):
    """The rows of --sensitivity FILE (write_sensitivity in src/cli/command.c)."""
    g6 = "%.6g".__mod__
    def interaction(i):
        if not s.interacts[i]:
            return [""] * 7
        return [s.interacts[i], *(g6(getattr(s, c)[i]) for c in (
            "effect_in_low", "effect_in_middle", "effect_in_high", "interaction",
            "interaction_lo", "interaction_hi"))]
    return [[str(s.pose[i] + 1), s.parameter[i], g6(s.effect[i]), g6(s.effect_lo[i]),
             g6(s.effect_hi[i]), str(s.n_low[i]), g10(s.p_low[i]),
             g10(s.p_low_lo[i]), g10(s.p_low_hi[i]), str(s.n_high[i]), g10(s.p_high[i]),
             g10(s.p_high_lo[i]), g10(s.p_high_hi[i]), g6(s.index[i]), g6(s.index_lo[i]),
             g6(s.index_hi[i]), *interaction(i), "0"] for i in range(len(s))]


@pytest.fixture(scope="module")
def ranged_run(tmp_path_factory):
    """One ranged run of the command and of Python: 150 drops of the cap."""
    d = tmp_path_factory.mktemp("ranged")
    trials, sens = d / "trials.csv", d / "sensitivity.csv"
    rows, _, _ = run_cli("-n", "150", "--seed", "3", *range_args(), "--trials", trials,
                         "--sensitivity", sens, CAP)
    poses = posedrop.Part.from_file(CAP).stable_poses()
    drops = poses.drop(150, seed=3, trials=True, **range_kwargs())
    return poses, drops, rows, read_csv(trials), read_csv(sens)


def test_ranged_counts_and_drawn_values_equal_command(ranged_run):
    poses, drops, rows, (trows, theader), _ = ranged_run
    assert pose_rows(poses, drops) == rows
    names = [key for _, key, _ in RANGES]
    assert theader[9:-1] == names and list(drops.trials.params) == names
    assert trial_rows(drops.trials) == trows
    # Each drop drew its own values, inside its range.
    for _, key, text in RANGES:
        v = drops.trials.params[key]
        assert len(np.unique(v)) == len(v)
        if "x" not in text:
            lo, hi = map(float, text.split(":"))
            assert v.min() >= lo and v.max() <= hi


def test_sensitivity_equals_command(ranged_run):
    _, drops, _, _, (srows, sheader) = ranged_run
    s = drops.sensitivity()
    assert sheader == ["pose", "parameter", "effect", "effect_lo", "effect_hi", "n_low", "p_low",
                       "p_low_lo", "p_low_hi", "n_high", "p_high", "p_high_lo", "p_high_hi",
                       "index", "index_lo", "index_hi", "interacts", "effect_in_low",
                       "effect_in_middle", "effect_in_high", "interaction", "interaction_lo",
                       "interaction_hi", "partial"]
    assert s.params == [key for _, key, _ in RANGES] and s.nposes == len(drops)
    assert s.n == drops.n - drops.unsettled
    assert sensitivity_rows(s) == srows


def test_grouped_sensitivity_equals_command(tmp_path):
    sens = tmp_path / "sensitivity.csv"
    rows, _, _ = run_cli("--group", "--units", "mm", "-n", "120", "--mu", "0.2:0.6",
                         "--restitution", "0.1:0.5", "--sensitivity", sens, PARTS / "hexnut.obj")
    poses = posedrop.Part.from_file(PARTS / "hexnut.obj", units="mm").stable_poses()
    g = poses.drop(120, mu="0.2:0.6", restitution="0.1:0.5", trials=True).grouped()
    srows, _ = read_csv(sens)
    s = g.sensitivity()
    assert s.nposes == len(g.classes) and sensitivity_rows(s) == srows
    assert [r[9] for r in rows] == [str(c) for c in g.count]


def test_sensitivity_needs_trials_and_ranges():
    poses = posedrop.Part.from_file(CAP).stable_poses()
    with pytest.raises(InputError) as e:
        poses.drop(40, mu="0.2:0.5").sensitivity()
    assert e.value.status == Status.ERR_USAGE
    # No range: no rows (the command refuses --sensitivity there).
    s = poses.drop(40, trials=True).sensitivity()
    assert s.params == [] and len(s) == 0 and s.index.shape == (0,)


def test_zero_width_range_is_the_fixed_value():
    """A range of zero width runs byte for byte as the fixed value."""
    poses = posedrop.Part.from_file(CAP).stable_poses()
    a = poses.drop(150, seed=7, mu="0.4:0.4", trials=True)
    b = poses.drop(150, seed=7, mu=0.4, trials=True)
    assert np.array_equal(a.count, b.count)
    assert np.array_equal(a.trials.q0, b.trials.q0) and np.array_equal(a.trials.time, b.trials.time)
    assert np.all(a.trials.params["mu"] == 0.4) and b.trials.params == {}


def test_tumble_equals_command():
    rows, _, _ = run_cli("-n", "150", "--tumble", "8", CAP)
    poses = posedrop.Part.from_file(CAP).stable_poses()
    drops = poses.drop(150, tumble=8)
    assert pose_rows(poses, drops) == rows
    # Tumble moves outcomes: the same seed without it gives other counts.
    assert not np.array_equal(drops.count, poses.drop(150).count)
    _, _, proc = run_cli("-n", "10", "--tumble", "20000", CAP, check=False)
    assert proc.returncode == 2
    with pytest.raises(InputError) as e:
        poses.drop(10, tumble=20000)
    assert e.value.status == Status.ERR_RANGE and "tumble" in str(e.value)


def unsettled_line(drops, path):
    """The command's stderr line on drops that did not settle
    (print_unsettled in src/cli/command.c), time and collision limits only."""
    parts = []
    if drops.time_limited:
        parts.append(" %d at the time limit (%.6g s simulated; --time-limit)"
                     % (drops.time_limited, drops.time_limit))
    if drops.collision_limited:
        parts.append(" %d at the collision limit" % drops.collision_limited)
    total = ("" if drops.transitions is not None
             else " (p sums to %.4g, not 1)" % ((drops.n - drops.unsettled) / drops.n))
    return "posedrop: %s: %d of %d drops did not settle and are in no count%s:%s" % (
        path, drops.unsettled, drops.n, total, ",".join(parts))


def test_ends_and_time_limit_equal_command(tmp_path):
    trials = tmp_path / "trials.csv"
    rows, _, proc = run_cli("-n", "60", "--seed", "5", "--time-limit", "0.3", "--trials", trials,
                            CAP)
    poses = posedrop.Part.from_file(CAP).stable_poses()
    drops = poses.drop(60, seed=5, time_limit=0.3, trials=True)
    assert pose_rows(poses, drops) == rows
    assert trial_rows(drops.trials) == read_csv(trials)[0]
    assert drops.time_limit == 0.3 and drops.time_limited > 0
    assert unsettled_line(drops, CAP) in proc.stderr.splitlines()
    ends = list(drops.trials.end_text)
    assert drops.time_limited == ends.count("time_limit")
    assert drops.n - drops.unsettled == ends.count("settled") == drops.count.sum()
    assert drops.collision_limited == drops.failed == 0 and drops.first_failed == -1


def test_collision_limit_is_counted_and_named():
    drops = posedrop.Part.from_file(CAP).drop(60, max_collisions=3, trials=True)
    ends = list(drops.trials.end_text)
    assert drops.collision_limited == ends.count("collision_limit") > 0
    assert drops.unsettled == drops.time_limited + drops.collision_limited + drops.failed
    stopped = drops.trials.end == posedrop.END_NAMES.index("collision_limit")
    assert np.all(drops.trials.pose[stopped] == -1) and np.all(drops.trials.stage == 0)


def auto_limit(size, height, g=9.81):
    """PD_TIME_LIMIT_UNITS (sqrt(L / g) + sqrt(2 h / g)), include/posedrop/sim.h."""
    return 100.0 * (math.sqrt(size / g) + math.sqrt(2 * height / g))


def test_auto_time_limit():
    part = posedrop.Part.from_file(CAP)
    auto = part.drop(20).time_limit
    assert part.drop(20, time_limit="auto").time_limit == auto
    # The closed form of its header, to rounding (a few operations in double).
    assert auto == pytest.approx(auto_limit(part.size, 0.12), rel=1e-12)
    # A height range: the top of the range.
    ranged = part.drop(20, height="0.08:0.16").time_limit
    assert ranged == pytest.approx(auto_limit(part.size, 0.16), rel=1e-12)


@pytest.mark.parametrize("value,status", [(0, Status.ERR_RANGE), (-1.0, Status.ERR_RANGE),
                                          ("soon", Status.ERR_USAGE),
                                          (float("nan"), Status.ERR_NONFINITE)])
def test_bad_time_limits(value, status):
    with pytest.raises(InputError) as e:
        posedrop.Part.from_file(CAP).drop(10, time_limit=value)
    assert e.value.status == status and "time_limit" in str(e.value)


def test_failed_end_words_are_the_documented_ones():
    """No public input makes a drop fail (tests/unit/test_sim.c reaches one
    through the drop loop), so the words of failed:STAGE:STATUS are checked
    against the stable names docs/cli.md gives for the end column."""
    from posedrop import _api
    assert _api._STAGE_NAMES[1:] == ("settle", "flight", "impact_search", "collision",
                                     "compliant", "contact_phase", "engine_reset", "engine_step")
    words = {s: _api._STATUS_WORDS[s] for s in (Status.ERR_NO_CONVERGENCE, Status.ERR_NONFINITE,
                                                Status.ERR_NOMEM, Status.ERR_INTERNAL,
                                                Status.ERR_USAGE, Status.ERR_RANGE)}
    assert list(words.values()) == ["no_convergence", "non_finite_number", "out_of_memory",
                                    "internal_error", "invalid_argument", "value_out_of_range"]


def test_no_failure_has_no_failed_stage_or_status():
    drops = posedrop.Part.from_file(CAP).drop(30, seed=2, time_limit=0.3)
    assert drops.failed == 0 and drops.first_failed == -1 and drops.time_limited > 0
    assert drops.failed_stage is None and drops.failed_status is None
    # The library's pd_sim_result fields, as the binding hands them over.
    raw = drops._h.arrays()
    assert raw["failed_stage"] == 0 and raw["failed_status"] == Status.OK
    assert drops.grouped().failed_stage is None


class _FailingHandle:
    """The arrays of a real run with drop k marked failed at stage and
    status, as the library records one (no public input makes a drop fail:
    see test_failed_end_words_are_the_documented_ones)."""

    def __init__(self, handle, k, stage, status):
        self.d = dict(handle.arrays())
        self.d.update(failed=1, unsettled=self.d["unsettled"] + 1, first_failed=k,
                      failed_stage=stage, failed_status=status)
        for key, value in (("trial_end", posedrop.END_NAMES.index("failed")),
                           ("trial_stage", stage), ("trial_status", status),
                           ("trial_pose", -1)):
            column = bytearray(self.d[key])
            column[4 * k:4 * k + 4] = np.int32(value).tobytes()
            self.d[key] = bytes(column)

    def arrays(self):
        return self.d


@pytest.mark.parametrize("stage,status,words", [
    (2, Status.ERR_NO_CONVERGENCE, ("flight", "no_convergence")),
    (8, Status.ERR_NONFINITE, ("engine_step", "non_finite_number"))])
def test_failed_stage_and_status_name_the_first_failed_drop(stage, status, words):
    poses = posedrop.Part.from_file(CAP).stable_poses()
    real = poses.drop(20, seed=3, trials=True)
    drops = posedrop.Drops(poses, _FailingHandle(real._h, 7, stage, int(status)))
    assert (drops.failed_stage, drops.failed_status) == words
    # The words of that drop's end in the trials (--trials' end column).
    assert drops.trials.end_text[drops.first_failed] == "failed:%s:%s" % words
    assert drops.failed == list(drops.trials.end_text).count("failed:%s:%s" % words)
