//! The articulated-body algorithm for eight states at once, one per SIMD lane: the
//! recursion of [`crate::dynamics::aba`] (RBDA Table 7.1, body coordinates) with every
//! quantity a `[f64; 8]`:
//!
//! 1. forward: `v_i = ⁱX_λ v_λ + S_i q̇_i`, `c_i = v_i ×ₘ S_i q̇_i`, `I^A_i = I_i`,
//!    `p^A_i = v_i ×_f I_i v_i`;
//! 2. backward: `U_i = I^A_i S_i`, `D_i = S_iᵀ U_i + I_a`, `u_i = τ_i − S_iᵀ p^A_i`;
//!    `I^a = I^A_i − U_i D_i⁻¹ U_iᵀ`, `p^a = p^A_i + I^a c_i + U_i D_i⁻¹ u_i`,
//!    `I^A_λ += λX_i^* I^a ⁱX_λ`, `p^A_λ += λX_i^* p^a`;
//! 3. forward: `a'_i = ⁱX_λ a_λ + c_i` (`a_0 = −g`), `q̈_i = D_i⁻¹(u_i − U_iᵀ a'_i)`,
//!    `a_i = a'_i + S_i q̈_i`.
//!
//! Articulated inertias are kept in blocks `[[A, B], [Bᵀ, C]]` and moved to the parent
//! as [`crate::dynamics::aba::inertia_to_parent`] does: rotate (`R A Rᵀ`, …), then shift
//! by `T = [t]×`: `B += (T A)ᵀ`, `C += T B + (T B)ᵀ + T (T A)ᵀ` — first through the
//! joint (a rotation about one body axis, or a shift along it), then through the
//! constant placement. Same instruction-set dispatch and bitwise agreement as
//! [`crate::dynamics::rnea_lanes`]; agreement with the scalar ABA to rounding.
//!
//! Models with mimic joints have no ABA (see [`crate::dynamics::forward_dynamics`]):
//! [`aba_rows`] refuses them.

// Lane loops index several arrays by the lane: an explicit index keeps the scalar code's
// operations visible.
#![allow(clippy::needless_range_loop)]

use crate::core::simd_lanes::{sin_cos8, Isa, LaneBuf, Lanes, LANES};
use crate::core::spatial::InertiaO;
use crate::dynamics::lane_inertia::Art;
use crate::dynamics::lane_spatial::{
    add3, affine, cross, inertia_times, lane_rows, Joint, LaneKernel, Placement, SinCos, S6, ZERO3,
    ZERO6,
};
use crate::model::data::Data;
use crate::model::{Model, WORLD};

/// The buffers of [`AbaLanes::aba`] for one model: the passes' (per body the velocity,
/// velocity product, articulated inertia and bias force, `U`, `D⁻¹`, `u`, the joint
/// sine/cosine and the acceleration), the inputs transposed to lanes, the accelerations,
/// and a scalar [`Data`] for the rows [`aba_rows`] sends to the scalar code. Allocated
/// once; a call allocates nothing.
pub struct AbaLanes {
    passes: Passes,
    q: LaneBuf,
    qd: LaneBuf,
    tau: LaneBuf,
    scalar: Data,
}

struct Passes {
    v: Vec<S6>,
    c: Vec<S6>,
    ia: Vec<Art>,
    pa: Vec<S6>,
    u_col: Vec<S6>,
    d_inv: LaneBuf,
    u: LaneBuf,
    sc: Vec<SinCos>,
    acc: Vec<S6>,
    qdd: LaneBuf,
    isa: Isa,
}

impl AbaLanes {
    /// Buffers for `model` (without mimic joints), on the best instruction set of this
    /// CPU.
    pub fn new(model: &Model) -> AbaLanes {
        let (nb, nv) = (model.nbodies(), model.nv);
        let art = Art::ZERO;
        AbaLanes {
            passes: Passes {
                v: vec![ZERO6; nb],
                c: vec![ZERO6; nb],
                ia: vec![art; nb],
                pa: vec![ZERO6; nb],
                u_col: vec![ZERO6; nb],
                d_inv: LaneBuf::zeros(nb),
                u: LaneBuf::zeros(nb),
                sc: vec![SinCos([0.0; LANES], [0.0; LANES]); nb],
                acc: vec![ZERO6; nb],
                qdd: LaneBuf::zeros(nv),
                isa: Isa::at_most(None),
            },
            q: LaneBuf::zeros(nv),
            qd: LaneBuf::zeros(nv),
            tau: LaneBuf::zeros(nv),
            scalar: Data::new(model),
        }
    }

    /// Runs on at most `max` (to compare instruction sets; all give the same result).
    pub fn limit_isa(&mut self, max: Isa) {
        self.passes.isa = Isa::at_most(Some(max));
    }

