//! [`Data`]: the reusable workspace of one model. Every algorithm writes its results here;
//! all buffers are sized once by [`Data::new`] so that no algorithm allocates per call.

use crate::core::spatial::{Force, InertiaO, Motion, Se3};
use crate::model::derivative_data::DerivativeData;
use crate::model::Model;
use nalgebra::{DMatrix, Matrix6, Vector6};

/// Per-model buffers. Body-indexed vectors have one entry per movable joint.
#[derive(Clone, Debug)]
pub struct Data {
    /// Joint placement relative to the parent body: `liMi = placement_i · joint_i(q)`.
    pub li_m_i: Vec<Se3>,
    /// Body placement in the world: `oMi`.
    pub o_m_i: Vec<Se3>,
    /// Link frame placements in the world (after [`crate::kinematics::update_frames`]).
    pub o_m_f: Vec<Se3>,
    /// Body spatial velocity, in the body frame.
    pub v: Vec<Motion>,
    /// Body spatial acceleration (Featherstone's, not the classical one), in the body frame.
    pub a: Vec<Motion>,
    /// Joint motion subspace of each body in the world frame (the columns of Pinocchio's
    /// `data.J`): for a revolute joint `(p × ω, ω)`, for a prismatic joint `(axis, 0)`.
    pub s_world: Vec<Motion>,
    /// Time derivative of `s_world`.
    pub ds_world: Vec<Motion>,
    /// Body spatial velocity in the world frame (reference point at the world origin).
    pub v_world: Vec<Motion>,
    /// Body forces (dynamics), in the body frame.
    pub f: Vec<Force>,
    /// 6 × nv scratch Jacobian for frame queries.
    pub jac: DMatrix<f64>,
    /// Joint torques (RNEA output), nv.
    pub tau: Vec<f64>,
    /// Joint accelerations (forward dynamics output), nv.
    pub qdd: Vec<f64>,
    /// Mass matrix (CRBA output), nv × nv.
    pub mass: DMatrix<f64>,
    /// Cholesky factor of the mass matrix.
    pub chol: DMatrix<f64>,
    /// Composite inertias (CRBA).
    pub ic: Vec<InertiaO>,
    /// Structured joint transforms (CRBA).
    pub(crate) axis_x: Vec<crate::model::AxisX>,
    /// Articulated inertias (ABA).
    pub ia: Vec<Matrix6<f64>>,
    /// Articulated bias forces (ABA).
    pub pa: Vec<Vector6<f64>>,
    /// `U_i = I^A_i S_i` (ABA).
    pub u_col: Vec<Vector6<f64>>,
    /// `D_i⁻¹` (ABA).
    pub d_inv: Vec<f64>,
    /// `u_i` (ABA).
    pub u: Vec<f64>,
    /// Velocity-product accelerations `c_i` (ABA).
    pub c: Vec<Motion>,
    /// Always zero, nv long (for `q̈ = 0` calls).
    pub scratch_nv: Vec<f64>,
    /// Scratch, nv long.
    pub scratch_nv2: Vec<f64>,
    /// Scratch for net torques, nv long.
    pub scratch_tau: Vec<f64>,
    /// Scratch for spring torques, nv long.
    pub scratch_spring: Vec<f64>,
    /// External wrenches per body, in body frames.
    pub f_ext: Vec<Force>,
    /// How often each effect's code ran.
    pub effect_runs: EffectRuns,
    /// The effects the last effect-aware dynamics call included.
    pub effects_used: EffectSet,
    /// The dynamics derivatives' buffers (sized by the first derivative call).
    pub deriv: DerivativeData,
}

/// Models of up to this many degrees of freedom get their `nv × nv` mass-matrix buffers
/// ([`Data::mass`], [`Data::chol`]) with the rest; larger ones when a dense algorithm
/// first asks ([`Data::ensure_dense`]), so that kinematics on a 20 000-joint chain does not
/// reserve gigabytes.
pub const EAGER_DENSE_DOF: usize = 4096;

/// The dense algorithms (CRBA, forward dynamics, simulation) refuse models of more
/// degrees of freedom than this through [`dense_fits`]: two `nv × nv` matrices of 8192²
/// are 1 GiB.
pub const MAX_DENSE_DOF: usize = 8192;

fn dense_n(nv: usize) -> usize {
    if nv <= EAGER_DENSE_DOF {
        nv
    } else {
        0
    }
}

