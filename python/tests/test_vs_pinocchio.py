"""armsim against Pinocchio (PyPI `pin`) on the bundled URDFs and on URDFs of PyPI
`example-robot-data`, at random states: FK placements of every frame, frame Jacobians
in the three expressions, RNEA, CRBA, ABA, gravity and nonlinear effects, to 1e-9
(relative to max(1, the largest entry)). Mimic joints are independent coordinates here,
as in Pinocchio's URDF parser; continuous joints take (cos, sin) in pin's q."""

from __future__ import annotations

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS, PinMap, assert_close, erd_robots, random_q

pin = pytest.importorskip("pinocchio")

URDFS = [
    ROBOTS / "ur5.urdf",
    ROBOTS / "panda.urdf",
    ROBOTS / "iiwa14.urdf",
    erd_robots() / "ur_description/urdf/ur5_robot.urdf",
    erd_robots() / "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
    erd_robots() / "kinova_description/robots/kinova.urdf",
    erd_robots() / "z1_description/urdf/z1.urdf",
    erd_robots() / "talos_data/robots/talos_left_arm.urdf",
    erd_robots() / "baxter_description/urdf/baxter.urdf",
]
STATES = 5
REFERENCES = {
    "local": pin.ReferenceFrame.LOCAL,
    "world": pin.ReferenceFrame.WORLD,
    "world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
}


def pin_frame(pm, name):
    """Pinocchio's BODY frame of URDF link `name` (armsim's frame of that link)."""
    return pm.getFrameId(name, pin.FrameType.BODY)


@pytest.fixture(params=URDFS, ids=lambda p: p.name)
def pair(request):
    path = request.param
    assert path.is_file(), f"{path} missing (pip install example-robot-data)"
    m = am.Model.from_file(path, ignore_mimic=True)
    pm = pin.buildModelFromUrdf(str(path))
    return m, pm, PinMap(m, pm)


def states(m, n, rng):
    for _ in range(n):
        yield random_q(m, rng), rng.normal(size=m.nv), rng.normal(size=m.nv)


def test_fk_placements_match_pin_for_every_frame(pair, rng):
    m, pm, mp = pair
    d, pd = m.create_data(), pm.createData()
    names = m.frame_names
    for q, _, _ in states(m, STATES, rng):
        am.forward_kinematics(m, d, q)
        pin.framesForwardKinematics(pm, pd, mp.q(q))
        for fid, name in enumerate(names):
            pf = pin_frame(pm, name)
            assert pf < len(pm.frames), name
            assert_close(d.frame_pose(fid), pd.oMf[pf].homogeneous, f"oMf[{name}]")


