//! The inverse of the joint-space inertia matrix, `M(q)⁻¹`, in O(n²) without forming `M`
//! (Carpentier, *Analytical Inverse of the Joint Space Inertia Matrix*, 2018; Pinocchio's
//! `computeMinverse`): the articulated-body algorithm run on the `n` unit torques at once,
//! with zero velocity and no gravity, in the world frame (where moving an inertia or a
//! force to the parent costs nothing). Column `c` of `M⁻¹` is `q̈` for `τ = e_c`.
//!
//! 1. backward: `U_i = I^A_i S_i`, `D_i = S_iᵀ U_i + I_a`; the partial row
//!    `M⁻¹_i· = D_i⁻¹(e_i − S_iᵀ P_i)` from the children's articulated forces `P_i`
//!    (`6 × n`, one column per unit torque); `P_λ += P_i + U_i M⁻¹_i·`,
//!    `I^A_λ += I^A_i − U_i D_i⁻¹ U_iᵀ` (`I^A_i` starts from the body's own world inertia);
//! 2. forward: `M⁻¹_i· −= D_i⁻¹ U_iᵀ A_λ`, `A_i = A_λ + S_i M⁻¹_i·` (the bodies'
//!    accelerations under the unit torques, `A_0 = 0`).
//!
//! Columns are bodies, and bodies come after their parents, so body `i`'s forces are
//! zero outside its subtree's columns `c ≥ i`, and the rows are needed for `c ≥ i` only
//! (the rest by symmetry). The columns are taken [`MINV_BLOCK`] at a time: `P_i` (then
//! `A_i`) is stored as blocks of six rows of [`MINV_BLOCK`] side-by-side columns
//! ([`ColumnBlock`]), so `S_iᵀ P_i` and `P_i + U_i M⁻¹_i·` are whole-vector operations
//! on a block. Body `i` starts at the block holding column `i`; that block's columns
//! `c < i` are zero in `P_i` and never read in `A_i`. A body's `P` and `I^A` are
//! written (not added to) by its first child, so nothing is zeroed beforehand. On a
//! serial chain two storage slots taken in turn hold every body's blocks ([`slots`]).
//!
//! Bodies are driven by `θ_i = m_i q_i` (a sign, without mimic joints), so
//! `M⁻¹_q = G⁻¹ M⁻¹_θ G⁻¹` and the armature enters `D_i` as `I_a / m_i²`.
//!
//! **Small models and mimic joints** take CRBA's `M` and invert it through its Cholesky
//! factor instead: up to [`SPD_FIXED_MAX`] coordinates (the arms) with an inverse compiled
//! for the size ([`crate::core::spd_inverse`]), which with CRBA takes 0.64× (6
//! coordinates) to 0.93× (12) the recursion's time; with mimic joints the articulated
//! recursion does not apply at any size.

// Block loops index rows and columns: explicit indices keep the equations visible.
#![allow(clippy::needless_range_loop)]

use crate::core::linalg::{cholesky_in_place, SingularMassMatrix};
use crate::core::simd_lanes::Isa;
use crate::core::spd_inverse::{spd_inverse_small, SPD_FIXED_MAX};
use crate::core::sym6::Sym6;
use crate::dynamics::crba::crba;
use crate::dynamics::forward::name_joint;
use crate::kinematics::compute_joint_jacobians;
use crate::model::data::Data;
use crate::model::derivative_data::{ColumnBlock, MINV_BLOCK};
use crate::model::{Model, WORLD};
use nalgebra::DMatrix;

/// Columns per block.
const L: usize = MINV_BLOCK;

/// One row of a [`ColumnBlock`]: [`MINV_BLOCK`] columns.
type Lane = [f64; L];

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
    if inverts_mass_matrix(model) {
        crba(model, data, q);
        invert_spd(&data.mass, &mut data.chol, &mut data.deriv.minv)
    } else {
        compute_joint_jacobians(model, data, q);
        minverse_from_placements(model, data)
    }
    .map_err(|e| name_joint(e, model))?;
    Ok(&data.deriv.minv)
}

/// Whether [`compute_minverse`] inverts CRBA's `M` rather than run the recursion: small
/// models and models with mimic joints (module docs).
pub(crate) fn inverts_mass_matrix(model: &Model) -> bool {
    model.nv <= SPD_FIXED_MAX || model.has_mimic
}

