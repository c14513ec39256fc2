//! The dense occupancy grid: tool points → voxels (3-D) or pixels (planar), stored as a
//! bitset over a box that is known to contain every reachable point, and the word-wise
//! scans over it (occupied cells, exposed faces, boundary cells, isolated holes, the
//! grid coarsened to twice the cell size).
//!
//! Cell `(i, j, k)` (global indices) covers `[i h − s_x, (i + 1) h − s_x) × …` in grid
//! coordinates — world x, y, z, or for a planar workspace the in-plane coordinates
//! `((p − o)·u, (p − o)·v)` — with `s` the grid's shift: zero for the common grid that
//! pools all samples, uniform in `[0, 2h)` per replicate for the estimates (so that the
//! lattice position is random and its effect averages out and enters the standard
//! error). The corner index is even in every axis, so that cell `(i, j, k)` of the `2h`
//! grid ([`Grid::coarse`]) is exactly the union of cells `(2i + a, 2j + b, 2k + c)`.
//!
//! Layout: rows along x padded to a multiple of 64 cells (one row is `wpr` whole words),
//! then y, then z. Padding and the two-cell margin around the bound are always empty.

use crate::core::spatial::Vec3;
use crate::kinematics::fk_lanes::{Lanes, LANES};

/// Largest grid, in cells (one bit each: 64 MiB per bitset; the volume pass keeps seven
/// per replicate).
pub const MAX_CELLS: u64 = 1 << 29;

/// The plane of a planar workspace: origin `o` (the point of the plane closest to the
/// world origin), in-plane axes `u`, `v` and normal `n`, orthonormal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PlaneFrame {
    pub o: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    pub n: Vec3,
}

/// Geometry of a dense grid.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Grid {
    /// `Some` for a planar (pixel) grid.
    pub plane: Option<PlaneFrame>,
    /// Cell edge (m).
    pub h: f64,
    inv_h: f64,
    /// Global index of local cell (0, 0, 0); even.
    pub i0: [i64; 3],
    i0f: [f64; 3],
    /// Shift `s` of the cells (see the module docs).
    pub shift: [f64; 3],
    /// Cells per axis (x padded to a multiple of 64; z is 1 for a planar grid).
    pub n: [usize; 3],
    /// 64-bit words per x row.
    pub wpr: usize,
}

/// Counts over one occupancy bitset.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Scan {
    /// Occupied cells.
    pub occupied: u64,
    /// Faces (3-D) or edges (planar) between an occupied and an empty cell.
    pub exposed: u64,
    /// Occupied cells with at least one empty face neighbour (6 in 3-D, 4 in a plane).
    pub boundary: u64,
    /// Empty cells whose face neighbours are all occupied.
    pub holes: u64,
}

impl Grid {
    /// A grid of cell `h` shifted by `shift` (each component in `[0, 2h)`; the third one
    /// is ignored for a planar grid) containing the ball of `radius` around `center`
    /// (world coordinates), with a two-cell margin; for a planar grid only the ball's disc
    /// in the plane. `Err` with the cell count when it would exceed [`MAX_CELLS`].
    pub fn new(
        h: f64,
        center: &Vec3,
        radius: f64,
        plane: Option<PlaneFrame>,
        shift: [f64; 3],
    ) -> Result<Grid, u64> {
        let c = match &plane {
            None => *center,
            Some(pl) => Vec3::new((center - pl.o).dot(&pl.u), (center - pl.o).dot(&pl.v), 0.0),
        };
        let axes = if plane.is_some() { 2 } else { 3 };
        let margin = 2.0 * h + 1e-9 * (1.0 + radius);
        let mut i0 = [0i64; 3];
        let mut n = [1usize; 3];
        let mut shift = shift;
        for k in 0..axes {
            let lo = ((c[k] + shift[k] - radius - margin) / h).floor() as i64;
            let hi = ((c[k] + shift[k] + radius + margin) / h).floor() as i64;
            let lo = lo - lo.rem_euclid(2);
            let mut len = (hi - lo + 1) as usize;
            len += len % 2;
            i0[k] = lo;
            n[k] = len;
        }
        if plane.is_some() {
            shift[2] = 0.0;
        }
        n[0] = n[0].div_ceil(64) * 64;
        let cells = n[0] as u64 * n[1] as u64 * n[2] as u64;
        if cells > MAX_CELLS {
            return Err(cells);
        }
        Ok(Grid {
            plane,
            h,
            inv_h: 1.0 / h,
            i0,
            i0f: [i0[0] as f64, i0[1] as f64, i0[2] as f64],
            shift,
            n,
            wpr: n[0] / 64,
        })
    }

