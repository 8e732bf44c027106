"""Which rest does a hanging robot reach? A reference independent of restpose: the quasi-static
release, a projected gradient flow in joint coordinates with the joint stops as clamps,
integrated finely with Pinocchio from restpose's start.

A robot released from its start and damped so heavily that inertia plays no part follows the
gradient flow of its gravity energy `V(x)` in the joint coordinates `x`, its stops holding it
where they push back:

    W ẋ = −∇V(x) + λ,   λ_i ≥ 0 pushing back only where joint i is on its stop,

where `W` is the damping metric. Two are integrated and reported:
  - `identity`: uniform viscous damping at every joint (W = I; rad and m weighted alike);
  - `mass`: damping proportional to the mass matrix (W = M(x) + 1e-4 max diag(M) I, Rayleigh
    damping: the overdamped limit of the dynamics M ẍ + c M ẋ = −∇V; regularized because M
    is singular on some robots).
They are different flows and may reach different rests: both are printed.

Integration: projected linearly implicit Euler (the time-stepping of a constrained gradient
flow): each step solves the box-constrained quadratic program (the stops are bounds on the
joint coordinates; a mimic joint's stop bounds its master)

    min_Δ  ½ Δᵀ (W/h + K₊) Δ + ∇Vᵀ Δ   subject to  lo ≤ x + Δ ≤ hi,

by projected Newton iterations; `K₊` is `K = ∂²V/∂x²` (Pinocchio's
`computeGeneralizedGravityDerivatives`) with its negative curvature in the metric W set to 0
(taken explicitly). h is chosen so that no joint moves by more than `--delta` (rad; a tenth of
it in m for prismatic joints) per step and the energy never rises. Stiff directions then follow
their slow manifold (the implicit step) and the path is resolved to `delta` everywhere; as the
flow comes to rest h grows and the step becomes the projected Newton step, which converges.
The rest is reported where the projected gradient (the velocity of the identity flow: ∇V less
its components pushing into the stops) is below 1e-9 in every joint.

The start is restpose's assembled start (`analyze --max-iterations 0` of the binary given by
`--start`, default the first `--restpose`: restpose moves the joints whose 0 lies outside their
limits onto the stop by its corrector, which moves neighbouring joints slightly too). Without a
binary: every joint at 0 (a continuous joint at angle 0), moved onto its stop
where 0 lies outside the limits; a mimic joint is `k x_master + offset` and its own limits are
stops on that combination (as in restpose). Stops: every revolute and prismatic joint with
`<limit>` (Pinocchio's lower/upper position limits, as urdfdom reads them).

Usage:
  python scripts/flow_oracle.py [--metric identity|mass|both|none] [--delta 0.01]
      [--restpose BIN ...] [--start BIN] [--policy LIMIT ...] [--json FILE] [ROBOT ...]
ROBOT: URDF file names without `.urdf` (default: every hanging robot of the corpus). With
`--restpose`, each binary solves the same robot (`analyze --load-steps 1`) and its energy is
compared with the flows' (`match` when equal to 1e-6 J). `--policy LIMIT` also runs the
projected Newton prototype (function `projected_newton`) with that step limit [rad]. A summary
per solver ends the output (iterations, robots in ≤ 30, robots at each flow's rest).
Environment: ERD_ROBOTS (the corpus's robots folder). Runs with the venv of
scripts/peers_venv.sh (pin 4.1.0): the whole corpus with both flows and two binaries takes about
10 minutes on a loaded 2-core machine (docs/method.md, "Which rest").
"""

import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

ERD = os.environ.get(
    "ERD_ROBOTS",
    os.path.expanduser("~/.cache/restpose-corpus/unpacked-6.0.0/cmeel.prefix/share/"
                       "example-robot-data/robots"))
GRADIENT_TOL = 1e-9
REJECTED = {"ur_description/urdf/ur3.urdf"}


