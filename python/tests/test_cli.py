"""The `restpose` command installed by the wheel is the command line of the Rust binary."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import pytest


def run(*args, **kw):
    return subprocess.run(["restpose", *map(str, args)], capture_output=True, text=True, **kw)


def test_the_command_is_on_the_path_of_the_venv():
    exe = shutil.which("restpose")
    assert exe is not None and sys.prefix in exe


def test_analyze_prints_the_summary_and_exits_0(robots):
    out = run("analyze", robots / "pendulum.urdf")
    assert out.returncode == 0, out.stderr
    assert "robot `pendulum`" in out.stdout and "stable" in out.stdout


def test_analyze_json_to_stdout(robots):
    out = run("analyze", robots / "pendulum.urdf", "--json", "-")
    assert out.returncode == 0
    r = json.loads(out.stdout)
    assert r["converged"] and r["joints"]["pivot"]["position"][0] == pytest.approx(-1.381577, abs=1e-6)


def test_exit_codes(robots, tmp_path):
    assert run("analyze", tmp_path / "missing.urdf").returncode == 1
    assert run("analyze", robots / "pendulum.urdf", "--max-iterations", "1").returncode == 3
    assert run("verify", robots / "pendulum.urdf", "--joint", "pivot=0").returncode == 4
    usage = run("analyze", robots / "pendulum.urdf", "--no-such-flag")
    assert usage.returncode == 2 and "--no-such-flag" in usage.stderr
    assert run("--help").returncode == 0
    version = run("--version")
    assert version.returncode == 0 and version.stdout.startswith("restpose ")


def test_located_error_on_stderr(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text('<robot name="r"><link name="a"/>\n<joint name="j" type="hinge"/></robot>')
    out = run("check", bad)
    assert out.returncode == 1 and f"{bad}:2:1" in out.stderr


def test_python_m_form(robots):
    out = subprocess.run(
        [sys.executable, "-m", "restpose._cli", "check", str(robots / "pendulum.urdf")],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0 and "pendulum" in out.stdout
