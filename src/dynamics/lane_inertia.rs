//! Spatial inertias for eight states at once, one per SIMD lane: [`Art`], a symmetric
//! 6×6 inertia in blocks `[[A, B], [Bᵀ, C]]` (linear, angular), built from a rigid body
//! and moved to a parent frame as [`crate::dynamics::aba::inertia_to_parent`] does:
//! rotate (`R A Rᵀ`, …), then shift by `T = [t]×`: `B += (T A)ᵀ`,
//! `C += T B + (T B)ᵀ + T (T A)ᵀ` — first through the joint (a rotation about one body
//! axis, or a shift along it), then through the constant placement. The articulated
//! inertias of [`crate::dynamics::aba_lanes`] and the composite inertias of
//! [`crate::dynamics::crba_lanes`] are both of this kind.

// Lane loops index several arrays by the lane: an explicit index keeps the scalar code's
// operations visible.
#![allow(clippy::needless_range_loop)]

use crate::core::simd_lanes::{Lanes, LANES};
use crate::core::spatial::InertiaO;
use crate::dynamics::lane_spatial::{add3, cross, Joint, Placement, S6, V3, ZERO3, ZERO6};

/// A 3×3 matrix per lane, `[row][column]`.
type M3 = [V3; 3];

const ZERO_M3: M3 = [ZERO3; 3];

/// An articulated inertia `[[A, B], [Bᵀ, C]]` (linear, angular) per lane.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct Art {
    a: M3,
    b: M3,
    c: M3,
}

/// `X` with `f` applied to each row: `Z[i][·] = f(X[i][·])`, so `Z = X Fᵀ` for a linear
/// `f(x) = F x`.
#[inline(always)]
fn map_rows(x: &M3, f: impl Fn(&V3) -> V3) -> M3 {
    [f(&x[0]), f(&x[1]), f(&x[2])]
}

/// `F X` for a linear `f(x) = F x`, column by column.
#[inline(always)]
fn map_cols(x: &M3, f: impl Fn(&V3) -> V3) -> M3 {
    let mut out = ZERO_M3;
    for c in 0..3 {
        let col = f(&[x[0][c], x[1][c], x[2][c]]);
        for r in 0..3 {
            out[r][c] = col[r];
        }
    }
    out
}

/// `Xᵀ`.
#[inline(always)]
fn transpose(x: &M3) -> M3 {
    let mut out = ZERO_M3;
    for r in 0..3 {
        for c in 0..3 {
            out[r][c] = x[c][r];
        }
    }
    out
}

/// `x += y`.
#[inline(always)]
fn add_m3(x: &mut M3, y: &M3) {
    for r in 0..3 {
        add3(&mut x[r], &y[r]);
    }
}

impl Art {
    /// The zero inertia.
    pub(crate) const ZERO: Art = Art {
        a: ZERO_M3,
        b: ZERO_M3,
        c: ZERO_M3,
    };

    /// A rigid body's inertia: `A = m 1`, `B = −[h]×`, `C = I_O`.
    #[inline(always)]
    pub(crate) fn rigid(y: &InertiaO) -> Art {
        let (m, h) = (y.m, y.h);
        let splat = |x: f64| [x; LANES];
        let b = [
            [splat(0.0), splat(h.z), splat(-h.y)],
            [splat(-h.z), splat(0.0), splat(h.x)],
            [splat(h.y), splat(-h.x), splat(0.0)],
        ];
        let mut a = ZERO_M3;
        let mut c = ZERO_M3;
        for r in 0..3 {
            a[r][r] = splat(m);
            for k in 0..3 {
                c[r][k] = splat(y.i_o[(r, k)]);
            }
        }
        Art { a, b, c }
    }

