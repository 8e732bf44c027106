#!/usr/bin/env python3
"""Solve restpose's generated benchmark mechanisms with peer tools and compare.

Peers (each skipped with a message when its package does not import):

* Pinocchio (``pin``): Newton on joint coordinates for the tree (chain) family,
  g(q) + K (q - q_ref) = 0 with ``computeGeneralizedGravity`` and
  ``computeGeneralizedGravityDerivatives``, backtracking line search on
  ``computePotentialEnergy`` + spring energy, from q = 0, tolerance 1e-8 N m.
  Skipped where its Data (O(nv^3) memory in pin 4.1) would not fit.
* scipy SLSQP on maximal coordinates (7 per body: position + quaternion),
  revolute-joint rows (3 position + 2 axis alignment), quaternion norms and
  loop closures as equality constraints (dependent rows dropped: SLSQP needs
  independent rows); analytic gradients; up to --slsqp-max-bodies.
* MuJoCo damped settling: the same data built with MjSpec (hinges with
  ``stiffness``/``springref``, each sprung joint critically damped on its own,
  ``connect`` equalities closing the ladder loops, implicitfast integrator),
  stepped until max |qvel| < --mujoco-vtol.

Independent references written here (not peer tools):

* numpy joint-space Newton (trees): gradient and Hessian of V(θ) from the
  subtree masses and moments, O(N^2) memory; reaches N = 1000 where
  Pinocchio's Data does not fit.
* Closed form (ladder): every loop is a parallelogram whose rung stays level,
  so each loop angle solves one scalar equation (``ladder_closed_form``).

Usage: python benches/peers/peers.py [--restpose PATH] [--help for the rest]
The Markdown table is printed on standard output (and written to --markdown).
"""

from __future__ import annotations

import argparse
import atexit
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

# Single-threaded BLAS, like the other tools here: on this 2-core machine a threaded OpenBLAS
# made SLSQP's small dense solves 10-30x slower and erratic (1.5 s instead of 47 ms on ladder 5).
for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import numpy as np  # noqa: E402

MECH = "{urn:urdf-mech:1}"

try:  # optional peers: a missing one is skipped with a message
    import pinocchio as pin
except Exception as e:  # noqa: BLE001 - report whatever went wrong
    pin = None
    PIN_ERROR = f"{type(e).__name__}: {e}"
try:
    import mujoco
except Exception as e:  # noqa: BLE001
    mujoco = None
    MUJOCO_ERROR = f"{type(e).__name__}: {e}"
try:
    import scipy
    from scipy.optimize import minimize
except Exception as e:  # noqa: BLE001
    scipy = None
    SCIPY_ERROR = f"{type(e).__name__}: {e}"


