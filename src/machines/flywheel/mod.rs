//! Flywheel sizing from the coefficient of speed fluctuation (Norton, *Design of
//! Machinery*, §11.11, eqs. 11.18–11.20; Shigley & Uicker ch. 16).
//!
//! Over one cycle of the input angle `φ`, the kinetic energy changes by the work of the
//! net torque, `E(φ) = ∫₀^φ (M_d − M_load) dφ` (trapezoidal rule on the samples). With
//! `ΔE = max E − min E`, the coefficient of speed fluctuation
//! `δ = (ω_max − ω_min) / ω_mean` (`ω_mean = (ω_max + ω_min)/2`) and
//! `½ J (ω_max² − ω_min²) = ΔE`, the inertia needed is
//!
//! ```text
//! J = ΔE / (δ ω_mean²).
//! ```
//!
//! When the load is not given, it is the constant that does the driving torque's work
//! over the cycle (`M_load = (1/Φ) ∫ M_d dφ`), i.e. a steady state.

pub mod design;
pub mod machine_motion;
use serde::Serialize;

/// The result of [`size`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Flywheel {
    /// `ΔE = max E − min E` (J).
    pub energy_fluctuation: f64,
    /// Input angle of the largest energy (rad).
    pub max_at: f64,
    /// Input angle of the smallest energy (rad).
    pub min_at: f64,
    /// Mean of the driving torque over the cycle (N m).
    pub mean_torque: f64,
    /// Net work over the cycle, `E(end)` (J): zero in a steady state.
    pub cycle_work: f64,
    /// Required moment of inertia `ΔE / (δ ω²)` (kg m²).
    pub inertia: f64,
}

/// `E(φ_k) = ∫ net dφ` by the trapezoidal rule.
pub fn energy_curve(phi: &[f64], net: &[f64]) -> Vec<f64> {
    let mut e = Vec::with_capacity(phi.len());
    let mut acc = 0.0;
    for k in 0..phi.len() {
        if k > 0 {
            acc += 0.5 * (net[k] + net[k - 1]) * (phi[k] - phi[k - 1]);
        }
        e.push(acc);
    }
    e
}

/// Sizes a flywheel for driving torque `drive(φ_k)` against `load` (constant; the cycle
/// mean of `drive` when `None`), mean speed `omega` and coefficient `delta`.
pub fn size(phi: &[f64], drive: &[f64], load: Option<f64>, omega: f64, delta: f64) -> Flywheel {
    let span = phi.last().copied().unwrap_or(0.0) - phi.first().copied().unwrap_or(0.0);
    let work = energy_curve(phi, drive).last().copied().unwrap_or(0.0);
    let mean = if span != 0.0 { work / span } else { 0.0 };
    let m_load = load.unwrap_or(mean);
    let net: Vec<f64> = drive.iter().map(|d| d - m_load).collect();
    let e = energy_curve(phi, &net);
    let (mut imax, mut imin) = (0, 0);
    for k in 0..e.len() {
        if e[k] > e[imax] {
            imax = k;
        }
        if e[k] < e[imin] {
            imin = k;
        }
    }
    let de = e.get(imax).copied().unwrap_or(0.0) - e.get(imin).copied().unwrap_or(0.0);
    Flywheel {
        energy_fluctuation: de,
        max_at: phi.get(imax).copied().unwrap_or(0.0),
        min_at: phi.get(imin).copied().unwrap_or(0.0),
        mean_torque: mean,
        cycle_work: e.last().copied().unwrap_or(0.0),
        inertia: de / (delta * omega * omega),
    }
}
