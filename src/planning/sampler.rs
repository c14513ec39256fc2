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
    /// Per coordinate, the base-`b` digits of the sample's index (from 1; Halton).
    digits: Vec<Digits>,
    shift: Vec<f64>,
    lo: Vec<f32>,
    span: Vec<f32>,
    rng: Rng,
}

impl Sampler {
    /// A sampler over the box, seeded.
    pub fn new(kind: SamplerKind, lo: &[f32], hi: &[f32], seed: u64) -> Sampler {
        let mut rng = Rng::new(seed);
        let shift = (0..lo.len())
            .map(|_| if seed == 0 { 0.0 } else { rng.next_f64() })
            .collect();
        Sampler {
            kind,
            digits: (0..lo.len())
                .map(|k| Digits::new(PRIMES[k % PRIMES.len()], 1))
                .collect(),
            shift,
            lo: lo.to_vec(),
            span: lo.iter().zip(hi).map(|(l, h)| h - l).collect(),
            rng,
        }
    }

    /// Writes the next sample into `out`.
    #[inline]
    pub fn next(&mut self, out: &mut [f32]) {
        for (k, o) in out.iter_mut().enumerate() {
            let u = match self.kind {
                SamplerKind::Halton => {
                    let d = &mut self.digits[k];
                    let v = d.radical_inverse() + self.shift[k];
                    d.increment();
                    if v >= 1.0 {
                        v - 1.0
                    } else {
                        v
                    }
                }
                SamplerKind::Random => self.rng.next_f64(),
            };
            *o = self.lo[k] + self.span[k] * u as f32;
        }
    }

    /// The generator, for other seeded choices (simplification).
    pub fn rng(&mut self) -> &mut Rng {
        &mut self.rng
    }
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
    use super::*;

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
