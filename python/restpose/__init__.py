"""restpose: the static equilibrium (rest pose) of URDF mechanisms, from Python.

>>> import restpose
>>> model = restpose.load("robots/pendulum.urdf")
>>> result = model.solve()
>>> result.converged, result.joint("pivot")
(True, array([-1.38157...]))

``restpose.load`` / ``restpose.load_string`` read URDF (with the ``mech:`` extensions),
``restpose.ModelBuilder`` builds a mechanism in code; ``Model.solve`` finds the stable rest
pose (the GIL released meanwhile) and returns a ``restpose.Result`` (joint values and link
frames as numpy arrays, energy, stability, reactions, stops, contacts, ``to_json()`` = the
command line's JSON); ``Model.verify`` checks a pose independently;
``restpose.testing.assert_rest_pose`` does so in a test. Errors are subclasses of
``restpose.Error`` with the file, line, column and element as attributes.

The distribution is ``restpose-urdf`` (``pip install restpose-urdf``): ``restpose`` on PyPI is
an unrelated project. It installs the ``restpose`` command line too.
"""

from __future__ import annotations

from os import PathLike
from typing import Any, Mapping, Optional, Sequence, Union

from restpose._errors import (
    AssemblyError,
    ConstantEnergyError,
    CoordinateError,
    Error,
    FileError,
    InputError,
    ModelError,
    PoseError,
    SolveError,
    UnknownJointError,
)
from restpose._native import Model, ModelBuilder, Result, __version__, load, load_string
from restpose._records import (
    ActiveLimit,
    BuriedBody,
    CheckReport,
    Contact,
    Diagnostics,
    Energy,
    Imbalance,
    Iterate,
    LimitViolation,
    Reaction,
    Stability,
    Toppled,
    Verification,
)

__all__ = [
    "load",
    "load_string",
    "analyze",
    "Model",
    "ModelBuilder",
    "Result",
    "CheckReport",
    "Verification",
    "Energy",
    "Stability",
    "Reaction",
    "Contact",
    "ActiveLimit",
    "LimitViolation",
    "BuriedBody",
    "Toppled",
    "Iterate",
    "Diagnostics",
    "Imbalance",
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
    "__version__",
]

_LOAD_OPTIONS = (
    "packages",
    "gravity",
    "floating_base",
    "ground",
    "base_xyz",
    "base_rpy",
    "inertia_from_geometry",
    "locks",
    "initial",
    "servos",
    "servo_reference",
    "srdf",
    "srdf_state",
)


def analyze(path: Union[str, "PathLike[str]"], **options: Any) -> Result:
    """``restpose analyze`` in one call: loads ``path`` with the input options of
    :func:`restpose.load` (``packages``, ``gravity``, ``floating_base``, ``ground``,
    ``base_xyz``, ``base_rpy``, ``inertia_from_geometry``, ``locks``, ``initial``, ``servos``,
    ``servo_reference``, ``srdf``, ``srdf_state``) and solves
    it with the solver options of :meth:`restpose.Model.solve` (``method``,
    ``linear_algebra``, ``tolerance``, ``constraint_tolerance``, ``max_iterations``,
    ``load_steps``, ``allow_unstable``, ``limits``, ``friction``, ``mu``, ``topple``)."""
    load_options = {k: options.pop(k) for k in _LOAD_OPTIONS if k in options}
    return load(path, **load_options).solve(**options)
