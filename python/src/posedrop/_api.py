"""Parts, stable poses and drops: the Python face of libposedrop.

Every number here is computed by the C library (through posedrop._posedrop);
this module only converts arguments and wraps results as numpy arrays.
"""
import numbers
import os
import sys
import warnings
from collections.abc import Mapping

import numpy as np

from . import _posedrop
from ._errors import InputError, PosedropWarning, UnitsWarning

_STATUS = _posedrop.statuses()

#: How each drop ended (``Trials.end``), as the command's --trials names them.
END_NAMES = ("settled", "time_limit", "collision_limit", "failed")

#: The scene parameters that take ranges, in ``pd_scene_param`` order
#: (the keys of :attr:`Trials.params`, the rows of a :class:`Sensitivity`).
_STAGE_NAMES, _STATUS_TEXTS, PARAM_NAMES = _posedrop.names()
_FAILED = END_NAMES.index("failed")
# A status as one word of the end column (src/cli/command.c's status_word):
# its fixed name with blanks, hyphens and slashes as underscores.
_STATUS_WORDS = tuple(t.replace(" ", "_").replace("-", "_").replace("/", "_")
                      for t in _STATUS_TEXTS)


def _user_stacklevel():
    """The stacklevel, for warnings.warn called by this function's caller,
    of the first frame outside the package: the user's line that called it."""
    here = os.path.dirname(os.path.abspath(__file__))
    frame, level = sys._getframe(1), 1
    while frame is not None and os.path.dirname(os.path.abspath(frame.f_code.co_filename)) == here:
        frame, level = frame.f_back, level + 1
    return level


def _failure_words(stage, status):
    """A failed drop's pd_drop_stage and pd_status as the words of
    failed:STAGE:STATUS."""
    return _STAGE_NAMES[stage], _STATUS_WORDS[status]


def _usage(message):
    return InputError(_STATUS["ERR_USAGE"], "invalid argument", message)


def _array(buf, dtype, shape):
    a = np.frombuffer(buf, dtype=dtype).reshape(shape)
    a.flags.writeable = False
    return a


def _f64(buf, *shape):
    return _array(buf, np.float64, shape or (-1,))


def _i32(buf, *shape):
    return _array(buf, np.int32, shape or (-1,))


def _i64(buf, *shape):
    return _array(buf, np.int64, shape or (-1,))


