"""Python's numbers against the command's output for the same part, options
and seed: static estimates to the last printed digit, drops byte for byte."""
import numpy as np
import pytest

import posedrop
from conftest import (PARTS, SHIPPED, clean, g10, g17, pose_rows, read_csv, run_cli)

END = {i: name for i, name in enumerate(posedrop.END_NAMES)}


@pytest.mark.parametrize("name,units", SHIPPED)
def test_static_equals_command(name, units):
    rows, header, _ = run_cli("--units", units, PARTS / name)
    assert header == ["pose", "nx", "ny", "nz", "area", "height", "p_qs", "p_pqs"]
    poses = posedrop.Part.from_file(PARTS / name, units=units).stable_poses()
    assert pose_rows(poses) == rows


@pytest.mark.parametrize("options,kwargs", [
    (["--topple", "edge"], dict(topple="edge")),
    (["--epsilon", "7.5"], dict(epsilon=7.5)),
    (["--epsilon", "20"], dict(epsilon=20)),
    (["--pqs-compare", "qs", "--pqs-band", "exact"], dict(pqs_compare="qs", pqs_band="exact")),
])
def test_static_options_equal_command(options, kwargs):
    rows, _, _ = run_cli(*options, PARTS / "rect_black_button.off")
    poses = posedrop.Part.from_file(PARTS / "rect_black_button.off").stable_poses(**kwargs)
    assert pose_rows(poses) == rows


def test_com_and_units_equal_command():
    rows, _, _ = run_cli("--units", "mm", "--com", "0.5,-0.25,3.1", PARTS / "hexnut.obj")
    part = posedrop.Part.from_file(PARTS / "hexnut.obj", units="mm", com=(0.5, -0.25, 3.1))
    assert pose_rows(part.stable_poses()) == rows
    assert part.com == pytest.approx([0.5e-3, -0.25e-3, 3.1e-3], rel=1e-15)


def test_facets_equal_command():
    rows, header, _ = run_cli("--facets", PARTS / "cap.off")
    assert header == ["facet", "nx", "ny", "nz", "area", "height", "p_raw", "stable", "knife",
                      "next", "rest", "pose"]
    f = posedrop.Part.from_file(PARTS / "cap.off").stable_poses().facets
    mine = [[str(i + 1), g10(clean(f.normal[i, 0])), g10(clean(f.normal[i, 1])),
             g10(clean(f.normal[i, 2])), g10(f.area[i]), g10(f.height[i]), g10(f.p_raw[i]),
             str(int(f.stable[i])), str(int(f.knife[i])), str(f.next[i] + 1), str(f.rest[i] + 1),
             str(f.pose[i] + 1)] for i in range(len(f))]
    assert mine == rows


def test_part_properties_equal_command_json():
    import json
    _, _, proc = run_cli("--format", "json", PARTS / "cap.off", check=False)
    doc = json.loads(proc.stdout)["part"]
    part = posedrop.Part.from_file(PARTS / "cap.off")
    assert [g17(x) for x in part.com] == [g17(x) for x in doc["centre_of_mass_m"]]
    assert g17(part.volume) == g17(doc["mass"]["volume_m3"])
    assert g17(part.size) == g17(doc["size_m"])
    assert part.inertia.tolist() == doc["mass"]["inertia_per_density_m5"]
    assert len(part.vertices) == doc["vertices"] and len(part.faces) == doc["triangles"]
    assert len(part.hull_facets) == doc["hull"]["facets"] == len(part.hull_normals)


@pytest.mark.parametrize("name,units", [("cap.off", "m"), ("hexnut.obj", "mm")])
def test_arrays_give_the_files_numbers(name, units):
    """Part(vertices, faces) from numpy arrays: the welded mesh of the file's
    part, handed back, gives the file's estimates to the last digit."""
    rows, _, _ = run_cli("--units", units, PARTS / name)
    part = posedrop.Part.from_file(PARTS / name, units=units)
    again = posedrop.Part(part.vertices.copy(), part.faces.astype(np.int64))
    assert pose_rows(again.stable_poses()) == rows
    # In the file's units, scaled as the readers scale.
    scale = {"m": 1.0, "mm": 1e-3}[units]
    if units != "m":
        mm = posedrop.Part(part.vertices / scale, part.faces, units=units)
        assert mm.stable_poses().p_qs == pytest.approx(part.stable_poses().p_qs, rel=1e-12)


def test_group_static_equals_command():
    rows, header, _ = run_cli("--group", "--units", "mm", PARTS / "hexnut.obj")
    poses = posedrop.Part.from_file(PARTS / "hexnut.obj", units="mm").stable_poses()
    cls = poses.classes()
    mine = []
    for c, members in enumerate(cls.members):
        first = members[0]
        n = poses.normal[first]
        mine.append([str(c + 1), g10(clean(n[0])), g10(clean(n[1])), g10(clean(n[2])),
                     g10(poses.area[first]), g10(poses.height[first]),
                     g10(clean(sum(poses.p_qs[m] for m in members))),
                     g10(clean(sum(poses.p_pqs[m] for m in members))),
                     " ".join(str(m + 1) for m in members)])
    assert header[-1] == "members"
    assert mine == rows


# -- drops -----------------------------------------------------------------

