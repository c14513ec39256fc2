//! The backward pass of the RNEA derivatives ([`crate::dynamics::rnea_derivatives`]) for a
//! long serial chain (body `i` on body `i − 1`, driving coordinate `i`, no mimic joints),
//! where every entry pairs an ancestor with a descendant and both walks run over
//! contiguous ranges. First, body by body from the tip, the subtree sums and each body's
//! covectors (O(n)); then the O(n²) entries as sums of rows of structure-of-arrays
//! columns, which vectorise (AVX2 at run time; each entry is summed in the same order on
//! every instruction set, and no fused multiply-add is written):
//!
//! - column `k`, rows `i ≥ k`: `∂τ_i/∂q_k = P_iᵀ Q_k`, `∂τ_i/∂q̇_k = P_iᵀ V_k`,
//!   `M_ik = (Y_i S_i)ᵀ S_k`, with `P_i = (Y_i S_i, Ẏ_iᵀ S_i)` from the subtree sums and
//!   `Q_k = (∂a_k, ∂v_k.ω)`, `V_k = (2 ∂v_k, S_k.ω)`;
//! - column `i`, rows `j < i`: `∂τ_j/∂q_i = S_jᵀ f^q_i`, `∂τ_j/∂q̇_i = S_jᵀ f^v_i`,
//!   `M_ji = S_jᵀ (Y_i S_i)`, with `f^q_i = Y_i ∂a_i + Ẏ_i ∂v_i + S_i ×* f_i` and
//!   `f^v_i = Y_i ∂a^v_i + Ẏ_i S_i`.
//!
//! Each column is written once, so nothing is zeroed first. The multipliers (signs) scale
//! the entries at the end when one is negative.

use crate::core::simd_lanes::Isa;
use crate::dynamics::terms::Terms;
use crate::model::data::Data;
use crate::model::derivative_data::CHAIN_SOA_ROWS;
use crate::model::Model;

/// Coordinates from which a serial chain takes this pass (below, the walks of
/// [`crate::dynamics::rnea_derivatives`] cost less than the columns' set-up).
pub(crate) const CHAIN_COLUMNS_MIN: usize = 24;

// Rows of the structure-of-arrays buffer: `P` (9), `f^q` (6), `f^v` (6), `Q` (9), `V`
// (9), `S` (6), the multiplier (1).
const P: usize = 0;
const FQ: usize = 9;
const FV: usize = 15;
const Q: usize = 21;
const V: usize = 30;
const S: usize = 39;
const MULT: usize = 45;

/// Whether `model` is a serial chain this pass applies to.
pub(crate) fn takes_chain_columns(model: &Model) -> bool {
    model.nv >= CHAIN_COLUMNS_MIN
        && !model.has_mimic
        && model.nbodies() == model.nv
        && model.is_serial_chain()
        && (0..model.nbodies()).all(|i| model.q_index[i] == i)
}

/// `τ` and the three partials (module docs).
pub(crate) fn backward_pass(model: &Model, data: &mut Data, terms: &Terms<'_>) {
    covectors(model, data);
    #[cfg(target_arch = "x86_64")]
    if data.deriv.isa >= Isa::Avx2 {
        // SAFETY: `isa` is at most what `Isa::detected` found on this CPU.
        unsafe { columns_avx2(model, data) };
        finish(model, data, terms);
        return;
    }
    columns(model, data);
    finish(model, data, terms);
}

/// Row `r` of the buffer (`n` values).
#[inline(always)]
fn row(soa: &[f64], n: usize, r: usize) -> &[f64] {
    &soa[r * n..(r + 1) * n]
}

/// From the tip: `τ_i`, the subtree sums, and every body's `P`, `f^q`, `f^v`, `Q`, `V`,
/// `S` and multiplier into the buffer.
fn covectors(model: &Model, data: &mut Data) {
    let n = model.nv;
    let d = &mut data.deriv;
    let soa = &mut d.soa;
    for i in (0..n).rev() {
        let (s, y, dy, f) = (data.s_world[i], d.oy[i], d.doy[i], d.of[i]);
        data.tau[i] = model.q_mult[i] * f.dot_motion(&s);
        let ys = y.mul_motion(&s);
        let dys = dy.tr_mul_motion(&s).n;
        let fq = y
            .mul_motion(&d.da_dq[i])
            .add(&dy.mul_motion(&d.dv_dq[i]))
            .add(&s.cross_force(&f));
        let fv = y.mul_motion(&d.da_dv[i]).add(&dy.mul_motion(&s));
        let (dv, da) = (d.dv_dq[i], d.da_dq[i]);
        let mut values = [0.0; CHAIN_SOA_ROWS];
        let mut put = |at: usize, xs: &[f64]| values[at..at + xs.len()].copy_from_slice(xs);
        put(P, &[ys.f.x, ys.f.y, ys.f.z, ys.n.x, ys.n.y, ys.n.z]);
        put(P + 6, &[dys.x, dys.y, dys.z]);
        put(FQ, &[fq.f.x, fq.f.y, fq.f.z, fq.n.x, fq.n.y, fq.n.z]);
        put(FV, &[fv.f.x, fv.f.y, fv.f.z, fv.n.x, fv.n.y, fv.n.z]);
        put(Q, &[da.v.x, da.v.y, da.v.z, da.w.x, da.w.y, da.w.z]);
        put(Q + 6, &[dv.w.x, dv.w.y, dv.w.z]);
        let dv2 = dv.scale(2.0);
        put(V, &[dv2.v.x, dv2.v.y, dv2.v.z, dv2.w.x, dv2.w.y, dv2.w.z]);
        put(V + 6, &[s.w.x, s.w.y, s.w.z]);
        put(S, &[s.v.x, s.v.y, s.v.z, s.w.x, s.w.y, s.w.z]);
        values[MULT] = model.q_mult[i];
        for (r, x) in values.iter().enumerate() {
            soa[r * n + i] = *x;
        }
        d.per_body[i] = values;
        if i > 0 {
            d.oy[i - 1] = d.oy[i - 1].add(&y);
            d.doy[i - 1] = d.doy[i - 1].add(&dy);
            d.of[i - 1] = d.of[i - 1].add(&f);
        }
    }
}

