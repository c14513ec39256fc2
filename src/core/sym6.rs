//! [`Sym6`]: a symmetric 6 × 6 matrix stored as its upper triangle (21 numbers), for the
//! articulated inertias of `M⁻¹`'s recursion: products and rank-one updates touch 21
//! entries instead of 36.

use crate::core::spatial::{InertiaO, Se3};

/// Position of entry `(r, c)` (either order) in the packed upper triangle, row by row.
const IDX: [[usize; 6]; 6] = {
    let mut t = [[0; 6]; 6];
    let mut k = 0;
    let mut r = 0;
    while r < 6 {
        let mut c = r;
        while c < 6 {
            t[r][c] = k;
            t[c][r] = k;
            k += 1;
            c += 1;
        }
        r += 1;
    }
    t
};

/// A symmetric 6 × 6 matrix (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sym6(pub [f64; 21]);

impl Default for Sym6 {
    fn default() -> Self {
        Self([0.0; 21])
    }
}

impl Sym6 {
    /// Entry `(r, c)`.
    #[inline(always)]
    pub fn get(&self, r: usize, c: usize) -> f64 {
        self.0[IDX[r][c]]
    }

    /// A rigid-body inertia in origin form, `[[m 1, −[h]×], [[h]×, I_O]]`.
    pub fn from_inertia(y: &InertiaO) -> Self {
        let i = y.i_o;
        let i_o = [
            i[(0, 0)],
            i[(0, 1)],
            i[(0, 2)],
            i[(1, 1)],
            i[(1, 2)],
            i[(2, 2)],
        ];
        Self::from_parts(y.m, &y.h, &i_o)
    }

    /// `y` (given in frame `b`) in frame `a`, `aMb`: [`InertiaO::transformed`] written
    /// straight into the packed triangle.
    #[inline(always)]
    pub fn from_inertia_moved(y: &InertiaO, a_m_b: &Se3) -> Self {
        let (m, h, i_o) = y.transformed_parts(a_m_b);
        Self::from_parts(m, &h, &i_o)
    }

    /// `[[m 1, −[h]×], [[h]×, I_O]]` from `I_O`'s upper triangle `[xx, xy, xz, yy, yz, zz]`.
    #[inline(always)]
    fn from_parts(m: f64, h: &crate::core::spatial::Vec3, i: &[f64; 6]) -> Self {
        Self([
            m, 0.0, 0.0, 0.0, h.z, -h.y, // row 0
            m, 0.0, -h.z, 0.0, h.x, // row 1
            m, h.y, -h.x, 0.0, // row 2
            i[0], i[1], i[2], // row 3
            i[3], i[4], // row 4
            i[5],
        ])
    }

    /// `self x`.
    #[inline(always)]
    pub fn mul(&self, x: &[f64; 6]) -> [f64; 6] {
        let mut out = [0.0; 6];
        for (r, o) in out.iter_mut().enumerate() {
            *o = (0..6).map(|c| self.0[IDX[r][c]] * x[c]).sum();
        }
        out
    }

    /// `to += self − u uᵀ s`.
    #[inline(always)]
    pub fn add_rank_one_update_to(&self, u: &[f64; 6], s: f64, to: &mut Sym6) {
        let mut k = 0;
        for r in 0..6 {
            let ur = u[r] * s;
            for uc in &u[r..] {
                to.0[k] += self.0[k] - ur * uc;
                k += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::core::spatial::{Inertia, InertiaO, Mat3, Vec3};
    use crate::core::sym6::Sym6;

    #[test]
    fn packed_inertia_acts_like_the_full_matrix() {
        let y = InertiaO::from_inertia(&Inertia::new(
            1.7,
            Vec3::new(0.05, 0.1, -0.2),
            Mat3::new(0.1, 0.01, 0.0, 0.01, 0.2, -0.02, 0.0, -0.02, 0.15),
        ));
        let (full, packed) = (y.to_matrix(), Sym6::from_inertia(&y));
        let x = [0.3, -0.4, 0.5, 1.0, -2.0, 0.7];
        let want = full * nalgebra::Vector6::from_column_slice(&x);
        let got = packed.mul(&x);
        for r in 0..6 {
            assert!((got[r] - want[r]).abs() < 1e-15, "row {r}");
            for c in 0..6 {
                assert_eq!(packed.get(r, c), full[(r, c)], "({r}, {c})");
            }
        }
        let mut to = Sym6::default();
        packed.add_rank_one_update_to(&x, 0.5, &mut to);
        for r in 0..6 {
            for c in 0..6 {
                let want = full[(r, c)] - x[r] * x[c] * 0.5;
                assert!((to.get(r, c) - want).abs() < 1e-15);
            }
        }
    }
}
