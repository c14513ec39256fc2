//! Analytical derivatives of forward dynamics, `∂q̈/∂q`, `∂q̈/∂q̇` and `∂q̈/∂τ = M⁻¹`
//! (Carpentier & Mansard, RSS 2018, §IV-C). Differentiating `ID(q, q̇, FD(q, q̇, τ)) = τ`:
//!
//! `∂q̈/∂q = −M⁻¹ ∂ID/∂q`, `∂q̈/∂q̇ = −M⁻¹ ∂ID/∂q̇`, `∂q̈/∂τ = M⁻¹`,
//!
//! with the inverse-dynamics partials ([`crate::dynamics::rnea_derivatives`]) taken at
//! `q̈ = FD(q, q̇, τ) = M⁻¹(τ − h)` and `M⁻¹` from [`crate::dynamics::compute_minverse`].

use crate::core::linalg::SingularMassMatrix;
use crate::core::simd_lanes::Isa;
use crate::dynamics::forward::name_joint;
use crate::dynamics::minverse::minverse_after_placements;
use crate::dynamics::rnea::add_armature;
use crate::dynamics::rnea_derivatives::{add_joint_accelerations, backward_pass, forward_pass};
use crate::dynamics::terms::Terms;
use crate::kinematics::forward_kinematics;
use crate::model::data::Data;
use crate::model::derivative_data::DerivativeData;
use crate::model::{Model, WORLD};
use nalgebra::DMatrix;

/// The partial derivatives of `q̈ = FD(q, q̇, τ)` ([`aba_derivatives`]), held in
/// [`Data::deriv`].
#[derive(Clone, Copy, Debug)]
pub struct AbaPartials<'a> {
    /// `∂q̈/∂q`, nv × nv.
    pub ddq_dq: &'a DMatrix<f64>,
    /// `∂q̈/∂q̇`, nv × nv.
    pub ddq_dv: &'a DMatrix<f64>,
    /// `∂q̈/∂τ = M(q)⁻¹`.
    pub minv: &'a DMatrix<f64>,
}

/// `∂q̈/∂q`, `∂q̈/∂q̇` and `M⁻¹` at `(q, q̇, τ)` with the model's gravity and armature, as
/// Pinocchio's `computeABADerivatives(model, data, q, v, tau)`; `data.qdd` gets `q̈`.
/// Fails when the mass matrix is singular or `q̈` is not finite.
///
/// One forward pass serves both: run with `q̈ = 0` it gives the bias `h(q, q̇)`, then
/// `q̈ = M⁻¹(τ − h)`, whose accelerations are added to it
/// ([`crate::dynamics::rnea_derivatives`] is affine in `q̈`) before the backward pass.
pub fn aba_derivatives<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<AbaPartials<'a>, SingularMassMatrix> {
    let nv = model.nv;
    assert!(
        q.len() == nv && v.len() == nv && tau.len() == nv,
        "q, v, tau need nv values"
    );
    data.deriv.ensure(model);
    let terms = Terms::of_model(model);
    forward_kinematics(model, data, q);
    let zero = std::mem::take(&mut data.scratch_nv);
    forward_pass(model, data, v, &zero, &terms);
    data.scratch_nv = zero;
    bias_to_rhs(model, data, tau);
    minverse_after_placements(model, data, q)?;
    solve_accelerations(model, data)?;
    let qdd = std::mem::take(&mut data.qdd);
    add_joint_accelerations(model, data, &qdd);
    backward_pass(model, data, &terms);
    add_armature(model, &terms, &qdd, &mut data.tau);
    data.qdd = qdd;
    let DerivativeData {
        dtau_dq,
        dtau_dv,
        ddq_dq,
        ddq_dv,
        minv,
        isa,
        ..
    } = &mut data.deriv;
    neg_product(ddq_dq, minv, dtau_dq, *isa);
    neg_product(ddq_dv, minv, dtau_dv, *isa);
    Ok(AbaPartials {
        ddq_dq: &data.deriv.ddq_dq,
        ddq_dv: &data.deriv.ddq_dv,
        minv: &data.deriv.minv,
    })
}

/// `τ − h(q, q̇)` into `data.deriv.rhs`, from the forces of a forward pass with `q̈ = 0`.
fn bias_to_rhs(model: &Model, data: &mut Data, tau: &[f64]) {
    let d = &mut data.deriv;
    d.bias_f.copy_from_slice(&d.of);
    d.rhs.copy_from_slice(tau);
    for i in (0..model.nbodies()).rev() {
        let f = d.bias_f[i];
        d.rhs[model.q_index[i]] -= model.q_mult[i] * f.dot_motion(&data.s_world[i]);
        let parent = model.parent[i];
        if parent != WORLD {
            d.bias_f[parent] = d.bias_f[parent].add(&f);
        }
    }
}

/// `q̈ = M⁻¹ (τ − h)` into `data.qdd`; a non-finite `q̈` with a factorable `M` means the
/// inputs overflowed.
fn solve_accelerations(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    let n = model.nv;
    let (minv, rhs) = (data.deriv.minv.as_slice(), &data.deriv.rhs);
    data.qdd.fill(0.0);
    for (k, col) in minv.chunks_exact(n).enumerate() {
        let x = rhs[k];
        for (o, m) in data.qdd.iter_mut().zip(col) {
            *o += m * x;
        }
    }
    if let Some(bad) = data.qdd.iter().position(|x| !x.is_finite()) {
        let mut e = SingularMassMatrix::at(bad, 0.0);
        e.inputs_overflow = true;
        return Err(name_joint(e, model));
    }
    Ok(())
}

