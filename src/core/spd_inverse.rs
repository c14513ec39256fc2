//! The inverse of a small symmetric positive-definite matrix (a mass matrix of up to
//! [`SPD_FIXED_MAX`] coordinates) through its Cholesky factor, `A = L Lᵀ`,
//! `A⁻¹ = L⁻ᵀ L⁻¹` (LAPACK's `potrf`, `trtri` and `lauum`, `n³/2` multiply-adds in all),
//! compiled once per size so that every loop unrolls and nothing is bounds-checked.
//!
//! At arm sizes this beats the O(n²) articulated-body recursion for `M⁻¹`: CRBA and this
//! inverse take 0.64× (6 coordinates) to 0.93× (12) the recursion's time, and more than
//! it from 16 on (the arms and generated chains; BENCHMARKS.md, "M⁻¹ on arms through a
//! Cholesky inverse").

// Triangular loops index rows and columns: explicit indices keep the equations visible.
#![allow(clippy::needless_range_loop)]

use crate::core::linalg::SingularMassMatrix;

/// Largest size compiled for its size; larger matrices are the caller's to invert.
pub const SPD_FIXED_MAX: usize = 12;

/// `out = a⁻¹` for the symmetric positive-definite `n × n` matrix `a` (column-major, both
/// triangles), `n ≤` [`SPD_FIXED_MAX`]; `out` is full and symmetric. Fails at the first
/// pivot that is not positive and finite (its coordinate and value).
pub fn spd_inverse_small(n: usize, a: &[f64], out: &mut [f64]) -> Result<(), SingularMassMatrix> {
    assert!(
        n <= SPD_FIXED_MAX && a.len() == n * n && out.len() == n * n,
        "an n × n matrix, n ≤ {SPD_FIXED_MAX}"
    );
    macro_rules! sizes {
        ($($n:literal)*) => {
            match n {
                0 => Ok(()),
                $($n => {
                    let mut l = [[0.0; $n]; $n];
                    l.as_flattened_mut().copy_from_slice(a);
                    let m = out.as_chunks_mut::<$n>().0;
                    inverse::<$n>(&mut l, m.try_into().expect("n columns"))
                })*
                _ => unreachable!("n ≤ SPD_FIXED_MAX"),
            }
        };
    }
    sizes!(1 2 3 4 5 6 7 8 9 10 11 12)
}

/// `out = a⁻¹`; `a[c][r]` is column `c` (only its lower triangle is read), overwritten by
/// `L` with the reciprocals of its diagonal.
#[inline(always)]
fn inverse<const N: usize>(
    a: &mut [[f64; N]; N],
    out: &mut [[f64; N]; N],
) -> Result<(), SingularMassMatrix> {
    cholesky(a)?;
    let mut x = [[0.0; N]; N];
    lower_inverse(a, &mut x);
    gram_of_lower(&x, out);
    Ok(())
}

/// `a = L Lᵀ` in place (lower triangle), the diagonal stored as `1 / L_jj`.
#[inline(always)]
fn cholesky<const N: usize>(a: &mut [[f64; N]; N]) -> Result<(), SingularMassMatrix> {
    for j in 0..N {
        let mut d = a[j][j];
        for k in 0..j {
            d -= a[k][j] * a[k][j];
        }
        if !(d > 0.0 && d.is_finite()) {
            return Err(SingularMassMatrix::at(j, d));
        }
        let r = 1.0 / d.sqrt();
        a[j][j] = r;
        for i in j + 1..N {
            let mut s = a[j][i];
            for k in 0..j {
                s -= a[k][i] * a[k][j];
            }
            a[j][i] = s * r;
        }
    }
    Ok(())
}

/// `x = L⁻¹` (lower; `x` starts at zero) by forward substitution, column by column:
/// `X_jj = 1 / L_jj`, `X_ij = −(Σ_{j≤k<i} L_ik X_kj) / L_ii`.
#[inline(always)]
fn lower_inverse<const N: usize>(l: &[[f64; N]; N], x: &mut [[f64; N]; N]) {
    for j in 0..N {
        x[j][j] = l[j][j];
        for i in j + 1..N {
            let mut s = 0.0;
            for k in j..i {
                s += l[k][i] * x[j][k];
            }
            x[j][i] = -s * l[i][i];
        }
    }
}

/// `g = Xᵀ X` for the lower-triangular `x` (full, symmetric): `g_ij = Σ_{k≥max(i,j)} X_ki X_kj`.
#[inline(always)]
fn gram_of_lower<const N: usize>(x: &[[f64; N]; N], g: &mut [[f64; N]; N]) {
    for j in 0..N {
        for i in j..N {
            let mut s = 0.0;
            for k in i..N {
                s += x[i][k] * x[j][k];
            }
            g[j][i] = s;
            g[i][j] = s;
        }
    }
}