class Robot:
    """A fixed-base robot in reduced joint coordinates x (mimic joints eliminated)."""

    def __init__(self, urdf):
        self.model = pin.buildModelFromUrdf(urdf)
        self.data = self.model.createData()
        m = self.model
        root = ET.fromstring(open(urdf, "rb").read().lstrip())
        mimic = {}
        types = {}
        for j in root.findall("joint"):  # not the <joint> of a <transmission>
            types[j.get("name")] = j.get("type")
            e = j.find("mimic")
            if e is not None:
                mimic[j.get("name")] = (e.get("joint"), float(e.get("multiplier", "1")),
                                        float(e.get("offset", "0")))
        # Reduced coordinates: one per non-mimic velocity index.
        self.names = [m.names[i] for i in range(1, m.njoints)]
        free = []
        for i in range(1, m.njoints):
            if m.names[i] not in mimic:
                free.extend(range(m.joints[i].idx_v, m.joints[i].idx_v + m.joints[i].nv))
        col = {v: k for k, v in enumerate(free)}
        self.nx = len(free)
        T = np.zeros((m.nv, self.nx))
        for v, k in col.items():
            T[v, k] = 1.0
        offsets = np.zeros(m.nv)
        for name, (master, k, off) in mimic.items():
            if not (m.existJointName(name) and m.existJointName(master)):
                continue
            a, b = m.joints[m.getJointId(name)], m.joints[m.getJointId(master)]
            T[a.idx_v, col[b.idx_v]] = k
            offsets[a.idx_v] = off
        self.T = T
        # Stops: rows t·v_full over 1-dof joints with nq = 1 (revolute, prismatic) and limits.
        self.stops = []  # (name, velocity index, lower, upper, prismatic)
        for i in range(1, m.njoints):
            jm = m.joints[i]
            name = m.names[i]
            if jm.nq != 1 or jm.nv != 1 or types.get(name) not in ("revolute", "prismatic"):
                continue
            lo, hi = m.lowerPositionLimit[jm.idx_q], m.upperPositionLimit[jm.idx_q]
            if np.isfinite(lo) and np.isfinite(hi) and lo <= hi and max(abs(lo), abs(hi)) < 1e9:
                self.stops.append((name, jm.idx_q, jm.idx_v, lo, hi, types[name] == "prismatic"))
        self.prismatic = np.array([
            any(s[2] == v and s[5] for s in self.stops) or
            any(m.joints[i].idx_v == v and types.get(m.names[i]) == "prismatic"
                for i in range(1, m.njoints))
            for v in free])
        # Start: 0 (neutral), mimic offsets, then onto the stops it violates.
        q = pin.neutral(m)
        for i in range(1, m.njoints):
            jm = m.joints[i]
            if jm.nq == 1 and m.names[i] in mimic:
                q[jm.idx_q] = offsets[jm.idx_v]
        x_shift = np.zeros(self.nx)
        for name, iq, iv, lo, hi, _ in self.stops:
            if iv in col:
                val = q[iq]
                x_shift[col[iv]] = min(max(val, lo), hi) - val
        self.q = pin.integrate(m, q, T @ x_shift)

    def box(self, q):
        """The stops as bounds on the step Δx: a stop on joint value v = k x_j + offset bounds
        x_j (a mimic joint's stop bounds its master). lo ≤ 0 ≤ hi; a bound reached is 0."""
        lo = np.full(self.nx, -np.inf)
        hi = np.full(self.nx, np.inf)
        for (name, iq, iv, a, b, _) in self.stops:
            j = np.flatnonzero(self.T[iv])
            if j.size != 1:
                continue
            j, k = j[0], self.T[iv, j[0]]
            v = q[iq]
            l, u = sorted(((a - v) / k, (b - v) / k))
            lo[j] = max(lo[j], min(l, 0.0))
            hi[j] = min(hi[j], max(u, 0.0))
        lo[np.abs(lo) < 1e-12] = 0.0
        hi[np.abs(hi) < 1e-12] = 0.0
        return lo, hi

    def energy(self, q):
        return pin.computePotentialEnergy(self.model, self.data, q)

    def derivatives(self, q):
        g = pin.computeGeneralizedGravity(self.model, self.data, q).copy()
        K = pin.computeGeneralizedGravityDerivatives(self.model, self.data, q).copy()
        M = pin.crba(self.model, self.data, q).copy()
        M = np.triu(M) + np.triu(M, 1).T
        T = self.T
        K = T.T @ K @ T
        return T.T @ g, 0.5 * (K + K.T), T.T @ M @ T


