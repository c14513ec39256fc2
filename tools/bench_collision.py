#!/usr/bin/env python3
"""The main job's collision stage beside coal 3 (FCL's successor, from PyPI), on the same
configurations, meshes and pairs.

    python3 tools/bench_collision.py [--runs 5]

1. Builds armsim (`cargo build --release --bin armsim --example collision_poses`) and
   writes the stage's inputs with `collision_poses` (every sample of the stage: 10 ms
   plus the attach and detach instants; the geometry world poses, the part on the tool
   inside the carry window; the tested body pairs of both scenes) to
   target/bench_collision/poses.json.
2. Runs `armsim run scenarios/ur5_pick_and_place.toml` `--runs` times and takes the
   median of `timings.collisions_s` (the whole stage: scene building with the meshes,
   the dense limits pass, the continuous certificate, the exact closest approaches).
3. With coal (a venv under target/coalvenv, `pip install coal`), on the same samples and
   pairs, `--runs` times each, medians:
   - `coal meshes, distances`: the minimum environment and self distance at every sample
     with BVH mesh-mesh distance, pairs visited by increasing bounding-sphere gap and
     stopped when the gap exceeds the best distance (armsim's former pruning);
   - `coal meshes, boolean`: `collide` on every pair at every sample;
   - `coal convex hulls, distances`: as the first, on the meshes' convex hulls.
   Loading the meshes is timed apart. The minima are printed beside armsim's.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "target", "bench_collision")
VENV = os.path.join(ROOT, "target", "coalvenv")
SCENARIO = "scenarios/ur5_pick_and_place.toml"


def ensure_venv():
    """Re-runs this script in the venv with coal, creating it if needed."""
    try:
        import coal  # noqa: F401
        import numpy  # noqa: F401
        return
    except ImportError:
        pass
    py = os.path.join(VENV, "bin", "python")
    if not os.path.exists(py):
        subprocess.check_call([sys.executable, "-m", "venv", VENV])
        subprocess.check_call([py, "-m", "pip", "install", "-q", "coal", "numpy"])
    os.execv(py, [py] + sys.argv)


def armsim_side(runs):
    subprocess.check_call(
        ["cargo", "build", "--release", "--bin", "armsim", "--example", "collision_poses"],
        cwd=ROOT,
    )
    os.makedirs(OUT, exist_ok=True)
    poses = os.path.join(OUT, "poses.json")
    exe = os.path.join(ROOT, "target", "release", "examples", "collision_poses")
    subprocess.check_call([exe, SCENARIO, poses], cwd=ROOT)
    stage = []
    for _ in range(runs):
        subprocess.check_call(
            [os.path.join(ROOT, "target", "release", "armsim"), "run", SCENARIO,
             "--out", OUT],
            cwd=ROOT, stdout=subprocess.DEVNULL,
        )
        with open(os.path.join(OUT, "ur5_pick_and_place.json")) as f:
            rep = json.load(f)
        stage.append(rep["timings"]["collisions_s"])
    with open(poses) as f:
        return json.load(f), stage, rep["collisions"]


def rpy_matrix(r, p, y):
    import numpy as np
    cr, sr, cp, sp, cy, sy = (np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y))
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


class Scene:
    """coal geometries of one model (bare or with the part) and the obstacles."""

    def __init__(self, data, which, hulls):
        import coal
        import numpy as np
        loader = coal.MeshLoader()
        self.geoms = []  # (body name, geometry)
        for g in data["geoms_" + which]:
            if g["kind"] == "mesh":
                m = loader.load(g["path"], np.array(g["scale"], dtype=float))
                if hulls:
                    m.buildConvexHull(True, "Qt")
                    m = m.convex
            else:
                m = coal.Box(*g["size"])
            m.computeLocalAABB()
            self.geoms.append((g["link"], m))
        self.obstacles = []
        for o in data["obstacles"]:
            assert o["shape"] == "box", o
            b = coal.Box(*o["size"])
            b.computeLocalAABB()
            t = coal.Transform3s(rpy_matrix(*o["rpy"]), np.array(o["xyz"], dtype=float))
            self.obstacles.append((o["name"], b, t))
        names = {n for n, _, _ in self.obstacles}
        # Shape pairs of the tested body pairs, environment and self apart.
        self.env, self.self_ = [], []
        for a, b in data["pairs_" + which]:
            ia = [i for i, (n, _) in enumerate(self.geoms) if n == a]
            if b in names:
                k = [i for i, (n, _, _) in enumerate(self.obstacles) if n == b][0]
                self.env += [(i, k) for i in ia]
            else:
                ib = [i for i, (n, _) in enumerate(self.geoms) if n == b]
                self.self_ += [(i, j) for i in ia for j in ib]

    def transforms(self, poses):
        import coal
        import numpy as np
        out = []
        for p in poses:
            m = np.array(p)
            out.append(coal.Transform3s(m[:, :3], m[:, 3]))
        return out


def centre(geom, tf):
    return tf.transform(geom.aabb_center), geom.aabb_radius


def min_distance(pairs, get):
    """Smallest distance over `pairs`, visited by increasing bounding-sphere gap."""
    import coal
    import numpy as np
    order = []
    for p in pairs:
        (ga, ta), (gb, tb) = get(p)
        (ca, ra), (cb, rb) = centre(ga, ta), centre(gb, tb)
        order.append((float(np.linalg.norm(ca - cb)) - ra - rb, p))
    order.sort(key=lambda x: x[0])
    best = float("inf")
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    for gap, p in order:
        if gap > 0 and gap >= best:
            break
        (ga, ta), (gb, tb) = get(p)
        res.clear()
        best = min(best, coal.distance(ga, ta, gb, tb, req, res))
    return best


def coal_pass(data, scenes, mode):
    """One pass over every sample: (min environment, min self) or collisions found."""
    import coal
    env_min, self_min, hits = float("inf"), float("inf"), 0
    creq, cres = coal.CollisionRequest(), coal.CollisionResult()
    for s in data["samples"]:
        sc = scenes["part" if s["carried"] else "bare"]
        tfs = sc.transforms(s["poses"])

        def env(p):
            i, k = p
            return (sc.geoms[i][1], tfs[i]), (sc.obstacles[k][1], sc.obstacles[k][2])

        def slf(p):
            i, j = p
            return (sc.geoms[i][1], tfs[i]), (sc.geoms[j][1], tfs[j])

        if mode == "boolean":
            for pairs, get in ((sc.env, env), (sc.self_, slf)):
                for p in pairs:
                    (ga, ta), (gb, tb) = get(p)
                    cres.clear()
                    if coal.collide(ga, ta, gb, tb, creq, cres):
                        hits += 1
        else:
            env_min = min(env_min, min_distance(sc.env, env))
            self_min = min(self_min, min_distance(sc.self_, slf))
    return env_min, self_min, hits


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    ensure_venv()
    import coal
    data, stage, coll = armsim_side(args.runs)
    rows = []
    arm_med = statistics.median(stage)
    rows.append(("armsim collision stage (certified, exact minima)", arm_med, None))
    for label, hulls, mode in (
        ("coal meshes, distances (armsim's former pruning)", False, "dist"),
        ("coal meshes, boolean only", False, "boolean"),
        ("coal convex hulls, distances", True, "dist"),
    ):
        t0 = time.process_time()
        scenes = {w: Scene(data, w, hulls) for w in ("bare", "part")}
        load = time.process_time() - t0
        ts, res = [], None
        for _ in range(args.runs):
            t0 = time.process_time()
            res = coal_pass(data, scenes, mode)
            ts.append(time.process_time() - t0)
        rows.append((label, statistics.median(ts), (load, res)))
    print(f"coal {coal.__version__ if hasattr(coal, '__version__') else '?'}; "
          f"{len(data['samples'])} configurations; {args.runs} runs, medians (CPU s)")
    print("| stage | median (s) | coal / armsim | loading (s) | result |")
    print("|---|---|---|---|---|")
    env = coll["min_environment"]
    slf = coll["min_self"]
    print(f"| {rows[0][0]} | {arm_med:.4f} | 1 | in the stage | "
          f"min env {env['distance']:.6f} ({env['pair'][0]}-{env['pair'][1]}), "
          f"min self {slf['distance']:.6f} ({slf['pair'][0]}-{slf['pair'][1]}) |")
    for label, t, (load, res) in rows[1:]:
        if label.endswith("boolean only"):
            what = f"{res[2]} colliding pairs"
        else:
            what = f"min env {res[0]:.6f}, min self {res[1]:.6f}"
        print(f"| {label} | {t:.4f} | {t / arm_med:.1f} | {load:.3f} | {what} |")


if __name__ == "__main__":
    main()
