"""compute_stable_poses: trimesh.poses.compute_stable_poses on posedrop's estimators."""
import numpy as np

from ._api import _STATUS, Part
from ._errors import InputError


def compute_stable_poses(mesh, center_mass=None, sigma=0.0, n_samples=1, threshold=0.0,
                         seed=None, estimator="qs"):
    """Stable poses of a mesh and their quasi-static probabilities, as trimesh gives them.

    A drop-in for ``trimesh.poses.compute_stable_poses`` (same arguments, same
    results' form and transform convention): replace
    ``trimesh.poses.compute_stable_poses(mesh)`` by
    ``posedrop.compute_stable_poses(mesh)``. The probabilities are posedrop's
    QS estimate (``estimator="pqs"`` for PQS) on the merged facets of the
    exact convex hull, with the exact quasi-static descent.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        A closed mesh (or any object with ``vertices`` and ``faces``).
    center_mass : (3,) float, optional
        Centre of mass; by default the library's, at uniform density.
    sigma : float
        As trimesh's: the variance of an isotropic Gaussian from which
        ``n_samples`` centres of mass are drawn (rejecting those outside the
        hull); the probabilities are averaged over them. 0 (the default):
        the centre of mass itself.
    n_samples : int
        Samples of the centre of mass when ``sigma`` > 0.
    threshold : float
        Poses with a probability not above this are left out.
    seed : None, int or numpy.random.Generator
        For the samples, as trimesh's ``seed``.
    estimator : {"qs", "pqs"}
        Which of posedrop's static estimates to return.

    Returns
    -------
    transforms : (k, 4, 4) float
        Homogeneous transforms that set the mesh resting on z = 0 in each
        pose, z pointing up (:attr:`StablePoses.transform`).
    probs : (k,) float
        The probability of each pose, most probable first.
    """
    if estimator not in ("qs", "pqs"):
        raise ValueError("estimator: expected 'qs' or 'pqs', got %r" % (estimator,))
    key = "p_" + estimator
    vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    if sigma == 0:
        samples = [Part(vertices, faces, com=center_mass).stable_poses()]
    else:
        if n_samples < 1:
            raise ValueError("n_samples: expected at least 1, got %r" % (n_samples,))
        base = Part(vertices, faces, com=center_mass)
        centre = (base.com if center_mass is None
                  else np.asarray(center_mass, dtype=np.float64))
        # Only the centre of mass moves between samples: each is a part made
        # of the convex hull alone (all the static estimates read), built in
        # a fraction of the mesh's time, and a centre outside the hull is
        # rejected before any build.
        hull_v = base.hull_vertices
        hull_t = np.array([(f[0], f[i], f[i + 1]) for f in base.hull_facets
                           for i in range(1, len(f) - 1)], dtype=np.intc)
        normals = base.hull_normals
        offsets = np.einsum("ij,ij->i", normals,
                            hull_v[[f[0] for f in base.hull_facets]])
        rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        samples = []
        while len(samples) < n_samples:
            for com in rng.multivariate_normal(centre, sigma * np.eye(3),
                                               n_samples - len(samples)):
                if np.any(normals @ com - offsets >= 0.0):
                    continue
                try:
                    samples.append(Part(hull_v, hull_t, com=com).stable_poses())
                except InputError as e:
                    if e.status != _STATUS["ERR_COM_OUTSIDE"]:
                        raise
    # The hull, and so its facet numbering, is the same for every sample.
    prob, transform = {}, {}
    for poses in samples:
        for i, f in enumerate(poses.facet):
            prob[f] = prob.get(f, 0.0) + getattr(poses, key)[i] / len(samples)
            transform.setdefault(f, poses.transform[i])
    facets = [f for f in prob if prob[f] > threshold]
    probs = np.array([prob[f] for f in facets], dtype=np.float64)
    transforms = np.array([transform[f] for f in facets], dtype=np.float64).reshape(-1, 4, 4)
    order = np.argsort(-probs, kind="stable")
    return transforms[order], probs[order]
