//! The composite-rigid-body algorithm for eight states at once, one per SIMD lane: the
//! recursion of [`crate::dynamics::crba`] (RBDA Table 6.2, body coordinates) with every
//! quantity a `[f64; 8]`:
//!
//! - `I^c_i = I_i`; backward: `I^c_λ += λX_i^* I^c_i ⁱX_λ`;
//! - `F = I^c_i S_i`, `M_ii = S_iᵀ F`; up the ancestors `j`: `F ← λX_j^* F`,
//!   `M_iλ(j) = M_λ(j)i = S_λ(j)ᵀ F`;
//! - `M_kk += I_a,k`.
//!
//! A composite inertia stays a rigid-body inertia (mass, first moment `h = m c`, `I_O`:
//! ten numbers, not the 21 of a general spatial inertia), moved to the parent through the
//! joint, then the placement: a rotation `h ← R h`, `I_O ← R I_O Rᵀ`, and a shift by `t`,
//! `I_O ← I_O − (h tᵀ + t hᵀ) + (2 t·h + m |t|²) 1 − m t tᵀ`, `h ← h + m t` (the parallel
//! axis theorem about the new origin). Forces go to the parent through the joint, then
//! the placement, as in [`crate::dynamics::rnea_lanes`]. Mimic joints: body `i` is driven
//! by `θ_i = m_i q_k + o_i`, so each entry is scaled by both bodies' multipliers and
//! summed onto the independent coordinates (`Gᵀ M G`), as the scalar CRBA does. Same
//! instruction-set dispatch and bitwise agreement as the other lane kernels; agreement
//! with the scalar CRBA to rounding.
//!
//! [`crba_rows`] runs the kernel over a row-major `(n, nv)` array of configurations into
//! `(n, nv, nv)` mass matrices, eight rows at a time; rows out of the lane `sin_cos`'s
//! range (or not finite) and the last `n mod 8` rows go through the scalar CRBA.

// Lane loops index several arrays by the lane: an explicit index keeps the scalar code's
// operations visible.
#![allow(clippy::needless_range_loop)]

use crate::core::simd_lanes::{lanes_in_range, sin_cos8, Isa, LaneBuf, Lanes, LANES};
use crate::core::spatial::InertiaO;
use crate::dynamics::lane_spatial::{
    affine, cross, gather, Joint, Placement, SinCos, S6, V3, ZERO3, ZERO6,
};
use crate::model::data::Data;
use crate::model::{Model, WORLD};

/// The buffers of [`CrbaLanes::crba`] for one model: per body the composite inertia and
/// joint sine/cosine, the mass matrices (`nv × nv` lane arrays, column-major), the
/// configurations transposed to lanes, and a scalar [`Data`] for the fallback rows.
/// Allocated once; a call allocates nothing.
pub struct CrbaLanes {
    passes: Passes,
    q: LaneBuf,
    scalar: Data,
}

struct Passes {
    ic: Vec<Composite>,
    sc: Vec<SinCos>,
    mass: LaneBuf,
    isa: Isa,
}

impl CrbaLanes {
    /// Buffers for `model`, running on the best instruction set of this CPU.
    pub fn new(model: &Model) -> CrbaLanes {
        let (nb, nv) = (model.nbodies(), model.nv);
        CrbaLanes {
            passes: Passes {
                ic: vec![Composite::ZERO; nb],
                sc: vec![SinCos([0.0; LANES], [0.0; LANES]); nb],
                mass: LaneBuf::zeros(nv * nv),
                isa: Isa::at_most(None),
            },
            q: LaneBuf::zeros(nv),
            scalar: Data::new(model),
        }
    }

    /// Runs on at most `max` (to compare instruction sets; all give the same matrices).
    pub fn limit_isa(&mut self, max: Isa) {
        self.passes.isa = Isa::at_most(Some(max));
    }

    /// The instruction set the kernel runs on.
    pub fn isa(&self) -> Isa {
        self.passes.isa
    }

    fn check(&self, model: &Model) {
        assert!(
            self.passes.ic.len() == model.nbodies() && self.q.len() == model.nv,
            "CrbaLanes was built for another model"
        );
    }

    /// `M(q)` for eight states with the model's armature: `q[k][lane]` is coordinate `k`
    /// of state `lane` (`|q| ≤ 1e4`, see [`lanes_in_range`]). Returns `M[c·nv + r][lane]`
    /// (column-major; symmetric).
    pub fn crba(&mut self, model: &Model, q: &[Lanes]) -> &[Lanes] {
        assert_eq!(q.len(), model.nv, "q needs one lane array per coordinate");
        self.check(model);
        self.passes.run(model, q);
        &self.passes.mass
    }
}

impl Passes {
    /// [`crba_kernel`] on the instruction set `isa`.
    fn run(&mut self, model: &Model, q: &[Lanes]) {
        #[cfg(target_arch = "x86_64")]
        match self.isa {
            // SAFETY: `isa` is at most what `Isa::detected` found on this CPU.
            Isa::Avx512 => unsafe { crba_avx512(self, model, q) },
            Isa::Avx2 => unsafe { crba_avx2(self, model, q) },
            Isa::Baseline => crba_kernel(self, model, q),
        }
        #[cfg(not(target_arch = "x86_64"))]
        crba_kernel(self, model, q);
    }
}

