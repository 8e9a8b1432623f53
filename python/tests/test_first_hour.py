"""What a new user meets first: the command's warnings as Python warnings
(a part in millimetres read as metres, drops that did not settle), refusals
in Python's words, and a progress callback that ends at the total."""
import warnings

import numpy as np
import pytest

import posedrop
from conftest import PARTS

# The cube of side 10 (a part in millimetres read as metres: 17.3 m across).
CUBE_V = np.array([[x, y, z] for x in (0, 10) for y in (0, 10) for z in (0, 10)], float)
CUBE_F = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                   [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]])[:, ::-1]


def test_millimetres_read_as_metres_warn_with_the_units_to_give():
    with pytest.warns(posedrop.UnitsWarning, match=r"the part is 17.3 m across; if the "
                      r"coordinates are in millimetres, pass units='mm'") as w:
        posedrop.Part(CUBE_V, CUBE_F)
    assert w[0].filename == __file__  # the user's line, not the package's
    with pytest.warns(posedrop.UnitsWarning, match=r"block.stl: the part is 45.8 m across"):
        posedrop.Part.from_file(PARTS / "block.stl")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the right unit: silent
        posedrop.Part(CUBE_V, CUBE_F, units="mm")
        posedrop.Part.from_file(PARTS / "block.stl", units="mm")
    # A part in metres read as millimetres: too small, metres suggested.
    with pytest.warns(posedrop.UnitsWarning, match=r"0.0354 mm across; if the coordinates are "
                      r"in metres, pass units='m'"):
        posedrop.Part.from_file(PARTS / "cap.off", units="mm")
    assert issubclass(posedrop.UnitsWarning, posedrop.PosedropWarning)


def test_from_trimesh_warns_too():
    trimesh = pytest.importorskip("trimesh")
    with pytest.warns(posedrop.UnitsWarning, match="45.8 m across") as w:
        posedrop.Part.from_trimesh(trimesh.load(PARTS / "block.stl"))
    assert w[0].filename == __file__
    with pytest.raises(posedrop.InputError, match=r"expected a trimesh.Trimesh .*got Scene: "
                       r"a trimesh.Scene holds several meshes"):
        posedrop.Part.from_trimesh(trimesh.Scene([trimesh.creation.box((0.01, 0.01, 0.01))]))


def test_unsettled_drops_warn_that_p_no_longer_sums_to_one():
    cap = posedrop.Part.from_file(PARTS / "cap.off")
    with pytest.warns(posedrop.PosedropWarning, match=r"^6 of 6 drops did not settle and are "
                      r"in no count \(p sums to 0, not 1\): 6 at the time limit \(0.05 s") as w:
        d = cap.drop(6, time_limit=0.05)
    assert w[0].filename == __file__
    assert d.unsettled == 6 and d.p.sum() == 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = cap.drop(6)
    assert d.unsettled == 0


def test_zero_drops_refused_as_the_command_refuses_them():
    cap = posedrop.Part.from_file(PARTS / "cap.off")
    for n in (0, -3):
        with pytest.raises(posedrop.InputError, match="n: expected a number of drops of at least 1"):
            cap.drop(n)


def test_progress_ends_at_the_total():
    cap = posedrop.Part.from_file(PARTS / "cap.off")
    calls = []
    cap.drop(120, threads=2, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (120, 120)
    assert all(a <= b for a, b in zip(calls, calls[1:]))


def test_sensitivity_without_records_names_the_python_argument():
    cap = posedrop.Part.from_file(PARTS / "cap.off")
    d = cap.drop(10, mu="0.2:0.5")
    for drops in (d, d.grouped()):
        with pytest.raises(posedrop.InputError) as e:
            drops.sensitivity()
        assert "trials=True" in str(e.value) and "pd_" not in str(e.value)