/// [`columns`] compiled for AVX2 (four entries of a column per instruction).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn columns_avx2(model: &Model, data: &mut Data) {
    columns(model, data);
}

/// The O(n²) entries, column by column (module docs).
#[inline(always)]
fn columns(model: &Model, data: &mut Data) {
    let n = model.nv;
    let d = &mut data.deriv;
    let soa = &d.soa;
    let (dq, dv, da) = (
        d.dtau_dq.as_mut_slice(),
        d.dtau_dv.as_mut_slice(),
        d.dtau_da.as_mut_slice(),
    );
    for k in 0..n {
        let mine = &d.per_body[k];
        let at = |r: usize| mine[r];
        // Rows i ≥ k: the descendants' P against this body's Q, V and S (S's three
        // missing rows zero).
        let c = [
            std::array::from_fn(|r| at(Q + r)),
            std::array::from_fn(|r| at(V + r)),
            std::array::from_fn(|r| if r < 6 { at(S + r) } else { 0.0 }),
        ];
        let rows = k * n + k..(k + 1) * n;
        let out = [&mut dq[rows.clone()], &mut dv[rows.clone()], &mut da[rows]];
        sum_rows::<9>(out, soa, n, k, P, c);
        // Rows j < k: the ancestors' S against this body's f^q, f^v and Y S.
        let c = [
            std::array::from_fn(|r| at(FQ + r)),
            std::array::from_fn(|r| at(FV + r)),
            std::array::from_fn(|r| at(P + r)),
        ];
        let rows = k * n..k * n + k;
        let out = [&mut dq[rows.clone()], &mut dv[rows.clone()], &mut da[rows]];
        sum_rows::<6>(out, soa, n, 0, S, c);
    }
}

/// Entries of a column computed at once (one AVX2 register).
const W: usize = 4;

/// `out[o][t] = Σ_r soa[left + r][from + t] · c[o][r]` for `r < LEN`, the three outputs
/// sharing the loads, summed in `r`'s order, [`W`] entries at a time in registers.
#[inline(always)]
fn sum_rows<const LEN: usize>(
    out: [&mut [f64]; 3],
    soa: &[f64],
    n: usize,
    from: usize,
    left: usize,
    c: [[f64; LEN]; 3],
) {
    let m = out[0].len();
    let rows: [&[f64]; LEN] = std::array::from_fn(|r| &row(soa, n, left + r)[from..from + m]);
    let [o0, o1, o2] = out;
    let (b0, t0) = o0.as_chunks_mut::<W>();
    let (b1, t1) = o1.as_chunks_mut::<W>();
    let (b2, t2) = o2.as_chunks_mut::<W>();
    for (b, ((x0, x1), x2)) in b0
        .iter_mut()
        .zip(b1.iter_mut())
        .zip(b2.iter_mut())
        .enumerate()
    {
        let mut acc = [[0.0; W]; 3];
        for r in 0..LEN {
            let x: &[f64; W] = rows[r][b * W..b * W + W].try_into().expect("W values");
            for (a, cc) in acc.iter_mut().zip(&c) {
                for l in 0..W {
                    a[l] = if r == 0 {
                        x[l] * cc[r]
                    } else {
                        a[l] + x[l] * cc[r]
                    };
                }
            }
        }
        (*x0, *x1, *x2) = (acc[0], acc[1], acc[2]);
    }
    let done = b0.len() * W;
    for (t, cc) in [t0, t1, t2].into_iter().zip(&c) {
        for (e, y) in t.iter_mut().enumerate() {
            let mut sum = rows[0][done + e] * cc[0];
            for r in 1..LEN {
                sum += rows[r][done + e] * cc[r];
            }
            *y = sum;
        }
    }
}

/// The multipliers when one is negative, and the armature on `M`'s diagonal.
fn finish(model: &Model, data: &mut Data, terms: &Terms<'_>) {
    let n = model.nv;
    let d = &mut data.deriv;
    if model.q_mult.iter().any(|m| *m < 0.0) {
        let mult = row(&d.soa, n, MULT);
        for mat in [&mut d.dtau_dq, &mut d.dtau_dv, &mut d.dtau_da] {
            for (k, col) in mat.as_mut_slice().chunks_exact_mut(n).enumerate() {
                for (x, m) in col.iter_mut().zip(mult) {
                    *x *= m * mult[k];
                }
            }
        }
    }
    let da = d.dtau_da.as_mut_slice();
    for k in 0..n {
        da[k * n + k] += terms.armature(model, k);
    }
}