/// A model too large for the dense algorithms ([`MAX_DENSE_DOF`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "the model has {nv} degrees of freedom: the dense algorithms (mass matrix, forward \
     dynamics with mimic joints, numeric IK) would hold two {nv} × {nv} matrices ({gib:.1} \
     GiB); they accept at most {MAX_DENSE_DOF}"
)]
pub struct TooManyDof {
    /// The model's degrees of freedom.
    pub nv: usize,
    /// The memory two `nv × nv` matrices would take (GiB).
    pub gib: f64,
}

/// [`TooManyDof`] when `model` has more degrees of freedom than the dense algorithms
/// accept ([`MAX_DENSE_DOF`]), for the callers that can refuse (CLI, Python, scenarios).
pub fn dense_fits(model: &Model) -> Result<(), TooManyDof> {
    if model.nv > MAX_DENSE_DOF {
        return Err(TooManyDof {
            nv: model.nv,
            gib: 2.0 * (model.nv as f64).powi(2) * 8.0 / (1u64 << 30) as f64,
        });
    }
    Ok(())
}

impl Data {
    /// Sizes [`Data::mass`] and [`Data::chol`] for `nv` if they are not yet (models above
    /// [`EAGER_DENSE_DOF`]); a no-op afterwards.
    pub fn ensure_dense(&mut self, nv: usize) {
        if self.mass.nrows() != nv {
            self.mass = DMatrix::zeros(nv, nv);
            self.chol = DMatrix::zeros(nv, nv);
        }
    }

    /// Allocates every buffer for `model` (the mass-matrix buffers only up to
    /// [`EAGER_DENSE_DOF`]).
    pub fn new(model: &Model) -> Self {
        let nb = model.nbodies();
        Self {
            li_m_i: vec![Se3::identity(); nb],
            o_m_i: vec![Se3::identity(); nb],
            o_m_f: vec![Se3::identity(); model.links.len()],
            v: vec![Motion::zero(); nb],
            a: vec![Motion::zero(); nb],
            s_world: vec![Motion::zero(); nb],
            ds_world: vec![Motion::zero(); nb],
            v_world: vec![Motion::zero(); nb],
            f: vec![Force::zero(); nb],
            jac: DMatrix::zeros(6, model.nv),
            tau: vec![0.0; model.nv],
            qdd: vec![0.0; model.nv],
            mass: DMatrix::zeros(dense_n(model.nv), dense_n(model.nv)),
            chol: DMatrix::zeros(dense_n(model.nv), dense_n(model.nv)),
            ic: vec![InertiaO::zero(); nb],
            axis_x: vec![Default::default(); nb],
            ia: vec![Matrix6::zeros(); nb],
            pa: vec![Vector6::zeros(); nb],
            u_col: vec![Vector6::zeros(); nb],
            d_inv: vec![0.0; nb],
            u: vec![0.0; nb],
            c: vec![Motion::zero(); nb],
            scratch_nv: vec![0.0; model.nv],
            scratch_nv2: vec![0.0; model.nv],
            scratch_tau: vec![0.0; model.nv],
            scratch_spring: vec![0.0; model.nv],
            f_ext: vec![Force::zero(); nb],
            effect_runs: Default::default(),
            effects_used: Default::default(),
            deriv: DerivativeData::default(),
        }
    }
}

/// The set of effects a computation included (what [`crate::dynamics::Effects`] named), recorded in
/// `Data::effects_used` by every effect-aware call.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EffectSet(pub(crate) u8);

impl EffectSet {
    /// The effect names, in the fixed order of the bits (and of every listing).
    pub const NAMES: [&'static str; 6] = [
        "gravity",
        "friction",
        "rotor_inertia",
        "joint_elasticity",
        "payload",
        "external_wrench",
    ];

    /// Whether the named effect is in the set.
    pub fn contains(&self, name: &str) -> bool {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .is_some_and(|i| self.0 & (1 << i) != 0)
    }

    /// The names in the set, in a fixed order.
    pub fn names(&self) -> Vec<&'static str> {
        (0..Self::NAMES.len())
            .filter(|i| self.0 & (1 << i) != 0)
            .map(|i| Self::NAMES[i])
            .collect()
    }
}

/// How many times each effect's code ran (for tests and audits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EffectRuns {
    /// Gravity.
    pub gravity: u64,
    /// Friction.
    pub friction: u64,
    /// Rotor inertia / gearing.
    pub rotor: u64,
    /// Elasticity.
    pub elasticity: u64,
    /// Payload.
    pub payload: u64,
    /// External wrenches.
    pub external: u64,
}
