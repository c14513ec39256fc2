//! The reduced (equivalent) moment of inertia and the reduced moment of a linkage on its
//! input (problem book ch. 4): the one-degree-of-freedom model `J_red(φ)`, `M_red(φ)` whose
//! kinetic energy and power equal the linkage's,
//!
//! ```text
//! J_red(φ) = Σ_i [ m_i (v_Si/ω)² + J_Si (ω_i/ω)² ] = q'ᵀ M q',
//! M_red(φ) = Σ F·v_P/ω + Σ M_k ω_k/ω = Qᵀ q',
//! dJ_red/dφ = 2 q'ᵀ M q'',
//! ```
//!
//! with `q' = dq/dφ` the path derivatives of the sweep (so `v/ω` is a derivative with
//! respect to the input; for a slide driver `J_red` is a reduced mass and `M_red` a
//! reduced force). `Q` holds gravity and the applied loads. The driving effort of the
//! kinetostatics is then `T = J_red φ̈ + ½ (dJ_red/dφ) φ̇² − M_red` (Lagrange's equation
//! of the reduced model; `tests/mechanism.rs` checks it against the joint-force route).

use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::kinetostatics::{applied_forces, mass_diagonal, Loads};
use nalgebra::DVector;

/// `(J_red, dJ_red/ds)` from the path derivatives `q'`, `q''`.
pub fn reduced_inertia(l: &Linkage, dq: &DVector<f64>, ddq: &DVector<f64>) -> (f64, f64) {
    let m = mass_diagonal(l);
    let j = dq.iter().zip(m.iter()).map(|(v, m)| m * v * v).sum();
    let dj = 2.0
        * dq.iter()
            .zip(ddq.iter())
            .zip(m.iter())
            .map(|((v, a), m)| m * v * a)
            .sum::<f64>();
    (j, dj)
}

/// `M_red = Qᵀ q'` at coordinates `q` with path derivatives `q'`.
pub fn reduced_moment(l: &Linkage, q: &DVector<f64>, dq: &DVector<f64>, loads: &Loads) -> f64 {
    applied_forces(l, q, loads).dot(dq)
}

/// The driving effort of the reduced model, `T = J_red s̈ + ½ J'_red ṡ² − M_red`.
pub fn driving_from_reduced(j: f64, dj: f64, m_red: f64, sd: f64, sdd: f64) -> f64 {
    j * sdd + 0.5 * dj * sd * sd - m_red
}
