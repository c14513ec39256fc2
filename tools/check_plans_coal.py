#!/usr/bin/env python3
"""Plans on a robot with no SRDF and checks every path on the real meshes with coal,
independently of armsim's collision code (issue 26).

1. An allowed-collision matrix computed here with Pinocchio and coal, as MoveIt's Setup
   Assistant computes one: pairs of links one joint apart, pairs in collision at the
   neutral configuration, in collision in >= 95 % of N samples, never in collision in N
   samples. (armsim computes its own; this one is the referee's.)
2. Random start/goal pairs drawn in the joint box (clipped to +-BOX rad), each free on the
   meshes for the pairs the referee's matrix keeps.
3. armsim's Planner (no SRDF) plans each; every solved path is re-checked with coal at
   STEPS points per radian of joint-space length, every kept pair.

Usage (from the repository, with the venv of tools/test_python.sh):
  target/pyvenv/bin/python tools/check_plans_coal.py robots/ur5.urdf [--problems 20]
      [--box 3.1416] [--samples 2000] [--steps 200] [--time-limit-ms 5000] [--seed 0]
Prints one line per problem and a summary; exits 1 when a path touches.
"""
import argparse
import itertools
import sys
import time

import numpy as np


def load(urdf):
    import pinocchio as pin

    model = pin.buildModelFromUrdf(urdf)
    import os

    # package:// URIs: the URDF's folder and the folders above it (as armsim looks).
    dirs = [os.path.dirname(os.path.abspath(urdf))]
    while os.path.dirname(dirs[-1]) != dirs[-1]:
        dirs.append(os.path.dirname(dirs[-1]))
    geom = pin.buildGeomFromUrdf(model, urdf, pin.GeometryType.COLLISION, package_dirs=dirs)
    return pin, model, geom


def link_pairs(model, geom):
    """Geometry objects grouped by their parent joint's link frame (one group per link)."""
    links = {}
    for k, g in enumerate(geom.geometryObjects):
        links.setdefault(g.parentFrame, []).append(k)
    return links


def colliding_pairs(pin, model, geom, q, pairs, links):
    data, gdata = model.createData(), geom.createData()
    pin.updateGeometryPlacements(model, data, geom, gdata, q)
    import coal

    out = set()
    req = coal.CollisionRequest()
    for a, b in pairs:
        for i in links[a]:
            for j in links[b]:
                res = coal.CollisionResult()
                gi, gj = geom.geometryObjects[i], geom.geometryObjects[j]
                if coal.collide(gi.geometry, gdata.oMg[i], gj.geometry, gdata.oMg[j], req, res):
                    out.add((a, b))
                    break
            if (a, b) in out:
                break
    return out


def referee_acm(pin, model, geom, links, samples, rng, lo, hi):
    frames = sorted(links)
    joint_of = {f: model.frames[f].parentJoint for f in frames}
    adjacent = set()
    for a, b in itertools.combinations(frames, 2):
        ja, jb = joint_of[a], joint_of[b]
        if ja == jb or model.parents[ja] == jb or model.parents[jb] == ja:
            adjacent.add((a, b))
    rest = [p for p in itertools.combinations(frames, 2) if p not in adjacent]
    default = colliding_pairs(pin, model, geom, pin.neutral(model), rest, links)
    counts = dict.fromkeys(rest, 0)
    for _ in range(samples):
        for p in colliding_pairs(pin, model, geom, rng.uniform(lo, hi), rest, links):
            counts[p] += 1
    kept = [p for p in rest if p not in default and 0 < counts[p] < 0.95 * samples]
    return kept, len(adjacent), len(default), sum(c == 0 for c in counts.values())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("urdf")
    ap.add_argument("--problems", type=int, default=20)
    ap.add_argument("--box", type=float, default=np.pi)
    ap.add_argument("--samples", type=int, default=2000)
    ap.add_argument("--steps", type=float, default=200.0)
    ap.add_argument("--time-limit-ms", type=float, default=5000.0)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    import armsim as am

    pin, model, geom = load(args.urdf)
    links = link_pairs(model, geom)
    lo = np.maximum(model.lowerPositionLimit, -args.box)
    hi = np.minimum(model.upperPositionLimit, args.box)
    rng = np.random.default_rng(args.seed)
    t = time.time()
    kept, n_adj, n_def, n_never = referee_acm(pin, model, geom, links, args.samples, rng, lo, hi)
    name = lambda f: model.frames[f].name
    print(f"referee matrix: {len(kept)} pairs kept ({n_adj} adjacent, {n_def} default, "
          f"{n_never} never in {args.samples} samples) in {time.time() - t:.1f} s")
    arm = am.Model.from_file(args.urdf)
    t = time.time()
    planner = am.Planner(arm, time_limit_ms=args.time_limit_ms, seed=args.seed)
    print(f"armsim set-up {time.time() - t:.2f} s; joints {planner.joints}")
    order = [model.getJointId(j) for j in planner.joints]
    idx = [model.joints[j].idx_q for j in order]

    def to_pin(q):
        out = pin.neutral(model)
        out[idx] = q
        return out

    def free(q):
        return not colliding_pairs(pin, model, geom, to_pin(q), kept, links)

    solved = touched = 0
    times = []
    for k in range(args.problems):
        ends = []
        while len(ends) < 2:
            q = rng.uniform(lo[idx], hi[idx])
            if free(q):
                ends.append(q)
        r = planner.plan(ends[0], ends[1])
        times.append((r["plan_time_us"] + r["simplify_time_us"]) / 1e3)
        line = f"{k:3d} {r['status']:>14} {times[-1]:9.1f} ms"
        if r["status"] == "solved":
            solved += 1
            path = np.asarray(r["path"])
            hit = None
            for a, b in zip(path[:-1], path[1:]):
                n = max(1, int(np.ceil(np.linalg.norm(b - a) * args.steps)))
                for s in np.linspace(0.0, 1.0, n + 1):
                    c = colliding_pairs(pin, model, geom, to_pin(a + s * (b - a)), kept, links)
                    if c:
                        hit = [(name(x), name(y)) for x, y in c]
                        break
                if hit:
                    break
            if hit:
                touched += 1
                line += f"  TOUCHES {hit}"
            else:
                line += f"  clear at {args.steps:g}/rad"
        else:
            line += f"  {r['reason']}"
        print(line, flush=True)
    print(f"solved {solved}/{args.problems}, paths touching on the meshes {touched}, "
          f"median time {np.median(times):.1f} ms")
    sys.exit(1 if touched else 0)


if __name__ == "__main__":
    main()
