//! Joint-space sample streams: uniform random and Owen-scrambled Sobol', mapped onto each
//! coordinate's sampling interval ([`Model::sampling_bounds`]).
//!
//! Both kinds are *seekable* (a stream can start at any sample index), so the work can be
//! cut into fixed chunks whose results do not depend on the number of threads:
//! - random: SplitMix64 (Steele, Lea & Flood 2014) in counter mode — value `k` of a
//!   stream is `mix64(key + (k + 1)·γ)`, as fast as `SmallRng` and free to seek;
//! - Sobol': Gray-code stream started at any index, Owen-scrambled per replicate.
//!
//! Both also fill eight configurations at once, one per SIMD lane (`next_lanes`, the
//! volume pass's hot loop), with the values of eight single draws.
//!
//! Replicate `r` of a run with seed `s` draws its random key or its scrambling seeds from
//! `(s, r)` alone, so replicates are independent and reproducible.

use crate::kinematics::fk_lanes::{Lanes, LANES};
use crate::model::Model;
use crate::workspace::sobol::{direction_numbers, laine_karras, LAINE_KARRAS, MAX_DIMS};

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

    /// Writes the next `m` configurations (1 to [`LANES`]) into lanes `0..m` of `q`
    /// (`q[k][lane]`, one lane array per coordinate); the spare lanes repeat lane `m − 1`.
    /// The same values as `m` calls of [`Self::next_q`]. `#[inline(always)]` in the
    /// implementations, so that it compiles with the caller's instruction set; with
    /// `AVX2`, parts are written with AVX2 intrinsics (the same operations).
    ///
    /// # Safety
    /// With `AVX2`, the CPU must have AVX2.
    unsafe fn next_lanes<const AVX2: bool>(&mut self, b: &JointBox, q: &mut [Lanes], m: usize);
}

/// `x as f64` for `x < 2^52`, exactly, by integer operations and one exact subtraction
/// (`2^52 + x` has `x` as its mantissa), which vectorise on every instruction set (the
/// conversion instruction for 64-bit integers needs AVX-512 DQ).
#[inline(always)]
fn small_u64_to_f64(x: u64) -> f64 {
    const TWO_52: f64 = 4_503_599_627_370_496.0;
    f64::from_bits(x | TWO_52.to_bits()) - TWO_52
}

/// `u ∈ [0, 1)` from a 64-bit random word: its 53 high bits `v`, `/ 2^53` — `v` converted
/// exactly as `2 ⌊v/2⌋ + (v mod 2)` (the same value as `v as f64`).
#[inline(always)]
fn unit_f64(r: u64) -> f64 {
    let v = r >> 11;
    let f = small_u64_to_f64(v >> 1) * 2.0 + small_u64_to_f64(v & 1);
    f * (1.0 / 9_007_199_254_740_992.0)
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
            *q = lo + unit_f64(r) * span;
        }
    }

    /// Value `k` of sample `s` is word `counter + s·d + k + 1`: every lane and coordinate
    /// is computed independently (SIMD over the lanes).
    #[inline(always)]
    unsafe fn next_lanes<const AVX2: bool>(&mut self, b: &JointBox, q: &mut [Lanes], m: usize) {
        let d = q.len() as u64;
        let base = self.counter;
        let mut first = [0u64; LANES];
        for (l, f) in first.iter_mut().enumerate() {
            *f = base.wrapping_add((l.min(m - 1) as u64).wrapping_mul(d));
        }
        for (k, ((lanes, &lo), &span)) in q.iter_mut().zip(&b.lo).zip(&b.span).enumerate() {
            for (v, &f) in lanes.iter_mut().zip(&first) {
                let c = f.wrapping_add(k as u64 + 1);
                let r = mix64(self.key.wrapping_add(c.wrapping_mul(GAMMA)));
                *v = lo + unit_f64(r) * span;
            }
        }
        self.counter = base.wrapping_add(m as u64 * d);
    }
}

