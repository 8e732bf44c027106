"""restpose's rest poses on pybullet_data (the data of the PyPI wheel pybullet 3.2.7), checked by
Pinocchio: the sibling of scripts/pinocchio_corpus.py (whose `check` it uses), run by
scripts/pybullet_corpus.sh.

Three kinds of solve, all by the direct solve (`--load-steps 1`):

  hanging   every URDF of pybullet_data outside `random_urdfs/` (95), and every 10th of the
            1,000 single objects of `random_urdfs/` (CORPUS_RANDOM=all: all of them), fixed
            base, limits enforced, no springs (`analyze -q FILE --load-steps 1 --json`);
  standing  the legged robots on the ground held by servos about a reference pose
            (`--floating-base --ground --friction stick --servo all=K`, K = CORPUS_SERVO);
            pybullet robots have no SRDF: the reference is the URDF's zero pose, or a crouch
            where pybullet's own examples give one (A1) or the zero pose does not stand
            (STANDING below says which and why);
  loops     minitaur with its knee loops closed as pybullet's own minitaur environment closes
            them (`createConstraint(JOINT_POINT2POINT)` between the two lower legs of each leg,
            pivots (0, 0.005, 0.2) and (0, 0.01, 0.2) in their links), written as
            `mech:loop_joint type="point_on_line"` along the knee axis: the two in-plane rows of
            the point-to-point constraint (the out-of-plane row is redundant in a planar
            five-bar, and the file's 1.57075 rad rotations leave it inconsistent by 1e-5 m);
            `--limits ignore` because Bullet reads the knees' `<limit>` without bounds as
            unlimited (urdfdom, and so restpose, reads [0, 0]).

Every converged pose is checked with Pinocchio as pinocchio_corpus.py does (forward kinematics,
gravity energy, g(q) = τ_stops + τ_servos + Σ J_cᵀ f), the loops with their reactions found
independently: Pinocchio's loop Jacobians (the child's pivot relative to the parent's, across
the line) and a least-squares λ must balance g(q) − τ_stops − τ_servos − Σ J_cᵀ f, the pivots
must lie on their lines in Pinocchio's kinematics, and restpose's reported reaction forces must
equal λ. Files that restpose or Pinocchio refuse are listed in REFUSED and PINOCCHIO_REFUSES
with the reason: a refusal that differs from the lists (another message, a file that now loads
or now fails in Pinocchio) and a crash (a panic, a signal, a timeout) fail; a located error or a
solve that does not converge on a standing or loop case is counted and listed.

Environment: RESTPOSE, ERD_ROBOTS (for pinocchio_corpus), PYBULLET_DATA (pybullet_data's
folder), CORPUS_SERVO (default 1000 N m/rad), CORPUS_TIMEOUT (s, default 120), CORPUS_RANDOM
(`all`, or N: every Nth of random_urdfs, default 10), CORPUS_JSON (write every row there).
Exits 1 on any disagreement.
"""

import glob
import json
import math
import os
import re
import sys
import tempfile

import numpy as np
import pinocchio as pin

import pinocchio_corpus as pc

PYB = os.environ["PYBULLET_DATA"]
SERVO = os.environ.get("CORPUS_SERVO", "1000")
RANDOM = os.environ.get("CORPUS_RANDOM", "10")

# Files that do not load, with the reason. (restpose's message, Pinocchio's verdict):
# restpose's located error must contain the text; Pinocchio (urdfdom) must refuse the file too
# unless "loads" is given, which would mark a file restpose refuses and Pinocchio reads (none
# since `differential/diff_ring.urdf`, a URDF with a blank line before `<?xml` that declares the
# xacro namespace without using it, is read as URDF).
REFUSED = {
    "bicycle/bike.urdf": ('attribute `xyz` = "0.07, 0, -0.69" must be 3 finite numbers',
                          "refuses"),
    "biped/biped2d_pybullet.urdf": ('attribute `lower` = "-1.57." is not a finite number',
                                    "refuses"),
    "humanoid/humanoid.urdf": ("not well-formed XML", "refuses"),
    "quadruped/microtaur/microtaur.urdf": ('`rpy` = "-3.14159 1.57079 0 0" must be 3 finite',
                                           "refuses"),
    "torus_deform.urdf": ("the robot has no <link>", "refuses"),
}

# Files that restpose loads and Pinocchio (urdfdom) refuses: restpose's answer is not checked.
PINOCCHIO_REFUSES = {
    # <joint type="spherical">: a restpose extension (docs/urdf-extensions.md), unknown to urdfdom
    "spherical_joint_limit.urdf",
}

