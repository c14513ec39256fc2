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