/// [`compute_minverse`] where `data.o_m_i` and `data.s_world` are current for `q` (after
/// the RNEA derivatives' forward pass): the recursion starts from them.
pub(crate) fn minverse_after_placements(
    model: &Model,
    data: &mut Data,
    q: &[f64],
) -> Result<(), SingularMassMatrix> {
    if inverts_mass_matrix(model) {
        compute_minverse(model, data, q).map(|_| ())
    } else {
        minverse_from_placements(model, data).map_err(|e| name_joint(e, model))
    }
}

/// The recursion for a model without mimic joints whose `data.o_m_i` and `data.s_world`
/// are current. Runs on the instruction set detected when the buffers were sized (the
/// same results on each: no fused multiply-add is written, and Rust contracts none).
fn minverse_from_placements(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    #[cfg(target_arch = "x86_64")]
    if data.deriv.isa >= Isa::Avx2 {
        // SAFETY: `isa` is at most what `Isa::detected` found on this CPU.
        return unsafe { recursion_avx2(model, data) };
    }
    recursion(model, data)
}

/// [`recursion`] compiled for AVX2 (a block row is one register).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn recursion_avx2(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    recursion(model, data)
}

/// The two passes and the mirrored result (see the module docs).
#[inline(always)]
fn recursion(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    backward_pass(model, data)?;
    forward_pass(model, data);
    write_minv(model, data);
    Ok(())
}

/// `D_i⁻¹`, `U_i`, the partial rows and the articulated forces of the unit torques.
/// `P_i` and `I^A_i` are current once every child has been visited; `p_set[i]` says
/// whether a child has written them (afterwards: whether body `i` has children).
#[inline(always)]
fn backward_pass(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    let nb = model.nbodies();
    let nblk = nb.div_ceil(L);
    let slot = slots(model);
    let d = &mut data.deriv;
    d.p_set[..nb].fill(false);
    for i in (0..nb).rev() {
        let b0 = i / L;
        let parent = model.parent[i];
        let (own, of_parent) = body_blocks(&mut d.cols, nblk, slot(i), parent, slot(parent));
        let p_i = &mut own[b0..];
        if !d.p_set[i] {
            // A leaf: no forces from below, its own inertia.
            p_i.fill([[0.0; L]; 6]);
            d.oya[i] = Sym6::from_inertia_moved(&model.inertia_o[i], &data.o_m_i[i]);
        }
        let s = data.s_world[i].to_array();
        let (u, d_inv) = pivot(model, i, &d.oya[i], &s)?;
        d.u[i] = u;
        d.d_inv[i] = d_inv;
        let row = &mut d.minv_rows[i * nblk + b0..(i + 1) * nblk];
        let body = Pivot {
            s,
            u,
            d_inv,
            diag: i % L,
        };
        let Some(p_parent) = of_parent else {
            for (k, (r, p)) in row.iter_mut().zip(p_i.iter()).enumerate() {
                *r = body.partial_row(k, p);
            }
            continue;
        };
        // Parents come before their children: `parent < i`.
        let (lo, hi) = d.oya.split_at_mut(i);
        if d.p_set[parent] {
            rows_and_forces::<true>(&mut p_parent[b0..], p_i, &body, row);
        } else {
            // The first child: the parent's columns before this child's are zero.
            p_parent[parent / L..b0].fill([[0.0; L]; 6]);
            rows_and_forces::<false>(&mut p_parent[b0..], p_i, &body, row);
            lo[parent] = Sym6::from_inertia_moved(&model.inertia_o[parent], &data.o_m_i[parent]);
            d.p_set[parent] = true;
        }
        hi[0].add_rank_one_update_to(&u, d_inv, &mut lo[parent]);
    }
    Ok(())
}

/// Where each body keeps its forces, then its accelerations, in `data.deriv.cols`: its
/// own slot of `⌈nb / MINV_BLOCK⌉` blocks, or on a serial chain (every body the child of
/// the one before) two slots in turn. A chain body's slot last held its grandchild's,
/// read by nobody since; so the chain's working set is two `6 × nb` slots (19 KB at 200
/// bodies) instead of `nb` of them (1.9 MB, out of the L2 cache), at the same results.
fn slots(model: &Model) -> impl Fn(usize) -> usize {
    let chain = model.is_serial_chain();
    move |i| if chain { i % 2 } else { i }
}

