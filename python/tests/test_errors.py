"""Errors: every input the command refuses raises InputError (a ValueError)
with the library's status and message; none crashes."""
import numpy as np
import pytest

import posedrop
from posedrop import InputError, Status
from conftest import PARTS, run_cli

CUBE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                   [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float) * 0.01
CUBE_F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                   [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])

# Files the command refuses with exit 2: (name, content).
BAD_FILES = [
    ("missing_coord.off", "OFF\n4 4 0\n0 0 0\n1 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n"),
    ("bad_index.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 9\n3 0 1 3\n3 0 2 3\n3 1 2 3\n"),
    ("nan.off", "OFF\n4 4 0\n0 0 0\nnan 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"),
    ("truncated.off", "OFF\n8 12 0\n0 0 0\n"),
    ("flat.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"),
    ("open.off", "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n"),
    ("garbage.stl", "\x00\x01\x02 not a mesh at all"),
    ("empty.obj", ""),
    ("words.obj", "v 0 0 0\nv 1 0 x\nf 1 2 3\n"),
    ("huge_count.off", "OFF\n999999999999 1 0\n"),
]


@pytest.mark.parametrize("name,content", BAD_FILES)
def test_bad_files_raise_what_the_command_says(tmp_path, name, content):
    path = tmp_path / name
    path.write_bytes(content.encode("latin-1"))
    _, _, proc = run_cli(path, check=False)
    assert proc.returncode == 2 and proc.stdout == ""
    with pytest.raises(InputError) as e:
        posedrop.Part.from_file(path)
    assert isinstance(e.value, ValueError) and isinstance(e.value, posedrop.PosedropError)
    # The same words, but for the option's name in each language.
    message = e.value.message.replace("com=(x, y, z)", "--com X,Y,Z")
    assert e.value.status != Status.OK and message in proc.stderr


def test_missing_file():
    with pytest.raises(InputError) as e:
        posedrop.Part.from_file(PARTS / "no-such-part.off")
    assert e.value.status == Status.ERR_IO and "no-such-part.off" in str(e.value)


def test_open_mesh_needs_a_centre_of_mass():
    faces = CUBE_F[:-2]
    with pytest.raises(InputError) as e:
        posedrop.Part(CUBE_V, faces)
    assert e.value.status == Status.ERR_NOT_CLOSED
    # The command's advice, in Python's words (--com is com= here).
    assert str(e.value).endswith("give its centre of mass with com=(x, y, z) to use it anyway")
    with pytest.warns(posedrop.PosedropWarning, match="boundary edge"):
        part = posedrop.Part(CUBE_V, faces, com=[0.005, 0.005, 0.005])
    assert not part.closed and part.volume is None and len(part.stable_poses()) == 6


@pytest.mark.parametrize("vertices,faces,com,status", [
    (CUBE_V * np.nan, CUBE_F, None, Status.ERR_NONFINITE),
    (CUBE_V, CUBE_F + 1, None, Status.ERR_RANGE),
    (CUBE_V, -CUBE_F, None, Status.ERR_RANGE),
    (CUBE_V, CUBE_F + 2 ** 40, None, Status.ERR_RANGE),
    (CUBE_V[:, :2], CUBE_F, None, Status.ERR_USAGE),
    (CUBE_V, CUBE_F[:, :2], None, Status.ERR_USAGE),
    (CUBE_V, CUBE_F.astype(float), None, Status.ERR_USAGE),
    (np.zeros((0, 3)), np.zeros((0, 3), int), None, Status.ERR_TOO_FEW_POINTS),
    (CUBE_V * [1, 1, 0], CUBE_F, None, Status.ERR_COPLANAR),
    (CUBE_V, CUBE_F, [0.02, 0.005, 0.005], Status.ERR_COM_OUTSIDE),
    (CUBE_V, CUBE_F, [0.005, np.inf, 0.005], Status.ERR_NONFINITE),
    (CUBE_V, CUBE_F, [0.005, 0.005], Status.ERR_USAGE),
    (CUBE_V * 1e-40, CUBE_F, None, Status.ERR_RANGE),
])
def test_bad_arrays(vertices, faces, com, status):
    with pytest.raises(InputError) as e:
        posedrop.Part(vertices, faces, com=com)
    assert e.value.status == status, e.value.message