def qp(W, c, lo, hi, max_iter=200):
    """min ½ pᵀWp + cᵀp subject to lo ≤ p ≤ hi (lo ≤ 0 ≤ hi), W positive definite, by projected
    Newton iterations (Bertsekas 1982): the coordinates at a bound whose gradient pushes out are
    held, the Newton step is taken in the others, projected on the box, halved until Armijo's
    condition holds. Returns p and the held coordinates."""
    n = W.shape[0]
    p = np.zeros(n)
    scale = np.max(np.abs(np.clip(np.linalg.solve(W, c), lo, hi)), initial=0.0)

    def f(x):
        return 0.5 * x @ W @ x + c @ x

    for _ in range(max_iter):
        grad = W @ p + c
        eps = 1e-12 * scale
        held = ((p <= lo + eps) & (grad > 0)) | ((p >= hi - eps) & (grad < 0))
        F = ~held
        d = np.zeros(n)
        if F.any():
            d[F] = -np.linalg.solve(W[np.ix_(F, F)], grad[F])
        t, f0 = 1.0, f(p)
        while True:
            pn = np.clip(p + t * d, lo, hi)
            if f(pn) <= f0 + 1e-4 * grad @ (pn - p) or t < 1e-12:
                break
            t *= 0.5
        done = np.max(np.abs(pn - p), initial=0.0) <= 1e-14 * np.max(np.abs(pn), initial=0.0)
        p = pn
        if done:
            return p, held
    return p, held  # feasible and lower than p = 0: a step all the same


def positive_part(K, Wm):
    """K with the negative eigenvalues of the pencil (K, Wm) set to 0."""
    L = np.linalg.cholesky(Wm)
    Li = np.linalg.inv(L)
    lam, U = np.linalg.eigh(Li @ K @ Li.T)
    B = L @ U
    return (B * np.maximum(lam, 0.0)) @ B.T


def flow(robot, metric, delta, max_steps=30000):
    """Integrate the projected flow to rest: (q, energy, active stops, steps, note)."""
    m = robot.model
    q = robot.q.copy()
    limit = np.where(robot.prismatic, 0.1 * delta, delta)
    h = 1e-6
    V = robot.energy(q)
    steps = 0
    while steps < max_steps:
        g, K, M = robot.derivatives(q)
        # (M can be singular: iCub's neck yaw and roll meet without a mass between them and its
        # M has an eigenvalue of 3.5e-18; regularized by 1e-4 of the largest diagonal entry)
        Wm = (np.eye(robot.nx) if metric == "identity"
              else M + 1e-4 * np.max(np.diag(M), initial=1.0) * np.eye(robot.nx))
        lo, hi = robot.box(q)
        # At rest: the projected gradient (the flow's velocity in the identity metric) vanishes.
        pg = np.where(((lo >= 0) & (g > 0)) | ((hi <= 0) & (g < 0)), 0.0, g)
        if np.max(np.abs(pg), initial=0.0) < GRADIENT_TOL:
            return q, V, active(robot, q), steps, "rest"
        # Negative curvature is taken explicitly (K₊: K with its negative eigenvalues in the
        # metric W set to 0), so that every step's matrix is positive definite.
        Kp = positive_part(K, Wm)
        while True:
            W = Wm / h + Kp
            p, _ = qp(W, g, lo, hi)
            over = np.max(np.abs(p) / limit, initial=0.0)
            if over > 1.0:
                h *= 0.5 / over
                continue
            qn = pin.integrate(m, q, robot.T @ p)
            Vn = robot.energy(qn)
            if Vn > V + 1e-13 * (1 + abs(V)):
                h *= 0.25
                if h < 1e-30:
                    return q, V, active(robot, q), steps, "energy cannot fall"
                continue
            break
        steps += 1
        q, V = qn, Vn
        if over < 0.5:
            h = min(2.0 * h, 1e15)
    return q, V, active(robot, q), steps, "max_steps"