/// Owen-scrambled Sobol' in Gray-code order, kept *bit-reversed*: the state is the
/// reversal of the Sobol' digits (XOR commutes with the reversal, so it advances by the
/// reversed direction numbers), and the scrambled output `rev(LK(rev(x)))`
/// ([`crate::workspace::sobol::owen_scramble`]) is then `rev(LK(state))`, one reversal per value.
///
/// Eight consecutive points from an index `8a` are `x(8a) ⊕ X_l`, `l = 0 … 7`, with `X_l`
/// the XOR of the first three direction numbers over the bits of `gray(l)` (since
/// `gray(8a + l) = gray(8a) ⊕ gray(l)`): a batch aligned on eight is one XOR per lane,
/// in SIMD.
pub(crate) struct SobolStream {
    /// Reversed digits of the current point (unused dimensions zero).
    x: [u32; 32],
    /// `v[k][j]`: reversed direction number `k` of dimension `j`.
    v: [[u32; 32]; 32],
    /// `lane[j][l]`: reversed `X_l` of dimension `j`.
    lane: [[u32; LANES]; 32],
    seeds: [u32; 32],
    index: u64,
}

impl SobolStream {
    /// Stream of replicate `replicate` positioned at sample `start`.
    pub fn new(seed: u64, replicate: u64, dims: usize, start: u64) -> Self {
        assert!(
            (1..=MAX_DIMS).contains(&dims),
            "Sobol: 1 to {MAX_DIMS} dimensions"
        );
        assert!(start < 1 << 32, "Sobol: at most 2^32 points");
        let mut v = [[0u32; 32]; 32];
        let mut seeds = [0u32; 32];
        for j in 0..dims {
            for (k, &dn) in direction_numbers(j).iter().enumerate() {
                v[k][j] = dn.reverse_bits();
            }
            seeds[j] = derive_seed(seed, replicate, 1000 + j as u64) as u32;
        }
        let xor_bits = |g: u64| {
            let mut x = [0u32; 32];
            for (k, vk) in v.iter().enumerate() {
                if (g >> k) & 1 == 1 {
                    for (a, b) in x.iter_mut().zip(vk) {
                        *a ^= b;
                    }
                }
            }
            x
        };
        let by_lane: [[u32; 32]; LANES] =
            std::array::from_fn(|l| xor_bits(l as u64 ^ (l as u64 >> 1)));
        let lane = std::array::from_fn(|j| std::array::from_fn(|l| by_lane[l][j]));
        Self {
            x: xor_bits(start ^ (start >> 1)),
            v,
            lane,
            seeds,
            index: start,
        }
    }

    /// Moves to the next point (Gray code: flip direction number `tz(index + 1)`).
    #[inline(always)]
    fn step(&mut self) {
        self.index += 1;
        let k = (self.index.trailing_zeros() as usize).min(31);
        for (x, v) in self.x.iter_mut().zip(&self.v[k]) {
            *x ^= v;
        }
    }
}

/// `x.reverse_bits()` by shifts and masks, which vectorise on every instruction set (the
/// intrinsic is left scalar by some).
#[inline(always)]
fn reverse_bits(x: u32) -> u32 {
    let x = ((x >> 1) & 0x5555_5555) | ((x & 0x5555_5555) << 1);
    let x = ((x >> 2) & 0x3333_3333) | ((x & 0x3333_3333) << 2);
    let x = ((x >> 4) & 0x0F0F_0F0F) | ((x & 0x0F0F_0F0F) << 4);
    let x = ((x >> 8) & 0x00FF_00FF) | ((x & 0x00FF_00FF) << 8);
    x.rotate_left(16)
}

/// The scrambled value of reversed digits `x` with `seed`, mapped into the sampling
/// interval: the centre of the `2^-32` cell the digits select.
#[inline(always)]
fn sobol_q(x: u32, seed: u32, lo: f64, span: f64) -> f64 {
    let y = reverse_bits(laine_karras(x, seed));
    let u = (small_u64_to_f64(y as u64) + 0.5) * (1.0 / 4_294_967_296.0);
    lo + u * span
}

impl QStream for SobolStream {
    #[inline(always)]
    fn next_q(&mut self, b: &JointBox, q: &mut [f64]) {
        assert!(self.index < 1 << 32, "Sobol: at most 2^32 points");
        for (j, ((q, &lo), &span)) in q.iter_mut().zip(&b.lo).zip(&b.span).enumerate() {
            *q = sobol_q(self.x[j], self.seeds[j], lo, span);
        }
        self.step();
    }

