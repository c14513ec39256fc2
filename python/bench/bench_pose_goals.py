"""What a tool-pose goal and a path constraint cost in planning time, against the same
problem posed with joint values (issue 30). MotionBenchMaker problems of the shared
benchmark (spherized robot + SRDF, one scene file per problem), one thread, one Planner
per robot built once:

- **joint**: `Planner.plan(start, goal)` with the problem's joint goal;
- **pose**: the same problem with `goal_pose = {link: tool, pose: FK(goal)}`: the goal set
  is every IK solution (closed form on the UR5, seeded numeric IK otherwise), searched
  from the start and the shortest simplified path kept (the joint goal is one of them);
- **constrained**: start and goal whose tool axis points down (IK of a random downward
  pose 25 cm above the problem's goal, and above the goal swung 0.8 rad about the base), planned
  with the axis held within 0.2 rad of straight down on every certified point
  (`path_constraints`, projection): the upright cup. Ends that collide with the scene
  are drawn again (5 tries, else the problem is skipped), so the count can differ.

Reports per robot and query kind: solved, median and p95 planning time (ms, IK of the
goal set included), median cost. Timings are per query, single-threaded; the host is
shared, so compare the kinds within one run.

    RAYON_NUM_THREADS=1 python python/bench/bench_pose_goals.py [--problems 40] [--robots ur5 panda]
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np
import yaml

import armsim as am

ROOT = Path(__file__).resolve().parents[2]
BENCH = Path(os.environ.get("PLAN_BENCH_DIR", ROOT.parent / "shared/benchmarks/motion-planning"))
TOOLS = {"ur5": "tool0", "panda": "panda_hand"}
DOWN = [0.0, 0.0, -1.0]


def problem(robot_dir: Path, scene: str, k: int, names: list[str]):
    """Start and joint goal of MBM problem k (model order) and its scene file."""
    req = yaml.safe_load((robot_dir / scene / f"request{k:04d}.yaml").read_text())
    js = req["start_state"]["joint_state"]
    start_of = dict(zip(js["name"], js["position"]))
    goal_of = {c["joint_name"]: c["position"] for c in req["goal_constraints"][0]["joint_constraints"]}
    start = np.array([start_of.get(n, 0.0) for n in names])
    goal = np.array([goal_of.get(n, start_of.get(n, 0.0)) for n in names])
    return start, goal, robot_dir / scene / f"scene{k:04d}.yaml"


def downward_config(robot: am.Robot, tool: str, rng, near: np.ndarray, q0: np.ndarray):
    """A configuration whose tool z axis points straight down, at a random point about
    25 cm above the tool position of `near` (above the objects it grasps); IK starts at
    `q0`, so that both ends of a query can lie on one IK branch (the tool-down
    configurations of different wrist branches are not connected under the constraint)."""
    t = robot.fk(near, tool)
    for _ in range(50):
        target = np.eye(4)
        target[:3, :3] = np.diag([1.0, -1.0, -1.0])  # z down
        target[:3, 3] = t[:3, 3] + [0.0, 0.0, 0.25] + rng.uniform(-0.1, 0.1, 3)
        sol = robot.ik(target, tool, q0=q0, seed=int(rng.integers(1 << 30)), max_restarts=4)
        if sol.converged:
            return np.asarray(sol.q)
    return None


def stats(rows):
    ok = [r for r in rows if r["status"] == "solved"]
    other = sorted({r["status"] for r in rows} - {"solved"})
    if not ok:
        return f"0/{len(rows)} {other} | – | – | –"
    t = np.array([(r["plan_time_us"] + r["simplify_time_us"]) / 1e3 for r in ok])
    c = np.array([r["cost"] for r in ok])
    return (f"{len(ok)}/{len(rows)}{' ' + ', '.join(other) if other else ''} | {np.median(t):.2f} | {np.percentile(t, 95):.2f} "
            f"| {np.median(c):.3f}")


def run(name: str, problems: int, scene: str, rng):
    d = BENCH / name
    urdf = next(d.glob("*_spherized.urdf"))
    model = am.Model.from_file(urdf)
    robot = am.Robot(model)
    tool = TOOLS[name]
    planner = am.Planner(model, srdf=d / f"{name}.srdf", seed=0)
    names = model.joint_names
    joint, pose, constrained = [], [], []
    for k in range(1, problems + 1):
        start, goal, scene_file = problem(d, scene, k, names)
        joint.append(planner.plan(start, goal, scene=scene_file))
        target = robot.fk(goal, tool)
        pose.append(planner.plan(start, goal_pose={"link": tool, "pose": target}, scene=scene_file))
        # The upright cup: from above the goal to above a point swung 0.8 rad about the
        # base, the tool pointing down at both ends.
        swung = goal.copy()
        swung[0] += 0.8 if k % 2 else -0.8
        cup = [{"type": "axis", "link": tool, "axis": [0, 0, 1], "direction": DOWN,
                "tolerance": 0.2}]
        for _ in range(5):  # new random ends while one collides with the scene
            a = downward_config(robot, tool, rng, goal, goal)
            if a is None:
                continue
            a_swung = a.copy()
            a_swung[0] = swung[0]
            b = downward_config(robot, tool, rng, swung, a_swung)
            if b is None:
                continue
            r = planner.plan(a, b, scene=scene_file, path_constraints=cup)
            if r["status"] not in ("invalid_start", "invalid_goal"):
                constrained.append(r)
                break
    return [("joint goal", stats(joint)), ("pose goal", stats(pose)),
            ("axis-constrained (0.2 rad)", stats(constrained))]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", type=int, default=40)
    ap.add_argument("--scene", default="table_pick")
    ap.add_argument("--robots", nargs="+", default=["ur5", "panda"])
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    print(f"MotionBenchMaker {args.scene}, problems 1–{args.problems}; load average "
          f"{os.getloadavg()[0]:.2f} at the start\n")
    print("| robot | query | solved | time median (ms) | time p95 (ms) | cost median |")
    print("|---|---|---|---|---|---|")
    for name in args.robots:
        for kind, row in run(name, args.problems, args.scene, rng):
            print(f"| {name} | {kind} | {row} |")
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
