"""Plain records of a result, a check and a verification: attribute access over the
library's serialized values, with number lists as numpy arrays. Field names are those of the
command line's JSON."""

from __future__ import annotations

import json
from typing import Any, Dict, List, Optional

import numpy as np

__all__ = [
    "Record",
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
    "CheckReport",
    "Verification",
]


class Record:
    """Fields of a section of restpose's JSON as attributes (``to_dict()`` gives them back)."""

    _arrays: tuple = ()
    _nested: Dict[str, Any] = {}

    def __init__(self, data: Dict[str, Any]) -> None:
        self._data = data
        for key, value in data.items():
            if key in self._arrays and value is not None:
                value = np.asarray(value, dtype=float)
            elif key in self._nested and value is not None:
                cls = self._nested[key]
                value = [cls(v) for v in value] if isinstance(value, list) else cls(value)
            setattr(self, key, value)

    def to_dict(self) -> Dict[str, Any]:
        """The fields as plain Python values (as in the JSON)."""
        return self._data

    def __eq__(self, other: object) -> bool:
        return type(other) is type(self) and other._data == self._data  # type: ignore[attr-defined]

    def __repr__(self) -> str:
        fields = ", ".join(
            f"{k}={v!r}" for k, v in self._data.items() if not isinstance(v, (list, dict)) or len(v) <= 6
        )
        return f"{type(self).__name__}({fields})"


class Energy(Record):
    """Potential energy by source [J]: ``total``, ``gravity``, ``springs``,
    ``joint_springs``, ``loads``."""

    total: float
    gravity: float
    springs: float
    joint_springs: float
    loads: float


class Stability(Record):
    """Stability verdict of a rest pose: ``verdict`` (``"stable"``, ``"unstable"``,
    ``"neutral"``), the eigenvalue ``tolerance`` [J], the lowest ``eigenvalues`` of the scaled
    reduced Hessian (ascending) and their ``modes`` (``{joint: change of its coordinates}``,
    largest entry ±1)."""

    _arrays = ("eigenvalues",)
    verdict: str
    tolerance: float
    eigenvalues: np.ndarray
    modes: List[Dict[str, np.ndarray]]

    def __init__(self, data: Dict[str, Any]) -> None:
        super().__init__(data)
        self.modes = [{k: np.asarray(v, dtype=float) for k, v in m.items()} for m in data["modes"]]

    @property
    def stable(self) -> bool:
        """Whether the verdict is ``"stable"``."""
        return self.verdict == "stable"


class Reaction(Record):
    """Reaction of a joint on its child link at the joint origin: ``force_world`` [N],
    ``torque_world`` [N m] in the world frame, ``force_joint``, ``torque_joint`` in the joint
    frame."""

    _arrays = ("force_world", "torque_world", "force_joint", "torque_joint")
    force_world: np.ndarray
    torque_world: np.ndarray
    force_joint: np.ndarray
    torque_joint: np.ndarray


class Contact(Record):
    """A contact point on a ground: ``link``, ``ground``, ``point_world``, ``normal_world``,
    ``gap`` [m], ``normal_force`` [N], ``tangential_force`` [N], ``required_friction``,
    ``state``."""

    _arrays = ("point_world", "normal_world", "tangential_force")
    link: str
    ground: str
    point_world: np.ndarray
    normal_world: np.ndarray
    gap: float
    normal_force: float
    tangential_force: np.ndarray
    required_friction: float
    state: str


class ActiveLimit(Record):
    """A joint resting on a stop: ``joint``, ``bound`` (``"lower"``/``"upper"``), ``value``,
    ``effort`` the stop carries [N m or N]."""

    joint: str
    bound: str
    value: float
    effort: float


class LimitViolation(Record):
    """A joint resting outside its URDF limits (with ``limits="ignore"``): ``joint``,
    ``position``, ``limits``."""

    _arrays = ("limits",)
    joint: str
    position: float
    limits: np.ndarray


class BuriedBody(Record):
    """A body without contact points whose centre of mass lies inside a ground: ``body``,
    ``ground``, ``depth`` [m] below the ground plane."""

    body: str
    ground: str
    depth: float


class Toppled(Record):
    """A floating group that could not stand on its ground start and toppled as a rigid body
    before the solve: ``body`` (its first link), ``steps`` (turns over a support edge or
    point), ``angle`` [rad] (its net rotation), ``support_before`` and ``support_after`` (links
    touching the ground), ``com_outside`` [m] (the centre of mass's projection outside the
    start support), ``energy_released`` [J], ``stopped`` (why it stopped early, or absent)."""

    body: str
    steps: int
    angle: float
    support_before: List[str]
    support_after: List[str]
    com_outside: float
    energy_released: float


class Iterate(Record):
    """One minimizer iteration: ``iteration``, ``potential_energy`` [J], ``gradient_norm``."""

    iteration: int
    potential_energy: float
    gradient_norm: float


