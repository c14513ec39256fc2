//! [`Data`]: the reusable workspace of one model. Every algorithm writes its results here;
//! all buffers are sized once by [`Data::new`] so that no algorithm allocates per call.

use crate::model::Model;
use crate::spatial::{Force, Motion, Se3};
use nalgebra::DMatrix;

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
}

impl Data {
    /// Allocates every buffer for `model`.
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
        }
    }
}
