"""The quantities beyond RNEA/ABA/CRBA against Pinocchio (PyPI `pin`), on the bundled
URDFs and URDFs of `example-robot-data`, at random states (fixed seeds): frame velocities,
accelerations and classical accelerations, the frame Jacobian's time variation, kinetic
and potential energy, the Coriolis matrix, the centre of mass and its Jacobian, and
inverse/forward dynamics with external wrenches and a payload. Each is also checked
against a second, independent relation (J v, finite differences, Ṁ − 2C skew, −Jᵀ w), and
bad arguments raise errors naming the argument."""

from __future__ import annotations

import numpy as np
import pytest

import armsim as am
from conftest import ROBOTS, PinMap, assert_close, random_q
from test_vs_pinocchio import REFERENCES, URDFS, pin_frame

pin = pytest.importorskip("pinocchio")

STATES = 4
H = 1e-6  # central finite-difference step


@pytest.fixture(params=URDFS, ids=lambda p: p.name)
def pair(request):
    path = request.param
    assert path.is_file(), f"{path} missing (pip install example-robot-data)"
    m = am.Model.from_file(path, ignore_mimic=True)
    pm = pin.buildModelFromUrdf(str(path))
    return m, pm, PinMap(m, pm), path


def states(m, rng, n=STATES):
    for _ in range(n):
        yield random_q(m, rng), rng.normal(size=m.nv), rng.normal(size=m.nv)


