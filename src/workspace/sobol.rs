//! The Sobol' low-discrepancy sequence and its Owen scrambling.
//!
//! - Direction numbers: Joe & Kuo (2008), file `new-joe-kuo-6.21201`, dimensions 1–31
//!   (the same table SciPy's `qmc.Sobol` uses), 32-bit resolution, so up to 2³² points.
//! - Order: Gray code (Antonov–Saleev), point `i` is `⊕ V_k` over the set bits `k` of
//!   `i ^ (i >> 1)`; every prefix of length 2^m is the same point set as the natural order,
//!   a (t, m, s)-net.
//! - Scrambling: nested uniform (Owen) scrambling by hashing, Burley, "Practical
//!   Hash-based Owen Scrambling", JCGT 9(4), 2020: bit-reverse, apply the Laine–Karras
//!   permutation with a per-dimension seed, reverse back. Every output digit is flipped by a
//!   pseudo-random function of the more significant input digits only, so the net
//!   structure is kept and each scrambled point is uniform on [0, 1)^s: independent seeds
//!   give independent randomised-QMC replicates, whose spread is an honest error estimate.

/// Highest dimension with direction numbers.
pub const MAX_DIMS: usize = 31;

/// `(s, a, m_1 … m_s)` of `new-joe-kuo-6.21201` for dimensions 2 to 31 (dimension 1 is
/// the van der Corput sequence, all `m = 1`).
const JOE_KUO: [(usize, u32, &[u32]); MAX_DIMS - 1] = [
    (1, 0, &[1]),
    (2, 1, &[1, 3]),
    (3, 1, &[1, 3, 1]),
    (3, 2, &[1, 1, 1]),
    (4, 1, &[1, 1, 3, 3]),
    (4, 4, &[1, 3, 5, 13]),
    (5, 2, &[1, 1, 5, 5, 17]),
    (5, 4, &[1, 1, 5, 5, 5]),
    (5, 7, &[1, 1, 7, 11, 19]),
    (5, 11, &[1, 1, 5, 1, 1]),
    (5, 13, &[1, 1, 1, 3, 11]),
    (5, 14, &[1, 3, 5, 5, 31]),
    (6, 1, &[1, 3, 3, 9, 7, 49]),
    (6, 13, &[1, 1, 1, 15, 21, 21]),
    (6, 16, &[1, 3, 1, 13, 27, 49]),
    (6, 19, &[1, 1, 1, 15, 7, 5]),
    (6, 22, &[1, 3, 1, 15, 13, 25]),
    (6, 25, &[1, 1, 5, 5, 19, 61]),
    (7, 1, &[1, 3, 7, 11, 23, 15, 103]),
    (7, 4, &[1, 3, 7, 13, 13, 15, 69]),
    (7, 7, &[1, 1, 3, 13, 7, 35, 63]),
    (7, 8, &[1, 3, 5, 9, 1, 25, 53]),
    (7, 14, &[1, 3, 1, 13, 9, 35, 107]),
    (7, 19, &[1, 3, 1, 5, 27, 61, 31]),
    (7, 21, &[1, 1, 5, 11, 19, 41, 61]),
    (7, 28, &[1, 3, 5, 3, 3, 13, 69]),
    (7, 31, &[1, 1, 7, 13, 1, 19, 1]),
    (7, 32, &[1, 3, 7, 5, 13, 19, 59]),
    (7, 37, &[1, 1, 3, 9, 25, 29, 41]),
    (7, 41, &[1, 3, 5, 13, 23, 1, 55]),
];

/// The 32 direction numbers `V_1 … V_32` of dimension `dim` (0-based), scaled by 2³².
pub fn direction_numbers(dim: usize) -> [u32; 32] {
    assert!(dim < MAX_DIMS, "Sobol: at most {MAX_DIMS} dimensions");
    let mut v = [0u32; 32];
    if dim == 0 {
        for (i, x) in v.iter_mut().enumerate() {
            *x = 1 << (31 - i);
        }
        return v;
    }
    let (s, a, m) = JOE_KUO[dim - 1];
    for i in 0..s {
        v[i] = m[i] << (31 - i);
    }
    for i in s..32 {
        let mut x = v[i - s] ^ (v[i - s] >> s);
        for k in 1..s {
            if (a >> (s - 1 - k)) & 1 == 1 {
                x ^= v[i - k];
            }
        }
        v[i] = x;
    }
    v
}

