//! Deterministic samples of the joint box: the Halton sequence (low discrepancy, one prime
//! base per coordinate) with a seeded Cranley–Patterson shift, or a seeded xorshift
//! generator. The same seed gives the same samples on every machine and thread count.
//!
//! The Halton bases start at 3, not 2, as VAMP's do (`vamp/random/halton.hh`): with seed 0
//! both planners then draw the same sample sequence, so their iteration counts compare
//! directly. Base 2 would also put the first coordinate's first samples at the exact middle
//! and quarters of its range, where symmetric joint limits (±π) place the arm in its most
//! aligned poses.

use crate::model::Model;
use std::sync::OnceLock;

/// The odd primes, one Halton base per coordinate (VAMP's bases).
const PRIMES: [u32; 16] = [3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59];

/// xorshift64* (Vigna): a small seeded generator, the same on every platform.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed (any value, zero included).
    pub fn new(seed: u64) -> Rng {
        // splitmix64 of the seed, so nearby seeds give unrelated streams.
        let mut z = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        Rng((z ^ (z >> 31)) | 1)
    }

    /// Next 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform integer in [0, n).
    #[inline]
    pub fn below(&mut self, n: usize) -> usize {
        (((self.next_u64() >> 32) * n as u64) >> 32) as usize
    }
}

/// A configuration drawn uniformly from the joint box ([`bounds`]) into `q`.
pub fn uniform(model: &Model, rng: &mut Rng, q: &mut [f64]) {
    for (k, x) in q.iter_mut().enumerate() {
        let (lo, hi) = bounds(model, k);
        *x = lo + (hi - lo) * rng.next_f64();
    }
}

/// The sampling range of coordinate `k`: its limits, or [−π, π] for a continuous joint.
pub fn bounds(model: &Model, k: usize) -> (f64, f64) {
    let (lo, hi) = (model.lower[k], model.upper[k]);
    if lo.is_finite() && hi.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (-std::f64::consts::PI, std::f64::consts::PI)
    }
}

/// Which sequence to draw from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerKind {
    /// Halton, shifted by the seed (seed 0: the plain sequence).
    Halton,
    /// Seeded pseudo-random.
    Random,
}

/// Samples of the joint box `[lo, hi]`.
#[derive(Clone, Debug)]
pub struct Sampler {
    kind: SamplerKind,
    /// Index of the next Halton sample (from 1).
    index: usize,
    /// Per coordinate, the radical inverses of the first [`TABLE_LEN`] indices
    /// ([`halton_table`], shared by every sampler).
    tables: Vec<&'static [f64]>,
    /// Per coordinate, the base-`b` digits of the index, once past the tables.
    digits: Vec<Digits>,
    shift: Vec<f64>,
    lo: Vec<f32>,
    span: Vec<f32>,
    /// The generator as the shifts left it (where [`Sampler::reset`] returns).
    rng_start: Rng,
    rng: Rng,
}

impl Default for Sampler {
    /// An empty sampler (no coordinates; allocates nothing).
    fn default() -> Sampler {
        Sampler::new(SamplerKind::Random, &[], &[], 0)
    }
}

impl Sampler {
    /// A sampler over the box, seeded.
    pub fn new(kind: SamplerKind, lo: &[f32], hi: &[f32], seed: u64) -> Sampler {
        let mut rng = Rng::new(seed);
        let shift = (0..lo.len())
            .map(|_| if seed == 0 { 0.0 } else { rng.next_f64() })
            .collect();
        let tables = match kind {
            SamplerKind::Halton => (0..lo.len())
                .map(|k| halton_table(k % PRIMES.len()))
                .collect(),
            SamplerKind::Random => Vec::new(),
        };
        Sampler {
            kind,
            index: 1,
            tables,
            // Filled when the tables run out (allocated now: nothing is allocated per sample).
            digits: Vec::with_capacity(lo.len()),
            shift,
            lo: lo.to_vec(),
            span: lo.iter().zip(hi).map(|(l, h)| h - l).collect(),
            rng_start: rng.clone(),
            rng,
        }
    }

    /// Back to the first sample, as [`Sampler::new`] left it (without allocating).
    pub fn reset(&mut self) {
        self.index = 1;
        self.digits.clear();
        self.rng = self.rng_start.clone();
    }

