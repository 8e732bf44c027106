"""restpose's pose files against the real tools: MuJoCo and Pinocchio (run by peers_check.sh).

For each published robot (example-robot-data: fixed base, floating base, mimic joints, and a
xacro file vendored in robots/xacro):
  1. `restpose analyze` writes the result JSON (with `q_mujoco`, `q_pinocchio`), a MuJoCo
     keyframe (--write-mujoco-key) and an SRDF named state (--write-srdf);
  2. MuJoCo opens the keyframe file (which loads the URDF), resets to key `rest`, runs
     `mj_forward`: every MuJoCo body named as a URDF link must be where restpose put the link;
  3. Pinocchio builds the model from the same URDF (free flyer when the base floats), runs the
     forward kinematics at `q_pinocchio`: every body frame must be where restpose put its link;
  4. `pin.loadReferenceConfigurations` reads the SRDF: the named state must equal
     `q_pinocchio`;
  5. restpose's own round trip: `verify --pose` passes the result JSON and the joint-states
     YAML, and `analyze` of the written URDF takes 0 iterations.
Poses are compared as the largest of the position error [m] and the rotation-matrix error
(max entry); the tolerance is 1e-9. Prints one line per robot and tool with the largest
error; exits 1 on any failure.

The URDF given to the tools is a copy without <visual> and without mesh <collision> elements
(MuJoCo cannot resolve `package://` meshes; kinematics and inertia do not depend on them).
"""

import json
import os
import re
import subprocess
import sys
import tempfile

import numpy as np
import mujoco
import pinocchio as pin

TOL = 1e-9
RESTPOSE = os.environ["RESTPOSE"]
ERD = os.environ["ERD_ROBOTS"]
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def stripped(src, dst, springs=None):
    """A copy of src without visuals and mesh collisions, optionally with joint springs."""
    text = open(src, encoding="utf-8").read()
    text = re.sub(r"<visual\b.*?</visual>", "", text, flags=re.S)
    text = re.sub(r"<collision\b(?:(?!</collision>).)*?<mesh\b.*?</collision>", "", text, flags=re.S)
    if springs is not None:
        import xml.etree.ElementTree as ET
        names = [j.get("name") for j in ET.fromstring(text.encode()).findall("joint")
                 if j.get("type") in ("revolute", "continuous", "prismatic")]
        extra = "".join(
            f'\n  <mech:joint_spring joint="{n}" stiffness="{springs[0]}" reference="{springs[1].get(n, 0.0)}"/>'
            for n in names
        )
        if "urn:urdf-mech:1" not in text:
            text = re.sub(r"<robot\b", '<robot xmlns:mech="urn:urdf-mech:1"', text, count=1)
        at = text.rfind("</robot>")
        text = text[:at] + extra + "\n" + text[at:]
    open(dst, "w", encoding="utf-8").write(text)


def rot_wxyz(q):
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, np.asarray(q, dtype=float))
    return m.reshape(3, 3)


def pose_error(p, R, link):
    dp = np.max(np.abs(np.asarray(p) - np.asarray(link["position"])))
    dR = np.max(np.abs(R - rot_wxyz(link["orientation_wxyz"])))
    return max(dp, dR)


def quietly(load, *args):
    """load(*args) with the C library's stdout and stderr closed: MuJoCo warns on every
    load that an attached model with an empty prefix (the URDF's own names) cannot be saved."""
    sys.stdout.flush()
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        return load(*args)
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved + [null]:
            os.close(fd)


def check_mujoco(key_file, links):
    model = quietly(mujoco.MjModel.from_xml_path, key_file)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    worst, n = 0.0, 0
    for b in range(model.nbody):
        name = model.body(b).name
        if name in links:
            err = pose_error(data.xpos[b], data.xmat[b].reshape(3, 3), links[name])
            worst, n = max(worst, err), n + 1
    return worst, n, model.nq


def check_pinocchio(urdf, floating, result, srdf, state):
    if floating:
        model = pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())
    else:
        model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    q = np.array(result["q_pinocchio"])
    if q.size != model.nq:
        raise AssertionError(f"q_pinocchio has {q.size} entries, Pinocchio's model nq = {model.nq}")
    pin.framesForwardKinematics(model, data, q)
    links = result["links"]
    worst, n = 0.0, 0
    for f, frame in enumerate(model.frames):
        if frame.type == pin.FrameType.BODY and frame.name in links:
            M = data.oMf[f]
            err = pose_error(M.translation, M.rotation, links[frame.name])
            worst, n = max(worst, err), n + 1
    pin.loadReferenceConfigurations(model, srdf, False)
    ref = model.referenceConfigurations[state]
    srdf_err = float(np.max(np.abs(ref - q))) if q.size else 0.0
    return worst, n, srdf_err