@pytest.mark.parametrize("ref", sorted(REFERENCES))
def test_frame_jacobians_match_pin_in_each_expression(pair, rng, ref):
    m, pm, mp = pair
    d, pd = m.create_data(), pm.createData()
    names = m.frame_names
    for q, _, _ in states(m, STATES, rng):
        for name in (names[-1], names[len(names) // 2]):
            j = am.frame_jacobian(m, d, q, m.frame_id(name), ref)
            pj = pin.computeFrameJacobian(pm, pd, mp.q(q), pin_frame(pm, name), REFERENCES[ref])
            assert_close(j, mp.from_v(pj), f"J[{name}, {ref}]")


def test_rnea_matches_pin(pair, rng):
    m, pm, mp = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, a in states(m, STATES, rng):
        tau = am.rnea(m, d, q, v, a)
        ptau = pin.rnea(pm, pd, mp.q(q), mp.v(v), mp.v(a))
        assert_close(tau, mp.from_v(ptau), "rnea")


def test_crba_matches_pin(pair, rng):
    m, pm, mp = pair
    d, pd = m.create_data(), pm.createData()
    for q, _, _ in states(m, STATES, rng):
        pmass = pin.crba(pm, pd, mp.q(q))
        pmass = np.triu(pmass) + np.triu(pmass, 1).T  # pin fills the upper triangle
        assert_close(am.crba(m, d, q), mp.from_vv(pmass), "crba")


def test_aba_matches_pin(pair, rng):
    m, pm, mp = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, _ in states(m, STATES, rng):
        tau = rng.normal(size=m.nv)
        ddq = am.aba(m, d, q, v, tau)
        pddq = pin.aba(pm, pd, mp.q(q), mp.v(v), mp.v(tau))
        assert_close(ddq, mp.from_v(pddq), "aba")


def test_gravity_and_nonlinear_effects_match_pin(pair, rng):
    m, pm, mp = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, _ in states(m, STATES, rng):
        g = am.compute_generalized_gravity(m, d, q)
        assert_close(g, mp.from_v(pin.computeGeneralizedGravity(pm, pd, mp.q(q))), "gravity")
        assert np.max(np.abs(g)) > 1e-3, "gravity must load some joint"
        h = am.nonlinear_effects(m, d, q, v)
        assert_close(h, mp.from_v(pin.nonLinearEffects(pm, pd, mp.q(q), mp.v(v))), "nle")


def test_batches_match_pin_row_by_row(pair, rng):
    m, pm, mp = pair
    pd = pm.createData()
    n = 40
    Q = np.array([random_q(m, rng) for _ in range(n)])
    V, A = rng.normal(size=(n, m.nv)), rng.normal(size=(n, m.nv))
    tau = am.rnea_batch(m, Q, V, A)
    ddq = am.aba_batch(m, Q, V, tau)
    frame = m.frame_names[-1]
    T = am.fk_batch(m, Q, frame)
    J = am.jacobian_batch(m, Q, frame, "local")
    pf = pin_frame(pm, frame)
    for i in range(n):
        pq = mp.q(Q[i])
        assert_close(tau[i], mp.from_v(pin.rnea(pm, pd, pq, mp.v(V[i]), mp.v(A[i]))), f"rnea_batch[{i}]")
        assert_close(ddq[i], A[i], f"aba_batch[{i}] inverts rnea_batch", tol=1e-7)
        pin.framesForwardKinematics(pm, pd, pq)
        assert_close(T[i], pd.oMf[pf].homogeneous, f"fk_batch[{i}]")
        pj = pin.computeFrameJacobian(pm, pd, pq, pf, pin.ReferenceFrame.LOCAL)
        assert_close(J[i], mp.from_v(pj), f"jacobian_batch[{i}]")


def test_crba_batch_matches_pin_crba_row_by_row(pair, rng):
    """am.crba_batch (eight rows at a time in SIMD lanes, plus a scalar tail: 43 rows)
    against pin.crba (upper triangle mirrored) on every row."""
    m, pm, mp = pair
    pd = pm.createData()
    n = 43
    Q = np.array([random_q(m, rng) for _ in range(n)])
    M = am.crba_batch(m, Q)
    assert M.shape == (n, m.nv, m.nv)
    for i in range(n):
        pmass = pin.crba(pm, pd, mp.q(Q[i]))
        pmass = np.triu(pmass) + np.triu(pmass, 1).T
        assert_close(M[i], mp.from_vv(pmass), f"crba_batch[{i}]")


def test_rnea_derivatives_match_pin(pair, rng):
    m, pm, mp = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, a in states(m, STATES, rng):
        dq, dv, mass = am.rnea_derivatives(m, d, q, v, a)
        pdq, pdv, pmass = pin.computeRNEADerivatives(pm, pd, mp.q(q), mp.v(v), mp.v(a))
        pmass = np.triu(pmass) + np.triu(pmass, 1).T
        assert_close(dq, mp.from_vv(pdq), "dtau_dq", tol=1e-8)
        assert_close(dv, mp.from_vv(pdv), "dtau_dv", tol=1e-8)
        assert_close(mass, mp.from_vv(pmass), "M", tol=1e-8)


def test_aba_derivatives_and_minverse_match_pin(pair, rng):
    m, pm, mp = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, _ in states(m, STATES, rng):
        tau = rng.normal(size=m.nv)
        dq, dv, minv = am.aba_derivatives(m, d, q, v, tau)
        pdq, pdv, pminv = pin.computeABADerivatives(pm, pd, mp.q(q), mp.v(v), mp.v(tau))
        pminv = np.triu(pminv) + np.triu(pminv, 1).T
        assert_close(dq, mp.from_vv(pdq), "ddq_dq", tol=1e-8)
        assert_close(dv, mp.from_vv(pdv), "ddq_dv", tol=1e-8)
        assert_close(minv, mp.from_vv(pminv), "Minv", tol=1e-8)
        pminv2 = pin.computeMinverse(pm, pd, mp.q(q))
        pminv2 = np.triu(pminv2) + np.triu(pminv2, 1).T
        assert_close(am.compute_minverse(m, d, q), mp.from_vv(pminv2), "computeMinverse", tol=1e-8)