def frames(m):
    """The last frame and one in the middle of the list."""
    names = m.frame_names
    return names[-1], names[len(names) // 2]


def moving_frames(m, pm):
    """`frames(m)` that hang from a joint (a wrench or payload there loads something)."""
    return [f for f in frames(m) if pm.frames[pin_frame(pm, f)].parentJoint > 0]


# --- frame velocity, acceleration, classical acceleration, J̇ -------------------------


@pytest.mark.parametrize("ref", sorted(REFERENCES))
def test_frame_velocity_and_acceleration_match_pin(pair, rng, ref):
    m, pm, mp, _ = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, a in states(m, rng):
        pin.forwardKinematics(pm, pd, mp.q(q), mp.v(v), mp.v(a))
        pin.updateFramePlacements(pm, pd)
        for name in frames(m):
            pf, rf = pin_frame(pm, name), REFERENCES[ref]
            vel = am.frame_velocity(m, d, q, v, name, ref)
            assert_close(vel, pin.getFrameVelocity(pm, pd, pf, rf).vector, f"v[{name}, {ref}]")
            # The velocity is the Jacobian times v, in the same expression.
            assert_close(vel, am.frame_jacobian(m, d, q, name, ref) @ v, f"J v[{name}, {ref}]")
            acc = am.frame_acceleration(m, d, q, v, a, name, ref)
            assert_close(acc, pin.getFrameAcceleration(pm, pd, pf, rf).vector, f"a[{name}, {ref}]")
            if ref == "world":
                with pytest.raises(am.ArmsimError, match="reference: the classical acceleration"):
                    am.frame_classical_acceleration(m, d, q, v, a, name, ref)
            else:
                cls = am.frame_classical_acceleration(m, d, q, v, a, name, ref)
                want = pin.getFrameClassicalAcceleration(pm, pd, pf, rf).vector
                assert_close(cls, want, f"classical a[{name}, {ref}]")


def test_classical_acceleration_is_the_second_derivative_of_the_origin(rng):
    m = am.Model.from_file(ROBOTS / "panda.urdf")
    d = m.create_data()
    q, v, _ = next(states(m, rng))
    # Along q(t) = q + t v (a = 0): p̈ by central differences of the placements.
    p = []
    for t in (-1e-4, 0.0, 1e-4):
        am.forward_kinematics(m, d, q + t * v)
        p.append(d.frame_pose("panda_hand")[:3, 3])
    fd = (p[0] - 2 * p[1] + p[2]) / 1e-8
    got = am.frame_classical_acceleration(m, d, q, v, np.zeros(m.nv), "panda_hand")
    np.testing.assert_allclose(got[:3], fd, atol=1e-5)


@pytest.mark.parametrize("ref", sorted(REFERENCES))
def test_jacobian_time_variation_matches_pin_and_gives_the_drift(pair, rng, ref):
    m, pm, mp, _ = pair
    d, pd = m.create_data(), pm.createData()
    zero = np.zeros(m.nv)
    for q, v, _ in states(m, rng):
        pin.computeJointJacobiansTimeVariation(pm, pd, mp.q(q), mp.v(v))
        pin.updateFramePlacements(pm, pd)
        for name in frames(m):
            dj = am.frame_jacobian_time_variation(m, d, q, v, name, ref)
            want = pin.getFrameJacobianTimeVariation(pm, pd, pin_frame(pm, name), REFERENCES[ref])
            assert_close(dj, mp.from_v(want), f"dJ[{name}, {ref}]")
            # J̇ v is the acceleration at a = 0: spatial (local, world) or classical
            # (world_aligned, the acceleration drift of the frame's origin).
            if ref == "world_aligned":
                drift = am.frame_classical_acceleration(m, d, q, v, zero, name, ref)
            else:
                drift = am.frame_acceleration(m, d, q, v, zero, name, ref)
            assert_close(dj @ v, drift, f"dJ v[{name}, {ref}]")


def test_jacobian_time_variation_is_the_derivative_of_the_jacobian(rng):
    m = am.Model.from_file(ROBOTS / "iiwa14.urdf")
    d = m.create_data()
    q, v, _ = next(states(m, rng))
    for ref in REFERENCES:
        jp = am.frame_jacobian(m, d, q + H * v, m.frame_names[-1], ref)
        jm = am.frame_jacobian(m, d, q - H * v, m.frame_names[-1], ref)
        dj = am.frame_jacobian_time_variation(m, d, q, v, m.frame_names[-1], ref)
        np.testing.assert_allclose(dj, (jp - jm) / (2 * H), atol=1e-7, err_msg=ref)


# --- energies, Coriolis ---------------------------------------------------------------


def test_energies_match_pin(pair, rng):
    m, pm, mp, _ = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, _ in states(m, rng):
        t = am.compute_kinetic_energy(m, d, q, v)
        u = am.compute_potential_energy(m, d, q)
        assert isinstance(t, float) and isinstance(u, float)
        assert_close(t, pin.computeKineticEnergy(pm, pd, mp.q(q), mp.v(v)), "T", tol=1e-10)
        assert_close(u, pin.computePotentialEnergy(pm, pd, mp.q(q)), "V", tol=1e-10)
        assert_close(t, 0.5 * v @ am.crba(m, d, q) @ v, "T = v M v / 2", tol=1e-10)


def test_gravity_torque_is_the_gradient_of_the_potential_energy(pair, rng):
    m, _, _, _ = pair
    d = m.create_data()
    q = random_q(m, rng)
    grad = np.array([(am.compute_potential_energy(m, d, q + H * e)
                      - am.compute_potential_energy(m, d, q - H * e)) / (2 * H)
                     for e in np.eye(m.nv)])
    assert_close(grad, am.gravity(m, d, q), "dV/dq", tol=1e-6)


def test_coriolis_matrix_matches_pin_and_its_identities(pair, rng):
    m, pm, mp, _ = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, _ in states(m, rng, 2):
        c = am.compute_coriolis_matrix(m, d, q, v)
        assert c.shape == (m.nv, m.nv)
        assert_close(c, mp.from_vv(pin.computeCoriolisMatrix(pm, pd, mp.q(q), mp.v(v))), "C")
        h_minus_g = am.nonlinear_effects(m, d, q, v) - am.gravity(m, d, q)
        assert_close(c @ v, h_minus_g, "C v = h - g")
        mdot = (am.crba(m, d, q + H * v) - am.crba(m, d, q - H * v)) / (2 * H)
        n = mdot - 2 * c
        assert_close(n + n.T, np.zeros_like(n), "Mdot - 2C skew", tol=1e-6)


# --- centre of mass -------------------------------------------------------------------


def test_center_of_mass_and_its_jacobian_match_pin(pair, rng):
    m, pm, mp, _ = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, _ in states(m, rng):
        c = am.center_of_mass(m, d, q)
        assert c.shape == (3,)
        assert_close(c, pin.centerOfMass(pm, pd, mp.q(q)), "com", tol=1e-10)
        j = am.jacobian_center_of_mass(m, d, q)
        assert j.shape == (3, m.nv)
        assert_close(j, mp.from_v(pin.jacobianCenterOfMass(pm, pd, mp.q(q))), "Jcom", tol=1e-10)
        fd = (am.center_of_mass(m, d, q + H * v) - am.center_of_mass(m, d, q - H * v)) / (2 * H)
        assert_close(j @ v, fd, "Jcom v = dc/dt", tol=1e-7)


# --- wrenches and payload -------------------------------------------------------------


def pin_fext(pm, pd, pq, wrenches):
    """Pinocchio's per-joint local `fext` for armsim wrenches {frame: (f, m) at the frame
    origin, world axes}."""
    pin.framesForwardKinematics(pm, pd, pq)
    fext = [pin.Force.Zero() for _ in range(pm.njoints)]
    for name, w in wrenches.items():
        pf = pin_frame(pm, name)
        p = pd.oMf[pf].translation
        f, n = np.asarray(w[:3]), np.asarray(w[3:])
        at_origin = pin.Force(f, n + np.cross(p, f))
        j = pm.frames[pf].parentJoint
        fext[j] = fext[j] + pd.oMi[j].actInv(at_origin)
    return fext


def random_wrenches(m, pm, rng):
    return {name: rng.normal(size=6) * 20 for name in moving_frames(m, pm)}


def test_wrenches_in_inverse_and_forward_dynamics_match_pin(pair, rng):
    m, pm, mp, _ = pair
    d, pd = m.create_data(), pm.createData()
    for q, v, a in states(m, rng):
        w = random_wrenches(m, pm, rng)
        assert w, "the robot has a moving frame"
        fext = pin_fext(pm, pd, mp.q(q), w)
        tau = am.inverse_dynamics(m, d, q, v, a, wrenches=w)
        ptau = pin.rnea(pm, pd, mp.q(q), mp.v(v), mp.v(a), fext)
        assert_close(tau, mp.from_v(ptau), "rnea with fext")
        # A wrench adds −Jᵀ w (the world-aligned Jacobian at the frame's origin).
        shift = sum(am.frame_jacobian(m, d, q, name, "world_aligned").T @ wr
                    for name, wr in w.items())
        assert_close(tau, am.rnea(m, d, q, v, a) - shift, "rnea - J^T w")
        ddq = am.forward_dynamics(m, d, q, v, tau, wrenches=w)
        pddq = pin.aba(pm, pd, mp.q(q), mp.v(v), mp.v(tau), fext)
        assert_close(ddq, mp.from_v(pddq), "aba with fext", tol=1e-8)
        assert_close(ddq, a, "forward_dynamics inverts inverse_dynamics", tol=1e-7)


def random_payload(name, rng):
    b = rng.normal(size=(3, 3))
    return {"frame": name, "mass": float(rng.uniform(0.5, 3.0)),
            "com": rng.normal(size=3) * 0.1, "inertia": b @ b.T * 0.01 + np.eye(3) * 1e-3}


def pin_with_payload(path, pm, p):
    """A copy of `pm` whose frame's joint carries the payload's inertia too."""
    pm2 = pin.buildModelFromUrdf(str(path))
    pf = pin_frame(pm2, p["frame"])
    j = pm2.frames[pf].parentJoint
    body = pin.Inertia(p["mass"], np.asarray(p["com"]), np.asarray(p["inertia"]))
    pm2.inertias[j] = pm2.inertias[j] + pm2.frames[pf].placement.act(body)
    return pm2


def test_payload_in_inverse_and_forward_dynamics_matches_pin(pair, rng):
    m, pm, mp, path = pair
    d = m.create_data()
    assert moving_frames(m, pm), "the robot has a moving frame"
    for name in moving_frames(m, pm):
        p = random_payload(name, rng)
        pm2 = pin_with_payload(path, pm, p)
        pd2 = pm2.createData()
        for q, v, a in states(m, rng, 2):
            pq, pv = mp.q(q), mp.v(v)
            tau = am.inverse_dynamics(m, d, q, v, a, payload=p)
            assert_close(tau, mp.from_v(pin.rnea(pm2, pd2, pq, pv, mp.v(a))), f"rnea payload {name}")
            assert np.max(np.abs(tau - am.rnea(m, d, q, v, a))) > 1e-6, "the payload loads a joint"
            ddq = am.forward_dynamics(m, d, q, v, tau, payload=p)
            assert_close(ddq, mp.from_v(pin.aba(pm2, pd2, pq, pv, mp.v(tau))), f"aba payload {name}", tol=1e-8)
            # Payload and wrenches together.
            w = random_wrenches(m, pm, rng)
            fext = pin_fext(pm2, pd2, pq, w)
            both = am.inverse_dynamics(m, d, q, v, a, wrenches=w, payload=p)
            assert_close(both, mp.from_v(pin.rnea(pm2, pd2, pq, pv, mp.v(a), fext)), "rnea payload+fext")


def test_no_loads_equal_rnea_and_aba(rng):
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    d = m.create_data()
    q, v, a = next(states(m, rng))
    np.testing.assert_array_equal(am.inverse_dynamics(m, d, q, v, a), am.rnea(m, d, q, v, a))
    np.testing.assert_array_equal(am.inverse_dynamics(m, d, q, v, a, wrenches={}, payload=None),
                                  am.rnea(m, d, q, v, a))
    np.testing.assert_allclose(am.forward_dynamics(m, d, q, v, a), am.aba(m, d, q, v, a),
                               rtol=0, atol=1e-12)
    # A frame given by index is the frame of that name; the order of a dict does not matter.
    w = {"tool0": [1.0, 2, 3, 0.1, 0.2, 0.3], "wrist_1_link": [0, 0, -5, 0, 0, 0]}
    by_index = {m.frame_id(k): w[k] for k in reversed(list(w))}
    np.testing.assert_array_equal(am.inverse_dynamics(m, d, q, v, a, wrenches=w),
                                  am.inverse_dynamics(m, d, q, v, a, wrenches=by_index))


# --- bad arguments --------------------------------------------------------------------


@pytest.fixture(scope="module")
def ur5():
    m = am.Model.from_file(ROBOTS / "ur5.urdf")
    return m, m.create_data()


def test_frame_motion_arguments_are_named(ur5):
    m, d = ur5
    z, nan = np.zeros(6), np.array([0, np.nan, 0, 0, 0, 0])
    with pytest.raises(am.ArmsimError, match="q: 5 values for 6 coordinates"):
        am.frame_velocity(m, d, np.zeros(5), z, "tool0")
    with pytest.raises(am.ArmsimError, match=r"v\[1\] is not finite"):
        am.frame_velocity(m, d, z, nan, "tool0")
    with pytest.raises(am.ArmsimError, match="a: 7 values for 6 coordinates"):
        am.frame_acceleration(m, d, z, z, np.zeros(7), "tool0")
    with pytest.raises(am.ArmsimError, match=r"a\[1\] is not finite"):
        am.frame_classical_acceleration(m, d, z, z, nan, "tool0")
    with pytest.raises(am.ArmsimError, match="no frame 'hand'"):
        am.frame_jacobian_time_variation(m, d, z, z, "hand")
    with pytest.raises(am.ArmsimError, match="unknown reference frame 'body'"):
        am.frame_acceleration(m, d, z, z, z, "tool0", "body")
    with pytest.raises(am.ArmsimError, match="v: expected a 1-D sequence"):
        am.frame_jacobian_time_variation(m, d, z, "fast", "tool0")
    with pytest.raises(am.ArmsimError, match=r"the frame velocity\[\d\] is not finite"):
        am.frame_velocity(m, d, z, np.full(6, 1e308), "tool0")  # parallel axes: ω overflows
    # Integer lists are numbers too.
    np.testing.assert_array_equal(am.frame_velocity(m, d, [0] * 6, [1] * 6, "tool0"),
                                  am.frame_velocity(m, d, z, np.ones(6), "tool0"))


def test_energy_coriolis_and_com_arguments_are_named(ur5):
    m, d = ur5
    z = np.zeros(6)
    with pytest.raises(am.ArmsimError, match=r"v\[2\] is not finite"):
        am.compute_kinetic_energy(m, d, z, [0, 0, np.inf, 0, 0, 0])
    with pytest.raises(am.ArmsimError, match="q: 4 values for 6 coordinates"):
        am.compute_potential_energy(m, d, np.zeros(4))
    with pytest.raises(am.ArmsimError, match="v: 3 values for 6 coordinates"):
        am.compute_coriolis_matrix(m, d, z, np.zeros(3))
    with pytest.raises(am.ArmsimError, match=r"q\[0\] is not finite"):
        am.center_of_mass(m, d, [np.nan] + [0] * 5)
    with pytest.raises(am.ArmsimError, match="q: 7 values"):
        am.jacobian_center_of_mass(m, d, np.zeros(7))
    with pytest.raises(am.ArmsimError, match=r"the kinetic energy is not finite.*largest \|q\| 0, \|v\| 1e\+?200"):
        am.compute_kinetic_energy(m, d, z, np.full(6, 1e200))
    panda = am.Model.from_file(ROBOTS / "panda.urdf")
    with pytest.raises(am.ArmsimError, match="data was created for 'ur5'"):
        am.center_of_mass(panda, d, np.zeros(panda.nv))


def chain_urdf(n, mass=1.0):
    """A chain of `n` revolute joints (link masses `mass`; none when 0)."""
    inertial = ("" if mass == 0 else
                f'<inertial><mass value="{mass}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" '
                'ixy="0" ixz="0" iyz="0"/></inertial>')
    links = "".join(f'<link name="l{i}">{inertial if i else ""}</link>' for i in range(n + 1))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0 0 0.1"/><axis xyz="{"0 0 1" if i % 2 else "0 1 0"}"/>'
        '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>' for i in range(n))
    return f'<robot name="chain{n}">{links}{joints}</robot>'


