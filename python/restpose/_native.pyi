"""Type stubs of the extension module `restpose._native` (re-exported by `restpose`)."""

from os import PathLike
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from restpose._records import (
    ActiveLimit,
    BuriedBody,
    CheckReport,
    Contact,
    Diagnostics,
    Energy,
    Iterate,
    LimitViolation,
    Reaction,
    Stability,
    Toppled,
    Verification,
)

__version__: str

_Path = Union[str, PathLike[str]]
_Vec3 = Union[Sequence[float], npt.ArrayLike]
_Values = Mapping[str, Union[float, None, Sequence[Optional[float]]]]
_Method = str  # "newton" | "bfgs" | "dfp"
_LinearAlgebra = str  # "auto" | "dense" | "sparse" | "tree"

def load(
    path: _Path,
    *,
    packages: Optional[Mapping[str, _Path]] = None,
    gravity: Optional[_Vec3] = None,
    floating_base: bool = False,
    ground: bool = False,
    base_xyz: Optional[_Vec3] = None,
    base_rpy: Optional[_Vec3] = None,
    inertia_from_geometry: Optional[float] = None,
    locks: Optional[_Values] = None,
    initial: Optional[_Values] = None,
    servos: Optional[Mapping[str, Union[float, Tuple[float, float]]]] = None,
    servo_reference: Optional[Union[Mapping[str, float], _Path]] = None,
    srdf: Optional[_Path] = None,
    srdf_state: Optional[str] = None,
) -> Model: ...
def load_string(
    text: str,
    *,
    file: str = "<string>",
    packages: Optional[Mapping[str, _Path]] = None,
    gravity: Optional[_Vec3] = None,
    floating_base: bool = False,
    ground: bool = False,
    base_xyz: Optional[_Vec3] = None,
    base_rpy: Optional[_Vec3] = None,
    inertia_from_geometry: Optional[float] = None,
    locks: Optional[_Values] = None,
    initial: Optional[_Values] = None,
    servos: Optional[Mapping[str, Union[float, Tuple[float, float]]]] = None,
    servo_reference: Optional[Union[Mapping[str, float], _Path]] = None,
    srdf: Optional[_Path] = None,
    srdf_state: Optional[str] = None,
) -> Model: ...
def run_cli(argv: List[str]) -> int: ...

class Model:
    @property
    def name(self) -> str: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def link_names(self) -> List[str]: ...
    @property
    def body_count(self) -> int: ...
    @property
    def gravity(self) -> List[float]: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def ignored(self) -> List[str]: ...
    def check(self) -> CheckReport: ...
    def solve(
        self,
        *,
        method: _Method = "newton",
        linear_algebra: _LinearAlgebra = "auto",
        tolerance: float = 1e-8,
        constraint_tolerance: float = 1e-10,
        max_iterations: int = 200,
        load_steps: int = 0,
        allow_unstable: bool = False,
        limits: str = "enforce",
        friction: str = "none",
        mu: Optional[float] = None,
        topple: bool = True,
    ) -> Result: ...
    def verify(
        self,
        pose: Union[Result, Mapping[str, Union[float, Sequence[float]]], _Path],
        *,
        force_tolerance: float = 1e-6,
        constraint_tolerance: float = 1e-10,
        gap_tolerance: float = 1e-9,
        limits: str = "enforce",
        friction: str = "none",
        mu: Optional[float] = None,
        linear_algebra: _LinearAlgebra = "auto",
        eigenvalues: bool = False,
    ) -> Verification: ...

class Result:
    @property
    def model(self) -> Model: ...
    @property
    def robot(self) -> str: ...
    @property
    def converged(self) -> bool: ...
    @property
    def termination(self) -> str: ...
    @property
    def iterations(self) -> int: ...
    @property
    def potential_energy(self) -> float: ...
    @property
    def dof(self) -> int: ...
    @property
    def slipping(self) -> bool: ...
    @property
    def joint_names(self) -> List[str]: ...
    @property
    def q(self) -> npt.NDArray[np.float64]: ...
    @property
    def joint_slices(self) -> Dict[str, slice]: ...
    @property
    def joints(self) -> Dict[str, npt.NDArray[np.float64]]: ...
    def joint(self, name: str) -> npt.NDArray[np.float64]: ...
    @property
    def link_names(self) -> List[str]: ...
    @property
    def link_positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def link_quaternions(self) -> npt.NDArray[np.float64]: ...
    @property
    def link_transforms(self) -> npt.NDArray[np.float64]: ...
    def link_transform(self, name: str) -> npt.NDArray[np.float64]: ...
    def link_pose_of(
        self, name: str
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    @property
    def energy(self) -> Energy: ...
    @property
    def stability(self) -> Optional[Stability]: ...
    @property
    def reactions(self) -> Dict[str, Reaction]: ...
    @property
    def contacts(self) -> List[Contact]: ...
    @property
    def active_limits(self) -> List[ActiveLimit]: ...
    @property
    def limit_violations(self) -> List[LimitViolation]: ...
    @property
    def buried_bodies(self) -> List[BuriedBody]: ...
    @property
    def topple(self) -> List[Toppled]: ...
    @property
    def redundant_constraints(self) -> List[str]: ...
    @property
    def independent_coordinates(self) -> List[str]: ...
    @property
    def history(self) -> List[Iterate]: ...
    @property
    def diagnostics(self) -> Diagnostics: ...
    @property
    def sizes(self) -> Tuple[int, int, int]: ...
    def to_json(self) -> str: ...
    def to_joint_states(self) -> str: ...

class ModelBuilder:
    def __init__(self, name: str) -> None: ...
    def set_gravity(self, gravity: _Vec3) -> None: ...
    def add_rigid_body(
        self,
        name: str,
        *,
        mass: float,
        com: _Vec3 = ...,
        inertia: Optional[npt.ArrayLike] = None,
    ) -> None: ...
    def add_joint(
        self,
        name: str,
        kind_name: str,
        *,
        parent: Optional[str],
        child: Optional[str],
        xyz: Optional[_Vec3] = None,
        rpy: Optional[_Vec3] = None,
        axis: _Vec3 = ...,
        child_xyz: Optional[_Vec3] = None,
        child_rpy: Optional[_Vec3] = None,
        loop: bool = False,
        limits: Optional[Tuple[float, float]] = None,
        pitch: Optional[float] = None,
        length: Optional[float] = None,
    ) -> None: ...
    def add_joint_spring(
        self,
        joint: str,
        *,
        stiffness: float,
        reference: float = 0.0,
        preload: float = 0.0,
        dof: int = 0,
    ) -> None: ...
    def add_spring(
        self,
        name: str,
        *,
        body_a: Optional[str],
        point_a: _Vec3,
        body_b: Optional[str],
        point_b: _Vec3,
        stiffness: float,
        free_length: float = 0.0,
        preload: float = 0.0,
        mode: str = "both",
    ) -> None: ...
    def add_load(self, name: str, *, body: str, point: _Vec3, force: _Vec3) -> None: ...
    def add_effort(self, joint: str, value: float, *, dof: int = 0) -> None: ...
    def add_lock(self, joint: str, value: Optional[float] = None, *, dof: int = 0) -> None: ...
    def add_initial(self, joint: str, value: float, *, dof: int = 0) -> None: ...
    def add_ground(self, name: str, *, origin: _Vec3 = ..., normal: _Vec3 = ...) -> None: ...
    def set_base_pose(self, *, xyz: Optional[_Vec3] = None, rpy: Optional[_Vec3] = None) -> None: ...
    def build(self) -> Model: ...
