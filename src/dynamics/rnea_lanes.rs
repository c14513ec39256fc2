//! Recursive Newton–Euler inverse dynamics for eight states at once, one per SIMD lane
//! (struct of arrays, [`crate::core::simd_lanes`]): the recursion of [`crate::dynamics::rnea`]
//! (RBDA Table 5.1, body coordinates), with every quantity a `[f64; 8]`:
//!
//! - forward pass: `v_i = ⁱX_λ v_λ + S_i q̇_i`,
//!   `a_i = ⁱX_λ a_λ + S_i q̈_i + v_i ×ₘ S_i q̇_i` (`a_0 = −g`),
//!   `f_i = I_i a_i + v_i ×_f I_i v_i`;
//! - backward pass: `τ_i = S_iᵀ f_i`, `f_λ += ᵡX_i^* f_i`; then `τ_k += I_a,k q̈_k`.
//!
//! `ⁱX_λ` is applied in two steps, the constant placement `P_i` (skipped when it is the
//! identity, a column shuffle when its rotation is a signed permutation) then the joint
//! `J_i(q_i)` (a rotation about one body axis, or a shift along it), never as a formed
//! 6×6 or 3×3 product. Joint sines and cosines come from [`sin_cos8`], the scalar code's
//! branch-free algorithm per lane. Mimic joints read `θ = m q_k + o` and add `m S_iᵀ f_i`
//! to `τ_k` as the scalar code does.
//!
//! The kernel is compiled three times (baseline, AVX2, AVX-512; [`Isa`] picks one at run
//! time) from the same straight-line lane loops, without fused multiply-adds: every
//! instruction set gives bitwise the same torques. They agree with the scalar
//! [`crate::dynamics::rnea`] to rounding (tested to 1e-12 relative).
//!
//! [`rnea_rows`] runs the kernel over row-major `(n, nv)` arrays, eight rows at a time;
//! rows whose joint values are out of the lane `sin_cos`'s range (or not finite) and the
//! last `n mod 8` rows go through the scalar `rnea`.

// Lane loops index several arrays by the lane: an explicit index keeps the scalar code's
// operations visible.
#![allow(clippy::needless_range_loop)]

use crate::core::simd_lanes::{lanes_in_range, sin_cos8, Isa, LaneBuf, Lanes, LANES};
use crate::core::spatial::{InertiaO, Se3};
use crate::model::data::Data;
use crate::model::{Model, WORLD};

/// A 3-vector per lane.
type V3 = [Lanes; 3];

/// A spatial vector per lane: `(linear, angular)`, aligned to the cache line (a lane
/// array is one 64-byte AVX-512 register; an unaligned one straddles two lines).
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct S6 {
    lin: V3,
    ang: V3,
}

const ZERO3: V3 = [[0.0; LANES]; 3];
const ZERO6: S6 = S6 {
    lin: ZERO3,
    ang: ZERO3,
};

/// The buffers of [`RneaLanes::rnea`] for one model: the passes' (below), the inputs
/// transposed to lanes, and a scalar [`Data`] for the rows [`rnea_rows`] sends to the
/// scalar code. Allocated once; a call allocates nothing.
pub struct RneaLanes {
    passes: Passes,
    q: LaneBuf,
    qd: LaneBuf,
    qdd: LaneBuf,
    scalar: Data,
}

/// What the two passes write: per body the velocity, acceleration, net force and joint
/// sine/cosine of eight states; the torques; the instruction set they run on.
struct Passes {
    v: Vec<S6>,
    a: Vec<S6>,
    f: Vec<S6>,
    sc: Vec<SinCos>,
    tau: LaneBuf,
    isa: Isa,
}

impl RneaLanes {
    /// Buffers for `model`, running on the best instruction set of this CPU.
    pub fn new(model: &Model) -> RneaLanes {
        let (nb, nv) = (model.nbodies(), model.nv);
        RneaLanes {
            passes: Passes {
                v: vec![ZERO6; nb],
                a: vec![ZERO6; nb],
                f: vec![ZERO6; nb],
                sc: vec![SinCos([0.0; LANES], [0.0; LANES]); nb],
                tau: LaneBuf::zeros(nv),
                isa: Isa::at_most(None),
            },
            q: LaneBuf::zeros(nv),
            qd: LaneBuf::zeros(nv),
            qdd: LaneBuf::zeros(nv),
            scalar: Data::new(model),
        }
    }