    /// The grid of cells `2h` covering the same box (same shift).
    #[cfg(test)]
    pub fn coarse(&self) -> Grid {
        let planar = self.plane.is_some();
        let nx = (self.n[0] / 2).div_ceil(64) * 64;
        let n = [nx, self.n[1] / 2, if planar { 1 } else { self.n[2] / 2 }];
        let i0 = [
            self.i0[0] / 2,
            self.i0[1] / 2,
            if planar { 0 } else { self.i0[2] / 2 },
        ];
        Grid {
            plane: self.plane,
            h: 2.0 * self.h,
            inv_h: 0.5 * self.inv_h,
            i0,
            i0f: [i0[0] as f64, i0[1] as f64, i0[2] as f64],
            shift: self.shift,
            n,
            wpr: nx / 64,
        }
    }

    /// 2 for a planar grid, 3 otherwise.
    pub fn dims(&self) -> i32 {
        if self.plane.is_some() {
            2
        } else {
            3
        }
    }

    /// Measure of one cell: `h³` or `h²`.
    pub fn cell_measure(&self) -> f64 {
        self.h.powi(self.dims())
    }

    /// Words of a bitset over this grid.
    pub fn words(&self) -> usize {
        self.wpr * self.n[1] * self.n[2]
    }

    /// An empty bitset.
    pub fn empty(&self) -> Vec<u64> {
        vec![0; self.words()]
    }

    /// Grid coordinates of a world point, and for a planar grid its signed distance to
    /// the plane (0 otherwise).
    #[inline(always)]
    pub fn coords(&self, p: &Vec3) -> ([f64; 3], f64) {
        match &self.plane {
            None => ([p.x, p.y, p.z], 0.0),
            Some(pl) => {
                let d = p - pl.o;
                ([d.dot(&pl.u), d.dot(&pl.v), 0.0], d.dot(&pl.n))
            }
        }
    }

    /// Local `(ix, iy, iz)` of the cell containing grid coordinates `c`, `None` outside
    /// the grid.
    #[inline(always)]
    pub fn locate_local(&self, c: &[f64; 3]) -> Option<[usize; 3]> {
        let fx = (c[0] + self.shift[0]) * self.inv_h - self.i0f[0];
        let fy = (c[1] + self.shift[1]) * self.inv_h - self.i0f[1];
        let fz = if self.plane.is_some() {
            0.0
        } else {
            (c[2] + self.shift[2]) * self.inv_h - self.i0f[2]
        };
        // `as usize` truncates towards zero: it is the floor for non-negative values.
        if fx >= 0.0
            && fy >= 0.0
            && fz >= 0.0
            && fx < self.n[0] as f64
            && fy < self.n[1] as f64
            && fz < self.n[2] as f64
        {
            Some([fx as usize, fy as usize, fz as usize])
        } else {
            None
        }
    }

    /// Bit index of local cell `l`.
    #[inline(always)]
    pub fn index(&self, l: [usize; 3]) -> usize {
        (((l[2] * self.n[1] + l[1]) * self.wpr) << 6) + l[0]
    }

    /// Bit index of the cell containing grid coordinates `c`, `None` outside the grid.
    #[inline(always)]
    pub fn locate(&self, c: &[f64; 3]) -> Option<usize> {
        self.locate_local(c).map(|l| self.index(l))
    }

