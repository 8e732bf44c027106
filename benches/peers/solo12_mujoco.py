#!/usr/bin/env python3
"""MuJoCo references for a URDF quadruped standing on the ground (issue 13 validation).

Reads the restpose input file itself (default robots/solo12/solo12_ground.urdf): the tree part
through MuJoCo's own URDF importer, and the statics extensions by this script: every
``mech:joint_spring`` (stiffness, reference), ``mech:initial``, the ``mech:ground`` plane and the
``mech:contact`` links, whose ``<collision><sphere>`` shapes are the feet. Two answers per
friction mode:

* ``settle``: damped dynamic simulation. The root link gets a free joint, the ground is a plane,
  joints get ``stiffness``/``springref`` = the springs and a damping, contact is stiff
  (``solref`` time constant, ``solimp``), frictionless (condim 1) or sticking (condim 3, high
  mu, no-slip solver). Start: the initial pose, lifted ``--lift`` above the touching height.
  Stepped until max |qvel| < ``--vtol``.
* ``rigid``: the rigid-contact static equilibrium of the same MuJoCo model, solved here by
  Newton on the KKT conditions: grad V(q) + J(q)^T lambda = 0, c(q) = 0, with V = gravity +
  springs (from MuJoCo's ``qfrc_bias`` at zero velocity and the joint stiffness), c the foot
  constraints (frictionless: sphere centre at height r above the plane; stick: sphere centre
  held at its initial position) and the neutral directions of the frictionless case (base x,
  y, yaw) pinned by three more rows whose multipliers must come out zero. The Hessian of the
  Lagrangian is a central finite difference of its gradient. This is the exact answer that a
  static solver such as restpose should reproduce; the damped simulation reaches it up to its
  contact penetration (and, with friction, the foot spheres' rolling: see
  docs/contact-validation.md).

Usage:
  python benches/peers/solo12_mujoco.py [URDF] [--friction none|stick|both] [--method
      settle|rigid|both] [--json OUT] ...
Prints one JSON object: {model, mujoco_version, runs: {"none": {settle, rigid}, "stick": ...}}.
Needs numpy and mujoco (benches/peers/requirements.txt).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

MECH = "{urn:urdf-mech:1}"
ROOT = Path(__file__).resolve().parents[2]
DEFAULT_URDF = ROOT / "robots/solo12/solo12_ground.urdf"


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def floats(s: str | None, n: int | None = None, default=None) -> list[float]:
    if s is None:
        return list(default)
    v = [float(x) for x in s.split()]
    if n is not None and len(v) != n:
        raise ValueError(f"expected {n} numbers, got {s!r}")
    return v


# ----------------------------------------------------------------------------------------
# The statics extensions, read from the file
# ----------------------------------------------------------------------------------------

@dataclass
class Foot:
    link: str
    radius: float
    offset: np.ndarray  # sphere centre in the link frame


@dataclass
class Statics:
    path: Path
    root_link: str
    springs: dict[str, tuple[float, float]] = field(default_factory=dict)  # joint -> (k, ref)
    initial: dict[str, float] = field(default_factory=dict)
    ground_point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    ground_normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    feet: list[Foot] = field(default_factory=list)
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))


def read_statics(path: Path) -> tuple[Statics, ET.ElementTree]:
    tree = ET.parse(path)
    robot = tree.getroot()
    links = {e.get("name"): e for e in robot.findall("link")}
    children = {j.find("child").get("link") for j in robot.findall("joint")}
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        raise SystemExit(f"{path}: expected one root link, found {roots}")
    st = Statics(path=path, root_link=roots[0])
    grounds = robot.findall(f"{MECH}ground")
    if len(grounds) != 1:
        raise SystemExit(f"{path}: this script handles exactly one <mech:ground>, found {len(grounds)}")
    st.ground_point = np.array(floats(grounds[0].get("xyz"), 3, [0, 0, 0]))
    n = np.array(floats(grounds[0].get("normal"), 3, [0, 0, 1]))
    st.ground_normal = n / np.linalg.norm(n)
    for g in robot.findall(f"{MECH}gravity"):
        st.gravity = np.array(floats(g.get("xyz"), 3))
    for s in robot.findall(f"{MECH}joint_spring"):
        if s.find(f"{MECH}force_deflection") is not None or float(s.get("preload", "0")) != 0.0:
            raise SystemExit(f"{path}: only linear joint springs without preload are handled")
        st.springs[s.get("joint")] = (float(s.get("stiffness")), float(s.get("reference", "0")))
    for i in robot.findall(f"{MECH}initial"):
        st.initial[i.get("joint")] = float(i.get("value"))
    contact_links = [c.get("link") for c in robot.findall(f"{MECH}contact")
                     if c.get("enabled", "true") != "false"]
    if not contact_links:
        raise SystemExit(f"{path}: no <mech:contact> links (this script does not guess them)")
    for ln in contact_links:
        spheres = []
        for col in links[ln].findall("collision"):
            sph = col.find("geometry/sphere")
            if sph is None:
                raise SystemExit(f"{path}: contact link {ln} has a non-sphere <collision>")
            o = col.find("origin")  # its rpy does not matter for a sphere
            spheres.append(Foot(ln, float(sph.get("radius")),
                                np.array(floats(o.get("xyz") if o is not None else None, 3, [0, 0, 0]))))
        if len(spheres) != 1:
            raise SystemExit(f"{path}: contact link {ln} needs exactly one sphere, has {len(spheres)}")
        st.feet += spheres
    return st, tree


# ----------------------------------------------------------------------------------------
# The MuJoCo model
# ----------------------------------------------------------------------------------------

@dataclass
class Params:
    friction: str  # "none" | "stick"
    timestep: float
    solref_tc: float
    solimp: tuple[float, float, float]
    mu: float
    noslip: int
    zeta: float
    base_damping: float
    lift: float


def vec3_param(cur, value):
    """MuJoCo 4 keeps joint stiffness/damping as arrays (polynomial terms), MuJoCo 3 as scalars."""
    if np.ndim(cur) == 0:
        return value
    out = np.zeros(len(cur))
    out[0] = value
    return out


def build(st: Statics, tree: ET.ElementTree, p: Params | None):
    """Compile the MuJoCo model. p = None: no contact (for the rigid KKT solve)."""
    robot = ET.fromstring(ET.tostring(tree.getroot()))
    for e in list(robot):
        if isinstance(e.tag, str) and e.tag.startswith(MECH):
            robot.remove(e)
    mj = ET.SubElement(robot, "mujoco")
    ET.SubElement(mj, "compiler", {"meshdir": str(st.path.parent), "strippath": "false",
                                   "discardvisual": "true", "fusestatic": "false",
                                   "balanceinertia": "true"})
    spec = mujoco.MjSpec.from_string(ET.tostring(robot, encoding="unicode"))
    spec.option.gravity = st.gravity
    base = spec.body(st.root_link)
    fj = base.add_freejoint()
    fj.name = "root_free"
    foot_links = {f.link for f in st.feet}
    for g in spec.geoms:  # only the feet collide (with discardvisual, MuJoCo drops the others)
        is_foot = g.type == mujoco.mjtGeom.mjGEOM_SPHERE and g.parent.name in foot_links
        g.contype = 1 if is_foot else 0
        g.conaffinity = 0
    if p is not None:
        spec.option.timestep = p.timestep
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
        spec.option.noslip_iterations = p.noslip if p.friction == "stick" else 0
        condim = 1 if p.friction == "none" else 3
        fr = [p.mu, 0.0, 0.0]
        floor = spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE,
                                        size=[0, 0, 1], pos=st.ground_point)
        z = np.array([0.0, 0.0, 1.0])
        n = st.ground_normal
        ax = np.cross(z, n)
        if np.linalg.norm(ax) > 1e-15:
            ang = math.atan2(np.linalg.norm(ax), z @ n)
            ax = ax / np.linalg.norm(ax)
            floor.quat = [math.cos(ang / 2), *(math.sin(ang / 2) * ax)]
        for g in (floor, *[g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_SPHERE
                           and g.parent.name in foot_links]):
            g.contype, g.conaffinity = (1, 0) if g is not floor else (0, 1)
            g.condim = condim
            g.friction = fr
            g.solref = [p.solref_tc, 1.0]
            g.solimp = [*p.solimp, 0.5, 2.0]
            g.margin = 0.0
        fj.damping = vec3_param(fj.damping, p.base_damping)
    for j in spec.joints:
        if j.name in st.springs:
            k, ref = st.springs[j.name]
            j.stiffness = vec3_param(j.stiffness, k)
            j.springref = ref
    m = spec.compile()
    return spec, m


def initial_qpos(m, st: Statics, lift: float) -> np.ndarray:
    q = m.qpos0.copy()
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "root_free")
    a = m.jnt_qposadr[jid]
    q[a:a + 3] = st.ground_normal * lift  # root at the world origin, as restpose starts it
    q[a + 3:a + 7] = [1, 0, 0, 0]
    for name, v in st.initial.items():
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j < 0:
            raise SystemExit(f"mech:initial names joint {name!r}, unknown to MuJoCo's import")
        q[m.jnt_qposadr[j]] = v
    return q


def foot_geom_ids(m, st: Statics) -> list[int]:
    ids = []
    for f in st.feet:
        b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f.link)
        gs = [g for g in range(m.ngeom) if m.geom_bodyid[g] == b
              and m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE]
        if len(gs) != 1 or abs(m.geom_size[gs[0], 0] - f.radius) > 1e-12:
            raise SystemExit(f"MuJoCo's import of {f.link}: expected one sphere of radius {f.radius}")
        ids.append(gs[0])
    return ids


def base_summary(m, d, st: Statics) -> dict:
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "root_free")
    a = m.jnt_qposadr[jid]
    pos = d.qpos[a:a + 3].copy()
    quat = d.qpos[a + 3:a + 7].copy()
    quat /= np.linalg.norm(quat)
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, quat)
    R = R.reshape(3, 3)
    roll = math.atan2(R[2, 1], R[2, 2])  # ZYX angles: roll and pitch depend on R's last row only,
    pitch = -math.asin(max(-1.0, min(1.0, R[2, 0])))  # so they are yaw-independent
    yaw = math.atan2(R[1, 0], R[0, 0])
    return {"position": pos.tolist(), "quaternion_wxyz": quat.tolist(),
            "height": float(st.ground_normal @ (pos - st.ground_point)),
            "roll": roll, "pitch": pitch, "yaw": yaw}


def joint_angles(m, d, st: Statics) -> dict:
    return {n: float(d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)]])
            for n in st.springs}


def sphere_centres(m, d, gids) -> np.ndarray:
    return np.array([d.geom_xpos[g].copy() for g in gids])


# ----------------------------------------------------------------------------------------
# Damped settling
# ----------------------------------------------------------------------------------------

def settle(st: Statics, tree, p: Params, vtol: float, budget: float) -> dict:
    spec, m = build(st, tree, p)
    d = mujoco.MjData(m)
    d.qpos[:] = initial_qpos(m, st, p.lift)
    mujoco.mj_forward(m, d)
    # Joint damping: each sprung joint critically damped (zeta) on its own, c = 2 zeta sqrt(k M_ii),
    # M_ii from the mass matrix at the initial pose. Damping does not move a static equilibrium.
    full = np.zeros((m.nv, m.nv))
    try:
        mujoco.mj_fullM(m, d, full)  # mujoco >= 4
    except TypeError:
        mujoco.mj_fullM(m, full, d.qM)  # mujoco 3
    for name, (k, _) in st.springs.items():
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        dof = m.jnt_dofadr[j]
        m.dof_damping[dof] = 2.0 * p.zeta * math.sqrt(k * full[dof, dof])
    gids = foot_geom_ids(m, st)
    start_centres = sphere_centres(m, d, gids)
    touchdown = [None] * len(gids)
    t0 = time.perf_counter()
    steps, vmax = 0, math.inf
    batch = 200
    while True:
        for _ in range(batch):
            mujoco.mj_step(m, d)
            for c in d.contact[:d.ncon]:
                for i, g in enumerate(gids):
                    if touchdown[i] is None and g in (c.geom1, c.geom2):
                        touchdown[i] = d.geom_xpos[g].copy()
        steps += batch
        vmax = float(np.max(np.abs(d.qvel)))
        wall = time.perf_counter() - t0
        if vmax < vtol and d.ncon >= 1 and steps * p.timestep > 0.5:
            break
        if wall > budget:
            break
    wall = time.perf_counter() - t0
    mujoco.mj_forward(m, d)
    feet = []
    f6 = np.zeros(6)
    total_normal = 0.0
    for i, (f, g) in enumerate(zip(st.feet, gids)):
        cs = [k for k, c in enumerate(d.contact[:d.ncon]) if g in (c.geom1, c.geom2)]
        fn, ft, pen = 0.0, np.zeros(3), 0.0
        for k in cs:
            mujoco.mj_contactForce(m, d, k, f6)
            c = d.contact[k]
            frame = c.frame.reshape(3, 3)  # rows: normal, tangent 1, tangent 2 (world)
            fn += f6[0]
            ft += f6[1] * frame[1] + f6[2] * frame[2]
            pen = max(pen, -c.dist)
        total_normal += fn
        centre = d.geom_xpos[g].copy()
        feet.append({"link": f.link, "contacts": len(cs), "normal_force": fn,
                     "tangential_force": float(np.linalg.norm(ft)),
                     "tangential_force_world": ft.tolist(),
                     "required_friction": float(np.linalg.norm(ft) / fn) if fn > 0 else None,
                     "penetration": pen, "centre_world": centre.tolist(),
                     "centre_start": start_centres[i].tolist(),
                     "centre_touchdown": None if touchdown[i] is None else touchdown[i].tolist()})
    weight = float(np.sum(m.body_mass) * np.linalg.norm(st.gravity))
    return {
        "settled": vmax < vtol, "max_qvel": vmax, "steps": steps, "sim_time": steps * p.timestep,
        "wall_time_s": wall, "base": base_summary(m, d, st), "joints": joint_angles(m, d, st),
        "feet": feet, "max_penetration": max(f["penetration"] for f in feet),
        "sum_normal_force": total_normal, "weight": weight,
        "params": {"friction": p.friction, "condim": 1 if p.friction == "none" else 3,
                   "timestep": p.timestep, "solref": [p.solref_tc, 1.0], "solimp": list(p.solimp),
                   "mu": p.mu if p.friction == "stick" else 0.0,
                   "noslip_iterations": p.noslip if p.friction == "stick" else 0,
                   "integrator": "implicitfast", "cone": "elliptic", "lift": p.lift,
                   "joint_damping_zeta": p.zeta, "base_damping": p.base_damping, "vtol": vtol},
    }


# ----------------------------------------------------------------------------------------
# Rigid contact: Newton on the KKT conditions with MuJoCo's kinematics
# ----------------------------------------------------------------------------------------

class Rigid:
    def __init__(self, st: Statics, tree, friction: str):
        self.st = st
        self.friction = friction
        _, self.m = build(st, tree, None)
        self.m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
        self.d = mujoco.MjData(self.m)
        self.gids = foot_geom_ids(self.m, st)
        fj = mujoco.mj_name2id(self.m, mujoco.mjtObj.mjOBJ_JOINT, "root_free")
        self.qa = self.m.jnt_qposadr[fj]
        self.da = self.m.jnt_dofadr[fj]
        q0 = initial_qpos(self.m, st, 0.0)
        self.eval(q0)
        self.anchor = sphere_centres(self.m, self.d, self.gids)  # stick: centres held here
        self.R0 = [self.d.geom_xmat[g].reshape(3, 3).copy() for g in self.gids]
        self.gaps0 = [float(st.ground_normal @ (c - st.ground_point)) - f.radius
                      for c, f in zip(self.anchor, st.feet)]
        self.pin = self.base_xy_yaw(q0)[0]
        self.Rb0 = self.base_xy_yaw(q0)[1]
        self.pb0 = q0[self.qa:self.qa + 3].copy()
        self.q0 = q0

    def eval(self, q):
        self.d.qpos[:] = q
        self.d.qvel[:] = 0
        mujoco.mj_forward(self.m, self.d)

    def base_xy_yaw(self, q):
        quat = q[self.qa + 3:self.qa + 7] / np.linalg.norm(q[self.qa + 3:self.qa + 7])
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, quat)
        R = R.reshape(3, 3)
        return np.array([q[self.qa], q[self.qa + 1], math.atan2(R[1, 0], R[0, 0])]), R

    def grad_v(self):
        # dV/dq in MuJoCo's tangent space: gravity (qfrc_bias at zero velocity) minus the
        # joint-stiffness passive force.
        return self.d.qfrc_bias - self.d.qfrc_spring if hasattr(self.d, "qfrc_spring") \
            else self.d.qfrc_bias - self.d.qfrc_passive

    def energy(self):
        v = 0.0
        for b in range(1, self.m.nbody):
            v -= self.m.body_mass[b] * (self.st.gravity @ self.d.xipos[b])
        for name, (k, ref) in self.st.springs.items():
            j = mujoco.mj_name2id(self.m, mujoco.mjtObj.mjOBJ_JOINT, name)
            v += 0.5 * k * (self.d.qpos[self.m.jnt_qposadr[j]] - ref) ** 2
        return v

    def cons(self, q):
        """Constraint residuals and Jacobian (rows x nv) at q (evaluates q)."""
        self.eval(q)
        m, d, st = self.m, self.d, self.st
        rows, jac = [], []
        jp = np.zeros((3, m.nv))
        jr = np.zeros((3, m.nv))
        if self.friction == "welded":  # base held at its initial pose, feet free: model check
            _, R = self.base_xy_yaw(q)
            psi = rotation_vector(R @ self.Rb0.T)
            rows = list(q[self.qa:self.qa + 3] - self.pb0) + list(psi)
            J = np.zeros((6, m.nv))
            J[0:3, self.da:self.da + 3] = np.eye(3)
            J[3:6, self.da + 3:self.da + 6] = inv_left_jacobian(psi) @ R  # local -> world rate
            return np.array(rows), J
        for i, (f, g) in enumerate(zip(st.feet, self.gids)):
            c = d.geom_xpos[g]
            mujoco.mj_jac(m, d, jp, jr, c, m.geom_bodyid[g])
            if self.friction == "none":
                rows.append(st.ground_normal @ (c - st.ground_point) - f.radius)
                jac.append(st.ground_normal @ jp)
            elif self.friction == "stick":
                rows += list(c - self.anchor[i])
                jac += list(jp.copy())
            elif self.friction == "stick-material":  # gap on the sphere; the material point
                n = st.ground_normal  # that touched (c0 - r n at touch) held tangentially
                R = d.geom_xmat[g].reshape(3, 3)
                pm = c + R @ (self.R0[i].T @ (-f.radius * n))
                jpm = np.zeros((3, m.nv))
                mujoco.mj_jac(m, d, jpm, None, pm, m.geom_bodyid[g])
                rows.append(n @ (c - st.ground_point) - f.radius)
                jac.append(n @ jp)
                for t in plane_basis(n):
                    rows.append(t @ (pm - (self.anchor[i] - f.radius * n)))
                    jac.append(t @ jpm)
            else:  # stick-rolling: c - c0 = r psi x n, psi the foot's rotation vector (world)
                n = st.ground_normal
                psi = rotation_vector(d.geom_xmat[g].reshape(3, 3) @ self.R0[i].T)
                rows += list(c - self.anchor[i] - f.radius * np.cross(psi, n))
                dpsi = inv_left_jacobian(psi) @ jr  # d psi = J_l(psi)^-1 omega (world frame)
                jac += list(jp - f.radius * np.cross(dpsi.T, n).T)
        if self.friction == "none":  # neutral directions pinned: base x, y (world) and yaw
            xyy, R = self.base_xy_yaw(q)
            r = xyy - self.pin
            r[2] = (r[2] + math.pi) % (2 * math.pi) - math.pi
            for k in range(2):
                row = np.zeros(m.nv)
                row[self.da + k] = 1.0
                rows.append(r[k])
                jac.append(row)
            row = np.zeros(m.nv)
            row[self.da + 3:self.da + 6] = R[2, :]  # world-z component of the local angular rate
            rows.append(r[2])
            jac.append(row)
        return np.array(rows), np.array(jac)

    def lag_grad(self, q, lam):
        c, J = self.cons(q)
        return self.grad_v() + J.T @ lam, c, J

    def step_q(self, q, dv):
        q2 = q.copy()
        mujoco.mj_integratePos(self.m, q2, dv, 1.0)
        return q2

    def fd_check(self, q, h=1e-6) -> tuple[float, float]:
        """Analytic constraint Jacobian and energy gradient against central differences."""
        nv = self.m.nv
        _, J = self.cons(q)
        g = self.grad_v().copy()
        jerr, gerr = 0.0, 0.0
        for k in range(nv):
            e = np.zeros(nv)
            e[k] = h
            cp, _ = self.cons(self.step_q(q, e))
            vp = self.energy()
            cm, _ = self.cons(self.step_q(q, -e))
            vm = self.energy()
            jerr = max(jerr, float(np.max(np.abs((cp - cm) / (2 * h) - J[:, k]))))
            gerr = max(gerr, abs((vp - vm) / (2 * h) - g[k]))
        return jerr, gerr

    def solve(self, tol=1e-10, max_iter=60) -> dict:
        t0 = time.perf_counter()
        q = self.q0.copy()
        nv = self.m.nv
        c, J = self.cons(q)
        lam = np.zeros(len(c))
        h = 1e-6
        history = []
        for it in range(max_iter):
            g, c, J = self.lag_grad(q, lam)
            res = max(np.max(np.abs(g)), np.max(np.abs(c)))
            history.append(res)
            if res < tol:
                break
            H = np.zeros((nv, nv))
            for k in range(nv):
                e = np.zeros(nv)
                e[k] = h
                gp, _, _ = self.lag_grad(self.step_q(q, e), lam)
                gm, _, _ = self.lag_grad(self.step_q(q, -e), lam)
                H[:, k] = (gp - gm) / (2 * h)
            H = 0.5 * (H + H.T)
            nc = len(c)
            K = np.block([[H, J.T], [J, np.zeros((nc, nc))]])
            sol = np.linalg.lstsq(K, -np.concatenate([g, c]), rcond=None)[0]
            dv, dlam = sol[:nv], sol[nv:]
            q = self.step_q(q, dv)
            lam = lam + dlam
        g, c, J = self.lag_grad(q, lam)
        # Reduced Hessian on the tangent space of the constraints: stability.
        H = np.zeros((nv, nv))
        for k in range(nv):
            e = np.zeros(nv)
            e[k] = h
            gp, _, _ = self.lag_grad(self.step_q(q, e), lam)
            gm, _, _ = self.lag_grad(self.step_q(q, -e), lam)
            H[:, k] = (gp - gm) / (2 * h)
        H = 0.5 * (H + H.T)
        _, s, vt = np.linalg.svd(J)
        rank = int(np.sum(s > 1e-10 * s[0]))
        Z = vt[rank:].T
        eig = np.linalg.eigvalsh(Z.T @ H @ Z) if Z.shape[1] else np.array([])
        wall = time.perf_counter() - t0
        jac_err, grad_err = self.fd_check(q)
        self.eval(q)
        feet = []
        total = 0.0
        nf = len(self.st.feet)
        for i, f in enumerate(self.st.feet):
            if self.friction == "welded":
                break
            if self.friction == "none":
                fn, ftv = -lam[i], np.zeros(3)
            else:  # force of the ground on the foot, world
                B = np.vstack([self.st.ground_normal, *plane_basis(self.st.ground_normal)]) \
                    if self.friction == "stick-material" else np.eye(3)
                fw = -B.T @ lam[3 * i:3 * i + 3]
                fn = float(self.st.ground_normal @ fw)
                ftv = fw - fn * self.st.ground_normal
            total += fn
            feet.append({"link": f.link, "normal_force": float(fn),
                         "tangential_force": float(np.linalg.norm(ftv)),
                         "tangential_force_world": ftv.tolist(),
                         "required_friction": float(np.linalg.norm(ftv) / fn) if fn > 0 else None,
                         "centre_world": self.d.geom_xpos[self.gids[i]].tolist(),
                         "initial_gap": self.gaps0[i]})
        pins = lam[nf:].tolist() if self.friction == "none" else []
        return {"converged": bool(history[-1] < tol), "iterations": len(history) - 1,
                "kkt_residual": float(max(np.max(np.abs(g)), np.max(np.abs(c)))),
                "wall_time_s": wall, "base": base_summary(self.m, self.d, self.st),
                "joints": joint_angles(self.m, self.d, self.st), "feet": feet,
                "sum_normal_force": total, "potential_energy": self.energy(),
                "pin_multipliers_x_y_yaw": pins,
                "reduced_hessian_min_eig": float(eig.min()) if eig.size else None,
                "fd_check": {"constraint_jacobian_max_abs_error": jac_err,
                             "energy_gradient_max_abs_error": grad_err},
                "constraint_rank": rank}


def plane_basis(n: np.ndarray) -> list[np.ndarray]:
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    return [t1, np.cross(n, t1)]


def rotation_vector(R: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, R.reshape(9))
    if q[0] < 0:
        q = -q
    s = np.linalg.norm(q[1:])
    return np.zeros(3) if s < 1e-300 else 2.0 * math.atan2(s, q[0]) * q[1:] / s


def inv_left_jacobian(psi: np.ndarray) -> np.ndarray:
    """Inverse left Jacobian of SO(3): psi' = J_l(psi)^-1 omega for R = exp([psi]x), R' = [omega]x R."""
    th = float(np.linalg.norm(psi))
    K = np.array([[0, -psi[2], psi[1]], [psi[2], 0, -psi[0]], [-psi[1], psi[0], 0]])
    if th < 1e-8:
        return np.eye(3) - 0.5 * K + K @ K / 12.0
    return np.eye(3) - 0.5 * K + (1 / th**2 - (1 + math.cos(th)) / (2 * th * math.sin(th))) * K @ K


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("urdf", nargs="?", default=str(DEFAULT_URDF))
    ap.add_argument("--friction", choices=["none", "stick", "both"], default="both")
    ap.add_argument("--method", choices=["settle", "rigid", "both"], default="both")
    ap.add_argument("--timestep", type=float, default=2.5e-4, help="[s]")
    ap.add_argument("--solref-tc", type=float, default=2e-3,
                    help="contact solref time constant [s] (MuJoCo wants >= 2 timesteps)")
    ap.add_argument("--solimp", type=float, nargs=3, default=[0.99, 0.999, 0.001],
                    help="contact solimp dmin dmax width")
    ap.add_argument("--mu", type=float, default=5.0, help="friction coefficient, stick runs")
    ap.add_argument("--noslip", type=int, default=50, help="noslip_iterations, stick runs")
    ap.add_argument("--zeta", type=float, default=1.0, help="joint damping ratio")
    ap.add_argument("--base-damping", type=float, default=5.0,
                    help="damping on the 6 free-joint dofs [N s/m, N m s/rad]: settles the "
                         "neutral slide and yaw of the frictionless case")
    ap.add_argument("--lift", type=float, default=1e-4, help="start this far above touching [m]")
    ap.add_argument("--vtol", type=float, default=1e-6, help="settled: max|qvel| below this")
    ap.add_argument("--budget", type=float, default=120.0, help="wall-time budget per run [s]")
    ap.add_argument("--welded", action="store_true",
                    help="also solve with the base welded and no contact (runs.welded.rigid): checks "
                         "that MuJoCo's import and restpose's agree on the model, contact aside")
    ap.add_argument("--json", help="also write the JSON here")
    a = ap.parse_args()

    st, tree = read_statics(Path(a.urdf))
    out = {"model": str(a.urdf), "mujoco_version": mujoco.__version__, "runs": {}}
    modes = ["none", "stick"] if a.friction == "both" else [a.friction]
    for fr in modes:
        run = {}
        if a.method in ("rigid", "both"):
            log(f"rigid KKT, friction {fr} ...")
            run["rigid"] = Rigid(st, tree, fr).solve()
            if fr == "stick":
                log("rigid KKT, friction stick with rolling feet ...")
                run["rigid_rolling"] = Rigid(st, tree, "stick-rolling").solve()
                log("rigid KKT, friction stick, material contact point held ...")
                run["rigid_material"] = Rigid(st, tree, "stick-material").solve()
        if a.method in ("settle", "both"):
            log(f"settling, friction {fr} ...")
            p = Params(fr, a.timestep, a.solref_tc, tuple(a.solimp), a.mu, a.noslip, a.zeta,
                       a.base_damping, a.lift)
            run["settle"] = settle(st, tree, p, a.vtol, a.budget)
        out["runs"][fr] = run
    if a.welded:
        log("rigid KKT, base welded, no contact ...")
        out["runs"]["welded"] = {"rigid": Rigid(st, tree, "welded").solve()}
    text = json.dumps(out, indent=1)
    print(text)
    if a.json:
        Path(a.json).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
