//! Batched inverse dynamics in SIMD lanes (`dynamics::rnea_lanes`) against the scalar
//! RNEA, state by state, on every robot in `robots/` (revolute and prismatic joints,
//! general and permuted placements), a tree (two arms on one torso), the mimic gripper and
//! a generated chain, with gravity off the z axis and armature; every instruction set
//! against the baseline, bit for bit; the row driver's scalar fallbacks. The same for
//! forward dynamics (`dynamics::aba_lanes`) against the scalar ABA, and ABA(RNEA(q̈)) = q̈.

mod common;

use armsim::core::simd_lanes::{Isa, Lanes, LANES};
use armsim::core::spatial::Vec3;
use armsim::dynamics::{self, AbaLanes, CrbaLanes, RneaLanes};
use armsim::model::data::Data;
use armsim::model::Model;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

/// Every test model with a tilted gravity and a random armature on every coordinate.
fn models() -> Vec<(String, Model)> {
    let mut v = common::test_models(12);
    v.push(("dual_arm".into(), common::load("tests/data/dual_arm.urdf")));
    let mut rng = SmallRng::seed_from_u64(11);
    for (_, m) in &mut v {
        m.gravity = Vec3::new(0.3, -0.2, -9.81);
        for a in &mut m.armature {
            *a = rng.random_range(0.0..0.2);
        }
    }
    v
}

/// `n` random rows of `(q, q̇, q̈)`, row-major.
fn rows(m: &Model, n: usize, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = SmallRng::seed_from_u64(seed);
    let (mut q, mut v, mut a) = (vec![], vec![], vec![]);
    for _ in 0..n {
        q.extend(m.random_q(&mut rng));
        v.extend(common::rand_vec(&mut rng, m.nv, 2.0));
        a.extend(common::rand_vec(&mut rng, m.nv, 3.0));
    }
    (q, v, a)
}

/// Rows `r0..r0 + 8` as one lane array per coordinate.
fn lanes(x: &[f64], nv: usize, r0: usize) -> Vec<Lanes> {
    (0..nv)
        .map(|k| std::array::from_fn(|l| x[(r0 + l) * nv + k]))
        .collect()
}

fn scalar_rows(m: &Model, q: &[f64], v: &[f64], a: &[f64]) -> Vec<f64> {
    let mut d = Data::new(m);
    let nv = m.nv;
    (0..q.len() / nv)
        .flat_map(|r| {
            let s = r * nv..(r + 1) * nv;
            dynamics::rnea(m, &mut d, &q[s.clone()], &v[s.clone()], &a[s]).to_vec()
        })
        .collect()
}

/// `|x − y| ≤ tol · max(1, |y|)` entry by entry.
fn assert_rel(what: &str, x: &[f64], y: &[f64], tol: f64) {
    assert_eq!(x.len(), y.len(), "{what}: length");
    for (k, (a, b)) in x.iter().zip(y).enumerate() {
        assert!(
            (a - b).abs() <= tol * b.abs().max(1.0),
            "{what}: entry {k}: lanes {a} against scalar {b}"
        );
    }
}

#[test]
fn rnea_in_lanes_equals_scalar_rnea_state_by_state() {
    for (name, m) in models() {
        let (q, v, a) = rows(&m, 4 * LANES, 3);
        let want = scalar_rows(&m, &q, &v, &a);
        let mut w = RneaLanes::new(&m);
        let nv = m.nv;
        for r0 in (0..4 * LANES).step_by(LANES) {
            let tau = w.rnea(
                &m,
                &lanes(&q, nv, r0),
                &lanes(&v, nv, r0),
                &lanes(&a, nv, r0),
            );
            for l in 0..LANES {
                let got: Vec<f64> = tau.iter().map(|t| t[l]).collect();
                let r = r0 + l;
                assert_rel(
                    &format!("{name} row {r}"),
                    &got,
                    &want[r * nv..(r + 1) * nv],
                    1e-12,
                );
            }
        }
    }
}