    /// Bit indices of the cells containing eight points in grid coordinates
    /// (`c[axis][lane]`; the third ignored for a planar grid), `u32::MAX` for a point
    /// outside the grid: [`Self::locate`]'s arithmetic, lane by lane (SIMD).
    #[inline(always)]
    pub fn locate_lanes(&self, c: &[Lanes; 3]) -> [u32; LANES] {
        let planar = self.plane.is_some();
        let [nx, ny, nz] = self.n.map(|v| v as f64);
        let row = (self.wpr << 6) as u32;
        let ny_u = self.n[1] as u32;
        let mut out = [0u32; LANES];
        for (l, o) in out.iter_mut().enumerate() {
            let fx = (c[0][l] + self.shift[0]) * self.inv_h - self.i0f[0];
            let fy = (c[1][l] + self.shift[1]) * self.inv_h - self.i0f[1];
            let fz = if planar {
                0.0
            } else {
                (c[2][l] + self.shift[2]) * self.inv_h - self.i0f[2]
            };
            let inside =
                (fx >= 0.0) & (fy >= 0.0) & (fz >= 0.0) & (fx < nx) & (fy < ny) & (fz < nz);
            let cell = |f: f64| -> u32 {
                let f = if inside { f } else { 0.0 };
                // SAFETY: `0 ≤ f < n ≤ MAX_CELLS < 2^31` (NaN is not inside): in range.
                unsafe { f.to_int_unchecked::<i32>() as u32 }
            };
            let i = (cell(fz) * ny_u + cell(fy)) * row + cell(fx);
            *o = if inside { i } else { u32::MAX };
        }
        out
    }