def test_a_massless_model_has_no_centre_of_mass():
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", am.LoaderWarning)
        m = am.Model.from_string(chain_urdf(2, mass=0.0), "massless.urdf")
    d = m.create_data()
    with pytest.raises(am.ArmsimError, match="'chain2' has no mass"):
        am.center_of_mass(m, d, [0.0, 0.0])
    with pytest.raises(am.ArmsimError, match="has no mass"):
        am.jacobian_center_of_mass(m, d, [0.0, 0.0])


def test_coriolis_matrix_refuses_a_model_beyond_its_size():
    m = am.Model.from_string(chain_urdf(201), "long.urdf")
    with pytest.raises(am.ArmsimError, match="201 coordinates.*at most 200"):
        am.compute_coriolis_matrix(m, m.create_data(), np.zeros(201), np.zeros(201))
    small = am.Model.from_string(chain_urdf(12), "chain.urdf")
    c = am.compute_coriolis_matrix(small, small.create_data(), np.full(12, 0.3), np.ones(12))
    assert c.shape == (12, 12) and np.any(c != 0)


def test_wrench_and_payload_arguments_are_named(ur5):
    m, d = ur5
    z = np.zeros(6)
    cases = [
        (dict(wrenches=[("tool0", z)]), r"wrenches: expected a dict \{frame: \[fx, fy, fz, mx, my, mz\]\}, got list"),
        (dict(wrenches={"hand": z}), "wrenches: no frame 'hand'"),
        (dict(wrenches={99: z}), "wrenches: frame index 99 does not exist"),
        (dict(wrenches={"tool0": np.zeros(5)}), r"wrenches\['tool0'\]: 5 values"),
        (dict(wrenches={"tool0": [0, 0, np.nan, 0, 0, 0]}), r"wrenches\['tool0'\]\[2\] is not finite"),
        (dict(payload=("tool0", 1.0)), "payload: expected a dict"),
        (dict(payload={"frame": "tool0"}), "payload: 'mass' is required"),
        (dict(payload={"mass": 1.0}), "payload: 'frame' is required"),
        (dict(payload={"frame": "tool0", "mass": 1.0, "masss": 2}), "payload: unknown key 'masss'"),
        (dict(payload={"frame": "hand", "mass": 1.0}), r"payload\['frame'\]: no frame 'hand'"),
        (dict(payload={"frame": "tool0", "mass": "heavy"}), r"payload\['mass'\]: expected a number"),
        (dict(payload={"frame": "tool0", "mass": -1.0}), "payload: mass -1 is not a non-negative number"),
        (dict(payload={"frame": "tool0", "mass": np.nan}), "payload: mass NaN is not a non-negative number"),
        (dict(payload={"frame": "base_link", "mass": 1.0}), "payload: link 'base_link' is fixed to the world"),
        (dict(payload={"frame": "tool0", "mass": 1.0, "com": [0, 0]}), r"payload\['com'\]: 2 values"),
        (dict(payload={"frame": "tool0", "mass": 1.0, "inertia": np.eye(2)}), r"payload\['inertia'\]: shape \(2, 2\), expected \(N, 3\)"),
        (dict(payload={"frame": "tool0", "mass": 1.0, "inertia": np.ones((4, 3))}), r"payload\['inertia'\]: shape \(4, 3\), expected \(3, 3\)"),
        (dict(payload={"frame": "tool0", "mass": 1.0, "inertia": np.triu(np.ones((3, 3)))}), r"payload\['inertia'\] is not symmetric"),
        (dict(payload={"frame": "tool0", "mass": 1.0, "inertia": np.diag([1, np.inf, 1])}), r"payload\['inertia'\]\[1, 1\] is not finite"),
    ]
    for kwargs, msg in cases:
        for fn in (am.inverse_dynamics, am.forward_dynamics):
            with pytest.raises(am.ArmsimError, match=msg):
                fn(m, d, z, z, z, **kwargs)
    with pytest.raises(TypeError):
        am.inverse_dynamics(m, d, z, z, z, {"tool0": z})  # keyword-only, unlike pin's fext
    assert issubclass(am.ArmsimError, ValueError)


