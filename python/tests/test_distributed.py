"""armsim.distributed on a local Ray cluster (2 CPUs): batch IK, workspace point clouds
and workspace sweeps give exactly the single-process numbers."""

from __future__ import annotations

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS

ray = pytest.importorskip("ray")
from armsim import distributed  # noqa: E402


@pytest.fixture(scope="module")
def cluster():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False,
             runtime_env={"env_vars": {"RAYON_NUM_THREADS": "1"}})
    yield
    ray.shutdown()


def test_ray_ik_batch_equals_the_single_process_run(cluster):
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    _, T = am.sample_poses(m, 30, seed=2, frame="tool0")
    T[7, :3, 3] = [2.5, 0.0, 0.3]  # out of reach: the status must travel too
    local = am.ik_batch(m, "tool0", T, seed=4, max_restarts=10)
    for shards in (2, 3):
        remote = distributed.ik_batch(m, "tool0", T, shards=shards, seed=4, max_restarts=10)
        np.testing.assert_array_equal(remote["q"], local["q"])
        np.testing.assert_array_equal(remote["position_error"], local["position_error"])
        assert remote["status"] == local["status"]
    assert local["status"][7] == "unreachable" and local["status"].count("converged") == 29


def test_ray_workspace_points_equal_the_single_process_run(cluster):
    m = am.Model.from_file(ROBOTS / "panda.urdf")
    q, T = am.sample_poses(m, 5000, seed=8, frame="panda_link8")
    q2, T2 = distributed.workspace_points(m, 5000, seed=8, frame="panda_link8", shards=3)
    np.testing.assert_array_equal(q2, q)
    np.testing.assert_array_equal(T2, T)


@pytest.mark.filterwarnings("ignore:armsim.workspace.*lower bound")
def test_ray_workspace_sweep_equals_the_single_process_runs(cluster):
    m = am.Model.from_file(ROBOTS / "planar_2r.toml")
    opts = dict(samples=1 << 14, keep_points=50)
    remote = distributed.workspace_sweep(m, [1, 2], **opts)
    for seed, r in zip([1, 2], remote):
        local = am.workspace(m, seed=seed, **opts)
        assert r["estimate"] == local["estimate"] and r["interval"] == local["interval"]
        np.testing.assert_array_equal(r["points"], local["points"])
        strip = lambda d: {k: v for k, v in d.items() if k not in ("time_s", "threads")}  # noqa: E731
        assert strip(r["report"]) == strip(local["report"])
    assert remote[0]["estimate"] != remote[1]["estimate"]


def test_robot_and_data_travel_to_ray_tasks(cluster):
    def task(robot, model, data, q):  # nested: Ray ships it by value
        tau = data.tau.copy()
        am.forward_kinematics(model, data, q)
        return robot.rnea(q), robot.fk(q, "tool0"), data.frame_pose("tool0"), tau

    r = am.Robot.from_file(ROBOTS / "ur5.urdf")
    m = r.model
    d = m.create_data()
    q = np.array([0.1, -1.0, 1.2, -0.3, 1.4, 0.2])
    tau = am.rnea(m, d, q, np.zeros(6), np.zeros(6)).copy()
    got = ray.get(ray.remote(task).remote(r, m, d, q))
    np.testing.assert_array_equal(got[0], r.rnea(q))
    np.testing.assert_array_equal(got[1], r.fk(q, "tool0"))
    np.testing.assert_array_equal(got[2], got[1])
    np.testing.assert_array_equal(got[3], tau)