# Legged robots standing on the ground: (file, extra options, what the reference pose is).
A1_CROUCH = ("pybullet's A1 examples (motion_imitation `INIT_MOTOR_ANGLES`): hip 0, "
             "thigh 0.9, calf −1.8 rad")
# pybullet's laikago examples load the y-up files with the orientation (x y z w) (0, ½, ½, 0)
# normalized, 0.5 m up: rpy (π/2, 0, π).
LAIKAGO_UP = ["--base-rpy", "1.5707963267948966", "0", "3.141592653589793",
              "--base-xyz", "0", "0", "0.5"]
# Ghost Robotics' Spirit and Vision 60: the zero pose has the legs straight back, flat; no
# pybullet example stands them. A crouch computed from the URDF: hip π/4, knee π/2 (upper leg
# 45° down-back, lower leg 45° down-forward, toe under the hip); joints "0".."7" are hip, knee
# of each leg in turn.
GHOST_CROUCH = [f"--servo={2 * i + k}={SERVO}@{v}" for i in range(4)
                for k, v in ((0, math.pi / 4), (1, math.pi / 2))]
GHOST_WHY = "crouch computed from the URDF: hip π/4, knee π/2 (toes under the hips)"
STANDING = [
    ("a1/a1.urdf", [f"--servo={j}_{k}_joint={SERVO}@{v}" for j in ("FR", "FL", "RR", "RL")
                    for k, v in (("hip", 0.0), ("upper", 0.9), ("lower", -1.8))], A1_CROUCH),
    ("aliengo/aliengo.urdf", [f"--servo={j}_{k}_joint={SERVO}@{v}"
                              for j in ("FR", "FL", "RR", "RL")
                              for k, v in (("hip", 0.0), ("upper", 0.9), ("lower", -1.8))],
     "the A1's crouch (hip 0, thigh 0.9, calf −1.8 rad): the zero pose is outside the calf limits"),
    ("laikago/laikago.urdf", LAIKAGO_UP, "zero pose, upright (the file is y-up: base rpy π/2 0 π)"),
    ("laikago/laikago_toes.urdf", LAIKAGO_UP, "zero pose, upright (y-up file)"),
    ("laikago/laikago_toes_limits.urdf", LAIKAGO_UP, "zero pose, upright (y-up file)"),
    ("laikago/laikago_toes_zup.urdf", [], "zero pose"),
    ("laikago/laikago_toes_zup_lores.urdf", [], "zero pose"),
    ("mini_cheetah/mini_cheetah.urdf", [], "zero pose"),
    ("quadruped/spirit40.urdf", GHOST_CROUCH, GHOST_WHY),
    ("quadruped/spirit40newer.urdf",
     [f"--servo={leg}_{k}_joint={SERVO}@{v}" for leg in ("FR", "FL", "RR", "RL")
      for k, v in (("upper", math.pi / 4), ("lower", math.pi / 2))], GHOST_WHY),
    ("quadruped/vision60.urdf", GHOST_CROUCH, GHOST_WHY),
    # Open legs with rigid knees (held at 0 by their [0, 0] limits) cannot stand: at pybullet's
    # motor angles (±π/2) the straight legs are horizontal. The zero pose: it lies on its motors.
    ("quadruped/quadruped.urdf", [], "zero pose (open legs; lies on its motors)"),
    ("quadruped/minitaur.urdf", [], "zero pose (open legs; lies on its motors)"),
]

# minitaur's knee loops: the legs, and pybullet's reset pose (minitaur.py: motor angle
# ±π/2, knee ∓2.1834 rad; the left legs' motors turn the other way), the start and the servos'
# reference.
MINITAUR_LEGS = ("front_right", "back_right", "front_left", "back_left")
PIVOT_R, PIVOT_L = (0.0, 0.005, 0.2), (0.0, 0.01, 0.2)


def analyze(urdf, extra):
    """pinocchio_corpus.analyze, and whether restpose crashed (a panic, a signal: not an
    honest refusal)."""
    return pc.analyze_checked(urdf, extra)