#[test]
fn rnea_in_lanes_is_bitwise_the_same_on_every_instruction_set() {
    for (name, m) in models() {
        let (q, v, a) = rows(&m, LANES, 4);
        let nv = m.nv;
        let (lq, lv, la) = (lanes(&q, nv, 0), lanes(&v, nv, 0), lanes(&a, nv, 0));
        let mut base = RneaLanes::new(&m);
        base.limit_isa(Isa::Baseline);
        assert_eq!(base.isa(), Isa::Baseline);
        let want: Vec<Lanes> = base.rnea(&m, &lq, &lv, &la).to_vec();
        for isa in [Isa::Avx2, Isa::Avx512] {
            if isa > Isa::detected() {
                continue;
            }
            let mut w = RneaLanes::new(&m);
            w.limit_isa(isa);
            let got = w.rnea(&m, &lq, &lv, &la);
            for (k, (g, b)) in got.iter().zip(&want).enumerate() {
                let (g, b) = (g.map(f64::to_bits), b.map(f64::to_bits));
                assert_eq!(
                    g, b,
                    "{name}: {isa:?} coordinate {k} differs from the baseline"
                );
            }
        }
    }
}

#[test]
fn rnea_rows_equals_scalar_rnea_with_tail_and_out_of_range_rows() {
    for (name, mut m) in models() {
        // A tail of 5 rows, and one group holding a joint value beyond the lane sin_cos
        // range, which must go through the scalar code (same torques).
        let n = 3 * LANES + 5;
        let (mut q, v, a) = rows(&m, n, 5);
        q[LANES * m.nv + 2 * m.nv] = 2.5e4;
        m.armature[0] = 0.0;
        let want = scalar_rows(&m, &q, &v, &a);
        let mut w = RneaLanes::new(&m);
        let mut tau = vec![f64::NAN; q.len()];
        dynamics::rnea_rows(&m, &mut w, &q, &v, &a, &mut tau);
        assert_rel(&name, &tau, &want, 1e-12);
        let fallback = LANES * m.nv..2 * LANES * m.nv;
        assert_eq!(
            tau[fallback.clone()],
            want[fallback],
            "{name}: scalar rows are the scalar code's"
        );
    }
}

#[test]
fn rnea_rows_passes_non_finite_inputs_to_the_scalar_code() {
    let m = common::load("robots/ur5.urdf");
    let (mut q, v, a) = rows(&m, LANES, 6);
    q[3] = f64::NAN;
    let mut tau = vec![0.0; q.len()];
    dynamics::rnea_rows(&m, &mut RneaLanes::new(&m), &q, &v, &a, &mut tau);
    assert!(
        tau[..m.nv].iter().any(|t| t.is_nan()),
        "row 0's NaN propagates"
    );
    let want = scalar_rows(&m, &q[m.nv..], &v[m.nv..], &a[m.nv..]);
    assert_eq!(
        tau[m.nv..],
        want[..],
        "the other rows are the scalar code's"
    );
}

/// The models without mimic joints (ABA needs one coordinate per body).
fn aba_models() -> Vec<(String, Model)> {
    models().into_iter().filter(|(_, m)| !m.has_mimic).collect()
}

fn scalar_aba_rows(m: &Model, q: &[f64], v: &[f64], t: &[f64]) -> Vec<f64> {
    let mut d = Data::new(m);
    let nv = m.nv;
    (0..q.len() / nv)
        .flat_map(|r| {
            let s = r * nv..(r + 1) * nv;
            dynamics::aba(m, &mut d, &q[s.clone()], &v[s.clone()], &t[s]).to_vec()
        })
        .collect()
}