    /// `q̈ = FD(q, q̇, τ)` for eight states with the model's gravity and armature (one
    /// lane array per coordinate, `|q| ≤ 1e4`). Returns `q̈[k][lane]`.
    pub fn aba(&mut self, model: &Model, q: &[Lanes], qd: &[Lanes], tau: &[Lanes]) -> &[Lanes] {
        let nv = model.nv;
        assert!(
            q.len() == nv && qd.len() == nv && tau.len() == nv,
            "q, qd, tau need one lane array per coordinate"
        );
        self.check(model);
        self.passes.run(model, q, qd, tau);
        &self.passes.qdd
    }

    fn check(&self, model: &Model) {
        assert!(
            !model.has_mimic,
            "ABA needs one coordinate per body; use forward_dynamics"
        );
        assert!(
            self.passes.v.len() == model.nbodies() && self.q.len() == model.nv,
            "AbaLanes was built for another model"
        );
    }
}

impl Passes {
    fn run(&mut self, model: &Model, q: &[Lanes], qd: &[Lanes], tau: &[Lanes]) {
        #[cfg(target_arch = "x86_64")]
        match self.isa {
            // SAFETY: `isa` is at most what `Isa::detected` found on this CPU.
            Isa::Avx512 => unsafe { aba_avx512(self, model, q, qd, tau) },
            Isa::Avx2 => unsafe { aba_avx2(self, model, q, qd, tau) },
            Isa::Baseline => aba_kernel(self, model, q, qd, tau),
        }
        #[cfg(not(target_arch = "x86_64"))]
        aba_kernel(self, model, q, qd, tau);
    }
}

/// [`aba_kernel`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn aba_avx2(w: &mut Passes, model: &Model, q: &[Lanes], qd: &[Lanes], tau: &[Lanes]) {
    aba_kernel(w, model, q, qd, tau)
}

/// [`aba_kernel`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq")]
unsafe fn aba_avx512(w: &mut Passes, model: &Model, q: &[Lanes], qd: &[Lanes], tau: &[Lanes]) {
    aba_kernel(w, model, q, qd, tau)
}

/// The joint of body `i` in the eight states (its sine/cosine already in `w.sc[i]`).
#[inline(always)]
fn joint(model: &Model, w: &Passes, i: usize) -> Joint {
    let kind = model.kind[i];
    Joint {
        k: kind.axis_index(),
        revolute: kind.is_revolute(),
        sc: w.sc[i],
    }
}

/// The three passes (see the module docs).
#[inline(always)]
fn aba_kernel(w: &mut Passes, model: &Model, q: &[Lanes], qd: &[Lanes], tau: &[Lanes]) {
    let nb = model.nbodies();
    for i in 0..nb {
        let (m, o, qi) = (model.q_mult[i], model.q_offset[i], model.q_index[i]);
        let theta = affine(&q[qi], m, o);
        w.sc[i] = if model.kind[i].is_revolute() {
            let (s, c) = sin_cos8(&theta);
            SinCos(s, c)
        } else {
            SinCos(theta, [0.0; LANES])
        };
        let j = joint(model, w, i);
        let rate = affine(&qd[qi], m, 0.0);
        let parent = model.parent[i];
        // Written in place: a copied `S6` or `Art` is a `memcpy` of 384 bytes or more.
        w.v[i] = if parent == WORLD {
            ZERO6
        } else {
            j.inv_motion(&Placement::of(model, i).inv_motion(&w.v[parent]))
        };
        let v = &mut w.v[i];
        j.add_subspace(v, &rate);
        w.c[i] = ZERO6;
        j.add_velocity_product(&mut w.c[i], v, &rate);
        w.ia[i] = Art::rigid(&model.inertia_o[i]);
        w.pa[i] = bias_force(&model.inertia_o[i], v);
    }
    for i in (0..nb).rev() {
        let kind = model.kind[i];
        let s = kind.axis_index() + if kind.is_revolute() { 3 } else { 0 };
        let u_col = w.ia[i].column(s);
        let (qi, m) = (model.q_index[i], model.q_mult[i]);
        let ia_k = model.armature[qi];
        let (mut d_inv, mut u) = ([0.0; LANES], [0.0; LANES]);
        for l in 0..LANES {
            d_inv[l] = 1.0 / (entry(&u_col, s)[l] + ia_k);
            // Body coordinate θ = m q + o: its generalised force is τ / m.
            u[l] = tau[qi][l] / m - entry(&w.pa[i], s)[l];
        }
        w.u_col[i] = u_col;
        w.d_inv[i] = d_inv;
        w.u[i] = u;
        let parent = model.parent[i];
        if parent != WORLD {
            let (j, place) = (joint(model, w, i), Placement::of(model, i));
            // `I_i^A` is not read again: reduced and moved to the parent in place (the
            // parent's, `parent < i`, is in `before`).
            let (before, from_i) = w.ia.split_at_mut(i);
            let ia = &mut from_i[0];
            ia.sub_rank_one(&u_col, &d_inv);
            let mut pa = ia.times(&w.c[i]);
            for r in 0..3 {
                for l in 0..LANES {
                    let ud = u[l] * d_inv[l];
                    pa.lin[r][l] += w.pa[i].lin[r][l] + u_col.lin[r][l] * ud;
                    pa.ang[r][l] += w.pa[i].ang[r][l] + u_col.ang[r][l] * ud;
                }
            }
            ia.joint_to_parent(&j);
            ia.placement_to_parent(&place);
            before[parent].add(ia);
            let fp = place.force(&j.force(&pa));
            add3(&mut w.pa[parent].lin, &fp.lin);
            add3(&mut w.pa[parent].ang, &fp.ang);
        }
    }
    let g = model.gravity;
    let a_root = S6 {
        lin: [[-g.x; LANES], [-g.y; LANES], [-g.z; LANES]],
        ang: ZERO3,
    };
    for i in 0..nb {
        let parent = model.parent[i];
        let ap = if parent == WORLD {
            &a_root
        } else {
            &w.acc[parent]
        };
        let j = joint(model, w, i);
        w.acc[i] = j.inv_motion(&Placement::of(model, i).inv_motion(ap));
        let a = &mut w.acc[i];
        add3(&mut a.lin, &w.c[i].lin);
        add3(&mut a.ang, &w.c[i].ang);
        let ua = dot6(&w.u_col[i], a);
        let mut th_dd = [0.0; LANES];
        for l in 0..LANES {
            th_dd[l] = w.d_inv[i][l] * (w.u[i][l] - ua[l]);
        }
        j.add_subspace(a, &th_dd);
        let (qi, m) = (model.q_index[i], model.q_mult[i]);
        for l in 0..LANES {
            w.qdd[qi][l] = th_dd[l] / m;
        }
    }
}

