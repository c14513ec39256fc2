//! The inverse of the joint-space inertia matrix, `M(q)⁻¹`, in O(n²) without forming `M`
//! (Carpentier, *Analytical Inverse of the Joint Space Inertia Matrix*, 2018; Pinocchio's
//! `computeMinverse`): the articulated-body algorithm run on the `n` unit torques at once,
//! with zero velocity and no gravity, in the world frame (where moving an inertia or a
//! force to the parent costs nothing). Column `c` of `M⁻¹` is `q̈` for `τ = e_c`.
//!
//! 1. backward: `U_i = I^A_i S_i`, `D_i = S_iᵀ U_i + I_a`; the partial row
//!    `M⁻¹_i· = D_i⁻¹(e_i − S_iᵀ P_i)` from the children's articulated forces `P_i`
//!    (`6 × n`, one column per unit torque); `P_λ += P_i + U_i M⁻¹_i·`,
//!    `I^A_λ += I^A_i − U_i D_i⁻¹ U_iᵀ`;
//! 2. forward: `M⁻¹_i· −= D_i⁻¹ U_iᵀ A_λ`, `A_i = A_λ + S_i M⁻¹_i·` (the bodies'
//!    accelerations under the unit torques, `A_0 = 0`).
//!
//! Bodies are driven by `θ_i = m_i q_i` (a sign, without mimic joints), so
//! `M⁻¹_q = G⁻¹ M⁻¹_θ G⁻¹` and the armature enters `D_i` as `I_a / m_i²`. With mimic
//! joints the articulated recursion does not apply: `M` from CRBA is inverted through
//! its Cholesky factor.

use crate::core::linalg::{cholesky_in_place, SingularMassMatrix};
use crate::dynamics::crba::crba;
use crate::kinematics::{forward_kinematics, world_subspace};
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use nalgebra::{DMatrix, Vector6};

#[inline(always)]
fn mvec(m: &crate::core::spatial::Motion) -> Vector6<f64> {
    Vector6::new(m.v.x, m.v.y, m.v.z, m.w.x, m.w.y, m.w.z)
}

/// `M(q)⁻¹` into `data.deriv.minv` (also returned), with the model's armature, as
/// Pinocchio's `computeMinverse(model, data, q)` (full, symmetric). Fails only when `M`
/// is singular (a massless chain end).
pub fn compute_minverse<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
) -> Result<&'a DMatrix<f64>, SingularMassMatrix> {
    assert_eq!(q.len(), model.nv, "q needs nv values");
    data.deriv.ensure(model);
    if model.has_mimic {
        invert_mass_matrix(model, data, q)?;
    } else {
        forward_kinematics(model, data, q);
        for i in 0..model.nbodies() {
            data.s_world[i] = world_subspace(model.kind[i], &data.o_m_i[i]);
        }
        minverse_from_placements(model, data)?;
    }
    Ok(&data.deriv.minv)
}

/// [`compute_minverse`] for a model without mimic joints whose `data.o_m_i` and
/// `data.s_world` are current (after the RNEA derivatives, say).
pub(crate) fn minverse_from_placements(
    model: &Model,
    data: &mut Data,
) -> Result<(), SingularMassMatrix> {
    backward_pass(model, data)?;
    forward_pass(model, data);
    Ok(())
}

/// `D_i⁻¹`, `U_i`, the partial rows and the articulated forces of the unit torques.
/// Bodies come after their parents, so body `i`'s subtree, where its forces are not
/// zero, lies in the columns `c ≥ i` (columns are bodies here).
fn backward_pass(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    let n = model.nv;
    let nb = model.nbodies();
    let d = &mut data.deriv;
    for i in 0..nb {
        d.oya[i] = model.inertia_o[i].transformed(&data.o_m_i[i]).to_matrix();
    }
    d.cols.fill(0.0);
    for i in (0..nb).rev() {
        let s = mvec(&data.s_world[i]);
        let (ci, mi) = (model.q_index[i], model.q_mult[i]);
        let u = d.oya[i] * s;
        let dd = s.dot(&u) + model.armature[ci] / (mi * mi);
        if !(dd > 0.0 && dd.is_finite()) {
            return Err(SingularMassMatrix::at(ci, dd));
        }
        let d_inv = 1.0 / dd;
        let (below, rest) = d.cols.split_at_mut(i * 6 * n);
        let p_i = &rest[..6 * n];
        let row = &mut d.row[..];
        row[i] = d_inv;
        for c in i + 1..nb {
            let col = &p_i[c * 6..c * 6 + 6];
            row[c] = -d_inv * (0..6).map(|r| s[r] * col[r]).sum::<f64>();
        }
        d.u[i] = u;
        d.d_inv[i] = d_inv;
        d.minv_rows[i * nb..(i + 1) * nb].copy_from_slice(row);
        let parent = model.parent[i];
        if parent != WORLD {
            let p_parent = &mut below[parent * 6 * n..(parent + 1) * 6 * n];
            for c in i..nb {
                for r in 0..6 {
                    p_parent[c * 6 + r] += p_i[c * 6 + r] + u[r] * row[c];
                }
            }
            let ia = d.oya[i] - u * u.transpose() * d_inv;
            d.oya[parent] += ia;
        }
    }
    Ok(())
}

/// Completes each row's upper part (`c ≥ i`, all a child needs of its parent's
/// accelerations) and writes `M⁻¹` in coordinates, mirrored.
fn forward_pass(model: &Model, data: &mut Data) {
    let n = model.nv;
    let nb = model.nbodies();
    let d = &mut data.deriv;
    for i in 0..nb {
        let s = mvec(&data.s_world[i]);
        let (u, d_inv) = (d.u[i], d.d_inv[i]);
        let parent = model.parent[i];
        let (below, rest) = d.cols.split_at_mut(i * 6 * n);
        let a_i = &mut rest[..6 * n];
        let row = &mut d.minv_rows[i * nb..(i + 1) * nb];
        for c in i..nb {
            if parent != WORLD {
                let a_p = &below[parent * 6 * n + c * 6..parent * 6 * n + c * 6 + 6];
                let uta: f64 = (0..6).map(|r| u[r] * a_p[r]).sum();
                row[c] -= d_inv * uta;
                for r in 0..6 {
                    a_i[c * 6 + r] = a_p[r] + s[r] * row[c];
                }
            } else {
                for r in 0..6 {
                    a_i[c * 6 + r] = s[r] * row[c];
                }
            }
        }
    }
    let minv = d.minv.as_mut_slice();
    for i in 0..nb {
        let (ci, mi) = (model.q_index[i], model.q_mult[i]);
        for c in i..nb {
            let (cc, mc) = (model.q_index[c], model.q_mult[c]);
            let x = d.minv_rows[i * nb + c] / (mi * mc);
            minv[cc * n + ci] = x;
            minv[ci * n + cc] = x;
        }
    }
}

/// `M⁻¹` through CRBA and the Cholesky factor (mimic joints).
fn invert_mass_matrix(model: &Model, data: &mut Data, q: &[f64]) -> Result<(), SingularMassMatrix> {
    crba(model, data, q);
    data.chol.copy_from(&data.mass);
    cholesky_in_place(&mut data.chol)?;
    let n = model.nv;
    let minv = &mut data.deriv.minv;
    minv.fill(0.0);
    for c in 0..n {
        minv[(c, c)] = 1.0;
    }
    for c in 0..n {
        let mut col = minv.column_mut(c);
        crate::core::linalg::cholesky_solve_in_place(&data.chol, col.as_mut_slice());
    }
    Ok(())
}
