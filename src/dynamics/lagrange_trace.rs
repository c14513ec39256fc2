//! Lagrange's equations of the second kind in the textbook's **trace / pseudo-inertia
//! form** (the robot chapter of the source textbook, restated in
//! docs/reference_data.md §S1; the same form as Uicker's and Paul's 4×4-matrix dynamics).
//! It is O(n⁴): the slow, transparent reference the recursive algorithms are checked
//! against, not a production path.
//!
//! With `K_j = T_0j` the 4×4 world pose of body `j` and `θ_k` the coordinate of body `k`'s
//! joint:
//!
//! - pseudo-inertia of body `j` in its own frame,
//!   `Ĩ_j = ∫ r̃ r̃ᵀ dm = [[Σ, h], [hᵀ, m]]`, `r̃ = (r, 1)`, `h = m c`,
//!   `Σ = ∫ r rᵀ dm = ½ tr(I_O) 1 − I_O`, `I_O = I_c − m [c]×²` (inertia about the
//!   body origin);
//! - first derivatives `D_jk = ∂K_j/∂θ_k = Ŝ_k K_j` for `k` an ancestor-or-self of `j`
//!   (0 otherwise), where `Ŝ_k = [[ [ω]×, v ], [0, 0]]` is the se(3) matrix of the joint's
//!   world twist `s_k = (v, ω)`. This is the textbook's `K_{0,k−1} Q_k K_{k−1,j}` with the
//!   constant derivative operator `Q_k`, since `Ŝ_k = K_{0,k} Q_k K_{0,k}⁻¹`;
//! - second derivatives `D_jkm = ∂²K_j/∂θ_k∂θ_m = Ŝ_a Ŝ_b K_j` for `k`, `m` both
//!   ancestors-or-self of `j`, `a` the shallower and `b` the deeper of the two (`a = b`
//!   allowed): `Ŝ_b` depends on `θ_a` (through `∂Ŝ_b/∂θ_a = [Ŝ_a, Ŝ_b]`) but not conversely;
//! - with the kinetic energy `T = ½ Σ_j tr(K̇_j Ĩ_j K̇_jᵀ)` and the potential
//!   `V = −Σ_j m_j gᵀ K_j r_j` (`g = (g, 0)`, `r_j = (c_j, 1)` homogeneous),
//!   `d/dt ∂L/∂θ̇_i − ∂L/∂θ_i = τ_i` becomes
//!
//!   `τ_i = Σ_k B_ik θ̈_k + Σ_k Σ_m B_ikm θ̇_k θ̇_m + B_i`,
//!
//!   `B_ik = Σ_j tr(D_jk Ĩ_j D_jiᵀ)`, `B_ikm = Σ_j tr(D_jkm Ĩ_j D_jiᵀ)`,
//!   `B_i = −Σ_j m_j gᵀ D_ji r_j`,
//!
//!   the sums running over the bodies `j` in the subtrees of all the indices involved.
//!
//! Everything above is at body level. Mimic joints: body `i` moves with
//! `θ_i = q_mult_i q[q_index_i] + q_offset_i`, so `θ̇_i = q_mult_i q̇[q_index_i]`
//! (likewise `θ̈`) and the torques project as `τ[q_index_i] += q_mult_i τ_i`
//! (`M = Gᵀ B G` for the mass matrix).

use crate::core::spatial::{skew, Motion, Se3, Vec3};
use crate::dynamics::lagrange_energy::assert_state_lengths;
use crate::kinematics::{body_rate, compute_joint_jacobians};
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use nalgebra::{DMatrix, Matrix4, Vector4};

/// `[[ [ω]×, v ], [0, 0]]`: the 4×4 se(3) matrix of a twist `(v, ω)`.
fn twist_hat(s: &Motion) -> Matrix4<f64> {
    let mut out = Matrix4::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&skew(&s.w));
    out.fixed_view_mut::<3, 1>(0, 3).copy_from(&s.v);
    out
}

/// The 4×4 homogeneous matrix of a pose.
fn homogeneous(t: &Se3) -> Matrix4<f64> {
    let mut out = Matrix4::identity();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&t.rot);
    out.fixed_view_mut::<3, 1>(0, 3).copy_from(&t.trans);
    out
}

/// Pseudo-inertia `Ĩ = [[Σ, h], [hᵀ, m]]` of body `j` in its own frame.
fn pseudo_inertia(model: &Model, j: usize) -> Matrix4<f64> {
    let i = &model.inertia[j];
    let cx = skew(&i.com);
    let i_o = i.inertia_com - cx * cx * i.mass;
    let sigma = crate::core::spatial::Mat3::identity() * (0.5 * i_o.trace()) - i_o;
    let h = i.com * i.mass;
    let mut out = Matrix4::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&sigma);
    out.fixed_view_mut::<3, 1>(0, 3).copy_from(&h);
    out.fixed_view_mut::<1, 3>(3, 0).copy_from(&h.transpose());
    out[(3, 3)] = i.mass;
    out
}

/// `tr(A B)` without forming the product.
#[inline]
fn trace_of_product(a: &Matrix4<f64>, b: &Matrix4<f64>) -> f64 {
    let mut s = 0.0;
    for r in 0..4 {
        for c in 0..4 {
            s += a[(r, c)] * b[(c, r)];
        }
    }
    s
}