    #[inline(always)]
    unsafe fn next_lanes<const AVX2: bool>(&mut self, b: &JointBox, q: &mut [Lanes], m: usize) {
        assert!(
            self.index + m as u64 <= 1 << 32,
            "Sobol: at most 2^32 points"
        );
        let mut x = [[0u32; LANES]; 32];
        if m == LANES && self.index.is_multiple_of(LANES as u64) {
            for (j, xj) in x.iter_mut().enumerate().take(q.len()) {
                for (l, v) in xj.iter_mut().enumerate() {
                    *v = self.x[j] ^ self.lane[j][l];
                }
            }
            // From point 8a to 8a + 8: X_7 (direction number 2), then the Gray step.
            self.index += LANES as u64 - 1;
            for (a, b) in self.x.iter_mut().zip(&self.v[2]) {
                *a ^= b;
            }
            self.step();
        } else {
            for l in 0..m {
                for (j, xj) in x.iter_mut().enumerate().take(q.len()) {
                    xj[l] = self.x[j];
                }
                self.step();
            }
            for xj in x.iter_mut() {
                let last = xj[m - 1];
                xj[m..].fill(last);
            }
        }
        #[cfg(target_arch = "x86_64")]
        if AVX2 {
            return self.map_lanes_avx2(b, &x, q);
        }
        for (j, (lanes, xj)) in q.iter_mut().zip(&x).enumerate() {
            let (lo, span, seed) = (b.lo[j], b.span[j], self.seeds[j]);
            for (v, &xl) in lanes.iter_mut().zip(xj) {
                *v = sobol_q(xl, seed, lo, span);
            }
        }
    }
}

impl SobolStream {
    /// [`sobol_q`] on eight lanes per coordinate with AVX2 intrinsics (the compiler
    /// leaves the portable loop scalar): the same integer operations, the conversion of
    /// [`small_u64_to_f64`], the same floating-point operations in the same order.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn map_lanes_avx2(&self, b: &JointBox, x: &[[u32; LANES]; 32], q: &mut [Lanes]) {
        use std::arch::x86_64::*;
        let c = |v: u32| _mm256_set1_epi32(v as i32);
        let swap = |v: __m256i, mask: u32, sh: i32| {
            let m = c(mask);
            let hi = _mm256_and_si256(_mm256_srl_epi32(v, _mm_cvtsi32_si128(sh)), m);
            let lo = _mm256_sll_epi32(_mm256_and_si256(v, m), _mm_cvtsi32_si128(sh));
            _mm256_or_si256(hi, lo)
        };
        const TWO_52: f64 = 4_503_599_627_370_496.0;
        let magic = _mm256_set1_epi64x(TWO_52.to_bits() as i64);
        let two_52 = _mm256_set1_pd(TWO_52);
        let half = _mm256_set1_pd(0.5);
        let scale = _mm256_set1_pd(1.0 / 4_294_967_296.0);
        for (j, lanes) in q.iter_mut().enumerate() {
            let mut v = _mm256_loadu_si256(x[j].as_ptr() as *const __m256i);
            v = _mm256_add_epi32(v, c(self.seeds[j]));
            for m in LAINE_KARRAS {
                v = _mm256_xor_si256(v, _mm256_mullo_epi32(v, c(m)));
            }
            v = swap(v, 0x5555_5555, 1);
            v = swap(v, 0x3333_3333, 2);
            v = swap(v, 0x0F0F_0F0F, 4);
            v = swap(v, 0x00FF_00FF, 8);
            v = _mm256_or_si256(_mm256_srli_epi32::<16>(v), _mm256_slli_epi32::<16>(v));
            let halves = [
                _mm256_cvtepu32_epi64(_mm256_castsi256_si128(v)),
                _mm256_cvtepu32_epi64(_mm256_extracti128_si256::<1>(v)),
            ];
            let (lo, span) = (_mm256_set1_pd(b.lo[j]), _mm256_set1_pd(b.span[j]));
            for (h, w) in halves.into_iter().enumerate() {
                let f = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(w, magic)), two_52);
                let u = _mm256_mul_pd(_mm256_add_pd(f, half), scale);
                let qv = _mm256_add_pd(lo, _mm256_mul_pd(u, span));
                _mm256_storeu_pd(lanes.as_mut_ptr().add(4 * h), qv);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::workspace::sample_stream::*;
    use crate::workspace::sobol::Sobol;

