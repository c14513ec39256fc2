//! `M⁻¹`'s recursion ([`crate::dynamics::minverse`]'s equations) one unit-torque column
//! at a time, for models of few bodies: there the blocks of four columns cost more than
//! they save (measured on the arms). Same buffers: body `i`'s `6 × nb` values are read
//! as `[f64; 6]` columns within its blocks' storage, its row within its row blocks'.

use crate::core::linalg::SingularMassMatrix;
use crate::core::sym6::Sym6;
use crate::model::data::Data;
use crate::model::derivative_data::MINV_BLOCK;
use crate::model::{Model, WORLD};

/// Bodies up to which [`by_column`] runs instead of the column blocks.
pub(crate) const MAX_BODIES: usize = 12;

/// The backward and forward passes; the caller mirrors the rows into `M⁻¹`.
pub(crate) fn by_column(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    backward_pass(model, data)?;
    forward_pass(model, data);
    Ok(())
}

/// `D_i⁻¹`, `U_i`, the partial rows `M⁻¹_i· = D_i⁻¹(e_i − S_iᵀ P_i)` and the forces
/// `P_λ += P_i + U_i M⁻¹_i·`, `I^A_λ += I^A_i − U_i D_i⁻¹ U_iᵀ`. Body `i`'s forces are
/// read in the columns `c > i` only.
fn backward_pass(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    let nb = model.nbodies();
    let stride = nb.div_ceil(MINV_BLOCK) * MINV_BLOCK;
    let n6 = 6 * stride;
    let d = &mut data.deriv;
    for i in 0..nb {
        d.oya[i] = Sym6::from_inertia_moved(&model.inertia_o[i], &data.o_m_i[i]);
    }
    let cols = d.cols.as_flattened_mut().as_flattened_mut();
    let rows = d.minv_rows.as_flattened_mut();
    for i in 0..nb {
        cols[i * n6 + 6 * i..i * n6 + 6 * nb].fill(0.0);
    }
    for i in (0..nb).rev() {
        let s = data.s_world[i].to_array();
        let (u, d_inv) = pivot(model, i, &d.oya[i], &s)?;
        let (below, rest) = cols.split_at_mut(i * n6);
        let p_i = &rest[6 * (i + 1)..6 * nb];
        let row = &mut rows[i * stride..i * stride + nb];
        row[i] = d_inv;
        for (r, col) in row[i + 1..].iter_mut().zip(p_i.as_chunks::<6>().0) {
            *r = -d_inv * dot6(&s, col);
        }
        d.u[i] = u;
        d.d_inv[i] = d_inv;
        let parent = model.parent[i];
        if parent != WORLD {
            let p_parent = &mut below[parent * n6 + 6 * i..parent * n6 + 6 * nb];
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

/// `U_i = I^A_i S_i` and `D_i⁻¹ = 1 / (S_iᵀ U_i + I_a / m_i²)` of body `i`, or the
/// singular joint (both kernels' pivot).
#[inline(always)]
pub(crate) fn pivot(
    model: &Model,
    i: usize,
    ia: &Sym6,
    s: &[f64; 6],
) -> Result<([f64; 6], f64), SingularMassMatrix> {
    let (ci, mi) = (model.q_index[i], model.q_mult[i]);
    let u = ia.mul(s);
    let dd = dot6(s, &u) + model.armature[ci] / (mi * mi);
    if !(dd > 0.0 && dd.is_finite()) {
        return Err(SingularMassMatrix::at(ci, dd));
    }
    Ok((u, 1.0 / dd))
}

/// `a · b` for six values each.
#[inline(always)]
fn dot6(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
}

/// Each row's upper part: `M⁻¹_i· −= D_i⁻¹ U_iᵀ A_λ`, `A_i = A_λ + S_i M⁻¹_i·`.
fn forward_pass(model: &Model, data: &mut Data) {
    let nb = model.nbodies();
    let stride = nb.div_ceil(MINV_BLOCK) * MINV_BLOCK;
    let n6 = 6 * stride;
    let d = &mut data.deriv;
    let cols = d.cols.as_flattened_mut().as_flattened_mut();
    let rows = d.minv_rows.as_flattened_mut();
    for i in 0..nb {
        let (u, d_inv) = (d.u[i], d.d_inv[i]);
        let s = data.s_world[i].to_array();
        let parent = model.parent[i];
        let (below, rest) = cols.split_at_mut(i * n6);
        let a_i = &mut rest[6 * i..6 * nb];
        let row = &mut rows[i * stride + i..i * stride + nb];
        if parent != WORLD {
            let a_p = &below[parent * n6 + 6 * i..parent * n6 + 6 * nb];
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
}
