"""The Python API: load, check, solve with the command line's options, results as numpy
arrays and records, the JSON contract, the builder, verify and restpose.testing, threads."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import restpose
from restpose.testing import assert_rest_pose

# The pendulum of Nikravesh & Srinivasan (1985): closed-form rest angle and energy
# (robots/pendulum.urdf's header).
PENDULUM_PHI = -1.381577
PENDULUM_V = -18.686957


# A 1 kg point mass at 1 m on a hinge about y with a 10 N m/rad spring; no <mech:gravity>.
ARM = """<robot name="arm" xmlns:mech="urn:urdf-mech:1"><link name="base"/>
<link name="arm"><inertial><origin xyz="1 0 0"/><mass value="1"/>
<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
<joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/></joint>
<mech:joint_spring joint="j" stiffness="10"/></robot>"""


def without_timings(d: dict) -> dict:
    d = json.loads(json.dumps(d))
    d["diagnostics"].pop("timings")
    return d


def test_pendulum_solves_to_the_papers_answer(robots):
    model = restpose.load(robots / "pendulum.urdf")
    result = model.solve()
    assert result.converged and result.termination == "converged"
    assert result.joint("pivot").shape == (1,)
    assert result.joint("pivot")[0] == pytest.approx(PENDULUM_PHI, abs=1e-6)
    assert result.potential_energy == pytest.approx(PENDULUM_V, abs=1e-6)
    assert result.energy.total == pytest.approx(result.potential_energy)
    assert result.energy.gravity + result.energy.springs == pytest.approx(result.energy.total)
    assert result.stability.verdict == "stable" and result.stability.stable
    assert result.stability.eigenvalues.shape == (1,) and result.stability.eigenvalues[0] > 0
    assert set(result.stability.modes[0]) == {"pivot"}
    assert result.dof == 1 and result.sizes == (1, 7, 6)
    # the independent equilibrium: spring torque balances gravity about the pivot
    r = result.reactions["pivot"]
    assert isinstance(r.force_world, np.ndarray) and r.force_world.shape == (3,)


def test_arrays_agree_with_each_other(robots):
    result = restpose.load(robots / "ur5_class.urdf").solve()
    assert result.converged
    names = result.link_names
    pos, quat, tf = result.link_positions, result.link_quaternions, result.link_transforms
    assert pos.shape == (len(names), 3) and quat.shape == (len(names), 4)
    assert tf.shape == (len(names), 4, 4)
    np.testing.assert_allclose(np.linalg.norm(quat, axis=1), 1.0, atol=1e-12)
    assert (quat[:, 0] >= 0).all()
    for i, name in enumerate(names):
        t = result.link_transform(name)
        np.testing.assert_array_equal(t, tf[i])
        np.testing.assert_allclose(t[:3, 3], pos[i], atol=1e-15)
        # rotation from the quaternion w x y z
        w, x, y, z = quat[i]
        rot = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )
        np.testing.assert_allclose(t[:3, :3], rot, atol=1e-12)
        p, q = result.link_pose_of(name)
        np.testing.assert_array_equal(p, pos[i])
        np.testing.assert_array_equal(q, quat[i])
    # q is the joints' values concatenated in model order
    q = result.q
    for name, sl in result.joint_slices.items():
        np.testing.assert_array_equal(q[sl], result.joints[name])
        np.testing.assert_array_equal(result.joint(name), result.joints[name])
    assert list(result.joints) == result.joint_names == result.model.joint_names


def test_to_json_is_the_command_lines_json(robots, tmp_path):
    path = robots / "four_bar_spatial.urdf"
    out = tmp_path / "r.json"
    subprocess.run(
        ["restpose", "analyze", "-q", str(path), "--json", str(out)], check=True
    )
    cli = json.loads(out.read_text())
    py = json.loads(restpose.load(path).solve().to_json())
    assert without_timings(py) == without_timings(cli)
    # every field of the JSON is reachable from the result
    r = restpose.load(path).solve()
    assert r.redundant_constraints == cli["redundant_constraints"]
    assert r.independent_coordinates == cli["independent_coordinates"]
    assert [i.iteration for i in r.history] == [i["iteration"] for i in cli["history"]]
    assert r.diagnostics.gradient_norm == cli["diagnostics"]["gradient_norm"]
    assert r.iterations == cli["iterations"] and r.dof == cli["dof"]


def test_joint_states_are_the_command_lines(robots, tmp_path):
    path = robots / "ur5_class.urdf"
    out = tmp_path / "js.yaml"
    subprocess.run(
        ["restpose", "analyze", "-q", str(path), "--write-joint-states", str(out)], check=True
    )
    result = restpose.load(path).solve()
    assert result.to_joint_states() == out.read_text()
    # and it is a pose that verify reads back as a rest pose
    back = tmp_path / "back.yaml"
    back.write_text(result.to_joint_states())
    assert result.model.verify(back).passed


def test_check_is_the_command_lines_check(robots):
    path = robots / "four_bar_spatial.urdf"
    cli = subprocess.run(
        ["restpose", "check", str(path), "--format", "json"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    report = restpose.load(path).check()
    assert json.loads(report.to_json()) == json.loads(cli)
    assert report.dof == json.loads(cli)["dof"] and report.assembly_error is None
    assert {j["role"] for j in report.joints} >= {"tree", "loop"}


def test_solver_options_change_the_solve(robots):
    model = restpose.load(robots / "pendulum.urdf")
    newton = model.solve()
    for method in ("bfgs", "dfp"):
        r = model.solve(method=method)
        assert r.converged
        assert r.joint("pivot")[0] == pytest.approx(newton.joint("pivot")[0], abs=1e-5)
    dense = model.solve(linear_algebra="dense")
    sparse = model.solve(linear_algebra="sparse")
    assert dense.diagnostics.linear_algebra == "dense"
    assert sparse.diagnostics.linear_algebra == "sparse"
    assert sparse.joint("pivot")[0] == pytest.approx(dense.joint("pivot")[0], abs=1e-8)
    stopped = model.solve(max_iterations=1)
    assert not stopped.converged and stopped.termination == "max_iterations"
    loose = model.solve(tolerance=1e-2)
    assert loose.iterations <= newton.iterations
    stepped = model.solve(load_steps=4)
    assert stepped.converged and stepped.diagnostics.load_steps == 4
    with pytest.raises(ValueError, match="method"):
        model.solve(method="gradient")
    with pytest.raises(ValueError, match="tolerance"):
        model.solve(tolerance=-1.0)
    with pytest.raises(ValueError, match="load_steps"):
        model.solve(load_steps=5000)


def test_input_options_locks_initial_gravity(robots):
    path = robots / "pendulum.urdf"
    locked = restpose.load(path, locks={"pivot": -0.5}).solve()
    assert locked.joint("pivot")[0] == pytest.approx(-0.5, abs=1e-10)
    # gravity applies only when the file has none: the pendulum's file has one
    assert restpose.load(path, gravity=(0, 0, -1)).gravity == pytest.approx([0, -9.81, 0])
    start = restpose.load(path, initial={"pivot": -1.3}).solve()
    assert start.joint("pivot")[0] == pytest.approx(PENDULUM_PHI, abs=1e-6)
    moon = restpose.load_string(ARM, gravity=(0, 0, -1.62))
    assert moon.gravity == pytest.approx([0, 0, -1.62])
    # k θ = m g L cos θ for the arm (1 kg at 1 m, 10 N m/rad about y)
    for model, g in ((moon, 1.62), (restpose.load_string(ARM), 9.81)):
        theta = model.solve().joint("j")[0]
        assert 10.0 * theta == pytest.approx(g * 1.0 * math.cos(theta), abs=1e-8)
    # several coordinates: a list (None = not given) or "joint[dof]" keys, as on the command line
    with pytest.raises(restpose.CoordinateError):
        restpose.load(path, locks={"pivot": [None, 0.3]})
    with pytest.raises(restpose.CoordinateError):
        restpose.load(path, initial={"pivot[1]": 0.3})
    assert restpose.load(path, locks={"pivot[0]": -0.5}).solve().joint("pivot")[0] == pytest.approx(-0.5)
    with pytest.raises(ValueError, match="finite"):
        restpose.load(path, locks={"pivot": float("nan")})
    # the analyze shortcut: input and solver options in one call
    r = restpose.analyze(path, locks={"pivot": -0.5}, method="bfgs")
    assert r.joint("pivot")[0] == pytest.approx(-0.5, abs=1e-10)


def test_floating_base_on_the_ground(robots):
    solo = robots / "solo12"
    urdf = next(solo.glob("*.urdf"))
    model = restpose.load(urdf, floating_base=True, ground=True, base_xyz=(0, 0, 0.5))
    result = model.solve()
    assert result.converged
    assert len(result.contacts) > 0
    total = sum(c.normal_force for c in result.contacts)
    mass = sum(b["mass"] for b in model.check().bodies)
    # the ground carries the weight
    assert total == pytest.approx(mass * 9.81, rel=1e-6)
    assert all(c.gap > -1e-6 for c in result.contacts)


PLANK = """<robot name="plank">
  <link name="plank"><inertial><origin xyz="0.45 0 0.125"/><mass value="3"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><origin xyz="0.45 0 0.125"/><geometry><box size="1.0 0.2 0.05"/></geometry></collision></link>
  <link name="foot"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="weld" type="fixed"><parent link="plank"/><child link="foot"/></joint>
