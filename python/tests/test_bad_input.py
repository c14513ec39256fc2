"""Broken inputs raise Python exceptions that name the problem; nothing crashes."""

from __future__ import annotations

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS


@pytest.fixture(scope="module")
def ur5():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    return m, m.create_data()


def test_missing_file_is_file_not_found_naming_the_path(tmp_path):
    path = tmp_path / "nope.urdf"
    with pytest.raises(FileNotFoundError, match="nope.urdf: no such file"):
        am.Model.from_file(path)
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        am.run_scenario(tmp_path / "nope.toml")


def test_broken_urdf_names_file_line_and_element(tmp_path):
    text = (ROBOTS / "ur5.urdf").read_text()
    lines = text.splitlines()
    line = next(i for i, l in enumerate(lines) if '<joint name="elbow_joint" type=' in l) + 1
    bad = tmp_path / "bad.urdf"
    bad.write_text(text.replace('<child link="forearm_link"', '<child link="no_such_link"'))
    with pytest.raises(am.ArmsimError) as e:
        am.Model.from_file(bad)
    msg = str(e.value)
    assert f"bad.urdf:{line}: joint 'elbow_joint'" in msg and "no_such_link" in msg, msg
    truncated = tmp_path / "cut.urdf"
    truncated.write_text(text[: len(text) // 2])
    with pytest.raises(am.ArmsimError, match="cut.urdf"):
        am.Model.from_file(truncated)
    assert issubclass(am.ArmsimError, ValueError)


def test_wrong_length_q_is_refused(ur5):
    m, d = ur5
    with pytest.raises(am.ArmsimError, match="q: 5 values for 6 coordinates"):
        am.forward_kinematics(m, d, np.zeros(5))
    with pytest.raises(am.ArmsimError, match="v: 7 values for 6 coordinates"):
        am.rnea(m, d, np.zeros(6), np.zeros(7), np.zeros(6))
    with pytest.raises(am.ArmsimError, match=r"Q: shape \(4, 5\), expected \(N, 6\)"):
        am.rnea_batch(m, np.zeros((4, 5)), np.zeros((4, 6)), np.zeros((4, 6)))
    with pytest.raises(am.ArmsimError, match="V has 3 rows but Q has 4"):
        am.rnea_batch(m, np.zeros((4, 6)), np.zeros((3, 6)), np.zeros((4, 6)))


def test_nan_in_q_is_refused_with_its_index(ur5):
    m, d = ur5
    q = np.zeros(6)
    q[2] = np.nan
    with pytest.raises(am.ArmsimError, match=r"q\[2\] is not finite"):
        am.rnea(m, d, q, np.zeros(6), np.zeros(6))
    with pytest.raises(am.ArmsimError, match=r"q\[2\] is not finite"):
        am.Robot(m).fk(q)
    Q = np.zeros((5, 6))
    Q[3, 1] = np.inf
    with pytest.raises(am.ArmsimError, match=r"Q\[3, 1\] is not finite"):
        am.fk_batch(m, Q, "tool0")


def test_bad_frame_reference_target_and_data_are_refused(ur5):
    m, d = ur5
    with pytest.raises(am.ArmsimError, match="no frame 'hand'.*tool0"):
        m.frame_id("hand")
    with pytest.raises(am.ArmsimError, match="frame index 99 does not exist"):
        d.frame_pose(99)
    with pytest.raises(am.ArmsimError, match="unknown reference frame 'body'"):
        am.frame_jacobian(m, d, m.neutral(), 3, "body")
    with pytest.raises(am.ArmsimError, match="rotation is not orthonormal"):
        am.Robot(m).ik(np.diag([2.0, 1.0, 1.0, 1.0]), "tool0")
    panda = am.Model.from_file(ROBOTS / "panda.urdf")
    with pytest.raises(am.ArmsimError, match="data was created for 'ur5'.*not for 'panda'"):
        am.rnea(panda, d, np.zeros(panda.nv), np.zeros(panda.nv), np.zeros(panda.nv))
    with pytest.raises(am.ArmsimError, match="unknown IK option 'tolerance'"):
        am.Robot(m).ik(np.eye(4), "tool0", tolerance=1e-3)
    with pytest.raises(am.ArmsimError, match="expected a 1-D sequence"):
        am.rnea(m, d, "abc", np.zeros(6), np.zeros(6))


def test_overflowing_dynamics_raise_naming_the_quantity(ur5):
    """Issue 28: a result that is not finite raises (ValueError), naming the quantity,
    the joint and the inputs, instead of returning NaN."""
    m, d = ur5
    q, v = np.zeros(m.nv), np.zeros(m.nv)
    v[0] = 1e200
    with pytest.raises(ValueError, match=r"tau of joint 'shoulder_pan_joint' is not finite.*\|v\| 1e200"):
        am.rnea(m, d, q, v, np.zeros(m.nv))
    with pytest.raises(ValueError, match="the nonlinear effects of joint"):
        am.nonlinear_effects(m, d, q, v)
    with pytest.raises(ValueError, match=r"row 0: tau of joint"):
        am.rnea_batch(m, q[None, :], v[None, :], np.zeros((1, m.nv)))
    # Row 9 of 16: inside the second group of eight SIMD lanes.
    V = np.zeros((16, m.nv))
    V[9, 0] = 1e200
    with pytest.raises(ValueError, match=r"row 9: tau of joint 'shoulder_pan_joint'"):
        am.rnea_batch(m, np.zeros((16, m.nv)), V, np.zeros((16, m.nv)))
    with pytest.raises(ValueError, match=r"row 9: "):
        am.aba_batch(m, np.zeros((16, m.nv)), V, np.zeros((16, m.nv)))


def test_huge_batches_and_far_targets_raise_instead_of_aborting(ur5):
    """Issue 28: a result too large to allocate raises (the interpreter survives), and a
    target beyond 1e9 m is refused before IK sees it."""
    m, _ = ur5
    with pytest.raises(am.ArmsimError, match=r"sample_poses: a result of 1000000000000 rows .* cannot be allocated"):
        am.sample_poses(m, 10**12)
    far = np.eye(4)
    far[0, 3] = 1e300
    with pytest.raises(am.ArmsimError, match=r"beyond the 1e\+?0?9 m accepted"):
        am.Robot(m).ik(far, "tool0")


def test_pose_and_workspace_refuse_what_the_cli_refuses(ur5):
    m, _ = ur5
    with pytest.raises(am.ArmsimError, match="not finite"):
        am.pose(np.full((3, 3), np.nan))
    with pytest.raises(am.ArmsimError, match="not orthonormal"):
        am.pose(np.diag([2.0, 1.0, 1.0]))
    with pytest.raises(am.ArmsimError, match="beyond 1e9 m"):
        am.pose(translation=[np.inf, 0.0, 0.0])
    assert np.allclose(am.pose(np.eye(3), [1.0, 2.0, 3.0])[:3, 3], [1.0, 2.0, 3.0])
    with pytest.raises(am.ArmsimError, match="samples must be positive"):
        am.workspace(m, samples=0)


def test_workspace_warns_when_the_estimate_is_only_a_lower_bound():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    with pytest.warns(UserWarning, match="only a lower bound"):
        r = am.workspace(m, samples=2**10, replicates=8, keep_points=0)
    assert r["interval_kind"] == "lower_bound"


def test_run_scenario_refuses_a_robot_file_and_says_what_reads_it():
    with pytest.raises(am.ArmsimError, match="Model.from_file"):
        am.run_scenario(ROBOTS / "ur5.urdf")
    with pytest.raises(am.ArmsimError, match="srdf="):
        am.run_scenario("robot.srdf")


def test_distributed_does_not_send_users_to_the_unrelated_pypi_package():
    import armsim.distributed as dist
    assert "needs ``pip install armsim``" not in dist.__doc__
    assert "unrelated package" in dist.__doc__


def test_batches_accept_what_single_calls_accept_float32_ints_and_lists():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    rng = np.random.default_rng(3)
    Q = rng.uniform(-1, 1, (5, m.nv))
    Z = np.zeros((5, m.nv))
    want = am.rnea_batch(m, Q, Z, Z)
    q32 = Q.astype(np.float32)
    got = am.rnea_batch(m, q32, Z.astype(np.int64), Z.tolist())
    np.testing.assert_allclose(got, am.rnea_batch(m, q32.astype(np.float64), Z, Z), rtol=0, atol=0)
    np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-5)
    single = am.rnea(m, m.create_data(), q32[0], Z[0].astype(int), Z[0].tolist())
    np.testing.assert_array_equal(got[0], single)
    T = am.fk_batch(m, Q, "tool0")
    r = am.ik_batch(m, "tool0", T.astype(np.float32).astype(np.float64).tolist(), seed=1)
    assert len(r["status"]) == 5
    with pytest.raises(am.ArmsimError, match=r"Q: expected numbers of shape \(N, 6\), got ndarray of dtype <U"):
        am.rnea_batch(m, np.array([["a"] * m.nv]), Z, Z)
    with pytest.raises(am.ArmsimError, match=r"V: expected shape \(N, 6\), got \(5,\)"):
        am.rnea_batch(m, Q, np.zeros(5), Z)


def test_crba_batch_errors_name_the_argument_and_the_row(ur5):
    m, _ = ur5
    Q = np.zeros((10, m.nv))
    Q[7, 2] = np.nan
    with pytest.raises(am.ArmsimError, match=r"^Q\[7, 2\] is not finite$"):
        am.crba_batch(m, Q)
    with pytest.raises(am.ArmsimError, match=r"^Q: shape \(4, 5\), expected \(N, 6\)$"):
        am.crba_batch(m, np.zeros((4, 5)))
    with pytest.raises(am.ArmsimError, match=r"Q: expected numbers of shape \(N, 6\)"):
        am.crba_batch(m, np.array([["a"] * m.nv]))


def test_negative_sizes_and_seeds_raise_value_errors_naming_the_argument(ur5):
    """Issue 31: counts, indices and seeds are checked with a message naming the
    argument (no bare OverflowError)."""
    m, _ = ur5
    T = am.fk_batch(m, np.zeros((2, 6)), "tool0")
    cases = [
        (lambda: am.sample_poses(m, -1), "n"),
        (lambda: am.sample_poses(m, 4, seed=-3), "seed"),
        (lambda: am.sample_poses(m, 4, start=-1), "start"),
        (lambda: am.ik_batch(m, "tool0", T, start=-2), "start"),
        (lambda: am.ik_batch(m, "tool0", T, seed=-1), "IK option seed"),
        (lambda: am.ik_batch(m, "tool0", T, max_restarts=-1), "IK option max_restarts"),
        (lambda: am.Robot(m).ik(T[0], "tool0", max_iterations=-5), "IK option max_iterations"),
        (lambda: am.workspace(m, samples=-1), "samples"),
        (lambda: am.workspace(m, seed=-1), "seed"),
        (lambda: am.workspace(m, replicates=-8), "replicates"),
        (lambda: am.workspace(m, keep_points=-1), "keep_points"),
        (lambda: m.is_continuous(-1), "k"),
        (lambda: am.plan(m, m.neutral(), m.neutral(), seed=-1), "seed"),
        (lambda: am.Robot(m).plan(m.neutral(), m.neutral(), seed=-1), "seed"),
        (lambda: am.Planner(m, seed=-1), "seed"),
    ]
    for call, name in cases:
        with pytest.raises(ValueError, match=rf"^{name}: expected a non-negative integer, got -\d+$"):
            call()
    with pytest.raises(ValueError, match=r"^seed: 18446744073709551616 is larger than the largest accepted, 18446744073709551615$"):
        am.sample_poses(m, 1, seed=2**64)
    # The largest seed and position still work.
    q, _ = am.sample_poses(m, 2, seed=2**64 - 1, start=2**64 - 2)
    assert q.shape == (2, 6)
    with pytest.raises(TypeError, match="'n'"):
        am.sample_poses(m, 1.5)


HUGE = 2**200  # beyond i128, where pyo3's own conversion raises a bare OverflowError


def test_integers_beyond_128_bits_raise_value_errors_naming_the_argument(ur5):
    """Issue 31: a Python integer of any size is refused with the argument's name, not a
    bare OverflowError ("int too big to convert")."""
    m, _ = ur5
    T = am.fk_batch(m, np.zeros((2, 6)), "tool0")
    u64, usize = 2**64 - 1, 2**64 - 1
    positive = [
        (lambda x: am.sample_poses(m, x), "n", usize),
        (lambda x: am.sample_poses(m, 4, seed=x), "seed", u64),
        (lambda x: am.sample_poses(m, 4, start=x), "start", u64),
        (lambda x: am.ik_batch(m, "tool0", T, start=x), "start", u64),
        (lambda x: am.ik_batch(m, "tool0", T, seed=x), "IK option seed", u64),
        (lambda x: am.ik_batch(m, "tool0", T, max_restarts=x), "IK option max_restarts", usize),
        (lambda x: am.Robot(m).ik(T[0], "tool0", max_iterations=x), "IK option max_iterations", usize),
        (lambda x: am.workspace(m, samples=x), "samples", u64),
        (lambda x: am.workspace(m, seed=x), "seed", u64),
        (lambda x: am.workspace(m, replicates=x), "replicates", usize),
        (lambda x: am.workspace(m, keep_points=x), "keep_points", usize),
        (lambda x: m.is_continuous(x), "k", usize),
        (lambda x: am.plan(m, m.neutral(), m.neutral(), seed=x), "seed", u64),
        (lambda x: am.Planner(m, seed=x), "seed", u64),
    ]
    for call, name, largest in positive:
        with pytest.raises(ValueError, match=rf"^{name}: {HUGE} is larger than the largest accepted, {largest}$"):
            call(HUGE)
        with pytest.raises(ValueError, match=rf"^{name}: expected a non-negative integer, got -{HUGE}$"):
            call(-HUGE)
    # Just beyond i128 on either side, and an integer too long to print.
    with pytest.raises(ValueError, match=rf"^seed: {2**127} is larger than"):
        am.sample_poses(m, 4, seed=2**127)
    with pytest.raises(ValueError, match=rf"^seed: expected a non-negative integer, got {-(2**127) - 1}$"):
        am.sample_poses(m, 4, seed=-(2**127) - 1)
    with pytest.raises(ValueError, match=r"^n: an integer of 20001 bits is larger than"):
        am.sample_poses(m, 2**20000)
    # A frame index: the frame does not exist.
    with pytest.raises(ValueError, match=rf"^frame index {HUGE} does not exist \(ur5 has \d+ frames\)$"):
        am.frame_jacobian(m, m.create_data(), np.zeros(6), HUGE)
    with pytest.raises(ValueError, match=rf"^frame index -{HUGE} does not exist"):
        am.fk_batch(m, np.zeros((2, 6)), -HUGE)
    # numpy integers are integers too.
    with pytest.raises(ValueError, match=r"^n: expected a non-negative integer, got -3$"):
        am.sample_poses(m, np.int64(-3))
