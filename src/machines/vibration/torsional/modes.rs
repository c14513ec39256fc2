//! Undamped natural modes: the generalised symmetric eigenproblem `K x = p² J x`
//! (docs/reference_data.md §S3), solved as the standard symmetric problem
//! `(J^{-1/2} K J^{-1/2}) v = p² v`, `x = J^{-1/2} v` (J diagonal and positive), with
//! nalgebra's symmetric eigen-decomposition (Householder tridiagonalisation + implicit QR).
//!
//! A free–free chain has exactly one zero frequency (rigid-body rotation, `x = 1`):
//! eigenvalues with `|p²| ≤ 1e-10 · max p²` (rounding) are reported as 0. Shapes are
//! normalised to `max |x_k| = 1` with the first entry above `1e-9` in magnitude positive.

use crate::machines::vibration::torsional::torsional_chain::TorsionalChain;
use nalgebra::{DMatrix, SymmetricEigen};

/// `60 / 2π`: cycles per minute per rad/s.
pub const CPM_PER_RAD_S: f64 = 30.0 / std::f64::consts::PI;

/// One undamped natural mode.
#[derive(Clone, Debug, PartialEq)]
pub struct Mode {
    /// Natural circular frequency `p` (rad/s); 0 for the rigid-body mode.
    pub omega: f64,
    /// Mode shape (absolute disk angles), `max |x| = 1`.
    pub shape: Vec<f64>,
}

impl Mode {
    /// Frequency in cycles per minute (vibrations per minute).
    pub fn frequency_cpm(&self) -> f64 {
        self.omega * CPM_PER_RAD_S
    }

    /// Frequency in Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.omega / (2.0 * std::f64::consts::PI)
    }

    /// Whether this is the rigid-body (zero-frequency) mode.
    pub fn is_rigid_body(&self) -> bool {
        self.omega == 0.0
    }
}

/// Normalises `x` to `max |x| = 1`, first entry above `1e-9` positive.
pub(crate) fn normalise_real(x: &mut [f64]) {
    let m = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if m == 0.0 {
        return;
    }
    let first = x
        .iter()
        .copied()
        .find(|v| v.abs() > 1e-9 * m)
        .unwrap_or(1.0);
    let s = first.signum() / m;
    x.iter_mut().for_each(|v| *v *= s);
}

/// The symmetric matrix `J^{-1/2} K J^{-1/2}`.
pub fn symmetric_dynamic_matrix(chain: &TorsionalChain) -> DMatrix<f64> {
    let mut s = chain.stiffness_matrix();
    let n = chain.len();
    for i in 0..n {
        for j in 0..n {
            s[(i, j)] /= (chain.inertia[i] * chain.inertia[j]).sqrt();
        }
    }
    s
}

/// All `n` undamped modes, ascending in frequency (the rigid-body mode first).
pub fn undamped_modes(chain: &TorsionalChain) -> Vec<Mode> {
    let n = chain.len();
    let eig = SymmetricEigen::new(symmetric_dynamic_matrix(chain));
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let top = eig.eigenvalues.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    order
        .into_iter()
        .map(|r| {
            let p2 = eig.eigenvalues[r];
            let omega = if p2.abs() <= 1e-10 * top {
                0.0
            } else {
                p2.max(0.0).sqrt()
            };
            let mut shape: Vec<f64> = (0..n)
                .map(|k| eig.eigenvectors[(k, r)] / chain.inertia[k].sqrt())
                .collect();
            normalise_real(&mut shape);
            Mode { omega, shape }
        })
        .collect()
}
