//! Forward dynamics through the mass matrix: `M(q) q̈ = τ − h(q, q̇)` with `M` from
//! [`super::crba`] and `h` from [`super::rnea`], solved by an in-place Cholesky
//! factorisation `M = L Lᵀ` (no allocation). Works with mimic joints (it uses the
//! projected `M` and `h`); [`forward_dynamics`] picks ABA when the model allows it.

use super::{aba, bias, crba};
use crate::data::Data;
use crate::model::Model;
use crate::spatial::Vec3;
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

/// `q̈` by CRBA + Cholesky into `data.qdd`.
pub fn forward_dynamics_crba<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    gravity: &Vec3,
) -> Result<&'a [f64], SingularMassMatrix> {
    bias(model, data, q, qd, gravity);
    for ((out, t), h) in data.qdd.iter_mut().zip(tau).zip(&data.tau) {
        *out = t - h;
    }
    crba(model, data, q);
    data.chol.copy_from(&data.mass);
    cholesky_in_place(&mut data.chol)?;
    cholesky_solve_in_place(&data.chol, &mut data.qdd);
    Ok(&data.qdd)
}

/// `q̈`: ABA when every body has its own coordinate, CRBA + Cholesky with mimic joints.
pub fn forward_dynamics<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    gravity: &Vec3,
) -> Result<&'a [f64], SingularMassMatrix> {
    if model.has_mimic {
        forward_dynamics_crba(model, data, q, qd, tau, gravity)
    } else {
        Ok(aba(model, data, q, qd, tau, gravity, None))
    }
}