/// Body `i`'s blocks (slot `own`) and, unless its `parent` is the world, its parent's
/// (slot `of_parent`, another slot).
#[inline(always)]
fn body_blocks(
    cols: &mut [ColumnBlock],
    nblk: usize,
    own: usize,
    parent: usize,
    of_parent: usize,
) -> (&mut [ColumnBlock], Option<&mut [ColumnBlock]>) {
    if parent == WORLD {
        return (&mut cols[own * nblk..(own + 1) * nblk], None);
    }
    assert_ne!(own, of_parent, "a body and its parent share no slot");
    let (lo, hi) = cols.split_at_mut(own.max(of_parent) * nblk);
    let (low, high) = (
        &mut lo[own.min(of_parent) * nblk..][..nblk],
        &mut hi[..nblk],
    );
    if own < of_parent {
        (low, Some(high))
    } else {
        (high, Some(low))
    }
}

/// Body `i`'s motion subspace `S_i`, `U_i`, `D_i⁻¹`, and where column `i` sits in its
/// first block.
struct Pivot {
    s: [f64; 6],
    u: [f64; 6],
    d_inv: f64,
    diag: usize,
}

impl Pivot {
    /// Block `k` of the partial row, `−D⁻¹ Sᵀ P`; in block 0, `M⁻¹_ii = D_i⁻¹` (`P_i`'s
    /// column `i` is zero).
    #[inline(always)]
    fn partial_row(&self, k: usize, p: &ColumnBlock) -> Lane {
        let (s, d_inv) = (&self.s, self.d_inv);
        let mut r = [0.0; L];
        for l in 0..L {
            let dot = s[0] * p[0][l]
                + s[1] * p[1][l]
                + s[2] * p[2][l]
                + s[3] * p[3][l]
                + s[4] * p[4][l]
                + s[5] * p[5][l];
            r[l] = -d_inv * dot;
        }
        if k == 0 {
            r[self.diag] = d_inv;
        }
        r
    }
}

/// The partial row of body `i` and `P_λ += P_i + U_i M⁻¹_i·`, block by block, each block
/// of `P_i` read once (`P_λ =` when not `ADD`).
#[inline(always)]
fn rows_and_forces<const ADD: bool>(
    p_parent: &mut [ColumnBlock],
    p_i: &[ColumnBlock],
    body: &Pivot,
    row: &mut [Lane],
) {
    let u = &body.u;
    for (k, ((pp, pi), x)) in p_parent.iter_mut().zip(p_i).zip(row).enumerate() {
        // Read into registers and written whole: the blocks could alias for all the
        // compiler knows, which kept it from vectorising the loop over columns.
        let (pi, old) = (*pi, *pp);
        let xr = body.partial_row(k, &pi);
        *x = xr;
        let mut out = [[0.0; L]; 6];
        for r in 0..6 {
            for l in 0..L {
                let f = pi[r][l] + u[r] * xr[l];
                out[r][l] = if ADD { old[r][l] + f } else { f };
            }
        }
        *pp = out;
    }
}

/// `A_i = A_λ + S_i M⁻¹_i·` for one block of columns (`A_λ = 0` at the root).
#[inline(always)]
fn child_acceleration(a_p: Option<&ColumnBlock>, s: &[f64; 6], x: &Lane) -> ColumnBlock {
    let ap = a_p.copied().unwrap_or([[0.0; L]; 6]);
    let mut out = [[0.0; L]; 6];
    for r in 0..6 {
        for l in 0..L {
            out[r][l] = ap[r][l] + s[r] * x[l];
        }
    }
    out
}

/// Completes each row's upper part (`c ≥ i`, all a child needs of its parent's
/// accelerations): `M⁻¹_i· −= D_i⁻¹ U_iᵀ A_λ`, then `A_i = A_λ + S_i M⁻¹_i·` for the
/// bodies with children.
#[inline(always)]
fn forward_pass(model: &Model, data: &mut Data) {
    let nb = model.nbodies();
    let nblk = nb.div_ceil(L);
    let slot = slots(model);
    let d = &mut data.deriv;
    for i in 0..nb {
        let b0 = i / L;
        let (u, d_inv, has_children) = (d.u[i], d.d_inv[i], d.p_set[i]);
        let s = data.s_world[i].to_array();
        let parent = model.parent[i];
        let (own, of_parent) = body_blocks(&mut d.cols, nblk, slot(i), parent, slot(parent));
        let a_i = &mut own[b0..];
        let row = &mut d.minv_rows[i * nblk + b0..(i + 1) * nblk];
        let Some(a_p) = of_parent else {
            if has_children {
                for (ai, x) in a_i.iter_mut().zip(row.iter()) {
                    *ai = child_acceleration(None, &s, x);
                }
            }
            continue;
        };
        let a_p = &a_p[b0..];
        if has_children {
            for ((x, ai), ap) in row.iter_mut().zip(a_i.iter_mut()).zip(a_p) {
                *x = complete_row(x, d_inv, &u, ap);
                *ai = child_acceleration(Some(ap), &s, x);
            }
        } else {
            for (x, ap) in row.iter_mut().zip(a_p) {
                *x = complete_row(x, d_inv, &u, ap);
            }
        }
    }
}

