"""The Python API on its own: DH tables against closed forms, pickling, the Robot
facade with IK, batches against single calls, scenarios and workspace sampling."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS, ROOT, random_q

G, L, M1, M2 = 9.81, 0.5, 2.0, 1.0  # robots/planar_2r.toml


def planar_2r_closed_form(q1, q2):
    """The textbook 2R arm's gravity torques and mass matrix (robots/planar_2r.toml)."""
    g1 = (M1 / 2 + M2) * G * L * np.cos(q1) + M2 / 2 * G * L * np.cos(q1 + q2)
    g2 = M2 / 2 * G * L * np.cos(q1 + q2)
    m11 = M1 * L**2 / 3 + M2 * L**2 * (4 / 3 + np.cos(q2))
    m12 = M2 * L**2 * (1 / 3 + np.cos(q2) / 2)
    m22 = M2 * L**2 / 3
    return np.array([g1, g2]), np.array([[m11, m12], [m12, m22]])


def test_dh_table_gravity_and_mass_matrix_match_the_closed_form():
    m = am.Model.from_file(ROBOTS / "planar_2r.toml")
    d = m.create_data()
    assert (m.nq, m.nv) == (2, 2) and all(m.is_continuous(k) for k in range(2))
    for q in ([0.0, 0.0], [0.3, -1.1], [2.0, 0.7]):
        g, mass = planar_2r_closed_form(*q)
        np.testing.assert_allclose(am.compute_generalized_gravity(m, d, q), g, rtol=0, atol=1e-12)
        np.testing.assert_allclose(am.crba(m, d, q), mass, rtol=0, atol=1e-12)
        np.testing.assert_allclose(am.rnea(m, d, q, [0, 0], [0, 0]), g, rtol=0, atol=1e-12)
    assert abs(am.gravity(m, d, [0.0, 0.0])[0] - 12.2625) < 1e-12


def test_forward_kinematics_of_the_2r_tip_is_the_planar_closed_form():
    m = am.Model.from_file(ROBOTS / "planar_2r.toml")
    d = m.create_data()
    q1, q2 = 0.4, 0.9
    am.forward_kinematics(m, d, np.array([q1, q2]))
    T = d.frame_pose(m.frame_id("tool"))
    want = [L * np.cos(q1) + L * np.cos(q1 + q2), 0.0, L * np.sin(q1) + L * np.sin(q1 + q2)]
    np.testing.assert_allclose(T[:3, 3], want, atol=1e-12)
    np.testing.assert_allclose(T[3], [0, 0, 0, 1])


def test_pickled_model_computes_the_same_and_keeps_gravity():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    m.gravity = [0.0, 0.0, -3.71]
    m2 = pickle.loads(pickle.dumps(m))
    assert m2.nq == m.nq and m2.joint_names == m.joint_names
    np.testing.assert_array_equal(m2.gravity, [0.0, 0.0, -3.71])
    q = np.array([0.1, -1.0, 1.2, -0.3, 1.4, 0.2])
    t1 = am.rnea(m, m.create_data(), q, np.ones(6), np.zeros(6))
    t2 = am.rnea(m2, m2.create_data(), q, np.ones(6), np.zeros(6))
    np.testing.assert_array_equal(t1, t2)


def test_gravity_setter_scales_the_holding_torques():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    q = np.array([0.1, -1.0, 1.2, -0.3, 1.4, 0.2])
    d = m.create_data()
    g1 = am.gravity(m, d, q).copy()
    m.gravity = [0.0, 0.0, -9.81 / 2]
    # The workspace made before the change serves the changed model.
    np.testing.assert_allclose(am.gravity(m, d, q), g1 / 2, rtol=1e-12, atol=1e-12)


def test_robot_ik_recovers_a_reachable_pose_and_names_an_unreachable_one():
    r = am.Robot.from_file(ROBOTS / "ur5.urdf")
    q = np.array([0.3, -1.2, 1.4, -0.5, 1.2, 0.4])
    T = r.fk(q, "tool0")
    sol = r.ik(T, "tool0", seed=3)
    assert sol.converged and sol.status == "converged", sol.reason
    assert sol.position_error <= 1e-6 and sol.rotation_error <= 1e-6
    np.testing.assert_allclose(r.fk(sol.q, "tool0"), T, atol=1e-5)
    far = am.pose(translation=[3.0, 0.0, 0.5])
    bad = r.ik(far, "tool0", max_restarts=5)
    assert bad.status == "unreachable" and not bad.converged
    assert bad.position_error > 1.0 and "out of reach" in bad.reason


def test_the_default_frame_is_the_tool_at_the_end_of_the_serial_chain():
    # The UR5's last link is `base` (fixed to the world); the default is `tool0`. The
    # Panda's hand carries the fingers; the default is the hand's TCP.
    for file, tool in [("ur5.urdf", "tool0"), ("panda.urdf", "panda_hand_tcp")]:
        r = am.Robot.from_file(ROBOTS / file)
        q = (r.model.lower_limits + r.model.upper_limits) / 2 + 0.1
        np.testing.assert_array_equal(r.fk(q), r.fk(q, tool))
        _, T = am.sample_poses(r.model, 3, seed=1)
        _, T_tool = am.sample_poses(r.model, 3, seed=1, frame=tool)
        np.testing.assert_array_equal(T, T_tool)