class Part:
    """A rigid part: a triangle mesh, its convex hull and its centre of mass.

    Built by the library as the command builds it from a file: vertices
    welded, faces oriented outward, mass properties at uniform density, the
    convex hull, and the centre of mass checked to lie strictly inside the
    hull. Immutable once built; several threads may use one part at once.

    Parameters
    ----------
    vertices : (n, 3) array_like of float
        Vertex coordinates, in ``units``.
    faces : (m, 3) array_like of int
        Triangles as indices into ``vertices`` (from 0), counter-clockwise
        seen from outside when consistently oriented (inconsistent faces
        are re-oriented with a :class:`PosedropWarning`).
    com : (3,) array_like of float, optional
        Centre of mass in ``units`` and in the vertices' frame. By default
        it is computed from the closed mesh at uniform density; a mesh that
        is not closed needs it.
    units : {"m", "cm", "mm", "in"}
        Unit of the coordinates; everything the part reports is in metres.

    Raises
    ------
    InputError
        A mesh the library refuses (no volume, not closed without ``com``,
        non-finite coordinates, an index out of range, ...).
    """

    def __init__(self, vertices, faces, com=None, units="m"):
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        f = np.asarray(faces)
        if v.ndim != 2 or v.shape[1] != 3:
            raise _usage("vertices: expected an (n, 3) array, got shape %s" % (v.shape,))
        if f.size == 0:
            f = f.reshape(0, 3)
        if f.ndim != 2 or f.shape[1] != 3:
            raise _usage("faces: expected an (m, 3) array of vertex indices, got shape %s"
                         % (f.shape,))
        if f.dtype.kind not in "iu":
            raise _usage("faces: expected integer vertex indices, got %s" % f.dtype)
        if f.size and (f.min() < 0 or f.max() >= len(v)):
            bad = np.argwhere((f < 0) | (f >= len(v)))[0]
            raise InputError(_STATUS["ERR_RANGE"], "value out of range",
                             "faces[%d, %d] is %d: expected a vertex index from 0 to %d"
                             % (bad[0], bad[1], f[bad[0], bad[1]], len(v) - 1))
        f = np.ascontiguousarray(f, dtype=np.intc)
        with _com_hint(com):
            self._h = _posedrop.part_from_arrays(v, f, _com(com), units)
        self._init()
        self._warn_units(units, "the mesh")

    @classmethod
    def from_file(cls, path, units="m", format=None, com=None):
        """Reads an OFF, STL (ASCII or binary) or OBJ file, as the command does.

        Parameters
        ----------
        path : str or os.PathLike
        units : {"m", "cm", "mm", "in"}
            Unit of the file's coordinates (the command's ``--units``).
        format : {None, "off", "stl", "obj"}
            None detects it from the content and the name (``--format``).
        com : (3,) array_like of float, optional
            Centre of mass in the file's units and frame (``--com``).
        """
        part = cls.__new__(cls)
        with _com_hint(com):
            part._h = _posedrop.part_from_file(os.fspath(path), units, format, _com(com))
        part._init()
        part._warn_units(units, os.fspath(path))
        return part

    @classmethod
    def from_trimesh(cls, mesh, com=None, units="m"):
        """A part from a ``trimesh.Trimesh`` (its vertices and faces).

        ``com`` defaults to the library's own centre of mass of the closed
        mesh at uniform density, as ``mesh.center_mass`` gives it for a
        watertight mesh.
        """
        if not (hasattr(mesh, "vertices") and hasattr(mesh, "faces")):
            hint = (": a trimesh.Scene holds several meshes; pass one of scene.geometry.values(), "
                    "or scene.to_geometry() (scene.dump(concatenate=True) in older trimesh) for "
                    "all of them as one" if type(mesh).__name__ == "Scene" else "")
            raise _usage("from_trimesh: expected a trimesh.Trimesh (with vertices and faces), "
                         "got %s%s" % (type(mesh).__name__, hint))
        return cls(mesh.vertices, mesh.faces, com=com, units=units)

    @classmethod
    def _wrap(cls, handle):
        part = cls.__new__(cls)
        part._h = handle
        part._init()
        return part

    def _init(self):
        info = self._h.info()
        self._info = info
        self._poses = None

    def _warn_units(self, units, what):
        """The command's warning for a part of a size no dropped part has
        (pd_units_plausible): a UnitsWarning naming the units to try."""
        suggest = _posedrop.units_plausible(self.size, units)
        if suggest is None:
            return
        size = self.size
        length = "%.3g m" % size if size >= 1.0 else "%.3g mm" % (size * 1e3)
        if suggest:
            names = {"m": "metres", "cm": "centimetres", "mm": "millimetres", "in": "inches"}
            hint = "if the coordinates are in %s, pass units=%r" % (names[suggest], suggest)
        else:
            hint = "is that what you meant? (units= says what the coordinates mean)"
        warnings.warn("%s: the part is %s across; %s" % (what, length, hint), UnitsWarning,
                      stacklevel=_user_stacklevel())

    # -- properties ---------------------------------------------------------

    @property
    def com(self):
        """Centre of mass used (given or computed), m, in the mesh's frame."""
        return np.array(self._info["com"])

    @property
    def size(self):
        """Bounding-box diagonal of the welded vertices, m: the length scale of every tolerance."""
        return self._info["size"]

    @property
    def closed(self):
        """True if the welded mesh is a closed surface."""
        return self._info["closed"]

    @property
    def volume(self):
        """Volume of the closed mesh, m^3 (None for a mesh that is not closed)."""
        return self._info.get("volume")

    @property
    def inertia(self):
        """Inertia tensor about the mesh's own centre of mass per unit density, m^5 (None if not closed)."""
        i = self._info.get("inertia")
        return None if i is None else _f64(i, 3, 3)

    @property
    def vertices(self):
        """(n, 3) welded vertices, m, in the mesh's frame."""
        return _f64(self._h.mesh()[0], -1, 3)

    @property
    def faces(self):
        """(m, 3) int32 triangles of the welded, oriented mesh."""
        return _i32(self._h.mesh()[1], -1, 3)

    @property
    def hull_vertices(self):
        """(h, 3) corner vertices of the convex hull, m, in the mesh's frame."""
        return _f64(self._h.hull()["vertices"], -1, 3)

    @property
    def hull_facets(self):
        """The hull's facets as a list of arrays of indices into :attr:`hull_vertices`,
        counter-clockwise seen from outside (merged coplanar polygons)."""
        h = self._h.hull()
        start, verts = _i32(h["facet_start"]), _i32(h["facet_vert"])
        return [verts[start[f]:start[f + 1]] for f in range(len(start) - 1)]

    @property
    def hull_normals(self):
        """(F, 3) outward unit normals of the hull's facets."""
        return _f64(self._h.hull()["normal"], -1, 3)

    def __repr__(self):
        return "<posedrop.Part: %d vertices, %d triangles, %d hull facets, size %.6g m>" % (
            self._info["nverts"], self._info["ntris"], self._info["hull_nfacets"], self.size)

    # -- estimates ----------------------------------------------------------

    def stable_poses(self, topple=None, epsilon=None, pqs_compare=None, pqs_band=None):
        """The stable poses with their QS and PQS probabilities.

        Parameters (None keeps the library's default, as the command without
        the option):

        topple : {"descent", "edge"}
            ``--topple``: the exact quasi-static descent (default) or the
            paper's graph between edge-adjacent facets.
        epsilon : float
            ``--epsilon``: the PQS perturbation angle in degrees, 0 to 90
            (default 20).
        pqs_compare : {"raw", "qs"}
            ``--pqs-compare``.
        pqs_band : {"rect", "exact"}
            ``--pqs-band``.

        Returns
        -------
        StablePoses
        """
        default = topple is None and epsilon is None and pqs_compare is None and pqs_band is None
        if default and self._poses is not None:
            return self._poses
        poses = StablePoses(self, self._h.estimate(topple, epsilon, pqs_compare, pqs_band))
        if default:
            self._poses = poses
        return poses

    def design(self, changes, *, target=None, maximise=None, equalise=None, model="pqs",
               group=False, n=20000, max_evals=12, check=20000, seed=1, threads=None):
        """The part changed within ranges to land as asked (``posedrop design``).

        Parameters
        ----------
        changes : sequence of tuples
            ``("scale", axis, lo, hi)``: a stretch by a factor along the
            principal axis nearest the file's axis ("x", "y", "z" or 0-2);
            ``("stretch", axis, lo, hi, a, b)``: only the slab a <= u <= b (m)
            along it; ``("com", axis, lo, hi)``: the centre of mass moved, m.
        target : sequence of (nx, ny, nz, p)
            Poses named by their facet's outward normal, and the probability
            wanted; or
        maximise : sequence of (nx, ny, nz)
            the poses whose summed share to maximise; or
        equalise : sequence of (nx, ny, nz)
            the poses to make equally likely.
        model : {"pqs", "qs"}
            The static model searched first.
        group : bool
            A normal names its pose's class.
        n, max_evals : int
            Drops per refinement evaluation (0: the static answer only), and
            the refinement's evaluations.
        check : int
            Fresh drops of the result (seed + 1).

        Returns
        -------
        Design
        """
        goals = [(g, v) for g, v in (("target", target), ("maximise", maximise),
                                     ("equalise", equalise)) if v is not None]
        if len(goals) != 1:
            raise _usage("design: give one of target, maximise, equalise")
        goal, rows = goals[0]
        rows = [tuple(float(x) for x in r) for r in rows]
        width = 4 if goal == "target" else 3
        if any(len(r) != width for r in rows):
            raise _usage("design: %s rows have %d numbers" % (goal, width))
        normals = [r[:3] for r in rows]
        p = [r[3] for r in rows] if goal == "target" else None
        d = self._h.design(_changes(changes), goal, normals, p, model, bool(group), int(n),
                           int(max_evals), int(check), int(seed), _opt_int(threads) or 0)
        return Design(d, normals)

    def drop(self, n=None, **options):
        """Monte Carlo drops from the default stable-pose table.

        The same as ``part.stable_poses().drop(n, **options)``; see
        :meth:`StablePoses.drop`.
        """
        return self.stable_poses().drop(n, **options)


