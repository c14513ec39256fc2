//! Modal balancing of a flexible rotor (textbook vol. 2, eqs. 16.52–16.56): correction
//! masses `X_i = m_i e_i` in given planes, all in one axial plane, such that
//!
//! - `Σ φ_k(x_i) X_i = −a_k A_k` for the mode `k` being corrected,
//! - `Σ φ_j(x_i) X_i = 0` for every other retained mode `j`,
//! - with the rigid-body conditions (N + 2 planes) `Σ X_i = 0`, `Σ x_i X_i = 0`.
//!
//! `a_k A_k` is unknown before trial runs; with `a_k A_k = 1` the result gives the ratios
//! of the masses. The modes come from [`crate::machines::vibration::rotor::fe_modes`], scaled to a
//! largest deflection of 1.

use crate::machines::vibration::rotor::RotorMode;
use nalgebra::{DMatrix, DVector};

/// Correction masses `X_i` (kg m) in `planes` for mode `target` (an index into `modes`),
/// keeping the modes `others` untouched; with `rigid`, also the force and moment
/// conditions. `None` when the number of planes does not match the conditions or the
/// system is singular (a plane at a node of a mode, or two planes at one place).
pub fn modal_balance(
    modes: &[RotorMode],
    planes: &[f64],
    target: usize,
    others: &[usize],
    rigid: bool,
    modal_unbalance: f64,
) -> Option<Vec<f64>> {
    let n = planes.len();
    let rows = 1 + others.len() + if rigid { 2 } else { 0 };
    if rows != n {
        return None;
    }
    let mut a = DMatrix::zeros(n, n);
    let mut b = DVector::zeros(n);
    for (i, &x) in planes.iter().enumerate() {
        a[(0, i)] = modes.get(target)?.at(x);
        for (r, &j) in others.iter().enumerate() {
            a[(1 + r, i)] = modes.get(j)?.at(x);
        }
        if rigid {
            a[(n - 2, i)] = 1.0;
            a[(n - 1, i)] = x;
        }
    }
    b[0] = -modal_unbalance;
    let lu = a.clone().lu();
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    if lu.determinant().abs() <= 1e-10 * scale.powi(n as i32) {
        return None;
    }
    lu.solve(&b).map(|x| x.iter().copied().collect())
}

/// The modal amplification `ω² / (ω_n² − ω²)` of an unbalance's `n`-th modal component
/// at speed `omega` (eq. 16.50).
pub fn modal_amplification(omega_n: f64, omega: f64) -> f64 {
    omega * omega / (omega_n * omega_n - omega * omega)
}