/// Component `s` of a spatial vector (0–2 linear, 3–5 angular).
#[inline(always)]
fn entry(x: &S6, s: usize) -> &Lanes {
    if s < 3 {
        &x.lin[s]
    } else {
        &x.ang[s - 3]
    }
}

/// `xᵀ y` per lane.
#[inline(always)]
fn dot6(x: &S6, y: &S6) -> Lanes {
    let mut out = [0.0; LANES];
    for l in 0..LANES {
        out[l] = ((x.lin[0][l] * y.lin[0][l] + x.lin[1][l] * y.lin[1][l])
            + x.lin[2][l] * y.lin[2][l])
            + ((x.ang[0][l] * y.ang[0][l] + x.ang[1][l] * y.ang[1][l]) + x.ang[2][l] * y.ang[2][l]);
    }
    out
}

/// `p = v ×_f I v`.
#[inline(always)]
fn bias_force(inertia: &InertiaO, v: &S6) -> S6 {
    let iv = inertia_times(inertia, v);
    let wf = cross(&v.ang, &iv.lin);
    let wn = cross(&v.ang, &iv.ang);
    let vf = cross(&v.lin, &iv.lin);
    let mut p = ZERO6;
    for r in 0..3 {
        for l in 0..LANES {
            p.lin[r][l] = wf[r][l];
            p.ang[r][l] = wn[r][l] + vf[r][l];
        }
    }
    p
}

/// `q̈` for every row of the row-major `(n, nv)` arrays `q`, `qd`, `tau` into `qdd`
/// (same shape), eight rows at a time in SIMD lanes; a group of eight with a joint value
/// the lane `sin_cos` cannot take (`|q| > 1e4`, or not finite) and the last `n mod 8`
/// rows go through the scalar [`crate::dynamics::aba`]. The model must have no mimic
/// joints. Allocates nothing.
pub fn aba_rows(
    model: &Model,
    w: &mut AbaLanes,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) {
    w.check(model);
    lane_rows(model, w, (q, qd, tau), qdd);
}

impl LaneKernel for AbaLanes {
    fn inputs(&mut self) -> [&mut [Lanes]; 3] {
        [&mut self.q, &mut self.qd, &mut self.tau]
    }

    fn run(&mut self, model: &Model) -> &[Lanes] {
        self.passes.run(model, &self.q, &self.qd, &self.tau);
        &self.passes.qdd
    }

    fn scalar<'s>(&'s mut self, model: &Model, q: &[f64], qd: &[f64], tau: &[f64]) -> &'s [f64] {
        crate::dynamics::aba(model, &mut self.scalar, q, qd, tau)
    }
}
