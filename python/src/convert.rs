//! Conversions between armsim's types and flat row-major arrays for numpy.

use armsim::{Mat3, Se3, Vec3};

/// A placement as a row-major 4×4 homogeneous matrix.
pub fn se3_to_4x4(p: &Se3, out: &mut [f64]) {
    for r in 0..3 {
        for c in 0..3 {
            out[4 * r + c] = p.rot[(r, c)];
        }
        out[4 * r + 3] = p.trans[r];
    }
    out[12..16].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
}

/// A row-major 4×4 homogeneous matrix as a placement (checked by [`check_pose`]).
pub fn se3_from_4x4(t: &[f64; 16]) -> Se3 {
    Se3 {
        rot: Mat3::new(t[0], t[1], t[2], t[4], t[5], t[6], t[8], t[9], t[10]),
        trans: Vec3::new(t[3], t[7], t[11]),
    }
}

/// Refuses a matrix that is not a rigid transform (finite, orthonormal rotation with
/// determinant +1 to 1e-6, last row `0 0 0 1`).
pub fn check_pose(t: &[f64; 16]) -> Result<(), String> {
    if let Some(i) = t.iter().position(|v| !v.is_finite()) {
        return Err(format!("entry ({}, {}) is not finite", i / 4, i % 4));
    }
    if t[12..16] != [0.0, 0.0, 0.0, 1.0] {
        return Err("the last row is not [0, 0, 0, 1]".into());
    }
    let limit = armsim::kinematics::ik::MAX_TARGET_DISTANCE;
    if let Some(x) = [t[3], t[7], t[11]].iter().find(|x| x.abs() > limit) {
        return Err(format!(
            "the translation {x:e} m is beyond the {limit:e} m accepted for a pose"
        ));
    }
    let r = se3_from_4x4(t).rot;
    let off = (r.transpose() * r - Mat3::identity()).abs().max();
    if off > 1e-6 || (r.determinant() - 1.0).abs() > 1e-6 {
        return Err(format!(
            "the rotation is not orthonormal (|RᵀR − I| = {off:.1e}, det = {:.6})",
            r.determinant()
        ));
    }
    Ok(())
}

/// Copies a column-major nalgebra matrix into a row-major slice.
pub fn matrix_row_major(m: &armsim::nalgebra::DMatrix<f64>, out: &mut [f64]) {
    let (rows, cols) = m.shape();
    assert_eq!(out.len(), rows * cols, "output of {rows} × {cols}");
    // Column by column over the contiguous storage (indexing `m[(r, c)]` checks both
    // bounds on every element).
    for (c, col) in m.as_slice().chunks_exact(rows.max(1)).enumerate() {
        for (r, &x) in col.iter().enumerate() {
            out[r * cols + c] = x;
        }
    }
}

/// A new C-ordered `rows × cols` numpy array holding `m` (nalgebra is column-major).
pub fn matrix_to_numpy<'py>(
    py: pyo3::Python<'py>,
    m: &armsim::nalgebra::DMatrix<f64>,
) -> pyo3::Bound<'py, numpy::PyArray2<f64>> {
    use numpy::PyArrayMethods;
    // SAFETY: a fresh array, written in full below before Python sees it.
    let arr = unsafe { numpy::PyArray2::<f64>::new(py, [m.nrows(), m.ncols()], false) };
    let out = unsafe { arr.as_slice_mut().expect("fresh C-ordered array") };
    matrix_row_major(m, out);
    arr
}

/// A new `n × n` numpy array holding the symmetric `m` (`M`, `M⁻¹`): its column-major
/// storage is also its row-major one, so one copy, no transposition.
pub fn symmetric_to_numpy<'py>(
    py: pyo3::Python<'py>,
    m: &armsim::nalgebra::DMatrix<f64>,
) -> pyo3::Bound<'py, numpy::PyArray2<f64>> {
    use numpy::PyArrayMethods;
    debug_assert!(m.is_square(), "a symmetric matrix is square");
    // SAFETY: as in `matrix_to_numpy`.
    let arr = unsafe { numpy::PyArray2::<f64>::new(py, [m.nrows(), m.ncols()], false) };
    unsafe { arr.as_slice_mut().expect("fresh C-ordered array") }.copy_from_slice(m.as_slice());
    arr
}

/// A new 4×4 numpy array holding the placement `p`.
pub fn se3_to_numpy<'py>(py: pyo3::Python<'py>, p: &Se3) -> pyo3::Bound<'py, numpy::PyArray2<f64>> {
    use numpy::PyArrayMethods;
    // SAFETY: as in `matrix_to_numpy`.
    let arr = unsafe { numpy::PyArray2::<f64>::new(py, [4, 4], false) };
    se3_to_4x4(p, unsafe {
        arr.as_slice_mut().expect("fresh C-ordered array")
    });
    arr
}
