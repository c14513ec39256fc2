"""`armsim.plan` / `Robot.plan` against `armsim plan` (the same seed gives the same path, bit
for bit) on shown MotionBenchMaker problems, and its bad input."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS, ROOT

BENCH = ROOT.parent / "shared" / "benchmarks" / "motion-planning"
PANDA = ROBOTS / "spherized" / "panda_spherized.urdf"
SRDF = ROBOTS / "spherized" / "panda.srdf"
ARMSIM = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target")) / "release" / "armsim"

needs_bench = pytest.mark.skipif(not BENCH.is_dir(), reason="../shared benchmarks not present")

# The spherized Panda's known loader warning (a mimic tag on its fixed finger joint).
pytestmark = pytest.mark.filterwarnings(
    'ignore:.*<mimic joint="panda_finger_joint1"> on a fixed joint:armsim.LoaderWarning')


def cli_plan(scene: Path, request: Path) -> dict:
    out = subprocess.run(
        [str(ARMSIM), "plan", str(PANDA), "--srdf", str(SRDF), "--moveit-scene", str(scene),
         "--moveit-request", str(request), "--json"],
        check=True, capture_output=True, text=True, cwd=ROOT)
    return json.loads(out.stdout)["results"][0]


@needs_bench
@pytest.mark.skipif(not ARMSIM.is_file(), reason="no armsim binary (run cargo build --release)")
@pytest.mark.parametrize("problem", ["0002", "0005", "0011"])
def test_robot_plan_gives_the_cli_path_bit_for_bit(problem):
    d = BENCH / "panda" / "box"
    scene, request = d / f"scene{problem}.yaml", d / f"request{problem}.yaml"
    robot = am.Robot.from_file(PANDA)
    r = robot.plan(scene=scene, request=request, srdf=SRDF)
    c = cli_plan(scene, request)
    assert r["status"] == c["status"] == "solved"
    assert r["iterations"] == c["iterations"]
    path = r["path"]
    assert path.shape == (len(c["path"]), 7)
    np.testing.assert_array_equal(path, np.array(c["path"]))
    assert r["cost"] == pytest.approx(np.linalg.norm(np.diff(path, axis=0), axis=1).sum(), rel=1e-5)
    assert r["joints"] == am.Model.from_file(PANDA).joint_names
    # The module function on the Model plans the same.
    m = am.Model.from_file(PANDA)
    r2 = am.plan(m, start=path[0], goal=path[-1], scene=scene, srdf=SRDF)
    np.testing.assert_array_equal(r2["path"], path)


@needs_bench
def test_plan_reports_an_invalid_start_and_refuses_bad_input():
    d = BENCH / "panda" / "box"
    m = am.Model.from_file(PANDA)
    req = am.plan(m, scene=d / "scene0002.yaml", request=d / "request0002.yaml", srdf=SRDF,
                  time_limit_ms=200)
    goal = req["path"][-1]
    # A start leaning forward into the box: the scene's obstacles are read.
    low = np.zeros(7)
    low[1], low[3] = 1.7, -0.1
    r = am.plan(m, start=low, goal=goal, scene=d / "scene0002.yaml", srdf=SRDF)
    assert r["status"] == "invalid_start"
    assert r["reason"] and r["path"].shape == (0, 7)
    with pytest.raises(FileNotFoundError):
        am.plan(m, start=goal, goal=goal, scene=d / "nope.yaml")
    with pytest.raises(am.ArmsimError, match="start"):
        am.plan(m, start=[0.0, 1.0], goal=goal)
    with pytest.raises(am.ArmsimError, match="goal"):
        am.plan(m, start=goal)
    with pytest.raises(am.ArmsimError, match="range"):
        am.plan(m, start=goal, goal=goal, range=-1.0)


UR5 = ROBOTS / "ur5.urdf"
UR5_HOME = [0.0, -1.57, 1.57, 0.0, 1.57, 0.0]
UR5_GOAL = [1.2, -1.0, 1.0, -1.5, -1.2, 0.5]
WALL = {"name": "wall", "shape": "box", "size": [0.3, 0.05, 0.5], "xyz": [0.45, 0.45, 0.25]}


def test_planner_plans_the_bundled_ur5_without_an_srdf_and_names_its_pairs():
    p = am.Planner(am.Model.from_file(UR5), seed=3)
    assert p.joints == am.Model.from_file(UR5).joint_names
    reasons = {r for _, _, r in p.disabled_pairs}
    assert "Adjacent" in reasons and reasons <= {"Adjacent", "Default", "Always", "Never"}
    assert p.checked_pairs and p.setup_time_s > 0
    r = p.plan(UR5_HOME, UR5_GOAL, obstacles=[WALL])
    assert r["status"] == "solved", r["reason"]
    assert r["path"].shape[1] == 6
    np.testing.assert_array_equal(r["path"][0], UR5_HOME)
    np.testing.assert_array_equal(r["path"][-1], UR5_GOAL)


def test_reused_planner_gives_the_path_of_a_fresh_one():
    m = am.Model.from_file(UR5)
    reused = am.Planner(m, seed=5)
    reused.plan(UR5_HOME, UR5_GOAL, obstacles=[{"shape": "sphere", "radius": 0.1,
                                                "xyz": [-0.4, -0.4, 0.3]}])
    a = reused.plan(UR5_HOME, UR5_GOAL, obstacles=[WALL])
    b = am.Planner(m, seed=5).plan(UR5_HOME, UR5_GOAL, obstacles=[WALL])
    assert a["status"] == b["status"] == "solved"
    np.testing.assert_array_equal(a["path"], b["path"])


def test_planner_names_what_a_start_touches_and_refuses_bad_obstacles():
    p = am.Planner(am.Model.from_file(UR5))
    ball = {"name": "ball", "shape": "sphere", "radius": 0.05, "xyz": [0.393, 0.109, 0.42]}
    r = p.plan(UR5_HOME, UR5_GOAL, obstacles=[ball])
    assert r["status"] == "invalid_start"
    assert "'ball'" in r["reason"] and " mm" in r["reason"]
    with pytest.raises(am.ArmsimError, match=r"obstacles\[0\].size"):
        p.plan(UR5_HOME, UR5_GOAL, obstacles=[{"shape": "box", "size": [0.1, -1, 0.1]}])
    with pytest.raises(am.ArmsimError, match=r"obstacles\[0\].radius: not a key"):
        p.plan(UR5_HOME, UR5_GOAL, obstacles=[{"shape": "box", "size": [0.1] * 3, "radius": 1}])
    with pytest.raises(am.ArmsimError, match="shape"):
        p.plan(UR5_HOME, UR5_GOAL, obstacles=[{"shape": "cone"}])


@needs_bench
def test_ctrl_c_stops_a_long_plan_promptly():
    """An impossible problem with a 60 s limit, interrupted after 0.3 s: KeyboardInterrupt
    within a second, and the planner stays usable."""
    import signal
    import threading
    import time
    import _thread

    # Python's own Ctrl-C handler: an earlier test's library (Ray) may have replaced it
    # with one that does not raise, and the interrupt would then go unseen.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _interrupt_a_long_plan(threading, time, _thread)
    finally:
        signal.signal(signal.SIGINT, previous)


def _interrupt_a_long_plan(threading, time, _thread):
    m = am.Model.from_file(PANDA)
    p = am.Planner(m, srdf=SRDF, time_limit_ms=60_000)
    block = {"name": "block", "shape": "box", "size": [0.02, 0.1, 0.17], "xyz": [0.0, -0.15, 0.335]}
    start = [1.5, 0.0, 0.0, -0.5, 0.0, 1.0, 0.785]
    goal = [-1.5, 0.0, 0.0, -0.5, 0.0, 1.0, 0.785]
    threading.Timer(0.3, _thread.interrupt_main).start()
    t0 = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        p.plan(start, goal, obstacles=[block])
    assert time.monotonic() - t0 < 1.5
    r = p.plan(start, start, obstacles=[block])
    assert r["status"] == "solved"