    /// Runs on at most `max` (to compare instruction sets; all give the same torques).
    pub fn limit_isa(&mut self, max: Isa) {
        self.passes.isa = Isa::at_most(Some(max));
    }

    /// The instruction set the kernel runs on.
    pub fn isa(&self) -> Isa {
        self.passes.isa
    }

    /// `τ = ID(q, q̇, q̈)` for eight states with the model's gravity and armature:
    /// `q[k][lane]` is coordinate `k` of state `lane` (one lane array per coordinate,
    /// `nv` of them; `|q| ≤ 1e4`, see [`lanes_in_range`]). Returns `τ[k][lane]`.
    pub fn rnea(&mut self, model: &Model, q: &[Lanes], qd: &[Lanes], qdd: &[Lanes]) -> &[Lanes] {
        let nv = model.nv;
        assert!(
            q.len() == nv && qd.len() == nv && qdd.len() == nv,
            "q, qd, qdd need one lane array per coordinate"
        );
        assert!(
            self.passes.v.len() == model.nbodies() && self.q.len() == nv,
            "RneaLanes was built for another model"
        );
        self.passes.run(model, q, qd, qdd);
        &self.passes.tau
    }
}

impl Passes {
    /// [`rnea_kernel`] on the instruction set `isa`.
    fn run(&mut self, model: &Model, q: &[Lanes], qd: &[Lanes], qdd: &[Lanes]) {
        #[cfg(target_arch = "x86_64")]
        match self.isa {
            // SAFETY: `isa` is at most what `Isa::detected` found on this CPU.
            Isa::Avx512 => unsafe { rnea_avx512(self, model, q, qd, qdd) },
            Isa::Avx2 => unsafe { rnea_avx2(self, model, q, qd, qdd) },
            Isa::Baseline => rnea_kernel(self, model, q, qd, qdd),
        }
        #[cfg(not(target_arch = "x86_64"))]
        rnea_kernel(self, model, q, qd, qdd);
    }
}

/// [`rnea_kernel`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn rnea_avx2(w: &mut Passes, model: &Model, q: &[Lanes], qd: &[Lanes], qdd: &[Lanes]) {
    rnea_kernel(w, model, q, qd, qdd)
}

/// [`rnea_kernel`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq")]
unsafe fn rnea_avx512(w: &mut Passes, model: &Model, q: &[Lanes], qd: &[Lanes], qdd: &[Lanes]) {
    rnea_kernel(w, model, q, qd, qdd)
}

/// The forward pass, the backward pass, the armature (see the module docs).
#[inline(always)]
fn rnea_kernel(w: &mut Passes, model: &Model, q: &[Lanes], qd: &[Lanes], qdd: &[Lanes]) {
    let g = model.gravity;
    let a_root = S6 {
        lin: [[-g.x; LANES], [-g.y; LANES], [-g.z; LANES]],
        ang: ZERO3,
    };
    for i in 0..model.nbodies() {
        let kind = model.kind[i];
        let (k, revolute) = (kind.axis_index(), kind.is_revolute());
        let (m, o) = (model.q_mult[i], model.q_offset[i]);
        let qi = model.q_index[i];
        let theta = affine(&q[qi], m, o);
        let (rate, accel) = (affine(&qd[qi], m, 0.0), affine(&qdd[qi], m, 0.0));
        let sc = if revolute {
            let (s, c) = sin_cos8(&theta);
            SinCos(s, c)
        } else {
            SinCos(theta, [0.0; LANES])
        };
        w.sc[i] = sc;
        let parent = model.parent[i];
        let place = Placement::of(model, i);
        let (vp, ap) = if parent == WORLD {
            (ZERO6, a_root)
        } else {
            (w.v[parent], w.a[parent])
        };
        let joint = Joint { k, revolute, sc };
        let mut v = joint.inv_motion(&place.inv_motion(&vp));
        let mut a = joint.inv_motion(&place.inv_motion(&ap));
        joint.add_subspace(&mut v, &rate);
        joint.add_subspace(&mut a, &accel);
        joint.add_velocity_product(&mut a, &v, &rate);
        w.v[i] = v;
        w.a[i] = a;
        w.f[i] = body_force(model, i, &v, &a);
    }
    for t in w.tau.iter_mut() {
        *t = [0.0; LANES];
    }
    for i in (0..model.nbodies()).rev() {
        let f = w.f[i];
        let kind = model.kind[i];
        let (k, revolute) = (kind.axis_index(), kind.is_revolute());
        let s = if revolute { &f.ang[k] } else { &f.lin[k] };
        let (m, t) = (model.q_mult[i], &mut w.tau[model.q_index[i]]);
        for l in 0..LANES {
            t[l] += m * s[l];
        }
        let parent = model.parent[i];
        if parent != WORLD {
            let joint = Joint {
                k,
                revolute,
                sc: w.sc[i],
            };
            let fp = Placement::of(model, i).force(&joint.force(&f));
            let p = &mut w.f[parent];
            add3(&mut p.lin, &fp.lin);
            add3(&mut p.ang, &fp.ang);
        }
    }
    for (kk, t) in w.tau.iter_mut().enumerate() {
        let ia = model.armature[kk];
        if ia != 0.0 {
            for l in 0..LANES {
                t[l] += ia * qdd[kk][l];
            }
        }
    }
}