def projected_newton(robot, max_step, max_iter=500):
    """A step policy measured against the flow: projected Newton (Bertsekas 1982) in joint
    coordinates. Every joint within ε of a stop that the gradient pushes into is held, the
    Newton step is taken in the others (eigenvalues by magnitude, floored at 1e-12 of the
    largest, as restpose's dense step), scaled as a whole to at most `max_step` in every joint,
    and the energy is searched along the projection arc x(t) = P(x + t d) (Armijo, halving):
    every stop the step reaches is met in the same iteration. Returns as `flow`."""
    m = robot.model
    q = robot.q.copy()
    V = robot.energy(q)
    for it in range(max_iter):
        g, K, _ = robot.derivatives(q)
        lo, hi = robot.box(q)
        pg = np.where(((lo >= 0) & (g > 0)) | ((hi <= 0) & (g < 0)), 0.0, g)
        if np.max(np.abs(pg), initial=0.0) < GRADIENT_TOL:
            return q, V, active(robot, q), it, "rest"
        eps = min(1e-3, np.max(np.abs(np.clip(-g, lo, hi)), initial=0.0))
        held = ((lo >= -eps) & (g > 0)) | ((hi <= eps) & (g < 0))
        F = ~held
        d = np.zeros(robot.nx)
        if F.any():
            lam, U = np.linalg.eigh(K[np.ix_(F, F)])
            big = np.max(np.abs(lam), initial=0.0)
            d[F] = -U @ ((U.T @ g[F]) / np.maximum(np.abs(lam), 1e-12 * big + 1e-300))
        # A held joint within ε of its stop goes onto it (Bertsekas' projection of its
        # gradient step; left where it is, it never reaches the stop and the search stalls).
        d[held] = np.where(g[held] > 0, lo[held], hi[held])
        long = np.max(np.abs(d), initial=0.0)
        if long > max_step:
            d *= max_step / long
        t = 1.0
        while True:
            x = np.clip(t * d, lo, hi)
            qn = pin.integrate(m, q, robot.T @ x)
            Vn = robot.energy(qn)
            if Vn <= V + 1e-4 * (g @ x) + 1e-13 * (1 + abs(V)):
                break
            t *= 0.5
            if t < 1e-20:
                return q, V, active(robot, q), it, "line search failed"
        q, V = qn, Vn
    return q, V, active(robot, q), max_iter, "max_iterations"


def active(robot, q, tol=1e-9):
    out = []
    for (name, iq, _, lo, hi, _) in robot.stops:
        if q[iq] <= lo + tol:
            out.append(name + "-")
        elif q[iq] >= hi - tol:
            out.append(name + "+")
    return out