CASES = [
    # name, URDF, restpose arguments, springs (stiffness, references) or None
    ("ur5 (fixed base)", f"{ERD}/ur_description/urdf/ur5_robot.urdf", [], None),
    ("panda (fixed base, mimic fingers)", f"{ERD}/panda_description/urdf/panda.urdf", [], None),
    ("baxter (fixed base, children order)", f"{ERD}/baxter_description/urdf/baxter.urdf", [], (50.0, {})),
    (
        "a1 (floating base on the ground)",
        f"{ERD}/a1_description/urdf/a1.urdf",
        ["--floating-base", "--ground", "--base-xyz", "0", "0", "0.45"],
        (200.0, {f"{l}_thigh_joint": 0.8 for l in ("FL", "FR", "RL", "RR")}
         | {f"{l}_calf_joint": -1.5 for l in ("FL", "FR", "RL", "RR")}),
    ),
    (
        "ur5e from xacro (fixed base)",
        f"{REPO}/robots/xacro/ur_description/urdf/ur.urdf.xacro",
        ["--xacro-arg", "ur_type:=ur5e", "--package", f"ur_description={REPO}/robots/xacro/ur_description"],
        None,
    ),
]


def main():
    failed = 0
    work = tempfile.mkdtemp(prefix="restpose-peers-")
    for name, src, args, springs in CASES:
        tag = re.sub(r"\W+", "_", name.split(" ")[0])
        urdf = os.path.join(work, tag + ".urdf")
        key = os.path.join(work, tag + "_key.xml")
        srdf = os.path.join(work, tag + ".srdf")
        res = os.path.join(work, tag + ".json")
        written = os.path.join(work, tag + "_rest.urdf")
        if src.endswith(".xacro"):
            # The expanded URDF (restpose's own expansion, written back), then stripped.
            expanded = os.path.join(work, tag + "_expanded.urdf")
            out = subprocess.run([RESTPOSE, "analyze", src, *args, "--write-urdf", expanded, "-q"],
                                 capture_output=True, text=True)
            if out.returncode != 0:
                print(f"FAIL {name}: restpose analyze (xacro) exited {out.returncode}: {out.stderr.strip()}")
                failed += 1
                continue
            stripped(expanded, urdf, springs)
            args = []
        else:
            stripped(src, urdf, springs)
        yaml = os.path.join(work, tag + ".yaml")
        cmd = [RESTPOSE, "analyze", urdf, *args, "--json", res, "--write-mujoco-key", key,
               "--write-srdf", srdf, "--write-urdf", written, "--write-joint-states", yaml, "-q"]
        out = subprocess.run(cmd, capture_output=True, text=True)
        if out.returncode != 0:
            print(f"FAIL {name}: restpose analyze exited {out.returncode}: {out.stderr.strip()}")
            failed += 1
            continue
        result = json.load(open(res))
        floating = "--floating-base" in args
        q_mj, q_pin = result["q_mujoco"], result["q_pinocchio"]
        start = 7 if floating else 0
        print(f"     {name}: largest joint value {max(abs(x) for x in q_mj[start:]):.3f}, "
              f"MuJoCo and Pinocchio orders {'differ' if q_mj != q_pin else 'agree'}")
        # restpose's own round trip: verify passes the JSON and the YAML, and analyze of the
        # written URDF starts at rest (the base pose included).
        flags = [a for a in args if a != "--base-xyz" and not re.fullmatch(r"-?[0-9.]+", a)]
        trips, trip_ok = [], True
        for pose in (res, yaml):
            v = subprocess.run([RESTPOSE, "verify", urdf, *flags, "--pose", pose, "-q"],
                               capture_output=True, text=True)
            trips.append(f"verify {os.path.splitext(pose)[1][1:]} exit {v.returncode}")
            trip_ok &= v.returncode == 0
        again = os.path.join(work, tag + "_again.json")
        a = subprocess.run([RESTPOSE, "analyze", written, *flags, "--json", again, "-q"],
                           capture_output=True, text=True)
        iterations = json.load(open(again))["iterations"] if a.returncode == 0 else None
        trips.append(f"analyze of the written URDF: {iterations} iterations")
        trip_ok &= iterations == 0
        failed += not trip_ok
        print(f"{'ok  ' if trip_ok else 'FAIL'} {name}: {', '.join(trips)}")
        try:
            m_err, m_n, nq = check_mujoco(key, result["links"])
            if len(result["q_mujoco"]) != nq:
                raise AssertionError(f"q_mujoco has {len(result['q_mujoco'])} entries, MuJoCo nq = {nq}")
            ok = m_err <= TOL and m_n > 0
            failed += not ok
            print(f"{'ok  ' if ok else 'FAIL'} {name}: MuJoCo {m_n} bodies, nq {nq}, max error {m_err:.1e}")
        except Exception as e:  # a tool's exception is a failure of this robot, not of the run
            failed += 1
            print(f"FAIL {name}: MuJoCo: {e}")
        try:
            p_err, p_n, s_err = check_pinocchio(urdf, floating, result, srdf, "rest")
            ok = p_err <= TOL and p_n > 0 and s_err <= 1e-12
            failed += not ok
            print(f"{'ok  ' if ok else 'FAIL'} {name}: Pinocchio {p_n} bodies, max error {p_err:.1e}; "
                  f"SRDF state vs q_pinocchio {s_err:.1e}")
        except Exception as e:
            failed += 1
            print(f"FAIL {name}: Pinocchio: {e}")
    print(f"{len(CASES)} robots, {failed} failures")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
