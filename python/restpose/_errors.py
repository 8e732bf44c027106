"""Exceptions raised by restpose: one class per kind of error, all subclasses of
:class:`restpose.Error`. Attributes not known for an error are ``None``."""

from __future__ import annotations

from typing import Optional

__all__ = [
    "Error",
    "FileError",
    "InputError",
    "UnknownJointError",
    "CoordinateError",
    "PoseError",
    "ModelError",
    "AssemblyError",
    "ConstantEnergyError",
    "SolveError",
]


class Error(Exception):
    """Base class of every restpose error. ``message`` is the text ``restpose`` prints; the
    location attributes (``file``, ``line``, ``column``, ``element``, ``joint``) are set where
    the error has them, else ``None``."""

    file: Optional[str] = None
    line: Optional[int] = None
    column: Optional[int] = None
    element: Optional[str] = None
    joint: Optional[str] = None

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message

    def __str__(self) -> str:
        return self.message


class FileError(Error, OSError):
    """A file could not be read or written (``file``, ``errno``)."""

    errno: Optional[int] = None


class InputError(Error, ValueError):
    """The input file is malformed or inconsistent at ``file``:``line``:``column``, in
    ``element`` (the tag as written, e.g. ``"joint"`` or ``"mech:spring"``; ``None`` where the
    error is not at an element, such as an XML syntax error)."""


class UnknownJointError(Error, LookupError):
    """A joint name the model does not have (``joint``), given as ``what`` (``"lock"``,
    ``"pose"``, ...); ``suggestion`` is the closest name of the model, if one is close."""

    what: Optional[str] = None
    suggestion: Optional[str] = None


class CoordinateError(Error, IndexError):
    """A coordinate index or a number of values that the joint does not have (``joint``,
    ``kind``, ``dof`` or ``expected``, ``count``)."""

    kind: Optional[str] = None
    dof: Optional[int] = None
    count: Optional[int] = None
    expected: Optional[list] = None


class PoseError(Error, ValueError):
    """A pose file that is none of the accepted formats (``file``)."""


class ModelError(Error, ValueError):
    """A model built in code (or a number of a file) that cannot be used: an unknown id, a
    negative or non-finite mass, an out-of-range number (``element``, ``name``, ``attribute``,
    ``value`` for the latter)."""

    name: Optional[str] = None
    attribute: Optional[str] = None
    value: Optional[float] = None


class AssemblyError(Error):
    """The loop joints cannot be closed from the initial guess, or redundant constraints
    disagree (``joint`` and its location, ``row``, ``residual``)."""

    row: Optional[str] = None
    residual: Optional[float] = None
    iterations: Optional[int] = None


class ConstantEnergyError(Error):
    """Nothing stores or releases energy while the mechanism can move (``robot``, ``dof``):
    every pose is a rest pose."""

    robot: Optional[str] = None
    dof: Optional[int] = None


class SolveError(Error):
    """The solve or verification failed for another reason (a non-finite number, a force table
    evaluated outside its range, a singular partition, too many degrees of freedom for a
    quasi-Newton method)."""
