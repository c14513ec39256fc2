//! Composite-rigid-body algorithm for the joint-space mass matrix `M(q)` (RBDA Table 6.2,
//! body coordinates):
//!
//! - `I^c_i = I_i`; backward: `I^c_λ += λX_i^* I^c_i ⁱX_λ`;
//! - `F = I^c_i S_i`, `M_ii = S_iᵀ F`; walking up the ancestors `j`,
//!   `F = λX_j^* F`, `M_ij = M_ji = S_jᵀ F`.
//!
//! After the model's permutation push-up (see [`crate::model`]) most joint transforms are
//! `ᵖX_i = (R_k(θ), t)`: a rotation about one body axis and a translation. Those take a
//! structured path ([`AxisX`]): moving a force costs 14 multiplications instead of 24, and
//! moving a composite inertia about a third of the general cost. Composite inertias are in
//! origin form ([`InertiaO`]). Mimic joints: entries are scaled by both bodies'
//! multipliers and summed onto the independent coordinates (`Gᵀ M G`). The armature
//! (`model.armature`) is added to the diagonal.

use crate::core::spatial::{column, unit, Force, InertiaO};
use crate::dynamics::rnea::project;
use crate::kinematics::{body_q, compute_joint_jacobians, joint_transform};
use crate::model::data::Data;
use crate::model::{AxisX, BodyKind, Model, WORLD};
use nalgebra::DMatrix;

/// The force `I S` for a unit motion along the body's joint axis: for a rotation about
/// `e_k`, `(e_k × h, I_O e_k)`; for a translation, `(m e_k, h × e_k)`.
#[inline(always)]
fn inertia_times_axis(y: &InertiaO, kind: BodyKind) -> Force {
    let k = kind.axis_index();
    let e = unit(k, 1.0);
    if kind.is_revolute() {
        Force::new(e.cross(&y.h), column(&y.i_o, k))
    } else {
        Force::new(e * y.m, y.h.cross(&e))
    }
}

/// Mean body depth above which the ancestor walk runs in world coordinates.
pub const WORLD_WALK_DEPTH: f64 = 8.0;

/// Mass matrix `M(q)` into `data.mass` (full, symmetric), also returned; `model.armature`
/// is on its diagonal, as in Pinocchio's `crba`.
pub fn crba<'a>(model: &Model, data: &'a mut Data, q: &[f64]) -> &'a DMatrix<f64> {
    crba_impl(model, data, q, None)
}

/// [`crba`] with an optional extra inertia (payload, body coordinates) on one body (the
/// model's armature included; a rotor effect's is the caller's to add).
pub(crate) fn crba_impl<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    payload: Option<(usize, &InertiaO)>,
) -> &'a DMatrix<f64> {
    assert_eq!(q.len(), model.nv);
    data.ensure_dense(model.nv);
    let nb = model.nbodies();
    for i in 0..nb {
        let theta = body_q(model, q, i);
        if model.placement_identity[i] {
            data.axis_x[i] = AxisX::new(model, i, theta);
        } else {
            data.li_m_i[i] = joint_transform(&model.placement[i], model.kind[i], theta);
        }
        data.ic[i] = model.inertia_o[i];
    }
    if let Some((pb, ip)) = payload {
        data.ic[pb] = data.ic[pb].add(ip);
    }
    let world_walk = model.mean_depth > WORLD_WALK_DEPTH;
    if world_walk {
        compute_joint_jacobians(model, data, q);
    }
    let n = model.nv;
    let m = data.mass.as_mut_slice();
    m.iter_mut().for_each(|x| *x = 0.0);
    for i in (0..nb).rev() {
        let kind = model.kind[i];
        let ki = model.q_index[i];
        let mi = model.q_mult[i];
        let mut f = inertia_times_axis(&data.ic[i], kind);
        // Column ki, rows of the ancestors (the lower/upper halves are mirrored below).
        m[ki * n + ki] += mi * mi * project(kind, &f);
        if world_walk {
            let fw = data.o_m_i[i].act_force(&f);
            let mut j = model.parent[i];
            while j != WORLD {
                let kj = model.q_index[j];
                let val = mi * model.q_mult[j] * fw.dot_motion(&data.s_world[j]);
                if kj == ki {
                    m[ki * n + ki] += 2.0 * val;
                } else {
                    m[ki * n + kj] += val;
                }
                j = model.parent[j];
            }
        }
        let mut j = i;
        while !world_walk && model.parent[j] != WORLD {
            f = if model.placement_identity[j] {
                data.axis_x[j].act_force(&f)
            } else {
                data.li_m_i[j].act_force(&f)
            };
            j = model.parent[j];
            let kj = model.q_index[j];
            let val = mi * model.q_mult[j] * project(model.kind[j], &f);
            if kj == ki {
                m[ki * n + ki] += 2.0 * val;
            } else {
                m[ki * n + kj] += val;
            }
        }
        let parent = model.parent[i];
        if parent != WORLD {
            let child = data.ic[i];
            if model.placement_identity[i] {
                data.axis_x[i].act_inertia_add(&child, &mut data.ic[parent]);
            } else {
                let moved = child.transformed(&data.li_m_i[i]);
                data.ic[parent] = data.ic[parent].add(&moved);
            }
        }
    }
    // Entry (kj, ki) was accumulated in column ki; with mimic joints a pair can land on
    // either side of the diagonal, so symmetrise by summing both halves.
    for c in 0..n {
        for r in c + 1..n {
            let v = m[c * n + r] + m[r * n + c];
            m[c * n + r] = v;
            m[r * n + c] = v;
        }
    }
    for (k, ia) in model.armature.iter().enumerate() {
        if *ia != 0.0 {
            m[k * n + k] += ia;
        }
    }
    &data.mass
}