    fn unit_box(d: usize) -> JointBox {
        JointBox {
            lo: (0..d).map(|k| -1.0 - k as f64).collect(),
            span: (0..d).map(|k| 2.0 + k as f64).collect(),
        }
    }

    /// `next_lanes` gives bitwise the values of single draws, for batches aligned on
    /// eight and not, full and partial, from streams started anywhere.
    fn lanes_match_single_draws<S: QStream>(make: impl Fn(u64) -> S, d: usize) {
        lanes_match::<S, false>(&make, d);
        #[cfg(target_arch = "x86_64")]
        if is_x86_feature_detected!("avx2") {
            lanes_match::<S, true>(&make, d);
        }
    }

    fn lanes_match<S: QStream, const AVX2: bool>(make: &impl Fn(u64) -> S, d: usize) {
        let b = unit_box(d);
        for start in [0u64, 3, 8, 1000, (1 << 20) - 5] {
            let (mut single, mut lanes) = (make(start), make(start));
            let mut q = vec![[0.0; LANES]; d];
            let mut row = vec![0.0; d];
            for m in [8usize, 8, 5, 8, 1, 8, 8, 3, 8] {
                // SAFETY: AVX2 only when detected.
                unsafe { lanes.next_lanes::<AVX2>(&b, &mut q, m) };
                for l in 0..LANES {
                    if l < m {
                        single.next_q(&b, &mut row);
                    }
                    for (lanes, v) in q.iter().zip(&row) {
                        assert_eq!(
                            lanes[l].to_bits(),
                            v.to_bits(),
                            "start {start} m {m} AVX2 {AVX2}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn exact_conversions_are_the_casts() {
        let mut r = 0x0123_4567_89AB_CDEFu64;
        for _ in 0..10_000 {
            let v = r >> 11;
            assert_eq!(unit_f64(r), v as f64 * (1.0 / 9_007_199_254_740_992.0));
            assert_eq!(small_u64_to_f64(r >> 32), (r >> 32) as f64);
            r = mix64(r);
        }
        for x in [0u64, 1, (1 << 53) - 1, 1 << 52, (1 << 52) + 1] {
            let f = small_u64_to_f64(x >> 1) * 2.0 + small_u64_to_f64(x & 1);
            assert_eq!(f, x as f64);
        }
    }

    #[test]
    fn reverse_bits_by_masks_is_the_intrinsic() {
        let mut x = 0x1234_5678u32;
        for _ in 0..1000 {
            assert_eq!(reverse_bits(x), x.reverse_bits());
            x = x.wrapping_mul(0x9E37_79B9).wrapping_add(0x7F4A_7C15);
        }
    }

    #[test]
    fn batched_draws_match_single_draws() {
        lanes_match_single_draws(|s| RandomStream::new(7, 2, 6, s), 6);
        lanes_match_single_draws(|s| SobolStream::new(7, 2, 6, s), 6);
        lanes_match_single_draws(|s| SobolStream::new(9, 0, 31, s), 31);
    }

    /// The bit-reversed Sobol' stream gives the owen-scrambled points of the reference
    /// [`Sobol`] generator, mapped to the box.
    #[test]
    fn sobol_stream_is_the_scrambled_sequence() {
        let d = 7;
        let b = unit_box(d);
        for start in [0u64, 5, 4096] {
            let seeds: Vec<u32> = (0..d as u64)
                .map(|j| derive_seed(11, 3, 1000 + j) as u32)
                .collect();
            let mut reference = Sobol::scrambled(&seeds, start);
            let mut s = SobolStream::new(11, 3, d, start);
            let (mut x, mut q) = (vec![0u32; d], vec![0.0; d]);
            for _ in 0..100 {
                reference.next_u32(&mut x);
                s.next_q(&b, &mut q);
                for k in 0..d {
                    let u = (x[k] as f64 + 0.5) / 4_294_967_296.0;
                    assert_eq!(q[k], b.lo[k] + u * b.span[k]);
                }
            }
        }
    }
}
