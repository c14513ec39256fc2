//! The driving effort by the virtual-power method (Jourdain's principle; the "method of
//! virtual work" of the problem books): over the actual motion the constraint forces do
//! no work, so the power of the driving effort balances the power of every other force,
//! the d'Alembert inertia forces included:
//!
//! ```text
//! T_d ṡ + Σ_i [ (m_i g − m_i a_Gi) · v_Gi − J_i α_i ω_i ] + Σ F_P · v_P + Σ M ω = 0.
//! ```
//!
//! It uses only velocities and accelerations, never the joint forces, so it checks the
//! Lagrange-multiplier route of [`crate::machines::linkage::kinetostatics`] independently.

use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::kinetostatics::Loads;
use crate::machines::linkage::Vec2;
use nalgebra::DVector;

/// The power of all forces but the driver's, for the motion `(q, q̇, q̈)`.
pub fn power_of_loads_and_inertia(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    qdd: &DVector<f64>,
    loads: &Loads,
) -> f64 {
    let mut p = 0.0;
    for (i, k) in l.links.iter().enumerate() {
        let v = Vec2::new(qd[3 * i], qd[3 * i + 1]);
        let a = Vec2::new(qdd[3 * i], qdd[3 * i + 1]);
        p += (loads.gravity * k.mass - a * k.mass).dot(&v);
        p -= k.inertia * qdd[3 * i + 2] * qd[3 * i + 2];
    }
    for f in &loads.forces {
        p += f.force.dot(&l.point_velocity(q, qd, f.link, &f.p));
    }
    for &(k, t) in &loads.torques {
        p += t * qd[3 * k + 2];
    }
    p
}

/// The driving torque (or force) `T_d = −P / ṡ`; `None` when `ṡ = 0`.
pub fn driving_effort(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    qdd: &DVector<f64>,
    loads: &Loads,
    sd: f64,
) -> Option<f64> {
    (sd != 0.0).then(|| -power_of_loads_and_inertia(l, q, qd, qdd, loads) / sd)
}
