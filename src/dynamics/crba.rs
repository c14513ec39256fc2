//! Composite-rigid-body algorithm for the joint-space mass matrix `M(q)` (RBDA Table 6.2,
//! body coordinates):
//!
//! - `I^c_i = I_i`; backward: `I^c_λ += λX_i^* I^c_i ⁱX_λ`;
//! - `F = I^c_i S_i`, `M_ii = S_iᵀ F`; walking up the ancestors `j`,
//!   `F = λX_j^* F`, `M_ij = M_ji = S_jᵀ F`.
//!
//! After the model's permutation push-up (see [`crate::model`]) most joint transforms are
//! `ᵖX_i = (R_k(θ), t)`: a rotation about one body axis and a translation. Those take a
//! structured path ([`AxisX`]): moving a force costs 14 multiplications instead of 24, and
//! moving a composite inertia about a third of the general cost. Composite inertias are in
//! origin form ([`InertiaO`]). Mimic joints: entries are scaled by both bodies'
//! multipliers and summed onto the independent coordinates (`Gᵀ M G`).

use super::rnea::project;
use crate::data::Data;
use crate::kinematics::{body_q, compute_joint_jacobians, joint_transform};
use crate::model::{BodyKind, Model, WORLD};
use crate::spatial::{column, unit, Force, InertiaO, Vec3};
use nalgebra::DMatrix;

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
    fn new(model: &Model, i: usize, theta: f64) -> Self {
        let kind = model.kind[i];
        let k = kind.axis_index();
        let t = model.placement[i].trans;
        if kind.is_revolute() {
            let (s, c) = crate::fastmath::sin_cos(theta);
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
    fn rot(&self, x: &Vec3) -> Vec3 {
        let (c, s) = (self.c, self.s);
        match self.k {
            0 => Vec3::new(x.x, c * x.y - s * x.z, s * x.y + c * x.z),
            1 => Vec3::new(c * x.x + s * x.z, x.y, c * x.z - s * x.x),
            _ => Vec3::new(c * x.x - s * x.y, s * x.x + c * x.y, x.z),
        }
    }

    /// `λX_i^* f`: `f' = R f`, `n' = R n + t × f'`.
    #[inline(always)]
    fn act_force(&self, f: &Force) -> Force {
        let ff = self.rot(&f.f);
        Force {
            f: ff,
            n: self.rot(&f.n) + self.t.cross(&ff),
        }
    }

    /// `R A Rᵀ` for a symmetric `A` (only rows and columns `i, j` mix), then the
    /// translation terms; see [`AxisX::act_inertia`].
    #[inline(always)]
    fn act_inertia_k<const I: usize, const J: usize, const K: usize>(
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
    fn act_inertia_add(&self, y: &InertiaO, out: &mut InertiaO) {
        match self.k {
            0 => self.act_inertia_k::<1, 2, 0>(y, out),
            1 => self.act_inertia_k::<2, 0, 1>(y, out),
            _ => self.act_inertia_k::<0, 1, 2>(y, out),
        }
    }
}

/// The force `I S` for a unit motion along the body's joint axis: for a rotation about
/// `e_k`, `(e_k × h, I_O e_k)`; for a translation, `(m e_k, h × e_k)`.
#[inline(always)]
fn inertia_times_axis(y: &InertiaO, kind: BodyKind) -> Force {
    let k = kind.axis_index();
    let e = unit(k, 1.0);
    if kind.is_revolute() {
        Force::new(e.cross(&y.h), column(&y.i_o, k))
    } else {
        Force::new(e * y.m, y.h.cross(&e))
    }
}

/// Mean body depth above which the ancestor walk runs in world coordinates.
pub const WORLD_WALK_DEPTH: f64 = 8.0;

/// Mass matrix into `data.mass` (full, symmetric), also returned.
pub fn crba<'a>(model: &Model, data: &'a mut Data, q: &[f64]) -> &'a DMatrix<f64> {
    crba_impl(model, data, q, None)
}

/// [`crba`] with an optional extra inertia (payload, body coordinates) on one body.
pub(crate) fn crba_impl<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    payload: Option<(usize, &InertiaO)>,
) -> &'a DMatrix<f64> {
    assert_eq!(q.len(), model.nv);
    let nb = model.nbodies();
    for i in 0..nb {
        let theta = body_q(model, q, i);
        if model.placement_identity[i] {
            data.axis_x[i] = AxisX::new(model, i, theta);
        } else {
            data.li_m_i[i] = joint_transform(&model.placement[i], model.kind[i], theta);
        }
        data.ic[i] = model.inertia_o[i];
    }
    if let Some((pb, ip)) = payload {
        data.ic[pb] = data.ic[pb].add(ip);
    }
    let world_walk = model.mean_depth > WORLD_WALK_DEPTH;
    if world_walk {
        compute_joint_jacobians(model, data, q);
    }
    let n = model.nv;
    let m = data.mass.as_mut_slice();
    m.iter_mut().for_each(|x| *x = 0.0);
    for i in (0..nb).rev() {
        let kind = model.kind[i];
        let ki = model.q_index[i];
        let mi = model.q_mult[i];
        let mut f = inertia_times_axis(&data.ic[i], kind);
        // Column ki, rows of the ancestors (the lower/upper halves are mirrored below).
        m[ki * n + ki] += mi * mi * project(kind, &f);
        if world_walk {
            let fw = data.o_m_i[i].act_force(&f);
            let mut j = model.parent[i];
            while j != WORLD {
                let kj = model.q_index[j];
                let val = mi * model.q_mult[j] * fw.dot_motion(&data.s_world[j]);
                if kj == ki {
                    m[ki * n + ki] += 2.0 * val;
                } else {
                    m[ki * n + kj] += val;
                }
                j = model.parent[j];
            }
        }
        let mut j = i;
        while !world_walk && model.parent[j] != WORLD {
            f = if model.placement_identity[j] {
                data.axis_x[j].act_force(&f)
            } else {
                data.li_m_i[j].act_force(&f)
            };
            j = model.parent[j];
            let kj = model.q_index[j];
            let val = mi * model.q_mult[j] * project(model.kind[j], &f);
            if kj == ki {
                m[ki * n + ki] += 2.0 * val;
            } else {
                m[ki * n + kj] += val;
            }
        }
        let parent = model.parent[i];
        if parent != WORLD {
            let child = data.ic[i];
            if model.placement_identity[i] {
                data.axis_x[i].act_inertia_add(&child, &mut data.ic[parent]);
            } else {
                let moved = child.transformed(&data.li_m_i[i]);
                data.ic[parent] = data.ic[parent].add(&moved);
            }
        }
    }
    // Entry (kj, ki) was accumulated in column ki; with mimic joints a pair can land on
    // either side of the diagonal, so symmetrise by summing both halves.
    for c in 0..n {
        for r in c + 1..n {
            let v = m[c * n + r] + m[r * n + c];
            m[c * n + r] = v;
            m[r * n + c] = v;
        }
    }
    &data.mass
}
