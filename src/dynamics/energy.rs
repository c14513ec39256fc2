//! Kinetic and potential energy: `T = ½ Σ v_iᵀ I_i v_i + ½ Σ I_a,k q̇_k²` (body velocities,
//! body inertias, the model's armature) and `V = −Σ m_i gᵀ c_i` (world centres of mass); and the
//! gradient `∂T/∂q` at fixed `q̇` (the force a symplectic integrator needs for a
//! configuration-dependent mass matrix); and both energies with the enabled effects
//! ([`energies_with`]: rotor armature and payload included).

use crate::core::spatial::{InertiaO, Vec3};
use crate::dynamics::effects::{mass_matrix, Effects};
use crate::dynamics::rnea::project;
use crate::kinematics::{forward_kinematics, forward_kinematics_vel, frame_placement};
use crate::model::data::Data;
use crate::model::{Model, WORLD};

/// Kinetic energy at `(q, q̇)`, `½ q̇ᵀ M(q) q̇`: the bodies' plus the armature's
/// `½ I_a,k q̇_k²`; updates placements and velocities in `data`.
pub fn kinetic_energy(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) -> f64 {
    forward_kinematics_vel(model, data, q, qd);
    let bodies: f64 = (0..model.nbodies())
        .map(|i| {
            0.5 * model.inertia_o[i]
                .mul_motion(&data.v[i])
                .dot_motion(&data.v[i])
        })
        .sum();
    let mut t = bodies;
    for (ia, v) in model.armature.iter().zip(qd) {
        if *ia != 0.0 {
            t += 0.5 * ia * v * v;
        }
    }
    t
}

/// Potential energy in gravity `g` at `q` (zero at the world origin); updates placements.
pub fn potential_energy(model: &Model, data: &mut Data, q: &[f64], gravity: &Vec3) -> f64 {
    forward_kinematics(model, data, q);
    (0..model.nbodies())
        .map(|i| {
            let b = &model.inertia[i];
            let c = data.o_m_i[i].act_point(&b.com);
            -b.mass * gravity.dot(&c)
        })
        .sum()
}

/// `∂T/∂q` at fixed `q̇` into `data.tau` (also returned), in O(n); overwrites the
/// placements, velocities and `data.f`.
///
/// Turning joint `i` by `dε` at fixed rates moves its subtree rigidly along the joint's
/// screw `S_i`, while the parent's velocity `v_λ` stays: seen from the subtree, only `v_λ`
/// changes, by `−dε S_i ×ₘ v_λ`, so `∂T/∂θ_i = h_iᵀ (v_λ ×ₘ S_i) = −S_iᵀ (v_i ×_f h_i)`,
/// with `h_i = Σ I_b v_b` the spatial momentum of the subtree (in frame `i`) and
/// `v_i = v_λ + S_i θ̇_i` (`S_i ×ₘ S_i = 0`). A body driven through `θ = m q_k + o` (mimic)
/// adds `m ∂T/∂θ_i` to coordinate `k`. With `C` the Christoffel Coriolis matrix,
/// `C(q, q̇) q̇ = Ṁ q̇ − ∂T/∂q`.
pub fn kinetic_energy_gradient<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    qd: &[f64],
) -> &'a [f64] {
    kinetic_energy_gradient_impl(model, data, q, qd, None)
}

/// [`kinetic_energy_gradient`] with an optional extra inertia (a payload, in body
/// coordinates) on one body.
pub(crate) fn kinetic_energy_gradient_impl<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    qd: &[f64],
    payload: Option<(usize, &InertiaO)>,
) -> &'a [f64] {
    forward_kinematics_vel(model, data, q, qd);
    let nb = model.nbodies();
    for i in 0..nb {
        let v = &data.v[i];
        let mut h = model.inertia_o[i].mul_motion(v);
        if let Some((pb, ip)) = payload {
            if pb == i {
                h = h.add(&ip.mul_motion(v));
            }
        }
        data.f[i] = h;
    }
    data.tau.fill(0.0);
    for i in (0..nb).rev() {
        let h = data.f[i];
        let dt = -project(model.kind[i], &data.v[i].cross_force(&h));
        data.tau[model.q_index[i]] += model.q_mult[i] * dt;
        let parent = model.parent[i];
        if parent != WORLD {
            let hp = data.li_m_i[i].act_force(&h);
            data.f[parent] = data.f[parent].add(&hp);
        }
    }
    &data.tau
}

/// Kinetic and potential energy with the enabled `effects`: `T = ½ q̇ᵀ M q̇` with the
/// effects' mass matrix (rotor armature, payload), and `V` of the bodies plus the
/// payload's `−m gᵀ c` (gravity from `effects`; none: `V = 0` from the bodies).
/// Returns `(T, V)`; uses `data.mass` and the placements.
pub fn energies_with(
    model: &Model,
    data: &mut Data,
    effects: &Effects,
    q: &[f64],
    qd: &[f64],
) -> (f64, f64) {
    let n = model.nv;
    let mass = mass_matrix(model, data, effects, q);
    let ke = 0.5
        * (0..n)
            .map(|i| (0..n).map(|j| qd[i] * mass[(i, j)] * qd[j]).sum::<f64>())
            .sum::<f64>();
    let g = effects.gravity.unwrap_or_else(Vec3::zeros);
    let mut pe = potential_energy(model, data, q, &g);
    if let Some(p) = &effects.payload {
        forward_kinematics(model, data, q);
        let c = frame_placement(model, data, p.link).act_point(&p.inertia.com);
        pe -= p.inertia.mass * g.dot(&c);
    }
    (ke, pe)
}
