//! Rutishauser's LR eigen-iteration on the tridiagonal matrix of the chain
//! (docs/reference_data.md §S3, textbook extras): a second route to `p²`, independent of
//! nalgebra's symmetric QR.
//!
//! `S = J^{-1/2} K J^{-1/2}` is symmetric tridiagonal (diagonal `d_k = (c_{k−1}+c_k)/J_k`,
//! off-diagonal `e_k = −c_k / sqrt(J_k J_{k+1})`). It is similar to the Jacobi form with
//! unit super-diagonal and sub-diagonal `f_k = e_k²`. One LR step factors `A = L R`
//! without pivoting (`L` unit lower bidiagonal with `l_k`, `R` upper bidiagonal with
//! diagonal `r_k` and unit super-diagonal):
//! `r_0 = d_0`, `l_k = f_k / r_k`, `r_{k+1} = d_{k+1} − l_k`,
//! and forms `A′ = R L`: `d′_k = r_k + l_k`, `d′_{n−1} = r_{n−1}`, `f′_k = r_{k+1} l_k`.
//! Unshifted LR on a positive (semi)definite matrix is stable (the pivots are ratios of
//! leading minors) and drives the diagonal to the eigenvalues in descending order, the
//! sub-diagonal to zero at the rate `λ_{k+1}/λ_k`; the bottom eigenvalue is deflated when
//! `sqrt|f| ≤ 1e-15 (|d_{n−2}| + |d_{n−1}|)`.

use crate::machines::vibration::torsional::torsional_chain::TorsionalChain;

/// The LR iteration did not converge.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("LR iteration: no convergence or a zero pivot after {iterations} steps ({remaining} eigenvalues left)")]
pub struct LrError {
    /// Steps taken.
    pub iterations: usize,
    /// Eigenvalues not yet deflated.
    pub remaining: usize,
}

/// Eigenvalues `p²` of the chain by the LR iteration, ascending.
pub fn lr_eigenvalues(chain: &TorsionalChain, max_iter: usize) -> Result<Vec<f64>, LrError> {
    let n = chain.len();
    let j = &chain.inertia;
    let c = &chain.stiffness;
    let mut d: Vec<f64> = (0..n)
        .map(|k| {
            let left = if k > 0 { c[k - 1] } else { 0.0 };
            let right = if k + 1 < n { c[k] } else { 0.0 };
            (left + right) / j[k]
        })
        .collect();
    let mut f: Vec<f64> = (0..n.saturating_sub(1))
        .map(|k| c[k] * c[k] / (j[k] * j[k + 1]))
        .collect();
    let mut out = Vec::with_capacity(n);
    let mut m = n;
    let mut iter = 0;
    while m > 0 {
        if m == 1 {
            out.push(d[0]);
            break;
        }
        if f[m - 2].abs().sqrt() <= 1e-15 * (d[m - 2].abs() + d[m - 1].abs()) {
            out.push(d[m - 1]);
            m -= 1;
            continue;
        }
        if iter >= max_iter {
            return Err(LrError {
                iterations: iter,
                remaining: m,
            });
        }
        iter += 1;
        // A = L R on the active block 0..m, then A' = R L.
        let mut r = d[0];
        for k in 0..m - 1 {
            // A decoupled block (f = 0, e.g. a shaft of zero stiffness) may end in a zero
            // pivot; a zero pivot with f ≠ 0 is a breakdown.
            let l = if f[k] == 0.0 { 0.0 } else { f[k] / r };
            if !l.is_finite() {
                return Err(LrError {
                    iterations: iter,
                    remaining: m,
                });
            }
            let r_next = d[k + 1] - l;
            d[k] = r + l;
            f[k] = r_next * l;
            r = r_next;
        }
        d[m - 1] = r;
    }
    out.sort_by(f64::total_cmp);
    Ok(out)
}
