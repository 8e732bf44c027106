#!/usr/bin/env python3
"""Compare restpose with MuJoCo on the Solo-12 standing on the ground (issue 13 validation).

Runs ``restpose analyze URDF --floating-base --json -`` (frictionless, then with
``--friction stick``) and ``benches/peers/solo12_mujoco.py`` (damped settling and the rigid-contact
KKT reference), and prints one Markdown table per friction mode: joint angles, base height,
roll and pitch, foot normal forces (and, sticking, tangential forces and required friction),
with the differences and the bounds they must meet.

Compared quantities: a frictionless quadruped on flat ground has neutral directions (slide x,
y and yaw), so only what is unique is compared: the 12 joint angles, the base height above the
ground, base roll and pitch, and the foot forces. Sticking adds tangential forces.

Bounds (documented in docs/contact-validation.md); delta = MuJoCo's largest foot penetration:
* restpose vs rigid KKT (both exact statics):  1e-6 rad, 1e-6 m, 1e-3 N.
* restpose or rigid vs MuJoCo settling: base height 1.5 delta + 1e-7 m; angles
  delta / 0.16 m (the shank) + 1e-5 rad; forces 1e-4 N + |F| (1e-4 + 2 delta / 0.16 m).
* Sticking: restpose must match one of three rigid stick models exactly (the sphere's centre
  held where it touched; the sphere's material point that touched held; the sphere rolling
  without slip, which is what MuJoCo's condim-3 friction does), and MuJoCo must match the
  rolling one within the settling bounds. restpose vs MuJoCo gets the difference between the
  matched model and the rolling one added to its bound (0.46 mm of base height for the centre
  held, 3e-7 m for the material point).

Exit status: 0 all within bounds; 1 a difference beyond its bound; 2 restpose did not run or
gave no ``contacts`` (before ground contact is implemented); 3 MuJoCo reference failed.

Usage: python benches/peers/compare_solo12.py [--restpose PATH] [--mujoco-json FILE] [--urdf F]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_URDF = ROOT / "robots/solo12/solo12_ground.urdf"
SHANK = 0.16  # m, knee to foot centre: the lever that turns a foot's sink into a joint angle
EXACT = {"angle": 1e-6, "length": 1e-6, "force": 1e-3}


def settle_bound(kind: str, delta: float, value: float = 0.0) -> float:
    if kind == "length":
        return 1.5 * delta + 1e-7
    if kind == "angle":
        return delta / SHANK + 1e-5
    return 1e-4 + abs(value) * (1e-4 + 2 * delta / SHANK)


def find_restpose(arg: str | None) -> Path | None:
    cands = [arg, os.environ.get("RESTPOSE"), str(ROOT / "target/release/restpose")]
    if os.environ.get("CARGO_TARGET_DIR"):
        cands.append(str(Path(os.environ["CARGO_TARGET_DIR"]) / "release/restpose"))
    for c in cands:
        if c and Path(c).is_file():
            return Path(c)
    return None


def quat_roll_pitch(w, x, y, z):
    # ZYX roll and pitch from the last row of R (yaw-independent), as solo12_mujoco.py does.
    r20 = 2 * (x * z - w * y)
    r21 = 2 * (y * z + w * x)
    r22 = 1 - 2 * (x * x + y * y)
    return math.atan2(r21, r22), -math.asin(max(-1.0, min(1.0, r20)))


def run_restpose(exe: Path, urdf: Path, friction: str, repeats: int):
    cmd = [str(exe), "analyze", str(urdf), "--floating-base", "--json", "-"]
    if friction == "stick":
        cmd += ["--friction", "stick"]
    best, out = math.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True)
        dt = time.perf_counter() - t0
        best = min(best, dt)
        out = p
    if out.returncode != 0 or not out.stdout.strip():
        return None, f"`{' '.join(cmd)}` exited {out.returncode}: {out.stderr.strip()[:600]}", best
    try:
        return json.loads(out.stdout), None, best
    except json.JSONDecodeError as e:
        return None, f"restpose JSON unreadable: {e}", best


def restpose_summary(r: dict, ground_point, ground_normal, root: str) -> dict:
    base = r["links"][root]
    pos = base["position"]
    w, x, y, z = base["orientation_wxyz"]
    roll, pitch = quat_roll_pitch(w, x, y, z)
    height = sum(n * (p - g) for n, p, g in zip(ground_normal, pos, ground_point))
    feet = {}
    for c in r["contacts"]:
        ft = c.get("tangential_force", 0.0)
        ftn = math.sqrt(sum(v * v for v in ft)) if isinstance(ft, list) else float(ft or 0.0)
        f = feet.setdefault(c["link"], {"normal_force": 0.0, "tangential_force": 0.0,
                                        "required_friction": None, "states": []})
        f["normal_force"] += c["normal_force"]
        f["tangential_force"] += ftn  # one contact per foot sphere; summed if several
        f["required_friction"] = c.get("required_friction")
        f["states"].append(c.get("state"))
    joints = {n: j["position"][0] for n, j in r["joints"].items()
              if j.get("type") in ("revolute", "continuous", "prismatic") and j["position"]}
    return {"base": {"height": height, "roll": roll, "pitch": pitch}, "joints": joints, "feet": feet}


def ref_summary(x: dict) -> dict:
    return {"base": {k: x["base"][k] for k in ("height", "roll", "pitch")},
            "joints": x["joints"],
            "feet": {f["link"]: f for f in x["feet"]}}


def rows_of(s: dict, joints, feet, stick: bool):
    rows = [("base height [m]", "length", s["base"]["height"]),
            ("base roll [rad]", "angle", s["base"]["roll"]),
            ("base pitch [rad]", "angle", s["base"]["pitch"])]
    rows += [(f"{j} [rad]", "angle", s["joints"][j]) for j in joints]
    for f in feet:
        rows.append((f"{f} normal force [N]", "force", s["feet"][f]["normal_force"]))
        if stick:
            rows.append((f"{f} tangential force [N]", "force", s["feet"][f]["tangential_force"]))
    return rows


def fmt(v):
    return "—" if v is None else f"{v:.7g}"


def compare(a: dict | None, b: dict, joints, feet, stick, bound_of, extra=None):
    """Max |a - b| over rows, and the list of (name, a, b, diff, bound) rows."""
    out, worst_ratio = [], 0.0
    rb = rows_of(b, joints, feet, stick)
    ra = rows_of(a, joints, feet, stick) if a is not None else [(n, k, None) for n, k, _ in rb]
    for (name, kind, va), (_, _, vb) in zip(ra, rb):
        bound = bound_of(kind, vb) + (extra.get(name, 0.0) if extra else 0.0)
        d = None if va is None else abs(va - vb)
        if d is not None:
            worst_ratio = max(worst_ratio, d / bound)
        out.append((name, va, vb, d, bound))
    return worst_ratio, out


def model_check(exe: Path | None, urdf: Path, mj: dict) -> bool:
    """Base welded, no ground: restpose (on a copy without mech:ground/mech:contact) against the
    rigid reference on MuJoCo's import of the same file. Checks that both read the same model
    (masses, frames, spring signs), so that the comparisons below are about contact alone.
    Returns True on a failure."""
    ref = mj["runs"].get("welded", {}).get("rigid")
    print("## model check: base welded, no ground\n")
    if ref is None or exe is None:
        print("not run (no `welded` run in the MuJoCo JSON, or no restpose binary)\n")
        return False
    import tempfile
    import xml.etree.ElementTree as ET
    text = urdf.read_text()
    kept = "\n".join(ln for ln in text.splitlines()
                     if "<mech:ground" not in ln and "<mech:contact" not in ln)
    with tempfile.TemporaryDirectory() as td:
        copy = Path(td) / urdf.name
        copy.write_text(kept)
        ET.parse(copy)  # still well-formed
        t0 = time.perf_counter()
        p = subprocess.run([str(exe), "analyze", str(copy), "--json", "-"], capture_output=True,
                           text=True)
        dt = time.perf_counter() - t0
    if p.returncode != 0:
        print(f"restpose failed ({p.returncode}): {p.stderr.strip()[:400]}\n")
        return True
    try:
        r = json.loads(p.stdout)
        dj = max(abs(r["joints"][j]["position"][0] - v) for j, v in ref["joints"].items())
        dv = abs(r["potential_energy"] - ref["potential_energy"])
    except (json.JSONDecodeError, KeyError, IndexError, TypeError) as e:
        print(f"restpose JSON not as expected: {type(e).__name__}: {e}\n")
        return True
    bad = dj > EXACT["angle"] or dv > 1e-8
    print(f"restpose {r['termination']} in {r['iterations']} iterations ({dt * 1e3:.0f} ms process); "
          f"rigid reference {ref['iterations']} Newton iterations. max |Δθ| = {dj:.2e} rad "
          f"(bound {EXACT['angle']:g}), |ΔV| = {dv:.2e} J (bound 1e-8; V = {ref['potential_energy']:.12f} J)"
          f": {'FAIL' if bad else 'agree'}.\n")
    return bad


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--urdf", default=str(DEFAULT_URDF))
    ap.add_argument("--restpose", help="binary (default $RESTPOSE, target/release/restpose, "
                                       "$CARGO_TARGET_DIR/release/restpose)")
    ap.add_argument("--mujoco-json", help="reuse solo12_mujoco.py output instead of running it")
    ap.add_argument("--python", default=sys.executable, help="interpreter with mujoco, numpy")
    ap.add_argument("--repeats", type=int, default=5, help="restpose runs per mode (best time)")
    a = ap.parse_args()
    urdf = Path(a.urdf)

    if a.mujoco_json:
        mj = json.loads(Path(a.mujoco_json).read_text())
    else:
        p = subprocess.run([a.python, str(Path(__file__).parent / "solo12_mujoco.py"), str(urdf),
                            "--welded"],
                           capture_output=True, text=True)
        if p.returncode != 0:
            print(f"solo12_mujoco.py failed ({p.returncode}):\n{p.stderr[-2000:]}")
            return 3
        mj = json.loads(p.stdout)

    # the ground and root as solo12_mujoco.py read them (same file)
    import xml.etree.ElementTree as ET
    robot = ET.parse(urdf).getroot()
    g = robot.find("{urn:urdf-mech:1}ground")
    gp = [float(v) for v in g.get("xyz", "0 0 0").split()]
    gn = [float(v) for v in g.get("normal", "0 0 1").split()]
    nn = math.sqrt(sum(v * v for v in gn))
    gn = [v / nn for v in gn]
    children = {j.find("child").get("link") for j in robot.findall("joint")}
    root = [lk.get("name") for lk in robot.findall("link") if lk.get("name") not in children][0]

    exe = find_restpose(a.restpose)
    fail, missing = False, False
    print(f"# Solo-12 on the ground: restpose vs MuJoCo ({mj['mujoco_version']})\n")
    print(f"model: {urdf}; restpose: {exe if exe else 'not found'}\n")
    fail |= model_check(exe, urdf, mj)
    for mode, runs in mj["runs"].items():
        if mode == "welded":
            continue
        stick = mode == "stick"
        settle, rigid = runs["settle"], runs["rigid"]
        rolling = runs.get("rigid_rolling")
        delta = settle["max_penetration"]
        joints = list(rigid["joints"])
        feet = [f["link"] for f in rigid["feet"]]
        s_mj, s_rg = ref_summary(settle), ref_summary(rigid)
        s_roll = ref_summary(rolling) if rolling else None
        print(f"## friction {mode}\n")
        print(f"MuJoCo settling: {settle['steps']} steps, {settle['sim_time']:.2f} s simulated, "
              f"{settle['wall_time_s']:.2f} s wall, max|qvel| {settle['max_qvel']:.1e}, "
              f"largest penetration delta = {delta:.3e} m, sum of normal forces "
              f"{settle['sum_normal_force']:.6f} N (weight {settle['weight']:.6f} N). "
              f"Rigid KKT: {rigid['iterations']} Newton iterations, {rigid['wall_time_s'] * 1e3:.0f} ms, "
              f"residual {rigid['kkt_residual']:.1e}, reduced-Hessian min eigenvalue "
              f"{rigid['reduced_hessian_min_eig']:.3f}.")
        rp, err, t = (None, "restpose binary not found", math.nan) if exe is None else \
            run_restpose(exe, urdf, mode, a.repeats)
        s_rp = None
        if rp is not None and "contacts" not in rp:
            err = "restpose JSON has no `contacts` field (ground contact not implemented?)"
        elif rp is not None:
            try:
                s_rp = restpose_summary(rp, gp, gn, root)
                missing = [f for f in feet if f not in s_rp["feet"]]
                if missing:
                    err = f"restpose reports no contact on {missing}"
                    s_rp = None
            except (KeyError, IndexError, TypeError) as e:
                err = f"restpose JSON not as expected: {type(e).__name__}: {e}"
        if s_rp is not None:
            tim = rp.get("diagnostics", {}).get("timings", {})
            print(f"restpose: termination {rp.get('termination')}, {rp.get('iterations')} iterations, "
                  f"process wall {t * 1e3:.1f} ms (best of {a.repeats}), timings {tim}, "
                  f"stability {rp.get('stability', {}).get('verdict')}.")
        else:
            print(f"restpose: NOT COMPARED: {err}")
            missing = True
        print()

        # MuJoCo settling against the rigid reference it should approach
        ref_for_mj = s_roll if stick else s_rg
        ratio_mj, rows_mj = compare(s_mj, ref_for_mj, joints, feet, stick,
                                    lambda k, v: settle_bound(k, delta, v))
        fail |= ratio_mj > 1
        # restpose against the rigid reference(s)
        ratio_rp, rows_rp, which = None, None, None
        extra = None
        if s_rp is not None:
            ratio_rp, rows_rp = compare(s_rp, s_rg, joints, feet, stick,
                                        lambda k, v: EXACT[k])
            which, matched = ("centre held", s_rg) if stick else ("frictionless", s_rg)
            if stick:
                for nm, key in (("material point held", "rigid_material"), ("rolling", "rigid_rolling")):
                    if key not in runs:
                        continue
                    cand = ref_summary(runs[key])
                    r2, rows2 = compare(s_rp, cand, joints, feet, stick, lambda k, v: EXACT[k])
                    if r2 < ratio_rp:
                        ratio_rp, rows_rp, which, matched = r2, rows2, nm, cand
                # allowance for restpose vs MuJoCo: the matched stick model vs rolling (MuJoCo's)
                _, rr = compare(matched, s_roll, joints, feet, stick, lambda k, v: 1.0)
                extra = {n: d for n, _, _, d, _ in rr}
            fail |= ratio_rp > 1
            key = {"frictionless": "rigid", "centre held": "rigid",
                   "material point held": "rigid_material", "rolling": "rigid_rolling"}[which]
            if "potential_energy" in rp:
                dv = abs(rp["potential_energy"] - runs[key]["potential_energy"])
                print(f"potential energy: restpose {rp['potential_energy']:.12f} J, rigid ({which}) "
                      f"{runs[key]['potential_energy']:.12f} J, |ΔV| = {dv:.1e} J (bound 1e-7)\n")
                fail |= dv > 1e-7
        ratio_x, rows_x = compare(s_rp, s_mj, joints, feet, stick,
                                  lambda k, v: settle_bound(k, delta, v), extra)
        fail |= s_rp is not None and ratio_x > 1

        ref_name = "rigid (rolling)" if stick else "rigid"
        print(f"| quantity | restpose | {ref_name} | MuJoCo | restpose−rigid{' (' + which + ')' if which else ''} | "
              f"bound | restpose−MuJoCo | bound | MuJoCo−{ref_name} | bound |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for i, (name, _, vref, dmj, bmj) in enumerate(rows_mj):
            vrp = rows_x[i][1]
            drg, brg = (rows_rp[i][3], rows_rp[i][4]) if rows_rp else (None, None)
            dx, bx = rows_x[i][3], rows_x[i][4]
            print(f"| {name} | {fmt(vrp)} | {fmt(vref)} | {fmt(rows_x[i][2])} | {fmt(drg)} | "
                  f"{fmt(brg)} | {fmt(dx)} | {fmt(bx)} | {fmt(dmj)} | {fmt(bmj)} |")
        if stick and rolling:
            for nm, key in (("centre held", "rigid"), ("material point held", "rigid_material")):
                if key in runs:
                    x = runs[key]
                    d_roll = max(abs(x["joints"][j] - rolling["joints"][j]) for j in joints)
                    d_ft = max(abs(a["tangential_force"] - b["tangential_force"])
                               for a, b in zip(x["feet"], rolling["feet"]))
                    print(f"\nRigid stick, {nm} vs rolling: max joint difference {d_roll:.3e} rad, "
                          f"base height {abs(x['base']['height'] - rolling['base']['height']):.3e} m, "
                          f"tangential force {d_ft:.3e} N.")
        print(f"\nworst difference / bound: MuJoCo vs rigid {ratio_mj:.2f}"
              + (f", restpose vs rigid ({which}) {ratio_rp:.2f}, restpose vs MuJoCo {ratio_x:.2f}"
                 if s_rp is not None else "") + "\n")
    status = 1 if fail else (2 if missing else 0)
    verdict = {0: "PASS", 1: "FAIL: a difference beyond its bound", 2: "restpose not compared",
               3: "MuJoCo failed"}[status]
    print(f"**{verdict}**")
    return status


if __name__ == "__main__":
    sys.exit(main())
