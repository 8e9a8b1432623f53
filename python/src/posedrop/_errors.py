"""Exceptions and warnings of the posedrop package.

Every failure of the C library arrives as a PosedropError carrying the
library's status (``status``, its short name ``status_name``) and its one-line
message. Mistakes in the input (a malformed file, a scene value out of range,
a mesh with no volume) raise InputError, which is also a ValueError; failures
of the library itself (a failed internal check, memory) raise InternalError,
which is also a RuntimeError. The command exits 2 for the first kind and 1
for the second.
"""


class PosedropError(Exception):
    """A posedrop library call failed.

    Attributes
    ----------
    status : int
        The library's ``pd_status`` value (see :class:`posedrop.Status`).
    status_name : str
        Its short fixed name, e.g. ``"parse error"``.
    message : str
        The library's message, e.g. ``"cap.off:12: expected 3 coordinates, found 2"``.
    """

    def __init__(self, status, status_name, message):
        super().__init__(message)
        self.status = status
        self.status_name = status_name
        self.message = message

    def __reduce__(self):
        return (type(self), (self.status, self.status_name, self.message))


class InputError(PosedropError, ValueError):
    """Bad input: a file, mesh, array, option or scene value the library refuses."""


class InternalError(PosedropError, RuntimeError):
    """The library failed on valid input (a bug to report, or out of memory)."""


class PosedropWarning(UserWarning):
    """A warning from the library: faces re-oriented, knife-edge facets, ..."""


class UnitsWarning(PosedropWarning):
    """A part of a size no dropped part has (outside 0.5 mm to 2 m across): most
    likely a file in millimetres read as metres (trimesh reads STL without
    units); the warning names the ``units=`` to try. The command's warning."""


# Shown and pickled as posedrop.InputError etc., where users import them.
for _cls in (PosedropError, InputError, InternalError, PosedropWarning, UnitsWarning):
    _cls.__module__ = "posedrop"
