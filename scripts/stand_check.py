"""Will it stand? Published legged robots on a floor and on slopes (run by stand_check.sh).

For each quadruped of example-robot-data (solo12, anymal b and c, hyq, go1, a1), standing in
its SRDF `standing` state, on a level floor and on slopes of 0.1, 0.2, 0.3 rad (gravity tilted
by alpha about y, ground z = 0), held by position servos about that state (`--servo all=K`) or
with every joint locked there (`--lock`), `restpose analyze --friction stick` reports
`friction.required_mu` and `balance.stability_margin`. Each is checked independently:

  1. Pinocchio builds the URDF with a free flyer, puts it at the JSON's `q_pinocchio`: its
     centre of mass must be restpose's `balance.centre_of_mass` (1e-9 m), and the reported
     contact forces with the weight (Pinocchio's mass) must balance the whole mechanism:
     force and moment about the centre of mass (1e-9 of m g and m g L);
  2. the support polygon is recomputed here: convex hull (monotone chain) of the loaded
     contact points projected along gravity, signed distance of the centre of mass's
     projection to its edges: must equal `stability_margin` (1e-9 m);
  3. `required_mu >= tan(alpha)` (1e-9): the forces sum to -m g, so
     max_i |t_i| / n_i >= sum |t_i| / sum n_i >= |sum t_i| / sum n_i = tan(alpha);
     with every joint locked the robot is one rigid body, and when the centre of mass
     projects inside the support polygon (margin > 0, computed in 2) forces parallel to
     gravity at the feet balance it (the projection is a convex combination of the feet's),
     each needing exactly tan(alpha): then `required_mu = tan(alpha)` (1e-9);
     with servos, `required_mu` is the largest need of the distribution reported (the legs'
     compliance makes it determinate): max_i |t_i| / n_i (1e-6, the least-norm choice's slack);
  4. `restpose verify` accepts the pose at mu = required_mu and refuses it at 0.99 of it.

Prints one line per robot and slope (the table of docs/friction.md); exits 1 on any failure.
"""

import json
import math
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

RESTPOSE = os.environ["RESTPOSE"]
ERD = os.environ["ERD_ROBOTS"]
SLOPES = (0.0, 0.1, 0.2, 0.3)
STIFFNESS = 200.0

# name, URDF, SRDF (below ERD), how the joints are held.
ROBOTS = [
    ("solo12", "solo_description/robots/solo12.urdf", "solo_description/srdf/solo.srdf", "servo"),
    ("anymal_b", "anymal_b_simple_description/robots/anymal.urdf",
     "anymal_b_simple_description/srdf/anymal.srdf", "servo"),
    ("anymal_c", "anymal_c_simple_description/urdf/anymal.urdf",
     "anymal_c_simple_description/srdf/anymal.srdf", "servo"),
    ("hyq", "hyq_description/robots/hyq_no_sensors.urdf", "hyq_description/srdf/hyq.srdf",
     "servo"),
    ("go1", "go1_description/urdf/go1.urdf", "go1_description/srdf/go1.srdf", "servo"),
    ("a1", "a1_description/urdf/a1.urdf", "a1_description/srdf/a1.srdf", "servo"),
]
ROBOTS += [(n + "_locked", u, s, "lock") for n, u, s, h in ROBOTS if h == "servo"]


def standing(srdf):
    """The joint values of the SRDF's `standing` group_state (the root joint left out)."""
    root = ET.parse(srdf).getroot()
    for gs in root.iter("group_state"):
        if gs.get("name") == "standing":
            return {j.get("name"): float(j.get("value")) for j in gs.iter("joint")
                    if len(j.get("value").split()) == 1}
    raise SystemExit(f"{srdf}: no group_state `standing`")


def stripped(src, dst):
    """A copy of src without visuals and mesh collisions (Pinocchio needs no meshes)."""
    text = open(src, encoding="utf-8").read()
    text = re.sub(r"<visual\b.*?</visual>", "", text, flags=re.S)
    text = re.sub(r"<collision\b.*?</collision>", "", text, flags=re.S)
    open(dst, "w", encoding="utf-8").write(text)


def hull(points):
    """Counter-clockwise convex hull of 2-D points (Andrew's monotone chain)."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


def segment_distance(p, a, b):
    ab = np.subtract(b, a)
    t = np.clip(np.dot(np.subtract(p, a), ab) / np.dot(ab, ab), 0.0, 1.0)
    return float(np.linalg.norm(np.subtract(p, np.add(a, t * ab))))


def margin(poly, p):
    """Signed distance of p to the polygon's edges, positive inside."""
    if len(poly) == 1:
        return -float(np.linalg.norm(np.subtract(p, poly[0])))
    if len(poly) == 2:
        return -segment_distance(p, poly[0], poly[1])
    d = min(segment_distance(p, poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly)))
    inside = all(
        (poly[(i + 1) % len(poly)][0] - poly[i][0]) * (p[1] - poly[i][1])
        - (poly[(i + 1) % len(poly)][1] - poly[i][1]) * (p[0] - poly[i][0]) >= 0
        for i in range(len(poly)))
    return d if inside else -d


def run(args):
    return subprocess.run([RESTPOSE] + args, capture_output=True, text=True, cwd=ERD)


