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

use crate::core::simd_lanes::{sin_cos8, Isa, LaneBuf, Lanes, LANES};
use crate::dynamics::lane_spatial::{
    add3, affine, cross, inertia_times, lane_rows, Joint, LaneKernel, Placement, SinCos, S6, ZERO3,
    ZERO6,
};
use crate::model::data::Data;
use crate::model::{Model, WORLD};

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

    fn check(&self, model: &Model) {
        assert!(
            self.passes.v.len() == model.nbodies() && self.q.len() == model.nv,
            "RneaLanes was built for another model"
        );
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
        self.check(model);
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
        // Read in place and written in place: a copied `S6` is a 384-byte `memcpy`.
        let (vp, ap) = if parent == WORLD {
            (&ZERO6, &a_root)
        } else {
            (&w.v[parent], &w.a[parent])
        };
        let joint = Joint { k, revolute, sc };
        w.a[i] = joint.inv_motion(&place.inv_motion(ap));
        w.v[i] = joint.inv_motion(&place.inv_motion(vp));
        let (v, a) = (&mut w.v[i], &mut w.a[i]);
        joint.add_subspace(v, &rate);
        joint.add_subspace(a, &accel);
        joint.add_velocity_product(a, v, &rate);
        w.f[i] = body_force(model, i, v, a);
    }
    for t in w.tau.iter_mut() {
        *t = [0.0; LANES];
    }
    for i in (0..model.nbodies()).rev() {
        // Parents come before their children: the parent's force is in `before`.
        let (before, from_i) = w.f.split_at_mut(i);
        let f = &from_i[0];
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
            let fp = Placement::of(model, i).force(&joint.force(f));
            let p = &mut before[parent];
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
    w.check(model);
    lane_rows(model, w, (q, qd, qdd), tau);
}

impl LaneKernel for RneaLanes {
    fn inputs(&mut self) -> [&mut [Lanes]; 3] {
        [&mut self.q, &mut self.qd, &mut self.qdd]
    }

    fn run(&mut self, model: &Model) -> &[Lanes] {
        self.passes.run(model, &self.q, &self.qd, &self.qdd);
        &self.passes.tau
    }

    fn scalar<'s>(&'s mut self, model: &Model, q: &[f64], qd: &[f64], qdd: &[f64]) -> &'s [f64] {
        crate::dynamics::rnea(model, &mut self.scalar, q, qd, qdd)
    }
}