/// [`crba_kernel`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn crba_avx2(w: &mut Passes, model: &Model, q: &[Lanes]) {
    crba_kernel(w, model, q)
}

/// [`crba_kernel`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq")]
unsafe fn crba_avx512(w: &mut Passes, model: &Model, q: &[Lanes]) {
    crba_kernel(w, model, q)
}

fn joint(model: &Model, w: &Passes, i: usize) -> Joint {
    let kind = model.kind[i];
    Joint {
        k: kind.axis_index(),
        revolute: kind.is_revolute(),
        sc: w.sc[i],
    }
}

/// The motion-subspace component of body `i` (0–2 linear, 3–5 angular).
#[inline(always)]
fn subspace_index(model: &Model, i: usize) -> usize {
    let kind = model.kind[i];
    kind.axis_index() + if kind.is_revolute() { 3 } else { 0 }
}

/// Component `s` of a spatial vector (0–2 linear, 3–5 angular), by value through a
/// match (an indexed read compiles to a gather).
#[inline(always)]
fn entry(x: &S6, s: usize) -> Lanes {
    match s {
        0 => x.lin[0],
        1 => x.lin[1],
        2 => x.lin[2],
        3 => x.ang[0],
        4 => x.ang[1],
        _ => x.ang[2],
    }
}

/// The backward pass (see the module docs).
#[inline(always)]
fn crba_kernel(w: &mut Passes, model: &Model, q: &[Lanes]) {
    let (nb, n) = (model.nbodies(), model.nv);
    for i in 0..nb {
        let theta = affine(&q[model.q_index[i]], model.q_mult[i], model.q_offset[i]);
        w.sc[i] = if model.kind[i].is_revolute() {
            let (s, c) = sin_cos8(&theta);
            SinCos(s, c)
        } else {
            SinCos(theta, [0.0; LANES])
        };
        w.ic[i] = Composite::rigid(&model.inertia_o[i]);
    }
    for x in w.mass.iter_mut() {
        *x = [0.0; LANES];
    }
    for i in (0..nb).rev() {
        let (ki, mi) = (model.q_index[i], model.q_mult[i]);
        let mut f = w.ic[i].times_axis(model.kind[i].is_revolute(), model.kind[i].axis_index());
        let own = entry(&f, subspace_index(model, i));
        let d = &mut w.mass[ki * n + ki];
        for l in 0..LANES {
            d[l] += mi * mi * own[l];
        }
        let mut j = i;
        while model.parent[j] != WORLD {
            f = Placement::of(model, j).force(&joint(model, w, j).force(&f));
            j = model.parent[j];
            let (kj, mj) = (model.q_index[j], model.q_mult[j]);
            let x = entry(&f, subspace_index(model, j));
            let scale = if kj == ki { 2.0 * mi * mj } else { mi * mj };
            for (at, once) in [(ki * n + kj, true), (kj * n + ki, kj != ki)] {
                if once {
                    let e = &mut w.mass[at];
                    for l in 0..LANES {
                        e[l] += scale * x[l];
                    }
                }
            }
        }
        let parent = model.parent[i];
        if parent != WORLD {
            let mut ic = w.ic[i];
            let j = joint(model, w, i);
            if j.revolute {
                ic.rotate(|x| j.rotate(x, false));
            } else {
                let mut d = ZERO3;
                d[j.k] = j.sc.0;
                ic.shift(&d);
            }
            let p = Placement::of(model, i);
            if !p.identity {
                ic.rotate(|x| p.rot(x, false));
            }
            if !p.zero_trans {
                let t = p.pose.trans;
                ic.shift(&[[t.x; LANES], [t.y; LANES], [t.z; LANES]]);
            }
            ic.add_to(&mut w.ic[parent]);
        }
    }
    for k in 0..n {
        let ia = model.armature[k];
        if ia != 0.0 {
            let d = &mut w.mass[k * n + k];
            for l in 0..LANES {
                d[l] += ia;
            }
        }
    }
}

/// A rigid-body inertia per lane about the frame's origin: the mass (the same in every
/// lane), the first moment `h = m c` and `I_O` (symmetric: xx, yy, zz, xy, xz, yz).
#[derive(Clone, Copy)]
struct Composite {
    m: f64,
    h: V3,
    i: [Lanes; 6],
}

/// The `I_O` entry `(r, c)` in [`Composite::i`].
const SYM: [[usize; 3]; 3] = [[0, 3, 4], [3, 1, 5], [4, 5, 2]];

impl Composite {
    const ZERO: Composite = Composite {
        m: 0.0,
        h: ZERO3,
        i: [[0.0; LANES]; 6],
    };

    #[inline(always)]
    fn rigid(y: &InertiaO) -> Composite {
        let io = &y.i_o;
        let entries = [
            io[(0, 0)],
            io[(1, 1)],
            io[(2, 2)],
            io[(0, 1)],
            io[(0, 2)],
            io[(1, 2)],
        ];
        Composite {
            m: y.m,
            h: [[y.h.x; LANES], [y.h.y; LANES], [y.h.z; LANES]],
            i: entries.map(|x| [x; LANES]),
        }
    }

