"""Shared fixtures: the repository's example robots and the published robots of
example-robot-data (installed from PyPI in the test venv)."""

from __future__ import annotations

import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
ROBOTS = REPO / "robots"


@pytest.fixture(scope="session")
def robots() -> pathlib.Path:
    return ROBOTS


def example_robot_data_dir() -> pathlib.Path | None:
    """The `robots` folder of the example-robot-data wheel (a cmeel prefix), if installed."""
    try:
        import cmeel  # noqa: F401  (the prefix lives beside it in site-packages)
    except ImportError:
        pass
    import site
    import sys

    for base in [*site.getsitepackages(), *sys.path]:
        d = pathlib.Path(base) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if d.is_dir():
            return d
    return None