    /// Writes the next sample into `out`.
    #[inline]
    pub fn next(&mut self, out: &mut [f32]) {
        if self.kind == SamplerKind::Random {
            for (k, o) in out.iter_mut().enumerate() {
                *o = self.lo[k] + self.span[k] * self.rng.next_f64() as f32;
            }
            return;
        }
        let i = self.index;
        self.index += 1;
        if i < TABLE_LEN {
            let parts = self
                .tables
                .iter()
                .zip(&self.shift)
                .zip(self.lo.iter().zip(&self.span));
            for (o, ((t, &sh), (&lo, &span))) in out.iter_mut().zip(parts) {
                *o = lo + span * wrap(t[i] + sh) as f32;
            }
            return;
        }
        if self.digits.is_empty() {
            let digits = (0..out.len()).map(|k| Digits::new(PRIMES[k % PRIMES.len()], i as u64));
            self.digits.extend(digits);
        }
        for (k, o) in out.iter_mut().enumerate() {
            let d = &mut self.digits[k];
            let u = wrap(d.radical_inverse() + self.shift[k]);
            d.increment();
            *o = self.lo[k] + self.span[k] * u as f32;
        }
    }

    /// The generator, for other seeded choices (simplification).
    pub fn rng(&mut self) -> &mut Rng {
        &mut self.rng
    }
}

/// `v` in [0, 2) back to [0, 1).
#[inline(always)]
fn wrap(v: f64) -> f64 {
    if v >= 1.0 {
        v - 1.0
    } else {
        v
    }
}

/// Samples whose radical inverses are tabled (per base, 256 KiB of f64).
const TABLE_LEN: usize = 1 << 15;

/// The radical inverses of `0..TABLE_LEN` in the base of coordinate `k` (`k < 16`), computed
/// once per process by a [`Digits`] counter (the same bits as counting on from there).
/// Taking a sample is then a load per coordinate: counting in each base was two thirds of
/// the time of the search's iterations that the dynamic domain turns away (20 of 30 ns).
fn halton_table(k: usize) -> &'static [f64] {
    static TABLES: [OnceLock<Box<[f64]>>; 16] = [const { OnceLock::new() }; 16];
    TABLES[k].get_or_init(|| {
        let mut d = Digits::new(PRIMES[k], 0);
        (0..TABLE_LEN)
            .map(|_| {
                let x = d.radical_inverse();
                d.increment();
                x
            })
            .collect()
    })
}

/// Digits of a `u64` in base 3 or more (`3^41 > 2^64`).
const DIGITS: usize = 41;

/// A counter kept as its base-`b` digits with the partial sums of its radical inverse
/// (most significant digit first), so that the next sample costs the digits that changed,
/// 1.5 multiply-adds on average in base 3, and no division: computing each radical inverse
/// anew by division was a quarter of the search's time. Summing from the most significant
/// digit may differ from [`radical_inverse`] in the last bit (the test bounds it).
#[derive(Clone, Debug)]
struct Digits {
    base: u32,
    /// Least significant first; `len` of them are in use.
    digit: [u32; DIGITS],
    len: usize,
    /// `weight[j] = b^−(j+1)`.
    weight: [f64; DIGITS],
    /// `partial[j] = Σ_{i ≥ j} digit[i] weight[i]` (`partial[len] = 0`).
    partial: [f64; DIGITS + 1],
}

impl Digits {
    fn new(base: u32, mut value: u64) -> Digits {
        let inv = 1.0 / base as f64;
        let mut weight = [0.0; DIGITS];
        let mut f = inv;
        for w in &mut weight {
            *w = f;
            f *= inv;
        }
        let mut d = Digits {
            base,
            digit: [0; DIGITS],
            len: 0,
            weight,
            partial: [0.0; DIGITS + 1],
        };
        while value > 0 {
            d.digit[d.len] = (value % base as u64) as u32;
            value /= base as u64;
            d.len += 1;
        }
        d.resum(d.len);
        d
    }

    /// Recomputes the partial sums of digits `0..top`.
    #[inline]
    fn resum(&mut self, top: usize) {
        for j in (0..top).rev() {
            self.partial[j] = self.partial[j + 1] + self.digit[j] as f64 * self.weight[j];
        }
    }

    #[inline]
    fn radical_inverse(&self) -> f64 {
        self.partial[0]
    }

    /// Adds one. The last digit changes alone `(b − 1)/b` of the time: one multiply-add.
    #[inline(always)]
    fn increment(&mut self) {
        let d0 = self.digit[0] + 1;
        if d0 < self.base && self.len > 0 {
            self.digit[0] = d0;
            self.partial[0] = self.partial[1] + d0 as f64 * self.weight[0];
        } else {
            self.carry();
        }
    }

    /// Adds one, carrying into higher digits.
    #[inline(never)]
    fn carry(&mut self) {
        let mut j = 0;
        while j < self.len && self.digit[j] + 1 == self.base {
            self.digit[j] = 0;
            j += 1;
        }
        if j == self.len {
            self.digit[j] = 0;
            self.len += 1;
            self.partial[self.len] = 0.0;
        }
        self.digit[j] += 1;
        self.resum(j + 1);
    }
}

