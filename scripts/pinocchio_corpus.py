"""restpose's rest poses on the example-robot-data corpus, checked by Pinocchio.

Run by scripts/pinocchio_corpus.sh (which provides the venv with `pin` and the corpus). For
every URDF of example-robot-data 6.0.0, hanging from its fixed base (`--load-steps 1`, the
direct solve), and for the legged robots with an SRDF standing state, standing on the ground
(`--floating-base --ground --friction stick --servo all=K --srdf FILE --srdf-state NAME`):

  1. `restpose analyze -q --json` gives the rest pose (`q_pinocchio`), the link frames, the
     energy, the stops' efforts, the servos' torques and the contact forces;
  2. Pinocchio builds the same URDF and, at `q_pinocchio`,
     - puts every link frame where restpose put it (forward kinematics, 1e-9);
     - computes the gravity energy (`computePotentialEnergy`), equal to restpose's (1e-9 J
       relative to the robot's m g ℓ);
     - computes the generalized gravity `g(q)`, which at a rest pose restpose reports must be
       held by the stops, servos and contacts: `g(q) = τ_stops + τ_servos + Σ J_cᵀ f_c`
       (a mimic joint's row folded into its master's with the multiplier), to 1e-6 of the
       largest term (the rest pose is converged to a reduced gradient of 1e-8 J).
Poses that restpose did not report converged are checked for kinematics and energy only, and
counted; a converged rest whose verdict is `unstable` fails (the minimizer leaves maxima and
saddles). Prints a table, the iteration-count distribution and corrector failures of the
converged solves, and exits 1 if any check fails.

Environment: RESTPOSE (the binary), ERD_ROBOTS (the corpus's robots folder), CORPUS_SERVO
(servo stiffness of the standing robots, default 1000 N m/rad), CORPUS_TIMEOUT (s, default 120),
CORPUS_JSON (write every row there).
"""

import glob
import json
import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

RESTPOSE = os.environ["RESTPOSE"]
ERD = os.environ["ERD_ROBOTS"]
SERVO = os.environ.get("CORPUS_SERVO", "1000")
TIMEOUT = float(os.environ.get("CORPUS_TIMEOUT", "120"))

# Legged robots standing on the ground, about an SRDF standing state.
STANDING = [
    ("a1_description/urdf/a1.urdf", "a1_description/srdf/a1.srdf", "standing"),
    ("anymal_b_simple_description/robots/anymal.urdf",
     "anymal_b_simple_description/srdf/anymal.srdf", "standing"),
    ("anymal_c_simple_description/urdf/anymal.urdf",
     "anymal_c_simple_description/srdf/anymal.srdf", "standing"),
    ("b1_description/urdf/b1.urdf", "b1_description/srdf/b1.srdf", "standing"),
    ("bolt_description/robots/bolt.urdf", "bolt_description/srdf/bolt.srdf", "standing"),
    ("go1_description/urdf/go1.urdf", "go1_description/srdf/go1.srdf", "standing"),
    ("go2_description/urdf/go2.urdf", "go2_description/srdf/go2.srdf", "standing"),
    ("hyq_description/robots/hyq_no_sensors.urdf", "hyq_description/srdf/hyq.srdf", "standing"),
    ("solo_description/robots/solo.urdf", "solo_description/srdf/solo.srdf", "standing"),
    ("solo_description/robots/solo12.urdf", "solo_description/srdf/solo.srdf", "standing"),
    ("icub_description/robots/icub.urdf", "icub_description/srdf/icub.srdf", "half_sitting"),
    ("romeo_description/urdf/romeo.urdf", "romeo_description/srdf/romeo.srdf", "half_sitting"),
    ("simple_humanoid_description/urdf/simple_humanoid.urdf",
     "simple_humanoid_description/srdf/simple_humanoid.srdf", "half_sitting"),
    ("talos_data/robots/talos_reduced.urdf", "talos_data/srdf/talos.srdf", "half_sitting"),
    ("talos_data/robots/talos_full_v2.urdf", "talos_data/srdf/talos.srdf", "half_sitting"),
]

# Files urdfdom itself rejects (see scripts/corpus.sh).
REJECTED = {"ur_description/urdf/ur3.urdf"}