DROP_CASES = [
    # (part, units, command options, keyword arguments)
    ("cap.off", "m", ["-n", "300", "--seed", "7"], dict(n=300, seed=7)),
    ("block.stl", "mm", ["-n", "200", "--mu", "0.5", "--restitution", "0.45", "-h", "0.05",
                         "-v", "0", "--vibration", "3", "--contact-time", "0"],
     dict(n=200, mu=0.5, restitution=0.45, height=0.05, belt_speed=0, vibration=3,
          contact_time=0)),
    ("button.off", "m", ["-n", "200", "--restitution-law", "energetic", "--initial",
                         "bootstrap", "--seed", "3"],
     dict(n=200, restitution_law="energetic", initial="bootstrap", seed=3)),
    ("block.stl", "mm", ["--ci", "0.08", "-n", "50"], dict(ci=0.08, n=50)),
    ("block.stl", "mm", ["-n", "40", "--engine", "ode", "--dt", "0.0005"],
     dict(n=40, engine="ode", dt=0.0005)),
    ("block.stl", "mm", ["-n", "30", "--engine", "bullet"], dict(n=30, engine="bullet")),
]


@pytest.mark.parametrize("name,units,options,kwargs", DROP_CASES)
def test_drops_equal_command(name, units, options, kwargs):
    rows, header, _ = run_cli("--units", units, "-j", "2", *options, PARTS / name)
    assert header[-7:] == ["n", "count", "p", "ci_lo", "ci_hi", "unsettled", "partial"]
    poses = posedrop.Part.from_file(PARTS / name, units=units).stable_poses()
    drops = poses.drop(threads=1, **kwargs)
    assert pose_rows(poses, drops) == rows


def test_scene_file_and_overrides_equal_command(tmp_path):
    scene = tmp_path / "belt.scene"
    scene.write_text("# a slower belt\nheight = 0.08\nmu = 0.6\nrestitution = 0.2\n")
    rows, _, _ = run_cli("-n", "150", "--scene", scene, "--mu", "0.4", PARTS / "button.off")
    poses = posedrop.Part.from_file(PARTS / "button.off").stable_poses()
    assert pose_rows(poses, poses.drop(150, scene=scene, mu=0.4)) == rows
    # A dict of settings is the same as keywords.
    assert pose_rows(poses, poses.drop(150, scene=str(scene), **{"mu": "0.4"})) == rows


def test_trials_equal_command(tmp_path):
    trials = tmp_path / "trials.csv"
    run_cli("-n", "120", "--seed", "11", "--trials", trials, PARTS / "cap.off")
    rows, header = read_csv(trials)
    assert header == ["drop", "qw", "qx", "qy", "qz", "pose", "collisions", "time", "end",
                      "partial"]
    t = posedrop.Part.from_file(PARTS / "cap.off").drop(120, seed=11, trials=True).trials
    mine = [[str(i + 1), *map(g17, t.q0[i]), str(t.pose[i] + 1), str(t.collisions[i]),
             g10(t.time[i]), END[t.end[i]], "0"] for i in range(len(t))]
    assert mine == rows


def test_stationary_and_transitions_equal_command(tmp_path):
    out = tmp_path / "transitions.csv"
    rows, _, _ = run_cli("--units", "mm", "-n", "140", "--initial", "stationary",
                         "--transitions", out, PARTS / "block.stl")
    poses = posedrop.Part.from_file(PARTS / "block.stl", units="mm").stable_poses()
    drops = poses.drop(140, initial="stationary")
    assert pose_rows(poses, drops) == rows
    trows, _ = read_csv(out)
    k = len(poses)
    P = drops.transition_matrix
    first = drops.first_count / max(drops.first_count.sum(), 1)
    mine = [[str(i), str(j + 1),
             str((drops.first_count if i == 0 else drops.transitions[i - 1])[j]),
             g10(first[j] if i == 0 else P[i - 1, j])]
            for i in range(k + 1) for j in range(k)]
    assert mine == trows
    assert drops.first_drops + k * drops.pose_drops == drops.n


def test_grouped_drops_equal_command():
    rows, _, _ = run_cli("--group", "--units", "mm", "-n", "200", PARTS / "hexnut.obj")
    poses = posedrop.Part.from_file(PARTS / "hexnut.obj", units="mm").stable_poses()
    g = poses.drop(200).grouped()
    mine = [[str(c + 1), str(g.n), str(g.count[c]), g10(g.p[c]), g10(g.ci_lo[c]),
             g10(g.ci_hi[c]), str(g.unsettled), "0", " ".join(str(m + 1) for m in members)]
            for c, members in enumerate(g.classes.members)]
    assert mine == [[r[0], *r[8:]] for r in rows]


def test_keys_without_an_option_pass_through(tmp_path):
    """gravity has no option of its own: a scene file for the command, a
    keyword for Python, the same text to pd_scene_set."""
    scene = tmp_path / "moon.scene"
    scene.write_text("gravity = 1.62\ncontact_time = 2e-4\ninitial = bootstrap\n")
    rows, _, _ = run_cli("-n", "120", "--scene", scene, PARTS / "cap.off")
    poses = posedrop.Part.from_file(PARTS / "cap.off").stable_poses()
    drops = poses.drop(120, gravity=1.62, contact_time=2e-4, initial="bootstrap")
    assert pose_rows(poses, drops) == rows and drops.bootstrap_rounds > 0


def test_scene_ranges_pass_through():
    """Ranges (LO:HI) reach the library as text and give the command's counts
    (test_ranges_ends.py compares every range, the drawn values and the
    sensitivity)."""
    poses = posedrop.Part.from_file(PARTS / "cap.off").stable_poses()
    rows, _, _ = run_cli("-n", "150", "--mu", "0.2:0.5", "--restitution", "0.1:0.6", "--seed", "3",
                         PARTS / "cap.off")
    drops = poses.drop(150, mu="0.2:0.5", restitution="0.1:0.6", seed=3)
    assert pose_rows(poses, drops) == rows
