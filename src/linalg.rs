//! Dense linear algebra the algorithms share without depending on each other: an
//! in-place Cholesky factorisation and solve (no allocation), used by forward dynamics
//! (`M q̈ = τ − h`) and by the damped least-squares IK. A leaf module.

use nalgebra::DMatrix;

/// Error when the mass matrix is not positive definite (e.g. a massless chain end).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the mass matrix is not positive definite (pivot {pivot} = {value:e}): a coordinate moves no mass")]
pub struct SingularMassMatrix {
    /// Index of the failing pivot.
    pub pivot: usize,
    /// Its value.
    pub value: f64,
}

/// In-place Cholesky: the lower triangle of `a` becomes `L` with `a = L Lᵀ`.
pub fn cholesky_in_place(a: &mut DMatrix<f64>) -> Result<(), SingularMassMatrix> {
    let n = a.nrows();
    for j in 0..n {
        let mut d = a[(j, j)];
        for k in 0..j {
            d -= a[(j, k)] * a[(j, k)];
        }
        if d.is_nan() || d <= 0.0 || !d.is_finite() {
            return Err(SingularMassMatrix { pivot: j, value: d });
        }
        let l = d.sqrt();
        a[(j, j)] = l;
        for i in j + 1..n {
            let mut s = a[(i, j)];
            for k in 0..j {
                s -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = s / l;
        }
    }
    Ok(())
}

/// Solves `L Lᵀ x = b` in place, `L` from [`cholesky_in_place`].
pub fn cholesky_solve_in_place(l: &DMatrix<f64>, b: &mut [f64]) {
    let n = l.nrows();
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[(i, k)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[(k, i)] * b[k];
        }
        b[i] = s / l[(i, i)];
    }
}
