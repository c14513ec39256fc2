//! Dexterity measures of a Jacobian: Yoshikawa's manipulability and the condition number.

use nalgebra::DMatrix;

/// Yoshikawa's manipulability `w = sqrt(det(J Jᵀ))` for a `m × n` Jacobian with `m ≤ n`,
/// computed as the product of the singular values (which also covers `m > n`, where it is
/// `sqrt(det(Jᵀ J))`). Goes to 0 smoothly at singularities.
pub fn manipulability(j: &DMatrix<f64>) -> f64 {
    if j.nrows() == 0 || j.ncols() == 0 {
        return 0.0;
    }
    j.singular_values().iter().product()
}

/// Condition number `σ_max / σ_min` (infinite at a singularity). Mixed translation and
/// rotation rows have different units: pass the 3-row block you mean, or a scaled `J`.
pub fn condition_number(j: &DMatrix<f64>) -> f64 {
    if j.nrows() == 0 || j.ncols() == 0 {
        return f64::INFINITY;
    }
    let s = j.singular_values();
    let max = s.max();
    let min = s.min();
    if min <= max * f64::EPSILON {
        f64::INFINITY
    } else {
        max / min
    }
}
