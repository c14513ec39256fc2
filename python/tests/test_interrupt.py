"""Ctrl-C during long batches (issue 31): a SIGINT sent 0.2 s into a batch sized to run
about 3 s raises KeyboardInterrupt within a fraction of that, for every looping batch
function, and the functions work normally afterwards.

The heavy rows come from a chain of 2000 bodies that all follow one coordinate (mimic
joints): each row costs tens of microseconds while its input and output stay small."""

from __future__ import annotations

import math
import os
import signal
import threading
import time

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS, ROOT

TARGET_S = 3.0  # what an uninterrupted batch would take
SIGNAL_AT_S = 0.2


def mimic_chain(n: int) -> str:
    links = ['<link name="l0"/>']
    joints = []
    inertia = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
    for i in range(1, n + 1):
        links.append(f'<link name="l{i}"><inertial><mass value="1"/>{inertia}</inertial></link>')
        mimic = "" if i == 1 else '<mimic joint="j1" multiplier="0.5"/>'
        joints.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            '<origin xyz="0 0 0.01" rpy="0 0.1 0"/><axis xyz="0 0 1"/>'
            f'<limit lower="-1" upper="1" effort="1" velocity="1"/>{mimic}</joint>')
    return '<robot name="mimic_chain">' + "".join(links + joints) + "</robot>"


@pytest.fixture(scope="module")
def chain():
    m = am.Model.from_string(mimic_chain(2000), "chain.urdf")
    assert m.nv == 1
    return m


@pytest.fixture
def default_sigint():
    """Python's own Ctrl-C handler (Ray, run by other tests, may have installed one that
    does not raise)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def rows_for(call, n0: int) -> int:
    """Rows that make `call(rows)` take about TARGET_S, from a timed run of `n0` rows."""
    t0 = time.perf_counter()
    call(n0)
    per_row = (time.perf_counter() - t0) / n0
    return max(n0, math.ceil(TARGET_S / per_row))


def interrupted_after(call) -> float:
    """Seconds until `call()` raised KeyboardInterrupt, a SIGINT being sent to this
    process from another thread SIGNAL_AT_S after the start (as Ctrl-C does)."""
    timer = threading.Timer(SIGNAL_AT_S, os.kill, (os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    return time.monotonic() - t0


def ur5_targets(n: int) -> np.ndarray:
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    _, T = am.sample_poses(m, n, seed=5, frame="tool0")
    return T


BATCHES = {
    "fk_batch": lambda m, n: am.fk_batch(m, np.full((n, 1), 0.3), "l2000"),
    "jacobian_batch": lambda m, n: am.jacobian_batch(m, np.full((n, 1), 0.3), "l2000"),
    "gravity_batch": lambda m, n: am.gravity_batch(m, np.full((n, 1), 0.3)),
    "sample_poses": lambda m, n: am.sample_poses(m, n, seed=1),
}


@pytest.mark.parametrize("name", sorted(BATCHES))
def test_ctrl_c_stops_a_long_kinematics_batch(chain, default_sigint, name):
    fn = BATCHES[name]
    n = rows_for(lambda k: fn(chain, k), 4000)
    took = interrupted_after(lambda: fn(chain, n))
    assert took < 1.0, f"{name} of {n} rows (~{TARGET_S} s) took {took:.2f} s to stop"
    small = fn(chain, 10)
    assert (small[0] if isinstance(small, tuple) else small).shape[0] == 10


def test_ctrl_c_stops_a_long_ik_batch(default_sigint):
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    T = ur5_targets(4000)
    run = lambda k: am.ik_batch(m, "tool0", T[:k], seed=2)  # noqa: E731
    n = rows_for(run, 200)
    targets = np.concatenate([T] * (n // len(T) + 1))[:n]
    took = interrupted_after(lambda: am.ik_batch(m, "tool0", targets, seed=2))
    assert took < 1.0, f"ik_batch of {n} targets (~{TARGET_S} s) took {took:.2f} s to stop"
    # Afterwards: the same answers as before the interrupt.
    again = am.ik_batch(m, "tool0", T[:20], seed=2)
    np.testing.assert_array_equal(again["q"], am.ik_batch(m, "tool0", T[:20], seed=2)["q"])
    assert again["status"].count("converged") == 20


def test_ctrl_c_stops_a_long_crba_batch(default_sigint):
    """crba_batch reads the stop flag between chunks of 256 rows. CRBA walks every body's
    ancestors (quadratic in the depth), so the chain here has 200 bodies, not 2000: a
    chunk then takes tens of milliseconds."""
    m = am.Model.from_string(mimic_chain(200), "chain200.urdf")
    n = rows_for(lambda k: am.crba_batch(m, np.full((k, 1), 0.3)), 1024)
    took = interrupted_after(lambda: am.crba_batch(m, np.full((n, 1), 0.3)))
    assert took < 1.0, f"crba_batch of {n} rows (~{TARGET_S} s) took {took:.2f} s to stop"
    assert am.crba_batch(m, np.full((3, 1), 0.3)).shape == (3, 1, 1)


def test_small_batches_answer_as_before(chain):
    """Below the interruptible size the batch runs on the calling thread: same values."""
    q = np.array([[0.3], [-0.2]])
    T = am.fk_batch(chain, q, "l2000")
    d = chain.create_data()
    for k in range(2):
        am.forward_kinematics(chain, d, q[k])
        np.testing.assert_array_equal(T[k], d.frame_pose("l2000"))


def test_ctrl_c_stops_a_long_workspace_run(default_sigint):
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    # 2^28 samples take tens of seconds here; the flag is read every 65 536 samples.
    took = interrupted_after(
        lambda: am.workspace(m, samples=1 << 28, replicates=4, voxel=0.05, extras=False))
    assert took < 1.0, f"workspace took {took:.2f} s to stop"
    r = am.workspace(m, samples=1 << 18, replicates=4, voxel=0.05, extras=False)
    assert r["estimate"] > 0


def long_scenario(tmp_path):
    """The bundled planar 2R scenario simulated for 5000 s at 0.2 ms steps (minutes)."""
    text = (ROOT / "scenarios/planar_2r.toml").read_text()
    text = text.replace("../robots/planar_2r.toml", str(ROBOTS / "planar_2r.toml"))
    text = text.replace("dt = 0.001", "dt = 0.0002\nduration = 5000.0")
    path = tmp_path / "long.toml"
    path.write_text(text)
    return path


def test_ctrl_c_cancels_a_long_scenario_run_and_writes_nothing(default_sigint, tmp_path):
    out = tmp_path / "out"
    took = interrupted_after(lambda: am.run_scenario(long_scenario(tmp_path), out_dir=out))
    assert took < 1.0, f"run_scenario took {took:.2f} s to stop"
    # Cancelled: no recording, report, plot or temporary file (at most the empty directory).
    assert not out.exists() or list(out.iterdir()) == []
    # Afterwards a run works as before.
    r = am.run_scenario(ROOT / "scenarios/planar_2r.toml", out_dir=tmp_path / "again")
    assert r["simulation"]["interrupted"] is False
    assert (tmp_path / "again" / "planar_2r.json").exists()
