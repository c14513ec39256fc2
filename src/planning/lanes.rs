//! Eight-lane geometry for the checker: stored lanes ([`L`], 32-byte aligned), points and
//! poses in registers ([`P3`], [`LanePose`]) over a [`Simd`] token, one robot configuration
//! per lane (structure of arrays, as in VAMP).

pub use crate::planning::lane_values::{Mask, ALL, L, N};
use crate::planning::simd::{Simd, W};

/// A point per lane, in registers.
#[derive(Clone, Copy)]
pub struct P3<S: Simd> {
    /// x per lane.
    pub x: W<S>,
    /// y per lane.
    pub y: W<S>,
    /// z per lane.
    pub z: W<S>,
}

/// A stored point per lane.
#[derive(Clone, Copy, Debug)]
pub struct P3m {
    /// x, y, z.
    pub c: [L; 3],
}

impl<S: Simd> P3<S> {
    /// The same point in every lane.
    #[inline(always)]
    pub fn splat(tok: S, p: &[f32; 3]) -> P3<S> {
        P3 {
            x: tok.splat(p[0]),
            y: tok.splat(p[1]),
            z: tok.splat(p[2]),
        }
    }

    /// Loads a stored point.
    #[inline(always)]
    pub fn load(tok: S, m: &P3m) -> P3<S> {
        P3 {
            x: tok.load(&m.c[0]),
            y: tok.load(&m.c[1]),
            z: tok.load(&m.c[2]),
        }
    }

    /// Stores the point.
    #[inline(always)]
    pub fn store(&self) -> P3m {
        P3m {
            c: [S::store(self.x), S::store(self.y), S::store(self.z)],
        }
    }

    /// Squared distance to `o`.
    #[inline(always)]
    pub fn dist2(&self, o: &P3<S>) -> W<S> {
        W::norm2(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

/// A rotation (row-major) and translation per lane, in registers.
#[derive(Clone, Copy)]
pub struct LanePose<S: Simd> {
    /// `r[row][col]`.
    pub r: [[W<S>; 3]; 3],
    /// Translation.
    pub t: P3<S>,
}

/// A stored pose per lane.
#[derive(Clone, Copy, Debug)]
pub struct PoseM {
    /// Rotation rows.
    pub r: [[L; 3]; 3],
    /// Translation.
    pub t: P3m,
}

impl Default for P3m {
    fn default() -> Self {
        P3m {
            c: [L::splat(0.0); 3],
        }
    }
}

impl Default for PoseM {
    fn default() -> Self {
        PoseM {
            r: [[L::splat(0.0); 3]; 3],
            t: P3m {
                c: [L::splat(0.0); 3],
            },
        }
    }
}

impl<S: Simd> LanePose<S> {
    /// The same constant pose in every lane.
    #[inline(always)]
    pub fn splat(tok: S, r: &[[f32; 3]; 3], t: &[f32; 3]) -> LanePose<S> {
        let z = tok.splat(0.0);
        let mut out = LanePose {
            r: [[z; 3]; 3],
            t: P3::splat(tok, t),
        };
        for (row, src) in out.r.iter_mut().zip(r) {
            for (x, v) in row.iter_mut().zip(src) {
                *x = tok.splat(*v);
            }
        }
        out
    }

    /// Loads a stored pose.
    #[inline(always)]
    pub fn load(tok: S, m: &PoseM) -> LanePose<S> {
        let z = tok.splat(0.0);
        let mut out = LanePose {
            r: [[z; 3]; 3],
            t: P3::load(tok, &m.t),
        };
        for i in 0..3 {
            for j in 0..3 {
                out.r[i][j] = tok.load(&m.r[i][j]);
            }
        }
        out
    }

    /// Stores the pose into `out`, lane array by lane array (a returned `PoseM`, 384
    /// bytes, would be copied with `memcpy`: 3 % of the checker's instructions).
    #[inline(always)]
    pub fn store_into(&self, out: &mut PoseM) {
        for i in 0..3 {
            for j in 0..3 {
                out.r[i][j] = S::store(self.r[i][j]);
            }
        }
        out.t = self.t.store();
    }

    /// `R p + t` for a constant point `p`.
    #[inline(always)]
    pub fn act(&self, tok: S, p: &[f32; 3]) -> P3<S> {
        let (px, py, pz) = (tok.splat(p[0]), tok.splat(p[1]), tok.splat(p[2]));
        let row = |k: usize, t: W<S>| {
            self.r[k][0].mul_add(px, self.r[k][1].mul_add(py, self.r[k][2].mul_add(pz, t)))
        };
        P3 {
            x: row(0, self.t.x),
            y: row(1, self.t.y),
            z: row(2, self.t.z),
        }
    }
}
