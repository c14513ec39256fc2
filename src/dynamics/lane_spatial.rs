//! The spatial algebra of the lane kernels ([`crate::dynamics::rnea_lanes`],
//! [`crate::dynamics::aba_lanes`]): 3-vectors and spatial vectors of eight states, one per
//! SIMD lane (struct of arrays, [`crate::core::simd_lanes`]), a joint's transform in eight
//! states ([`Joint`]: a rotation about one body axis, or a shift along it), a body's
//! constant placement ([`Placement`]: identity, signed permutation or 3×3, then a
//! translation), rigid-body inertia times a motion, and the transposition of eight input
//! rows into lanes. Straight-line lane loops without fused multiply-adds: the same bits on
//! every instruction set.

// Lane loops index several arrays by the lane: an explicit index keeps the scalar code's
// operations visible.
#![allow(clippy::needless_range_loop)]

use crate::core::simd_lanes::{lanes_in_range, Lanes, LANES};
use crate::core::spatial::{InertiaO, Se3};
use crate::model::Model;

/// A 3-vector per lane.
pub(crate) type V3 = [Lanes; 3];

/// A spatial vector per lane: `(linear, angular)`, aligned to the cache line (a lane
/// array is one 64-byte AVX-512 register; an unaligned one straddles two lines).
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct S6 {
    pub(crate) lin: V3,
    pub(crate) ang: V3,
}

pub(crate) const ZERO3: V3 = [[0.0; LANES]; 3];
pub(crate) const ZERO6: S6 = S6 {
    lin: ZERO3,
    ang: ZERO3,
};

/// `m x + o` per lane (`x` itself for an ordinary joint).
#[inline(always)]
pub(crate) fn affine(x: &Lanes, m: f64, o: f64) -> Lanes {
    if m == 1.0 && o == 0.0 {
        return *x;
    }
    let mut out = [0.0; LANES];
    for l in 0..LANES {
        out[l] = x[l] * m + o;
    }
    out
}

/// `I m = (mass m_lin − h × m_ang, I_O m_ang + h × m_lin)`.
#[inline(always)]
pub(crate) fn inertia_times(inertia: &InertiaO, m: &S6) -> S6 {
    let (mass, h) = (inertia.m, [inertia.h.x, inertia.h.y, inertia.h.z]);
    let io = &inertia.i_o;
    let (xx, yy, zz) = (io[(0, 0)], io[(1, 1)], io[(2, 2)]);
    let (xy, xz, yz) = (io[(0, 1)], io[(0, 2)], io[(1, 2)]);
    let hw = cross_c(&h, &m.ang);
    let hv = cross_c(&h, &m.lin);
    let mut out = ZERO6;
    for r in 0..3 {
        for l in 0..LANES {
            out.lin[r][l] = m.lin[r][l] * mass - hw[r][l];
        }
    }
    let w = &m.ang;
    for l in 0..LANES {
        out.ang[0][l] = ((xx * w[0][l] + xy * w[1][l]) + xz * w[2][l]) + hv[0][l];
        out.ang[1][l] = ((xy * w[0][l] + yy * w[1][l]) + yz * w[2][l]) + hv[1][l];
        out.ang[2][l] = ((xz * w[0][l] + yz * w[1][l]) + zz * w[2][l]) + hv[2][l];
    }
    out
}

/// A joint's `(sin θ, cos θ)` per lane (a prismatic joint's `(θ, 0)`), cache-line
/// aligned as [`S6`].
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct SinCos(pub(crate) Lanes, pub(crate) Lanes);

/// A joint's transform in one of eight states: a rotation about body axis `k` by the
/// angle whose `(sin, cos)` is `sc`, or (prismatic) a shift `sc.0` along it.
pub(crate) struct Joint {
    pub(crate) k: usize,
    pub(crate) revolute: bool,
    pub(crate) sc: SinCos,
}

impl Joint {
    /// `J⁻¹ m`: `(Rᵀ v, Rᵀ ω)`, or `(v − d × ω, ω)` for a shift `d`.
    #[inline(always)]
    pub(crate) fn inv_motion(&self, m: &S6) -> S6 {
        if self.revolute {
            S6 {
                lin: self.rotate(&m.lin, true),
                ang: self.rotate(&m.ang, true),
            }
        } else {
            let dw = self.shift_cross(&m.ang);
            let mut lin = m.lin;
            sub3(&mut lin, &dw);
            S6 { lin, ang: m.ang }
        }
    }

    /// `J f`: `(R f, R n)`, or `(f, n + d × f)` for a shift `d`.
    #[inline(always)]
    pub(crate) fn force(&self, f: &S6) -> S6 {
        if self.revolute {
            S6 {
                lin: self.rotate(&f.lin, false),
                ang: self.rotate(&f.ang, false),
            }
        } else {
            let df = self.shift_cross(&f.lin);
            let mut ang = f.ang;
            add3(&mut ang, &df);
            S6 { lin: f.lin, ang }
        }
    }

