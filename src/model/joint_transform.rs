//! The structured joint transform `(R_k(θ), t)` the mass-matrix algorithm
//! ([`crate::dynamics::crba`]) caches in [`crate::model::data::Data`]: a rotation about one body
//! axis and a translation, which moves forces and inertias at a fraction of the general
//! cost. It lives with the model (it reads only the body kinds and placements) so that
//! `Data` does not depend on the dynamics module.

use crate::core::spatial::{unit, Force, InertiaO, Vec3};
use crate::model::compiled::Model;

/// A joint transform `(R_k(θ), t)` with `R_k` a rotation about body axis `k` (`c = cos θ`,
/// `s = sin θ`; a prismatic joint is `c = 1, s = 0` with `t` shifted along the axis).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct AxisX {
    k: usize,
    c: f64,
    s: f64,
    t: Vec3,
}

impl AxisX {
    /// The transform of body `i` at coordinate `theta` (placement rotation = identity).
    #[inline(always)]
    pub(crate) fn new(model: &Model, i: usize, theta: f64) -> Self {
        let kind = model.kind[i];
        let k = kind.axis_index();
        let t = model.placement[i].trans;
        if kind.is_revolute() {
            let (s, c) = crate::core::fastmath::sin_cos(theta);
            AxisX { k, c, s, t }
        } else {
            AxisX {
                k,
                c: 1.0,
                s: 0.0,
                t: t + unit(k, theta),
            }
        }
    }

    /// `R x`.
    #[inline(always)]
    pub(crate) fn rot(&self, x: &Vec3) -> Vec3 {
        let (c, s) = (self.c, self.s);
        match self.k {
            0 => Vec3::new(x.x, c * x.y - s * x.z, s * x.y + c * x.z),
            1 => Vec3::new(c * x.x + s * x.z, x.y, c * x.z - s * x.x),
            _ => Vec3::new(c * x.x - s * x.y, s * x.x + c * x.y, x.z),
        }
    }

    /// `λX_i^* f`: `f' = R f`, `n' = R n + t × f'`.
    #[inline(always)]
    pub(crate) fn act_force(&self, f: &Force) -> Force {
        let ff = self.rot(&f.f);
        Force {
            f: ff,
            n: self.rot(&f.n) + self.t.cross(&ff),
        }
    }

    /// `R A Rᵀ` for a symmetric `A` (only rows and columns `i, j` mix), then the
    /// translation terms; see [`AxisX::act_inertia`].
    #[inline(always)]
    pub(crate) fn act_inertia_k<const I: usize, const J: usize, const K: usize>(
        &self,
        y: &InertiaO,
        out: &mut InertiaO,
    ) {
        let (c, s) = (self.c, self.s);
        let a = &y.i_o;
        let (aii, ajj, akk) = (a[(I, I)], a[(J, J)], a[(K, K)]);
        let (aij, aik, ajk) = (a[(I, J)], a[(I, K)], a[(J, K)]);
        let (cc, ss, cs) = (c * c, s * s, c * s);
        // Rotated entries, indexed by (I, J, K).
        let r_ii = cc * aii - 2.0 * cs * aij + ss * ajj;
        let r_jj = ss * aii + 2.0 * cs * aij + cc * ajj;
        let r_ij = cs * (aii - ajj) + (cc - ss) * aij;
        let r_ik = c * aik - s * ajk;
        let r_jk = s * aik + c * ajk;
        let r_kk = akk;
        // Map back to (x, y, z) positions.
        let mut d = [0.0; 3];
        let mut o = [[0.0; 3]; 3];
        d[I] = r_ii;
        d[J] = r_jj;
        d[K] = r_kk;
        o[I][J] = r_ij;
        o[I][K] = r_ik;
        o[J][K] = r_jk;
        let (xy, xz, yz) = (o[0][1] + o[1][0], o[0][2] + o[2][0], o[1][2] + o[2][1]);
        let h = self.rot(&y.h);
        let p = self.t;
        let m = y.m;
        let diag = 2.0 * h.dot(&p) + m * p.norm_squared();
        let e = |r: usize, q: usize| -(h[r] * p[q] + p[r] * h[q]) - m * p[r] * p[q];
        let (xx, yy, zz) = (
            d[0] + e(0, 0) + diag,
            d[1] + e(1, 1) + diag,
            d[2] + e(2, 2) + diag,
        );
        let (xy, xz, yz) = (xy + e(0, 1), xz + e(0, 2), yz + e(1, 2));
        // Accumulate straight into the parent (a temporary read back as vectors would
        // stall on store forwarding).
        out.m += m;
        out.h += h + p * m;
        let o = &mut out.i_o;
        o[(0, 0)] += xx;
        o[(1, 1)] += yy;
        o[(2, 2)] += zz;
        o[(0, 1)] += xy;
        o[(1, 0)] += xy;
        o[(0, 2)] += xz;
        o[(2, 0)] += xz;
        o[(1, 2)] += yz;
        o[(2, 1)] += yz;
    }

    /// Adds the inertia moved to the parent frame to `out`: `h' = R h + m t`,
    /// `I' = R I Rᵀ − ([Rh]×[t]× + [t]×[Rh]×) − m [t]×²`, with
    /// `[a]×[b]× = b aᵀ − (a·b) 1`.
    #[inline(always)]
    pub(crate) fn act_inertia_add(&self, y: &InertiaO, out: &mut InertiaO) {
        match self.k {
            0 => self.act_inertia_k::<1, 2, 0>(y, out),
            1 => self.act_inertia_k::<2, 0, 1>(y, out),
            _ => self.act_inertia_k::<0, 1, 2>(y, out),
        }
    }
}