    /// [`Self::locate_lanes`] with AVX2 intrinsics when `AVX2` (the compiler leaves the
    /// portable loop scalar inside the large hot loop); the same operations, so bitwise
    /// the same cells.
    ///
    /// # Safety
    /// With `AVX2`, the CPU must have AVX2 (the caller's `#[target_feature]` entry).
    #[inline(always)]
    pub unsafe fn locate_lanes_with<const AVX2: bool>(&self, c: &[Lanes; 3]) -> [u32; LANES] {
        #[cfg(target_arch = "x86_64")]
        if AVX2 {
            return self.locate_lanes_avx2(c);
        }
        self.locate_lanes(c)
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn locate_lanes_avx2(&self, c: &[Lanes; 3]) -> [u32; LANES] {
        use std::arch::x86_64::*;
        let mut out = [0u32; LANES];
        let axes = if self.plane.is_some() { 2 } else { 3 };
        let row = _mm_set1_epi32((self.wpr << 6) as i32);
        let ny = _mm_set1_epi32(self.n[1] as i32);
        let (zero, inv_h) = (_mm256_setzero_pd(), _mm256_set1_pd(self.inv_h));
        // The low 32 bits of each 64-bit lane: lanes 0, 2, 4, 6 of eight 32-bit ones.
        let low = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
        for half in 0..2 {
            let mut inside = _mm256_cmp_pd::<_CMP_EQ_OQ>(zero, zero);
            let mut cell = [_mm_setzero_si128(); 3];
            for a in 0..axes {
                let v = _mm256_loadu_pd(c[a].as_ptr().add(4 * half));
                let t = _mm256_add_pd(v, _mm256_set1_pd(self.shift[a]));
                let f = _mm256_sub_pd(_mm256_mul_pd(t, inv_h), _mm256_set1_pd(self.i0f[a]));
                let ge = _mm256_cmp_pd::<_CMP_GE_OQ>(f, zero);
                let lt = _mm256_cmp_pd::<_CMP_LT_OQ>(f, _mm256_set1_pd(self.n[a] as f64));
                inside = _mm256_and_pd(inside, _mm256_and_pd(ge, lt));
                // Truncation; lanes outside (any value) are replaced below.
                cell[a] = _mm256_cvttpd_epi32(f);
            }
            let plane = _mm_add_epi32(_mm_mullo_epi32(cell[2], ny), cell[1]);
            let i = _mm_add_epi32(_mm_mullo_epi32(plane, row), cell[0]);
            let m = _mm256_permutevar8x32_epi32(_mm256_castpd_si256(inside), low);
            let m = _mm256_castsi256_si128(m);
            let r = _mm_or_si128(_mm_and_si128(m, i), _mm_andnot_si128(m, _mm_set1_epi32(-1)));
            _mm_storeu_si128(out.as_mut_ptr().add(4 * half) as *mut __m128i, r);
        }
        out
    }

    /// Local `(ix, iy, iz)` of bit index `i`.
    pub fn local(&self, i: usize) -> [usize; 3] {
        let ix = i & 63;
        let word = i >> 6;
        let row = word / self.wpr;
        [
            (word % self.wpr) * 64 + ix,
            row % self.n[1],
            row / self.n[1],
        ]
    }

    /// Global cell index of bit index `i`.
    pub fn global(&self, i: usize) -> [i64; 3] {
        let l = self.local(i);
        [
            self.i0[0] + l[0] as i64,
            self.i0[1] + l[1] as i64,
            self.i0[2] + l[2] as i64,
        ]
    }

    /// World position of the centre of the cell with bit index `i` (for a planar grid,
    /// the centre of the pixel in the plane).
    pub fn center(&self, i: usize) -> Vec3 {
        let g = self.global(i);
        let c = |k: usize| (g[k] as f64 + 0.5) * self.h - self.shift[k];
        match &self.plane {
            None => Vec3::new(c(0), c(1), c(2)),
            Some(pl) => pl.o + pl.u * c(0) + pl.v * c(1),
        }
    }

    /// Whether bit `i` is set.
    #[inline(always)]
    pub fn test(bits: &[u64], i: usize) -> bool {
        bits[i >> 6] >> (i & 63) & 1 == 1
    }

    /// Sets bit `i`; returns whether it was clear.
    #[inline(always)]
    pub fn set(bits: &mut [u64], i: usize) -> bool {
        let w = &mut bits[i >> 6];
        let m = 1u64 << (i & 63);
        let was_clear = *w & m == 0;
        *w |= m;
        was_clear
    }

    /// Calls `f(word_index, w, [x+, x−, y+, y−, z+, z−])` for every word, where bit `b` of
    /// each neighbour word is the occupancy of the face neighbour of bit `b` of `w`
    /// (empty outside the grid; for a planar grid the z neighbours read as occupied so
    /// that they never make a cell boundary).
    fn for_each_word(&self, bits: &[u64], mut f: impl FnMut(usize, u64, [u64; 6])) {
        let [_, ny, nz] = self.n;
        let wpr = self.wpr;
        let planar = self.plane.is_some();
        let plane_words = ny * wpr;
        for iz in 0..nz {
            for iy in 0..ny {
                let row = (iz * ny + iy) * wpr;
                for k in 0..wpr {
                    let i = row + k;
                    let w = bits[i];
                    let next = if k + 1 < wpr { bits[i + 1] } else { 0 };
                    let prev = if k > 0 { bits[i - 1] } else { 0 };
                    let xp = (w >> 1) | (next << 63);
                    let xm = (w << 1) | (prev >> 63);
                    let yp = if iy + 1 < ny { bits[i + wpr] } else { 0 };
                    let ym = if iy > 0 { bits[i - wpr] } else { 0 };
                    let (zp, zm) = if planar {
                        (!0, !0)
                    } else {
                        (
                            if iz + 1 < nz {
                                bits[i + plane_words]
                            } else {
                                0
                            },
                            if iz > 0 { bits[i - plane_words] } else { 0 },
                        )
                    };
                    f(i, w, [xp, xm, yp, ym, zp, zm]);
                }
            }
        }
    }

    /// Occupied cells, exposed faces, boundary cells and isolated holes.
    pub fn scan(&self, bits: &[u64]) -> Scan {
        let planar = self.plane.is_some();
        let wpr = self.wpr;
        let ny = self.n[1];
        let mut s = Scan::default();
        self.for_each_word(bits, |i, w, nb| {
            let [xp, xm, yp, ym, zp, zm] = nb;
            s.occupied += w.count_ones() as u64;
            // Each face between neighbours counted once, from its lower cell; the faces on
            // the low sides of the grid from the first cell of each line.
            let mut e = (w ^ xp).count_ones() + (w ^ yp).count_ones();
            if i % wpr == 0 {
                e += (w & 1) as u32;
            }
            if (i / wpr).is_multiple_of(ny) {
                e += w.count_ones();
            }
            if !planar {
                e += (w ^ zp).count_ones();
                if i < ny * wpr {
                    e += w.count_ones();
                }
            }
            s.exposed += e as u64;
            let all = xp & xm & yp & ym & zp & zm;
            s.boundary += (w & !all).count_ones() as u64;
            s.holes += (!w & all).count_ones() as u64;
        });
        s
    }

    /// The boundary cells (occupied with an empty face neighbour) as a bitset.
    pub fn boundary_bits(&self, bits: &[u64]) -> Vec<u64> {
        let mut out = self.empty();
        self.for_each_word(bits, |i, w, nb| {
            out[i] = w & !nb.iter().fold(!0u64, |a, &b| a & b);
        });
        out
    }
}

impl Grid {
    /// Cells of the occupied set after an erosion (`erode`) or a dilation by the cube of
    /// `3^D` cells (26 neighbours in 3-D, 8 in a plane). The eroded set is the *inner*
    /// cells — occupied with every neighbour occupied — and the dilated set the occupied
    /// cells plus every cell touching one.
    pub fn morph_count(&self, bits: &[u64], erode: bool) -> u64 {
        count_bits(&self.morph(bits, erode))
    }