    /// `m += S x` (`S = e_k` in the angular part, or the linear part for a shift).
    #[inline(always)]
    pub(crate) fn add_subspace(&self, m: &mut S6, x: &Lanes) {
        let part = if self.revolute {
            &mut m.ang
        } else {
            &mut m.lin
        };
        for l in 0..LANES {
            part[self.k][l] += x[l];
        }
    }

    /// `a += v ×ₘ (S q̇)`: `(v_lin × e_k q̇, ω × e_k q̇)` for a rotation, `(ω × e_k q̇, 0)`
    /// for a shift.
    #[inline(always)]
    pub(crate) fn add_velocity_product(&self, a: &mut S6, v: &S6, rate: &Lanes) {
        if self.revolute {
            self.add_cross_axis(&mut a.lin, &v.lin, rate);
            self.add_cross_axis(&mut a.ang, &v.ang, rate);
        } else {
            self.add_cross_axis(&mut a.lin, &v.ang, rate);
        }
    }

    /// `out += x × e_k q̇`: component `i` gains `x_j q̇`, component `j` loses `x_i q̇`.
    #[inline(always)]
    pub(crate) fn add_cross_axis(&self, out: &mut V3, x: &V3, rate: &Lanes) {
        let (i, j) = ((self.k + 1) % 3, (self.k + 2) % 3);
        for l in 0..LANES {
            out[i][l] += x[j][l] * rate[l];
            out[j][l] -= x[i][l] * rate[l];
        }
    }

    /// `R_k x` (or `R_kᵀ x` when `transpose`).
    #[inline(always)]
    pub(crate) fn rotate(&self, x: &V3, transpose: bool) -> V3 {
        let (i, j) = ((self.k + 1) % 3, (self.k + 2) % 3);
        let SinCos(s, c) = &self.sc;
        let mut out = *x;
        for l in 0..LANES {
            let sl = if transpose { -s[l] } else { s[l] };
            out[i][l] = c[l] * x[i][l] - sl * x[j][l];
            out[j][l] = sl * x[i][l] + c[l] * x[j][l];
        }
        out
    }

    /// `d × x` for the shift `d = e_k θ` (`θ` is `sc.0` for a prismatic joint).
    #[inline(always)]
    pub(crate) fn shift_cross(&self, x: &V3) -> V3 {
        let (i, j) = ((self.k + 1) % 3, (self.k + 2) % 3);
        let d = &self.sc.0;
        let mut out = ZERO3;
        for l in 0..LANES {
            out[i][l] = -(d[l] * x[j][l]);
            out[j][l] = d[l] * x[i][l];
        }
        out
    }
}

/// A body's constant placement `P = (R, t)` in its parent, with the rotation's cheap
/// forms.
pub(crate) struct Placement<'m> {
    pub(crate) pose: &'m Se3,
    pub(crate) identity: bool,
    pub(crate) perm: Option<[(usize, f64); 3]>,
    pub(crate) zero_trans: bool,
}

impl<'m> Placement<'m> {
    #[inline(always)]
    pub(crate) fn of(model: &'m Model, i: usize) -> Self {
        let pose = &model.placement[i];
        Placement {
            pose,
            identity: model.placement_identity[i],
            perm: model.placement_perm[i],
            zero_trans: pose.trans.iter().all(|&x| x == 0.0),
        }
    }

    /// `P⁻¹ m = (Rᵀ (v − t × ω), Rᵀ ω)`.
    #[inline(always)]
    pub(crate) fn inv_motion(&self, m: &S6) -> S6 {
        let mut lin = m.lin;
        if !self.zero_trans {
            let t = [self.pose.trans.x, self.pose.trans.y, self.pose.trans.z];
            sub3(&mut lin, &cross_c(&t, &m.ang));
        }
        S6 {
            lin: self.rot(&lin, true),
            ang: self.rot(&m.ang, true),
        }
    }

    /// `P f = (R f, R n + t × R f)`.
    #[inline(always)]
    pub(crate) fn force(&self, f: &S6) -> S6 {
        let lin = self.rot(&f.lin, false);
        let mut ang = self.rot(&f.ang, false);
        if !self.zero_trans {
            let t = [self.pose.trans.x, self.pose.trans.y, self.pose.trans.z];
            add3(&mut ang, &cross_c(&t, &lin));
        }
        S6 { lin, ang }
    }

