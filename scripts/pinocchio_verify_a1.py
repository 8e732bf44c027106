#!/usr/bin/env python3
"""Independent check of `restpose verify` on a floating base standing on the ground (issue 21).

Reads a restpose result JSON (base pose, joint values, contact points) of a robot on the
ground, and computes with Pinocchio the efforts and contact forces that hold that pose:

    g(q) = J_cᵀ λ + [0₆; τ]

(g the generalized gravity, J_c the normal rows of the contact points, the base's six
coordinates unactuated). The base rows fix λ up to the self-equilibrated combinations of the
contacts; printed are the least-norm λ (what `analyze --lock` reports) and the λ of least
efforts ‖τ‖ (what `verify` reports for a pose no lock holds), each with its efforts τ.

usage: pinocchio_verify_a1.py ROBOT.urdf RESULT.json
"""
import json
import sys

import numpy as np
import pinocchio as pin


def main(urdf, result):
    res = json.load(open(result))
    model = pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())
    data = model.createData()
    root = model.frames[model.getFrameId(model.names[1])].name if False else None
    # The root link: the free flyer's child body.
    root = [f.name for f in model.frames if f.parentJoint == 1 and f.type == pin.FrameType.BODY][0]
    link = res["links"][root]
    q = pin.neutral(model)
    q[0:3] = link["position"]
    w, x, y, z = link["orientation_wxyz"]
    q[3:7] = [x, y, z, w]
    for j in range(2, model.njoints):
        name = model.names[j]
        if name in res["joints"]:
            q[model.joints[j].idx_q] = res["joints"][name]["position"][0]
    pin.computeJointJacobians(model, data, q)
    pin.framesForwardKinematics(model, data, q)
    g = pin.computeGeneralizedGravity(model, data, q)
    rows = []
    for c in res["contacts"]:
        fid = model.getFrameId(c["link"])
        o = data.oMf[fid].translation
        jac = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        r = np.array(c["point_world"]) - o
        n = np.array(c["normal_world"])
        lin = jac[0:3] + np.cross(jac[3:6].T, r).T  # v_p = v_o + ω × r
        rows.append(n @ lin)
    jc = np.array(rows)
    jb, jj = jc[:, 0:6], jc[:, 6:]
    lam0 = np.linalg.lstsq(jb.T, g[0:6], rcond=None)[0]
    null = np.linalg.svd(jb.T)[2][np.linalg.matrix_rank(jb.T):].T
    names = [model.names[j] for j in range(2, model.njoints)]

    def show(title, lam):
        tau = g[6:] - jj.T @ lam
        print(title)
        print("  base residual", np.abs(g[0:6] - jb.T @ lam).max())
        for c, l in zip(res["contacts"], lam):
            print(f"  {c['link']:24s} {l:12.6f} N")
        print(f"  total {lam.sum():.6f} N, weight {np.abs(g[0:6]).max():.6f}")
        for n_, t in zip(names, tau):
            print(f"  {n_:24s} {t:12.6f}")

    show("least-norm contact forces (analyze --lock):", lam0)
    # Least efforts: λ = λ0 + N t minimizing ‖g_j − J_jᵀ λ‖.
    a = jj.T @ null
    t = np.linalg.lstsq(a, g[6:] - jj.T @ lam0, rcond=None)[0]
    show("least efforts (verify without locks):", lam0 + null @ t)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
