"""posedrop.compute_stable_poses against trimesh.poses.compute_stable_poses.

trimesh's method (trimesh/poses.py) is the paper's QS on the triangles of
the convex hull: each triangle starts with its solid angle at the centre of
mass, an unstable one hands it across the edge that the ray from its
centroid to the projected centre of mass crosses, and the poses are grouped
by normal rounded to 3 decimals. With its defaults (sigma 0, n_samples 1)
nothing is sampled, so there is no sampling error: where the two methods
take the same path the probabilities agree to round-off. posedrop's
topple="edge" crosses the edge nearest the projection, and the default
topple="descent" pivots about the point of the facet nearest it: all three
cross the same edge unless the projection lies beyond two edges of the
facet or nearest one of its vertices. So the probabilities may differ only
by the probability that flows through such facets, which the tests below
measure and bound.
"""
import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")
import posedrop  # noqa: E402
from conftest import PARTS, SHIPPED, pose_rows, run_cli  # noqa: E402

# PD_TOL_PLANE_REL (include/posedrop/tolerances.h): the hull merges
# triangles whose corners lie within this of one plane, relative to size.
PLANE_REL = 1e-7
# Probabilities are sums of a few hundred solid angles: round-off.
ROUND = 1e-12


def random_hull(seed):
    pts = np.random.default_rng(seed).normal(size=(40, 3)) * [1.0, 0.6, 0.3]
    return trimesh.convex.convex_hull(pts)


MESHES = {
    "box": lambda: trimesh.creation.box((0.04, 0.02, 0.01)),
    "cylinder": lambda: trimesh.creation.cylinder(radius=0.01, height=0.03, sections=12),
    "cone": lambda: trimesh.creation.cone(radius=0.01, height=0.02, sections=10),
    "cap": lambda: trimesh.load(PARTS / "cap.off"),
    "hexnut": lambda: trimesh.load(PARTS / "hexnut.obj"),
    # Random hulls on which trimesh's rule, the edge rule and descent part
    # ways in vertex regions (found by trying seeds 0-39).
    "hull2": lambda: random_hull(2),
    "hull7": lambda: random_hull(7),
    "hull19": lambda: random_hull(19),
    "hull25": lambda: random_hull(25),
    "hull1": lambda: random_hull(1),
}


def normal_bound(mesh, part):
    """How far one hull triangle's normal may turn from its merged facet's:
    corners within PLANE_REL * size of the plane, over the triangle's
    shortest height (twice for both ends)."""
    cvh = mesh.convex_hull
    tri = cvh.triangles
    edges = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2)
    heights = 2 * cvh.area_faces / edges.max(axis=1)
    return 2 * PLANE_REL * part.size / heights.min() + ROUND


def in_vertex_region(part):
    """Whether each hull facet's projected centre of mass lies where the
    rules may part ways: beyond two or more of the facet's edges, or beyond
    one but nearest a vertex. Beyond exactly one edge and nearest a point
    inside it, all three cross that edge: trimesh's ray from the centroid
    leaves through it, it is the nearest edge, and the part pivots about
    it."""
    verts, com = part.hull_vertices, part.com
    out = []
    for f, loop in enumerate(part.hull_facets):
        n = part.hull_normals[f]
        c = com - np.dot(com - verts[loop[0]], n) * n
        edges = [(verts[a], verts[b]) for a, b in zip(loop, np.roll(loop, -1))]
        beyond = [(A, B) for A, B in edges if np.dot(c - A, np.cross(B - A, n)) > 0]
        if len(beyond) == 1:
            A, B = beyond[0]
            t = np.dot(c - A, B - A) / np.dot(B - A, B - A)
            out.append(not 0 < t < 1)
        else:
            out.append(len(beyond) >= 2)
    return np.array(out)


def vertex_region_probability(part, poses):
    """The probability whose quasi-static path (the edge rule's, which the
    others follow up to such a facet) passes through one of in_vertex_region:
    all that the rules can move, so the most they can differ by (in sum of
    absolute differences) is twice it."""
    region, f = in_vertex_region(part), poses.facets
    total = 0.0
    for start in range(len(f)):
        g = start
        while g >= 0 and not region[g]:
            g = f.next[g]
        if g >= 0:
            total += f.p_raw[start]
    return total


def match(normals_a, normals_b, bound):
    """Index into b of each normal of a, or -1."""
    out = []
    for n in normals_a:
        d = np.linalg.norm(normals_b - n, axis=1)
        out.append(int(d.argmin()) if d.min() <= bound else -1)
    return np.array(out)


@pytest.mark.parametrize("name", MESHES)
def test_same_poses_and_probabilities_as_trimesh(name):
    mesh = MESHES[name]()
    T_tm, p_tm = trimesh.poses.compute_stable_poses(mesh)
    T_pd, p_pd = posedrop.compute_stable_poses(mesh)
    part = posedrop.Part.from_trimesh(mesh)
    bound = normal_bound(mesh, part)
    n_tm, n_pd = -T_tm[:, 2, :3], -T_pd[:, 2, :3]
    # The same set of stable poses, one to one.
    j = match(n_tm, n_pd, bound)
    assert (j >= 0).all() and len(set(j)) == len(j) == len(p_pd)
    # The transforms: the same rotation (up to the normals' difference) and
    # the same lift, which puts the lowest vertex on z = 0.
    assert np.abs(T_pd[j] - T_tm).max() <= 4 * bound * max(1.0, part.size)
    for T in T_pd:
        z = mesh.vertices @ T[:3, :3].T + T[:3, 3]
        assert abs(z[:, 2].min()) <= 4 * ROUND * part.size
    # Probabilities: the edge rule is trimesh's but in vertex regions.
    edge = part.stable_poses(topple="edge")
    je = match(n_tm, edge.normal, bound)
    gap = np.abs(edge.p_qs[je] - p_tm).sum()
    assert gap <= 2 * vertex_region_probability(part, edge) + len(p_tm) * ROUND
    # The default (descent) differs from the edge rule only there too.
    assert np.abs(p_pd[j] - p_tm).sum() <= 2 * vertex_region_probability(part, edge) + \
        len(p_tm) * ROUND
    assert p_pd.sum() == pytest.approx(1.0, abs=len(p_pd) * ROUND)