def restpose(binary, urdf, extra=()):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "r.json")
        subprocess.run([binary, "analyze", "-q", urdf, "--load-steps", "1", "--json", out,
                        "--package", f"example-robot-data={ERD}/..", *extra],
                       capture_output=True, text=True, timeout=600)
        if not os.path.exists(out):
            return None
        return json.load(open(out))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--metric", default="both", choices=["identity", "mass", "both", "none"])
    ap.add_argument("--delta", type=float, default=0.01)
    ap.add_argument("--restpose", action="append", default=[])
    ap.add_argument("--start", help="restpose binary whose assembled start (--max-iterations 0) "
                    "the flows start from (default: the first --restpose; else 0 clamped)")
    ap.add_argument("--json")
    ap.add_argument("--policy", type=float, action="append", default=[],
                    help="also run the projected Newton policy with this step limit [rad]")
    ap.add_argument("robots", nargs="*")
    a = ap.parse_args()
    metrics = {"both": ["identity", "mass"], "none": []}.get(a.metric, [a.metric])
    rows = []
    for f in sorted(glob.glob(f"{ERD}/**/*.urdf", recursive=True)):
        rel = os.path.relpath(f, ERD)
        name = os.path.basename(f)[:-5]
        if rel in REJECTED or "restpose-springs" in f:
            continue
        if a.robots and name not in a.robots and rel not in a.robots:
            continue
        robot = Robot(f)
        start = a.start or (a.restpose[0] if a.restpose else None)
        if start:
            r0 = restpose(start, f, ["--max-iterations", "0"])
            q0 = np.array(r0["q_pinocchio"], dtype=float) if r0 else None
            if q0 is None or q0.size != robot.model.nq:
                print(f"{rel}: no start from {start}", flush=True)
                continue
            robot.q = q0
        row = {"robot": rel, "start_energy": robot.energy(robot.q), "flows": {}, "restpose": {}}
        for metric in metrics:
            try:
                q, V, act, steps, note = flow(robot, metric, a.delta)
            except (np.linalg.LinAlgError, RuntimeError) as e:
                q, V, act, steps, note = robot.q, float("nan"), [], 0, f"error: {e}"
            row["flows"][metric] = {"energy": V, "active": act, "steps": steps, "end": note,
                                    "q": q.tolist()}
        for lim in a.policy:
            q, V, act, steps, note = projected_newton(robot, lim)
            row["flows"][f"pn{lim:g}"] = {"energy": V, "active": act, "steps": steps,
                                          "end": note, "q": q.tolist()}
        for b in a.restpose:
            r = restpose(b, f)
            row["restpose"][b] = (None if r is None else {
                "energy": r["energy"]["total"], "iterations": r["iterations"],
                "termination": r["termination"],
                "active": sorted(x["joint"] + ("-" if x["bound"] == "lower" else "+")
                                 for x in r.get("active_limits", []))})
        rows.append(row)
        print(report(row), flush=True)
    if a.json:
        json.dump(rows, open(a.json, "w"), indent=1)
    print(summary(rows))


def summary(rows):
    """Per solver (restpose binaries, policies): iterations in all, robots in ≤ 30, robots at
    the rest of each flow (energy within 1e-6 J)."""
    solvers = {}
    for row in rows:
        for b, r in row["restpose"].items():
            if r is not None:
                solvers.setdefault(os.path.basename(b), []).append(
                    (row, r["energy"], r["iterations"], r["termination"] == "converged"))
        for name, fl in row["flows"].items():
            if name.startswith("pn"):
                solvers.setdefault(name, []).append(
                    (row, fl["energy"], fl["steps"], fl["end"] == "rest"))
    metrics = [m for m in ("identity", "mass") if rows and m in rows[0]["flows"]]
    out = []
    for name, xs in solvers.items():
        its = [x[2] for x in xs if x[3]]
        line = (f"{name:20s} {len(xs)} robots, {len(its)} converged, {sum(its)} iterations, "
                f"{sum(1 for i in its if i <= 30)} in <= 30")
        for m in metrics:
            done = [x for x in xs if m in x[0]["flows"] and x[0]["flows"][m]["end"] == "rest"]
            same = sum(1 for x in done if abs(x[1] - x[0]["flows"][m]["energy"]) <= 1e-6)
            low = sum(1 for x in done if x[1] < x[0]["flows"][m]["energy"] - 1e-6)
            line += f"; {m} flow: {same}/{len(done)} at its rest, {low} lower"
        out.append(line)
    return "\n".join(out)


def report(row):
    parts = [f"{row['robot']:52s} V0={row['start_energy']:.6f}"]
    for metric, fl in row["flows"].items():
        parts.append(f"{metric}: V={fl['energy']:.10f} {fl['end']} {fl['steps']} steps, "
                     f"{len(fl['active'])} stops")
    for b, r in row["restpose"].items():
        if r is None:
            parts.append(f"{os.path.basename(b)}: error")
            continue
        match = ",".join(m for m, fl in row["flows"].items()
                         if abs(fl["energy"] - r["energy"]) <= 1e-6
                         and m in ("identity", "mass")) or "none"
        parts.append(f"{os.path.basename(b)}: {r['termination']} it={r['iterations']} "
                     f"V={r['energy']:.10f} match={match}")
    return "\n    ".join(parts)


if __name__ == "__main__":
    sys.exit(main())
