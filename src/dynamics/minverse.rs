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
use crate::core::sym6::Sym6;
use crate::dynamics::crba::crba;
use crate::dynamics::forward::name_joint;
use crate::kinematics::compute_joint_jacobians;
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use nalgebra::DMatrix;

/// `M(q)⁻¹` into `data.deriv.minv` (also returned), with the model's armature, as
/// Pinocchio's `computeMinverse(model, data, q)` (full, symmetric). Fails only when `M`
/// is singular (a massless chain end); the error names the joint.
pub fn compute_minverse<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
) -> Result<&'a DMatrix<f64>, SingularMassMatrix> {
    assert_eq!(q.len(), model.nv, "q needs nv values");
    data.deriv.ensure(model);
    if model.has_mimic {
        invert_mass_matrix(model, data, q).map_err(|e| name_joint(e, model))?;
    } else {
        compute_joint_jacobians(model, data, q);
        minverse_from_placements(model, data).map_err(|e| name_joint(e, model))?;
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
        d.oya[i] = Sym6::from_inertia(&model.inertia_o[i].transformed(&data.o_m_i[i]));
    }
    // Body i's articulated forces are read in the columns c > i only.
    for i in 0..nb {
        d.cols[i * 6 * n + 6 * i..(i + 1) * 6 * n].fill(0.0);
    }
    for i in (0..nb).rev() {
        let s = data.s_world[i].to_array();
        let (ci, mi) = (model.q_index[i], model.q_mult[i]);
        let u = d.oya[i].mul(&s);
        let dd = dot6(&s, &u) + model.armature[ci] / (mi * mi);
        if !(dd > 0.0 && dd.is_finite()) {
            return Err(SingularMassMatrix::at(ci, dd));
        }
        let d_inv = 1.0 / dd;
        let (below, rest) = d.cols.split_at_mut(i * 6 * n);
        let p_i = &rest[6 * (i + 1)..6 * n];
        let row = &mut d.minv_rows[i * nb..(i + 1) * nb];
        row[i] = d_inv;
        for (r, col) in row[i + 1..].iter_mut().zip(p_i.as_chunks::<6>().0) {
            *r = -d_inv * dot6(&s, col);
        }
        d.u[i] = u;
        d.d_inv[i] = d_inv;
        let parent = model.parent[i];
        if parent != WORLD {
            let p_parent = &mut below[parent * 6 * n + 6 * i..(parent + 1) * 6 * n];
            let (own, children) = p_parent.split_at_mut(6);
            for (o, x) in own.iter_mut().zip(u.iter()) {
                *o += x * row[i];
            }
            for ((pp, pi), x) in (children.as_chunks_mut::<6>().0.iter_mut())
                .zip(p_i.as_chunks::<6>().0)
                .zip(&row[i + 1..])
            {
                for r in 0..6 {
                    pp[r] += pi[r] + u[r] * x;
                }
            }
            // Parents come before their children: `parent < i`.
            let (lo, hi) = d.oya.split_at_mut(i);
            hi[0].add_rank_one_update_to(&u, d_inv, &mut lo[parent]);
        }
    }
    Ok(())
}

/// `a · b` for six values each.
#[inline(always)]
fn dot6(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
}

/// Completes each row's upper part (`c ≥ i`, all a child needs of its parent's
/// accelerations) and writes `M⁻¹` in coordinates, mirrored.
fn forward_pass(model: &Model, data: &mut Data) {
    let n = model.nv;
    let nb = model.nbodies();
    let d = &mut data.deriv;
    for i in 0..nb {
        let (u, d_inv) = (d.u[i], d.d_inv[i]);
        let s = data.s_world[i].to_array();
        let parent = model.parent[i];
        let (below, rest) = d.cols.split_at_mut(i * 6 * n);
        let a_i = &mut rest[..6 * n];
        let row = &mut d.minv_rows[i * nb + i..(i + 1) * nb];
        let a_i = &mut a_i[6 * i..];
        if parent != WORLD {
            let a_p = &below[parent * 6 * n + 6 * i..(parent + 1) * 6 * n];
            for ((x, ai), ap) in row
                .iter_mut()
                .zip(a_i.as_chunks_mut::<6>().0)
                .zip(a_p.as_chunks::<6>().0)
            {
                let xv = *x - d_inv * dot6(&u, ap);
                *x = xv;
                for r in 0..6 {
                    ai[r] = ap[r] + s[r] * xv;
                }
            }
        } else {
            for (&x, ai) in row.iter().zip(a_i.as_chunks_mut::<6>().0) {
                for r in 0..6 {
                    ai[r] = s[r] * x;
                }
            }
        }
    }
    let minv = d.minv.as_mut_slice();
    for i in 0..nb {
        let (ci, mi) = (model.q_index[i], model.q_mult[i]);
        for c in i..nb {
            let (cc, mc) = (model.q_index[c], model.q_mult[c]);
            // Without mimic joints the multipliers are signs: dividing is multiplying.
            let x = d.minv_rows[i * nb + c] * (mi * mc);
            minv[cc * n + ci] = x;
            minv[ci * n + cc] = x;
        }
    }
}

/// `M⁻¹` through CRBA and the Cholesky factor (mimic joints).
fn invert_mass_matrix(model: &Model, data: &mut Data, q: &[f64]) -> Result<(), SingularMassMatrix> {
    crba(model, data, q);
    data.chol.copy_from(&data.mass);
    invert_factored(data)
}

/// `data.deriv.minv = M⁻¹` for the mass matrix held in `data.chol`, through its Cholesky
/// factor (computed in place).
pub(crate) fn invert_factored(data: &mut Data) -> Result<(), SingularMassMatrix> {
    cholesky_in_place(&mut data.chol)?;
    let minv = &mut data.deriv.minv;
    minv.fill(0.0);
    for c in 0..minv.ncols() {
        minv[(c, c)] = 1.0;
        let mut col = minv.column_mut(c);
        crate::core::linalg::cholesky_solve_in_place(&data.chol, col.as_mut_slice());
    }
    Ok(())
}
