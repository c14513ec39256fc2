"""`armsim.plan` / `Planner.plan` with a tool-pose goal (`goal_pose`), path constraints
(`path_constraints`) and the optimising planner (`planner="aorrtc"` and its budget): the
pose reached is checked by forward kinematics, the constraints at densely re-sampled
points of the returned path, AORRTC's cost against RRT-Connect's, and the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS

UR5 = ROBOTS / "ur5.urdf"
HOME = [0.0, -1.57, 1.57, 0.0, 1.57, 0.0]
GOAL_Q = [1.2, -1.0, 1.0, -1.5, -1.2, 0.5]
WALL = {"name": "wall", "shape": "box", "size": [0.3, 0.05, 0.5], "xyz": [0.45, 0.45, 0.25]}


@pytest.fixture(scope="module")
def robot():
    return am.Robot.from_file(UR5)


@pytest.fixture(scope="module")
def planner(robot):
    return am.Planner(robot.model, seed=7)


def angle(ra, rb) -> float:
    """Geodesic angle between two rotation matrices (rad)."""
    c = (np.trace(ra.T @ rb) - 1.0) / 2.0
    return math.acos(max(-1.0, min(1.0, c)))


def dense(path: np.ndarray, per_edge: int = 40):
    """The path's waypoints and `per_edge - 1` points inside each straight edge."""
    for a, b in zip(path[:-1], path[1:]):
        for t in np.linspace(0.0, 1.0, per_edge + 1)[:-1]:
            yield a + t * (b - a)
    yield path[-1]


def test_pose_goal_is_reached_to_1e6_checked_by_forward_kinematics(robot, planner):
    target = robot.fk(GOAL_Q, "tool0")
    r = planner.plan(HOME, goal_pose={"link": "tool0", "pose": target}, obstacles=[WALL])
    assert r["status"] == "solved", r["reason"]
    assert r["planner"] == "rrt-connect"
    path = r["path"]
    np.testing.assert_array_equal(path[0], HOME)
    np.testing.assert_array_equal(r["goal"], path[-1])
    reached = robot.fk(path[-1], "tool0")
    assert np.linalg.norm(reached[:3, 3] - target[:3, 3]) < 1e-6
    assert angle(reached[:3, :3], target[:3, :3]) < 1e-6
    # The UR5's closed form gives up to 8 branches; the set is reported.
    assert 1 <= r["goal_set"]["valid"] <= r["goal_set"]["found"] <= 8
    assert r["goal_set"]["searches"] >= 1
    assert r["joints"] == robot.joint_names
    # The cost is the joint-space length of the returned path.
    assert r["cost"] == pytest.approx(np.linalg.norm(np.diff(path, axis=0), axis=1).sum(),
                                      rel=1e-5)
    # The module function and a fresh planner (same seed) return the same path.
    m = robot.model
    r2 = am.plan(m, start=HOME, goal_pose={"link": "tool0", "pose": target}, seed=7)
    r3 = am.Planner(m, seed=7).plan(HOME, goal_pose={"link": "tool0", "pose": target})
    assert r2["status"] == "solved", r2["reason"]
    np.testing.assert_array_equal(r2["path"], r3["path"])
    # The link defaults to the tool link, as in Robot.fk: `tool0`, not the URDF's last
    # link "base", which no joint moves.
    assert robot.frame_names[-1] == "base"
    default = am.Planner(m, seed=7).plan(HOME, goal_pose={"pose": target})
    assert default["status"] == "solved", default["reason"]
    np.testing.assert_array_equal(default["path"], r3["path"])
    named = planner.plan(HOME, goal_pose={"link": "base", "pose": target})
    assert named["status"] == "invalid_goal"


def test_position_only_goal_reaches_the_point(robot, planner):
    # A position-only goal takes the numeric goal set (no closed form without the
    # orientation), on the fixed frame tool0.
    p = robot.fk(GOAL_Q, "tool0")[:3, 3]
    r = planner.plan(HOME, goal_pose={"link": "tool0", "position": p.tolist()})
    assert r["status"] == "solved", r["reason"]
    assert r["goal_set"]["found"] >= 1
    assert np.linalg.norm(robot.fk(r["path"][-1], "tool0")[:3, 3] - p) < 1e-6


