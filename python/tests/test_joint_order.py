"""Joint order against Pinocchio (issue 31): on example-robot-data trees whose order
differs between the libraries, ``am.from_pinocchio_order`` / ``am.to_pinocchio_order``
make a pin-ordered ``q`` give pin's dynamics in armsim, round-trip, handle continuous
joints (pin's cos, sin), and refuse what they cannot map, naming the joint."""

from __future__ import annotations

import numpy as np
import pytest

import armsim as am
from conftest import erd_robots

pin = pytest.importorskip("pinocchio")

ANYMAL = erd_robots() / "anymal_b_simple_description/robots/anymal.urdf"
PR2 = erd_robots() / "pr2_description/urdf/pr2.urdf"
PANDA = erd_robots() / "panda_description/urdf/panda.urdf"


def load(path, **kw):
    assert path.is_file(), f"{path} missing (pip install example-robot-data)"
    return am.Model.from_file(path, ignore_mimic=True, **kw), pin.buildModelFromUrdf(str(path))


def pin_q(pm, rng):
    """A random configuration in pin's layout (continuous joints: a unit (cos, sin))."""
    lo = np.where(np.isfinite(pm.lowerPositionLimit), pm.lowerPositionLimit, -1.0)
    hi = np.where(np.isfinite(pm.upperPositionLimit), pm.upperPositionLimit, 1.0)
    q = rng.uniform(np.maximum(lo, -3.0), np.minimum(hi, 3.0))
    for j in pm.joints[1:]:
        if j.nq == 2:
            th = rng.uniform(-np.pi, np.pi)
            q[j.idx_q:j.idx_q + 2] = np.cos(th), np.sin(th)
    return q


@pytest.mark.filterwarnings("ignore::armsim.LoaderWarning")
@pytest.mark.parametrize("path", [ANYMAL, PR2], ids=["anymal", "pr2"])
def test_a_pin_ordered_state_converted_gives_pins_rnea(path, rng):
    m, pm = load(path)
    assert m.joint_names != list(pm.names)[1:1 + m.nv], "the orders must differ for this test"
    d, pd = m.create_data(), pm.createData()
    for _ in range(3):
        q, v, a = pin_q(pm, rng), rng.normal(size=pm.nv), rng.normal(size=pm.nv)
        want = pin.rnea(pm, pd, q, v, a)
        tau = am.rnea(m, d, am.from_pinocchio_order(m, pm, q),
                      am.from_pinocchio_order(m, pm, v), am.from_pinocchio_order(m, pm, a))
        got = am.to_pinocchio_order(m, pm, tau, kind="v")
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * max(1.0, np.abs(want).max()))
    if pm.nq == pm.nv:
        # The trap the helpers exist for: the unconverted q has the right length and
        # gives other torques.
        wrong = am.rnea(m, d, q, v, a)
        assert np.abs(wrong - am.from_pinocchio_order(m, pm, want)).max() > 1e-3


@pytest.mark.filterwarnings("ignore::armsim.LoaderWarning")
def test_conversions_round_trip_vectors_and_batches(rng):
    m, pm = load(ANYMAL)
    q = pin_q(pm, rng)
    x = am.from_pinocchio_order(m, pm, q)
    assert x.shape == (m.nv,)
    np.testing.assert_array_equal(am.to_pinocchio_order(m, pm, x), q)
    Q = np.stack([pin_q(pm, rng) for _ in range(7)])
    X = am.from_pinocchio_order(m, pm, Q)
    assert X.shape == (7, m.nv)
    np.testing.assert_array_equal(X[3], am.from_pinocchio_order(m, pm, Q[3]))
    np.testing.assert_array_equal(am.to_pinocchio_order(m, pm, X), Q)
    # Each coordinate lands on the joint of the same name.
    names = list(pm.names)
    for k, name in enumerate(m.joint_names):
        assert x[k] == q[pm.joints[names.index(name)].idx_q]
    # Lists are accepted as arrays are.
    np.testing.assert_array_equal(am.from_pinocchio_order(m, pm, q.tolist()), x)