def check(name, urdf, srdf, how, alpha, tmp, failures):
    g = np.array([-9.81 * math.sin(alpha), 0.0, -9.81 * math.cos(alpha)])
    state = standing(os.path.join(ERD, srdf))
    common = [urdf, "--package", "example-robot-data=..", "--floating-base", "--ground",
              "--gravity", *(repr(float(x) + 0.0) for x in g), "--friction", "stick"]
    if how == "servo":
        hold = ["--servo", f"all={STIFFNESS:g}", "--srdf", srdf, "--srdf-state", "standing"]
        vhold = hold
    else:
        hold = [a for j, v in state.items() for a in ("--lock", f"{j}={v!r}")]
        vhold = [a for j in state for a in ("--lock", j)]
    out = os.path.join(tmp, f"{name}_{alpha}.json")
    r = run(["analyze", *common, *hold, "--json", out, "-q"])
    if r.returncode != 0:
        failures.append(f"{name} {alpha}: analyze exit {r.returncode}: {r.stderr.strip()[:300]}")
        print(f"{name:16s} {alpha:4.1f}  analyze failed (exit {r.returncode})")
        return
    d = json.load(open(out))
    fr, bal = d.get("friction"), d.get("balance")
    if not d["converged"] or fr is None or bal is None:
        failures.append(f"{name} {alpha}: converged {d['converged']}, friction {fr}, balance {bal}")
        return
    errs = []

    # 1. Pinocchio's centre of mass and mass; the balance of the whole mechanism.
    plain = os.path.join(tmp, os.path.basename(urdf))
    stripped(os.path.join(ERD, urdf), plain)
    model = pin.buildModelFromUrdf(plain, pin.JointModelFreeFlyer())
    data = model.createData()
    q = np.array(d["q_pinocchio"])
    com = pin.centerOfMass(model, data, q)
    mass = pin.computeTotalMass(model)
    err_com = float(np.max(np.abs(com - np.array(bal["centre_of_mass"]))))
    if err_com > 1e-9:
        errs.append(f"centre of mass off by {err_com:.2e} m")
    force = mass * g
    moment = np.zeros(3)
    length = 0.0
    for c in d["contacts"]:
        f = c["normal_force"] * np.array(c["normal_world"]) + np.array(c["tangential_force"])
        arm = np.array(c["point_world"]) - com
        force = force + f
        moment = moment + np.cross(arm, f)
        length = max(length, float(np.linalg.norm(arm)))
    weight = mass * 9.81
    if np.max(np.abs(force)) > 1e-9 * weight or np.max(np.abs(moment)) > 1e-9 * weight * length:
        errs.append(f"contact forces do not balance the weight: force {np.max(np.abs(force)):.2e} N,"
                    f" moment {np.max(np.abs(moment)):.2e} N m")

    # 2. The support polygon and the stability margin.
    down = g / np.linalg.norm(g)
    e1 = np.cross([0.0, 1.0, 0.0], down)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(down, e1)

    def flat(p):
        return (float(np.dot(p, e1)), float(np.dot(p, e2)))

    loaded = [flat(c["point_world"]) for c in d["contacts"] if c["normal_force"] > 1e-9 * weight]
    poly = hull(loaded)
    # Hull vertices closer than 1e-12 m apart are one point (rounding).
    mine = margin(poly, flat(com))
    if abs(mine - bal["stability_margin"]) > 1e-9:
        errs.append(f"stability margin {bal['stability_margin']:.12f} vs {mine:.12f} here")

    # 3. required_mu.
    need = fr["required_mu"]
    tan = math.tan(alpha)
    if need < tan - 1e-9:
        errs.append(f"required_mu {need} below tan(alpha) {tan}")
    if how == "lock" and mine > 0 and abs(need - tan) > 1e-9:
        errs.append(f"required_mu {need} vs tan(alpha) {tan} (rigid, margin {mine:.3g} > 0)")
    largest = max((math.hypot(*c["tangential_force"][:3]) / c["normal_force"]
                   for c in d["contacts"] if c["normal_force"] > 0), default=0.0)
    if how == "servo" and abs(largest - need) > 1e-6 * max(need, 1.0):
        errs.append(f"required_mu {need} vs largest need of the forces {largest}")

    # 4. verify at required_mu and below.
    if need > 0:
        for mu, ok in ((need * (1 + 1e-12), True), (0.99 * need, False)):
            v = run(["verify", *common, *vhold, "--pose", out, "--mu", repr(mu), "-q"])
            if (v.returncode == 0) != ok:
                errs.append(f"verify at mu {mu:.6g}: exit {v.returncode} {v.stdout.strip()[:200]}")
    print(f"{name:16s} {alpha:4.1f}  required_mu {need:.6f}  tan {tan:.6f}  margin {bal['stability_margin']:.6f} m"
          f"  ({len(poly)} corners)  {'ok' if not errs else 'FAIL: ' + '; '.join(errs)}")
    failures.extend(f"{name} {alpha}: {e}" for e in errs)


def main():
    only = sys.argv[1:]
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, urdf, srdf, how in ROBOTS:
            if only and name not in only:
                continue
            for alpha in SLOPES:
                check(name, urdf, srdf, how, alpha, tmp, failures)
    print(f"{len(failures)} failures")
    for f in failures:
        print("  " + f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
