//! Composite-rigid-body algorithm for the joint-space mass matrix `M(q)` (RBDA §6.2,
//! in the world-frame form Pinocchio 3 uses):
//!
//! - forward: body placements `oMi` and world joint axes `S_i^w` (the Jacobian columns),
//!   body inertias moved to the world once, `I^w_i = oMi · I_i`;
//! - backward: composite inertias by plain addition, `I^c_λ += I^c_i` (all in world
//!   coordinates), `F_i = I^c_i S_i^w`, and for every ancestor-or-self `j` of `i`:
//!   `M_ij = M_ji = S_jᵀ F_i` (a 6-term dot product; RBDA eq. 6.20 with `F` carried to
//!   the world instead of transformed joint by joint).
//!
//! Composite inertias are kept in origin form ([`InertiaO`]). Mimic joints: entries are
//! scaled by both bodies' multipliers and summed onto the independent coordinates
//! (`Gᵀ M G`).

use crate::data::Data;
use crate::kinematics::compute_joint_jacobians;
use crate::model::{Model, WORLD};
use crate::spatial::InertiaO;
use nalgebra::DMatrix;

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
    compute_joint_jacobians(model, data, q);
    for i in 0..nb {
        data.ic[i] = model.inertia_o[i].transformed(&data.o_m_i[i]);
    }
    if let Some((pb, ip)) = payload {
        data.ic[pb] = data.ic[pb].add(&ip.transformed(&data.o_m_i[pb]));
    }
    data.mass.fill(0.0);
    for i in (0..nb).rev() {
        let ki = model.q_index[i];
        let mi = model.q_mult[i];
        let f = data.ic[i].mul_motion(&data.s_world[i]);
        data.mass[(ki, ki)] += mi * mi * f.dot_motion(&data.s_world[i]);
        let mut j = model.parent[i];
        while j != WORLD {
            let kj = model.q_index[j];
            let val = mi * model.q_mult[j] * f.dot_motion(&data.s_world[j]);
            if kj == ki {
                data.mass[(ki, ki)] += 2.0 * val;
            } else {
                data.mass[(ki, kj)] += val;
                data.mass[(kj, ki)] += val;
            }
            j = model.parent[j];
        }
        let parent = model.parent[i];
        if parent != WORLD {
            data.ic[parent] = data.ic[parent].add(&data.ic[i]);
        }
    }
    &data.mass
}
