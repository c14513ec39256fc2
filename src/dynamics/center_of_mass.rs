//! The robot's centre of mass and its Jacobian (Pinocchio's `centerOfMass` and
//! `jacobianCenterOfMass`), over the model's bodies (links fixed to the world carry no
//! coordinate and are left out, as Pinocchio leaves out the universe's inertia).
//!
//! - `c = Σ_j m_j c_j / M`, `c_j` body `j`'s centre of mass in world coordinates and
//!   `M = Σ_j m_j`.
//! - `J_c = ∂c/∂q` (3 × nv, world axes): turning body `k`'s joint moves every body of its
//!   subtree rigidly along the joint's world motion subspace `s_k = (v_k, ω_k)`, the point
//!   `c_j` at `v_k + ω_k × c_j`; so column `q_index_k` collects
//!   `q_mult_k m_j (v_k + ω_k × c_j) / M` over the bodies `j` that `k` supports (a mimic
//!   body adds into its master's column).
//!
//! Both are `None` when the total mass is zero (no centre of mass exists).

use crate::core::spatial::Vec3;
use crate::kinematics::{compute_joint_jacobians, forward_kinematics};
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use nalgebra::DMatrix;

/// The sum of the bodies' masses (kg).
pub fn total_mass(model: &Model) -> f64 {
    model.inertia.iter().map(|b| b.mass).sum()
}

/// The world centre of mass at `q`; updates the placements. `None` for a massless model.
pub fn center_of_mass(model: &Model, data: &mut Data, q: &[f64]) -> Option<Vec3> {
    forward_kinematics(model, data, q);
    com_from_placements(model, data)
}

/// `Σ m_j c_j / M` from the current placements `data.o_m_i`.
fn com_from_placements(model: &Model, data: &Data) -> Option<Vec3> {
    let total = total_mass(model);
    if total <= 0.0 {
        return None;
    }
    let moment = (0..model.nbodies()).fold(Vec3::zeros(), |acc, j| {
        let b = &model.inertia[j];
        acc + data.o_m_i[j].act_point(&b.com) * b.mass
    });
    Some(moment / total)
}

/// The 3 × nv Jacobian of the centre of mass at `q` into `out` (see the module docs);
/// returns the centre of mass. Updates the placements and `data.s_world`. A massless
/// model leaves `out` zero and returns `None`. Allocates nothing.
pub fn jacobian_center_of_mass(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    out: &mut DMatrix<f64>,
) -> Option<Vec3> {
    assert_eq!(out.shape(), (3, model.nv), "the CoM Jacobian is 3 × nv");
    out.as_mut_slice().fill(0.0);
    compute_joint_jacobians(model, data, q);
    let com = com_from_placements(model, data)?;
    let total = total_mass(model);
    for j in 0..model.nbodies() {
        let b = &model.inertia[j];
        if b.mass == 0.0 {
            continue;
        }
        let c = data.o_m_i[j].act_point(&b.com);
        let share = b.mass / total;
        let mut k = j;
        while k != WORLD {
            let s = &data.s_world[k];
            let col = (s.v + s.w.cross(&c)) * (share * model.q_mult[k]);
            let mut dst = out.column_mut(model.q_index[k]);
            dst[0] += col.x;
            dst[1] += col.y;
            dst[2] += col.z;
            k = model.parent[k];
        }
    }
    Some(com)
}