def disagreements(fk, de, res, scale, converged):
    """What restpose and Pinocchio disagree on (empty: they agree): link frames to 1e-9 m, the
    gravity energy to 1e-9 of the force scale, and at a converged rest g(q) = τ held to 1e-6."""
    bad = []
    if fk > 1e-9:
        bad.append(f"forward kinematics differ by {fk:.1e} m")
    if de > 1e-9 * scale:
        bad.append(f"gravity energy differs by {de:.1e} J")
    if converged and res > 1e-6 * scale:
        bad.append(f"g(q) − τ held = {res:.1e} (scale {scale:.1e})")
    return bad


def unstable_rest(r):
    """Why a result is not a rest the solver may report as found: `converged` with the verdict
    `unstable` (without --allow-unstable the minimizer leaves maxima and saddles, those that
    only the critical cone shows included), or "" if it is not that."""
    verdict = (r.get("stability") or {}).get("verdict")
    if r["termination"] == "converged" and verdict == "unstable":
        return "converged, but the verdict says unstable"
    return ""


def analyze(urdf, extra):
    """`restpose analyze -q URDF --load-steps 1 --json`: (result or None, error, seconds)."""
    r, err, dt, _ = analyze_checked(urdf, extra)
    return r, err, dt


def analyze_checked(urdf, extra, line=-1):
    """`analyze`, and whether restpose crashed (a panic, a signal, a timeout: not an honest
    refusal); the error is stderr's last non-blank line (`line`: which one)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "r.json")
        cmd = [RESTPOSE, "analyze", "-q", urdf, "--load-steps", "1", "--json", out] + extra
        t0 = time.time()
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            return None, f"timeout after {TIMEOUT:.0f} s", time.time() - t0, True
        dt = time.time() - t0
        crashed = p.returncode not in (0, 1, 3) or "panicked" in p.stderr
        lines = [x for x in p.stderr.splitlines() if x.strip()]
        if not os.path.exists(out):
            return None, (lines[line] if lines else f"exit {p.returncode}"), dt, crashed
        return json.load(open(out)), "", dt, crashed


def mimics(urdf):
    """{mimic joint: (master, multiplier)} from the URDF."""
    out = {}
    # Leading blank lines before `<?xml` (urdfdom reads them; ElementTree does not).
    for j in ET.fromstring(open(urdf, "rb").read().lstrip()).iter("joint"):
        m = j.find("mimic")
        if m is not None:
            out[j.get("name")] = (m.get("joint"), float(m.get("multiplier", "1")))
    return out


def check(urdf, floating, r):
    """(FK error [m], energy error [J], torque residual, its scale, notes)."""
    model = (pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer()) if floating
             else pin.buildModelFromUrdf(urdf))
    data = model.createData()
    q = np.array(r["q_pinocchio"], dtype=float)
    if q.size != model.nq:
        raise AssertionError(f"q_pinocchio has {q.size} entries, Pinocchio's nq = {model.nq}")
    pin.framesForwardKinematics(model, data, q)
    pin.computeJointJacobians(model, data, q)
    links = r["links"]
    fk = 0.0
    for f, frame in enumerate(model.frames):
        if frame.type == pin.FrameType.BODY and frame.name in links:
            fk = max(fk, float(np.max(np.abs(data.oMf[f].translation
                                              - np.array(links[frame.name]["position"])))))
    energy = abs(pin.computePotentialEnergy(model, data, q) - r["energy"]["gravity"])
    g = pin.computeGeneralizedGravity(model, data, q).copy()
    # Generalized forces held by the stops, servos and contacts.
    held = np.zeros(model.nv)

    def index(joint):
        jid = model.getJointId(joint)
        if jid >= model.njoints or model.joints[jid].nv != 1:
            raise AssertionError(f"joint {joint} is not a 1-dof joint of Pinocchio's model")
        return model.joints[jid].idx_v

    terms = [abs(x) for x in g]
    for a in r.get("active_limits", []):
        held[index(a["joint"])] += a["effort"]
        terms.append(abs(a["effort"]))
    for s in r.get("servos") or []:
        held[index(s["joint"])] += s["torque"]
        terms.append(abs(s["torque"]))
    for c in r.get("contacts", []):
        fid = model.getFrameId(c["link"], pin.FrameType.BODY)
        J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        arm = np.array(c["point_world"]) - data.oMf[fid].translation
        Jp = J[:3] - pin.skew(arm) @ J[3:]
        f = np.array(c["normal_world"]) * c["normal_force"] + np.array(c["tangential_force"])
        held += Jp.T @ f
        terms.append(float(np.linalg.norm(f)))
    residual = g - held
    for joint, (master, k) in mimics(urdf).items():
        if model.existJointName(joint) and model.existJointName(master):
            i, m = index(joint), index(master)
            residual[m] += k * residual[i]
            residual[i] = 0.0
    return fk, energy, float(np.max(np.abs(residual))) if residual.size else 0.0, max(terms + [1.0])


def cases():
    files = sorted(f for f in glob.glob(f"{ERD}/**/*.urdf", recursive=True)
                   if "restpose-springs" not in f)
    for f in files:
        name = os.path.relpath(f, ERD)
        if name not in REJECTED:
            yield name, f, False, ["--package", f"example-robot-data={ERD}/.."]
    for urdf, srdf, state in STANDING:
        yield (f"{urdf} standing ({state})", f"{ERD}/{urdf}", True,
               ["--floating-base", "--ground", "--friction", "stick", "--servo", f"all={SERVO}",
                "--srdf", f"{ERD}/{srdf}", "--srdf-state", state,
                "--package", f"example-robot-data={ERD}/.."])


def main():
    rows, failures = [], []
    print(f"{'robot':66s} {'termination':18s} {'iter':>4s} {'rounds':>6s} {'corr.f':>6s} "
          f"{'FK [m]':>8s} {'dV [J]':>8s} {'τ resid.':>8s} {'time/s':>6s}")
    for name, urdf, floating, extra in cases():
        r, err, dt = analyze(urdf, extra)
        row = {"robot": name, "time": dt}
        if r is None:
            row["termination"] = "error"
            row["error"] = err
            print(f"{name:66s} error: {err[-90:]}")
            rows.append(row)
            continue
        d = r["diagnostics"]
        row.update(termination=r["termination"], iterations=r["iterations"],
                   rounds=max([h.get("round", 1) for h in r["history"]] or [1]),
                   corrector_failures=d["corrector_failures"], energy_total=r["energy"]["total"])
        try:
            fk, de, res, scale = check(urdf, floating, r)
        except Exception as e:  # a model Pinocchio cannot build the same way is a failure
            failures.append(f"{name}: {e}")
            print(f"{name:66s} Pinocchio: {e}")
            rows.append(row)
            continue
        row.update(fk=fk, energy=de, residual=res, scale=scale)
        converged = r["termination"] == "converged"
        bad = disagreements(fk, de, res, scale, converged)
        if bad:
            failures.append(f"{name}: " + "; ".join(bad))
        if unstable_rest(r):
            failures.append(f"{name}: {unstable_rest(r)}")
        print(f"{name:66s} {r['termination']:18s} {r['iterations']:4d} {row['rounds']:6d} "
              f"{d['corrector_failures']:6d} {fk:8.1e} {de:8.1e} "
              f"{res if converged else float('nan'):8.1e} {dt:6.2f}" + ("  FAIL" if bad else ""))
        rows.append(row)
    # The distribution of the converged solves.
    done = [x for x in rows if x.get("termination") == "converged"]
    its = sorted(x["iterations"] for x in done)
    print(f"\n{len(rows)} solves: {len(done)} converged, "
          + ", ".join(f"{sum(1 for x in rows if x.get('termination') == t)} {t}"
                      for t in sorted({x.get('termination') for x in rows} - {'converged'})))
    if its:
        bins = [(0, 10), (11, 20), (21, 30), (31, 50), (51, 100), (101, 200)]
        print("iterations of the converged: "
              + ", ".join(f"{lo}–{hi}: {sum(1 for i in its if lo <= i <= hi)}" for lo, hi in bins)
              + f"; median {its[len(its) // 2]}, ≤ 30: {sum(1 for i in its if i <= 30)}")
        print(f"corrector failures (converged solves): "
              f"{sum(x['corrector_failures'] for x in done)}")
    if os.environ.get("CORPUS_JSON"):
        json.dump(rows, open(os.environ["CORPUS_JSON"], "w"), indent=1)
    for f in failures:
        print("  FAILED " + f)
    print(f"pinocchio corpus: {len(rows) - len(failures)} agree with Pinocchio, "
          f"{len(failures)} disagree")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