def log(*a):
    print(*a, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------------------
# URDF (with the mech: extensions) as plain data
# --------------------------------------------------------------------------------------


def rpy_matrix(rpy):
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = (math.cos(r), math.sin(r), math.cos(p), math.sin(p),
                              math.cos(y), math.sin(y))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def mat_to_quat(r):
    """Unit quaternion (w, x, y, z) of a rotation matrix."""
    t = np.trace(r)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = [0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2]) * 2
        q = [(r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s]
    elif r[1, 1] > r[2, 2]:
        s = math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2]) * 2
        q = [(r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s]
    else:
        s = math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1]) * 2
        q = [(r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    return q / np.linalg.norm(q)


def axis_angle_matrix(a, t):
    a = np.asarray(a, float)
    k = skew(a)
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * (k @ k)


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _floats(s, n=3, default=0.0):
    if s is None:
        return np.full(n, default, float)
    return np.array([float(x) for x in s.split()], float)


@dataclass
class Link:
    name: str
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # at COM, link axes


@dataclass
class Joint:
    name: str
    type: str
    parent: str
    child: str
    xyz: np.ndarray
    rpy: np.ndarray
    axis: np.ndarray
    loop: bool = False
    child_xyz: np.ndarray = field(default_factory=lambda: np.zeros(3))
    child_rpy: np.ndarray = field(default_factory=lambda: np.zeros(3))


@dataclass
class Mech:
    name: str
    links: dict
    joints: list  # tree joints, in file order
    loops: list  # mech:loop_joint
    springs: dict  # joint name -> (stiffness, reference)
    gravity: np.ndarray
    root: str

    def tree_order(self):
        """Tree joints ordered parents before children."""
        placed = {self.root}
        out, rest = [], list(self.joints)
        while rest:
            progress = False
            for j in list(rest):
                if j.parent in placed:
                    out.append(j)
                    placed.add(j.child)
                    rest.remove(j)
                    progress = True
            if not progress:
                raise ValueError("URDF tree is not connected to its root")
        return out

    def zero_pose(self):
        """World rotation and position of every link at zero joint values."""
        pose = {self.root: (np.eye(3), np.zeros(3))}
        for j in self.tree_order():
            rp, pp = pose[j.parent]
            pose[j.child] = (rp @ rpy_matrix(j.rpy), pp + rp @ j.xyz)
        return pose


def parse_urdf(text: str) -> Mech:
    root = ET.fromstring(text)
    links = {}
    for el in root.findall("link"):
        lk = Link(el.get("name"))
        inert = el.find("inertial")
        if inert is not None:
            org = inert.find("origin")
            lk.com = _floats(org.get("xyz") if org is not None else None)
            r = rpy_matrix(_floats(org.get("rpy") if org is not None else None))
            lk.mass = float(inert.find("mass").get("value"))
            i = inert.find("inertia")
            g = lambda k: float(i.get(k, "0"))  # noqa: E731
            ii = np.array([[g("ixx"), g("ixy"), g("ixz")], [g("ixy"), g("iyy"), g("iyz")],
                           [g("ixz"), g("iyz"), g("izz")]])
            lk.inertia = r @ ii @ r.T
        links[lk.name] = lk

    def origin(el, tag="origin"):
        o = el.find(tag)
        if o is None:
            return np.zeros(3), np.zeros(3)
        return _floats(o.get("xyz")), _floats(o.get("rpy"))

    def axis(el):
        a = el.find("axis")
        v = _floats(a.get("xyz") if a is not None else "1 0 0")
        return v / np.linalg.norm(v)

    joints = []
    for el in root.findall("joint"):
        xyz, rpy = origin(el)
        joints.append(Joint(el.get("name"), el.get("type"), el.find("parent").get("link"),
                            el.find("child").get("link"), xyz, rpy, axis(el)))
    loops = []
    for el in root.findall(MECH + "loop_joint"):
        xyz, rpy = origin(el)
        cxyz, crpy = origin(el, "child_origin")
        loops.append(Joint(el.get("name"), el.get("type"), el.find("parent").get("link"),
                           el.find("child").get("link"), xyz, rpy, axis(el), True, cxyz, crpy))
    springs = {}
    for el in root.findall(MECH + "joint_spring"):
        springs[el.get("joint")] = (float(el.get("stiffness")), float(el.get("reference", "0")))
    g = root.find(MECH + "gravity")
    gravity = _floats(g.get("xyz")) if g is not None else np.array([0, 0, -9.81])
    children = {j.child for j in joints}
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        raise ValueError(f"expected one root link, found {roots}")
    for j in joints + loops:
        if j.type not in ("revolute", "continuous"):
            raise ValueError(f"joint {j.name}: only revolute/continuous joints are modelled here")
    return Mech(root.get("name"), links, joints, loops, springs, gravity, roots[0])


def wrap(d):
    """Angle difference folded into (-pi, pi]."""
    return (np.asarray(d) + math.pi) % (2 * math.pi) - math.pi


def max_angle_diff(a: dict, b: dict):
    """Max |a - b| over the joints both name (angles compared modulo 2 pi)."""
    common = sorted(set(a) & set(b))
    if not common:
        return float("nan"), 0
    return float(max(abs(wrap(a[k] - b[k])) for k in common)), len(common)


# --------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------


@dataclass
class Result:
    tool: str
    ok: bool  # converged / settled
    angles: dict = field(default_factory=dict)  # joint name -> angle [rad]
    energy: float = float("nan")  # gravity + spring potential, restpose's zero
    iterations: str = ""  # iterations or steps, as text
    time_ms: float = float("nan")  # in-process solve time
    note: str = ""
    extra: dict = field(default_factory=dict)


# --------------------------------------------------------------------------------------
# restpose
# --------------------------------------------------------------------------------------


def default_restpose(repo: Path) -> str:
    cands = [repo / "target" / "release" / "restpose"]
    if os.environ.get("CARGO_TARGET_DIR"):
        cands.append(Path(os.environ["CARGO_TARGET_DIR"]) / "release" / "restpose")
    cands.append(Path.home() / ".cache" / "restpose-target" / "release" / "restpose")
    for c in cands:
        if c.is_file() and os.access(c, os.X_OK):
            return str(c)
    return str(cands[-1])


def find_time_field(d, prefix=""):
    """A solve-time field in restpose's JSON, if it has one: (key, milliseconds)."""
    if not isinstance(d, dict):
        return None
    for k, v in d.items():
        key = k.lower()
        if isinstance(v, (int, float)) and not isinstance(v, bool) and (
                "time" in key or "elapsed" in key or key.endswith("_ms") or key.endswith("_s")):
            if "ms" in key or "milli" in key:
                return prefix + k, float(v)
            if key.endswith("_s") or "sec" in key:
                return prefix + k, float(v) * 1e3
            return prefix + k, float(v)  # unit unknown: assume ms, key is reported
        if isinstance(v, dict) and k not in ("joints", "links", "reactions"):
            r = find_time_field(v, prefix + k + ".")
            if r:
                return r
    return None


def run_restpose(exe, urdf: Path, timeout: float, repeats: int) -> Result:
    out = urdf.with_suffix(".restpose.json")
    walls = []
    data = None
    for rep in range(repeats):
        out.unlink(missing_ok=True)
        t0 = time.perf_counter()
        try:
            p = subprocess.run([exe, "analyze", str(urdf), "--json", str(out), "-q"],
                               capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return Result("restpose", False, note=f"timed out after {timeout:.0f} s (skipped)",
                          time_ms=float("nan"))
        wall = (time.perf_counter() - t0) * 1e3
        if not out.exists():
            return Result("restpose", False, note=f"no JSON (exit {p.returncode}): "
                          + (p.stderr.strip().splitlines() or ["?"])[-1][:120])
        data = json.loads(out.read_text())
        walls.append(wall)
        if wall > 2000 or (wall > 200 and rep >= 2):  # slow: fewer runs
            break
    angles = {}
    for name, j in data["joints"].items():
        pos = j.get("position") or []
        if len(pos) == 1:
            angles[name] = float(pos[0])
    wall = min(walls)
    r = Result("restpose", bool(data.get("converged")), angles, float(data["potential_energy"]),
               str(data.get("iterations", "")))
    r.extra = {"wall_ms": wall, "runs": len(walls),
               "termination": data.get("termination"), "dof": data.get("dof"),
               "coordinates": data.get("coordinates"),
               "stability": (data.get("stability") or {}).get("verdict")}
    tf = find_time_field(data)
    if tf:
        r.time_ms = tf[1]
        r.extra["time_basis"] = f"JSON `{tf[0]}`"
        r.extra["json_time"] = True
    else:
        r.time_ms = wall
        r.extra["time_basis"] = "process wall (the JSON has no solve time)"
    if not r.ok:
        r.note = f"termination: {data.get('termination')}"
    return r


def restpose_bench_time(bench: str, family: str, n: int, timeout: float):
    """In-process solve time from restpose's own bench harness (benches/chain.rs, the compiled
    `chain` binary run directly). Two formats are understood:
    - child mode (RESTPOSE_BENCH_CHILD=family:N:auto): one line
      `name bodies dof iterations best_ms peak_mb algebra`, best of 3 solves;
    - the older table harness: `| family | N | coordinates | iterations | solve [ms] | ...`
      rows for the chain of each size argument and the ladder of half of it.
    Returns (ms, iterations, algebra) or None."""
    arg = n if family == "chain" else 2 * n  # the older harness halves the ladder size
    env = dict(os.environ, RESTPOSE_BENCH_CHILD=f"{family}:{n}:auto")
    p = subprocess.Popen([bench, str(arg), "--bench"], stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, text=True, env=env)
    t0 = time.perf_counter()
    found = None
    try:
        for line in p.stdout:
            f = line.split()
            if len(f) >= 5 and f[0] == f"{family}{n}":  # child mode
                found = (float(f[4]), f[3], f[6] if len(f) > 6 else "")
                break
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) >= 5 and cells[0] == family and cells[1] == str(n):
                found = (float(cells[4]), cells[3], "")
                break
            if time.perf_counter() - t0 > timeout:
                break
    finally:
        p.kill()
        p.wait()
    return found


# --------------------------------------------------------------------------------------
# Pinocchio: Newton on joint coordinates (trees only)
# --------------------------------------------------------------------------------------


def mem_available():
    """MemAvailable in bytes (Linux), or None."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def solve_pinocchio(urdf: Path, mech: Mech, tol=1e-8, max_iter=500) -> Result:
    if pin is None:
        return Result("pinocchio", False, note=f"skipped: pinocchio does not import ({PIN_ERROR})")
    if mech.loops:
        return Result("pinocchio", False, note="skipped: closed loops (Pinocchio is used on trees only)")
    model = pin.buildModelFromUrdf(str(urdf))  # mech: elements are ignored by urdfdom
    model.gravity.linear = np.array(mech.gravity, float)
    # pin 4.1's Data grows as nv^3 (measured on these chains: 68 MB at nv = 100, 0.51 GB at
    # 200, 1.7 GB at 300, about 63 nv^3 bytes): a 1000-joint chain would need ~63 GB and gets
    # the process OOM-killed, so refuse what does not fit in half the available memory.
    need = 64.0 * model.nv ** 3
    avail = mem_available()
    if avail and need > 0.5 * avail:
        return Result("pinocchio", False, note=(
            f"skipped: pinocchio's Data for nv = {model.nv} needs ~{need / 1e9:.0f} GB "
            f"(grows as nv^3), {avail / 1e9:.0f} GB available"))
    data = model.createData()
    nv = model.nv
    k = np.zeros(nv)
    ref = np.zeros(nv)
    names = []
    for jid in range(1, model.njoints):
        name = model.names[jid]
        if model.nvs[jid] != 1:
            return Result("pinocchio", False, note=f"skipped: joint {name} is not 1-dof")
        names.append((name, model.idx_vs[jid]))
        if name in mech.springs:
            k[model.idx_vs[jid]], ref[model.idx_vs[jid]] = mech.springs[name]

    t0 = time.perf_counter()
    q = pin.neutral(model)
    theta = np.zeros(nv)  # unwrapped joint angles: continuous joints are (cos, sin) in q

    def energy(q, th):
        return pin.computePotentialEnergy(model, data, q) + 0.5 * float(k @ (th - ref) ** 2)

    v = energy(q, theta)
    it = 0
    gnorm = float("inf")
    halvings = 0
    ok = False
    while it < max_iter:
        grad = pin.computeGeneralizedGravity(model, data, q) + k * (theta - ref)
        gnorm = float(np.max(np.abs(grad)))
        if gnorm < tol:
            ok = True
            break
        h = pin.computeGeneralizedGravityDerivatives(model, data, q) + np.diag(k)
        h = 0.5 * (h + h.T)
        shift = 0.0
        while True:  # Newton step; shift the Hessian if it is not positive definite
            try:
                c = np.linalg.cholesky(h + shift * np.eye(nv))
                break
            except np.linalg.LinAlgError:
                shift = max(2 * shift, 1e-6 * max(1.0, float(np.max(np.abs(np.diag(h))))))
        dq = -np.linalg.solve(c.T, np.linalg.solve(c, grad))
        slope = float(grad @ dq)
        a = 1.0
        while True:
            qn = pin.integrate(model, q, a * dq)
            thn = theta + a * dq
            vn = energy(qn, thn)
            # Armijo, with room for round-off in V near the solution (V changes there by
            # ~|g|^2/k, far below eps |V|)
            if vn <= v + 1e-4 * a * slope + 1e-13 * max(1.0, abs(v)) or a < 1e-12:
                break
            a *= 0.5
            halvings += 1
        q, theta, v = qn, thn, vn
        it += 1
    ms = (time.perf_counter() - t0) * 1e3
    angles = {name: float(theta[i]) for name, i in names}
    return Result("pinocchio", ok, angles, v, str(it), ms,
                  note="" if ok else f"not converged: max|g| = {gnorm:.1e}",
                  extra={"halvings": halvings, "gnorm": gnorm})


# --------------------------------------------------------------------------------------
# Joint-space Newton in plain numpy (trees): an independent reference where Pinocchio cannot go
# --------------------------------------------------------------------------------------


def solve_numpy_tree(mech: Mech, tol=1e-8, max_iter=500) -> Result:
    """V(θ) = -Σ m_b g·c_b(θ) + Σ ½ k_i (θ_i - ref_i)² on the joint angles of a tree, by Newton
    with the same line search as the Pinocchio solver. With a_i, o_i joint i's world axis and
    origin and M_i, S_i the mass and first moment Σ m_b c_b of the bodies it carries:
        ∂V/∂θ_i = -g·(a_i × (S_i - M_i o_i)) + k_i (θ_i - ref_i)
        ∂²V/∂θ_i∂θ_j = -(g × a_i)·(a_j × (S_j - M_j o_j))   (i = j or i an ancestor of j)
    and zero for joints on different branches. O(N²) memory, not Pinocchio's O(N³)."""
    if mech.loops:
        return Result("numpy joint-space", False, note="skipped: closed loops")
    t0 = time.perf_counter()
    order = mech.tree_order()
    nj = len(order)
    idx = {j.name: i for i, j in enumerate(order)}
    parent_joint = {}  # joint index -> index of the joint above it (or -1)
    by_child = {j.child: i for i, j in enumerate(order)}
    for i, j in enumerate(order):
        parent_joint[i] = by_child.get(j.parent, -1)
    anc = np.zeros((nj, nj), bool)  # anc[i, j]: i is j or an ancestor of j
    for jj in range(nj):
        i = jj
        while i >= 0:
            anc[i, jj] = True
            i = parent_joint[i]
    k = np.array([mech.springs.get(j.name, (0.0, 0.0))[0] for j in order])
    ref = np.array([mech.springs.get(j.name, (0.0, 0.0))[1] for j in order])
    mass = np.array([mech.links[j.child].mass for j in order])
    com_local = np.array([mech.links[j.child].com for j in order])
    g = np.array(mech.gravity, float)
    ro = [rpy_matrix(j.rpy) for j in order]
    # the root link does not move: its gravity energy is a constant (zero for the generated files)
    root = mech.links[mech.root]
    v_root = -root.mass * float(g @ root.com)

    def kin(th):
        rot = {mech.root: np.eye(3)}
        pos = {mech.root: np.zeros(3)}
        a = np.zeros((nj, 3))
        o = np.zeros((nj, 3))
        c = np.zeros((nj, 3))
        for i, j in enumerate(order):
            rp, pp = rot[j.parent], pos[j.parent]
            rj = rp @ ro[i]
            o[i] = pp + rp @ j.xyz
            a[i] = rj @ j.axis
            r = rj @ axis_angle_matrix(j.axis, th[i])
            rot[j.child], pos[j.child] = r, o[i]
            c[i] = o[i] + r @ com_local[i]
        # subtree sums, leaves first (tree_order puts parents first)
        msub = mass.copy()
        ssub = mass[:, None] * c
        for i in range(nj - 1, -1, -1):
            p = parent_joint[i]
            if p >= 0:
                msub[p] += msub[i]
                ssub[p] += ssub[i]
        w = ssub - msub[:, None] * o
        return a, c, w

    def energy(th, c):
        return -float(mass @ (c @ g)) + 0.5 * float(k @ (th - ref) ** 2) + v_root

    th = np.zeros(nj)
    a, c, w = kin(th)
    v = energy(th, c)
    it, halvings, gnorm, ok = 0, 0, float("inf"), False
    while it < max_iter:
        grad = -np.cross(a, w) @ g + k * (th - ref)
        gnorm = float(np.max(np.abs(grad)))
        if gnorm < tol:
            ok = True
            break
        u = np.cross(a, w)  # a_j × w_j
        p = np.cross(g, a)  # g × a_i
        h = -(p @ u.T) * anc
        h = np.triu(h) + np.triu(h, 1).T + np.diag(k)
        shift = 0.0
        while True:
            try:
                ch = np.linalg.cholesky(h + shift * np.eye(nj))
                break
            except np.linalg.LinAlgError:
                shift = max(2 * shift, 1e-6 * max(1.0, float(np.max(np.abs(np.diag(h))))))
        d = -np.linalg.solve(ch.T, np.linalg.solve(ch, grad))
        slope = float(grad @ d)
        al = 1.0
        while True:
            thn = th + al * d
            an, cn, wn = kin(thn)
            vn = energy(thn, cn)
            if vn <= v + 1e-4 * al * slope + 1e-13 * max(1.0, abs(v)) or al < 1e-12:
                break
            al *= 0.5
            halvings += 1
        th, a, c, w, v = thn, an, cn, wn, vn
        it += 1
    ms = (time.perf_counter() - t0) * 1e3
    angles = {j.name: float(th[idx[j.name]]) for j in order}
    r = Result("numpy joint-space", ok, angles, v, str(it), ms,
               note="" if ok else f"not converged: max|∂V/∂θ| = {gnorm:.1e}")
    r.extra = {"gnorm": gnorm, "halvings": halvings}
    return r


# --------------------------------------------------------------------------------------
# scipy SLSQP on maximal coordinates
# --------------------------------------------------------------------------------------


def cross(a, b):
    """a × b for 3-vectors (np.cross is slow on single vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def rot(q, c):
    """q (w, x, y, z) applied to c, as c + 2w(v×c) + 2v×(v×c) (a rotation when |q| = 1)."""
    w, v = q[0], q[1:]
    u = cross(v, c)
    return c + 2 * w * u + 2 * cross(v, u)


def drot(q, c):
    """3 × 4 Jacobian of rot(q, c) with respect to q."""
    w, v = q[0], q[1:]
    u = cross(v, c)
    sc = skew(c)
    jv = -2 * w * sc - 2 * skew(u) - 2 * skew(v) @ sc
    return np.column_stack([2 * u, jv])


def perp(a):
    e = np.cross(a, [1.0, 0, 0])
    if np.linalg.norm(e) < 1e-6:
        e = np.cross(a, [0, 1.0, 0])
    return e / np.linalg.norm(e)


class MaxCoords:
    """Maximal coordinates: body b holds x[7b:7b+3] = position, x[7b+3:7b+7] = quaternion."""

    def __init__(self, mech: Mech):
        self.mech = mech
        self.bodies = [n for n in mech.links if n != mech.root]
        self.index = {n: i for i, n in enumerate(self.bodies)}
        self.n = 7 * len(self.bodies)
        pose = mech.zero_pose()
        self.x0 = np.zeros(self.n)
        for n, i in self.index.items():
            r, p = pose[n]
            self.x0[7 * i:7 * i + 3] = p
            self.x0[7 * i + 3:7 * i + 7] = mat_to_quat(r)
        self.mass = np.array([mech.links[n].mass for n in self.bodies])
        self.com = np.array([mech.links[n].com for n in self.bodies])
        self.g = np.array(mech.gravity, float)
        # joints as constant vectors: parent side in the parent's frame, child side in the child's
        self.joints = []
        for j in mech.joints + mech.loops:
            ro = rpy_matrix(j.rpy)
            roc = rpy_matrix(j.child_rpy)
            e1 = perp(j.axis)
            e2 = np.cross(j.axis, e1)
            self.joints.append(dict(
                name=j.name, p=self.index.get(j.parent, -1), c=self.index[j.child],
                oP=j.xyz, oC=j.child_xyz, e1P=ro @ e1, e2P=ro @ e2, aC=roc @ j.axis,
                e1C=roc @ e1, spring=mech.springs.get(j.name)))
        self.m = 5 * len(self.joints) + len(self.bodies)
        self.row_names = [f"{j['name']}.{r}" for j in self.joints
                          for r in ("pos_x", "pos_y", "pos_z", "axis_1", "axis_2")]
        self.row_names += [f"{b}.quat_norm" for b in self.bodies]
        # check that the zero pose closes the loops
        r = self.constraints(self.x0)
        if np.max(np.abs(r)) > 1e-9:
            raise ValueError(f"the zero pose violates the constraints by {np.max(np.abs(r)):.1e}")
        self.keep = self.independent_rows(self.x0)
        self.dropped = [self.row_names[i] for i in range(self.m) if i not in set(self.keep)]

    def independent_rows(self, x, rtol=1e-9):
        """A maximal independent subset of the constraint rows at x, greedy in the order:
        quaternion norms, tree joints, loop joints (so dependent loop-closure rows are the
        ones left out). SLSQP refuses more equality rows than variables and its LSQ
        subproblem wants independent rows; restpose keeps redundant rows and deals with them
        itself."""
        jac = self.jacobian(x)
        nj = len(self.joints)
        order = list(range(5 * nj, self.m)) + list(range(5 * nj))
        basis = np.zeros((0, self.n))
        keep = []
        for i in order:
            row = jac[i]
            res = row - basis.T @ (basis @ row)
            res = res - basis.T @ (basis @ res)  # second Gram-Schmidt pass
            nrm = np.linalg.norm(res)
            if nrm > rtol * max(1.0, np.linalg.norm(row)):
                basis = np.vstack([basis, res / nrm])
                keep.append(i)
        return sorted(keep)

    def _pq(self, x, b):
        if b < 0:
            return np.zeros(3), np.array([1.0, 0, 0, 0])
        return x[7 * b:7 * b + 3], x[7 * b + 3:7 * b + 7]

    def angle_and_grad(self, x, j, want_grad=True):
        """Joint angle atan2((R_P e2P)·(R_C e1C), (R_P e1P)·(R_C e1C)) and its gradient."""
        _, qp = self._pq(x, j["p"])
        _, qc = self._pq(x, j["c"])
        f1 = rot(qp, j["e1P"])
        f2 = rot(qp, j["e2P"])
        h = rot(qc, j["e1C"])
        cx, cy = f1 @ h, f2 @ h
        t = math.atan2(cy, cx)
        if not want_grad:
            return t, None
        den = cx * cx + cy * cy
        grad = {}
        dcx_c = drot(qc, j["e1C"]).T @ f1
        dcy_c = drot(qc, j["e1C"]).T @ f2
        grad[j["c"]] = (cx * dcy_c - cy * dcx_c) / den
        if j["p"] >= 0:
            dcx_p = drot(qp, j["e1P"]).T @ h
            dcy_p = drot(qp, j["e2P"]).T @ h
            grad[j["p"]] = (cx * dcy_p - cy * dcx_p) / den
        return t, grad

    def objective(self, x):
        p = x.reshape(-1, 7)
        v = 0.0
        for b in range(len(self.bodies)):
            v -= self.mass[b] * (self.g @ (p[b, :3] + rot(p[b, 3:], self.com[b])))
        for j in self.joints:
            if j["spring"]:
                kk, ref = j["spring"]
                t, _ = self.angle_and_grad(x, j, False)
                v += 0.5 * kk * (t - ref) ** 2
        return v

    def gradient(self, x):
        p = x.reshape(-1, 7)
        gr = np.zeros_like(x).reshape(-1, 7)
        for b in range(len(self.bodies)):
            gr[b, :3] -= self.mass[b] * self.g
            gr[b, 3:] -= self.mass[b] * (drot(p[b, 3:], self.com[b]).T @ self.g)
        for j in self.joints:
            if j["spring"]:
                kk, ref = j["spring"]
                t, g = self.angle_and_grad(x, j)
                for b, gb in g.items():
                    gr[b, 3:] += kk * (t - ref) * gb
        return gr.ravel()

    def constraints(self, x):
        out = np.zeros(self.m)
        r = 0
        for j in self.joints:
            pp, qp = self._pq(x, j["p"])
            pc, qc = self._pq(x, j["c"])
            out[r:r + 3] = pp + rot(qp, j["oP"]) - pc - rot(qc, j["oC"])
            ac = rot(qc, j["aC"])
            out[r + 3] = rot(qp, j["e1P"]) @ ac
            out[r + 4] = rot(qp, j["e2P"]) @ ac
            r += 5
        q = x.reshape(-1, 7)[:, 3:]
        out[r:] = np.sum(q * q, axis=1) - 1.0
        return out

    def jacobian(self, x):
        jac = np.zeros((self.m, self.n))
        r = 0
        for j in self.joints:
            b, c = j["p"], j["c"]
            pp, qp = self._pq(x, b)
            pc, qc = self._pq(x, c)
            ac = rot(qc, j["aC"])
            jac[r:r + 3, 7 * c:7 * c + 3] = -np.eye(3)
            jac[r:r + 3, 7 * c + 3:7 * c + 7] = -drot(qc, j["oC"])
            dac = drot(qc, j["aC"])
            f1, f2 = rot(qp, j["e1P"]), rot(qp, j["e2P"])
            jac[r + 3, 7 * c + 3:7 * c + 7] = f1 @ dac
            jac[r + 4, 7 * c + 3:7 * c + 7] = f2 @ dac
            if b >= 0:
                jac[r:r + 3, 7 * b:7 * b + 3] = np.eye(3)
                jac[r:r + 3, 7 * b + 3:7 * b + 7] = drot(qp, j["oP"])
                jac[r + 3, 7 * b + 3:7 * b + 7] = ac @ drot(qp, j["e1P"])
                jac[r + 4, 7 * b + 3:7 * b + 7] = ac @ drot(qp, j["e2P"])
            r += 5
        for i in range(len(self.bodies)):
            jac[r + i, 7 * i + 3:7 * i + 7] = 2 * x[7 * i + 3:7 * i + 7]
        return jac

    def angles(self, x):
        return {j["name"]: self.angle_and_grad(x, j, False)[0] for j in self.joints}


def solve_slsqp(mech: Mech, max_bodies: int, rel_ftol=1e-16, max_iter=1000) -> Result:
    if scipy is None:
        return Result("scipy SLSQP", False, note=f"skipped: scipy does not import ({SCIPY_ERROR})")
    nb = len(mech.links) - 1
    if nb > max_bodies:
        return Result("scipy SLSQP", False,
                      note=f"skipped: {nb} bodies > --slsqp-max-bodies {max_bodies} (dense SQP, slow)")
    t0 = time.perf_counter()  # the time includes the choice of independent rows
    mc = MaxCoords(mech)
    # SLSQP's ftol is absolute on V: scale it by the mechanism's gravity energy scale
    # (total weight × extent of the zero pose)
    pts = mc.x0.reshape(-1, 7)[:, :3]
    extent = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))) if len(pts) else 1.0
    ftol = rel_ftol * max(1.0, float(mc.mass.sum()) * float(np.linalg.norm(mc.g)) * max(extent, 1e-3))
    keep = mc.keep
    res = minimize(mc.objective, mc.x0, jac=mc.gradient, method="SLSQP",
                   constraints=[{"type": "eq", "fun": lambda x: mc.constraints(x)[keep],
                                 "jac": lambda x: mc.jacobian(x)[keep]}],
                   options={"maxiter": max_iter, "ftol": ftol})
    ms = (time.perf_counter() - t0) * 1e3
    x = res.x
    viol = float(np.max(np.abs(mc.constraints(x))))  # all rows, the dropped ones too
    # the projected gradient at the result: how stationary it is
    jac = mc.jacobian(x)
    lam, *_ = np.linalg.lstsq(jac.T, mc.gradient(x), rcond=None)
    kkt = float(np.max(np.abs(mc.gradient(x) - jac.T @ lam)))
    ok = res.success and viol < 1e-8
    note = "" if res.success else f"SLSQP: {res.message}"
    r = Result("scipy SLSQP", ok, mc.angles(x), float(res.fun), str(res.nit), ms, note)
    r.extra = {"violation": viol, "kkt": kkt, "message": res.message, "nvar": mc.n, "ncon": mc.m,
               "ftol": ftol,
               "nkept": len(keep), "dropped": mc.dropped}
    return r


# --------------------------------------------------------------------------------------
# MuJoCo damped settling
# --------------------------------------------------------------------------------------


def _vec3_param(cur, value):
    """MuJoCo 4 keeps joint stiffness/damping as arrays (polynomial terms), MuJoCo 3 as scalars."""
    if np.ndim(cur) == 0:
        return value
    out = np.zeros(len(cur))
    out[0] = value
    return out


def build_mjspec(mech: Mech, damping: dict, timestep: float):
    """The mechanism as a MuJoCo model, built with MjSpec (MJCF text would do as well, but its
    XML parser refuses the 1000-deep nesting of the 1000-link chain)."""
    s = mujoco.MjSpec()
    s.modelname = mech.name
    s.compiler.degree = False
    s.compiler.autolimits = True
    # the generated ladder's link inertia diag(1e-3, 1e-3, 1e-2) breaks the triangle inequality
    # (restpose warns too) and MuJoCo refuses it unless balanced; statics does not depend on it
    s.compiler.balanceinertia = True
    s.option.gravity = np.array(mech.gravity, float)
    s.option.timestep = timestep
    s.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # damping taken implicitly
    s.option.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    s.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    kids = {}
    for j in mech.joints:
        kids.setdefault(j.parent, []).append(j)
    stack = [(s.worldbody, j) for j in reversed(kids.get(mech.root, []))]
    while stack:  # depth first, children in file order
        parent, j = stack.pop()
        lk = mech.links[j.child]
        b = parent.add_body(name=j.child, pos=j.xyz, quat=mat_to_quat(rpy_matrix(j.rpy)))
        b.explicitinertial = True
        b.mass = lk.mass
        b.ipos = lk.com
        ii = lk.inertia
        b.fullinertia = [ii[0, 0], ii[1, 1], ii[2, 2], ii[0, 1], ii[0, 2], ii[1, 2]]
        kk, ref = mech.springs.get(j.name, (0.0, 0.0))
        jt = b.add_joint(name=j.name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=j.axis)
        jt.stiffness = _vec3_param(jt.stiffness, kk)
        jt.springref = ref
        jt.damping = _vec3_param(jt.damping, damping[j.name])
        stack.extend((b, c) for c in reversed(kids.get(j.child, [])))
    for lj in mech.loops:
        # a ball closure ("connect") at the loop joint's origin; the loop joint's two axis rows
        # are left out (for the planar ladder they are implied by the tree's parallel hinges).
        # MuJoCo computes the point on body2 from the zero pose, where the loops are closed.
        e = s.add_equality(name=lj.name, type=mujoco.mjtEq.mjEQ_CONNECT,
                           objtype=mujoco.mjtObj.mjOBJ_BODY, name1=lj.parent, name2=lj.child)
        data = np.zeros(len(e.data))
        data[:3] = lj.xyz
        if len(data) > 10:
            data[10] = 1.0  # torquescale, as the MJCF default (unused by connect)
        e.data = data
        # as hard as MuJoCo allows: time constant 2 steps (the "refsafe" minimum), impedance 0.9999
        e.solref = [2 * timestep, 1.0]
        e.solimp = [0.9999, 0.9999, 0.001, 0.5, 2.0]
    return s


def solve_mujoco(mech: Mech, vtol: float, budget_s: float, timestep: float, zeta: float,
                 mjcf_out: Path | None = None, min_steps: int = 5000) -> Result:
    if mujoco is None:
        return Result("mujoco", False, note=f"skipped: mujoco does not import ({MUJOCO_ERROR})")
    # Damping: each sprung joint critically damped on its own (zeta = 1): c = 2 zeta sqrt(k M_ii)
    # with M_ii the joint's diagonal mass-matrix entry at the zero pose. Joints without a spring
    # (the ladder's right posts and rung pins) get none: the loops tie them to a sprung joint.
    probe = build_mjspec(mech, {j.name: 0.0 for j in mech.joints}, timestep).compile()
    pd = mujoco.MjData(probe)
    mujoco.mj_forward(probe, pd)
    full = np.zeros((probe.nv, probe.nv))
    try:
        mujoco.mj_fullM(probe, pd, full)  # mujoco >= 4
    except TypeError:
        mujoco.mj_fullM(probe, full, pd.qM)  # mujoco 3
    mdiag = np.diag(full)
    damping = {}
    for j in mech.joints:
        dof = probe.jnt_dofadr[mujoco.mj_name2id(probe, mujoco.mjtObj.mjOBJ_JOINT, j.name)]
        kk = mech.springs.get(j.name, (0.0, 0.0))[0]
        damping[j.name] = 2.0 * zeta * math.sqrt(kk * mdiag[dof])
    spec = build_mjspec(mech, damping, timestep)
    m = spec.compile()
    if mjcf_out:
        mjcf_out.write_text(spec.to_xml())
    d = mujoco.MjData(m)
    # cost probe: a model whose steps are too slow to settle within the budget is not run
    # (settling takes 1e3-1e5 steps here)
    t0 = time.perf_counter()
    mujoco.mj_step(m, d, nstep=5)
    per_step = (time.perf_counter() - t0) / 5
    if per_step * min_steps > budget_s:
        return Result("mujoco", False, note=(
            f"not run: one step takes {per_step * 1e3:.0f} ms, {min_steps} steps would exceed "
            f"the {budget_s:.0f} s budget (--mujoco-budget)"))
    mujoco.mj_resetData(m, d)
    t0 = time.perf_counter()
    steps = 0
    batch = 10
    vmax = float("inf")
    while True:
        mujoco.mj_step(m, d, nstep=batch)
        steps += batch
        vmax = float(np.max(np.abs(d.qvel)))
        if vmax < vtol or not np.isfinite(vmax):
            break
        if time.perf_counter() - t0 > budget_s:
            break
    ms = (time.perf_counter() - t0) * 1e3
    mujoco.mj_forward(m, d)
    angles = {}
    for j in mech.joints:
        jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j.name)
        angles[j.name] = float(d.qpos[m.jnt_qposadr[jid]])
    # loop-joint angles from the body orientations, as the other tools report them
    for lj in mech.loops:
        rp = d.xmat[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, lj.parent)].reshape(3, 3)
        rc = d.xmat[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, lj.child)].reshape(3, 3)
        e1 = perp(lj.axis)
        e2 = np.cross(lj.axis, e1)
        ro, roc = rpy_matrix(lj.rpy), rpy_matrix(lj.child_rpy)
        h = rc @ roc @ e1
        angles[lj.name] = math.atan2((rp @ ro @ e2) @ h, (rp @ ro @ e1) @ h)
    energy = float(d.energy[0])  # gravity (about the world origin) + joint springs
    ok = vmax < vtol
    viol = float(np.max(np.abs(d.efc_pos[d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]))) \
        if mech.loops and d.nefc else 0.0
    note = "" if ok else (f"not settled in {budget_s:.0f} s budget: max|qvel| = {vmax:.1e}"
                          if np.isfinite(vmax) else "diverged")
    r = Result("mujoco", ok, angles, energy, f"{steps} steps", ms, note)
    r.extra = {"vmax": vmax, "sim_time": float(d.time), "loop_violation": viol,
               "timestep": timestep, "zeta": zeta}
    return r


# --------------------------------------------------------------------------------------
# Ladder closed form
# --------------------------------------------------------------------------------------


def ladder_closed_form(mech: Mech, n: int) -> Result:
    """Every loop k is a parallelogram (posts of equal length, rung level): its posts turn by
    theta_k about their hanging points, its rung and everything below translate by
    L (sin theta_k, -cos theta_k) (L = post length), so
        V_k(theta) = -|g| (m_L c_L + m_R c_R + L M_k) cos theta + k/2 (theta - ref)^2
    with c = post centre-of-mass distance from its pin and M_k = rung k + all lower loops.
    Each theta_k solves V_k'(theta) = 0 by Newton; hang_left = hang_right = close = theta,
    rung_pin = -theta. Needs gravity along -y and the generator's geometry."""
    t0 = time.perf_counter()
    g = float(np.linalg.norm(mech.gravity))
    angles = {}
    total = 0.0
    masses = {nm: lk.mass for nm, lk in mech.links.items()}
    jn = {j.name: j for j in mech.joints}
    for k in range(n):
        left, right, rung = f"left{k}", f"right{k}", f"rung{k}"
        length = -jn[f"rung_pin{k}"].xyz[1]
        cl, cr = -mech.links[left].com[1], -mech.links[right].com[1]
        below = masses[rung] + sum(masses[f"left{i}"] + masses[f"right{i}"] + masses[f"rung{i}"]
                                   for i in range(k + 1, n))
        a = g * (masses[left] * cl + masses[right] * cr + length * below)
        kk, ref = mech.springs[f"hang_left{k}"]
        th = 0.0
        for _ in range(50):
            f_ = a * math.sin(th) + kk * (th - ref)
            th -= f_ / (a * math.cos(th) + kk)
            if abs(f_) < 1e-15:
                break
        for nm in ("hang_left", "hang_right", "close"):
            angles[f"{nm}{k}"] = th
        angles[f"rung_pin{k}"] = -th
        total += 0.5 * kk * (th - ref) ** 2
    # gravity energy from the positions (y only; x does not matter with gravity along y)
    y0 = 0.0
    for k in range(n):
        th = angles[f"hang_left{k}"]
        length = -jn[f"rung_pin{k}"].xyz[1]
        for post in (f"left{k}", f"right{k}"):
            total += masses[post] * g * (y0 + mech.links[post].com[1] * math.cos(th))
        y0 -= length * math.cos(th)
        total += masses[f"rung{k}"] * g * (y0 + mech.links[f"rung{k}"].com[1])
    ms = (time.perf_counter() - t0) * 1e3
    return Result("closed form", True, angles, total, "—", ms)


# --------------------------------------------------------------------------------------
# Main
# --------------------------------------------------------------------------------------


def best_of(fn, repeats):
    """Run a peer; when it is fast (< 1 s) run it again up to `repeats` times in all and keep the
    shortest time (the first call also pays for warm-up)."""
    r = fn()
    for _ in range(repeats - 1):
        if not (r.ok and r.time_ms < 1000):
            break
        r2 = fn()
        if r2.time_ms < r.time_ms:
            r = r2
    return r


def fmt(x, spec):
    return "—" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def main():
    repo = Path(__file__).resolve().parents[2]
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--restpose", default=default_restpose(repo), help="restpose binary")
    ap.add_argument("--chain", default="10,100,1000", help="chain sizes (comma list, '' for none)")
    ap.add_argument("--ladder", default="5,10,50", help="ladder sizes (comma list, '' for none)")
    ap.add_argument("--tools", default="restpose,pinocchio,numpy,slsqp,mujoco,closed-form",
                    help="comma list of: restpose, pinocchio, numpy (joint-space Newton, trees), "
                    "slsqp, mujoco, closed-form (ladder)")
    ap.add_argument("--restpose-timeout", type=float, default=60.0,
                    help="skip a size when restpose analyze takes longer [s]")
    ap.add_argument("--repeats", type=int, default=3,
                    help="runs of each fast peer (< 1 s), shortest time kept")
    ap.add_argument("--restpose-repeats", type=int, default=10,
                    help="runs of restpose analyze (shortest kept; 3 over 200 ms, 1 over 2 s)")
    ap.add_argument("--restpose-bench", default=None, help=(
        "restpose's compiled bench harness (the `chain` binary that `cargo bench --bench chain "
        "--no-run` names, under target/release/deps/): gives restpose's in-process solve time; "
        "without it restpose's time is the whole `analyze` process"))
    ap.add_argument("--slsqp-max-bodies", type=int, default=150,
                    help="skip SLSQP above this many bodies (dense SQP: ~20 s at 100 bodies)")
    ap.add_argument("--mujoco-vtol", type=float, default=1e-8, help="settled when max|qvel| < this [rad/s]")
    ap.add_argument("--mujoco-budget", type=float, default=30.0, help="settling wall-time budget [s]")
    ap.add_argument("--mujoco-timestep", type=float, default=2e-3,
                    help="MuJoCo's default; also sets the loop constraints' solref time constant (2 steps)")
    ap.add_argument("--mujoco-zeta", type=float, default=1.0,
                    help="damping ratio of each sprung joint taken alone: c = 2 zeta sqrt(k M_ii)")
    ap.add_argument("--exact-tol", type=float, default=1e-6, help="agreement for exact solvers [rad]")
    ap.add_argument("--settle-tol", type=float, default=1e-5, help="agreement for MuJoCo settling [rad]")
    ap.add_argument("--markdown", type=Path, help="also write the Markdown table here")
    ap.add_argument("--json", type=Path, help="write all results as JSON here")
    ap.add_argument("--keep", type=Path, help="keep generated URDF/MJCF/JSON files in this folder")
    args = ap.parse_args()
    tools = set(args.tools.split(","))
    sizes = lambda s: [int(x) for x in s.split(",") if x.strip()]  # noqa: E731

    exe = args.restpose
    if not (Path(exe).is_file() and os.access(exe, os.X_OK)):
        sys.exit(f"restpose binary not found: {exe} (build it or pass --restpose PATH)")
    version = subprocess.run([exe, "--version"], capture_output=True, text=True).stdout.strip()
    log(f"restpose: {exe} ({version})")
    for nm, mod, err in (("pinocchio", pin, "PIN_ERROR"), ("mujoco", mujoco, "MUJOCO_ERROR"),
                         ("scipy", scipy, "SCIPY_ERROR")):
        log(f"{nm}: {mod.__version__ if mod else 'NOT AVAILABLE: ' + globals()[err]}")

    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="restpose-peers-"))
    work.mkdir(parents=True, exist_ok=True)
    if not args.keep:
        atexit.register(shutil.rmtree, work, ignore_errors=True)
    cases = [("chain", n) for n in sizes(args.chain)] + [("ladder", n) for n in sizes(args.ladder)]
    rows = []
    all_results = []
    for family, n in cases:
        text = subprocess.run([exe, "generate", family, "--size", str(n)], capture_output=True,
                              text=True, check=True).stdout
        urdf = work / f"{family}{n}.urdf"
        urdf.write_text(text)
        mech = parse_urdf(text)
        log(f"== {family} N={n}: {len(mech.links) - 1} bodies, {len(mech.joints)} joints, "
            f"{len(mech.loops)} loop joints")
        results = []
        if "restpose" in tools:
            log("  restpose ...")
            rr = run_restpose(exe, urdf, args.restpose_timeout, args.restpose_repeats)
            if args.restpose_bench and rr.ok and not rr.extra.get("json_time"):
                bt = restpose_bench_time(args.restpose_bench, family, n, 4 * args.restpose_timeout)
                if bt and bt[0] <= rr.extra["wall_ms"]:
                    rr.time_ms = bt[0]
                    rr.extra["time_basis"] = ("in-process solve, bench harness"
                                              + (f" ({bt[2]})" if bt[2] else ""))
                elif bt:  # the whole process was faster: the bench run was disturbed
                    rr.extra["time_basis"] = (f"process wall (bench harness said {bt[0]:.1f} ms, "
                                              "more than the whole process: noise)")
                if bt and bt[1] != rr.iterations:
                    rr.extra["time_basis"] += (f" (its solve took {bt[1]} iterations, the CLI's "
                                               f"{rr.iterations}: different builds?)")
                if not bt:
                    log(f"  (no {family} {n} row from --restpose-bench)")
            results.append(rr)
        if "pinocchio" in tools and not mech.loops:
            log("  pinocchio ...")
            results.append(best_of(lambda: solve_pinocchio(urdf, mech), args.repeats))
        if "numpy" in tools and not mech.loops:
            log("  numpy joint-space ...")
            results.append(best_of(lambda: solve_numpy_tree(mech), args.repeats))
        if "slsqp" in tools:
            log("  slsqp ...")
            results.append(best_of(lambda: solve_slsqp(mech, args.slsqp_max_bodies), args.repeats))
        if "mujoco" in tools:
            log("  mujoco ...")
            results.append(best_of(lambda: solve_mujoco(
                mech, args.mujoco_vtol, args.mujoco_budget, args.mujoco_timestep, args.mujoco_zeta,
                work / f"{family}{n}.xml" if args.keep else None), args.repeats))
        if "closed-form" in tools and family == "ladder":
            results.append(best_of(lambda: ladder_closed_form(mech, n), args.repeats))
        for r in results:
            log(f"  {r.tool}: ok={r.ok} V={r.energy:.12g} it={r.iterations} t={r.time_ms:.2f} ms {r.note}")
        ref = next((r for r in results if r.tool == "restpose" and r.ok and r.angles), None)
        # with no restpose result, compare with the first exact peer that converged, and say so
        fallback = next((r for r in results if r.tool in ("pinocchio", "numpy joint-space",
                                                          "closed form") and r.ok), None)
        for r in results:
            cmp_to = ref if ref is not None else fallback
            d, nj = (max_angle_diff(r.angles, cmp_to.angles) if cmp_to is not None and r.angles
                     and r is not cmp_to else (float("nan"), 0))
            de = r.energy - cmp_to.energy if cmp_to is not None and r is not cmp_to else float("nan")
            tol = args.settle_tol if r.tool == "mujoco" else args.exact_tol
            if r is cmp_to:
                verdict = "reference" if r is ref else "reference (no restpose result)"
            elif not r.angles:
                verdict = "—"
            elif cmp_to is None:
                verdict = "no reference"
            else:
                verdict = ("agrees" if d < tol else "DISAGREES") + f" (< {tol:g})"
                if not r.ok:
                    verdict += ", not converged"
                if cmp_to is not ref:
                    verdict += f" vs {cmp_to.tool}"
            ratio = (r.time_ms / ref.time_ms if ref is not None and ref.ok and r is not ref
                     and ref.time_ms > 0 else float("nan"))
            ratio_wall = (r.time_ms / ref.extra["wall_ms"] if ref is not None and ref.ok
                          and r is not ref else float("nan"))
            rows.append((family, n, r, d, de, verdict, ratio, ratio_wall, nj))
            all_results.append({"family": family, "n": n, "tool": r.tool, "ok": r.ok,
                                "energy": r.energy, "iterations": r.iterations,
                                "time_ms": r.time_ms, "max_dtheta": d, "dV": de,
                                "joints_compared": nj, "verdict": verdict, "ratio": ratio,
                                "ratio_process": ratio_wall,
                                "note": r.note, "extra": r.extra, "angles": r.angles})

    # ---- Markdown ----
    out = []
    built = time.strftime("%Y-%m-%d %H:%M", time.localtime(os.path.getmtime(exe)))
    bench_note = ""
    if args.restpose_bench:
        bench_note = (f", bench harness `{args.restpose_bench}` (built "
                      + time.strftime("%Y-%m-%d %H:%M", time.localtime(os.path.getmtime(args.restpose_bench)))
                      + ")")
    out.append(f"restpose: `{version}` (`{exe}`, built {built}{bench_note}); "
               f"Python {platform.python_version()}; numpy {np.__version__}"
               + (f"; scipy {scipy.__version__}" if scipy else "; scipy: not available")
               + (f"; pin (Pinocchio) {pin.__version__}" if pin else "; pin: not available")
               + (f"; mujoco {mujoco.__version__}" if mujoco else "; mujoco: not available") + ".")
    out.append("")
    out.append("| family | N | tool | converged | V [J] | ΔV [J] | max \\|Δθ\\| [rad] | agreement "
               "| iterations | time [ms] | ÷ restpose solve | ÷ restpose process | notes |")
    out.append("|---|---:|---|---|---:|---:|---:|---|---:|---:|---:|---:|---|")
    for family, n, r, d, de, verdict, ratio, ratio_wall, nj in rows:
        note = r.note
        if r.tool == "restpose" and "wall_ms" in r.extra:
            e = r.extra
            note = (f"time = {e['time_basis']}; `analyze` process wall {e['wall_ms']:.1f} ms "
                    f"(best of {e['runs']}); {e['stability']}"
                    + (f"; {r.note}" if r.note else ""))
        elif r.tool == "scipy SLSQP" and "violation" in r.extra:
            dropped = (f" ({r.extra['ncon'] - r.extra['nkept']} dependent rows dropped)"
                       if r.extra["nkept"] < r.extra["ncon"] else "")
            note = (f"{r.extra['nvar']} vars, {r.extra['ncon']} eq. rows{dropped}, ‖Φ‖∞ {r.extra['violation']:.0e}, "
                    f"KKT residual {r.extra['kkt']:.0e}" + (f"; {r.note}" if r.note else ""))
        elif r.tool == "mujoco" and "vmax" in r.extra:
            note = (f"sim time {r.extra['sim_time']:.2f} s, max\\|qvel\\| {r.extra['vmax']:.0e}"
                    + (f", loop violation {r.extra['loop_violation']:.0e}" if r.extra["loop_violation"] else "")
                    + (f"; {r.note}" if r.note else ""))
        elif r.tool in ("pinocchio", "numpy joint-space") and "gnorm" in r.extra:
            note = (f"max\\|∂V/∂θ\\| {r.extra['gnorm']:.0e}, {r.extra['halvings']} step halvings"
                    + (f"; {r.note}" if r.note else ""))
        out.append("| " + " | ".join([
            family, str(n), r.tool, "yes" if r.ok else "no",
            fmt(r.energy, ".9f"), fmt(de, ".1e"), fmt(d, ".1e"), verdict,
            r.iterations or "—", fmt(r.time_ms, ".2f"), fmt(ratio, ".3g"), fmt(ratio_wall, ".3g"),
            note]) + " |")
    table = "\n".join(out)
    print(table)
    if args.markdown:
        args.markdown.write_text(table + "\n")
    if args.json:
        args.json.write_text(json.dumps(all_results, indent=1, default=float))


if __name__ == "__main__":
    main()