def minitaur_loops(src, out):
    """Writes `src` (a minitaur URDF) with the knee loops closed; returns the loops as
    (name, parent link, parent point, child link, child point, axis in the parent)."""
    text = open(src).read()
    loops, extra = [], []
    for leg in MINITAUR_LEGS:
        side = 1.0 if "right" in leg else -1.0
        name = f"toe_{leg}"
        parent, child = f"lower_leg_{leg}R_link", f"lower_leg_{leg}L_link"
        loops.append((name, parent, PIVOT_R, child, PIVOT_L, (0.0, 1.0, 0.0)))
        extra.append(
            f'  <mech:loop_joint name="{name}" type="point_on_line">\n'
            f'    <parent link="{parent}"/><origin xyz="{" ".join(map(str, PIVOT_R))}"/>\n'
            f'    <child link="{child}"/><child_origin xyz="{" ".join(map(str, PIVOT_L))}"/>\n'
            f'    <axis xyz="0 1 0"/>\n  </mech:loop_joint>')
        for s in "RL":
            extra.append(f'  <mech:initial joint="motor_{leg}{s}_joint" value="{side * math.pi / 2}"/>')
            extra.append(f'  <mech:initial joint="knee_{leg}{s}_link" value="{-side * 2.1834}"/>')
    text = re.sub(r"<robot\b", '<robot xmlns:mech="urn:urdf-mech:1"', text, count=1)
    # The meshes stay where they are: relative file names made absolute.
    folder = os.path.dirname(os.path.abspath(src))
    text = re.sub(r'filename="(?![/]|package:)([^"]+)"',
                  lambda m: f'filename="{os.path.join(folder, m.group(1))}"', text)
    text = text.replace("</robot>", "\n".join(extra) + "\n</robot>")
    with open(out, "w") as f:
        f.write(text)
    return loops


def motor_servos():
    return [f"--servo=motor_{leg}{s}_joint={SERVO}" for leg in MINITAUR_LEGS for s in "RL"]


def check_loops(urdf, floating, r, loops):
    """The loop check: (largest pivot-off-line distance [m], residual of g(q) balanced by the
    stops, servos, contacts and a least-squares λ across the lines, its scale, largest
    |λ − restpose's reaction|)."""
    model = (pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer()) if floating
             else pin.buildModelFromUrdf(urdf))
    data = model.createData()
    q = np.array(r["q_pinocchio"], dtype=float)
    pin.framesForwardKinematics(model, data, q)
    pin.computeJointJacobians(model, data, q)
    g = pin.computeGeneralizedGravity(model, data, q).copy()
    held = np.zeros(model.nv)
    terms = [abs(x) for x in g]
    for a in r.get("active_limits", []):
        held[model.joints[model.getJointId(a["joint"])].idx_v] += a["effort"]
        terms.append(abs(a["effort"]))
    for s in r.get("servos") or []:
        held[model.joints[model.getJointId(s["joint"])].idx_v] += s["torque"]
        terms.append(abs(s["torque"]))

    def point_jacobian(link, p_world):
        fid = model.getFrameId(link, pin.FrameType.BODY)
        J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        return J[:3] - pin.skew(p_world - data.oMf[fid].translation) @ J[3:]

    for c in r.get("contacts", []):
        f = np.array(c["normal_world"]) * c["normal_force"] + np.array(c["tangential_force"])
        held += point_jacobian(c["link"], np.array(c["point_world"])).T @ f
        terms.append(float(np.linalg.norm(f)))
    off_line, rows, dirs = 0.0, [], []
    for name, parent, pp, child, pcl, axis in loops:
        mp, mc = data.oMf[model.getFrameId(parent, pin.FrameType.BODY)], data.oMf[model.getFrameId(child, pin.FrameType.BODY)]
        xp, xc = mp.act(np.array(pp)), mc.act(np.array(pcl))
        a = mp.rotation @ np.array(axis)
        off_line = max(off_line, float(np.linalg.norm(np.cross(xc - xp, a))))
        # Two directions across the line: the reaction's directions.
        e1 = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(a, e1)
        Jrel = point_jacobian(child, xc) - point_jacobian(parent, xc)
        for e in (e1, e2):
            rows.append(e @ Jrel)
            dirs.append((name, e))
    A = np.array(rows).T  # nv × (2 per loop): generalized force of a unit reaction on the child
    lam, *_ = np.linalg.lstsq(A, g - held, rcond=None)
    residual = g - held - A @ lam
    terms += [abs(x) for x in lam]
    reported = {n: np.array(v["force_world"]) for n, v in r.get("reactions", {}).items()}
    dlam = max((abs(float(e @ reported[n]) - l) for (n, e), l in zip(dirs, lam)), default=0.0)
    return off_line, float(np.max(np.abs(residual))), max(terms + [1.0]), dlam