#[test]
fn aba_in_lanes_equals_scalar_aba_state_by_state() {
    let ms = aba_models();
    assert!(ms.len() >= 8, "every robot, the tree and the chain");
    for (name, m) in ms {
        let (q, v, t) = rows(&m, 4 * LANES, 7);
        let want = scalar_aba_rows(&m, &q, &v, &t);
        let mut w = AbaLanes::new(&m);
        let nv = m.nv;
        for r0 in (0..4 * LANES).step_by(LANES) {
            let qdd = w.aba(
                &m,
                &lanes(&q, nv, r0),
                &lanes(&v, nv, r0),
                &lanes(&t, nv, r0),
            );
            for l in 0..LANES {
                let got: Vec<f64> = qdd.iter().map(|x| x[l]).collect();
                let r = r0 + l;
                let scale = want[r * nv..(r + 1) * nv]
                    .iter()
                    .fold(1.0f64, |a, x| a.max(x.abs()));
                let err = got
                    .iter()
                    .zip(&want[r * nv..(r + 1) * nv])
                    .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
                assert!(
                    err <= 1e-10 * scale,
                    "{name} row {r}: |Δq̈| {err:e} (scale {scale:e})"
                );
            }
        }
    }
}

#[test]
fn aba_in_lanes_inverts_rnea_in_lanes() {
    for (name, m) in aba_models() {
        let (q, v, a) = rows(&m, LANES, 8);
        let nv = m.nv;
        let (lq, lv, la) = (lanes(&q, nv, 0), lanes(&v, nv, 0), lanes(&a, nv, 0));
        let tau: Vec<Lanes> = RneaLanes::new(&m).rnea(&m, &lq, &lv, &la).to_vec();
        let qdd = AbaLanes::new(&m).aba(&m, &lq, &lv, &tau).to_vec();
        for (k, (x, y)) in qdd.iter().zip(&la).enumerate() {
            for l in 0..LANES {
                assert!(
                    (x[l] - y[l]).abs() <= 1e-8 * y[l].abs().max(1.0),
                    "{name} q̈[{k}] lane {l}: {} against {}",
                    x[l],
                    y[l]
                );
            }
        }
    }
}

#[test]
fn aba_in_lanes_is_bitwise_the_same_on_every_instruction_set() {
    for (name, m) in aba_models() {
        let (q, v, t) = rows(&m, LANES, 9);
        let nv = m.nv;
        let (lq, lv, lt) = (lanes(&q, nv, 0), lanes(&v, nv, 0), lanes(&t, nv, 0));
        let mut base = AbaLanes::new(&m);
        base.limit_isa(Isa::Baseline);
        let want: Vec<Lanes> = base.aba(&m, &lq, &lv, &lt).to_vec();
        for isa in [Isa::Avx2, Isa::Avx512] {
            if isa > Isa::detected() {
                continue;
            }
            let mut w = AbaLanes::new(&m);
            w.limit_isa(isa);
            let got = w.aba(&m, &lq, &lv, &lt);
            for (k, (g, b)) in got.iter().zip(&want).enumerate() {
                assert_eq!(
                    g.map(f64::to_bits),
                    b.map(f64::to_bits),
                    "{name}: {isa:?} q̈[{k}]"
                );
            }
        }
    }
}

#[test]
fn aba_rows_equals_scalar_aba_with_tail_and_out_of_range_rows() {
    for (name, m) in aba_models() {
        let n = 2 * LANES + 3;
        let (mut q, v, t) = rows(&m, n, 10);
        q[LANES * m.nv + m.nv - 1] = -3e4;
        let want = scalar_aba_rows(&m, &q, &v, &t);
        let mut got = vec![f64::NAN; q.len()];
        dynamics::aba_rows(&m, &mut AbaLanes::new(&m), &q, &v, &t, &mut got);
        let fallback = LANES * m.nv..n * m.nv;
        assert_eq!(
            got[fallback.clone()],
            want[fallback],
            "{name}: scalar rows are the scalar code's"
        );
        let scale = want.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        for (k, (x, y)) in got.iter().zip(&want).enumerate() {
            assert!(
                (x - y).abs() <= 1e-10 * scale,
                "{name} entry {k}: {x} against {y}"
            );
        }
    }
}