/// The body-level coefficients of the trace form at one configuration.
struct TraceTerms {
    /// Number of bodies.
    nb: usize,
    /// `B_ik`, nb × nb.
    b2: DMatrix<f64>,
    /// `B_ikm` at `[(i * nb + k) * nb + m]` (empty when not requested).
    b3: Vec<f64>,
    /// `B_i` (empty when not requested).
    b1: Vec<f64>,
}

impl TraceTerms {
    /// Computes `B_ik`, and `B_ikm`, `B_i` when `full` (gravity `gravity`).
    fn compute(model: &Model, data: &mut Data, q: &[f64], full: bool, gravity: &Vec3) -> Self {
        compute_joint_jacobians(model, data, q);
        let nb = model.nbodies();
        let s_hat: Vec<Matrix4<f64>> = data.s_world.iter().map(twist_hat).collect();
        let g = Vector4::new(gravity.x, gravity.y, gravity.z, 0.0);
        let mut terms = TraceTerms {
            nb,
            b2: DMatrix::zeros(nb, nb),
            b3: if full {
                vec![0.0; nb * nb * nb]
            } else {
                Vec::new()
            },
            b1: if full { vec![0.0; nb] } else { Vec::new() },
        };
        // Per body j: its ancestors-or-self (root first), D_jk and Ĩ_j D_jkᵀ for them.
        let mut path: Vec<usize> = Vec::with_capacity(nb);
        let mut d: Vec<Matrix4<f64>> = Vec::with_capacity(nb);
        let mut e: Vec<Matrix4<f64>> = Vec::with_capacity(nb);
        for j in 0..nb {
            path.clear();
            let mut a = j;
            while a != WORLD {
                path.push(a);
                a = model.parent[a];
            }
            path.reverse();
            let k_j = homogeneous(&data.o_m_i[j]);
            let pi_j = pseudo_inertia(model, j);
            d.clear();
            e.clear();
            for &k in &path {
                let d_jk = s_hat[k] * k_j;
                e.push(pi_j * d_jk.transpose());
                d.push(d_jk);
            }
            // B_ik += tr(D_jk Ĩ_j D_jiᵀ).
            for (ia, &i) in path.iter().enumerate() {
                for (ka, &k) in path.iter().enumerate() {
                    terms.b2[(i, k)] += trace_of_product(&d[ka], &e[ia]);
                }
            }
            if !full {
                continue;
            }
            // B_ikm += tr(D_jkm Ĩ_j D_jiᵀ), D_jkm = Ŝ_a Ŝ_b K_j = Ŝ_a D_jb (a shallower).
            for (ka, &k) in path.iter().enumerate() {
                for (ma, &m) in path.iter().enumerate() {
                    let d_jkm = if ka <= ma {
                        s_hat[k] * d[ma]
                    } else {
                        s_hat[m] * d[ka]
                    };
                    for (ia, &i) in path.iter().enumerate() {
                        terms.b3[(i * nb + k) * nb + m] += trace_of_product(&d_jkm, &e[ia]);
                    }
                }
            }
            // B_i += −m_j gᵀ D_ji r_j.
            let inertia = &model.inertia[j];
            let r_j = Vector4::new(inertia.com.x, inertia.com.y, inertia.com.z, 1.0);
            for (ia, &i) in path.iter().enumerate() {
                terms.b1[i] -= inertia.mass * g.dot(&(d[ia] * r_j));
            }
        }
        terms
    }
}

/// Inverse dynamics `τ(q, q̇, q̈)` by the trace / pseudo-inertia form of Lagrange's
/// equations (see the module docs): `τ_i = Σ_k B_ik θ̈_k + Σ_k Σ_m B_ikm θ̇_k θ̇_m + B_i`,
/// projected onto the coordinates. `gravity` is the world gravity vector. Uses
/// `data.o_m_i` and `data.s_world` as scratch; allocates. O(n⁴).
pub fn lagrange_trace(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: &Vec3,
) -> Vec<f64> {
    let nv = model.nv;
    assert_state_lengths(nv, q, qd, qdd);
    let t = TraceTerms::compute(model, data, q, true, gravity);
    let nb = t.nb;
    let rate: Vec<f64> = (0..nb).map(|i| body_rate(model, qd, i)).collect();
    let acc: Vec<f64> = (0..nb).map(|i| body_rate(model, qdd, i)).collect();
    let mut tau = vec![0.0; nv];
    for i in 0..nb {
        let mut tau_i = t.b1[i];
        for k in 0..nb {
            tau_i += t.b2[(i, k)] * acc[k];
            for m in 0..nb {
                tau_i += t.b3[(i * nb + k) * nb + m] * rate[k] * rate[m];
            }
        }
        tau[model.q_index[i]] += model.q_mult[i] * tau_i;
    }
    tau
}

/// Joint-space mass matrix from the trace form: `M = Gᵀ B G` with
/// `B_ik = Σ_j tr(D_jk Ĩ_j D_jiᵀ)` (see the module docs). Allocates. O(n³).
pub fn mass_matrix_trace(model: &Model, data: &mut Data, q: &[f64]) -> DMatrix<f64> {
    assert_eq!(q.len(), model.nv, "q needs nv values");
    let t = TraceTerms::compute(model, data, q, false, &Vec3::zeros());
    let mut mass = DMatrix::zeros(model.nv, model.nv);
    for i in 0..t.nb {
        for k in 0..t.nb {
            mass[(model.q_index[i], model.q_index[k])] +=
                model.q_mult[i] * model.q_mult[k] * t.b2[(i, k)];
        }
    }
    mass
}
