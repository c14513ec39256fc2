//! Dense linear algebra the algorithms share without depending on each other: an
//! in-place Cholesky factorisation and solve (no allocation), used by forward dynamics
//! (`M q̈ = τ − h`) and by the damped least-squares IK. A leaf module.

use nalgebra::DMatrix;

/// Error when the mass matrix is not positive definite (e.g. a massless chain end), or
/// forward dynamics gives a non-finite `q̈`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", self.describe())]
pub struct SingularMassMatrix {
    /// Index of the failing pivot (the coordinate).
    pub pivot: usize,
    /// Its value (0 for a non-finite `q̈`).
    pub value: f64,
    /// The coordinate's joint name, where the caller knows the model (else empty).
    pub joint: String,
    /// The inputs (`τ`, `q̇`, `q`) were not finite, or the accelerations overflowed
    /// with a positive definite mass matrix: the mass is not the cause.
    pub inputs_overflow: bool,
}

impl SingularMassMatrix {
    /// The error at `pivot` with `value`, no joint name yet.
    pub fn at(pivot: usize, value: f64) -> Self {
        Self {
            pivot,
            value,
            joint: String::new(),
            inputs_overflow: false,
        }
    }

    fn describe(&self) -> String {
        let at = if self.joint.is_empty() {
            format!("coordinate {}", self.pivot)
        } else {
            format!("coordinate {} (joint '{}')", self.pivot, self.joint)
        };
        if self.inputs_overflow {
            format!(
                "the acceleration of {at} is not finite: the torques or velocities overflow \
                 floating-point arithmetic (the mass matrix is positive definite)"
            )
        } else {
            format!(
                "the mass matrix is not positive definite at {at} (pivot {:e}): that joint \
                 moves no mass (a massless branch needs an inertial, or fix the joint)",
                self.value
            )
        }
    }
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
            return Err(SingularMassMatrix::at(j, d));
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