</robot>"""


def test_a_body_that_cannot_stand_topples_at_the_ground_start():
    # A plank on a foot under its end (docs/servo.md, the topple): its centre of mass 0.40 m
    # beyond the foot's edge, it turns about that edge until the plank's far corners (0.9 m
    # out, 0.1 m up) touch, tan(angle) = 1/9, and rests with its centre of mass at 0.725/sqrt(82).
    model = restpose.load_string(PLANK, floating_base=True, ground=True)
    result = model.solve(friction="stick")
    assert result.converged
    [t] = result.topple
    assert isinstance(t, restpose.Toppled)
    assert (t.body, t.steps) == ("plank", 1)
    assert t.angle == pytest.approx(math.atan(1 / 9), abs=1e-12)
    assert t.com_outside == pytest.approx(0.40, abs=1e-12)
    assert (t.support_before, t.support_after) == (["foot"], ["plank", "foot"])
    assert result.potential_energy == pytest.approx(3 * 9.81 * 0.725 / math.sqrt(82), abs=1e-9)
    assert json.loads(result.to_json())["topple"] == [t.to_dict()]
    # off: no topple, the field absent; the solve itself lets it fall from the foot
    off = model.solve(friction="stick", topple=False)
    assert off.topple == [] and "topple" not in json.loads(off.to_json())


def test_servos_about_an_srdf_state_are_the_command_lines(robots, tmp_path):
    # Bolt standing as in the Pinocchio corpus (docs/servo.md): servos of 1000 N m/rad about
    # its SRDF `standing` state, which is also the start; it topples onto its trunk, then the
    # solve converges. The same numbers as `restpose analyze` with the same options.
    bolt = robots / "bolt"
    srdf = bolt / "bolt.srdf"
    out = tmp_path / "bolt.json"
    subprocess.run(
        ["restpose", "analyze", "-q", str(bolt / "bolt.urdf"), "--floating-base", "--ground",
         "--friction", "stick", "--servo", "all=1000", "--servo", "FL_KFE=500@-1.5",
         "--srdf", str(srdf), "--srdf-state", "standing", "--load-steps", "1",
         "--json", str(out)],
        check=True,
    )
    cli = json.loads(out.read_text())
    model = restpose.load(
        bolt / "bolt.urdf", floating_base=True, ground=True,
        servos={"FL_KFE": (500, -1.5), "all": 1000}, srdf=srdf, srdf_state="standing",
    )
    r = model.solve(friction="stick", load_steps=1)
    assert r.converged and r.iterations == cli["iterations"]
    assert r.potential_energy == cli["potential_energy"]
    assert [t.to_dict() for t in r.topple] == cli["topple"]
    servos = json.loads(r.to_json())["servos"]
    assert servos == cli["servos"]
    assert {s["joint"]: (s["stiffness"], s["reference"]) for s in servos}["FL_KFE"] == (500, -1.5)
    # a mapping as the reference pose: the SRDF state's values give the same rest
    state = {"FL_HAA": -0.3, "FL_HFE": 0.78539816, "FL_KFE": -1.57079633,
             "FR_HAA": 0.3, "FR_HFE": 0.78539816, "FR_KFE": -1.57079633}
    common = dict(floating_base=True, ground=True, servos={"all": 1000})
    by_map = restpose.load(bolt / "bolt.urdf", servo_reference=state, **common)
    by_srdf = restpose.load(bolt / "bolt.urdf", srdf=srdf, srdf_state="standing", **common)
    a, b = (m.solve(friction="stick", load_steps=1) for m in (by_map, by_srdf))
    assert a.converged and a.potential_energy == b.potential_energy
    with pytest.raises(ValueError, match="srdf and srdf_state"):
        restpose.load(bolt / "bolt.urdf", srdf=srdf)


def test_buried_bodies_name_bodies_resting_inside_a_ground():
    # The arm without collision geometry under a ground at z = 1: its point mass at
    # (cos θ, 0, −sin θ) rests 1 + sin θ inside it (docs/contact.md).
    shelf = ARM.replace("</robot>", '<mech:ground name="shelf" xyz="0 0 1"/></robot>')
    result = restpose.load_string(shelf).solve()
    assert result.converged
    theta = result.joint("j")[0]
    [b] = result.buried_bodies
    assert isinstance(b, restpose.BuriedBody)
    assert (b.body, b.ground) == ("arm", "shelf")
    assert b.depth == pytest.approx(1.0 + math.sin(theta), abs=1e-12)
    assert json.loads(result.to_json())["buried_bodies"] == [b.to_dict()]
    # none: an empty list here, the field absent from the JSON
    free = restpose.load_string(ARM).solve()
    assert free.buried_bodies == [] and "buried_bodies" not in json.loads(free.to_json())


def test_builder_pendulum_matches_the_closed_form():
    b = restpose.ModelBuilder("pendulum")
    b.add_rigid_body("arm", mass=1.0, com=(0.5, 0, 0), inertia=np.eye(3) * 1e-3)
    b.add_joint("hinge", "revolute", parent=None, child="arm", axis=(0, 1, 0))
    b.add_joint_spring("hinge", stiffness=10.0)
    model = b.build()
    r = model.solve()
    theta = r.joint("hinge")[0]
    # about y, gravity -z: k θ = m g L cos θ
    assert r.converged and 10.0 * theta == pytest.approx(9.81 * 0.5 * math.cos(theta), abs=1e-8)
    assert_rest_pose(model, r, stable=True)
    with pytest.raises(ValueError, match="built already"):
        b.build()


def test_builder_validates_like_the_importer():
    b = restpose.ModelBuilder("bad")
    b.add_rigid_body("arm", mass=-1.0)
    b.add_joint("hinge", "revolute", parent=None, child="arm")
    with pytest.raises(restpose.ModelError) as e:
        b.build()
    assert "arm" in str(e.value)
    b = restpose.ModelBuilder("x")
    b.add_rigid_body("arm", mass=1.0)
    with pytest.raises(restpose.UnknownJointError) as e:
        b.add_joint_spring("hnge", stiffness=1.0)
    with pytest.raises(ValueError, match="joint kind"):
        b.add_joint("j", "hinge", parent=None, child="arm")
    with pytest.raises(ValueError, match="no body named"):
        b.add_joint("j", "revolute", parent="base", child="arm")
    b.add_joint("hinge", "revolute", parent=None, child="arm", limits=(1.0, -1.0))
    with pytest.raises(restpose.ModelError):
        b.build()


def test_verify_and_assert_rest_pose(robots):
    model = restpose.load(robots / "pendulum.urdf")
    result = model.solve()
    v = model.verify(result)
    assert v.passed and bool(v)
    assert json.loads(v.to_json())["passed"] is True
    assert v.stability.verdict == "stable"
    # the same pose as joint values, and as a result of another model of the same file
    assert model.verify({"pivot": float(result.joint("pivot")[0])}).passed
    assert restpose.load(robots / "pendulum.urdf").verify(result).passed
    assert_rest_pose(model, result, stable=True)
    # a pose off the rest pose fails, with the joint named in the message
    with pytest.raises(AssertionError, match="pivot") as e:
        assert_rest_pose(model, {"pivot": 0.0})
    assert "needs effort" in str(e.value)
    bad = model.verify({"pivot": 0.0})
    assert not bad.passed and bad.max_imbalance.joint == "pivot"
    assert abs(bad.max_imbalance.effort) > 1.0
    # the band in which a stop or contact touches, as `restpose verify --gap-tolerance`
    assert model.verify(result, gap_tolerance=1e-6).passed
    with pytest.raises(ValueError, match="gap_tolerance"):
        model.verify(result, gap_tolerance=0.0)


def test_verify_a_pose_file_like_the_command_line(robots, tmp_path):
    path = robots / "pendulum.urdf"
    out = tmp_path / "r.json"
    subprocess.run(["restpose", "analyze", "-q", str(path), "--json", str(out)], check=True)
    model = restpose.load(path)
    v = model.verify(out)
    cli = subprocess.run(
        ["restpose", "verify", str(path), "--pose", str(out), "--json", "-"],
        capture_output=True,
        text=True,
    )
    assert cli.returncode == 0
    assert json.loads(v.to_json()) == json.loads(cli.stdout)


def test_solves_release_the_gil():
    text = subprocess.run(
        ["restpose", "generate", "chain", "--size", "2000"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    model = restpose.load_string(text)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    time.sleep(0.01)
    before = len(ticks)
    started = time.perf_counter()
    result = model.solve()
    elapsed = time.perf_counter() - started
    during = len([x for x in ticks if started <= x <= started + elapsed])
    done.set()
    t.join()
    assert result.converged and before > 0
    # with the GIL held the counter could not tick at all during the solve
    assert elapsed > 0.02, "the solve is too short to tell"
    assert during >= 5


def test_models_are_independent_and_threads_can_share_them(robots):
    a = restpose.load(robots / "pendulum.urdf")
    b = restpose.load(robots / "pendulum.urdf", locks={"pivot": 0.2})
    ra, rb = a.solve(), b.solve()
    assert ra.joint("pivot")[0] != rb.joint("pivot")[0]
    results = [None] * 4

    def work(i):
        results[i] = a.solve().joint("pivot")[0]

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(r == ra.joint("pivot")[0] for r in results)


def test_docstrings_and_stubs():
    assert "rest pose" in restpose.Model.solve.__doc__
    assert "URDF" in restpose.load.__doc__
    import pathlib

    pkg = pathlib.Path(restpose.__file__).parent
    assert (pkg / "py.typed").exists()
    assert (pkg / "_native.pyi").exists()
    assert restpose.__version__
