//! Joint-space sample streams: uniform random and Owen-scrambled Sobol', mapped onto each
//! coordinate's sampling interval ([`Model::sampling_bounds`]).
//!
//! Both kinds are *seekable* (a stream can start at any sample index), so the work can be
//! cut into fixed chunks whose results do not depend on the number of threads:
//! - random: SplitMix64 (Steele, Lea & Flood 2014) in counter mode — value `k` of a
//!   stream is `mix64(key + (k + 1)·γ)`, as fast as `SmallRng` and free to seek;
//! - Sobol': Gray-code stream started at any index, Owen-scrambled per replicate.
//!
//! Replicate `r` of a run with seed `s` draws its random key or its scrambling seeds from
//! `(s, r)` alone, so replicates are independent and reproducible.

use super::sobol::Sobol;
use crate::model::Model;

/// SplitMix64's increment (the golden ratio in 64-bit fixed point).
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's output function (a bijective 64-bit mixer).
#[inline(always)]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A seed for purpose `(a, b)` derived from the user's seed.
pub(crate) fn derive_seed(seed: u64, a: u64, b: u64) -> u64 {
    let h = mix64(seed ^ 0x5851_F42D_4C95_7F2D);
    let h = mix64(h.wrapping_add(a.wrapping_add(1).wrapping_mul(GAMMA)));
    mix64(h ^ b.wrapping_add(1).wrapping_mul(0xD1B5_4A32_D192_ED03))
}

/// The box of joint space that is sampled: `q_k = lo_k + u_k · span_k`, `u ∈ [0, 1)`.
#[derive(Clone, Debug)]
pub(crate) struct JointBox {
    pub lo: Vec<f64>,
    pub span: Vec<f64>,
}

impl JointBox {
    pub fn new(model: &Model) -> Self {
        let (lo, span) = (0..model.nv)
            .map(|k| {
                let (a, b) = model.sampling_bounds(k);
                (a, (b - a).max(0.0))
            })
            .unzip();
        Self { lo, span }
    }
}

/// A source of configurations.
pub(crate) trait QStream {
    /// Writes the next configuration into `q`.
    fn next_q(&mut self, b: &JointBox, q: &mut [f64]);
}

/// Counter-mode SplitMix64.
pub(crate) struct RandomStream {
    key: u64,
    counter: u64,
}

impl RandomStream {
    /// Stream of replicate `replicate`, positioned at sample `start` (`dims` values per
    /// sample).
    pub fn new(seed: u64, replicate: u64, dims: usize, start: u64) -> Self {
        Self {
            key: derive_seed(seed, replicate, 0),
            counter: start * dims as u64,
        }
    }
}

impl QStream for RandomStream {
    #[inline(always)]
    fn next_q(&mut self, b: &JointBox, q: &mut [f64]) {
        for ((q, &lo), &span) in q.iter_mut().zip(&b.lo).zip(&b.span) {
            self.counter = self.counter.wrapping_add(1);
            let r = mix64(self.key.wrapping_add(self.counter.wrapping_mul(GAMMA)));
            let u = (r >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0);
            *q = lo + u * span;
        }
    }
}

/// Owen-scrambled Sobol'.
pub(crate) struct SobolStream {
    sobol: Sobol,
    buf: [u32; super::sobol::MAX_DIMS],
}

impl SobolStream {
    /// Stream of replicate `replicate` positioned at sample `start`.
    pub fn new(seed: u64, replicate: u64, dims: usize, start: u64) -> Self {
        let seeds: Vec<u32> = (0..dims as u64)
            .map(|j| derive_seed(seed, replicate, 1000 + j) as u32)
            .collect();
        Self {
            sobol: Sobol::scrambled(&seeds, start),
            buf: [0; super::sobol::MAX_DIMS],
        }
    }
}

impl QStream for SobolStream {
    #[inline(always)]
    fn next_q(&mut self, b: &JointBox, q: &mut [f64]) {
        let d = q.len();
        self.sobol.next_u32(&mut self.buf[..d]);
        for (((q, &lo), &span), &x) in q.iter_mut().zip(&b.lo).zip(&b.span).zip(&self.buf) {
            // The centre of the 2^-32 cell the scrambled digits select.
            let u = (x as f64 + 0.5) * (1.0 / 4_294_967_296.0);
            *q = lo + u * span;
        }
    }
}
