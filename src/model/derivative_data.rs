//! [`DerivativeData`]: the buffers of the dynamics derivatives (∂τ/∂q, ∂τ/∂q̇, ∂q̈/∂q,
//! ∂q̈/∂q̇, `M⁻¹`) and the per-body world-frame quantities their recursions keep. Sized
//! on the first derivative call ([`DerivativeData::ensure`]), not with the rest of
//! [`crate::model::data::Data`]: kinematics-only users never pay for five `nv × nv`
//! matrices. Afterwards no call allocates.

use crate::core::simd_lanes::Isa;
use crate::core::spatial::{Force, InertiaO, Mat3, Motion, Vec3};
use crate::core::sym6::Sym6;
use crate::model::Model;
use nalgebra::DMatrix;

/// The derivative algorithms refuse models of more degrees of freedom than this through
/// [`derivatives_fit`]: their five `nv × nv` results and the `6 nv × nv` columns of
/// `M⁻¹`'s recursion are about 2 GiB at 4096.
pub const MAX_DERIVATIVE_DOF: usize = 2048;

/// A model too large for the dynamics derivatives ([`MAX_DERIVATIVE_DOF`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "the model has {nv} degrees of freedom: the dynamics derivatives hold five {nv} × {nv} \
     matrices and accept at most {MAX_DERIVATIVE_DOF}"
)]
pub struct TooManyDofForDerivatives {
    /// The model's degrees of freedom.
    pub nv: usize,
}

/// [`TooManyDofForDerivatives`] when `model` is above [`MAX_DERIVATIVE_DOF`], for the
/// callers that can refuse (CLI, Python).
pub fn derivatives_fit(model: &Model) -> Result<(), TooManyDofForDerivatives> {
    if model.nv > MAX_DERIVATIVE_DOF {
        return Err(TooManyDofForDerivatives { nv: model.nv });
    }
    Ok(())
}

/// Rows of the RNEA derivatives' structure-of-arrays buffer on long serial chains (see
/// `dynamics::rnea_derivatives_chain`).
pub(crate) const CHAIN_SOA_ROWS: usize = 46;

/// Unit-torque columns `M⁻¹`'s recursion takes at once (one AVX2 register of `f64`).
pub(crate) const MINV_BLOCK: usize = 4;

/// Six rows (a spatial vector's components) of [`MINV_BLOCK`] columns, side by side.
pub(crate) type ColumnBlock = [[f64; MINV_BLOCK]; 6];

/// The variation of a body's momentum with its velocity (Carpentier & Mansard's
/// `∂(Y v)`-term, `v ×* Y − Y v× + (· ×* Y v)`), which only reads the angular part of
/// the motion it acts on: `D x = (a × x_ω, C x_ω)`. Sums of these stay of this form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MomentumVariation {
    /// `A = [a]×`, the force block (`a = −2 × linear momentum`).
    pub a: Vec3,
    /// The moment block.
    pub c: Mat3,
}

impl Default for MomentumVariation {
    fn default() -> Self {
        Self {
            a: Vec3::zeros(),
            c: Mat3::zeros(),
        }
    }
}

impl MomentumVariation {
    /// `D x`.
    #[inline(always)]
    pub fn mul_motion(&self, x: &Motion) -> Force {
        Force::new(self.a.cross(&x.w), self.c * x.w)
    }

    /// `Dᵀ s`, as a covector paired with motions: `(0, Aᵀ s_v + Cᵀ s_ω)`.
    #[inline(always)]
    pub fn tr_mul_motion(&self, s: &Motion) -> Force {
        Force::new(Vec3::zeros(), s.v.cross(&self.a) + self.c.tr_mul(&s.w))
    }

    /// `self + o`.
    #[inline(always)]
    pub fn add(&self, o: &Self) -> Self {
        Self {
            a: self.a + o.a,
            c: self.c + o.c,
        }
    }
}