_AXES = {"x": 0, "y": 1, "z": 2, 0: 0, 1: 1, 2: 2}


def _changes(changes):
    out = []
    for c in changes:
        c = tuple(c)
        if len(c) < 4 or c[1] not in _AXES:
            raise _usage("changes: expected (kind, axis, lo, hi[, a, b]), axis x, y, z or 0-2")
        out.append((str(c[0]), _AXES[c[1]]) + tuple(float(x) for x in c[2:]))
    return out


class Design:
    """The result of :meth:`Part.design`.

    Attributes
    ----------
    part : Part
        The changed part (metres).
    value_before, value_static, value : (k,)
        Each change's value (factor, or offset in m) as given, at the static
        model's optimum, and after the drops.
    normal : (t, 3)
        The named poses.
    p_target, qs_before, pqs_before, qs_static, pqs_static, qs_after, pqs_after,
    p_refine, p_after, ci_lo, ci_hi : (t,)
        Per named pose: the target (the mean for equalise, 1 for maximise),
        the static estimates as given, at the static optimum and at the
        result, the refinement drops' estimate and the fresh drops' with its
        95% Wilson interval.
    vanished, appeared : (t,) bool
        The pose's facet no longer rests on the result / did not rest on
        the part as given.
    objective_static, objective_refine, objective_after : float
    static_evals, drop_evals, drops, poses_before, poses_after : int
    """

    _COLUMNS = ("p_target", "qs_before", "pqs_before", "qs_static", "pqs_static", "qs_after",
                "pqs_after", "p_refine", "p_after", "ci_lo", "ci_hi")

    def __init__(self, d, normals):
        self.part = Part._wrap(d["part"])
        for k in ("value_before", "value_static", "value"):
            setattr(self, k, _f64(d[k]))
        self.normal = np.array(normals, dtype=np.float64).reshape(-1, 3)
        t = _f64(d["targets"], -1, 14)
        for k, name in enumerate(self._COLUMNS):
            setattr(self, name, t[:, k])
        self.vanished = t[:, 11] != 0
        self.appeared = t[:, 12] != 0
        for k in ("objective_static", "objective_refine", "objective_after", "static_evals",
                  "drop_evals", "drops", "poses_before", "poses_after"):
            setattr(self, k, d[k])

    def __repr__(self):
        return "<posedrop.Design: values %s, p_after %s>" % (
            np.array2string(self.value, precision=5), np.array2string(self.p_after, precision=4))