/// Laine–Karras permutation (Burley 2020): a bijection of `u32` in which output bit `k`
/// depends only on input bits `0 ..= k` (adds and products by even constants only carry
/// upwards).
#[inline(always)]
pub(crate) fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    for m in LAINE_KARRAS {
        x ^= x.wrapping_mul(m);
    }
    x
}

/// The multipliers of [`laine_karras`], in order.
pub(crate) const LAINE_KARRAS: [u32; 4] = [0x6c50_b47c, 0xb82f_1e52, 0xc7af_e638, 0x8d22_f6e6];

/// Nested uniform (Owen) scrambling of a 32-bit coordinate with `seed`: digit `j` (from
/// the most significant) is flipped by a hash of `seed` and digits `1 … j−1`.
#[inline(always)]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// A Sobol' point stream in Gray-code order, optionally Owen-scrambled, that can start
/// at any index.
#[derive(Clone, Debug)]
pub struct Sobol {
    v: Vec<[u32; 32]>,
    x: Vec<u32>,
    seeds: Option<Vec<u32>>,
    index: u64,
}

impl Sobol {
    /// Unscrambled stream of `dims` dimensions starting at point `start`.
    pub fn new(dims: usize, start: u64) -> Self {
        Self::build(dims, start, None)
    }

    /// Owen-scrambled stream, one scrambling seed per dimension.
    pub fn scrambled(seeds: &[u32], start: u64) -> Self {
        Self::build(seeds.len(), start, Some(seeds.to_vec()))
    }

    fn build(dims: usize, start: u64, seeds: Option<Vec<u32>>) -> Self {
        assert!(
            (1..=MAX_DIMS).contains(&dims),
            "Sobol: 1 to {MAX_DIMS} dimensions"
        );
        assert!(start < 1 << 32, "Sobol: at most 2^32 points");
        let v: Vec<[u32; 32]> = (0..dims).map(direction_numbers).collect();
        let gray = start ^ (start >> 1);
        let x = v
            .iter()
            .map(|vd| {
                (0..32)
                    .filter(|&k| (gray >> k) & 1 == 1)
                    .fold(0u32, |acc, k| acc ^ vd[k])
            })
            .collect();
        Self {
            v,
            x,
            seeds,
            index: start,
        }
    }

    /// Number of dimensions.
    pub fn dims(&self) -> usize {
        self.v.len()
    }

    /// Index of the point the next call returns.
    pub fn index(&self) -> u64 {
        self.index
    }

    /// Writes the current point (32-bit digits, scrambled if seeded) into `out` and
    /// advances. Panics past 2³² points.
    #[inline(always)]
    pub fn next_u32(&mut self, out: &mut [u32]) {
        assert!(self.index < 1 << 32, "Sobol: at most 2^32 points");
        match &self.seeds {
            Some(s) => {
                for ((o, &x), &seed) in out.iter_mut().zip(&self.x).zip(s) {
                    *o = owen_scramble(x, seed);
                }
            }
            None => out.copy_from_slice(&self.x),
        }
        self.index += 1;
        let k = (self.index.trailing_zeros() as usize).min(31);
        for (x, v) in self.x.iter_mut().zip(&self.v) {
            *x ^= v[k];
        }
    }

    /// The current point as `f64` in [0, 1) (`digits / 2³²`) and advances.
    pub fn next_f64(&mut self, out: &mut [f64]) {
        let mut buf = [0u32; MAX_DIMS];
        let d = self.dims();
        self.next_u32(&mut buf[..d]);
        for (o, &b) in out.iter_mut().zip(&buf[..d]) {
            *o = b as f64 * (1.0 / 4_294_967_296.0);
        }
    }
}
