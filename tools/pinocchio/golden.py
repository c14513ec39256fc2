#!/usr/bin/env python3
"""Golden values from Pinocchio (Python bindings of the same `pin` wheel).

Usage: golden.py [--mimic] [--states K] [--seed X] [--ee LINK] robot.urdf > golden.json

Fixed-base model from pinocchio.buildModelFromUrdf(path, mimic=...). Random
states are drawn like bench.cpp: per joint, q uniform in the URDF limits
([-pi, pi] when unbounded); URDF "continuous" joints are Pinocchio
RevoluteUnbounded joints with nq=2, q=(cos t, sin t) -- "theta" gives t.
v, a, tau_in uniform in [-1, 1]. (Values differ from bench.cpp's RNG; only the
distribution is the same.)

Per state the output has (all in Pinocchio conventions, gravity (0,0,-9.81)):
  joint_placements  oMi for every joint (world <- joint frame), [R | p]
  link_placements   oMf for every URDF link (BODY frame), [R | p]
  J_world           data.J after computeJointJacobians: 6 x nv, rows
                    [linear; angular], WORLD convention (linear part = velocity
                    of the body point coinciding with the world origin)
  J_ee_lwa          frame Jacobian of link --ee (default: the last BODY frame) in
                    LOCAL_WORLD_ALIGNED (linear = velocity of that link origin,
                    expressed in world axes), 6 x nv
  rnea              tau = rnea(q, v, a)
  nle               rnea(q, v, 0)  (Coriolis + gravity)
  gravity           computeGeneralizedGravity(q)
  M                 crba(q), symmetrised (Pinocchio fills the upper triangle)
  aba               ddq = aba(q, v, tau_in)   (omitted for mimic models)
  dtau_dq, dtau_dv  computeRNEADerivatives(q, v, a)       (omitted for mimic models)
  ddq_dq, ddq_dv, Minv
                    computeABADerivatives(q, v, tau_in)   (omitted for mimic models;
                    Minv symmetrised like M)
Matrices are row-major nested lists.
"""
import argparse
import hashlib
import json
import math
import os
import sys

import numpy as np
import pinocchio as pin


def random_state(model, rng):
    q = pin.neutral(model)
    theta = []
    for j in range(1, model.njoints):
        jm = model.joints[j]
        if jm.nq == 0:
            continue
        iq = jm.idx_q
        if jm.nq == 1:
            lo, hi = model.lowerPositionLimit[iq], model.upperPositionLimit[iq]
            if not (math.isfinite(lo) and math.isfinite(hi)) or hi < lo or hi - lo > 1e6:
                lo, hi = -math.pi, math.pi
            q[iq] = lo + (hi - lo) * rng.uniform()
            theta.append(float(q[iq]))
        elif jm.nq == 2 and jm.nv == 1:
            t = -math.pi + 2 * math.pi * rng.uniform()
            q[iq], q[iq + 1] = math.cos(t), math.sin(t)
            theta.append(t)
        else:
            raise SystemExit(f"unsupported joint {model.names[j]} ({jm.shortname()})")
    return q, theta


def se3(m):
    return {"rotation": m.rotation.tolist(), "translation": m.translation.tolist()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("urdf")
    ap.add_argument("--mimic", action="store_true")
    ap.add_argument("--states", type=int, default=8)
    ap.add_argument("--seed", type=int, default=42)
    ap.add_argument("--ee", help="link used for J_ee_lwa (default: last BODY frame)")
    args = ap.parse_args()

    model = pin.buildModelFromUrdf(args.urdf, mimic=args.mimic)
    data = model.createData()
    has_mimic = len(model.mimicking_joints) > 0
    bodies = [i for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY]
    ee = model.getFrameId(args.ee, pin.FrameType.BODY) if args.ee else bodies[-1]
    if ee >= len(model.frames):
        raise SystemExit(f"no link named {args.ee}")
    rng = np.random.default_rng(args.seed)

    out = {
        "pinocchio": pin.__version__,
        "model": os.path.splitext(os.path.basename(args.urdf))[0],
        "urdf": args.urdf,
        "urdf_sha256": hashlib.sha256(open(args.urdf, "rb").read()).hexdigest(),
        "mimic": args.mimic,
        "nq": model.nq,
        "nv": model.nv,
        "gravity": model.gravity.linear.tolist(),
        "joints": [
            {"name": model.names[j], "type": model.joints[j].shortname(),
             "idx_q": model.joints[j].idx_q, "nq": model.joints[j].nq,
             "idx_v": model.joints[j].idx_v, "nv": model.joints[j].nv}
            for j in range(1, model.njoints)
        ],
        "links": [model.frames[i].name for i in bodies],
        "ee_link": model.frames[ee].name,
        "states": [],
    }
    for _ in range(args.states):
        q, theta = random_state(model, rng)
        v, a, tau_in = (rng.uniform(-1, 1, model.nv) for _ in range(3))
        st = {"q": q.tolist(), "theta": theta, "v": v.tolist(), "a": a.tolist(), "tau_in": tau_in.tolist()}
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        st["joint_placements"] = {model.names[j]: se3(data.oMi[j]) for j in range(1, model.njoints)}
        st["link_placements"] = {model.frames[i].name: se3(data.oMf[i]) for i in bodies}
        J = pin.computeJointJacobians(model, data, q).copy()
        pin.updateFramePlacements(model, data)
        st["J_world"] = J.tolist()
        st["J_ee_lwa"] = pin.getFrameJacobian(model, data, ee, pin.LOCAL_WORLD_ALIGNED).tolist()
        st["rnea"] = pin.rnea(model, data, q, v, a).tolist()
        st["nle"] = pin.rnea(model, data, q, v, np.zeros(model.nv)).tolist()
        st["gravity"] = pin.computeGeneralizedGravity(model, data, q).tolist()
        M = pin.crba(model, data, q).copy()
        M = np.triu(M) + np.triu(M, 1).T
        st["M"] = M.tolist()
        if not has_mimic:
            st["aba"] = pin.aba(model, data, q, v, tau_in).tolist()
            dq, dv, _ = pin.computeRNEADerivatives(model, data, q, v, a)
            st["dtau_dq"], st["dtau_dv"] = dq.tolist(), dv.tolist()
            ddq_dq, ddq_dv, minv = pin.computeABADerivatives(model, data, q, v, tau_in)
            minv = np.triu(minv) + np.triu(minv, 1).T
            st["ddq_dq"], st["ddq_dv"], st["Minv"] = ddq_dq.tolist(), ddq_dv.tolist(), minv.tolist()
        out["states"].append(st)
    json.dump(out, sys.stdout, indent=None)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