def test_unreachable_pose_is_an_invalid_goal_with_its_reason(planner):
    far = np.eye(4)
    far[:3, 3] = [2.0, 0.0, 0.4]  # the UR5 reaches about 0.85 m
    r = planner.plan(HOME, goal_pose={"link": "tool0", "pose": far})
    assert r["status"] == "invalid_goal"
    assert "unreachable" in r["reason"]
    assert r["path"].shape == (0, 6) and r["goal"] is None


def test_axis_and_box_constraints_hold_at_dense_samples_of_the_path(robot, planner):
    t0 = robot.fk(HOME, "tool0")
    up = t0[:3, 2]  # the tool's z axis at the start, kept within 0.1 rad
    target = t0.copy()
    target[:3, 3] += [0.0, 0.15, -0.1]
    lo, hi = np.minimum(t0[:3, 3], target[:3, 3]), np.maximum(t0[:3, 3], target[:3, 3])
    centre, size = (lo + hi) / 2, hi - lo + 0.1  # 5 cm of room around the straight move
    constraints = [
        {"type": "axis", "link": "tool0", "axis": [0, 0, 1], "direction": up.tolist(),
         "tolerance": 0.1},
        {"type": "position", "link": "tool0", "shape": "box", "size": size.tolist(),
         "xyz": centre.tolist()},
    ]
    r = planner.plan(HOME, goal_pose={"link": "tool0", "pose": target},
                     path_constraints=constraints)
    assert r["status"] == "solved", r["reason"]
    path = r["path"]
    reached = robot.fk(path[-1], "tool0")
    assert np.linalg.norm(reached[:3, 3] - target[:3, 3]) < 1e-6
    assert angle(reached[:3, :3], target[:3, :3]) < 1e-6
    worst_angle, worst_out = 0.0, -1.0
    for q in dense(path):
        t = robot.fk(q, "tool0")
        worst_angle = max(worst_angle, math.acos(min(1.0, float(t[:3, 2] @ up))))
        worst_out = max(worst_out, float(np.max(np.abs(t[:3, 3] - centre) - size / 2)))
    assert worst_angle <= 0.1 + 1e-9
    assert worst_out <= 1e-9
    # A joint goal under an orientation constraint goes through the same search.
    q_end = path[-1]
    r = planner.plan(HOME, goal=q_end, path_constraints=[
        {"type": "orientation", "link": "tool0", "rotation": t0[:3, :3].tolist(),
         "tolerance": 0.1}])
    assert r["status"] == "solved", r["reason"]
    assert max(angle(robot.fk(q, "tool0")[:3, :3], t0[:3, :3]) for q in dense(r["path"])) \
        <= 0.1 + 1e-9


def test_aorrtc_is_no_costlier_than_rrt_connect_and_repeats_itself(robot):
    m = robot.model
    first = am.Planner(m, seed=3).plan(HOME, GOAL_Q, obstacles=[WALL])
    best = am.Planner(m, seed=3).plan(HOME, GOAL_Q, obstacles=[WALL], planner="aorrtc",
                                      budget_iterations=3000)
    again = am.plan(m, start=HOME, goal=GOAL_Q, seed=3, planner="aorrtc",
                    budget_iterations=3000)
    assert first["status"] == best["status"] == "solved"
    assert first["planner"] == "rrt-connect" and best["planner"] == "aorrtc"
    assert best["cost"] <= first["cost"] + 1e-9
    np.testing.assert_array_equal(best["path"][-1], GOAL_Q)
    imp = best["improvements"]
    assert imp and set(imp[0]) == {"time_us", "iterations", "cost"}
    costs = [i["cost"] for i in imp]
    assert all(b <= a for a, b in zip(costs, costs[1:]))
    assert costs[-1] == pytest.approx(best["cost"], rel=1e-9)
    assert best["iterations"] <= 3000
    # Same seed, same path (a reused planner, and the module function in free space
    # against itself).
    best2 = am.Planner(m, seed=3).plan(HOME, GOAL_Q, obstacles=[WALL], planner="aorrtc",
                                       budget_iterations=3000)
    np.testing.assert_array_equal(best["path"], best2["path"])
    again2 = am.plan(m, start=HOME, goal=GOAL_Q, seed=3, planner="aorrtc",
                     budget_iterations=3000)
    np.testing.assert_array_equal(again["path"], again2["path"])


