"""Pickling (issue 31): ``Model``, ``Data`` and ``Robot`` survive ``pickle`` and
``copy.deepcopy`` and compute bit-for-bit what the originals compute; a ``Data`` keeps
what Python can read from it (frame placements, ``tau``, ``ddq``) and its model's size."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS

Q = np.array([0.1, -1.0, 1.2, -0.3, 1.4, 0.2])
V = np.array([0.5, -0.2, 0.3, 1.0, -0.7, 0.1])


def roundtrips(x):
    return [pickle.loads(pickle.dumps(x)), copy.deepcopy(x)]


def test_robot_pickles_and_computes_bit_for_bit():
    r = am.Robot.from_file(ROBOTS / "ur5.urdf")
    T = r.fk(Q, "tool0")
    for r2 in roundtrips(r):
        assert isinstance(r2, am.Robot) and r2.joint_names == r.joint_names
        np.testing.assert_array_equal(r2.fk(Q, "tool0"), T)
        np.testing.assert_array_equal(r2.jacobian(Q, "tool0", "local"), r.jacobian(Q, "tool0", "local"))
        np.testing.assert_array_equal(r2.rnea(Q, V, V), r.rnea(Q, V, V))
        np.testing.assert_array_equal(r2.aba(Q, V, V), r.aba(Q, V, V))
        np.testing.assert_array_equal(r2.crba(Q), r.crba(Q))
        a, b = r.ik(T, "tool0", seed=7), r2.ik(T, "tool0", seed=7)
        assert a.status == b.status == "converged"
        np.testing.assert_array_equal(a.q, b.q)


def test_robot_keeps_its_gravity_through_pickling():
    """A Robot computes with its model's gravity as it was when the robot was made;
    the pickled one computes the same."""
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    m.gravity = [0.0, 0.0, -1.62]
    r = am.Robot(m)
    m.gravity = [0.0, 0.0, -3.71]
    g = r.gravity(Q)
    np.testing.assert_allclose(g, am.gravity(m, m.create_data(), Q) * 1.62 / 3.71, rtol=1e-12, atol=1e-12)
    for r2 in roundtrips(r):
        np.testing.assert_array_equal(r2.gravity(Q), g)
        np.testing.assert_array_equal(r2.model.gravity, [0.0, 0.0, -3.71])


def test_data_pickles_with_its_results_and_model_size():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    d = m.create_data()
    am.forward_kinematics(m, d, Q)
    tau = am.rnea(m, d, Q, V, V).copy()
    ddq = am.aba(m, d, Q, V, tau).copy()
    am.forward_kinematics(m, d, Q)
    poses = [d.frame_pose(f) for f in range(len(m.frame_names))]
    assert np.abs(d.tau).max() > 0 and np.abs(d.ddq).max() > 0
    for d2 in roundtrips(d):
        assert isinstance(d2, am.Data) and d2.nv == d.nv == m.nv
        np.testing.assert_array_equal(d2.tau, tau)
        np.testing.assert_array_equal(d2.ddq, ddq)
        for f, want in enumerate(poses):
            np.testing.assert_array_equal(d2.frame_pose(f), want)
        # It serves its model, and computes what a fresh workspace computes.
        np.testing.assert_array_equal(am.rnea(m, d2, V, Q, Q), am.rnea(m, m.create_data(), V, Q, Q))
    panda = am.Model.from_file(ROBOTS / "panda.urdf")
    d3 = pickle.loads(pickle.dumps(panda.create_data()))
    assert d3.nv == panda.nv != m.nv and d3.tau.shape == (panda.nv,)
    with pytest.raises(am.ArmsimError, match="data was created for 'panda'"):
        am.rnea(m, d3, Q, V, V)


def test_model_and_data_pickled_together_stay_together():
    m = am.Model.from_file(ROBOTS / "panda.urdf")
    m.gravity = [0.0, 0.0, -1.0]
    d = m.create_data()
    m2, d2 = pickle.loads(pickle.dumps((m, d)))
    q = m.neutral()
    np.testing.assert_array_equal(am.gravity(m2, d2, q), am.gravity(m, d, q))
    np.testing.assert_array_equal(m2.gravity, [0.0, 0.0, -1.0])
    m3 = copy.deepcopy(m)
    np.testing.assert_array_equal(am.crba(m3, m3.create_data(), q), am.crba(m, d, q))


def test_a_corrupt_data_state_is_refused():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    ctor, (model, placements, tau, ddq) = m.create_data().__reduce__()
    with pytest.raises(am.ArmsimError, match="Data state: tau has 5 values, the model 'ur5' needs 6"):
        ctor(model, placements, tau[:5], ddq)
    with pytest.raises(am.ArmsimError, match="Data state: placements has"):
        ctor(model, placements[:-1], tau, ddq)
