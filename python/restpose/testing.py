"""Assertions for tests (pytest or unittest): a pose is a rest pose, checked by restpose's
independent verification (``Model.verify``), with a readable failure message."""

from __future__ import annotations

from os import PathLike
from typing import Any, Mapping, Sequence, Union

from restpose._native import Model, Result
from restpose._records import Verification

__all__ = ["assert_rest_pose"]


def assert_rest_pose(
    model: Model,
    pose: Union[Result, Mapping[str, Union[float, Sequence[float]]], str, "PathLike[str]"],
    *,
    stable: bool = False,
    **options: Any,
) -> Verification:
    """Asserts that ``pose`` is a rest pose of ``model`` (and a stable one if ``stable``);
    returns the verification. ``pose`` is a ``restpose.Result``, a ``{joint: value(s)}`` dict
    or a pose file; ``options`` are those of ``Model.verify`` (``force_tolerance`` [N m or N],
    ``constraint_tolerance``, ``limits``, ``friction``, ``mu``, ``linear_algebra``).

    Raises ``AssertionError`` naming the joints that need an effort to hold the pose.
    """
    v = model.verify(pose, **options)
    if not v.passed:
        raise AssertionError(f"{model.name}: pose is not a rest pose\n{v.explain()}")
    if stable and (v.stability is None or v.stability.verdict != "stable"):
        verdict = "no degree of freedom" if v.stability is None else v.stability.verdict
        eig = "" if v.stability is None else f", lowest eigenvalues {list(v.stability.eigenvalues)}"
        raise AssertionError(f"{model.name}: rest pose is not stable ({verdict}{eig})")
    return v