class DesignSensitivity:
    """The derivatives of each pose's (class's) probability with respect to
    each change, pose-major, as ``posedrop design --sensitivity`` writes
    them (per unit factor, or per metre).

    Attributes
    ----------
    pose : (rows,) int32
    d_qs, d_pqs : (rows,)
        Exact derivatives of QS and PQS.
    d_p, ci_lo, ci_hi : (rows,)
        Paired drops' central difference and its 95% interval (0 without drops).
    qs_kink, pqs_kink : (rows,) bool
        The static structure changes within a small step (one-sided derivative).
    step : (changes,)
        The drops' half step per change.
    """

    _COLUMNS = ("d_qs", "d_pqs", "d_p", "ci_lo", "ci_hi")

    def __init__(self, d):
        self.nposes = d["nposes"]
        self.ndrops = d["ndrops"]
        self.step = _f64(d["step"])
        self.pose = _i32(d["pose"])
        v = _f64(d["values"], -1, 7)
        for k, name in enumerate(self._COLUMNS):
            setattr(self, name, v[:, k])
        self.qs_kink = v[:, 5] != 0
        self.pqs_kink = v[:, 6] != 0

    def __len__(self):
        return len(self.pose)


class _com_hint:
    """Adds the command's advice to a mesh refused as not closed: in Python
    the centre of mass is given with com= (the command's --com)."""

    def __init__(self, com):
        self.com = com

    def __enter__(self):
        return self

    def __exit__(self, kind, e, tb):
        if (isinstance(e, InputError) and self.com is None
                and e.status in (_STATUS["ERR_NOT_CLOSED"], _STATUS["ERR_ORIENTATION"])):
            raise type(e)(e.status, e.status_name, e.message + "; give its centre of mass "
                          "with com=(x, y, z) to use it anyway") from None
        return False


def _com(com):
    if com is None:
        return None
    c = np.asarray(com, dtype=np.float64).reshape(-1)
    if c.shape != (3,):
        raise _usage("com: expected three numbers X, Y, Z")
    return tuple(float(x) for x in c)


