//! Damped (complex) modes: the quadratic eigenproblem `(λ² J + λ B + K) x = 0`
//! (docs/reference_data.md §S3) through its 2n first-order (companion) form.
//!
//! - **Eigenvalues.** With `y = J^{1/2} φ` and the frequency scale `s` (the largest
//!   `sqrt(K_kk/J_k)`), the state `z = (s y, ẏ)` obeys `ż = A z` with
//!   `A = [[0, s I], [−S/s, −J^{-1/2} B J^{-1/2}]]`, `S = J^{-1/2} K J^{-1/2}`: the same
//!   eigenvalues as `[[0, I], [−J⁻¹K, −J⁻¹B]]`, but balanced (nalgebra's Schur does not
//!   balance). The eigenvalues come from nalgebra's real Schur form.
//! - **Shapes.** For each eigenvalue `λ` with `Im λ > 0` the null vector of the complex
//!   matrix `Q(λ) = λ² J + λ B + K` by inverse iteration with complex LU (shift
//!   `λ (1 + 1e-10)` so the factorisation stays regular), then one Newton step on the
//!   eigenvalue, `λ ← λ − xᵀQ(λ)x / xᵀQ′(λ)x` with `Q′ = 2λJ + B` (Q is complex
//!   symmetric, so `x` is also the left eigenvector), and one more inverse iteration.
//!   The shape is scaled so its largest component is exactly `1 + 0i`.
//! - Eigenvalues with `Im λ > 0` are reported (their conjugates carry no more
//!   information); real eigenvalues (the rigid-body 0, overdamped motions) separately.
//!   Eigenvalues below `1e-6 ×` the largest in magnitude are the rigid-body zero: a free
//!   chain without absolute damping has a defective double zero (Jordan block: rotation
//!   at constant speed), which the Schur form returns split by `~sqrt(ε)`; they are
//!   reported as real zeros.
//!   `ζ = −Re λ / |λ|`, damped frequency `Im λ`, undamped-equivalent frequency `|λ|`.
//!
//! The shapes are complex because the damping is not proportional (`B` is not a
//! combination of `J` and `K`): masses pass through zero at different instants, the phase
//! lags of the shape. The report's split into a "real" and an "imaginary" determinant is
//! not used (it is wrong for n > 1).

use crate::machines::vibration::torsional::modes::CPM_PER_RAD_S;
use crate::machines::vibration::torsional::torsional_chain::TorsionalChain;
use nalgebra::{Complex, DMatrix, DVector};

type C64 = Complex<f64>;

/// One damped mode (an eigenvalue with positive imaginary part).
#[derive(Clone, Debug, PartialEq)]
pub struct DampedMode {
    /// `λ = −ζ ω_0 + i ω_d` (1/s).
    pub eigenvalue: C64,
    /// Complex shape, largest component `1 + 0i`.
    pub shape: Vec<C64>,
    /// Backward error `‖Q(λ) x‖ / (‖x‖ (|λ|²‖J‖ + |λ|‖B‖ + ‖K‖))`.
    pub residual: f64,
}

impl DampedMode {
    /// Damping ratio `ζ = −Re λ / |λ|`.
    pub fn damping_ratio(&self) -> f64 {
        -self.eigenvalue.re / self.eigenvalue.norm()
    }

    /// Damped frequency `Im λ` in cycles/min.
    pub fn damped_frequency_cpm(&self) -> f64 {
        self.eigenvalue.im * CPM_PER_RAD_S
    }

    /// `|λ|` in cycles/min (the undamped-equivalent frequency).
    pub fn natural_frequency_cpm(&self) -> f64 {
        self.eigenvalue.norm() * CPM_PER_RAD_S
    }

    /// Phase of each shape component (degrees, in (−180, 180]).
    pub fn phase_deg(&self) -> Vec<f64> {
        self.shape.iter().map(|z| z.arg().to_degrees()).collect()
    }
}

/// All eigenvalues of the damped chain, split as described in the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct DampedModes {
    /// Oscillatory modes, ascending in `Im λ`.
    pub oscillatory: Vec<DampedMode>,
    /// Real eigenvalues (rigid-body, overdamped), descending (0 first).
    pub real_eigenvalues: Vec<f64>,
}

/// The balanced 2n state matrix `A` (see the module docs).
pub fn state_matrix(chain: &TorsionalChain) -> DMatrix<f64> {
    let n = chain.len();
    let sq: Vec<f64> = chain.inertia.iter().map(|j| j.sqrt()).collect();
    let k = chain.stiffness_matrix();
    let b = chain.damping_matrix();
    let s = (0..n)
        .map(|i| (k[(i, i)] / chain.inertia[i]).sqrt())
        .fold(0.0_f64, f64::max)
        .max(1.0);
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = s;
        for j in 0..n {
            a[(n + i, j)] = -k[(i, j)] / (sq[i] * sq[j] * s);
            a[(n + i, n + j)] = -b[(i, j)] / (sq[i] * sq[j]);
        }
    }
    a
}