/// Up to this many coordinates [`neg_product`] sums columns directly; above, the blocked
/// product of nalgebra (matrixmultiply) is faster.
pub(crate) const DIRECT_PRODUCT_MAX: usize = 24;

/// Up to this many coordinates (every bundled arm) [`neg_product`] is compiled for the
/// size: the loops unrolled, each column summed in registers.
const FIXED_PRODUCT_MAX: usize = 12;

/// `out = −a b` for square column-major matrices, on at most the instruction set `isa`
/// (the one chosen when the derivative buffers were sized): at arm sizes column by column as sums
/// of `a`'s columns (contiguous, so the inner loop vectorises, and no packing), else the
/// blocked general product. Every size sums in the same order (`k` ascending from 0), so
/// the fixed-size and AVX2 forms give the same bits as the loop.
pub(crate) fn neg_product(out: &mut DMatrix<f64>, a: &DMatrix<f64>, b: &DMatrix<f64>, isa: Isa) {
    let n = a.nrows();
    if n > DIRECT_PRODUCT_MAX {
        out.gemm(-1.0, a, b, 0.0);
        return;
    }
    let (o, a, b) = (out.as_mut_slice(), a.as_slice(), b.as_slice());
    if n <= FIXED_PRODUCT_MAX {
        #[cfg(target_arch = "x86_64")]
        if isa >= Isa::Avx2 {
            // SAFETY: `isa` is at most what `Isa::detected` found on this CPU.
            return unsafe { neg_product_small_avx2(n, o, a, b) };
        }
        return neg_product_small(n, o, a, b);
    }
    for (c, oc) in o.chunks_exact_mut(n).enumerate() {
        oc.fill(0.0);
        for (k, ak) in a.chunks_exact(n).enumerate() {
            let x = -b[c * n + k];
            for (o, y) in oc.iter_mut().zip(ak) {
                *o += x * y;
            }
        }
    }
}

/// [`neg_product_small`] compiled for AVX2 (no fused multiply-add: the same bits).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn neg_product_small_avx2(n: usize, out: &mut [f64], a: &[f64], b: &[f64]) {
    neg_product_small(n, out, a, b)
}

/// `out = −a b` for `n × n` column-major slices, `n ≤` [`FIXED_PRODUCT_MAX`].
#[inline(always)]
fn neg_product_small(n: usize, out: &mut [f64], a: &[f64], b: &[f64]) {
    macro_rules! sizes {
        ($($n:literal)*) => {
            match n {
                0 => {}
                $($n => neg_product_fixed::<$n>(
                    out.as_chunks_mut::<$n>().0,
                    a.as_chunks::<$n>().0,
                    b.as_chunks::<$n>().0,
                ),)*
                _ => unreachable!("n ≤ FIXED_PRODUCT_MAX"),
            }
        };
    }
    sizes!(1 2 3 4 5 6 7 8 9 10 11 12)
}

/// `out = −a b`, one column of `out` (`−Σ_k b_kc a_k`) at a time.
#[inline(always)]
fn neg_product_fixed<const N: usize>(out: &mut [[f64; N]], a: &[[f64; N]], b: &[[f64; N]]) {
    for (oc, bc) in out.iter_mut().zip(b) {
        let mut acc = [0.0; N];
        for (ak, bk) in a.iter().zip(bc) {
            let x = -bk;
            for r in 0..N {
                acc[r] += x * ak[r];
            }
        }
        *oc = acc;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic `n × n` matrix with entries of mixed signs and magnitudes.
    fn matrix(n: usize, seed: f64) -> DMatrix<f64> {
        DMatrix::from_fn(n, n, |r, c| {
            ((r * 7 + c * 3) as f64 + seed).sin() * (1.0 + r as f64)
        })
    }

    #[test]
    fn neg_product_equals_minus_the_nalgebra_product_at_every_size() {
        for n in 0..=DIRECT_PRODUCT_MAX + 2 {
            let (a, b) = (matrix(n, 0.3), matrix(n, 1.7));
            let mut out = DMatrix::from_element(n, n, f64::NAN);
            neg_product(&mut out, &a, &b, Isa::detected());
            let want = -(&a * &b);
            let scale = want.amax().max(1.0);
            assert!((&out - &want).amax() <= 1e-14 * scale * n as f64, "n = {n}");
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn neg_product_gives_the_same_bits_on_avx2_and_baseline() {
        if Isa::detected() < Isa::Avx2 {
            return;
        }
        for n in 0..=FIXED_PRODUCT_MAX {
            let (a, b) = (matrix(n, 0.1), matrix(n, 2.9));
            let (mut x, mut y) = (vec![0.0; n * n], vec![0.0; n * n]);
            neg_product_small(n, &mut x, a.as_slice(), b.as_slice());
            // SAFETY: AVX2 was detected above.
            unsafe { neg_product_small_avx2(n, &mut y, a.as_slice(), b.as_slice()) };
            let bits = |v: &[f64]| v.iter().map(|z| z.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&x), bits(&y), "n = {n}");
        }
    }
}