    /// `R x` (or `Rᵀ x`).
    #[inline(always)]
    pub(crate) fn rot(&self, x: &V3, transpose: bool) -> V3 {
        if self.identity {
            return *x;
        }
        let mut out = ZERO3;
        if let Some(p) = self.perm {
            // Column c of R is sign × e_src: R x puts sign x_c at src; Rᵀ x takes it back.
            for (c, &(src, sign)) in p.iter().enumerate() {
                let (to, from) = if transpose { (c, src) } else { (src, c) };
                for l in 0..LANES {
                    out[to][l] = x[from][l] * sign;
                }
            }
            return out;
        }
        let r = &self.pose.rot;
        for row in 0..3 {
            let e = |c: usize| if transpose { r[(c, row)] } else { r[(row, c)] };
            let (e0, e1, e2) = (e(0), e(1), e(2));
            for l in 0..LANES {
                out[row][l] = (e0 * x[0][l] + e1 * x[1][l]) + e2 * x[2][l];
            }
        }
        out
    }
}

/// `a × b` per lane.
#[inline(always)]
pub(crate) fn cross(a: &V3, b: &V3) -> V3 {
    let mut out = ZERO3;
    for l in 0..LANES {
        out[0][l] = a[1][l] * b[2][l] - a[2][l] * b[1][l];
        out[1][l] = a[2][l] * b[0][l] - a[0][l] * b[2][l];
        out[2][l] = a[0][l] * b[1][l] - a[1][l] * b[0][l];
    }
    out
}

/// `c × b` for a constant `c`.
#[inline(always)]
pub(crate) fn cross_c(c: &[f64; 3], b: &V3) -> V3 {
    let mut out = ZERO3;
    for l in 0..LANES {
        out[0][l] = c[1] * b[2][l] - c[2] * b[1][l];
        out[1][l] = c[2] * b[0][l] - c[0] * b[2][l];
        out[2][l] = c[0] * b[1][l] - c[1] * b[0][l];
    }
    out
}

#[inline(always)]
pub(crate) fn add3(a: &mut V3, b: &V3) {
    for r in 0..3 {
        for l in 0..LANES {
            a[r][l] += b[r][l];
        }
    }
}

#[inline(always)]
pub(crate) fn sub3(a: &mut V3, b: &V3) {
    for r in 0..3 {
        for l in 0..LANES {
            a[r][l] -= b[r][l];
        }
    }
}

/// Eight rows of `nv` values into one lane array per coordinate.
#[inline(always)]
pub(crate) fn gather(rows: &[f64], nv: usize, out: &mut [Lanes]) {
    assert!(rows.len() == LANES * nv && out.len() >= nv);
    // Whole lane arrays stored at once (two or four vector stores), not eight scalars.
    for (k, o) in out[..nv].iter_mut().enumerate() {
        *o = std::array::from_fn(|l| rows[l * nv + k]);
    }
}

/// A lane kernel as [`lane_rows`] drives it: three inputs transposed to lanes, eight
/// states through the kernel, one row through the scalar algorithm.
pub(crate) trait LaneKernel {
    /// The three input buffers (one lane array per coordinate).
    fn inputs(&mut self) -> [&mut [Lanes]; 3];
    /// Runs the kernel on the inputs; the result per coordinate.
    fn run(&mut self, model: &Model) -> &[Lanes];
    /// One row through the scalar algorithm.
    fn scalar<'s>(&'s mut self, model: &Model, x: &[f64], y: &[f64], z: &[f64]) -> &'s [f64];
}

/// The kernel `w` on every row of the row-major `(n, nv)` arrays `x`, `y`, `z` into `out`
/// (same shape), eight rows at a time; a group with a joint value the lane `sin_cos`
/// cannot take (`|x| > 1e4`, or not finite) and the last `n mod 8` rows go through the
/// scalar algorithm. Allocates nothing.
pub(crate) fn lane_rows<K: LaneKernel>(
    model: &Model,
    w: &mut K,
    (x, y, z): (&[f64], &[f64], &[f64]),
    out: &mut [f64],
) {
    let nv = model.nv;
    let n = x.len().checked_div(nv).unwrap_or(0);
    assert!(
        x.len() == n * nv && y.len() == x.len() && z.len() == x.len() && out.len() == x.len(),
        "the three inputs and the output need the same (n, nv) shape"
    );
    let scalar_row = |w: &mut K, out: &mut [f64], r: usize| {
        let s = r * nv..(r + 1) * nv;
        let res = w.scalar(model, &x[s.clone()], &y[s.clone()], &z[s.clone()]);
        out[s].copy_from_slice(res);
    };
    let full = n / LANES * LANES;
    for r0 in (0..full).step_by(LANES) {
        let rows = r0 * nv..(r0 + LANES) * nv;
        let [bx, by, bz] = w.inputs();
        gather(&x[rows.clone()], nv, bx);
        if !lanes_in_range(bx) {
            for r in r0..r0 + LANES {
                scalar_row(w, out, r);
            }
            continue;
        }
        gather(&y[rows.clone()], nv, by);
        gather(&z[rows.clone()], nv, bz);
        let res = w.run(model);
        for (l, row) in out[rows].chunks_exact_mut(nv).enumerate() {
            for (k, o) in row.iter_mut().enumerate() {
                *o = res[k][l];
            }
        }
    }
    for r in full..n {
        scalar_row(w, out, r);
    }
}