/// `Q(λ) = λ² J + λ B + K`.
pub fn quadratic_matrix(chain: &TorsionalChain, lambda: C64) -> DMatrix<C64> {
    let k = chain.stiffness_matrix();
    let b = chain.damping_matrix();
    let n = chain.len();
    DMatrix::from_fn(n, n, |i, j| {
        let mut q = C64::from(k[(i, j)]) + lambda * b[(i, j)];
        if i == j {
            q += lambda * lambda * chain.inertia[i];
        }
        q
    })
}

fn inverse_iteration(chain: &TorsionalChain, shift: C64, x: &mut DVector<C64>, steps: usize) {
    let lu = quadratic_matrix(chain, shift).lu();
    for _ in 0..steps {
        if let Some(y) = lu.solve(x) {
            let nrm = y.norm();
            if nrm.is_finite() && nrm > 0.0 {
                *x = y.unscale(nrm);
            }
        }
    }
}

fn backward_error(chain: &TorsionalChain, lambda: C64, x: &DVector<C64>) -> f64 {
    let scale = lambda.norm_sqr() * chain.inertia_matrix().norm()
        + lambda.norm() * chain.damping_matrix().norm()
        + chain.stiffness_matrix().norm();
    (quadratic_matrix(chain, lambda) * x).norm() / (x.norm() * scale)
}

fn mode_for(chain: &TorsionalChain, lambda0: C64) -> DampedMode {
    let n = chain.len();
    let mut x = DVector::from_fn(n, |k, _| C64::new(1.0, 0.1 * k as f64 / n as f64));
    let mut lambda = lambda0;
    inverse_iteration(chain, lambda * (1.0 + 1e-10), &mut x, 3);
    // One Newton step on λ (two-sided Rayleigh functional for complex-symmetric Q).
    let q = quadratic_matrix(chain, lambda);
    let bm = chain.damping_matrix();
    let dq = DMatrix::from_fn(n, n, |i, j| {
        let mut v = C64::from(bm[(i, j)]);
        if i == j {
            v += lambda * (2.0 * chain.inertia[i]);
        }
        v
    });
    let num = x.transpose() * (&q * &x);
    let den = x.transpose() * (&dq * &x);
    if den[0].norm() > 0.0 {
        let cand = lambda - num[0] / den[0];
        if cand.re.is_finite() && cand.im.is_finite() {
            let before = backward_error(chain, lambda, &x);
            let mut xc = x.clone();
            inverse_iteration(chain, cand * (1.0 + 1e-12), &mut xc, 2);
            if backward_error(chain, cand, &xc) <= before {
                lambda = cand;
                x = xc;
            }
        }
    }
    let residual = backward_error(chain, lambda, &x);
    let big = (0..n)
        .max_by(|&a, &b| x[a].norm().total_cmp(&x[b].norm()))
        .unwrap_or(0);
    let pivot = x[big];
    let mut shape: Vec<C64> = x.iter().map(|v| v / pivot).collect();
    shape[big] = C64::new(1.0, 0.0);
    DampedMode {
        eigenvalue: lambda,
        shape,
        residual,
    }
}

/// Damped modes of the chain (see the module docs).
pub fn damped_modes(chain: &TorsionalChain) -> DampedModes {
    let ev = state_matrix(chain).complex_eigenvalues();
    let scale = ev.iter().fold(0.0_f64, |m, z| m.max(z.norm())).max(1e-300);
    let mut osc: Vec<C64> = Vec::new();
    let mut real: Vec<f64> = Vec::new();
    for z in ev.iter() {
        // A free chain without absolute damping has a defective double zero (rigid-body
        // rotation at constant speed); Schur returns it as a pair of size ~sqrt(ε)·scale.
        if z.norm() <= 1e-6 * scale {
            real.push(0.0);
        } else if z.im.abs() <= 1e-12 * scale {
            real.push(z.re);
        } else if z.im > 0.0 {
            osc.push(*z);
        }
    }
    osc.sort_by(|a, b| a.im.total_cmp(&b.im));
    real.sort_by(|a, b| b.total_cmp(a));
    DampedModes {
        oscillatory: osc.into_iter().map(|l| mode_for(chain, l)).collect(),
        real_eigenvalues: real,
    }
}