@pytest.mark.filterwarnings("ignore::armsim.LoaderWarning")
def test_continuous_joints_convert_between_an_angle_and_cos_sin(rng):
    m, pm = load(PR2)
    assert pm.nq > pm.nv, "pr2 has continuous joints"
    q = pin_q(pm, rng)
    x = am.from_pinocchio_order(m, pm, q)  # length nq: a configuration
    np.testing.assert_allclose(am.to_pinocchio_order(m, pm, x, kind="q"), q, rtol=0, atol=1e-15)
    theta = rng.uniform(-np.pi, np.pi, m.nv)
    np.testing.assert_allclose(
        am.from_pinocchio_order(m, pm, am.to_pinocchio_order(m, pm, theta, kind="q")),
        theta, rtol=0, atol=1e-14)
    v = rng.normal(size=pm.nv)
    np.testing.assert_array_equal(
        am.to_pinocchio_order(m, pm, am.from_pinocchio_order(m, pm, v), kind="v"), v)
    with pytest.raises(am.ArmsimError, match="kind: pin_model has continuous joints.*kind='q'"):
        am.to_pinocchio_order(m, pm, x)
    with pytest.raises(am.ArmsimError, match=f"x: 5 values, but pin_model has nq={pm.nq}"):
        am.from_pinocchio_order(m, pm, np.zeros(5))


@pytest.mark.filterwarnings("ignore::armsim.LoaderWarning")
def test_what_cannot_be_mapped_is_refused_naming_the_joint():
    m, pm = load(ANYMAL)
    ff = pin.buildModelFromUrdf(str(ANYMAL), pin.JointModelFreeFlyer())
    with pytest.raises(ValueError, match="joint 'root_joint' .*nq=7, nv=6.* free-flyer"):
        am.from_pinocchio_order(m, ff, np.zeros(ff.nq))
    other = am.Model.from_file(erd_robots() / "ur_description/urdf/ur5_robot.urdf")
    with pytest.raises(am.ArmsimError, match="joint 'shoulder_pan_joint' of armsim's model .* not in pin_model"):
        am.to_pinocchio_order(other, pm, np.zeros(other.nv))
    # armsim keeps the mimic finger dependent by default; pin's parser does not.
    panda = am.Model.from_file(PANDA)
    pin_panda = pin.buildModelFromUrdf(str(PANDA))
    with pytest.raises(am.ArmsimError, match="joint 'panda_finger_joint2' of pin_model has no coordinate.*ignore_mimic=True"):
        am.from_pinocchio_order(panda, pin_panda, np.zeros(pin_panda.nq))
    panda_free = am.Model.from_file(PANDA, ignore_mimic=True)
    pin_mimic = pin.buildModelFromUrdf(str(PANDA), mimic=True)
    with pytest.raises(am.ArmsimError, match="joint 'panda_finger_joint2' is a mimic joint in pin_model"):
        am.from_pinocchio_order(panda_free, pin_mimic, np.zeros(pin_mimic.nq))
    # Loaded the same way, both work.
    np.testing.assert_array_equal(
        am.from_pinocchio_order(panda, pin_mimic, np.arange(pin_mimic.nq, dtype=float)),
        np.arange(8.0))
    with pytest.raises(am.ArmsimError, match="x: 11 values for the 12 coordinates"):
        am.to_pinocchio_order(m, pm, np.zeros(11))
    with pytest.raises(am.ArmsimError, match=r"x: expected a vector or an \(N, n\) batch, got shape \(2, 3, 12\)"):
        am.from_pinocchio_order(m, pm, np.zeros((2, 3, 12)))
    with pytest.raises(am.ArmsimError, match="pin_model: expected a pinocchio.Model"):
        am.from_pinocchio_order(m, object(), np.zeros(12))
    with pytest.raises(am.ArmsimError, match="kind: expected 'q', 'v' or None"):
        am.from_pinocchio_order(m, pm, np.zeros(12), kind="tau")