def for_pinocchio(urdf, tmp):
    """The file Pinocchio reads: `urdf`, or a copy without what restpose reads and urdfdom
    refuses: mesh `scale` with more than three numbers (restpose uses the first three,
    docs/urdf-extensions.md) and, in a file that declares the xacro namespace (which restpose
    expands as xacro), `$(optenv NAME DEFAULT)` (as xacro: NAME's value, else DEFAULT; husky's
    IMU frame)."""
    text = open(urdf).read()
    fixed = text
    if "xmlns:xacro=" in text:
        fixed = re.sub(r"\$\(optenv\s+(\S+)\s*([^)]*)\)",
                       lambda m: os.environ.get(m.group(1), m.group(2)), fixed)
    fixed = re.sub(r'scale="\s*([^"\s]+)\s+([^"\s]+)\s+([^"\s]+)(?:\s+[^"\s]+)+\s*"',
                   r'scale="\1 \2 \3"', fixed)
    if fixed == text:
        return urdf
    out = os.path.join(tmp, "pin_" + os.path.basename(urdf))
    with open(out, "w") as f:
        f.write(fixed)
    return out


def pinocchio_loads(urdf):
    try:
        pin.buildModelFromUrdf(urdf)
        return True, ""
    except Exception as e:  # urdfdom's refusal
        return False, str(e).strip().splitlines()[-1][:80]


def cases(tmp):
    """(group, name, urdf, floating, options, loops)."""
    files = sorted(glob.glob(f"{PYB}/**/*.urdf", recursive=True))
    plain = [f for f in files if "/random_urdfs/" not in f]
    rand = [f for f in files if "/random_urdfs/" in f]
    if RANDOM != "all":
        rand = rand[::int(RANDOM)]
    for f in plain + rand:
        yield "hanging", os.path.relpath(f, PYB), f, False, [], None
    for name, extra, _ in STANDING:
        yield ("standing", f"{name} standing", f"{PYB}/{name}", True,
               ["--floating-base", "--ground", "--friction", "stick", "--servo", f"all={SERVO}"]
               + extra, None)
    for src in ("minitaur.urdf", "minitaur_v1.urdf"):
        out = os.path.join(tmp, src.replace(".urdf", "_loops.urdf"))
        loops = minitaur_loops(f"{PYB}/quadruped/{src}", out)
        common = ["--limits", "ignore"]
        yield ("loops", f"{src} loops, hanging, motor servos", out, False,
               common + motor_servos(), loops)
        if src == "minitaur.urdf":
            # Free motors: each leg's five-bar hangs under its own weight, by both paths.
            for la in ("dense", "sparse"):
                yield ("loops", f"{src} loops, hanging free, {la}", out, False,
                       common + ["--linear-algebra", la], loops)
        yield ("loops", f"{src} loops, standing, motor servos", out, True,
               common + motor_servos() + ["--floating-base", "--ground", "--friction", "stick"],
               loops)


