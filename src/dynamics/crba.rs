//! Composite-rigid-body algorithm for the joint-space mass matrix `M(q)` (RBDA Table 6.2):
//!
//! - `I^c_i = I_i + Σ_children ᵢX_c^* I^c_c ᶜX_i` (composite inertia, backward pass);
//! - `F = I^c_i S_i`, `M_ii = S_iᵀ F`; walking up the ancestors `j`,
//!   `F = ʲX_i^* F`, `M_ij = M_ji = S_jᵀ F`.
//!
//! Composite inertias are kept in origin form ([`InertiaO`]) where moving and adding are
//! linear. Mimic joints: entries are scaled by both bodies' multipliers and summed onto
//! the independent coordinates (`Gᵀ M G`).

use super::rnea::project;
use crate::data::Data;
use crate::kinematics::{body_q, joint_transform};
use crate::model::{Model, WORLD};
use crate::spatial::{Force, InertiaO, Motion};
use nalgebra::DMatrix;

/// The force `I S` for a unit motion along the body's joint axis.
#[inline(always)]
fn inertia_times_axis(i: &InertiaO, kind: crate::model::BodyKind) -> Force {
    let mut e = crate::spatial::Vec3::zeros();
    e[kind.axis_index()] = 1.0;
    let m = if kind.is_revolute() {
        Motion::new(crate::spatial::Vec3::zeros(), e)
    } else {
        Motion::new(e, crate::spatial::Vec3::zeros())
    };
    i.mul_motion(&m)
}

/// Mass matrix into `data.mass` (full, symmetric), also returned.
pub fn crba<'a>(model: &Model, data: &'a mut Data, q: &[f64]) -> &'a DMatrix<f64> {
    crba_impl(model, data, q, None)
}

/// [`crba`] with an optional extra inertia (payload, body coordinates) on one body.
pub(crate) fn crba_impl<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    payload: Option<(usize, &InertiaO)>,
) -> &'a DMatrix<f64> {
    assert_eq!(q.len(), model.nv);
    let nb = model.nbodies();
    for i in 0..nb {
        data.li_m_i[i] = joint_transform(&model.placement[i], model.kind[i], body_q(model, q, i));
        data.ic[i] = model.inertia_o[i];
    }
    if let Some((pb, ip)) = payload {
        data.ic[pb] = data.ic[pb].add(ip);
    }
    data.mass.fill(0.0);
    for i in (0..nb).rev() {
        let ki = model.q_index[i];
        let mi = model.q_mult[i];
        let mut f = inertia_times_axis(&data.ic[i], model.kind[i]);
        data.mass[(ki, ki)] += mi * mi * project(model.kind[i], &f);
        let mut j = i;
        while model.parent[j] != WORLD {
            f = data.li_m_i[j].act_force(&f);
            j = model.parent[j];
            let kj = model.q_index[j];
            let val = mi * model.q_mult[j] * project(model.kind[j], &f);
            if kj == ki {
                data.mass[(ki, ki)] += 2.0 * val;
            } else {
                data.mass[(ki, kj)] += val;
                data.mass[(kj, ki)] += val;
            }
        }
        let parent = model.parent[i];
        if parent != WORLD {
            let moved = data.ic[i].transformed(&data.li_m_i[i]);
            data.ic[parent] = data.ic[parent].add(&moved);
        }
    }
    &data.mass
}