    /// `I x = (A x_lin + B x_ang, Bᵀ x_lin + C x_ang)`.
    #[inline(always)]
    pub(crate) fn times(&self, x: &S6) -> S6 {
        let mut out = ZERO6;
        for r in 0..3 {
            for l in 0..LANES {
                out.lin[r][l] = ((self.a[r][0][l] * x.lin[0][l] + self.a[r][1][l] * x.lin[1][l])
                    + self.a[r][2][l] * x.lin[2][l])
                    + ((self.b[r][0][l] * x.ang[0][l] + self.b[r][1][l] * x.ang[1][l])
                        + self.b[r][2][l] * x.ang[2][l]);
                out.ang[r][l] = ((self.b[0][r][l] * x.lin[0][l] + self.b[1][r][l] * x.lin[1][l])
                    + self.b[2][r][l] * x.lin[2][l])
                    + ((self.c[r][0][l] * x.ang[0][l] + self.c[r][1][l] * x.ang[1][l])
                        + self.c[r][2][l] * x.ang[2][l]);
            }
        }
        out
    }

    /// Column `s` of the 6×6 matrix (`U = I S` for the unit motion `e_s`).
    #[inline(always)]
    pub(crate) fn column(&self, s: usize) -> S6 {
        let mut out = ZERO6;
        for r in 0..3 {
            if s < 3 {
                out.lin[r] = self.a[r][s];
                out.ang[r] = self.b[s][r];
            } else {
                out.lin[r] = self.b[r][s - 3];
                out.ang[r] = self.c[r][s - 3];
            }
        }
        out
    }

    /// `I −= U D⁻¹ Uᵀ`.
    #[inline(always)]
    pub(crate) fn sub_rank_one(&mut self, u: &S6, d_inv: &Lanes) {
        for r in 0..3 {
            for c in 0..3 {
                for l in 0..LANES {
                    let (ul, ua) = (u.lin[r][l] * d_inv[l], u.ang[r][l] * d_inv[l]);
                    self.a[r][c][l] -= ul * u.lin[c][l];
                    self.b[r][c][l] -= ul * u.ang[c][l];
                    self.c[r][c][l] -= ua * u.ang[c][l];
                }
            }
        }
    }

    /// `self += o`.
    #[inline(always)]
    pub(crate) fn add(&mut self, o: &Art) {
        add_m3(&mut self.a, &o.a);
        add_m3(&mut self.b, &o.b);
        add_m3(&mut self.c, &o.c);
    }

    /// `R · Rᵀ` on every block for the rotation `f(x) = R x`.
    #[inline(always)]
    fn rotate(&mut self, f: impl Fn(&V3) -> V3 + Copy) {
        self.a = map_rows(&map_cols(&self.a, f), f);
        self.b = map_rows(&map_cols(&self.b, f), f);
        self.c = map_rows(&map_cols(&self.c, f), f);
    }

    /// The shift by `t` (`T = [t]×`): `B += (T A)ᵀ`, `C += T B + (T B)ᵀ + T (T A)ᵀ`
    /// (with the old `B`).
    #[inline(always)]
    fn shift(&mut self, t: &V3) {
        let tx = |x: &V3| cross(t, x);
        let ta_t = transpose(&map_cols(&self.a, tx));
        let tb = map_cols(&self.b, tx);
        let t_ta_t = map_cols(&ta_t, tx);
        add_m3(&mut self.b, &ta_t);
        add_m3(&mut self.c, &tb);
        add_m3(&mut self.c, &transpose(&tb));
        add_m3(&mut self.c, &t_ta_t);
    }

    /// From the body frame to the joint's predecessor frame: `R_k · R_kᵀ`, or the shift
    /// by `d = e_k θ`.
    #[inline(always)]
    pub(crate) fn joint_to_parent(&mut self, j: &Joint) {
        if j.revolute {
            self.rotate(|x| j.rotate(x, false));
        } else {
            let mut d = ZERO3;
            d[j.k] = j.sc.0;
            self.shift(&d);
        }
    }

    /// Through the constant placement: rotate, then shift by its translation.
    #[inline(always)]
    pub(crate) fn placement_to_parent(&mut self, p: &Placement) {
        if !p.identity {
            self.rotate(|x| p.rot(x, false));
        }
        if !p.zero_trans {
            let t = p.pose.trans;
            self.shift(&[[t.x; LANES], [t.y; LANES], [t.z; LANES]]);
        }
    }
}