/// Buffers of the derivative algorithms (see the module docs). Body-indexed vectors have
/// one entry per body, world frame.
#[derive(Clone, Debug, Default)]
pub struct DerivativeData {
    /// `∂τ/∂q` (RNEA derivatives), nv × nv.
    pub dtau_dq: DMatrix<f64>,
    /// `∂τ/∂q̇`, nv × nv.
    pub dtau_dv: DMatrix<f64>,
    /// `∂τ/∂q̈ = M`, nv × nv (armature included).
    pub dtau_da: DMatrix<f64>,
    /// `∂q̈/∂q` (ABA derivatives), nv × nv.
    pub ddq_dq: DMatrix<f64>,
    /// `∂q̈/∂q̇`, nv × nv.
    pub ddq_dv: DMatrix<f64>,
    /// `M⁻¹ = ∂q̈/∂τ`, nv × nv.
    pub minv: DMatrix<f64>,
    /// Body velocities, world frame.
    pub(crate) ov: Vec<Motion>,
    /// Body accelerations with gravity as a base acceleration, world frame.
    pub(crate) oa: Vec<Motion>,
    /// `∂v_i/∂q_k` minus `S_k × v_i` for `k` this body: `v_λ × S_k`.
    pub(crate) dv_dq: Vec<Motion>,
    /// `∂a_i/∂q_k` minus `S_k × a_i + dv_dq × v_i`: `a_λ × S_k + v_λ × (v_λ × S_k)`.
    pub(crate) da_dq: Vec<Motion>,
    /// `∂a_i/∂q̇_k` minus `S_k × v_i`: `2 v_λ × S_k`.
    pub(crate) da_dv: Vec<Motion>,
    /// Subtree (composite) inertias, world frame.
    pub(crate) oy: Vec<InertiaO>,
    /// Subtree momentum variations.
    pub(crate) doy: Vec<MomentumVariation>,
    /// Subtree forces, world frame.
    pub(crate) of: Vec<Force>,
    /// Articulated inertias, world frame (`M⁻¹`).
    pub(crate) oya: Vec<Sym6>,
    /// `U_i = I^A_i S_i` (`M⁻¹`).
    pub(crate) u: Vec<[f64; 6]>,
    /// `D_i⁻¹` (`M⁻¹`).
    pub(crate) d_inv: Vec<f64>,
    /// Per body, the `6 × nb` articulated forces, then the accelerations, of the unit
    /// joint torques (`M⁻¹`), in `⌈nb / MINV_BLOCK⌉` column blocks, body after body.
    pub(crate) cols: Vec<ColumnBlock>,
    /// Whether a child has written body `i`'s forces yet (`M⁻¹`'s backward pass;
    /// afterwards: whether it has children).
    pub(crate) p_set: Vec<bool>,
    /// Subtree forces of the bias (ABA derivatives; scratch).
    pub(crate) bias_f: Vec<Force>,
    /// World accelerations of `q̈` alone (ABA derivatives; scratch).
    pub(crate) acc: Vec<Motion>,
    /// `τ − h(q, q̇)`, nv (ABA derivatives; scratch).
    pub(crate) rhs: Vec<f64>,
    /// `M⁻¹` by bodies, row-major, each row `⌈nb / MINV_BLOCK⌉` blocks (`M⁻¹`'s
    /// recursion).
    pub(crate) minv_rows: Vec<[f64; MINV_BLOCK]>,
    /// Per body, [`CHAIN_SOA_ROWS`] rows of `nb` values: the RNEA derivatives' covectors
    /// on long serial chains (structure of arrays).
    pub(crate) soa: Vec<f64>,
    /// The same values body by body (a body's own row of constants).
    pub(crate) per_body: Vec<[f64; CHAIN_SOA_ROWS]>,
    /// The instruction set `M⁻¹`'s recursion runs on (detected when sized).
    pub(crate) isa: Isa,
    /// The degrees of freedom the buffers are sized for.
    pub(crate) nv: usize,
}

impl DerivativeData {
    /// Sizes every buffer for `model` on the first call; a no-op afterwards.
    pub fn ensure(&mut self, model: &Model) {
        let (nv, nb) = (model.nv, model.nbodies());
        if self.nv == nv && self.ov.len() == nb && self.dtau_dq.nrows() == nv {
            return;
        }
        let sq = || DMatrix::zeros(nv, nv);
        let blocks = nb * nb.div_ceil(MINV_BLOCK);
        *self = Self {
            dtau_dq: sq(),
            dtau_dv: sq(),
            dtau_da: sq(),
            ddq_dq: sq(),
            ddq_dv: sq(),
            minv: sq(),
            ov: vec![Motion::zero(); nb],
            oa: vec![Motion::zero(); nb],
            dv_dq: vec![Motion::zero(); nb],
            da_dq: vec![Motion::zero(); nb],
            da_dv: vec![Motion::zero(); nb],
            oy: vec![InertiaO::zero(); nb],
            doy: vec![MomentumVariation::default(); nb],
            of: vec![Force::zero(); nb],
            oya: vec![Sym6::default(); nb],
            u: vec![[0.0; 6]; nb],
            d_inv: vec![0.0; nb],
            cols: vec![[[0.0; MINV_BLOCK]; 6]; blocks],
            p_set: vec![false; nb],
            bias_f: vec![Force::zero(); nb],
            acc: vec![Motion::zero(); nb],
            rhs: vec![0.0; nv],
            minv_rows: vec![[0.0; MINV_BLOCK]; blocks],
            soa: vec![0.0; CHAIN_SOA_ROWS * nb],
            per_body: vec![[0.0; CHAIN_SOA_ROWS]; nb],
            isa: Isa::detected(),
            nv,
        };
    }
}