    /// The erosion (`erode`) or dilation of the occupied set by the cube of `3^D` cells,
    /// as a bitset. Separable: one pass per axis.
    pub fn morph(&self, bits: &[u64], erode: bool) -> Vec<u64> {
        let [_, ny, nz] = self.n;
        let wpr = self.wpr;
        let op = |a: u64, b: u64| if erode { a & b } else { a | b };
        // Along x, inside and across the words of a row.
        let mut a: Vec<u64> = (0..bits.len())
            .map(|i| {
                let w = bits[i];
                let k = i % wpr;
                let next = if k + 1 < wpr { bits[i + 1] } else { 0 };
                let prev = if k > 0 { bits[i - 1] } else { 0 };
                op(op(w, (w >> 1) | (next << 63)), (w << 1) | (prev >> 63))
            })
            .collect();
        // Along y, then z (outside the grid reads as empty).
        let mut b = vec![0u64; a.len()];
        let passes: &[(usize, usize)] = if self.plane.is_some() {
            &[(wpr, ny)]
        } else {
            &[(wpr, ny), (wpr * ny, nz)]
        };
        for &(stride, len) in passes {
            for (i, out) in b.iter_mut().enumerate() {
                let pos = (i / stride) % len;
                let up = if pos + 1 < len { a[i + stride] } else { 0 };
                let down = if pos > 0 { a[i - stride] } else { 0 };
                *out = op(op(a[i], up), down);
            }
            std::mem::swap(&mut a, &mut b);
        }
        a
    }

    /// The morphological closing of the occupied set by the cube of `3^D` cells (a
    /// dilation, then an erosion): the occupied cells plus the empty cells whose every
    /// neighbour touches an occupied cell. It fills the cells that under-sampling leaves
    /// empty in the bulk and along a boundary, and leaves a digital half-space (the cells
    /// that meet `{x · n ≤ b}`) unchanged: it never adds a cell beyond the closing of the
    /// true cells.
    pub fn closing(&self, bits: &[u64]) -> Vec<u64> {
        self.morph(&self.morph(bits, false), true)
    }
    /// Occupied cells of the grid of `2h` (cell `(i, j, k)` of it is the union of cells
    /// `(2i + a, 2j + b, 2k + c)`: the corner index is even), from the fine bitset.
    pub fn coarse_count(&self, bits: &[u64]) -> u64 {
        let [_, ny, nz] = self.n;
        let wpr = self.wpr;
        let (zstep, zs) = if self.plane.is_some() { (1, 1) } else { (2, 2) };
        let mut count = 0u64;
        for iz in (0..nz).step_by(zstep) {
            for iy in (0..ny).step_by(2) {
                for k in 0..wpr {
                    let mut w = 0u64;
                    for dz in 0..zs.min(nz - iz) {
                        for dy in 0..2.min(ny - iy) {
                            w |= bits[((iz + dz) * ny + iy + dy) * wpr + k];
                        }
                    }
                    count += ((w | (w >> 1)) & 0x5555_5555_5555_5555).count_ones() as u64;
                }
            }
        }
        count
    }
}

/// Saturating hit counts per cell as a thermometer code: `at_least[k]` has the cells hit
/// at least `k + 1` times (k = 0, 1, 2).
#[derive(Clone, Debug)]
pub(crate) struct Hits {
    pub at_least: [Vec<u64>; 3],
}

impl Hits {
    /// No hits on `grid`.
    pub fn new(grid: &Grid) -> Hits {
        Hits {
            at_least: [grid.empty(), grid.empty(), grid.empty()],
        }
    }

    /// One more hit in cell `i` (the reference for [`crate::workspace::counts::Counts`]).
    #[cfg(test)]
    pub fn hit(&mut self, i: usize) {
        let [a, b, c] = &mut self.at_least;
        if !Grid::set(a, i) && !Grid::set(b, i) {
            Grid::set(c, i);
        }
    }