def test_bad_options_and_scenes(tmp_path):
    part = posedrop.Part(CUBE_V, CUBE_F)
    cases = [
        (lambda: posedrop.Part(CUBE_V, CUBE_F, units="furlong"), Status.ERR_USAGE),
        (lambda: posedrop.Part.from_file(PARTS / "cap.off", format="ply"), Status.ERR_USAGE),
        (lambda: part.stable_poses(topple="roll"), Status.ERR_USAGE),
        (lambda: part.stable_poses(epsilon=91), Status.ERR_USAGE),
        (lambda: part.stable_poses(epsilon=float("nan")), Status.ERR_NONFINITE),
        (lambda: part.drop(10, mu=-0.5), Status.ERR_RANGE),
        (lambda: part.drop(10, mu="abc"), Status.ERR_PARSE),
        (lambda: part.drop(10, mu=float("nan")), Status.ERR_PARSE),
        (lambda: part.drop(10, restitution=3), Status.ERR_RANGE),
        (lambda: part.drop(10, initial="sideways"), Status.ERR_PARSE),
        (lambda: part.drop(10, wobble=1), Status.ERR_USAGE),
        (lambda: part.drop(10, mu=[0.3]), Status.ERR_USAGE),
        (lambda: part.drop(-1), Status.ERR_USAGE),
        (lambda: part.drop(2.5), Status.ERR_USAGE),
        (lambda: part.drop(10, seed=-1), Status.ERR_USAGE),
        (lambda: part.drop(10, seed=2 ** 64), Status.ERR_USAGE),
        (lambda: part.drop(10, threads=-2), Status.ERR_USAGE),
        (lambda: part.drop(10, engine="havok"), Status.ERR_USAGE),
        (lambda: part.drop(10, dt=0.5, engine="ode"), Status.ERR_USAGE),
        (lambda: part.drop(10, ci=0.7), Status.ERR_USAGE),
        (lambda: part.drop(100, ci=0.1, initial="stationary"), Status.ERR_USAGE),
        (lambda: part.drop(10, initial="stationary"), Status.ERR_USAGE),
        (lambda: part.drop(10, scene=tmp_path / "none.scene"), Status.ERR_IO),
    ]
    for call, status in cases:
        with pytest.raises(InputError) as e:
            call()
        assert e.value.status == status, e.value.message
        assert e.value.message


def test_scene_file_errors_name_file_and_line(tmp_path):
    scene = tmp_path / "bad.scene"
    scene.write_text("height = 0.1\nmu = 0.3\nmu = 0.4\n")
    part = posedrop.Part(CUBE_V, CUBE_F)
    with pytest.raises(InputError) as e:
        part.drop(10, scene=scene)
    _, _, proc = run_cli("-n", "10", "--scene", scene, PARTS / "cap.off", check=False)
    assert proc.returncode == 2 and e.value.message in proc.stderr and "bad.scene:3" in str(e.value)


def test_warnings_are_python_warnings():
    flipped = CUBE_F.copy()
    flipped[0] = flipped[0][::-1]
    with pytest.warns(posedrop.PosedropWarning):
        part = posedrop.Part(CUBE_V, flipped)
    assert part.volume == pytest.approx(1e-6, rel=1e-12)


def test_exceptions_pickle():
    import pickle
    try:
        posedrop.Part.from_file(PARTS / "no-such-part.off")
    except InputError as e:
        again = pickle.loads(pickle.dumps(e))
        assert (again.status, again.message) == (e.status, e.message)


@pytest.mark.filterwarnings("ignore::posedrop.PosedropWarning")
def test_random_triangle_soups_never_crash():
    """Arbitrary arrays: a part or an InputError, never a crash, and never a
    number that is not finite."""
    rng = np.random.default_rng(3)
    built = refused = 0
    for trial in range(300):
        nv = int(rng.integers(0, 12))
        v = rng.normal(size=(nv, 3)) * 10.0 ** rng.integers(-6, 4)
        if nv and trial % 3 == 0:
            v[rng.integers(0, nv, size=nv // 2)] = v[0]  # duplicates
        if nv and trial % 5 == 0:
            v[:, int(rng.integers(0, 3))] = 0.0  # flat
        nf = int(rng.integers(0, 20))
        f = rng.integers(0, max(nv, 1), size=(nf, 3))
        com = None if trial % 2 else rng.normal(size=3) * 0.1
        try:
            part = posedrop.Part(v, f, com=com)
        except InputError:
            refused += 1
            continue
        poses = part.stable_poses()
        assert np.isfinite(poses.p_qs).all() and np.isfinite(poses.transform).all()
        built += 1
    assert refused > 0 and built > 0


@pytest.mark.filterwarnings("ignore::posedrop.PosedropWarning")
@pytest.mark.parametrize("name,units", [("cap.off", "m"), ("block.stl", "mm"),
                                        ("hexnut.obj", "mm")])
def test_mutated_files_fail_where_the_command_fails(tmp_path, name, units):
    """Shipped files cut short or with bytes changed: Python builds a part
    exactly when the command succeeds, and raises InputError exactly when
    it exits 2, with the command's message."""
    data = (PARTS / name).read_bytes()
    rng = np.random.default_rng(len(data))
    outcomes = set()
    for k in range(16):
        b = bytearray(data)
        if k % 2:
            b = b[:int(rng.integers(0, len(b)))]
        else:
            for i in rng.integers(0, len(b), size=int(rng.integers(1, 4))):
                b[i] = int(rng.integers(0, 256))
        path = tmp_path / ("m%d%s" % (k, (PARTS / name).suffix))
        path.write_bytes(bytes(b))
        _, _, proc = run_cli("--units", units, path, check=False)
        assert proc.returncode in (0, 2), proc.stderr
        if proc.returncode == 0:
            posedrop.Part.from_file(path, units=units).stable_poses()
        else:
            with pytest.raises(InputError) as e:
                posedrop.Part.from_file(path, units=units).stable_poses()
            assert e.value.message.replace("com=(x, y, z)", "--com X,Y,Z") in proc.stderr
        outcomes.add(proc.returncode)
    assert 2 in outcomes
