//! Lagrange's equations in the **energy form** `τ = M(q) q̈ + C(q, q̇) q̇ + g(q)`, with the
//! Coriolis matrix built from the Christoffel symbols of an analytic `∂M/∂q`
//! (Spong, Hutchinson & Vidyasagar, *Robot Modeling and Control*, §7.3; Murray, Li &
//! Sastry, *A Mathematical Introduction to Robotic Manipulation*, §4.3). Dense and
//! O(n⁴) for `∂M/∂q`: a reference and a source of `C(q, q̇)`, not a production path.
//!
//! - Kinetic energy `T = ½ q̇ᵀ M q̇`, `M(q) = Σ_j J_jᵀ Î_j J_j`: `J_j` is the 6 × nv world
//!   Jacobian of body `j` (column `q_index_m` collects `q_mult_m s_m` for every
//!   ancestor-or-self `m` of `j`, `s_m` = `data.s_world[m]`), `Î_j` the body's 6×6
//!   spatial inertia in world coordinates, (linear, angular) order.
//! - Derivatives with respect to the body coordinate `θ_k`, for `k` an ancestor-or-self of
//!   the body concerned (0 otherwise):
//!   `∂s_m/∂θ_k = s_k ×ₘ s_m` (zero for `k = m`), so `∂J_j/∂θ_k` has the columns
//!   `q_mult_m (s_k ×ₘ s_m)`; and `∂Î_j/∂θ_k = −ad_{s_k}ᵀ Î_j − Î_j ad_{s_k}` with
//!   `ad_s = [[ [ω]×, [v]× ], [0, [ω]×]]` the motion cross-product matrix
//!   (`ad_s (v', ω') = (ω × v' + v × ω', ω × ω')`). Then
//!   `∂M/∂θ_k = Σ_j (∂J_jᵀ Î_j J_j + J_jᵀ ∂Î_j J_j + J_jᵀ Î_j ∂J_j)` and, by the chain rule
//!   through `θ_k = q_mult_k q[q_index_k] + q_offset_k`,
//!   `∂M/∂q_c = Σ_{k: q_index_k = c} q_mult_k ∂M/∂θ_k`.
//! - Christoffel symbols `c_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)` and the
//!   Coriolis matrix `C_ij = Σ_k c_ijk q̇_k`; with this choice `Ṁ − 2C` is skew-symmetric.
//! - Gravity `g(q) = ∂V/∂q`, `V = −Σ_j m_j gᵀ p_j` (`p_j` the world centre of mass of body
//!   `j`): `∂p_j/∂θ_k = v_k + ω_k × p_j`, so `g_k = −Σ_{j ∈ subtree(k)} m_j gᵀ (v_k + ω_k × p_j)`
//!   at body level, projected like the torques (`g[q_index_k] += q_mult_k g_k`).

use crate::core::spatial::{skew, InertiaO, Motion, Vec3};
use crate::kinematics::compute_joint_jacobians;
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use nalgebra::{DMatrix, Matrix6};

/// `ad_s`, the 6×6 motion cross-product matrix of `s` in (linear, angular) order.
fn ad_matrix(s: &Motion) -> Matrix6<f64> {
    let mut out = Matrix6::zeros();
    let wx = skew(&s.w);
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&wx);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&skew(&s.v));
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&wx);
    out
}

/// Adds `scale · m` to column `c` of a 6 × nv matrix.
fn add_col(out: &mut DMatrix<f64>, c: usize, m: &Motion, scale: f64) {
    let a = m.to_array();
    for (r, x) in a.iter().enumerate() {
        out[(r, c)] += scale * x;
    }
}

/// Whether body `a` is an ancestor of (or is) body `j`.
fn is_ancestor_or_self(model: &Model, a: usize, mut j: usize) -> bool {
    while j != WORLD && j >= a {
        if j == a {
            return true;
        }
        j = model.parent[j];
    }
    false
}

/// World Jacobians `J_j` (6 × nv) and world spatial inertias `Î_j` of every body.
fn jacobians_and_inertias(model: &Model, data: &Data) -> (Vec<DMatrix<f64>>, Vec<Matrix6<f64>>) {
    let nb = model.nbodies();
    let mut jac = Vec::with_capacity(nb);
    let mut inertia = Vec::with_capacity(nb);
    for j in 0..nb {
        let mut jj = DMatrix::zeros(6, model.nv);
        let mut m = j;
        while m != WORLD {
            add_col(&mut jj, model.q_index[m], &data.s_world[m], model.q_mult[m]);
            m = model.parent[m];
        }
        jac.push(jj);
        inertia.push(
            InertiaO::from_inertia(&model.inertia[j])
                .transformed(&data.o_m_i[j])
                .to_matrix(),
        );
    }
    (jac, inertia)
}

