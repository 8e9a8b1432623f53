#!/usr/bin/env python3
"""trimesh-table.py: posedrop.compute_stable_poses against trimesh's, the
numbers of docs/python.md's "Switching from trimesh" (scripts/doc_tables.py
trimesh runs it; prints the table's markdown, then a line '#numbers' and
one 'key,value,se' line per number).

Needs the posedrop module, trimesh and pytest in the Python that runs it
(it reuses python/tests/test_trimesh.py's meshes and helpers):

    .venv/bin/python scripts/trimesh-table.py

On the test's ten meshes: whether both find the same poses one to one, the
largest difference of their transforms, the summed absolute difference of
the probabilities for the default (descent) and topple="edge", and the
probability that passes through a facet where the rules may part (twice it
bounds the difference). On random 40-point hulls of seeds 0-39: on how many
trimesh's probabilities equal topple="edge"'s, and the default's, to
round-off. Then the CPU seconds of sampled centres of mass (sigma > 0) on a
12-sided cylinder, against trimesh's (timings, not compared). Everything but the timings is deterministic.
"""
import os
import sys
import time
import warnings

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python", "tests"))

import numpy as np  # noqa: E402
import posedrop  # noqa: E402
import trimesh  # noqa: E402
import test_trimesh as tt  # noqa: E402


def compare(mesh):
    """(same poses, worst transform difference, sum |dp| default, sum |dp|
    edge, probability through vertex regions)."""
    T_tm, p_tm = trimesh.poses.compute_stable_poses(mesh)
    T_pd, p_pd = posedrop.compute_stable_poses(mesh)
    part = posedrop.Part.from_trimesh(mesh)
    bound = tt.normal_bound(mesh, part)
    j = tt.match(-T_tm[:, 2, :3], -T_pd[:, 2, :3], bound)
    same = bool((j >= 0).all() and len(set(j)) == len(j) == len(p_pd))
    edge = part.stable_poses(topple="edge")
    je = tt.match(-T_tm[:, 2, :3], edge.normal, bound)
    dT = float(np.abs(T_pd[j] - T_tm).max()) if same else float("nan")
    return (same, dT, float(np.abs(p_pd[j] - p_tm).sum()),
            float(np.abs(edge.p_qs[je] - p_tm).sum()),
            float(tt.vertex_region_probability(part, edge)))


def cpu(f):
    t0 = time.process_time()
    f()
    return time.process_time() - t0


def main():
    # The random hulls are metres across: the size warning is expected.
    warnings.simplefilter("ignore", posedrop.UnitsWarning)
    out = ["| mesh | same poses | transforms, worst difference | sum abs. dp, default "
           "| sum abs. dp, `topple=\"edge\"` | p through vertex regions |",
           "|---|---|---:|---:|---:|---:|"]
    numbers = []
    for name, make in tt.MESHES.items():
        same, dT, dp, dpe, vr = compare(make())
        out.append(f"| {name} | {'yes' if same else 'no'} | {dT:.2g} | {dp:.2g} | {dpe:.2g} "
                   f"| {vr:.3g} |")
        numbers += [(f"{name} same", float(same)), (f"{name} vertex-region p", vr)]
    edge_eq = default_eq = 0
    for seed in range(40):
        mesh = tt.random_hull(seed)
        T_tm, p_tm = trimesh.poses.compute_stable_poses(mesh)
        T_pd, p_pd = posedrop.compute_stable_poses(mesh)
        part = posedrop.Part.from_trimesh(mesh)
        bound = tt.normal_bound(mesh, part)
        edge = part.stable_poses(topple="edge")
        tol = len(p_tm) * tt.ROUND
        je = tt.match(-T_tm[:, 2, :3], edge.normal, bound)
        j = tt.match(-T_tm[:, 2, :3], -T_pd[:, 2, :3], bound)
        edge_eq += bool((je >= 0).all() and np.abs(edge.p_qs[je] - p_tm).max() <= tol)
        default_eq += bool((j >= 0).all() and np.abs(p_pd[j] - p_tm).max() <= tol)
    numbers += [("random hulls equal to edge", float(edge_eq)),
                ("random hulls equal to default", float(default_eq))]
    out += ["", f"Of 40 random 40-point hulls (seeds 0-39), trimesh's probabilities equal "
            f"`topple=\"edge\"`'s to round-off on {edge_eq} and the default's on {default_eq}."]
    mesh = trimesh.creation.cylinder(radius=0.01, height=0.03, sections=12)
    com = mesh.center_mass
    times = []
    for sigma, n in ((1e-3, 20), (1e-5, 200)):
        kw = dict(center_mass=com, sigma=sigma, n_samples=n, seed=1)
        pd_s = cpu(lambda: posedrop.compute_stable_poses(mesh, **kw))
        tm_s = cpu(lambda: trimesh.poses.compute_stable_poses(mesh, **kw))
        times.append(f"sigma {sigma:g} and {n} samples {pd_s:.3f} s (trimesh {tm_s:.3f} s)")
    out += ["", "CPU seconds, a 12-sided cylinder (r 10 mm, h 30 mm), seed 1: "
            + "; ".join(times) + f". trimesh {trimesh.__version__}, numpy {np.__version__}."]
    print("\n".join(out))
    print("#numbers")
    for k, v in numbers:
        # Deterministic: the same module and trimesh give the same numbers.
        print(f"{k},{v!r},0.0")


if __name__ == "__main__":
    main()