@pytest.mark.parametrize("kwargs, match", [
    ({"planner": "rrt"}, "planner: expected 'rrt-connect' or 'aorrtc'"),
    ({"budget_iterations": 100}, "budget_iterations applies to planner='aorrtc'"),
    ({"budget_ms": 10.0}, "budget_ms applies to planner='aorrtc'"),
    ({"planner": "aorrtc", "budget_iterations": 0}, "budget_iterations: expected 1"),
    ({"planner": "aorrtc", "budget_iterations": -1}, "budget_iterations: expected a non-negative"),
    ({"planner": "aorrtc", "budget_ms": float("nan")}, "budget_ms: expected a positive"),
    ({"planner": "aorrtc", "path_constraints": [
        {"type": "axis", "axis": [0, 0, 1], "direction": [0, 0, 1], "tolerance": 0.5}]},
     "aorrtc.*path_constraints"),
    ({"path_constraints": [{"type": "axis", "axis": [0, 0, 0], "direction": [0, 0, 1],
                            "tolerance": 0.5}]}, r"path_constraints\[0\]\.axis: expected a non-zero"),
    ({"path_constraints": [{"type": "axis", "axis": [0, 0, 1], "direction": [0, 0, 1],
                            "tolerance": 3.5}]}, r"path_constraints\[0\]\.tolerance: expected a number in \(0, 3.14"),
    ({"path_constraints": [{"type": "position", "shape": "box", "size": [0.1, 0.1, 0.1],
                            "radius": 0.1}]}, r"path_constraints\[0\]\.radius: not a key of a box"),
    ({"path_constraints": [{"type": "position", "shape": "sphere", "radius": float("inf")}]},
     r"path_constraints\[0\]\.radius: expected a number in \(0"),
    ({"path_constraints": [{"type": "cone"}]}, r"path_constraints\[0\]\.type: expected axis"),
    ({"path_constraints": [{"type": "orientation", "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 2]],
                            "tolerance": 0.1}]}, r"path_constraints\[0\]\.rotation: the rotation is not orthonormal"),
    ({"path_constraints": [{"type": "axis", "link": "nope", "axis": [0, 0, 1],
                            "direction": [0, 0, 1], "tolerance": 0.5}]},
     r"path_constraints\[0\]\.link: no frame 'nope'"),
])
def test_bad_search_and_constraint_arguments_are_refused_by_name(planner, kwargs, match):
    with pytest.raises(am.ArmsimError, match=match):
        planner.plan(HOME, GOAL_Q, **kwargs)


def test_bad_goal_pose_is_refused_by_name(robot, planner):
    t = robot.fk(GOAL_Q, "tool0")
    with pytest.raises(am.ArmsimError, match="goal and goal_pose: give one"):
        planner.plan(HOME, GOAL_Q, goal_pose={"pose": t})
    with pytest.raises(am.ArmsimError, match="aorrtc.*goal_pose"):
        planner.plan(HOME, goal_pose={"pose": t}, planner="aorrtc")
    with pytest.raises(am.ArmsimError, match=r"goal_pose\.tolerance: not a key of a goal pose"):
        planner.plan(HOME, goal_pose={"pose": t, "tolerance": 1e-3})
    with pytest.raises(am.ArmsimError, match="goal_pose: give exactly one of 'pose'"):
        planner.plan(HOME, goal_pose={"pose": t, "position": [0.3, 0.1, 0.4]})
    bad = t.copy()
    bad[0, 3] = float("nan")
    with pytest.raises(am.ArmsimError, match=r"goal_pose\.pose\[0, 3\] is not finite"):
        planner.plan(HOME, goal_pose={"pose": bad})
    with pytest.raises(am.ArmsimError, match=r"goal_pose\.position: expected three finite"):
        planner.plan(HOME, goal_pose={"position": [0.3, 0.1]})
    with pytest.raises(am.ArmsimError, match="goal: give it, a goal_pose"):
        planner.plan(HOME)
    with pytest.raises(am.ArmsimError, match="goal_pose: expected a dict"):
        planner.plan(HOME, goal_pose=t)