PIN_NAMES = {
    "frame_velocity": "getFrameVelocity",
    "frame_acceleration": "getFrameAcceleration",
    "frame_classical_acceleration": "getFrameClassicalAcceleration",
    "frame_jacobian_time_variation": "getFrameJacobianTimeVariation",
    "compute_kinetic_energy": "computeKineticEnergy",
    "compute_potential_energy": "computePotentialEnergy",
    "compute_coriolis_matrix": "computeCoriolisMatrix",
    "center_of_mass": "centerOfMass",
    "jacobian_center_of_mass": "jacobianCenterOfMass",
    "inverse_dynamics": "rnea",
    "forward_dynamics": "aba",
}


def test_each_function_is_exported_and_documented_with_its_pinocchio_name():
    for name, pin_name in PIN_NAMES.items():
        fn = getattr(am, name)
        assert name in am.__all__, name
        assert pin_name in (fn.__doc__ or ""), f"{name}'s docstring names {pin_name}"


def test_mimic_joints_keep_the_identities(rng):
    # Panda's finger joint mimics the other (armsim's default): one coordinate drives two
    # bodies, through every new function.
    m = am.Model.from_file(ROBOTS / "panda.urdf")
    d = m.create_data()
    assert m.nv == 8
    q, v, a = next(states(m, rng))
    finger = "panda_rightfinger"
    assert_close(am.frame_velocity(m, d, q, v, finger), am.frame_jacobian(m, d, q, finger) @ v, "J v")
    dj = am.frame_jacobian_time_variation(m, d, q, v, finger)
    assert_close(dj @ v, am.frame_classical_acceleration(m, d, q, v, np.zeros(m.nv), finger), "dJ v")
    c = am.compute_coriolis_matrix(m, d, q, v)
    assert_close(c @ v, am.nonlinear_effects(m, d, q, v) - am.gravity(m, d, q), "C v = h - g")
    assert_close(am.compute_kinetic_energy(m, d, q, v), 0.5 * v @ am.crba(m, d, q) @ v, "T", tol=1e-10)
    fd = (am.center_of_mass(m, d, q + H * v) - am.center_of_mass(m, d, q - H * v)) / (2 * H)
    assert_close(am.jacobian_center_of_mass(m, d, q) @ v, fd, "Jcom v", tol=1e-7)
    w = {finger: rng.normal(size=6)}
    p = random_payload("panda_leftfinger", rng)
    tau = am.inverse_dynamics(m, d, q, v, a, wrenches=w, payload=p)
    assert_close(am.forward_dynamics(m, d, q, v, tau, wrenches=w, payload=p), a, "fd(id)", tol=1e-7)
    shift = am.frame_jacobian(m, d, q, finger).T @ w[finger]
    assert_close(am.inverse_dynamics(m, d, q, v, a, payload=p) - shift, tau, "-J^T w")