class StablePoses:
    """The stable poses of a part, most probable under QS first.

    Index i here is pose i + 1 of the command's output. Arrays (read-only):

    normal : (k, 3)
        Outward unit normal of the resting facet, in the mesh's frame: the
        direction of gravity in the part's frame.
    transform : (k, 4, 4)
        Homogeneous transforms that set the part resting on the plane z = 0
        in that pose, as ``trimesh.poses.compute_stable_poses`` returns them:
        the rotation's rows are x, y, z with z = -normal, x = (-z_y, z_x, 0)
        normalised (or (1, 0, 0) for a horizontal facet), y = z x x, and the
        translation is along z only, putting the lowest hull vertex at z = 0.
        In metres, as everything the part reports: apply it to the mesh in
        metres (``trimesh_mesh.apply_transform(T)`` for a mesh in metres).
    area : (k,)
        Area of the resting facet of the hull, m^2.
    height : (k,)
        Height of the centre of mass above the floor, m.
    p_qs, p_pqs : (k,)
        Quasi-static and perturbed quasi-static probabilities.
    facet : (k,)
        Index of the resting facet in the part's hull (:attr:`Part.hull_facets`).
    """

    def __init__(self, part, handle):
        self.part = part
        self._h = handle
        d = handle.poses()
        self.facet = _i32(d["facet"])
        self.normal = _f64(d["normal"], -1, 3)
        self.transform = _f64(d["transform"], -1, 4, 4)
        self.area = _f64(d["area"])
        self.height = _f64(d["height"])
        self.p_qs = _f64(d["p_qs"])
        self.p_pqs = _f64(d["p_pqs"])
        self.n_knife = d["nknife"]
        self._facets = None
        self._classes = None

    def __len__(self):
        return len(self.p_qs)

    def __repr__(self):
        return "<posedrop.StablePoses: %d poses, p_qs %s>" % (
            len(self), np.array2string(self.p_qs, precision=4))

    @property
    def facets(self):
        """Every hull facet (the command's ``--facets``), as a :class:`Facets`."""
        if self._facets is None:
            self._facets = Facets(self._h.facets())
        return self._facets

    def classes(self):
        """The poses grouped by the part's rotational symmetry (``--group``).

        Returns
        -------
        PoseClasses
        """
        if self._classes is None:
            class_of, n = self._h.classes()
            self._classes = PoseClasses(self, _i32(class_of), n)
        return self._classes

    def design_sensitivity(self, changes, classes=None, n=0, seed=1, threads=None):
        """The exact derivatives of each pose's QS and PQS probabilities
        with respect to each change (see :meth:`Part.design` for changes),
        and with ``n`` > 0 paired drops' differences with 95% intervals;
        per class with ``classes`` (a :class:`PoseClasses`).

        Returns
        -------
        DesignSensitivity
        """
        cls = _class_array(classes) if classes is not None else None
        return DesignSensitivity(self._h.design_sensitivity(
            _changes(changes), cls, len(classes) if classes is not None else 0, int(n),
            int(seed), _opt_int(threads) or 0))

    def drop(self, n=None, *, ci=None, seed=None, threads=None, engine=None, dt=None,
             scene=None, max_drops=None, time_limit=None, max_collisions=None, trials=False,
             cancel=None, progress=None, **settings):
        """Monte Carlo drops of the part onto these poses (``posedrop -n N``).

        Each argument left at None keeps the library's default, which is the
        command's default too, so the same arguments and seed give the
        command's counts byte for byte, for any thread count.

        Parameters
        ----------
        n : int
            Drops to run (``-n``; default 2000; with ``ci``, at least these).
        ci : float
            Keep dropping until every pose's 95% interval is within ``ci``
            on each side (``--ci``), at most ``max_drops``.
        seed : int
            Random seed, 0 to 2**64 - 1 (``--seed``; default 1).
        threads : int
            Threads (``-j``); 0 or None: all cores. Never changes results.
        engine : {"impulse", "ode", "bullet"}
            ``--engine``.
        dt : float
            Time step of "ode" and "bullet", s (``--dt``).
        scene : str, os.PathLike or dict
            A scene file of ``key = value`` lines (``--scene``), or a dict of
            settings; keyword settings override it, as options after
            ``--scene`` do.
        **settings
            Scene settings by key, e.g. ``height=0.05, mu=0.5,
            restitution_law="energetic", vibration=1.5 (degrees),
            initial="stationary", contact_time="auto"``. Each is handed to
            the library as text (``pd_scene_set``), exactly as in a scene
            file, so every key and value form the library accepts works
            here too: ranges such as ``mu="0.2:0.5"``,
            ``contact_time="0.3x:3x"`` (multiples of auto, log uniform) or
            ``height="0.08:0.16 log"``, each drop drawing its own values
            from the seed and its index; ``tumble=`` (rad/s, the angular
            speed at release about a random axis).
        time_limit : float or "auto"
            Simulated seconds per drop, above 0 (``--time-limit``); None or
            "auto": the part's own limit (``pd_time_limit_auto``), which
            :attr:`Drops.time_limit` reports.
        max_drops, max_collisions : int
            The library's other run limits (``pd_sim_options``).
        trials : bool
            Keep one record per drop (``--trials``): :attr:`Drops.trials`,
            which :meth:`Drops.sensitivity` needs.
        cancel : threading.Event, optional
            Anything with ``is_set()``: once set, the drops under way finish
            and the drops done so far are returned with ``partial`` True.
        progress : callable, optional
            Called as ``progress(done, total)`` on the calling thread about
            every 50 ms while the drops run.

        Returns
        -------
        Drops

        Raises
        ------
        KeyboardInterrupt
            On Ctrl-C: the drops under way finish, no new one starts, and
            the interrupt propagates (use ``cancel`` for a partial result);
            on a thread other than the main one too, as long as Python's
            own SIGINT handler was in place when posedrop was imported.
        TypeError
            ``cancel`` without an ``is_set()`` method.
        InputError
            A scene value or option the library refuses.
        """
        items = []
        if isinstance(scene, Mapping):
            items += list(scene.items())
            scene = None
        items += list(settings.items())
        pairs = [(str(k), _scene_text(k, v)) for k, v in items]
        scene_file = None if scene is None else os.fspath(scene)
        for name, value in (("n", n), ("threads", threads), ("max_drops", max_drops),
                            ("max_collisions", max_collisions), ("seed", seed)):
            if value is not None and not isinstance(value, numbers.Integral):
                raise _usage("%s: expected a whole number, got %r" % (name, value))
        if seed is not None and not 0 <= seed < 2 ** 64:
            raise _usage("seed: expected 0 to 2**64 - 1, got %d" % seed)
        for name, value in (("n", n), ("max_drops", max_drops)):
            if value is not None and not -2 ** 63 <= value < 2 ** 63:
                raise _usage("%s: %d is out of range" % (name, value))
        if n is not None and n < 1:
            raise _usage("n: expected a number of drops of at least 1, got %d" % n)
        for name, value in (("threads", threads), ("max_collisions", max_collisions)):
            if value is not None and not -2 ** 31 <= value < 2 ** 31:
                raise _usage("%s: %d is out of range" % (name, value))
        h = self._h.drop(scene_file, pairs, n=_opt_int(n), ci=ci, seed=_opt_int(seed),
                         threads=_opt_int(threads), engine=engine, dt=dt,
                         max_drops=_opt_int(max_drops), time_limit=time_limit,
                         max_collisions=_opt_int(max_collisions), trials=bool(trials),
                         cancel=cancel, progress=progress)
        drops = Drops(self, h)
        _warn_unsettled(drops)
        return drops


