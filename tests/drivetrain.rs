//! Torsional drivetrain chains (docs/reference_data.md §S3): every result is checked against an
//! independent route — published frequencies, closed forms, Holzer tables, the LR
//! iteration, perturbation estimates, time integration, the rigid-body engine (CRBA,
//! ABA, the flexible-joint model), finite differences, Monte Carlo.

mod common;
#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocs;

use armsim::core::spatial::Vec3;
use armsim::dynamics::{self, Effects, Elasticity};
use armsim::machines::vibration::torsional::absorber::{
    lanchester_damper, lanchester_optimum_damping, tuned_absorber_inertia,
};
use armsim::machines::vibration::torsional::damped::{damped_modes, quadratic_matrix};
use armsim::machines::vibration::torsional::forced::{
    critical_speeds, harmonic_response, order_response, Excitation,
};
use armsim::machines::vibration::torsional::holzer::{
    frequencies_below, holzer_frequencies, holzer_table, residual_torque,
};
use armsim::machines::vibration::torsional::identify::{
    chain_with, identify_damping, predict, DampingParameter, Measurement,
};
use armsim::machines::vibration::torsional::lr::lr_eigenvalues;
use armsim::machines::vibration::torsional::modes::{undamped_modes, CPM_PER_RAD_S};
use armsim::machines::vibration::torsional::time::{
    steady_state_by_integration, HarmonicForcing, Rk4,
};
use armsim::machines::vibration::torsional::{GearStage, GearedChain, TorsionalChain};
use armsim::model::data::Data;
use nalgebra::{Complex, DMatrix};
use rand::{rngs::SmallRng, Rng, SeedableRng};
use std::path::PathBuf;

// ---------------------------------------------------------------------------------------
// Data.

const CYL: [usize; 6] = [1, 2, 3, 4, 5, 6];
const FIRING: [f64; 6] = [0.0, 120.0, 240.0, 180.0, 300.0, 60.0];
const A_CYL: f64 = 16_800.0;
const A_PROP: f64 = 237_300.0;

/// The 11-mass ship shafting of the report (docs/reference_data.md §S3), undamped.
fn ship_undamped() -> TorsionalChain {
    let names = [
        "front_end",
        "cyl1",
        "cyl2",
        "cyl3",
        "cyl4",
        "cyl5",
        "cyl6",
        "camshaft_drive",
        "flywheel",
        "intermediate_shaft",
        "propeller",
    ];
    let mut j = vec![9181.0];
    j.extend([7999.0; 6]);
    j.extend([5422.0, 9538.3, 857.9, 48240.1]);
    let mut c = vec![1201.92];
    c.extend([940.82; 5]);
    c.extend([1434.93, 1934.24, 77.16, 101.04]);
    let c = c.into_iter().map(|x| x * 1e6).collect();
    TorsionalChain::new(names.iter().map(|s| s.to_string()).collect(), j, c).unwrap()
}

/// The ship shafting with the report's damping.
fn ship() -> TorsionalChain {
    let mut a = vec![0.0; 11];
    for k in CYL {
        a[k] = A_CYL;
    }
    a[10] = A_PROP;
    let mut b = vec![0.0; 10];
    b[0] = 158_100.0;
    for bk in b.iter_mut().take(6).skip(1) {
        *bk = 316_200.0;
    }
    b[6] = 158_100.0;
    ship_undamped().with_damping(a, b).unwrap()
}