def test_meshes_where_no_facet_is_in_a_vertex_region_agree_to_round_off():
    agreed = 0
    for name, make in MESHES.items():
        mesh = make()
        part = posedrop.Part.from_trimesh(mesh)
        edge = part.stable_poses(topple="edge")
        if vertex_region_probability(part, edge) > 0:
            continue
        T_tm, p_tm = trimesh.poses.compute_stable_poses(mesh)
        j = match(-T_tm[:, 2, :3], edge.normal, normal_bound(mesh, part))
        assert np.abs(edge.p_qs[j] - p_tm).max() <= len(p_tm) * ROUND, name
        agreed += 1
    assert agreed >= 5
    # And the bound of the test above is not idle: on some meshes the rules differ.
    differ = 0
    for name in ("hull2", "hull7", "hull19", "hull25"):
        mesh = MESHES[name]()
        part = posedrop.Part.from_trimesh(mesh)
        T_tm, p_tm = trimesh.poses.compute_stable_poses(mesh)
        T_pd, p_pd = posedrop.compute_stable_poses(mesh)
        j = match(-T_tm[:, 2, :3], -T_pd[:, 2, :3], normal_bound(mesh, part))
        differ += np.abs(p_pd[j] - p_tm).sum() > 1e-3
    assert differ >= 3


def test_one_line_switch_keeps_the_result_form():
    mesh = trimesh.creation.box((0.03, 0.02, 0.01))
    a = trimesh.poses.compute_stable_poses(mesh, threshold=0.1)
    b = posedrop.compute_stable_poses(mesh, threshold=0.1)
    assert type(a) is type(b) and len(b) == 2
    assert a[0].shape == b[0].shape and a[0].dtype == b[0].dtype
    assert a[1].shape == b[1].shape and a[1].dtype == b[1].dtype
    assert (np.diff(b[1]) <= 0).all() and (b[1] > 0.1).all()
    # Writable, as trimesh's are.
    b[0][0, 0, 0] = 2.0


def test_sampled_centres_of_mass_as_trimesh():
    """sigma > 0: the same centres of mass drawn from the same seed (the
    same numpy calls), so the averages agree as the unsampled ones do."""
    mesh = trimesh.creation.box((0.04, 0.02, 0.01))
    com = mesh.center_mass
    kw = dict(center_mass=com, sigma=1e-6, n_samples=20, seed=4)
    T_tm, p_tm = trimesh.poses.compute_stable_poses(mesh, **kw)
    T_pd, p_pd = posedrop.compute_stable_poses(mesh, **kw)
    j = match(-T_tm[:, 2, :3], -T_pd[:, 2, :3], 1e-9)
    assert (j >= 0).all() and len(p_pd) == len(p_tm)
    assert np.abs(p_pd[j] - p_tm).max() <= 20 * ROUND
    # And they are not the unsampled probabilities: the samples moved them.
    assert np.abs(p_pd - posedrop.compute_stable_poses(mesh)[1]).max() > 1e-4


@pytest.mark.parametrize("name,units", [("cap.off", "m"), ("hexnut.obj", "mm")])
def test_transform_rests_the_part_on_its_facet(name, units):
    """In metres, whatever the file's unit."""
    part = posedrop.Part.from_file(PARTS / name, units=units)
    poses = part.stable_poses()
    for i, T in enumerate(poses.transform):
        R = T[:3, :3]
        assert np.abs(R @ R.T - np.eye(3)).max() <= 4e-16 * 4
        assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-15)
        assert R @ poses.normal[i] == pytest.approx([0, 0, -1], abs=4e-16)
        z = part.hull_vertices @ R.T + T[:3, 3]
        assert abs(z[:, 2].min()) <= ROUND * part.size
        # The centre of mass ends at the pose's height above the floor, which
        # the library measures from the merged facet's plane: its corners
        # lie within PLANE_REL * size of it.
        assert (R @ part.com + T[:3, 3])[2] == pytest.approx(poses.height[i],
                                                             abs=PLANE_REL * part.size)


# trimesh's OFF reader (5.2.0) fails on a face of more than four corners:
# it fans the face's indices while they are still strings, which numpy (1.26
# and 2 alike) refuses to multiply. square_black_button.off's octagonal cap
# top is the one such face among the shipped parts. Expected to fail, and
# strictly, so that a trimesh that reads it shows here (docs/python.md).
NO_TRIMESH = pytest.mark.xfail(raises=TypeError, strict=True,
                               reason="trimesh fans an octagon's string indices")


@pytest.mark.parametrize("name,units", [
    pytest.param(*p, marks=NO_TRIMESH) if p[0] == "square_black_button.off" else p
    for p in SHIPPED])
def test_trimesh_loaded_parts_give_the_commands_numbers(name, units):
    """A shipped part read by trimesh (unprocessed: its vertices and the
    same fan triangles) gives the command's rows to the last digit."""
    rows, _, _ = run_cli("--units", units, PARTS / name)
    mesh = trimesh.load(PARTS / name, process=False)
    assert pose_rows(posedrop.Part.from_trimesh(mesh, units=units).stable_poses()) == rows
