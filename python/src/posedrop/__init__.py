"""posedrop: how a rigid part comes to rest when dropped on a flat surface.

The Python binding of libposedrop (the C library of the posedrop command):
stable poses with their quasi-static (QS) and perturbed quasi-static (PQS)
probabilities, and Monte Carlo drops on posedrop's impulse simulator, ODE or
Bullet. Every number is the library's, the same as the command prints for the
same part, options and seed.

    import posedrop, trimesh
    part = posedrop.Part.from_trimesh(trimesh.creation.box((0.04, 0.02, 0.01)))
    poses = part.stable_poses()
    poses.p_qs, poses.transform             # numpy arrays
    drops = poses.drop(2000, seed=1, mu=0.5)
    drops.count, drops.p, drops.ci_lo, drops.ci_hi

See docs/python.md in the repository.
"""
import enum as _enum
import signal as _signal
import threading as _threading

from . import _posedrop
from ._api import (END_NAMES, PARAM_NAMES, Design, DesignSensitivity, Drops, Facets, Part,
                   PoseClasses, Sensitivity, StablePoses, Trials)
from ._errors import InputError, InternalError, PosedropError, PosedropWarning, UnitsWarning
from ._trimesh import compute_stable_poses

#: The library's statuses (``pd_status``), e.g. ``Status.ERR_PARSE``.
Status = _enum.IntEnum("Status", _posedrop.statuses())

#: The version of the C library the module runs (``pd_version()``).
__version__ = _posedrop.version()


def _on_sigint(signum, frame):
    """Ctrl-C: drops running on any thread stop (raising KeyboardInterrupt
    there), not only those the main thread waits for; then the usual
    KeyboardInterrupt in the main thread."""
    _posedrop.interrupt()
    _signal.default_int_handler(signum, frame)


# Only in place of Python's own handler, and only from the main thread (the
# only one that may set a handler): a program's own handler is left alone.
if (_threading.current_thread() is _threading.main_thread()
        and _signal.getsignal(_signal.SIGINT) is _signal.default_int_handler):
    _signal.signal(_signal.SIGINT, _on_sigint)


def engine_available(engine):
    """True if drops can run on that engine ("impulse", "ode", "bullet") here."""
    return _posedrop.engine_available(engine)


__all__ = ["Part", "StablePoses", "Facets", "PoseClasses", "Drops", "Trials", "Sensitivity",
           "Design", "DesignSensitivity",
           "END_NAMES", "PARAM_NAMES",
           "compute_stable_poses", "PosedropError", "InputError", "InternalError",
           "PosedropWarning", "UnitsWarning", "Status", "engine_available", "__version__"]