fn ship_excitation() -> Excitation {
    Excitation {
        cylinders: CYL.to_vec(),
        firing_angles_deg: FIRING.to_vec(),
        orders: (1..=12).map(|k| k as f64).collect(),
        amplitudes: vec![
            85.0e3, 68.0e3, 51.0e3, 38.0e3, 29.0e3, 22.0e3, 17.0e3, 13.5e3, 11.0e3, 9.0e3, 7.5e3,
            6.0e3,
        ],
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

// ---------------------------------------------------------------------------------------
// Undamped modes.

#[test]
fn ship_undamped_frequencies_match_the_report() {
    let chain = ship_undamped();
    let modes = undamped_modes(&chain);
    assert_eq!(modes.len(), 11);
    // Rigid-body mode: zero frequency, uniform shape.
    assert_eq!(modes[0].omega, 0.0);
    assert!(
        modes[0].shape.iter().all(|x| (x - 1.0).abs() < 1e-9),
        "{:?}",
        modes[0].shape
    );
    for (m, published) in modes[1..4].iter().zip([354.1, 1197.6, 2373.6]) {
        let f = m.frequency_cpm();
        assert!(
            (f - published).abs() < 0.1,
            "{f} cpm vs published {published}"
        );
    }
    // Ascending, and every pair satisfies K x = p² J x with J-orthogonal shapes.
    let k = chain.stiffness_matrix();
    let j = chain.inertia_matrix();
    for w in modes.windows(2) {
        assert!(w[1].omega > w[0].omega);
    }
    for (r, m) in modes.iter().enumerate() {
        let x = nalgebra::DVector::from_column_slice(&m.shape);
        let res = &k * &x - &j * &x * (m.omega * m.omega);
        assert!(
            res.norm() < 1e-12 * k.norm() * x.norm(),
            "mode {r}: residual {}",
            res.norm()
        );
        assert!((m.shape.iter().fold(0.0_f64, |a, v| a.max(v.abs())) - 1.0).abs() < 1e-15);
        for (s, o) in modes.iter().enumerate().filter(|(s, _)| *s != r) {
            let y = nalgebra::DVector::from_column_slice(&o.shape);
            let cross = (x.transpose() * &j * &y)[0];
            assert!(
                cross.abs() < 1e-9 * chain.inertia.iter().sum::<f64>(),
                "modes {r},{s}"
            );
        }
    }
}

#[test]
fn holzer_finds_the_same_frequencies() {
    let chain = ship_undamped();
    let modes = undamped_modes(&chain);
    let geared = GearedChain::from(chain.clone());
    let h = holzer_frequencies(&geared);
    assert_eq!(h.len(), 11);
    assert!(h[0] * CPM_PER_RAD_S < 1e-6, "rigid-body mode {}", h[0]);
    for (r, (m, w)) in modes.iter().zip(&h).enumerate().skip(1) {
        assert!(
            rel(*w, m.omega) < 1e-9,
            "mode {r}: Holzer {w}, eigen {}",
            m.omega
        );
        // The residual torque changes sign across the frequency, and mode r has r nodes.
        let (lo, hi) = (w * (1.0 - 1e-6), w * (1.0 + 1e-6));
        assert!(residual_torque(&geared, lo) * residual_torque(&geared, hi) < 0.0);
        assert_eq!(frequencies_below(&geared, lo), r);
        let t = holzer_table(&geared, *w);
        let nodes = t.angles.windows(2).filter(|p| p[0] * p[1] < 0.0).count();
        assert_eq!(nodes, r, "mode {r}");
        // The Holzer amplitudes are the mode shape (scaled to φ_1 = 1).
        for (a, x) in t.angles.iter().zip(&m.shape) {
            assert!(
                (a - x / m.shape[0]).abs() < 1e-6,
                "mode {r}: {a} vs {}",
                x / m.shape[0]
            );
        }
    }
}

#[test]
fn lr_iteration_agrees_with_symmetric_eigen() {
    let chain = ship_undamped();
    let modes = undamped_modes(&chain);
    let lr = lr_eigenvalues(&chain, 100_000).unwrap();
    let top = modes[10].omega.powi(2);
    for (m, p2) in modes.iter().zip(&lr) {
        assert!(
            (m.omega.powi(2) - p2).abs() < 1e-10 * top,
            "{} vs {p2}",
            m.omega.powi(2)
        );
    }
    // And on a chain with no zero mode structure in common: the two-mass closed form.
    let two = TorsionalChain::unnamed(vec![2.0, 5.0], vec![700.0]).unwrap();
    let e = lr_eigenvalues(&two, 1000).unwrap();
    assert!(e[0].abs() < 1e-12);
    assert!(rel(e[1], 700.0 * (0.5 + 0.2)) < 1e-14);
}

// ---------------------------------------------------------------------------------------
// Damped modes.

#[test]
fn two_mass_damped_pair_is_the_one_dof_closed_form() {
    // The twist δ = φ2 − φ1 of two disks joined by (c, b) obeys μ δ̈ + b δ̇ + c δ = 0,
    // μ = J1 J2 / (J1 + J2): exactly a 1-DOF damped oscillator.
    let (j1, j2, c): (f64, f64, f64) = (1.2, 0.8, 2.0e4);
    let mu = j1 * j2 / (j1 + j2);
    let omega = (c / mu).sqrt();
    for zeta in [0.01, 0.1, 0.5, 0.9] {
        let b = 2.0 * zeta * (c * mu).sqrt();
        let chain = TorsionalChain::unnamed(vec![j1, j2], vec![c])
            .unwrap()
            .with_damping(vec![0.0, 0.0], vec![b])
            .unwrap();
        let d = damped_modes(&chain);
        assert_eq!(d.oscillatory.len(), 1);
        assert_eq!(d.real_eigenvalues, vec![0.0, 0.0]); // rigid body: defective double zero
        let l = d.oscillatory[0].eigenvalue;
        let expect = Complex::new(-zeta * omega, omega * (1.0 - zeta * zeta).sqrt());
        assert!(
            (l - expect).norm() < 1e-12 * omega,
            "ζ = {zeta}: {l} vs {expect}"
        );
        assert!(rel(d.oscillatory[0].damping_ratio(), zeta) < 1e-12);
        // Shape ∝ (J2, −J1) (momentum balance), largest component exactly 1 + 0i.
        let s = &d.oscillatory[0].shape;
        assert_eq!(s[1], Complex::new(1.0, 0.0));
        assert!((s[0] - Complex::new(-j2 / j1, 0.0)).norm() < 1e-12);
    }
}

#[test]
fn proportional_damping_gives_real_shapes_and_modal_eigenvalues() {
    // B = αJ + βK: every undamped mode stays a mode, λ² + (α + β p²) λ + p² = 0.
    let base = ship_undamped();
    let (alpha, beta) = (0.8, 2.0e-4);
    let a = base.inertia.iter().map(|j| alpha * j).collect();
    let b = base.stiffness.iter().map(|c| beta * c).collect();
    let chain = base.clone().with_damping(a, b).unwrap();
    let modes = undamped_modes(&base);
    let d = damped_modes(&chain);
    let mut expect: Vec<Complex<f64>> = Vec::new();
    for m in &modes[1..] {
        let h = 0.5 * (alpha + beta * m.omega * m.omega);
        if h < m.omega {
            expect.push(Complex::new(-h, (m.omega * m.omega - h * h).sqrt()));
        }
    }
    assert_eq!(d.oscillatory.len(), expect.len());
    for (got, want) in d.oscillatory.iter().zip(&expect) {
        assert!(
            (got.eigenvalue - want).norm() < 1e-9 * want.norm(),
            "{} vs {want}",
            got.eigenvalue
        );
        for z in &got.shape {
            assert!(
                z.im.abs() < 1e-9,
                "proportional damping must give a real shape: {z}"
            );
        }
    }
}

#[test]
fn ship_damped_modes_are_close_to_undamped_with_phase_lags() {
    let chain = ship();
    let undamped = undamped_modes(&ship_undamped());
    let d = damped_modes(&chain);
    // 2n eigenvalues: 10 complex pairs and the real rigid-body pair (0 and the decay of
    // the whole shaft line on its absolute dampers, ≈ −Σa/ΣJ).
    assert_eq!(2 * d.oscillatory.len() + d.real_eigenvalues.len(), 22);
    assert_eq!(d.real_eigenvalues.len(), 2);
    assert_eq!(d.real_eigenvalues[0], 0.0);
    let total_j: f64 = chain.inertia.iter().sum();
    let total_a: f64 = chain.absolute_damping.iter().sum();
    assert!(
        rel(d.real_eigenvalues[1], -total_a / total_j) < 0.01,
        "{}",
        d.real_eigenvalues[1]
    );
    let j = chain.inertia_matrix();
    let bm = chain.damping_matrix();
    for r in 0..3 {
        let m = &d.oscillatory[r];
        let p = undamped[r + 1].omega;
        // The eigenpair solves the quadratic problem (checked directly, not as computed).
        let x = nalgebra::DVector::from_column_slice(&m.shape);
        let res = quadratic_matrix(&chain, m.eigenvalue) * &x;
        let scale = chain.stiffness_matrix().norm() * x.norm();
        assert!(
            res.norm() < 1e-12 * scale,
            "mode {r}: residual {}",
            res.norm() / scale
        );
        assert!(
            m.residual < 1e-13,
            "mode {r}: backward error {}",
            m.residual
        );
        // Light damping: the damped frequency within 0.25 % of the undamped one (mode 1:
        // 353.33 vs 354.09 cpm), |λ| within 0.15 %.
        assert!(
            rel(m.eigenvalue.im, p) < 2.5e-3,
            "mode {r}: {} vs {p}",
            m.eigenvalue.im
        );
        assert!(rel(m.eigenvalue.norm(), p) < 1.5e-3);
        // First-order perturbation: Re λ ≈ −xᵀBx / (2 xᵀJx) with the undamped shape.
        let u = nalgebra::DVector::from_column_slice(&undamped[r + 1].shape);
        let est = -(u.transpose() * &bm * &u)[0] / (2.0 * (u.transpose() * &j * &u)[0]);
        assert!(
            rel(m.eigenvalue.re, est) < 0.01,
            "mode {r}: Re λ {} vs {est}",
            m.eigenvalue.re
        );
        assert_eq!(
            m.shape
                .iter()
                .filter(|z| **z == Complex::new(1.0, 0.0))
                .count(),
            1
        );
    }
    // Non-proportional damping: the first mode's disks are not in phase (nor in
    // antiphase) — phase lags of a few degrees.
    let spread = d.oscillatory[0]
        .phase_deg()
        .iter()
        .map(|p| {
            let q = p.rem_euclid(180.0);
            q.min(180.0 - q)
        })
        .fold(0.0_f64, f64::max);
    assert!(spread > 1.0 && spread < 20.0, "phase spread {spread}°");
}

// ---------------------------------------------------------------------------------------
// Forced response.

#[test]
fn harmonic_solution_equals_long_time_integration() {
    // Ship data as given (no extra damping): order 6 at 59 rpm, next to the first
    // resonance. The slowest transient decays as e^(−1.77 t); 20 s of RK4 from rest
    // (118 periods, 400 steps each, ω_max h = 0.23) leaves it at 1e-15.
    let chain = ship();
    let exc = ship_excitation();
    let i6 = 5;
    let (ms, mc) = exc.torque_vectors(11, i6);
    let nu = 6.0 * 59.0 * std::f64::consts::PI / 30.0;
    let h = harmonic_response(&chain, nu, &ms, &mc).unwrap();
    let td = steady_state_by_integration(&chain, nu, &ms, &mc, 118, 400);
    let scale = h.amplitudes().iter().fold(0.0_f64, |m, v| m.max(*v));
    for k in 0..11 {
        assert!(
            (h.sin[k] - td.sin[k]).abs() < 1e-6 * scale,
            "S[{k}] {} vs {}",
            h.sin[k],
            td.sin[k]
        );
        assert!(
            (h.cos[k] - td.cos[k]).abs() < 1e-6 * scale,
            "C[{k}] {} vs {}",
            h.cos[k],
            td.cos[k]
        );
    }
    let (ta, tb) = (h.shaft_torques(&chain), td.shaft_torques(&chain));
    for (a, b) in ta.iter().zip(&tb) {
        assert!(rel(*b, *a) < 1e-6, "shaft torque {a} vs {b}");
    }
    // Too short an integration does not reach the steady state: the check has teeth.
    let early = steady_state_by_integration(&chain, nu, &ms, &mc, 6, 400);
    let worst = (0..11).fold(0.0_f64, |m, k| m.max((h.sin[k] - early.sin[k]).abs()));
    assert!(worst > 1e-3 * scale);
}

#[test]
fn excitation_follows_the_firing_angles() {
    // M_j(t) = A cos(k (w t − α_j)) = M_s,j sin νt + M_c,j cos νt, straight from the
    // definition at a few instants.
    let exc = ship_excitation();
    let w = 80.0 * std::f64::consts::PI / 30.0;
    for (i, &k) in exc.orders.iter().enumerate() {
        let (ms, mc) = exc.torque_vectors(11, i);
        for t in [0.0, 0.013, 0.4] {
            for (c, &alpha) in CYL.iter().zip(&FIRING) {
                let direct = exc.amplitudes[i] * (k * (w * t - alpha.to_radians())).cos();
                let split = ms[*c] * (k * w * t).sin() + mc[*c] * (k * w * t).cos();
                assert!(
                    (direct - split).abs() < 1e-9 * exc.amplitudes[i],
                    "order {k}"
                );
            }
            assert_eq!(ms[0], 0.0);
            assert_eq!(mc[10], 0.0);
        }
    }
}

#[test]
fn real_block_system_equals_the_complex_phasor_form() {
    // forced.rs solves the 2n real system, identify.rs the complex n system.
    let chain = ship();
    let exc = ship_excitation();
    let data: Vec<Measurement> = [
        (3.0, 80.0, 2),
        (6.0, 59.0, 8),
        (10.0, 119.0, 3),
        (12.0, 45.0, 9),
    ]
    .iter()
    .map(|&(order, speed_rpm, shaft)| Measurement {
        order,
        speed_rpm,
        shaft,
        torque: 1.0,
    })
    .collect();
    let (t, _) = predict(&chain, &exc, &[], &[], &data);
    for (m, tc) in data.iter().zip(&t) {
        let i = exc.orders.iter().position(|&o| o == m.order).unwrap();
        let r = order_response(&chain, &exc, i, m.speed_rpm).unwrap();
        assert!(rel(r.shaft_torques(&chain)[m.shaft], *tc) < 1e-10);
    }
}

#[test]
fn critical_speed_table_shows_order_six_in_phase_near_59_rpm() {
    let chain = ship();
    let modes = undamped_modes(&chain);
    let exc = ship_excitation();
    let table = critical_speeds(&modes, &exc);
    assert_eq!(table.len(), 12 * 10);
    let c61 = table
        .iter()
        .find(|c| c.order == 6.0 && c.mode == 1)
        .unwrap();
    assert!(
        (c61.speed_rpm - 354.1 / 6.0).abs() < 0.02,
        "{}",
        c61.speed_rpm
    );
    assert!((c61.relative - 1.0).abs() < 1e-12);
    // In phase: the phase sum is the plain sum of the cylinder amplitudes.
    let plain: f64 = CYL.iter().map(|&k| modes[1].shape[k]).sum();
    assert!((c61.phase_sum - plain.abs()).abs() < 1e-12);
    // Order 6 (and its multiple 12) is the strongest for mode 1; the others are minor.
    for c in table.iter().filter(|c| c.mode == 1) {
        if c.order == 6.0 || c.order == 12.0 {
            assert!((c.relative - 1.0).abs() < 1e-12);
        } else {
            assert!(c.relative < 0.1, "order {}: {}", c.order, c.relative);
        }
    }
    // And the forced sweep peaks there: order 6's largest shaft torque between 53 and
    // 66 rpm (the barred range) is at 59 ± 0.5 rpm, in the propeller-side shafting.
    let speeds: Vec<f64> = (0..=130).map(|i| 53.0 + 0.1 * i as f64).collect();
    let sw = armsim::machines::vibration::torsional::sweep(&chain, &exc, &speeds);
    let (si, shaft, _) = sw[5].peak().unwrap();
    assert!((speeds[si] - 59.0).abs() <= 0.5, "peak at {}", speeds[si]);
    assert!(shaft >= 7, "peak in shaft {shaft}");
}

// ---------------------------------------------------------------------------------------
// Time integration allocates nothing.

#[test]
fn rk4_step_does_not_allocate() {
    let chain = ship();
    let exc = ship_excitation();
    let (ms, mc) = exc.torque_vectors(11, 5);
    let forcing = HarmonicForcing {
        terms: vec![(37.0, ms, mc)],
    };
    let mut force = |t: f64, out: &mut [f64]| forcing.eval(t, out);
    let mut rk = Rk4::new(&chain);
    let (mut x, mut v) = (vec![0.0; 11], vec![0.0; 11]);
    let before = allocs();
    for s in 0..10_000 {
        rk.step(s as f64 * 1e-4, 1e-4, &mut x, &mut v, &mut force);
    }
    assert_eq!(allocs() - before, 0);
    assert!(x.iter().any(|v| *v != 0.0));
    // The counter works: an allocation is seen.
    let before = allocs();
    let v2 = std::hint::black_box(vec![1.0; 3]);
    assert!(allocs() > before && v2.len() == 3);
}

// ---------------------------------------------------------------------------------------
// Damping identification.

fn ident_params() -> Vec<DampingParameter> {
    vec![
        DampingParameter {
            name: "cylinder_absolute".into(),
            absolute: CYL.iter().map(|&k| (k, 1.0)).collect(),
            relative: vec![],
        },
        DampingParameter {
            name: "propeller".into(),
            absolute: vec![(10, 1.0)],
            relative: vec![],
        },
    ]
}

fn ident_base() -> TorsionalChain {
    let mut base = ship();
    for k in CYL {
        base.absolute_damping[k] = 0.0;
    }
    base.absolute_damping[10] = 0.0;
    base
}

/// Orders 4–6 around the first-mode resonances, 10–12 around the second's, shafts
/// cyl3–cyl4 and flywheel–intermediate.
fn ident_points() -> Vec<Measurement> {
    let modes = undamped_modes(&ship());
    let mut out = Vec::new();
    for (k, mode) in [
        (4.0, 1),
        (5.0, 1),
        (6.0, 1),
        (10.0, 2),
        (11.0, 2),
        (12.0, 2),
    ] {
        let nc = modes[mode].frequency_cpm() / k;
        for f in [0.92, 0.97, 1.0, 1.03, 1.08] {
            let speed_rpm = (nc * f * 2.0_f64).round() / 2.0;
            if speed_rpm <= 125.0 {
                for shaft in [3, 8] {
                    out.push(Measurement {
                        order: k,
                        speed_rpm,
                        shaft,
                        torque: 1.0,
                    });
                }
            }
        }
    }
    out
}

fn gaussian(rng: &mut SmallRng) -> f64 {
    // Box–Muller.
    let u1: f64 = rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * (1.0 - u1).ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

fn noisy(truth: &[f64], noise: f64, seed: u64) -> Vec<Measurement> {
    let base = ident_base();
    let exc = ship_excitation();
    let mut data = ident_points();
    let (t, _) = predict(&base, &exc, &ident_params(), truth, &data);
    let mut rng = SmallRng::seed_from_u64(seed);
    for (m, t) in data.iter_mut().zip(t) {
        m.torque = t * (1.0 + noise * gaussian(&mut rng));
    }
    data
}

#[test]
fn identification_jacobian_matches_finite_differences() {
    // The two absolute parameters and a relative one (the cylinder-to-cylinder dampers,
    // half weight on the end segments, as in the report).
    let (mut base, exc, mut params, data) = (
        ident_base(),
        ship_excitation(),
        ident_params(),
        ident_points(),
    );
    base.relative_damping = vec![0.0; 10];
    params.push(DampingParameter {
        name: "cylinder_relative".into(),
        absolute: vec![],
        relative: vec![
            (0, 0.5),
            (1, 1.0),
            (2, 1.0),
            (3, 1.0),
            (4, 1.0),
            (5, 1.0),
            (6, 0.5),
        ],
    });
    let theta = [12_000.0, 300_000.0, 250_000.0];
    let (t0, jac) = predict(&base, &exc, &params, &theta, &data);
    for j in 0..3 {
        let h = 1e-4 * theta[j];
        let (mut tp, mut tm) = (theta, theta);
        tp[j] += h;
        tm[j] -= h;
        let (a, _) = predict(&base, &exc, &params, &tp, &data);
        let (b, _) = predict(&base, &exc, &params, &tm, &data);
        for i in 0..data.len() {
            let fd = (a[i] - b[i]) / (2.0 * h);
            assert!(
                (fd - jac[(i, j)]).abs() < 1e-6 * (t0[i] / theta[j]),
                "({i},{j}): {fd} vs {}",
                jac[(i, j)]
            );
        }
    }
    // chain_with puts the coefficients where the patterns say.
    let c = chain_with(&base, &params, &theta);
    assert_eq!(c.absolute_damping[3], 12_000.0);
    assert_eq!(c.absolute_damping[10], 300_000.0);
    assert_eq!(c.absolute_damping[0], 0.0);
    assert_eq!(c.relative_damping[0], 125_000.0);
    assert_eq!(c.relative_damping[3], 250_000.0);
    assert_eq!(c.relative_damping[7], 0.0);
    // With the report's values the model is the ship chain itself.
    let (t_ship, _) = predict(&ship(), &exc, &[], &[], &data);
    let (t_par, _) = predict(&base, &exc, &params, &[A_CYL, A_PROP, 316_200.0], &data);
    for (a, b) in t_ship.iter().zip(&t_par) {
        assert!(rel(*b, *a) < 1e-12);
    }
}

#[test]
fn identification_round_trip_within_reported_uncertainty() {
    let truth = [A_CYL, A_PROP];
    let (base, exc, params) = (ident_base(), ship_excitation(), ident_params());
    // Noise-free data: recovered to the solver's precision.
    let clean = noisy(&truth, 0.0, 1);
    let e0 = identify_damping(&base, &exc, &params, &clean, &[5_000.0, 100_000.0]).unwrap();
    for (v, t) in e0.values.iter().zip(truth) {
        assert!(rel(*v, t) < 1e-8, "{:?}", e0.values);
    }
    // 2 % noise: truth within 3 standard errors; the reported σ̂ matches the noise.
    let data = noisy(&truth, 0.02, 2024);
    let e = identify_damping(&base, &exc, &params, &data, &[5_000.0, 100_000.0]).unwrap();
    for (j, t) in truth.iter().enumerate() {
        let z = (e.values[j] - t) / e.std_errors[j];
        assert!(
            z.abs() < 3.0,
            "parameter {j}: {} ± {} (z = {z})",
            e.values[j],
            e.std_errors[j]
        );
        assert!(e.std_errors[j] < 0.1 * t);
    }
    assert!((e.sigma - 0.02).abs() < 0.006, "σ̂ = {}", e.sigma);
    // Less noise, smaller uncertainty (linearised: SE ∝ noise, so ~4× for 0.5 %).
    let quiet = identify_damping(
        &base,
        &exc,
        &params,
        &noisy(&truth, 0.005, 2024),
        &[5_000.0, 100_000.0],
    )
    .unwrap();
    for j in 0..2 {
        let ratio = e.std_errors[j] / quiet.std_errors[j];
        assert!(
            (3.0..5.5).contains(&ratio),
            "parameter {j}: SE ratio {ratio}"
        );
    }
}

#[test]
fn reported_standard_errors_match_the_scatter_of_repeated_fits() {
    // Monte Carlo over 40 noise seeds: the empirical standard deviation of the
    // estimates agrees with the mean reported standard error, and about 95 % of the
    // fits cover the truth with ±2 SE.
    let truth = [A_CYL, A_PROP];
    let (base, exc, params) = (ident_base(), ship_excitation(), ident_params());
    let runs = 40;
    let mut est = vec![Vec::new(); 2];
    let mut se = [0.0; 2];
    let mut covered = 0;
    for seed in 0..runs {
        let data = noisy(&truth, 0.02, 100 + seed);
        let e = identify_damping(&base, &exc, &params, &data, &[5_000.0, 100_000.0]).unwrap();
        let mut inside = true;
        for j in 0..2 {
            est[j].push(e.values[j]);
            se[j] += e.std_errors[j] / runs as f64;
            inside &= (e.values[j] - truth[j]).abs() < 2.0 * e.std_errors[j];
        }
        covered += inside as usize;
    }
    for j in 0..2 {
        let mean = est[j].iter().sum::<f64>() / runs as f64;
        let sd =
            (est[j].iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (runs - 1) as f64).sqrt();
        let ratio = sd / se[j];
        assert!(
            (0.65..1.5).contains(&ratio),
            "parameter {j}: scatter {sd} vs reported {}",
            se[j]
        );
        assert!((mean - truth[j]).abs() < 3.0 * se[j] / (runs as f64).sqrt() + 0.01 * truth[j]);
    }
    assert!(
        covered >= 32,
        "{covered}/{runs} fits cover the truth at ±2 SE"
    );
}

// ---------------------------------------------------------------------------------------
// Gears.

#[test]
fn geared_chain_has_the_frequencies_of_the_referred_chain() {
    // Motor — shaft — pinion | wheel (i = 3) — shaft — wheel2 | (i = 0.5) — shaft — load.
    let input = TorsionalChain::new(
        vec!["motor".into(), "pinion".into()],
        vec![0.5, 0.05],
        vec![4.0e3],
    )
    .unwrap();
    let s1 = TorsionalChain::new(
        vec!["wheel".into(), "pinion2".into()],
        vec![0.4, 0.02],
        vec![2.5e3],
    )
    .unwrap();
    let s2 = TorsionalChain::new(
        vec!["wheel2".into(), "load".into()],
        vec![0.1, 3.0],
        vec![9.0e3],
    )
    .unwrap();
    let (i1, i2) = (3.0, 0.5);
    let g = GearedChain::new(
        input,
        vec![
            GearStage {
                ratio: i1,
                chain: s1,
            },
            GearStage {
                ratio: i2,
                chain: s2,
            },
        ],
    )
    .unwrap();
    let r = g.refer();
    // The referred chain, written out by hand (× r², pinion and wheel merged).
    let r2 = i1 * i1;
    let r3 = (i1 * i2) * (i1 * i2);
    let hand = TorsionalChain::unnamed(
        vec![0.5, 0.05 + r2 * 0.4, r2 * 0.02 + r3 * 0.1, r3 * 3.0],
        vec![4.0e3, r2 * 2.5e3, r3 * 9.0e3],
    )
    .unwrap();
    assert_eq!(r.chain.inertia, hand.inertia);
    assert_eq!(r.chain.stiffness, hand.stiffness);
    let ref_modes = undamped_modes(&r.chain);
    // Route 1: Holzer through the gear meshes in physical units.
    let h = holzer_frequencies(&g);
    // Route 2: the constrained Lagrangian in physical angles, φ = G q.
    let n_phys = 6;
    let mut gm = DMatrix::zeros(n_phys, 4);
    for (p, &(k, ratio)) in r.mass_map.iter().enumerate() {
        gm[(p, k)] = ratio;
    }
    let j_phys = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![
        0.5, 0.05, 0.4, 0.02, 0.1, 3.0,
    ]));
    let mut k_phys = DMatrix::zeros(n_phys, n_phys);
    for (a, c) in [(0, 4.0e3), (2, 2.5e3), (4, 9.0e3)] {
        k_phys[(a, a)] += c;
        k_phys[(a + 1, a + 1)] += c;
        k_phys[(a, a + 1)] -= c;
        k_phys[(a + 1, a)] -= c;
    }
    let m_red = gm.transpose() * &j_phys * &gm;
    let k_red = gm.transpose() * &k_phys * &gm;
    let l = m_red.clone().cholesky().unwrap().l();
    let li = l.clone().try_inverse().unwrap();
    let mut lag: Vec<f64> = (&li * &k_red * li.transpose())
        .symmetric_eigenvalues()
        .iter()
        .copied()
        .collect();
    lag.sort_by(f64::total_cmp);
    for r_ in 1..4 {
        let w = ref_modes[r_].omega;
        assert!(rel(h[r_], w) < 1e-9, "Holzer {} vs {w}", h[r_]);
        assert!(
            rel(lag[r_].sqrt(), w) < 1e-9,
            "Lagrange {} vs {w}",
            lag[r_].sqrt()
        );
    }
    // Amplitudes map back: the Holzer angles (physical) are r × the referred shape.
    for m in &ref_modes[1..] {
        let t = holzer_table(&g, m.omega);
        let referred: Vec<f64> = m.shape.iter().map(|x| x / m.shape[0]).collect();
        let phys = r.physical_angles(&referred);
        for (a, b) in t.angles.iter().zip(&phys) {
            assert!((a - b).abs() < 1e-6 * b.abs().max(1.0), "{a} vs {b}");
        }
        // Shaft torques: physical = referred / r.
        let ref_torques = r.chain.shaft_torques(&referred);
        for (a, b) in t
            .shaft_torques
            .iter()
            .zip(r.physical_shaft_torques(&ref_torques))
        {
            assert!((a - b).abs() < 1e-6 * b.abs().max(1.0), "{a} vs {b}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// Absorbers.

#[test]
fn tuned_absorber_closed_form_matches_the_forced_chain() {
    let (j_r, j_a, c_a): (f64, f64, f64) = (10.0, 1.5, 6.0e4);
    let a = (c_a / j_a).sqrt();
    let chain = TorsionalChain::unnamed(vec![j_r, j_a], vec![c_a]).unwrap();
    for nu in [50.0, 150.0, 250.0] {
        // Drive the main disk with M cos νt: φ_r = −M / (ν² I_r).
        let r = harmonic_response(&chain, nu, &[0.0, 0.0], &[100.0, 0.0]).unwrap();
        let i_r = tuned_absorber_inertia(j_r, j_a, a, nu);
        assert!(rel(r.cos[0], -100.0 / (nu * nu * i_r)) < 1e-10, "ν = {nu}");
        assert!(r.sin[0].abs() < 1e-15);
    }
    // Tuned to the excitation (a = j w): the main disk stands still.
    let r = harmonic_response(&chain, a, &[0.0, 0.0], &[100.0, 0.0]).unwrap();
    assert!(
        r.cos[0].abs() < 1e-10 * r.cos[1].abs(),
        "{} vs {}",
        r.cos[0],
        r.cos[1]
    );
    assert!(tuned_absorber_inertia(j_r, j_a, a, a * (1.0 - 1e-9)).abs() > 1e8);
}

#[test]
fn lanchester_damper_closed_form_and_optimum() {
    let (j_r, j_a) = (10.0, 1.5);
    let nu = 120.0;
    let b_opt = lanchester_optimum_damping(j_a, nu);
    assert_eq!(b_opt, nu * j_a);
    let (i_r, b_r) = lanchester_damper(j_r, j_a, b_opt, nu);
    assert!(rel(i_r, j_r + j_a / 2.0) < 1e-15);
    assert!(rel(b_r, b_opt / 2.0) < 1e-15);
    // It is the optimum: any other b gives less effective damping.
    for f in [0.5, 0.9, 0.99, 1.01, 1.1, 2.0] {
        assert!(lanchester_damper(j_r, j_a, f * b_opt, nu).1 < b_r);
    }
    // Against the forced chain (disks joined only by the damper, c = 0): the phasor of
    // the main disk X = F / (−ν² I_r + iν b_r).
    for b in [0.3 * b_opt, b_opt, 4.0 * b_opt] {
        let chain = TorsionalChain::unnamed(vec![j_r, j_a], vec![0.0])
            .unwrap()
            .with_damping(vec![0.0, 0.0], vec![b])
            .unwrap();
        let r = harmonic_response(&chain, nu, &[0.0, 0.0], &[100.0, 0.0]).unwrap();
        let x = Complex::new(r.cos[0], -r.sin[0]);
        let (i_r, b_r) = lanchester_damper(j_r, j_a, b, nu);
        let want = Complex::new(100.0, 0.0) / Complex::new(-nu * nu * i_r, nu * b_r);
        assert!(
            (x - want).norm() < 1e-10 * want.norm(),
            "b = {b}: {x} vs {want}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// The same engine: the chain as an armsim Model.

#[test]
fn crba_of_the_chain_model_is_diag_j_in_absolute_angles() {
    let chain = ship();
    let model = chain.to_model().unwrap();
    assert_eq!(model.nv, 11);
    let mut data = Data::new(&model);
    let q: Vec<f64> = (0..11).map(|k| 0.3 * k as f64 - 1.0).collect();
    let m_rel = dynamics::crba(&model, &mut data, &q).clone();
    // φ = L q (L: relative → absolute); T = L⁻¹ maps absolute → relative, and the kinetic
    // energy ½ q̇ᵀ M q̇ = ½ φ̇ᵀ (Tᵀ M T) φ̇ gives M_abs = Tᵀ M T = L⁻ᵀ M L⁻¹.
    let l = chain.relative_to_absolute();
    let t = l.clone().try_inverse().unwrap();
    let m_abs = t.transpose() * &m_rel * &t;
    let j = chain.inertia_matrix();
    assert!((&m_abs - &j).norm() < 1e-9 * j.norm(), "{m_abs}");
    // The shafts are diag(0, c) in twists and the relative dampers the joint damping.
    let mut k_rel = DMatrix::zeros(11, 11);
    for k in 0..10 {
        k_rel[(k + 1, k + 1)] = chain.stiffness[k];
        assert_eq!(model.dof_joint(k + 1).damping, chain.relative_damping[k]);
    }
    let k_abs = t.transpose() * &k_rel * &t;
    assert!((&k_abs - chain.stiffness_matrix()).norm() < 1e-6);
    // ABA with spring-damper joint torques reproduces the chain's accelerations.
    let mut free = ship_undamped()
        .with_damping(vec![0.0; 11], chain.relative_damping.clone())
        .unwrap();
    free.names = chain.names.clone();
    let qd: Vec<f64> = (0..11).map(|k| 0.05 * (k as f64).sin()).collect();
    let tau: Vec<f64> = (0..11)
        .map(|k| {
            if k == 0 {
                0.0
            } else {
                -free.stiffness[k - 1] * q[k] - free.relative_damping[k - 1] * qd[k]
            }
        })
        .collect();
    let mut model = model;
    model.gravity = Vec3::zeros();
    let qdd = dynamics::aba(&model, &mut data, &q, &qd, &tau).to_vec();
    let phi: Vec<f64> = (&l * nalgebra::DVector::from_column_slice(&q))
        .iter()
        .copied()
        .collect();
    let phid: Vec<f64> = (&l * nalgebra::DVector::from_column_slice(&qd))
        .iter()
        .copied()
        .collect();
    let mut rk = Rk4::new(&free);
    let mut acc = vec![0.0; 11];
    rk.acceleration(
        0.0,
        &phi,
        &phid,
        &mut |_, m: &mut [f64]| m.fill(0.0),
        &mut acc,
    );
    let acc_rel = &t * nalgebra::DVector::from_vec(acc);
    let scale = acc_rel.amax();
    for k in 0..11 {
        assert!(
            (qdd[k] - acc_rel[k]).abs() < 1e-9 * scale,
            "q̈[{k}] {} vs {}",
            qdd[k],
            acc_rel[k]
        );
    }
}

#[test]
fn flexible_joint_and_two_mass_chain_agree() {
    // Spong's flexible joint (motor inertia J_m, spring k, damper d, link inertia J_l)
    // is the two-mass chain (J_m, J_l; c = k, b = d), motor first.
    let (jm, jl, k, d) = (0.2, 0.8, 400.0, 0.6);
    let m = common::single_joint(jl);
    let e = Effects {
        elasticity: Some(Elasticity {
            stiffness: vec![k],
            damping: vec![d],
            motor_inertia: vec![jm],
        }),
        ..Default::default()
    };
    let mut data = Data::new(&m);
    // Engine state derivative, state (q, q̇, θ, θ̇).
    let mut f = |s: [f64; 4]| -> [f64; 4] {
        let mut thdd = [0.0];
        let qdd = dynamics::elastic_forward_dynamics(
            &m,
            &mut data,
            &e,
            &[s[0]],
            &[s[1]],
            &[s[2]],
            &[s[3]],
            &[0.0],
            &mut thdd,
        )
        .unwrap()[0];
        [s[1], qdd, s[3], thdd[0]]
    };
    let chain = TorsionalChain::new(vec!["motor".into(), "link".into()], vec![jm, jl], vec![k])
        .unwrap()
        .with_damping(vec![0.0, 0.0], vec![d])
        .unwrap();
    // Frequency: eigenvalues of the engine's (linear) state map, by central differences.
    let mut a = DMatrix::zeros(4, 4);
    for c in 0..4 {
        let mut sp = [0.0; 4];
        let mut sm = [0.0; 4];
        sp[c] = 1e-3;
        sm[c] = -1e-3;
        let (fp, fm) = (f(sp), f(sm));
        for r in 0..4 {
            a[(r, c)] = (fp[r] - fm[r]) / 2e-3;
        }
    }
    let ev = a.complex_eigenvalues();
    let engine = ev
        .iter()
        .copied()
        .filter(|z| z.im > 1e-6)
        .fold(Complex::new(0.0, 0.0), |_, z| z);
    let dm = damped_modes(&chain);
    let lam = dm.oscillatory[0].eigenvalue;
    assert!(
        (engine - lam).norm() < 1e-9 * lam.norm(),
        "engine {engine} vs chain {lam}"
    );
    let p = (k * (1.0 / jm + 1.0 / jl)).sqrt();
    let undamped = chain
        .clone()
        .with_damping(vec![0.0, 0.0], vec![0.0])
        .unwrap();
    assert!(rel(undamped_modes(&undamped)[1].omega, p) < 1e-12);
    // Time response from an initial twist, same RK4 step on both sides, and both against
    // the closed form δ̈ + 2ζp δ̇ + p² δ = 0 (δ = θ − q) with 2ζp = d (1/J_m + 1/J_l).
    let h = 1e-5;
    let mut s = [0.0, 0.0, 0.01, 0.0];
    let mut rk = Rk4::new(&chain);
    let (mut x, mut v) = ([0.01, 0.0], [0.0, 0.0]);
    let mut zero = |_: f64, out: &mut [f64]| out.fill(0.0);
    let two_zeta_p = d * (1.0 / jm + 1.0 / jl);
    let sigma = 0.5 * two_zeta_p;
    let wd = (p * p - sigma * sigma).sqrt();
    let closed =
        |t: f64| 0.01 * (-sigma * t).exp() * ((wd * t).cos() + sigma / wd * (wd * t).sin());
    let mut worst_pair: f64 = 0.0;
    let mut worst_closed: f64 = 0.0;
    for n in 0..20_000 {
        let k1 = f(s);
        let add = |s: [f64; 4], k: [f64; 4], c: f64| {
            [
                s[0] + c * k[0],
                s[1] + c * k[1],
                s[2] + c * k[2],
                s[3] + c * k[3],
            ]
        };
        let k2 = f(add(s, k1, h / 2.0));
        let k3 = f(add(s, k2, h / 2.0));
        let k4 = f(add(s, k3, h));
        for i in 0..4 {
            s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        rk.step(n as f64 * h, h, &mut x, &mut v, &mut zero);
        // Chain disk 0 = motor θ, disk 1 = link q.
        worst_pair = worst_pair.max((x[0] - s[2]).abs()).max((x[1] - s[0]).abs());
        worst_closed = worst_closed.max(((x[0] - x[1]) - closed((n + 1) as f64 * h)).abs());
    }
    assert!(worst_pair < 1e-9 * 0.01, "engine vs chain: {worst_pair}");
    assert!(
        worst_closed < 1e-9 * 0.01,
        "chain vs closed form: {worst_closed}"
    );
    // Momentum: J_m θ̇ + J_l q̇ = 0 on both sides.
    assert!((jm * v[0] + jl * v[1]).abs() < 1e-12);
}

// ---------------------------------------------------------------------------------------
// Scenarios.

#[test]
fn ship_scenario_runs_and_names_its_masses() {
    let r = armsim::scenarios::run_file(&root().join("scenarios/ship_shafting.toml")).unwrap();
    let j = &r.json;
    let masses = j["masses"].as_array().unwrap();
    assert_eq!(masses.len(), 11);
    assert_eq!(masses[10], "propeller");
    assert_eq!(j["shafts"].as_array().unwrap().len(), 10);
    let modes = j["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 11);
    assert_eq!(modes[0]["frequency_cpm"].as_f64().unwrap(), 0.0);
    for (m, published) in modes[1..4].iter().zip([354.1, 1197.6, 2373.6]) {
        assert!((m["frequency_cpm"].as_f64().unwrap() - published).abs() < 0.1);
        assert_eq!(m["shape"].as_array().unwrap().len(), 11);
    }
    let dm = j["damped_modes"].as_array().unwrap();
    assert_eq!(dm.len(), 10);
    for d in dm {
        assert!(d["eigenvalue"][1].as_f64().unwrap() > 0.0);
        assert!(d["eigenvalue"][0].as_f64().unwrap() < 0.0);
        let shape = d["shape"].as_array().unwrap();
        assert_eq!(shape.len(), 11);
        assert_eq!(shape[0].as_array().unwrap().len(), 2);
    }
    assert_eq!(j["forced"].as_array().unwrap().len(), 12);
    let f6 = &j["forced"][5];
    assert_eq!(f6["order"].as_f64(), Some(6.0));
    assert_eq!(f6["shaft_torque_Nm"].as_array().unwrap().len(), 10);
    assert!((f6["peak"]["speed_rpm"].as_f64().unwrap() - 59.0).abs() <= 0.5);
    let crit = j["critical_speeds"].as_array().unwrap();
    let c61 = crit
        .iter()
        .find(|c| c["order"].as_f64() == Some(6.0) && c["mode"] == 1)
        .unwrap();
    assert!((c61["speed_rpm"].as_f64().unwrap() - 59.0).abs() < 0.05);
    assert!((c61["relative_excitation"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    assert!(j["time_check"]["max_relative_difference"].as_f64().unwrap() < 1e-6);
    let id = &j["identification"]["parameters"];
    for (p, truth) in id.as_array().unwrap().iter().zip([A_CYL, A_PROP]) {
        let (v, se) = (
            p["estimate"].as_f64().unwrap(),
            p["std_error"].as_f64().unwrap(),
        );
        assert!((v - truth).abs() < 3.0 * se, "{v} ± {se} vs {truth}");
    }
    assert!(r.text.contains("354.09"));
    assert!(r.text.contains("major (in phase)"));
}

#[test]
fn ship_scenario_measurements_are_the_documented_synthetic_data() {
    // The file says: model with the report's damping, orders 4–6 and 10–12 around the
    // first two resonances, 2 % Gaussian relative noise, SmallRng seed 2024. Regenerate.
    let text = std::fs::read_to_string(root().join("scenarios/ship_shafting.toml")).unwrap();
    let table: toml::Table = toml::from_str(&text).unwrap();
    let listed = table["identification"]["measurements"].as_array().unwrap();
    let names = ship().names;
    let regenerated = noisy(&[A_CYL, A_PROP], 0.02, 2024);
    assert_eq!(listed.len(), regenerated.len());
    for (l, m) in listed.iter().zip(&regenerated) {
        let num = |k: &str| {
            l[k].as_float()
                .or(l[k].as_integer().map(|i| i as f64))
                .unwrap()
        };
        assert_eq!(num("order"), m.order);
        assert_eq!(num("speed_rpm"), m.speed_rpm);
        assert_eq!(l["between"][0].as_str().unwrap(), names[m.shaft]);
        assert_eq!(l["between"][1].as_str().unwrap(), names[m.shaft + 1]);
        assert!(
            rel(num("torque"), m.torque) < 1e-5,
            "{} vs {}",
            num("torque"),
            m.torque
        );
    }
}

#[test]
fn two_mass_scenario_runs() {
    let r = armsim::scenarios::run_file(&root().join("scenarios/torsional_two_mass.toml")).unwrap();
    let j = &r.json;
    let p = (2.0e4_f64 * (1.0 / 1.2 + 1.0 / 0.8)).sqrt();
    assert!(rel(j["modes"][1]["frequency_rad_s"].as_f64().unwrap(), p) < 1e-12);
    let mu = 1.2 * 0.8 / 2.0;
    let zeta = 20.0 / (2.0 * (2.0e4_f64 * mu).sqrt());
    let l = &j["damped_modes"][0]["eigenvalue"];
    assert!(rel(l[0].as_f64().unwrap(), -zeta * p) < 1e-12);
    assert!(rel(l[1].as_f64().unwrap(), p * (1.0 - zeta * zeta).sqrt()) < 1e-12);
    assert_eq!(j["masses"][0], "engine");
}

/// What each broken scenario must report: file → (line, key, message fragment).
const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "torsional_negative_inertia.toml",
        7,
        "chain.inertia[2]",
        "must be positive",
    ),
    (
        "torsional_stiffness_count.toml",
        7,
        "chain.stiffness",
        "2 values, expected 3",
    ),
    (
        "torsional_unknown_key.toml",
        8,
        "chain.damping",
        "unknown field",
    ),
    (
        "torsional_wrong_type.toml",
        5,
        "chain.inertia",
        "invalid type",
    ),
    (
        "torsional_unknown_cylinder.toml",
        10,
        "engine.cylinders[1]",
        "'cyl9' is not a disk",
    ),
    (
        "torsional_measurement_shaft.toml",
        24,
        "identification.measurements[1].between",
        "not adjacent",
    ),
    (
        "torsional_time_step.toml",
        22,
        "time_check.steps_per_period",
        "too long for the highest mode",
    ),
    (
        "torsional_excitation_without_engine.toml",
        8,
        "excitation",
        "needs an [engine]",
    ),
    (
        "torsional_too_many_disks.toml",
        7,
        "chain.inertia",
        "201 disks: at most 200",
    ),
    (
        "torsional_sweep_too_much_work.toml",
        20,
        "sweep.points",
        "too much work",
    ),
    (
        "torsional_time_check_too_long.toml",
        21,
        "time_check.periods",
        "at most 1e7 RK4 steps",
    ),
];

#[test]
fn broken_torsional_scenarios_give_located_errors() {
    let dir = root().join("tests/broken_scenarios");
    for (file, line, key, msg) in BROKEN {
        let path = dir.join(file);
        let e = match armsim::scenarios::run_file(&path) {
            Ok(_) => panic!("{file}: expected an error"),
            Err(e) => e,
        };
        assert_eq!(e.line, Some(*line), "{file}: {e}");
        assert_eq!(e.key, *key, "{file}: {e}");
        assert!(e.message.contains(msg), "{file}: {e}");
        let shown = e.to_string();
        assert!(
            shown.starts_with(&format!("{}:{line}: {key}: ", path.display())),
            "{shown}"
        );
    }
    // Every torsional_* file in the directory is listed above.
    let listed: Vec<&str> = BROKEN.iter().map(|b| b.0).collect();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name.starts_with("torsional_") {
            assert!(listed.contains(&name.as_str()), "{name} is not checked");
        }
    }
}