def _warn_unsettled(drops):
    """The command's line for drops that did not settle: how many, why, and
    that p (count / n) then sums to less than 1."""
    if drops.unsettled == 0:
        return
    why = []
    if drops.time_limited:
        why.append("%d at the time limit (%.6g s simulated; time_limit=)"
                   % (drops.time_limited, drops.time_limit))
    if drops.collision_limited:
        why.append("%d at the collision limit (max_collisions=)" % drops.collision_limited)
    if drops.failed:
        why.append("%d failed" % drops.failed)
    total = ("" if drops.transitions is not None
             else " (p sums to %.4g, not 1)" % ((drops.n - drops.unsettled) / drops.n))
    warnings.warn("%d of %d drops did not settle and are in no count%s: %s"
                  % (drops.unsettled, drops.n, total, ", ".join(why)), PosedropWarning,
                  stacklevel=_user_stacklevel())


def _opt_int(x):
    return None if x is None else int(x)


def _scene_text(key, value):
    """A scene value as the text pd_scene_set reads: a string as it is, a
    number in the shortest form that reads back to the same double."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise _usage("scene %s: expected a number or a string, got %r" % (key, value))
    if isinstance(value, numbers.Integral):
        return str(int(value))
    return repr(float(value))


class Facets:
    """Every facet of the hull (the command's ``--facets``), indexed as the hull.

    Arrays: ``normal`` (F, 3), ``solid_angle`` (sr, at the centre of mass),
    ``p_raw`` (solid angle over 4 pi), ``area``, ``height``, ``stable`` and
    ``knife`` (bool), ``next`` (quasi-static successor, -1 for a stable
    facet), ``rest`` (the stable facet it ends on), ``pose`` (that facet's
    pose index), ``p_qs``, ``p_pqs``.
    """

    def __init__(self, d):
        self.normal = _f64(d["normal"], -1, 3)
        for key in ("solid_angle", "p_raw", "area", "height", "p_qs", "p_pqs"):
            setattr(self, key, _f64(d[key]))
        for key in ("next", "rest", "pose"):
            setattr(self, key, _i32(d[key]))
        self.stable = _i32(d["stable"]).astype(bool)
        self.knife = _i32(d["knife"]).astype(bool)

    def __len__(self):
        return len(self.area)


class PoseClasses:
    """Stable poses grouped into classes that a rotation of the part about
    its centre of mass maps onto each other (a prism's sides, a nut's six
    flats; mirror images stay apart), numbered most probable (summed QS) first.

    Attributes
    ----------
    class_of : (k,) int32
        The class of each pose.
    members : list of arrays
        The poses of each class.
    p_qs, p_pqs : (c,)
        Summed over each class's members.
    """

    def __init__(self, poses, class_of, n):
        self.poses = poses
        self.class_of = class_of
        self.members = [np.flatnonzero(class_of == c) for c in range(n)]
        self.p_qs = np.array([poses.p_qs[m].sum() for m in self.members])
        self.p_pqs = np.array([poses.p_pqs[m].sum() for m in self.members])

    def __len__(self):
        return len(self.members)

    def __repr__(self):
        return "<posedrop.PoseClasses: %d classes of %d poses>" % (len(self), len(self.class_of))


class Trials:
    """One record per drop, in drop order (``--trials``).

    q0 : (n, 4)
        Initial orientation, unit quaternion (w, x, y, z), part to world.
    pose : (n,)
        The pose (index) it settled in, -1 if it did not settle.
    collisions : (n,)
        Impulses applied (impulse engine; 0 for the stepping engines).
    time : (n,)
        Simulated seconds.
    end : (n,)
        How it ended, an index into :data:`posedrop.END_NAMES`.
    stage, status : (n,)
        A failed drop's ``pd_drop_stage`` (where it failed) and
        ``pd_status`` (how); 0 for the others.
    end_text : (n,) str
        How it ended as the ``end`` column of ``--trials`` writes it:
        ``settled``, ``time_limit``, ``collision_limit`` or
        ``failed:STAGE:STATUS`` (e.g. ``failed:flight:no_convergence``).
    params : dict of str to (n,) float64
        The values each drop drew for every ranged scene parameter, keyed by
        its name in ``pd_scene_param`` order (``mu``, ``contact_time``, ...),
        in the unit of the scene's text and of ``--trials``' columns:
        degrees for vibration, SI for the others (s for contact_time,
        resolved for this part when given in multiples of auto). Empty for a
        scene without ranges.
    """

    def __init__(self, d):
        self.q0 = _f64(d["trial_q0"], -1, 4)
        self.pose = _i32(d["trial_pose"])
        self.collisions = _i32(d["trial_collisions"])
        self.time = _f64(d["trial_time"])
        self.end = _i32(d["trial_end"])
        self.stage = _i32(d["trial_stage"])
        self.status = _i32(d["trial_status"])
        text = np.array(END_NAMES, dtype=object)[self.end]
        for i in np.flatnonzero(self.end == _FAILED):
            text[i] = "failed:%s:%s" % _failure_words(self.stage[i], self.status[i])
        self.end_text = text.astype(str)
        drawn = _f64(d["trial_param"], len(self.pose), len(PARAM_NAMES))
        self.params = {}
        for name in d["ranged"]:
            k = PARAM_NAMES.index(name)
            column = drawn[:, k]
            # As --trials prints it: vibration is stored in radians.
            column = column / (np.pi / 180.0) if name == "vibration" else column.copy()
            column.flags.writeable = False
            self.params[name] = column

    def __len__(self):
        return len(self.pose)


def _class_array(classes):
    return np.ascontiguousarray(classes.class_of, dtype=np.intc)


class Sensitivity:
    """What each ranged scene parameter moves, one row per pose (or class)
    and parameter, pose-major, as the rows of ``--sensitivity FILE``
    (``reshape(nposes, len(params))`` gives a pose-by-parameter table).

    Attributes
    ----------
    n : int
        Drops used: the settled ones (of a stationary run, only those
        started uniform).
    nposes : int
        Poses (or classes).
    params : list of str
        The ranged parameters, in ``pd_scene_param`` order; empty for a
        scene without a range of nonzero width.
    resolution : float
        The widest half-width of an effect's interval: what the drops
        resolve.
    interaction_tests : int
        Pose and ordered parameter pairs tested for an interaction.
    pose : (rows,) int32
        The pose (or class) index, from 0 (the file's ``pose`` less 1).
    parameter : (rows,) str
        The parameter's name.
    effect, effect_lo, effect_hi : (rows,)
        ``p_high - p_low``, how far the pose moves across the range, and its
        95% bootstrap interval.
    n_low, n_high : (rows,) int64
        Settled drops whose value fell in the lower, upper third of the
        range (thirds of the logarithm for a log-uniform range).
    p_low, p_low_lo, p_low_hi, p_high, p_high_lo, p_high_hi : (rows,)
        The pose's share of those and its 95% Wilson interval.
    index, index_lo, index_hi : (rows,)
        The first-order index S_i and its 95% bootstrap interval.
    interacts : (rows,) str
        The parameter across whose thirds the effect changes, or "".
    effect_in_low, effect_in_middle, effect_in_high : (rows,)
        With ``interacts``: the effect in that parameter's thirds.
    interaction, interaction_lo, interaction_hi : (rows,)
        With ``interacts``: the largest change of those and its interval.
    """

    _COLUMNS = ("effect", "effect_lo", "effect_hi", "p_low", "p_low_lo", "p_low_hi", "p_high",
                "p_high_lo", "p_high_hi", "index", "index_lo", "index_hi", "effect_in_low",
                "effect_in_middle", "effect_in_high", "interaction", "interaction_lo",
                "interaction_hi")

    def __init__(self, d):
        self.n = d["n"]
        self.nposes = d["nposes"]
        self.params = list(d["params"])
        self.pose = _i32(d["pose"])
        self.parameter = np.array(self.params * self.nposes, dtype=str)
        self.n_low = _i64(d["n_low"])
        self.n_high = _i64(d["n_high"])
        self.resolution = d["resolution"]
        self.interaction_tests = d["interaction_tests"]
        self.interacts = np.array(list(d["interacts"]), dtype=str)
        values = _f64(d["values"], -1, len(self._COLUMNS))
        for k, name in enumerate(self._COLUMNS):
            setattr(self, name, values[:, k])

    def __len__(self):
        return len(self.pose)

    def __repr__(self):
        return "<posedrop.Sensitivity: %d poses x %s, from %d drops>" % (
            self.nposes, self.params, self.n)


class Drops:
    """The outcome of Monte Carlo drops, one entry per stable pose (or class).

    Attributes
    ----------
    n : int
        Drops run.
    count : (k,) int64
        Drops that settled in each pose.
    p, ci_lo, ci_hi : (k,)
        ``count / n`` and its 95% Wilson interval; with
        ``initial="stationary"``, the long-run probability of the estimated
        pose-to-pose chain and its resampled interval.
    unsettled : int
        Drops that settled in no pose (in no count): the sum of
        ``time_limited``, ``collision_limited`` and ``failed``.
    time_limited, collision_limited, failed : int
        Drops that ended at the time limit, at the collision limit, or that
        failed (a solver could not go on; :attr:`Trials.end_text` says
        where and how).
    first_failed : int
        The first failed drop's index in the run, -1 if none.
    failed_stage, failed_status : str or None
        Where and how that drop failed (``pd_sim_result``'s
        ``failed_stage`` and ``failed_status``), as the words of its
        ``failed:STAGE:STATUS`` end (e.g. ``"flight"`` and
        ``"no_convergence"``); None when no drop failed. Known without
        ``trials=True``.
    time_limit : float
        The time limit the drops ran with, s: the ``time_limit`` given, or
        the part's automatic one.
    partial : bool
        True if the run was cancelled before all drops ran: the result holds
        the first ``n`` drops, each as in a full run.
    trials : Trials or None
        Per-drop records when ``trials=True``.
    transitions : (k, k) int64 or None
        ``initial="stationary"``: drops started resting on pose i that
        settled in pose j (the ``--transitions`` counts).
    first_count : (k,) int64 or None
        ``initial="stationary"``: uniform drops that settled in each pose (mu0).
    energy_gain, fallbacks, collisions, bootstrap_rounds, stationarity,
    first_drops, pose_drops, closed_classes, stationary_shift, seed
        As in the library's ``pd_sim_result``.
    """

    def __init__(self, poses, handle, classes=None):
        self.poses = poses
        self.classes = classes
        self._h = handle
        d = handle.arrays()
        self.n = d["n"]
        self.count = _i64(d["count"])
        self.p = _f64(d["p"])
        self.ci_lo = _f64(d["ci_lo"])
        self.ci_hi = _f64(d["ci_hi"])
        self._parent = None
        for key in ("unsettled", "time_limited", "collision_limited", "failed", "first_failed",
                    "time_limit", "energy_gain", "fallbacks", "collisions", "partial",
                    "bootstrap_rounds", "stationarity", "seed"):
            setattr(self, key, d[key])
        self.failed_stage, self.failed_status = (
            _failure_words(d["failed_stage"], d["failed_status"]) if self.failed else (None, None))
        k = d["nposes"]
        self.trials = Trials(d) if "trial_q0" in d else None
        stationary = "transitions" in d
        self.transitions = _i64(d["transitions"], k, k) if stationary else None
        self.first_count = _i64(d["first_count"]) if stationary else None
        for key in ("first_drops", "pose_drops", "closed_classes", "stationary_shift"):
            setattr(self, key, d.get(key))

    @property
    def transition_matrix(self):
        """``initial="stationary"``: the estimated chain P, each row of
        :attr:`transitions` over its settled drops (a row of zeros where no
        drop settled), as the ``p`` column of ``--transitions``."""
        if self.transitions is None:
            return None
        t = self.transitions.astype(np.float64)
        total = t.sum(axis=1, keepdims=True)
        return np.divide(t, total, out=np.zeros_like(t), where=total > 0)

    def grouped(self, classes=None):
        """The counts summed over pose classes (``--group``), with each class's
        own interval (an interval is not the sum of its members').

        classes : PoseClasses, optional
            By default the poses' own :meth:`StablePoses.classes`.
        """
        if self.classes is not None:
            raise _usage("these drops are grouped already")
        classes = self.poses.classes() if classes is None else classes
        g = Drops(self.poses, self._h.grouped(_class_array(classes), len(classes)), classes)
        g._parent = self
        return g

    def sensitivity(self):
        """What each ranged scene parameter moves (``--sensitivity FILE``).

        For every pose (or class, on :meth:`grouped` drops) and every ranged
        parameter of nonzero width: the pose's probability among the
        settled drops whose value fell in the lower and upper thirds of the
        range, and the first-order variance-based index of the pose's
        indicator with respect to the parameter (``pd_sim_sensitivity``;
        docs/uncertainty.md gives the estimator). The drops must have been
        run with ``trials=True``.

        Returns
        -------
        Sensitivity
        """
        if (self._parent if self._parent is not None else self).trials is None:
            raise _usage("sensitivity: these drops kept no per-drop records: run them with "
                         "drop(..., trials=True)")
        if self._parent is not None:
            c = self.classes
            return Sensitivity(self._parent._h.sensitivity(_class_array(c), len(c)))
        return Sensitivity(self._h.sensitivity())

    def __len__(self):
        return len(self.count)

    def __repr__(self):
        return "<posedrop.Drops: n %d%s, p %s, unsettled %d>" % (
            self.n, " (partial)" if self.partial else "",
            np.array2string(self.p, precision=4), self.unsettled)