    /// `into += self`.
    #[inline(always)]
    fn add_to(&self, into: &mut Composite) {
        into.m += self.m;
        for r in 0..3 {
            for l in 0..LANES {
                into.h[r][l] += self.h[r][l];
            }
        }
        for e in 0..6 {
            for l in 0..LANES {
                into.i[e][l] += self.i[e][l];
            }
        }
    }

    /// `h ← R h`, `I_O ← R I_O Rᵀ` for the rotation `f(x) = R x`: `M = R I_O` column by
    /// column, then `(R Mᵀ)ᵀ = R I_O Rᵀ` row by row.
    #[inline(always)]
    fn rotate(&mut self, f: impl Fn(&V3) -> V3 + Copy) {
        self.h = f(&self.h);
        let col = |c: usize| -> V3 { [self.i[SYM[0][c]], self.i[SYM[1][c]], self.i[SYM[2][c]]] };
        let m = [f(&col(0)), f(&col(1)), f(&col(2))]; // m[c][r] = (R I)[r][c]
        let rows: [V3; 3] = std::array::from_fn(|r| f(&[m[0][r], m[1][r], m[2][r]]));
        // rows[r][a] = (R (R I)ᵀ)[a][r] = (R I Rᵀ)[r][a].
        for (r, c) in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)] {
            self.i[SYM[r][c]] = rows[r][c];
        }
    }

    /// The origin moves by `−t` (the old origin is at `t` in the new frame).
    #[inline(always)]
    fn shift(&mut self, t: &V3) {
        let m = self.m;
        let mut diag = [0.0; LANES];
        for l in 0..LANES {
            let th = (t[0][l] * self.h[0][l] + t[1][l] * self.h[1][l]) + t[2][l] * self.h[2][l];
            let tt = (t[0][l] * t[0][l] + t[1][l] * t[1][l]) + t[2][l] * t[2][l];
            diag[l] = 2.0 * th + m * tt;
        }
        for (r, c) in [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)] {
            let e = &mut self.i[SYM[r][c]];
            for l in 0..LANES {
                let (hr, hc, tr, tc) = (self.h[r][l], self.h[c][l], t[r][l], t[c][l]);
                e[l] -= (hr * tc + tr * hc) + m * tr * tc;
                if r == c {
                    e[l] += diag[l];
                }
            }
        }
        for r in 0..3 {
            for l in 0..LANES {
                self.h[r][l] += m * t[r][l];
            }
        }
    }

    /// `I S` for the unit motion about (revolute) or along axis `k`: `(e_k × h, I_O e_k)`,
    /// or `(m e_k, h × e_k)`.
    #[inline(always)]
    fn times_axis(&self, revolute: bool, k: usize) -> S6 {
        let mut e = ZERO3;
        e[k] = [1.0; LANES];
        let mut out = ZERO6;
        if revolute {
            out.lin = cross(&e, &self.h);
            out.ang = [self.i[SYM[0][k]], self.i[SYM[1][k]], self.i[SYM[2][k]]];
        } else {
            out.lin[k] = [self.m; LANES];
            out.ang = cross(&self.h, &e);
        }
        out
    }
}

/// `M(q)` for every row of the row-major `(n, nv)` array `q` into `mass` (`(n, nv, nv)`,
/// each matrix symmetric), eight rows at a time in SIMD lanes; a group of eight with a
/// joint value the lane `sin_cos` cannot take (`|q| > 1e4`, or not finite) and the last
/// `n mod 8` rows go through the scalar [`crate::dynamics::crba`]. Allocates nothing.
pub fn crba_rows(model: &Model, w: &mut CrbaLanes, q: &[f64], mass: &mut [f64]) {
    w.check(model);
    let (nv, nn) = (model.nv, model.nv * model.nv);
    let n = q.len().checked_div(nv).unwrap_or(0);
    assert!(
        q.len() == n * nv && mass.len() == n * nn,
        "q needs nv values and mass nv² values per row"
    );
    let scalar_row = |w: &mut CrbaLanes, mass: &mut [f64], r: usize| {
        let m = crate::dynamics::crba(model, &mut w.scalar, &q[r * nv..(r + 1) * nv]);
        mass[r * nn..(r + 1) * nn].copy_from_slice(m.as_slice());
    };
    let full = n / LANES * LANES;
    for r0 in (0..full).step_by(LANES) {
        gather(&q[r0 * nv..(r0 + LANES) * nv], nv, &mut w.q);
        if !lanes_in_range(&w.q) {
            for r in r0..r0 + LANES {
                scalar_row(w, mass, r);
            }
            continue;
        }
        w.passes.run(model, &w.q);
        let out = &mut mass[r0 * nn..(r0 + LANES) * nn];
        for (l, m) in out.chunks_exact_mut(nn).enumerate() {
            for (x, lanes) in m.iter_mut().zip(w.passes.mass.iter()) {
                *x = lanes[l];
            }
        }
    }
    for r in full..n {
        scalar_row(w, mass, r);
    }
}
