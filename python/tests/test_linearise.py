"""`am.linearise_step` (the A and B of one RK4 or semi-implicit Euler step) against
central differences of the same step written here on Pinocchio's `aba`: an independent
forward dynamics, so the comparison checks the step, the chain rule and the derivatives."""

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
    erd_robots() / "kinova_description/robots/kinova.urdf",
    erd_robots() / "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
]
SCHEMES = ["rk4", "semi_implicit_euler"]


def pin_step(pm, pd, mp, x, tau, dt, scheme):
    """One step in armsim's coordinates, with Pinocchio's ABA as the dynamics."""
    n = len(tau)

    def f(x):
        a = pin.aba(pm, pd, mp.q(x[:n]), mp.v(x[n:]), mp.v(tau))
        return np.concatenate([x[n:], mp.from_v(a)])

    if scheme == "semi_implicit_euler":
        v = x[n:] + dt * f(x)[n:]
        return np.concatenate([x[:n] + dt * v, v])
    k1 = f(x)
    k2 = f(x + dt / 2 * k1)
    k3 = f(x + dt / 2 * k2)
    k4 = f(x + dt * k3)
    return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def central(g, x, h):
    cols = []
    for k in range(len(x)):
        e = np.zeros(len(x))
        e[k] = h
        cols.append((g(x + e) - g(x - e)) / (2 * h))
    return np.stack(cols, axis=1)


@pytest.mark.parametrize("path", URDFS, ids=lambda p: p.name)
@pytest.mark.parametrize("scheme", SCHEMES)
def test_a_and_b_match_differences_of_the_step_on_pinocchio_aba(path, scheme, rng):
    m = am.Model.from_file(path, ignore_mimic=True)
    pm = pin.buildModelFromUrdf(str(path))
    mp, d, pd = PinMap(m, pm), m.create_data(), pm.createData()
    dt = 0.01
    for _ in range(2):
        q, v, tau = random_q(m, rng), rng.normal(size=m.nv), rng.normal(size=m.nv)
        x = np.concatenate([q, v])
        A, B, x_next = am.linearise_step(m, d, q, v, tau, dt, integrator=scheme)
        assert A.shape == (2 * m.nv, 2 * m.nv) and B.shape == (2 * m.nv, m.nv)
        assert_close(x_next, pin_step(pm, pd, mp, x, tau, dt, scheme), "x_next", tol=1e-10)
        fa = central(lambda y: pin_step(pm, pd, mp, y, tau, dt, scheme), x, 1e-6)
        assert_close(A, fa, f"A ({scheme})", tol=1e-6)
        fb = central(lambda t: pin_step(pm, pd, mp, x, t, dt, scheme), tau, 1e-4)
        assert_close(B, fb, f"B ({scheme})", tol=1e-6)


ROTOR = """<robot name="rotor">
  <link name="base"/>
  <link name="wheel">
    <inertial><mass value="1"/><origin xyz="0 0 0"/>
      <inertia ixx="0.3" iyy="0.3" izz="0.3" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="wheel"/><axis xyz="0 0 1"/>
    <dynamics damping="0.4" friction="0"/>
  </joint>
</robot>
"""


def test_friction_on_a_damped_rotor_gives_the_closed_form(tmp_path):
    """M = J, a = (tau - b v)/J: A = [[1, h(1 - hb/J)], [0, 1 - hb/J]], B = [h²/J, h/J]."""
    path = tmp_path / "rotor.urdf"
    path.write_text(ROTOR)
    m = am.Model.from_file(path)
    d = m.create_data()
    J, b, h = 0.3, 0.4, 0.05
    A, B, x_next = am.linearise_step(m, d, [0.7], [1.2], [2.0], h, "semi_implicit_euler", friction=True)
    decay = 1 - h * b / J
    np.testing.assert_allclose(A, [[1, h * decay], [0, decay]], rtol=0, atol=1e-14)
    np.testing.assert_allclose(B, [[h * h / J], [h / J]], rtol=0, atol=1e-14)
    v1 = 1.2 + h * (2.0 - b * 1.2) / J
    np.testing.assert_allclose(x_next, [0.7 + h * v1, v1], rtol=0, atol=1e-14)
    A0, _, _ = am.linearise_step(m, d, [0.7], [1.2], [2.0], h, "semi_implicit_euler")
    np.testing.assert_allclose(A0, [[1, h], [0, 1]], rtol=0, atol=1e-14)


def test_bad_step_and_integrator_name_the_argument():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    d, z = m.create_data(), np.zeros(6)
    with pytest.raises(ValueError, match="dt"):
        am.linearise_step(m, d, z, z, z, 0.0)
    with pytest.raises(ValueError, match="dt"):
        am.linearise_step(m, d, z, z, z, float("nan"))
    with pytest.raises(ValueError, match="integrator: 'euler'"):
        am.linearise_step(m, d, z, z, z, 0.01, integrator="euler")
    with pytest.raises(ValueError, match="tau"):
        am.linearise_step(m, d, z, z, np.zeros(5), 0.01)
