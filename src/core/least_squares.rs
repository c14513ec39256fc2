//! The one linear solve the mechanism code uses: the minimum-norm least-squares solution
//! of `A x = b` by the singular value decomposition (Golub & Van Loan, *Matrix
//! Computations*, 4th ed., §5.5: `x = V Σ⁺ Uᵀ b`), optionally the solution nearest to a
//! reference `x_ref` (`x = x_ref + A⁺ (b − A x_ref)`). Singular values below
//! `RANK_TOL · σ_max` count as zero, so a rank-deficient `A` (a dead centre, a change
//! point, redundant constraints) still gives an answer, with its rank and the residual
//! `‖A x − b‖` saying whether `b` was consistent.

use nalgebra::{DMatrix, DVector};

/// Relative threshold below which a singular value counts as zero.
pub const RANK_TOL: f64 = 1e-10;

/// The result of [`min_norm_solve`].
#[derive(Clone, Debug)]
pub struct MinNormSolve {
    /// The solution.
    pub x: DVector<f64>,
    /// Numerical rank of `A`.
    pub rank: usize,
    /// `‖A x − b‖∞`: zero (to rounding) when `b` is in the range of `A`.
    pub residual: f64,
    /// Largest singular value.
    pub sigma_max: f64,
    /// Smallest singular value (of the `min(m, n)`).
    pub sigma_min: f64,
}

/// Singular values of `a`, largest first.
pub fn singular_values(a: &DMatrix<f64>) -> Vec<f64> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return Vec::new();
    }
    let mut s: Vec<f64> = a
        .clone()
        .svd(false, false)
        .singular_values
        .iter()
        .copied()
        .collect();
    s.sort_by(|x, y| y.total_cmp(x));
    s
}

/// Numerical rank of `a` (singular values above `RANK_TOL · σ_max`).
pub fn rank(a: &DMatrix<f64>) -> usize {
    let s = singular_values(a);
    let tol = s.first().copied().unwrap_or(0.0) * RANK_TOL;
    s.iter().filter(|&&x| x > tol).count()
}

/// The SVD of a matrix, kept to solve several right sides with it.
pub struct Factorization {
    svd: nalgebra::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>,
    /// Singular values, largest first.
    pub singular_values: Vec<f64>,
}

impl Factorization {
    /// Factorizes `a`.
    pub fn new(a: &DMatrix<f64>) -> Self {
        let svd = a.clone().svd(true, true);
        let mut sv: Vec<f64> = svd.singular_values.iter().copied().collect();
        sv.sort_by(|x, y| y.total_cmp(x));
        Self {
            svd,
            singular_values: sv,
        }
    }

    /// Minimum-norm least-squares solution of `a x = b` (`a` the factorized matrix), or
    /// with `reference`, the solution nearest to it.
    pub fn solve(
        &self,
        a: &DMatrix<f64>,
        b: &DVector<f64>,
        reference: Option<&DVector<f64>>,
    ) -> MinNormSolve {
        let rhs = match reference {
            Some(r) => b - a * r,
            None => b.clone(),
        };
        let sv = &self.svd.singular_values;
        let smax = self.singular_values.first().copied().unwrap_or(0.0);
        let smin = self.singular_values.last().copied().unwrap_or(0.0);
        let tol = smax * RANK_TOL;
        let u = self.svd.u.as_ref().expect("u requested");
        let vt = self.svd.v_t.as_ref().expect("v_t requested");
        let mut x = DVector::zeros(a.ncols());
        let mut r = 0;
        for (k, &s) in sv.iter().enumerate() {
            if s > tol && s > 0.0 {
                r += 1;
                let c = u.column(k).dot(&rhs) / s;
                x += vt.row(k).transpose() * c;
            }
        }
        if let Some(r0) = reference {
            x += r0;
        }
        let residual = (a * &x - b).amax();
        MinNormSolve {
            x,
            rank: r,
            residual,
            sigma_max: smax,
            sigma_min: smin,
        }
    }
}

/// Minimum-norm least-squares solution of `a x = b`, or with `reference`, the solution
/// nearest to it.
pub fn min_norm_solve(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    reference: Option<&DVector<f64>>,
) -> MinNormSolve {
    Factorization::new(a).solve(a, b, reference)
}

#[cfg(test)]
mod tests {
    use crate::core::least_squares::*;

    #[test]
    fn min_norm_of_a_rank_one_system_and_the_nearest_to_a_reference() {
        // x + y = 2: minimum norm (1, 1); nearest to (3, 0) is (2.5, -0.5).
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 2.0, 2.0]);
        let b = DVector::from_vec(vec![2.0, 4.0]);
        let s = min_norm_solve(&a, &b, None);
        assert_eq!(s.rank, 1);
        assert!((s.x[0] - 1.0).abs() < 1e-14 && (s.x[1] - 1.0).abs() < 1e-14);
        assert!(s.residual < 1e-14);
        let r = DVector::from_vec(vec![3.0, 0.0]);
        let s = min_norm_solve(&a, &b, Some(&r));
        assert!((s.x[0] - 2.5).abs() < 1e-14 && (s.x[1] + 0.5).abs() < 1e-14);
        // Inconsistent right side: the residual says so.
        let b = DVector::from_vec(vec![2.0, 5.0]);
        assert!(min_norm_solve(&a, &b, None).residual > 0.1);
    }
}