    /// Adds `other`'s hits (saturating at 3).
    pub fn add(&mut self, other: &Hits) {
        let [a1, a2, a3] = &mut self.at_least;
        let [b1, b2, b3] = &other.at_least;
        for w in 0..a1.len() {
            let (x1, x2, x3) = (a1[w], a2[w], a3[w]);
            let (y1, y2, y3) = (b1[w], b2[w], b3[w]);
            a1[w] = x1 | y1;
            a2[w] = x2 | y2 | (x1 & y1);
            a3[w] = x3 | y3 | (x2 & y1) | (x1 & y2);
        }
    }

    /// Occupied cells (hit at least once).
    pub fn occupied(&self) -> &[u64] {
        &self.at_least[0]
    }

    /// The *closed occupancy*: the occupied cells plus the empty cells of their closing
    /// ([`Grid::closing`]) that touch a cell hit only once or twice — cells left empty
    /// where the sampling is sparse. An empty cell of the closing among well-hit cells
    /// is not a sampling gap but the workspace's own shape (a concave boundary at the
    /// voxel scale), and stays empty.
    pub fn closed_occupancy(&self, grid: &Grid) -> Vec<u64> {
        let [a, _, c] = &self.at_least;
        let sparse: Vec<u64> = a.iter().zip(c).map(|(x, y)| x & !y).collect();
        let near_sparse = grid.morph(&sparse, false);
        let mut out = grid.closing(a);
        for ((o, n), x) in out.iter_mut().zip(&near_sparse).zip(a) {
            *o = x | (*o & n);
        }
        out
    }

    /// Cells of `mask` not hit, hit exactly once and exactly twice.
    pub fn counts_in(&self, mask: &[u64]) -> [u64; 3] {
        let [a, b, c] = &self.at_least;
        let mut f = [0u64; 3];
        for w in 0..a.len() {
            f[0] += (mask[w] & !a[w]).count_ones() as u64;
            f[1] += (mask[w] & a[w] & !b[w]).count_ones() as u64;
            f[2] += (mask[w] & b[w] & !c[w]).count_ones() as u64;
        }
        f
    }

    /// Cells hit exactly once and exactly twice.
    pub fn singles_doubles(&self) -> (u64, u64) {
        let [a, b, c] = &self.at_least;
        let (mut f1, mut f2) = (0u64, 0u64);
        for w in 0..a.len() {
            f1 += (a[w] & !b[w]).count_ones() as u64;
            f2 += (b[w] & !c[w]).count_ones() as u64;
        }
        (f1, f2)
    }
}

/// Set bits of a bitset.
pub(crate) fn count_bits(bits: &[u64]) -> u64 {
    bits.iter().map(|w| w.count_ones() as u64).sum()
}

/// Bit indices of the set bits, in order.
pub(crate) fn set_bits(bits: &[u64]) -> impl Iterator<Item = usize> + '_ {
    bits.iter().enumerate().flat_map(|(wi, &w)| {
        let mut w = w;
        std::iter::from_fn(move || {
            if w == 0 {
                None
            } else {
                let b = w.trailing_zeros() as usize;
                w &= w - 1;
                Some((wi << 6) + b)
            }
        })
    })
}

#[cfg(test)]
mod tests {
    use crate::workspace::grid::*;

    fn grid3(plane: Option<PlaneFrame>) -> Grid {
        Grid::new(1.0, &Vec3::zeros(), 4.0, plane, [0.0; 3]).expect("small")
    }

    fn fill(g: &Grid, cells: &[[i64; 3]]) -> Vec<u64> {
        let mut bits = g.empty();
        for c in cells {
            let p = [c[0] as f64 + 0.5, c[1] as f64 + 0.5, c[2] as f64 + 0.5];
            let i = g.locate(&p).expect("inside");
            assert_eq!(
                g.global(i),
                if g.plane.is_some() {
                    [c[0], c[1], 0]
                } else {
                    *c
                }
            );
            Grid::set(&mut bits, i);
        }
        bits
    }