def main():
    rows, failures = [], []
    print(f"{'robot':58s} {'termination':18s} {'iter':>4s} {'rounds':>6s} {'corr.f':>6s} "
          f"{'FK [m]':>8s} {'dV [J]':>8s} {'τ resid.':>8s} {'time/s':>6s}")
    with tempfile.TemporaryDirectory() as tmp:
        for group, name, urdf, floating, extra, loops in cases(tmp):
            row = {"group": group, "robot": name}
            rows.append(row)
            r, err, dt, crashed = analyze(urdf, extra)
            row["time"] = dt
            rel = name if group == "hanging" else None
            if crashed:
                failures.append(f"{name}: restpose crashed: {err}")
            if r is None:
                row.update(termination="error", error=err)
                loads, why = pinocchio_loads(urdf)
                row["pinocchio"] = "loads" if loads else why
                if group != "hanging":  # an honest refusal: counted, listed
                    print(f"{name:58s} {err.replace(PYB + '/', '')[:150]}")
                    continue
                want = REFUSED.get(rel)
                if want is None or want[0] not in err or (want[1] == "loads") != loads:
                    failures.append(f"{name}: restpose: {err}; Pinocchio: {row['pinocchio']}"
                                    + ("" if want is None else f" (expected: {want})"))
                    print(f"{name:58s} error: {err[-100:]}  FAIL")
                else:
                    print(f"{name:58s} refused: {err[-80:]} (Pinocchio: {row['pinocchio']})")
                continue
            if rel in REFUSED:
                failures.append(f"{name}: loads now; REFUSED lists it ({REFUSED[rel][0]})")
            d = r["diagnostics"]
            row.update(termination=r["termination"], iterations=r["iterations"],
                       rounds=max([h.get("round", 1) for h in r["history"]] or [1]),
                       corrector_failures=d["corrector_failures"],
                       energy_total=r["energy"]["total"], dof=len(r.get("q_pinocchio", [])))
            converged = r["termination"] == "converged"
            if pc.unstable_rest(r):
                failures.append(f"{name}: {pc.unstable_rest(r)}")
            head = (f"{name:58s} {r['termination']:18s} {r['iterations']:4d} {row['rounds']:6d} "
                    f"{d['corrector_failures']:6d}")
            if rel in PINOCCHIO_REFUSES:
                loads, why = pinocchio_loads(urdf)
                row["pinocchio"] = "loads" if loads else why
                if loads:
                    failures.append(f"{name}: Pinocchio loads it now; PINOCCHIO_REFUSES lists it")
                print(f"{head} {'':8s} {'':8s} {'':8s} {dt:6.2f}  not checked: Pinocchio: {why}")
                continue
            bad = []
            try:
                urdf = for_pinocchio(urdf, tmp)
                fk, de, res, scale = pc.check(urdf, floating, r)
                if loops:
                    off, res, scale, dlam = check_loops(urdf, floating, r, loops)
                    row.update(off_line=off, reaction_error=dlam)
                    if off > 1e-9:
                        bad.append(f"loop pivots {off:.1e} m off their lines")
                    if converged and dlam > 1e-6 * scale:
                        bad.append(f"loop reactions differ from Pinocchio's λ by {dlam:.1e} N")
            except Exception as e:  # a model Pinocchio cannot build the same way is a failure
                failures.append(f"{name}: {e}")
                print(f"{head} Pinocchio: {e}  FAIL")
                continue
            row.update(fk=fk, energy=de, residual=res, scale=scale)
            bad += pc.disagreements(fk, de, res, scale, converged)
            if bad:
                failures.append(f"{name}: " + "; ".join(bad))
            row["agree"] = not bad
            # On the ground: what carries the robot (the links in contact, the base height).
            support = ""
            if floating:
                links = sorted({c["link"] for c in r.get("contacts", [])})
                support = (f"  base z {r['q_pinocchio'][2]:.3f} m, {len(links)} links in contact"
                           f" ({', '.join(links[:4])}{', …' if len(links) > 4 else ''})")
                row["support"] = links
            print(f"{head} {fk:8.1e} {de:8.1e} {res if converged else float('nan'):8.1e} "
                  f"{dt:6.2f}" + ("  FAIL" if bad else "") + support)
    print("\nstanding reference poses:")
    for name, _, why in STANDING:
        print(f"  {name}: {why}")
    for group in ("hanging", "standing", "loops"):
        summary(group, [x for x in rows if x["group"] == group])
    if os.environ.get("CORPUS_JSON"):
        json.dump(rows, open(os.environ["CORPUS_JSON"], "w"), indent=1)
    for f in failures:
        print("  FAILED " + f)
    checked = sum(1 for x in rows if "fk" in x)
    agree = sum(1 for x in rows if x.get("agree"))
    print(f"pybullet corpus: {len(rows)} solves, {checked} checked by Pinocchio: {agree} agree, "
          f"{checked - agree} disagree; {len(failures)} failures")
    sys.exit(1 if failures else 0)


def summary(group, rows):
    """The termination counts and the iteration-count distribution of the converged."""
    if not rows:
        return
    done = [x for x in rows if x.get("termination") == "converged"]
    moving = [x for x in done if x.get("dof", 1) > 0 or x["iterations"] > 0]
    its = sorted(x["iterations"] for x in moving)
    print(f"\n{group}: {len(rows)} solves: {len(done)} converged, "
          + ", ".join(f"{sum(1 for x in rows if x.get('termination') == t)} {t}"
                      for t in sorted({x.get('termination') for x in rows} - {'converged'})))
    if its:
        bins = [(0, 10), (11, 20), (21, 30), (31, 50), (51, 100), (101, 200)]
        print(f"  iterations of the {len(its)} converged with a moving joint: "
              + ", ".join(f"{lo}–{hi}: {sum(1 for i in its if lo <= i <= hi)}" for lo, hi in bins)
              + f"; median {its[len(its) // 2]}, largest {its[-1]}, "
              f"≤ 30: {sum(1 for i in its if i <= 30)}")
        print(f"  corrector failures (converged solves): "
              f"{sum(x['corrector_failures'] for x in done)}")


if __name__ == "__main__":
    main()