class Diagnostics(Record):
    """Solver counters: ``gradient_norm``, ``constraint_residual``, ``function_evaluations``,
    ``corrector_failures``, ``step_halvings``, ``repartitions``, ``load_steps``,
    ``linear_algebra``, ``free_directions``, ``timings`` (seconds by stage), ..."""

    gradient_norm: float
    constraint_residual: float
    timings: Dict[str, float]


class Imbalance(Record):
    """Effort a joint coordinate needs to hold a pose: ``joint``, ``dof``, ``effort``."""

    joint: str
    dof: int
    effort: float


class _Json(Record):
    def __init__(self, data: Dict[str, Any], text: str) -> None:
        super().__init__(data)
        self._json = text

    def to_json(self) -> str:
        """The JSON text the command line writes for this."""
        return self._json


class CheckReport(_Json):
    """What ``restpose check`` says of a model: ``robot``, ``bodies`` (name, mass, links),
    ``fixed_links``, ``joints`` (name, type, parent, child, role, rows), ``springs``,
    ``forces``, ``gravity``, ``coordinates``, ``constraints``, ``dof`` (``None`` if the initial
    guess does not assemble), ``assembly_error``, ``warnings``, ``ignored``.
    ``to_json()`` equals ``restpose check --format json``."""

    _arrays = ("gravity",)
    robot: str
    bodies: List[Dict[str, Any]]
    fixed_links: List[str]
    joints: List[Dict[str, Any]]
    springs: List[str]
    forces: List[str]
    gravity: np.ndarray
    coordinates: int
    constraints: int
    dof: Optional[int]
    assembly_error: Optional[str]
    warnings: List[str]
    ignored: List[str]


class Verification(_Json):
    """Whether a pose is a rest pose (``restpose verify``): ``passed``,
    ``constraint_residual`` (raw ‖Φ‖∞), ``scaled_constraint_residual`` (‖DΦ‖∞, what
    ``constraint_tolerance`` bounds), ``imbalance`` (the effort each joint coordinate needs),
    ``max_imbalance``, ``unassigned``, ``projected_gradient``, ``potential_energy``,
    ``stability``, ``tolerances``, ``effort_tolerance``, ``contacts``, ``active_limits``,
    ``failures``. ``to_json()`` equals ``restpose verify --json -``."""

    _nested = {
        "imbalance": Imbalance,
        "max_imbalance": Imbalance,
        "stability": Stability,
        "contacts": Contact,
        "active_limits": ActiveLimit,
    }
    passed: bool
    constraint_residual: float
    scaled_constraint_residual: float
    imbalance: List[Imbalance]
    max_imbalance: Optional[Imbalance]
    unassigned: float
    projected_gradient: float
    potential_energy: float
    stability: Optional[Stability]
    tolerances: Dict[str, float]
    effort_tolerance: float
    contacts: List[Contact]
    active_limits: List[ActiveLimit]
    failures: List[str]

    def __bool__(self) -> bool:
        return bool(self.passed)

    def explain(self) -> str:
        """A readable account of why the pose passes or fails (the largest imbalances, the
        residual, what the stops and contacts refuse)."""
        lines = [
            f"{'passed' if self.passed else 'NOT a rest pose'}: constraint residual "
            f"{self.scaled_constraint_residual:.3e} (tolerance {self.tolerances['constraint']:.1e}), "
            f"effort tolerance {self.effort_tolerance:.3e}"
        ]
        worst = sorted(self.imbalance, key=lambda i: -abs(i.effort))[:5]
        for i in worst:
            flag = "  <-- exceeds" if abs(i.effort) > self.effort_tolerance else ""
            lines.append(f"  joint {i.joint!r} dof {i.dof}: needs effort {i.effort:+.3e}{flag}")
        if self.unassigned > self.effort_tolerance:
            lines.append(f"  unassigned generalized force {self.unassigned:.3e}")
        for f in self.failures:
            lines.append(f"  {f}")
        return "\n".join(lines)


_SECTIONS = {
    "energy": Energy,
    "stability": Stability,
    "contacts": Contact,
    "active_limits": ActiveLimit,
    "limit_violations": LimitViolation,
    "buried_bodies": BuriedBody,
    "topple": Toppled,
    "history": Iterate,
    "diagnostics": Diagnostics,
}


def wrap(section: str, value: Any) -> Any:
    """The record(s) of a result section given as plain values."""
    if value is None:
        return None
    if section == "reactions":
        return {name: Reaction(r) for name, r in value}
    cls = _SECTIONS.get(section)
    if cls is None:
        return value
    if isinstance(value, list):
        return [cls(v) for v in value]
    return cls(value)


def dumps(value: Any) -> str:
    """Pretty JSON as the command line writes it."""
    return json.dumps(value, indent=2)
