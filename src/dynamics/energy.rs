//! Kinetic and potential energy: `T = ½ Σ v_iᵀ I_i v_i` (body velocities, body inertias)
//! and `V = −Σ m_i gᵀ c_i` (world centres of mass).

use crate::data::Data;
use crate::kinematics::{forward_kinematics, forward_kinematics_vel};
use crate::model::Model;
use crate::spatial::Vec3;

/// Kinetic energy at `(q, q̇)`; updates placements and velocities in `data`.
pub fn kinetic_energy(model: &Model, data: &mut Data, q: &[f64], qd: &[f64]) -> f64 {
    forward_kinematics_vel(model, data, q, qd);
    (0..model.nbodies())
        .map(|i| {
            0.5 * model.inertia_o[i]
                .mul_motion(&data.v[i])
                .dot_motion(&data.v[i])
        })
        .sum()
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