def test_robot_methods_agree_with_the_model_data_functions(rng):
    r = am.Robot.from_file(ROBOTS / "panda.urdf")
    m = r.model
    d = m.create_data()
    q, v, a = random_q(m, rng), rng.normal(size=m.nv), rng.normal(size=m.nv)
    am.forward_kinematics(m, d, q)
    np.testing.assert_array_equal(r.fk(q, "panda_link8"), d.frame_pose("panda_link8"))
    np.testing.assert_array_equal(r.jacobian(q, "panda_link8", "world"),
                                  am.frame_jacobian(m, d, q, "panda_link8", "world"))
    np.testing.assert_array_equal(r.rnea(q, v, a), am.rnea(m, d, q, v, a))
    np.testing.assert_allclose(r.aba(q, v, r.rnea(q, v, a)), a, atol=1e-8)
    np.testing.assert_array_equal(r.crba(q), am.crba(m, d, q))
    np.testing.assert_array_equal(r.gravity(q), r.rnea(q))


def test_batches_equal_the_single_calls(rng):
    m = am.Model.from_file(ROBOTS / "iiwa14.urdf")
    d = m.create_data()
    n = 100
    Q = np.array([random_q(m, rng) for _ in range(n)])
    V, A = rng.normal(size=(n, m.nv)), rng.normal(size=(n, m.nv))
    tau = am.rnea_batch(m, Q, V, A)
    ddq = am.aba_batch(m, Q, V, tau)
    grav = am.gravity_batch(m, Q)
    for i in range(0, n, 7):
        # RNEA and ABA batches run eight rows at a time in SIMD lanes: the single call's
        # operations in another order, so equal to rounding.
        np.testing.assert_allclose(tau[i], am.rnea(m, d, Q[i], V[i], A[i]), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(ddq[i], am.aba(m, d, Q[i], V[i], tau[i]), rtol=1e-10, atol=1e-10)
        np.testing.assert_array_equal(grav[i], am.gravity(m, d, Q[i]))
    # Fortran-ordered input is read correctly too.
    np.testing.assert_array_equal(am.rnea_batch(m, np.asfortranarray(Q), V, A), tau)


def test_crba_batch_equals_the_single_call_on_every_row(rng):
    """Lanes (eight rows at a time), the scalar tail (the last n mod 8 rows) and a group
    with a joint value out of the lane sin_cos's range (scalar) all equal am.crba."""
    for name in ["iiwa14.urdf", "panda.urdf", "ur5.urdf"]:
        m = am.Model.from_file(ROBOTS / name)
        d = m.create_data()
        n = 37
        Q = np.array([random_q(m, rng) for _ in range(n)])
        Q[9, 0] = 2e4  # rows 8..15 go through the scalar code
        M = am.crba_batch(m, Q)
        assert M.shape == (n, m.nv, m.nv)
        for i in range(n):
            want = am.crba(m, d, Q[i])
            np.testing.assert_allclose(M[i], want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
            np.testing.assert_array_equal(M[i], M[i].T)
        # Fortran order, float32, ints and lists are read as the single call reads them.
        np.testing.assert_array_equal(am.crba_batch(m, np.asfortranarray(Q)), M)
        q32 = Q[:3].astype(np.float32)
        np.testing.assert_array_equal(am.crba_batch(m, q32), am.crba_batch(m, q32.astype(np.float64)))
        np.testing.assert_array_equal(am.crba_batch(m, [[0] * m.nv]), am.crba_batch(m, np.zeros((1, m.nv))))
        assert am.crba_batch(m, np.zeros((0, m.nv))).shape == (0, m.nv, m.nv)


def test_ik_batch_solves_sampled_poses_and_shards_reproduce_the_whole():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    q, T = am.sample_poses(m, 24, seed=5, frame="tool0")
    whole = am.ik_batch(m, "tool0", T, seed=11)
    assert whole["q"].shape == (24, 6)
    assert whole["status"].count("converged") == 24, whole["reason"]
    got = am.fk_batch(m, whole["q"], "tool0")
    np.testing.assert_allclose(got, T, atol=1e-5)
    parts = [am.ik_batch(m, "tool0", T[s:s + 10], start=s, seed=11) for s in (0, 10, 20)]
    np.testing.assert_array_equal(np.concatenate([p["q"] for p in parts]), whole["q"])


def test_sample_poses_depends_only_on_seed_and_index():
    m = am.Model.from_file(ROBOTS / "panda.urdf")
    q, T = am.sample_poses(m, 1000, seed=9)
    q2, T2 = am.sample_poses(m, 300, seed=9, start=700)
    np.testing.assert_array_equal(q[700:], q2)
    np.testing.assert_array_equal(T[700:], T2)
    assert np.all(q >= m.lower_limits) and np.all(q <= m.upper_limits)
    assert not np.array_equal(am.sample_poses(m, 10, seed=10)[0], q[:10])


def test_workspace_of_the_2r_arm_covers_the_disc_area():
    m = am.Model.from_file(ROBOTS / "planar_2r.toml")
    w = am.workspace(m, samples=1 << 16, seed=1)
    assert w["planar"] and w["unit"] == "m^2"
    lo, hi = w["interval"]
    assert lo <= np.pi <= hi, (lo, hi)  # reach 1 m, full turns: a disc of area pi
    assert w["points"].shape == (1000, 3) and w["q"].shape == (1000, 2)
    assert np.all(np.linalg.norm(w["points"], axis=1) <= 1.0 + 1e-12)


def test_run_scenario_returns_the_report_and_writes_the_files(tmp_path):
    r = am.run_scenario(ROOT / "scenarios/planar_2r.toml", out_dir=tmp_path)
    assert r["scenario"] == "planar_2r" and r["model"]["joints"] == ["joint1", "joint2"]
    assert r["ok"] is True and len(r["torque_check"]) == 2
    assert (tmp_path / "planar_2r.json").is_file()
    assert all(0 < t["peak_torque"] < 30 for t in r["torque_check"])