/// Mass matrix `M(q) = Σ_j J_jᵀ Î_j J_j` (see the module docs). Allocates.
pub fn mass_matrix_energy(model: &Model, data: &mut Data, q: &[f64]) -> DMatrix<f64> {
    assert_eq!(q.len(), model.nv, "q needs nv values");
    compute_joint_jacobians(model, data, q);
    let (jac, inertia) = jacobians_and_inertias(model, data);
    let mut mass = DMatrix::zeros(model.nv, model.nv);
    for (jj, ii) in jac.iter().zip(&inertia) {
        mass += jj.transpose() * (ii * jj);
    }
    mass
}

/// `∂M/∂q_c` for every coordinate `c` (nv matrices of nv × nv), analytically
/// (see the module docs). Allocates. O(n⁴).
pub fn mass_matrix_derivatives(model: &Model, data: &mut Data, q: &[f64]) -> Vec<DMatrix<f64>> {
    assert_eq!(q.len(), model.nv, "q needs nv values");
    compute_joint_jacobians(model, data, q);
    let (jac, inertia) = jacobians_and_inertias(model, data);
    let nb = model.nbodies();
    let nv = model.nv;
    let mut out = vec![DMatrix::zeros(nv, nv); nv];
    let mut djac = DMatrix::zeros(6, nv);
    for k in 0..nb {
        let sk = data.s_world[k];
        let ad = ad_matrix(&sk);
        let mut dm = DMatrix::<f64>::zeros(nv, nv);
        for j in (k..nb).filter(|&j| is_ancestor_or_self(model, k, j)) {
            // ∂J_j/∂θ_k: columns q_mult_m (s_k ×ₘ s_m) for m in (k, j] on the path.
            djac.fill(0.0);
            let mut m = j;
            while m != k {
                let col = sk.cross_motion(&data.s_world[m]);
                add_col(&mut djac, model.q_index[m], &col, model.q_mult[m]);
                m = model.parent[m];
            }
            let ii = &inertia[j];
            let jj = &jac[j];
            let d_inertia = -(ad.transpose() * ii) - ii * ad;
            let x = djac.transpose() * (ii * jj);
            dm += &x + x.transpose() + jj.transpose() * (d_inertia * jj);
        }
        out[model.q_index[k]] += dm * model.q_mult[k];
    }
    out
}

/// Coriolis matrix `C(q, q̇)` from the Christoffel symbols of `∂M/∂q`:
/// `C_ij = Σ_k ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i) q̇_k`. Allocates. O(n⁴).
pub fn coriolis_matrix(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) -> DMatrix<f64> {
    assert_eq!(qd.len(), model.nv, "qd needs nv values");
    let dm = mass_matrix_derivatives(model, data, q);
    let nv = model.nv;
    DMatrix::from_fn(nv, nv, |i, j| {
        (0..nv)
            .map(|k| 0.5 * (dm[k][(i, j)] + dm[j][(i, k)] - dm[i][(j, k)]) * qd[k])
            .sum()
    })
}

/// Generalised gravity `g(q) = ∂V/∂q` from the potential energy (see the module docs).
/// Allocates. O(n²).
pub fn gravity_torque_energy(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    gravity: &Vec3,
) -> Vec<f64> {
    assert_eq!(q.len(), model.nv, "q needs nv values");
    compute_joint_jacobians(model, data, q);
    let mut g = vec![0.0; model.nv];
    for j in 0..model.nbodies() {
        let inertia = &model.inertia[j];
        let p = data.o_m_i[j].act_point(&inertia.com);
        let mut k = j;
        while k != WORLD {
            let s = &data.s_world[k];
            let dp = s.v + s.w.cross(&p);
            g[model.q_index[k]] -= model.q_mult[k] * inertia.mass * gravity.dot(&dp);
            k = model.parent[k];
        }
    }
    g
}

/// Inverse dynamics in the energy form `τ = M q̈ + C q̇ + g` (see the module docs).
/// Allocates. O(n⁴).
pub fn lagrange_energy(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    gravity: &Vec3,
) -> Vec<f64> {
    let nv = model.nv;
    assert_state_lengths(nv, q, qd, qdd);
    let mass = mass_matrix_energy(model, data, q);
    let c = coriolis_matrix(model, data, q, qd);
    let g = gravity_torque_energy(model, data, q, gravity);
    (0..nv)
        .map(|i| {
            (0..nv)
                .map(|j| mass[(i, j)] * qdd[j] + c[(i, j)] * qd[j])
                .sum::<f64>()
                + g[i]
        })
        .collect()
}

/// `q`, `q̇` and `q̈` must each have `nv` values.
pub(super) fn assert_state_lengths(nv: usize, q: &[f64], qd: &[f64], qdd: &[f64]) {
    assert!(
        q.len() == nv && qd.len() == nv && qdd.len() == nv,
        "q, qd, qdd need nv values"
    );
}