    #[test]
    fn single_voxel_and_hollow_cube() {
        let g = grid3(None);
        let one = g.scan(&fill(&g, &[[0, 0, 0]]));
        assert_eq!(
            one,
            Scan {
                occupied: 1,
                exposed: 6,
                boundary: 1,
                holes: 0
            }
        );
        // 3 × 3 × 3 block without its centre: 26 voxels, 54 outer faces and 6 around
        // the cavity, every voxel on the boundary, one hole.
        let mut cells = Vec::new();
        for x in -1..=1 {
            for y in -1..=1 {
                for z in -1..=1 {
                    if (x, y, z) != (0, 0, 0) {
                        cells.push([x, y, z]);
                    }
                }
            }
        }
        let s = g.scan(&fill(&g, &cells));
        assert_eq!(
            s,
            Scan {
                occupied: 26,
                exposed: 60,
                boundary: 26,
                holes: 1
            }
        );
        // Across the 64-bit word boundary of a row: x = 63 − i0 and its neighbour.
        let big = Grid::new(1.0, &Vec3::new(60.0, 0.0, 0.0), 70.0, None, [0.0; 3]).expect("grid");
        let x = 63 + big.i0[0];
        let s = big.scan(&fill(&big, &[[x, 0, 0], [x + 1, 0, 0]]));
        assert_eq!((s.occupied, s.exposed, s.boundary), (2, 10, 2));
    }

    #[test]
    fn erosion_dilation_and_coarse_counts() {
        let g = grid3(None);
        // A 3 × 3 × 3 block: one inner cell, 5³ cells in its dilation, and on cells of 2
        // (block from −1 to 1 meets coarse cells −1 and 0 per axis) 8 coarse cells.
        let mut cells = Vec::new();
        for x in -1..=1 {
            for y in -1..=1 {
                for z in -1..=1 {
                    cells.push([x, y, z]);
                }
            }
        }
        let bits = fill(&g, &cells);
        assert_eq!(g.morph_count(&bits, true), 1);
        assert_eq!(g.morph_count(&bits, false), 125);
        assert_eq!(g.coarse_count(&bits), 8);
        // One cell: no inner cell, 27 in the dilation, one coarse cell.
        let one = fill(&g, &[[0, 0, 0]]);
        assert_eq!(g.morph_count(&one, true), 0);
        assert_eq!(g.morph_count(&one, false), 27);
        assert_eq!(g.coarse_count(&one), 1);
        // In a plane: a 3 × 3 square has one inner pixel and 25 in its dilation.
        let pl = PlaneFrame {
            o: Vec3::zeros(),
            u: Vec3::x(),
            v: Vec3::z(),
            n: Vec3::y(),
        };
        let g = grid3(Some(pl));
        let mut sq = Vec::new();
        for x in 0..3 {
            for y in 0..3 {
                sq.push([x, y, 0]);
            }
        }
        let bits = fill(&g, &sq);
        assert_eq!(g.morph_count(&bits, true), 1);
        assert_eq!(g.morph_count(&bits, false), 25);
        assert_eq!(g.coarse_count(&bits), 4);
    }

    #[test]
    fn planar_pixels_and_coarse_grid() {
        let pl = PlaneFrame {
            o: Vec3::zeros(),
            u: Vec3::x(),
            v: Vec3::z(),
            n: Vec3::y(),
        };
        let g = grid3(Some(pl));
        assert_eq!(g.dims(), 2);
        assert_eq!(g.cell_measure(), 1.0);
        // A 3 × 3 square of pixels: perimeter 12 edges, 8 boundary pixels.
        let mut cells = Vec::new();
        for x in 0..3 {
            for y in 0..3 {
                cells.push([x, y, 0]);
            }
        }
        let bits = fill(&g, &cells);
        let s = g.scan(&bits);
        assert_eq!(
            s,
            Scan {
                occupied: 9,
                exposed: 12,
                boundary: 8,
                holes: 0
            }
        );
        assert_eq!(set_bits(&g.boundary_bits(&bits)).count(), 8);
        // On cells of 2: pixels 0..3 cover coarse cells 0 and 1 in each axis.
        let c = g.coarse();
        let mut coarse = c.empty();
        for i in set_bits(&bits) {
            let [x, y, z] = g.local(i);
            Grid::set(&mut coarse, c.index([x / 2, y / 2, z / 2]));
        }
        assert_eq!(set_bits(&coarse).count(), 4);
        // A shifted grid moves the cells: with s = 0.25, x = 0.8 is in cell 1.
        let sh = Grid::new(1.0, &Vec3::zeros(), 4.0, Some(pl), [0.25, 0.0, 0.7]).expect("grid");
        assert_eq!(sh.shift, [0.25, 0.0, 0.0]);
        let i = sh.locate(&[0.8, 0.1, 0.0]).expect("inside");
        assert_eq!(sh.global(i), [1, 0, 0]);
        assert!((sh.center(i) - Vec3::new(1.25, 0.0, 0.5)).norm() < 1e-15);
    }
}