/// The scalar CRBA's `M` for every row of `q`, concatenated (column-major).
fn scalar_crba_rows(m: &Model, q: &[f64]) -> Vec<f64> {
    let mut d = Data::new(m);
    let nv = m.nv;
    (0..q.len() / nv)
        .flat_map(|r| {
            dynamics::crba(m, &mut d, &q[r * nv..(r + 1) * nv])
                .as_slice()
                .to_vec()
        })
        .collect()
}

#[test]
fn crba_in_lanes_equals_scalar_crba_state_by_state() {
    // Mimic joints included: CRBA sums G^T M G onto the independent coordinates.
    for (name, m) in models() {
        let (q, _, _) = rows(&m, LANES, 12);
        let mut w = CrbaLanes::new(&m);
        let got = w.crba(&m, &lanes(&q, m.nv, 0)).to_vec();
        let want = scalar_crba_rows(&m, &q);
        let nn = m.nv * m.nv;
        for l in 0..LANES {
            let lane: Vec<f64> = got.iter().map(|x| x[l]).collect();
            assert_rel(
                &format!("{name} lane {l}: M"),
                &lane,
                &want[l * nn..(l + 1) * nn],
                1e-12,
            );
        }
    }
}

#[test]
fn crba_in_lanes_is_bitwise_the_same_on_every_instruction_set() {
    for (name, m) in models() {
        let (q, _, _) = rows(&m, LANES, 13);
        let lq = lanes(&q, m.nv, 0);
        let mut base = CrbaLanes::new(&m);
        base.limit_isa(Isa::Baseline);
        assert_eq!(base.isa(), Isa::Baseline);
        let want: Vec<Lanes> = base.crba(&m, &lq).to_vec();
        for isa in [Isa::Avx2, Isa::Avx512] {
            if isa > Isa::detected() {
                continue;
            }
            let mut w = CrbaLanes::new(&m);
            w.limit_isa(isa);
            let same = w
                .crba(&m, &lq)
                .iter()
                .zip(&want)
                .all(|(g, b)| g.map(f64::to_bits) == b.map(f64::to_bits));
            assert!(same, "{name}: {isa:?} differs from the baseline");
        }
    }
}

#[test]
fn crba_rows_equals_scalar_crba_with_tail_and_out_of_range_rows() {
    for (name, m) in models() {
        let n = 3 * LANES + 5;
        let (mut q, _, _) = rows(&m, n, 14);
        q[LANES * m.nv] = 2.5e4; // row 8, group 1: beyond the lane sin_cos range
        let mut mass = vec![f64::NAN; n * m.nv * m.nv];
        dynamics::crba_rows(&m, &mut CrbaLanes::new(&m), &q, &mut mass);
        assert_rel(
            &format!("{name}: M rows"),
            &mass,
            &scalar_crba_rows(&m, &q),
            1e-12,
        );
    }
}

#[test]
fn crba_in_lanes_inverts_aba_in_lanes() {
    // M(q) (ABA(q, 0, τ) with gravity off) = τ: the mass matrix times ABA's q̈.
    for (name, mut m) in aba_models() {
        m.gravity = Vec3::zeros();
        let (q, _, t) = rows(&m, LANES, 15);
        let (nv, lq, lt) = (m.nv, lanes(&q, m.nv, 0), lanes(&t, m.nv, 0));
        let zero = vec![[0.0; LANES]; nv];
        let qdd = AbaLanes::new(&m).aba(&m, &lq, &zero, &lt).to_vec();
        let mass = CrbaLanes::new(&m).crba(&m, &lq).to_vec();
        for l in 0..LANES {
            let tau: Vec<f64> = (0..nv)
                .map(|r| (0..nv).map(|c| mass[c * nv + r][l] * qdd[c][l]).sum())
                .collect();
            let want: Vec<f64> = (0..nv).map(|k| lt[k][l]).collect();
            assert_rel(&format!("{name} lane {l}: M q̈ = τ"), &tau, &want, 1e-9);
        }
    }
}