/// `x − D⁻¹ Uᵀ A_λ` for one block of columns.
#[inline(always)]
fn complete_row(x: &Lane, d_inv: f64, u: &[f64; 6], a_p: &ColumnBlock) -> Lane {
    let mut out = [0.0; L];
    for l in 0..L {
        let dot = u[0] * a_p[0][l]
            + u[1] * a_p[1][l]
            + u[2] * a_p[2][l]
            + u[3] * a_p[3][l]
            + u[4] * a_p[4][l]
            + u[5] * a_p[5][l];
        out[l] = x[l] - d_inv * dot;
    }
    out
}

/// `M⁻¹` in coordinates from the rows' upper parts, mirrored.
#[inline(always)]
fn write_minv(model: &Model, data: &mut Data) {
    let (n, nb) = (model.nv, model.nbodies());
    let stride = nb.div_ceil(L) * L;
    let d = &mut data.deriv;
    let rows = d.minv_rows.as_flattened();
    if (0..nb).all(|i| model.q_index[i] == i) {
        // Body `i`'s row is coordinate `i`'s: stored as column `i`'s lower part (the
        // contiguous stores), then mirrored.
        for i in 0..nb {
            let mi = model.q_mult[i];
            let col = &mut d.minv.as_mut_slice()[i * n + i..(i + 1) * n];
            let row = &rows[i * stride + i..i * stride + nb];
            for ((m, x), mc) in col.iter_mut().zip(row).zip(&model.q_mult[i..nb]) {
                // Without mimic joints the multipliers are signs: dividing is multiplying.
                *m = x * (mi * mc);
            }
        }
        d.minv.fill_upper_triangle_with_lower_triangle();
        return;
    }
    let minv = d.minv.as_mut_slice();
    for i in 0..nb {
        let (ci, mi) = (model.q_index[i], model.q_mult[i]);
        for c in i..nb {
            let (cc, mc) = (model.q_index[c], model.q_mult[c]);
            let x = rows[i * stride + c] * (mi * mc);
            minv[cc * n + ci] = x;
            minv[ci * n + cc] = x;
        }
    }
}

/// `U_i = I^A_i S_i` and `D_i⁻¹ = 1 / (S_iᵀ U_i + I_a / m_i²)` of body `i`, or the
/// singular joint.
#[inline(always)]
fn pivot(
    model: &Model,
    i: usize,
    ia: &Sym6,
    s: &[f64; 6],
) -> Result<([f64; 6], f64), SingularMassMatrix> {
    let (ci, mi) = (model.q_index[i], model.q_mult[i]);
    let u = ia.mul(s);
    let su = s[0] * u[0] + s[1] * u[1] + s[2] * u[2] + s[3] * u[3] + s[4] * u[4] + s[5] * u[5];
    let dd = su + model.armature[ci] / (mi * mi);
    if !(dd > 0.0 && dd.is_finite()) {
        return Err(SingularMassMatrix::at(ci, dd));
    }
    Ok((u, 1.0 / dd))
}

/// `minv = m⁻¹` for a symmetric positive-definite `m` (a mass matrix) through its
/// Cholesky factor: compiled for the size up to [`SPD_FIXED_MAX`] coordinates, else
/// factored in `chol` and solved column by column.
pub(crate) fn invert_spd(
    m: &DMatrix<f64>,
    chol: &mut DMatrix<f64>,
    minv: &mut DMatrix<f64>,
) -> Result<(), SingularMassMatrix> {
    let n = m.nrows();
    if n <= SPD_FIXED_MAX {
        return spd_inverse_small(n, m.as_slice(), minv.as_mut_slice());
    }
    chol.copy_from(m);
    cholesky_in_place(chol)?;
    minv.fill(0.0);
    for c in 0..n {
        minv[(c, c)] = 1.0;
        let mut col = minv.column_mut(c);
        crate::core::linalg::cholesky_solve_in_place(chol, col.as_mut_slice());
    }
    Ok(())
}