/// `m x + o` per lane (`x` itself for an ordinary joint).
#[inline(always)]
fn affine(x: &Lanes, m: f64, o: f64) -> Lanes {
    if m == 1.0 && o == 0.0 {
        return *x;
    }
    let mut out = [0.0; LANES];
    for l in 0..LANES {
        out[l] = x[l] * m + o;
    }
    out
}

/// `f_i = I_i a_i + v_i ×_f I_i v_i`, with `I v = (m v − h × ω, I_O ω + h × v)` and
/// `v ×_f F = (ω × F_lin, ω × F_ang + v × F_lin)`.
#[inline(always)]
fn body_force(model: &Model, i: usize, v: &S6, a: &S6) -> S6 {
    let inertia = &model.inertia_o[i];
    let ia = inertia_times(inertia, a);
    let iv = inertia_times(inertia, v);
    let wf = cross(&v.ang, &iv.lin);
    let wn = cross(&v.ang, &iv.ang);
    let vf = cross(&v.lin, &iv.lin);
    let mut f = ia;
    for r in 0..3 {
        for l in 0..LANES {
            f.lin[r][l] += wf[r][l];
            f.ang[r][l] += wn[r][l] + vf[r][l];
        }
    }
    f
}

/// `I m = (mass m_lin − h × m_ang, I_O m_ang + h × m_lin)`.
#[inline(always)]
fn inertia_times(inertia: &InertiaO, m: &S6) -> S6 {
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
struct SinCos(Lanes, Lanes);

/// A joint's transform in one of eight states: a rotation about body axis `k` by the
/// angle whose `(sin, cos)` is `sc`, or (prismatic) a shift `sc.0` along it.
struct Joint {
    k: usize,
    revolute: bool,
    sc: SinCos,
}

impl Joint {
    /// `J⁻¹ m`: `(Rᵀ v, Rᵀ ω)`, or `(v − d × ω, ω)` for a shift `d`.
    #[inline(always)]
    fn inv_motion(&self, m: &S6) -> S6 {
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
    fn force(&self, f: &S6) -> S6 {
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
    fn add_subspace(&self, m: &mut S6, x: &Lanes) {
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
    fn add_velocity_product(&self, a: &mut S6, v: &S6, rate: &Lanes) {
        if self.revolute {
            self.add_cross_axis(&mut a.lin, &v.lin, rate);
            self.add_cross_axis(&mut a.ang, &v.ang, rate);
        } else {
            self.add_cross_axis(&mut a.lin, &v.ang, rate);
        }
    }

    /// `out += x × e_k q̇`: component `i` gains `x_j q̇`, component `j` loses `x_i q̇`.
    #[inline(always)]
    fn add_cross_axis(&self, out: &mut V3, x: &V3, rate: &Lanes) {
        let (i, j) = ((self.k + 1) % 3, (self.k + 2) % 3);
        for l in 0..LANES {
            out[i][l] += x[j][l] * rate[l];
            out[j][l] -= x[i][l] * rate[l];
        }
    }

    /// `R_k x` (or `R_kᵀ x` when `transpose`).
    #[inline(always)]
    fn rotate(&self, x: &V3, transpose: bool) -> V3 {
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
    fn shift_cross(&self, x: &V3) -> V3 {
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
struct Placement<'m> {
    pose: &'m Se3,
    identity: bool,
    perm: Option<[(usize, f64); 3]>,
    zero_trans: bool,
}

impl<'m> Placement<'m> {
    #[inline(always)]
    fn of(model: &'m Model, i: usize) -> Self {
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
    fn inv_motion(&self, m: &S6) -> S6 {
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
    fn force(&self, f: &S6) -> S6 {
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
    fn rot(&self, x: &V3, transpose: bool) -> V3 {
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
fn cross(a: &V3, b: &V3) -> V3 {
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
fn cross_c(c: &[f64; 3], b: &V3) -> V3 {
    let mut out = ZERO3;
    for l in 0..LANES {
        out[0][l] = c[1] * b[2][l] - c[2] * b[1][l];
        out[1][l] = c[2] * b[0][l] - c[0] * b[2][l];
        out[2][l] = c[0] * b[1][l] - c[1] * b[0][l];
    }
    out
}

#[inline(always)]
fn add3(a: &mut V3, b: &V3) {
    for r in 0..3 {
        for l in 0..LANES {
            a[r][l] += b[r][l];
        }
    }
}

#[inline(always)]
fn sub3(a: &mut V3, b: &V3) {
    for r in 0..3 {
        for l in 0..LANES {
            a[r][l] -= b[r][l];
        }
    }
}

/// `τ` for every row of the row-major `(n, nv)` arrays `q`, `qd`, `qdd` into `tau` (same
/// shape), eight rows at a time in SIMD lanes; a group of eight with a joint value the
/// lane `sin_cos` cannot take (`|q| > 1e4`, or not finite) and the last `n mod 8` rows
/// go through the scalar [`crate::dynamics::rnea`]. Allocates nothing.
pub fn rnea_rows(
    model: &Model,
    w: &mut RneaLanes,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    tau: &mut [f64],
) {
    let nv = model.nv;
    let n = q.len().checked_div(nv).unwrap_or(0);
    assert!(
        q.len() == n * nv && qd.len() == q.len() && qdd.len() == q.len() && tau.len() == q.len(),
        "q, qd, qdd and tau need the same (n, nv) shape"
    );
    assert!(
        w.passes.v.len() == model.nbodies() && w.q.len() == nv,
        "RneaLanes was built for another model"
    );
    let full = n / LANES * LANES;
    for r0 in (0..full).step_by(LANES) {
        let rows = r0 * nv..(r0 + LANES) * nv;
        gather(&q[rows.clone()], nv, &mut w.q);
        if !lanes_in_range(&w.q) {
            for r in r0..r0 + LANES {
                scalar_row(model, w, q, qd, qdd, tau, r);
            }
            continue;
        }
        gather(&qd[rows.clone()], nv, &mut w.qd);
        gather(&qdd[rows.clone()], nv, &mut w.qdd);
        w.passes.run(model, &w.q, &w.qd, &w.qdd);
        for (l, row) in tau[rows].chunks_exact_mut(nv).enumerate() {
            for (k, t) in row.iter_mut().enumerate() {
                *t = w.passes.tau[k][l];
            }
        }
    }
    for r in full..n {
        scalar_row(model, w, q, qd, qdd, tau, r);
    }
}

/// Row `r` through the scalar `rnea`.
fn scalar_row(
    model: &Model,
    w: &mut RneaLanes,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    tau: &mut [f64],
    r: usize,
) {
    let nv = model.nv;
    let s = r * nv..(r + 1) * nv;
    let t = crate::dynamics::rnea(
        model,
        &mut w.scalar,
        &q[s.clone()],
        &qd[s.clone()],
        &qdd[s.clone()],
    );
    tau[s].copy_from_slice(t);
}

/// Eight rows of `nv` values into one lane array per coordinate.
#[inline(always)]
fn gather(rows: &[f64], nv: usize, out: &mut [Lanes]) {
    for (l, row) in rows.chunks_exact(nv).enumerate() {
        for (k, x) in row.iter().enumerate() {
            out[k][l] = *x;
        }
    }
}