/// Van der Corput radical inverse of `i` in base `b`, by division (the reference of
/// [`Digits`]).
#[cfg(test)]
fn radical_inverse(mut i: u64, b: u32) -> f64 {
    let b64 = b as u64;
    let inv = 1.0 / b as f64;
    let mut f = inv;
    let mut r = 0.0;
    while i > 0 {
        r += (i % b64) as f64 * f;
        i /= b64;
        f *= inv;
    }
    r
}

#[cfg(test)]
mod tests {
    use crate::planning::sampler::*;

    #[test]
    fn radical_inverse_reverses_the_digits() {
        // 6 = 110₂ → 0.011₂ = 0.375; 5 = 12₃ → 0.21₃ = 2/3 + 1/9.
        assert_eq!(radical_inverse(6, 2), 0.375);
        assert!((radical_inverse(5, 3) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-15);
    }

    #[test]
    fn halton_in_2d_fills_every_cell_of_a_9x5_grid_within_45_samples() {
        // Bases 3 and 5: any 3^i × 5^j consecutive samples hit each cell of that grid once.
        let mut s = Sampler::new(SamplerKind::Halton, &[0.0, 0.0], &[1.0, 1.0], 0);
        let mut seen = [[0u32; 5]; 9];
        let mut q = [0.0f32; 2];
        for _ in 0..45 {
            s.next(&mut q);
            seen[(q[0] * 9.0) as usize][(q[1] * 5.0) as usize] += 1;
        }
        assert!(seen.iter().flatten().all(|&x| x == 1), "{seen:?}");
    }

    #[test]
    fn digit_counter_gives_the_radical_inverse_by_division_to_the_last_bits() {
        for base in PRIMES {
            let mut d = Digits::new(base, 1);
            for i in 1..20_000u64 {
                let (x, want) = (d.radical_inverse(), radical_inverse(i, base));
                assert!(
                    (x - want).abs() <= 2.0 * f64::EPSILON * want,
                    "base {base}, index {i}: {x} vs {want}"
                );
                d.increment();
            }
        }
    }

    #[test]
    fn tabled_and_counted_samples_continue_one_sequence() {
        // Across the end of the tables, a sampler's samples are those of counting from 1.
        let (lo, hi) = ([-1.0f32, 0.0, 2.0], [1.0f32, 5.0, 3.0]);
        let mut s = Sampler::new(SamplerKind::Halton, &lo, &hi, 17);
        let shift = s.shift.clone();
        let mut counters: Vec<Digits> = (0..3).map(|k| Digits::new(PRIMES[k], 1)).collect();
        let mut q = [0.0f32; 3];
        for i in 1..TABLE_LEN + 100 {
            s.next(&mut q);
            for k in 0..3 {
                let u = wrap(counters[k].radical_inverse() + shift[k]);
                counters[k].increment();
                let want = lo[k] + (hi[k] - lo[k]) * u as f32;
                assert_eq!(q[k].to_bits(), want.to_bits(), "sample {i}, coordinate {k}");
            }
        }
    }

    #[test]
    fn a_reset_sampler_draws_what_a_new_one_draws() {
        for kind in [SamplerKind::Halton, SamplerKind::Random] {
            let mut a = Sampler::new(kind, &[0.0, -1.0], &[1.0, 1.0], 5);
            let mut q = [0.0f32; 2];
            for _ in 0..TABLE_LEN + 10 {
                a.next(&mut q);
            }
            a.rng().next_u64();
            a.reset();
            let mut b = Sampler::new(kind, &[0.0, -1.0], &[1.0, 1.0], 5);
            let mut p = [0.0f32; 2];
            for _ in 0..100 {
                a.next(&mut q);
                b.next(&mut p);
                assert_eq!(q, p);
            }
            assert_eq!(a.rng().next_u64(), b.rng().next_u64());
        }
    }

    #[test]
    fn halton_starts_with_vamps_first_samples() {
        // VAMP's Halton (bases 3, 5) starts at (1/3, 1/5), (2/3, 2/5), (1/9, 3/5).
        let mut s = Sampler::new(SamplerKind::Halton, &[0.0, 0.0], &[1.0, 1.0], 0);
        let mut q = [0.0f32; 2];
        for want in [[1.0 / 3.0, 0.2], [2.0 / 3.0, 0.4], [1.0 / 9.0, 0.6]] {
            s.next(&mut q);
            assert!(
                (q[0] - want[0]).abs() < 1e-6 && (q[1] - want[1]).abs() < 1e-6,
                "{q:?}"
            );
        }
    }
}
