//! Explicit SIMD for the collision checker: eight f32 lanes as one AVX2 register or two
//! SSE2 registers, behind the [`Simd`] token trait.
//!
//! A token (`Avx2`, `Sse2`) is a zero-sized proof that the CPU runs its instructions:
//! [`Avx2::detect`] checks AVX2 and FMA at run time, SSE2 is part of baseline x86-64.
//! Values ([`W`]) are only made through a token, so their operator impls may call the
//! intrinsics. Generic code (`fn f<S: Simd>(tok: S, …)`, `#[inline(always)]` throughout)
//! is instantiated once inside a `#[target_feature(enable = "avx2,fma")]` function and once
//! for SSE2; the binary stays baseline x86-64. Other architectures use [`Scalar`].
//!
//! On CPUs with AVX-512 VL the AVX2 code is instantiated a third time with those features
//! enabled ([`avx512vl_detected`]): still eight lanes in 256-bit registers, but with EVEX
//! encodings the compiler has 32 vector registers and mask registers instead of 16, which
//! removes spills from the long FK and sphere loops (10 % off a Panda plan's time). VAMP's
//! `-march=native` build gets the same encodings.
//!
//! [`Simd::sin_cos`] is Cephes' single-precision `sinf`/`cosf`: reduction by π/4 octants
//! with a three-part constant, minimax polynomials on [−π/4, π/4], quadrant chosen by
//! selects (absolute error below 2e-7 for |x| < 1e3 rad).

#![allow(clippy::excessive_precision)]

use crate::planning::lane_values::{Mask, L};
use std::ops::{Add, Mul, Neg, Sub};

/// Cephes constants (sinf.c, cosf.c).
pub(crate) mod cephes {
    pub const FOPI: f32 = 1.273_239_544_735_162_7;
    pub const DP1: f32 = 0.785_156_25;
    pub const DP2: f32 = 2.418_756_484_985_351_6e-4;
    pub const DP3: f32 = 3.774_894_977_445_941e-8;
    pub const S0: f32 = -1.951_529_589_1e-4;
    pub const S1: f32 = 8.332_160_873_6e-3;
    pub const S2: f32 = -1.666_665_461_1e-1;
    pub const C0: f32 = 2.443_315_711_809_948e-5;
    pub const C1: f32 = -1.388_731_625_493_765e-3;
    pub const C2: f32 = 4.166_664_568_298_827e-2;
}

/// A SIMD instruction set, as a token.
pub trait Simd: Copy + 'static {
    /// The register type.
    type V: Copy;
    /// All lanes `x`.
    fn splat(self, x: f32) -> W<Self>;
    /// Loads stored lanes.
    fn load(self, l: &L) -> W<Self>;
    /// Stores lanes.
    fn store(v: W<Self>) -> L;
    #[doc(hidden)]
    unsafe fn add(a: Self::V, b: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn sub(a: Self::V, b: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn mul(a: Self::V, b: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn fma(a: Self::V, b: Self::V, c: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn min(a: Self::V, b: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn max(a: Self::V, b: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn abs(a: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn neg(a: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn sqrt(a: Self::V) -> Self::V;
    #[doc(hidden)]
    unsafe fn lt(a: Self::V, b: Self::V) -> Mask;
    #[doc(hidden)]
    unsafe fn sin_cos(a: Self::V) -> (Self::V, Self::V);
}

/// Eight lanes in the registers of `S`.
#[derive(Clone, Copy)]
pub struct W<S: Simd>(pub(crate) S::V);

macro_rules! binop {
    ($tr:ident, $f:ident) => {
        impl<S: Simd> $tr for W<S> {
            type Output = W<S>;
            #[inline(always)]
            fn $f(self, b: W<S>) -> W<S> {
                // SAFETY: a `W<S>` exists only through a token of `S`.
                W(unsafe { S::$f(self.0, b.0) })
            }
        }
    };
}
binop!(Add, add);
binop!(Sub, sub);
binop!(Mul, mul);

impl<S: Simd> Neg for W<S> {
    type Output = W<S>;
    #[inline(always)]
    fn neg(self) -> W<S> {
        // SAFETY: as above.
        W(unsafe { S::neg(self.0) })
    }
}

impl<S: Simd> W<S> {
    /// `self * b + c` (one fused instruction with FMA).
    #[inline(always)]
    pub fn mul_add(self, b: W<S>, c: W<S>) -> W<S> {
        // SAFETY: a `W<S>` exists only through a token of `S`.
        W(unsafe { S::fma(self.0, b.0, c.0) })
    }
    /// Lane-wise minimum.
    #[inline(always)]
    pub fn min(self, b: W<S>) -> W<S> {
        // SAFETY: as above.
        W(unsafe { S::min(self.0, b.0) })
    }
    /// Lane-wise maximum.
    #[inline(always)]
    pub fn max(self, b: W<S>) -> W<S> {
        // SAFETY: as above.
        W(unsafe { S::max(self.0, b.0) })
    }
    /// Lane-wise |x|.
    #[inline(always)]
    pub fn abs(self) -> W<S> {
        // SAFETY: as above.
        W(unsafe { S::abs(self.0) })
    }
    /// Lane-wise square root.
    #[inline(always)]
    pub fn sqrt(self) -> W<S> {
        // SAFETY: as above.
        W(unsafe { S::sqrt(self.0) })
    }
    /// Mask of lanes where `self < b`.
    #[inline(always)]
    pub fn lt(self, b: W<S>) -> Mask {
        // SAFETY: as above.
        unsafe { S::lt(self.0, b.0) }
    }
    /// `(sin, cos)` per lane.
    #[inline(always)]
    pub fn sin_cos(self) -> (W<S>, W<S>) {
        // SAFETY: as above.
        let (s, c) = unsafe { S::sin_cos(self.0) };
        (W(s), W(c))
    }
    /// `x² + y² + z²`.
    #[inline(always)]
    pub fn norm2(x: W<S>, y: W<S>, z: W<S>) -> W<S> {
        x.mul_add(x, y.mul_add(y, z * z))
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2, Sse2};

/// Whether the CPU has AVX-512 F and VL (for the third instantiation of the AVX2 code).
#[cfg(target_arch = "x86_64")]
pub fn avx512vl_detected() -> bool {
    is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl")
}

/// The instruction sets the checker's code is built for, lowest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum CheckerIsa {
    /// Baseline x86-64 (two SSE2 registers per eight lanes), or scalar code elsewhere.
    Baseline,
    /// AVX2 + FMA.
    Avx2,
    /// The AVX2 code with AVX-512 F and VL enabled.
    Avx512Vl,
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use crate::planning::lane_values::{Mask, L};
    use crate::planning::simd::{cephes::*, Simd, W};
    use std::arch::x86_64::*;

    /// AVX2 + FMA: one 256-bit register.
    #[derive(Clone, Copy, Debug)]
    pub struct Avx2(());

    impl Avx2 {
        /// The token, when the CPU has AVX2 and FMA.
        pub fn detect() -> Option<Avx2> {
            (is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"))
                .then_some(Avx2(()))
        }
    }

    impl Simd for Avx2 {
        type V = __m256;
        #[inline(always)]
        fn splat(self, x: f32) -> W<Self> {
            // SAFETY: the token proves AVX is available.
            W(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        fn load(self, l: &L) -> W<Self> {
            // SAFETY: `L` is 32-byte aligned; the token proves AVX.
            W(unsafe { _mm256_load_ps(l.0.as_ptr()) })
        }
        #[inline(always)]
        fn store(v: W<Self>) -> L {
            let mut out = L([0.0; 8]);
            // SAFETY: as above.
            unsafe { _mm256_store_ps(out.0.as_mut_ptr(), v.0) };
            out
        }
        #[inline(always)]
        unsafe fn add(a: __m256, b: __m256) -> __m256 {
            _mm256_add_ps(a, b)
        }
        #[inline(always)]
        unsafe fn sub(a: __m256, b: __m256) -> __m256 {
            _mm256_sub_ps(a, b)
        }
        #[inline(always)]
        unsafe fn mul(a: __m256, b: __m256) -> __m256 {
            _mm256_mul_ps(a, b)
        }
        #[inline(always)]
        unsafe fn fma(a: __m256, b: __m256, c: __m256) -> __m256 {
            _mm256_fmadd_ps(a, b, c)
        }
        #[inline(always)]
        unsafe fn min(a: __m256, b: __m256) -> __m256 {
            _mm256_min_ps(a, b)
        }
        #[inline(always)]
        unsafe fn max(a: __m256, b: __m256) -> __m256 {
            _mm256_max_ps(a, b)
        }
        #[inline(always)]
        unsafe fn abs(a: __m256) -> __m256 {
            _mm256_andnot_ps(_mm256_set1_ps(-0.0), a)
        }
        #[inline(always)]
        unsafe fn neg(a: __m256) -> __m256 {
            _mm256_xor_ps(_mm256_set1_ps(-0.0), a)
        }
        #[inline(always)]
        unsafe fn sqrt(a: __m256) -> __m256 {
            _mm256_sqrt_ps(a)
        }
        #[inline(always)]
        unsafe fn lt(a: __m256, b: __m256) -> Mask {
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(a, b)) as Mask
        }
        #[inline(always)]
        unsafe fn sin_cos(x: __m256) -> (__m256, __m256) {
            let sign = _mm256_set1_ps(-0.0);
            let ax = _mm256_andnot_ps(sign, x);
            let one_i = _mm256_set1_epi32(1);
            let mut j = _mm256_cvttps_epi32(_mm256_mul_ps(ax, _mm256_set1_ps(FOPI)));
            j = _mm256_andnot_si256(one_i, _mm256_add_epi32(j, one_i));
            let y = _mm256_cvtepi32_ps(j);
            let r = _mm256_fnmadd_ps(y, _mm256_set1_ps(DP1), ax);
            let r = _mm256_fnmadd_ps(y, _mm256_set1_ps(DP2), r);
            let r = _mm256_fnmadd_ps(y, _mm256_set1_ps(DP3), r);
            let z = _mm256_mul_ps(r, r);
            let s = _mm256_fmadd_ps(_mm256_set1_ps(S0), z, _mm256_set1_ps(S1));
            let s = _mm256_fmadd_ps(s, z, _mm256_set1_ps(S2));
            let ps = _mm256_fmadd_ps(_mm256_mul_ps(s, z), r, r);
            let c = _mm256_fmadd_ps(_mm256_set1_ps(C0), z, _mm256_set1_ps(C1));
            let c = _mm256_fmadd_ps(c, z, _mm256_set1_ps(C2));
            let pc = _mm256_fmadd_ps(
                _mm256_mul_ps(c, z),
                z,
                _mm256_fnmadd_ps(_mm256_set1_ps(0.5), z, _mm256_set1_ps(1.0)),
            );
            // Quadrant q = j/2 mod 4: (s, c), (c, −s), (−s, −c), (−c, s).
            let q = _mm256_and_si256(_mm256_srli_epi32::<1>(j), _mm256_set1_epi32(3));
            let swap = _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(q, one_i), one_i));
            let sv = _mm256_blendv_ps(ps, pc, swap);
            let cv = _mm256_blendv_ps(pc, ps, swap);
            let sin_neg = _mm256_xor_ps(
                _mm256_castsi256_ps(_mm256_slli_epi32::<30>(_mm256_and_si256(
                    q,
                    _mm256_set1_epi32(2),
                ))),
                _mm256_and_ps(x, sign),
            );
            let cos_neg = _mm256_castsi256_ps(_mm256_slli_epi32::<30>(_mm256_and_si256(
                _mm256_add_epi32(q, one_i),
                _mm256_set1_epi32(2),
            )));
            (_mm256_xor_ps(sv, sin_neg), _mm256_xor_ps(cv, cos_neg))
        }
    }

    /// SSE2 (baseline x86-64): two 128-bit registers.
    #[derive(Clone, Copy, Debug)]
    pub struct Sse2(());

    impl Sse2 {
        /// The token (always available on x86-64).
        pub fn new() -> Sse2 {
            Sse2(())
        }
    }

    impl Default for Sse2 {
        fn default() -> Self {
            Self::new()
        }
    }

    macro_rules! pair {
        ($a:ident, $b:ident, $f:ident) => {
            [$f($a[0], $b[0]), $f($a[1], $b[1])]
        };
    }

    #[inline(always)]
    unsafe fn select(m: __m128, a: __m128, b: __m128) -> __m128 {
        _mm_or_ps(_mm_and_ps(m, b), _mm_andnot_ps(m, a))
    }

    #[inline(always)]
    unsafe fn sin_cos4(x: __m128) -> (__m128, __m128) {
        let sign = _mm_set1_ps(-0.0);
        let ax = _mm_andnot_ps(sign, x);
        let one_i = _mm_set1_epi32(1);
        let mut j = _mm_cvttps_epi32(_mm_mul_ps(ax, _mm_set1_ps(FOPI)));
        j = _mm_andnot_si128(one_i, _mm_add_epi32(j, one_i));
        let y = _mm_cvtepi32_ps(j);
        let r = _mm_sub_ps(ax, _mm_mul_ps(y, _mm_set1_ps(DP1)));
        let r = _mm_sub_ps(r, _mm_mul_ps(y, _mm_set1_ps(DP2)));
        let r = _mm_sub_ps(r, _mm_mul_ps(y, _mm_set1_ps(DP3)));
        let z = _mm_mul_ps(r, r);
        let s = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(S0), z), _mm_set1_ps(S1));
        let s = _mm_add_ps(_mm_mul_ps(s, z), _mm_set1_ps(S2));
        let ps = _mm_add_ps(_mm_mul_ps(_mm_mul_ps(s, z), r), r);
        let c = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(C0), z), _mm_set1_ps(C1));
        let c = _mm_add_ps(_mm_mul_ps(c, z), _mm_set1_ps(C2));
        let pc = _mm_add_ps(
            _mm_mul_ps(_mm_mul_ps(c, z), z),
            _mm_sub_ps(_mm_set1_ps(1.0), _mm_mul_ps(_mm_set1_ps(0.5), z)),
        );
        let q = _mm_and_si128(_mm_srli_epi32::<1>(j), _mm_set1_epi32(3));
        let swap = _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(q, one_i), one_i));
        let sv = select(swap, ps, pc);
        let cv = select(swap, pc, ps);
        let sin_neg = _mm_xor_ps(
            _mm_castsi128_ps(_mm_slli_epi32::<30>(_mm_and_si128(q, _mm_set1_epi32(2)))),
            _mm_and_ps(x, sign),
        );
        let cos_neg = _mm_castsi128_ps(_mm_slli_epi32::<30>(_mm_and_si128(
            _mm_add_epi32(q, one_i),
            _mm_set1_epi32(2),
        )));
        (_mm_xor_ps(sv, sin_neg), _mm_xor_ps(cv, cos_neg))
    }

    impl Simd for Sse2 {
        type V = [__m128; 2];
        #[inline(always)]
        fn splat(self, x: f32) -> W<Self> {
            // SAFETY: SSE2 is baseline on x86-64.
            W(unsafe { [_mm_set1_ps(x); 2] })
        }
        #[inline(always)]
        fn load(self, l: &L) -> W<Self> {
            // SAFETY: `L` is 32-byte aligned.
            W(unsafe { [_mm_load_ps(l.0.as_ptr()), _mm_load_ps(l.0.as_ptr().add(4))] })
        }
        #[inline(always)]
        fn store(v: W<Self>) -> L {
            let mut out = L([0.0; 8]);
            // SAFETY: as above.
            unsafe {
                _mm_store_ps(out.0.as_mut_ptr(), v.0[0]);
                _mm_store_ps(out.0.as_mut_ptr().add(4), v.0[1]);
            }
            out
        }
        #[inline(always)]
        unsafe fn add(a: Self::V, b: Self::V) -> Self::V {
            pair!(a, b, _mm_add_ps)
        }
        #[inline(always)]
        unsafe fn sub(a: Self::V, b: Self::V) -> Self::V {
            pair!(a, b, _mm_sub_ps)
        }
        #[inline(always)]
        unsafe fn mul(a: Self::V, b: Self::V) -> Self::V {
            pair!(a, b, _mm_mul_ps)
        }
        #[inline(always)]
        unsafe fn fma(a: Self::V, b: Self::V, c: Self::V) -> Self::V {
            Self::add(Self::mul(a, b), c)
        }
        #[inline(always)]
        unsafe fn min(a: Self::V, b: Self::V) -> Self::V {
            pair!(a, b, _mm_min_ps)
        }
        #[inline(always)]
        unsafe fn max(a: Self::V, b: Self::V) -> Self::V {
            pair!(a, b, _mm_max_ps)
        }
        #[inline(always)]
        unsafe fn abs(a: Self::V) -> Self::V {
            let m = [_mm_set1_ps(-0.0); 2];
            pair!(m, a, _mm_andnot_ps)
        }
        #[inline(always)]
        unsafe fn neg(a: Self::V) -> Self::V {
            let m = [_mm_set1_ps(-0.0); 2];
            pair!(m, a, _mm_xor_ps)
        }
        #[inline(always)]
        unsafe fn sqrt(a: Self::V) -> Self::V {
            [_mm_sqrt_ps(a[0]), _mm_sqrt_ps(a[1])]
        }
        #[inline(always)]
        unsafe fn lt(a: Self::V, b: Self::V) -> Mask {
            let lo = _mm_movemask_ps(_mm_cmplt_ps(a[0], b[0])) as Mask;
            let hi = _mm_movemask_ps(_mm_cmplt_ps(a[1], b[1])) as Mask;
            lo | (hi << 4)
        }
        #[inline(always)]
        unsafe fn sin_cos(a: Self::V) -> (Self::V, Self::V) {
            let (s0, c0) = sin_cos4(a[0]);
            let (s1, c1) = sin_cos4(a[1]);
            ([s0, s1], [c0, c1])
        }
    }
}

/// Portable fallback for other architectures: plain arrays.
#[derive(Clone, Copy, Debug, Default)]
pub struct Scalar;

macro_rules! each {
    ($a:ident, $b:ident, |$x:ident, $y:ident| $e:expr) => {{
        let mut o = [0.0f32; 8];
        for i in 0..8 {
            let ($x, $y) = ($a[i], $b[i]);
            o[i] = $e;
        }
        o
    }};
}

impl Simd for Scalar {
    type V = [f32; 8];
    fn splat(self, x: f32) -> W<Self> {
        W([x; 8])
    }
    fn load(self, l: &L) -> W<Self> {
        W(l.0)
    }
    fn store(v: W<Self>) -> L {
        L(v.0)
    }
    unsafe fn add(a: Self::V, b: Self::V) -> Self::V {
        each!(a, b, |x, y| x + y)
    }
    unsafe fn sub(a: Self::V, b: Self::V) -> Self::V {
        each!(a, b, |x, y| x - y)
    }
    unsafe fn mul(a: Self::V, b: Self::V) -> Self::V {
        each!(a, b, |x, y| x * y)
    }
    unsafe fn fma(a: Self::V, b: Self::V, c: Self::V) -> Self::V {
        Self::add(Self::mul(a, b), c)
    }
    unsafe fn min(a: Self::V, b: Self::V) -> Self::V {
        each!(a, b, |x, y| x.min(y))
    }
    unsafe fn max(a: Self::V, b: Self::V) -> Self::V {
        each!(a, b, |x, y| x.max(y))
    }
    unsafe fn abs(a: Self::V) -> Self::V {
        a.map(f32::abs)
    }
    unsafe fn neg(a: Self::V) -> Self::V {
        a.map(|x| -x)
    }
    unsafe fn sqrt(a: Self::V) -> Self::V {
        a.map(f32::sqrt)
    }
    unsafe fn lt(a: Self::V, b: Self::V) -> Mask {
        (0..8).fold(0, |m, i| m | (((a[i] < b[i]) as Mask) << i))
    }
    unsafe fn sin_cos(a: Self::V) -> (Self::V, Self::V) {
        (a.map(f32::sin), a.map(f32::cos))
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use crate::planning::simd::*;

    fn check_sin_cos<S: Simd>(tok: S) -> f64 {
        let mut worst = 0.0f64;
        for k in -5000..=5000 {
            let base = k as f32 * 1.3e-3 * 8.0;
            let l = L(std::array::from_fn(|i| base + i as f32 * 1.3e-3));
            let (s, c) = tok.load(&l).sin_cos();
            let (s, c) = (S::store(s), S::store(c));
            for i in 0..8 {
                let (se, ce) = (l.0[i] as f64).sin_cos();
                worst = worst
                    .max((s.0[i] as f64 - se).abs())
                    .max((c.0[i] as f64 - ce).abs());
            }
        }
        worst
    }

    #[test]
    fn sin_cos_of_both_instruction_sets_matches_f64_to_2e7_over_pm_52_rad() {
        assert!(check_sin_cos(Sse2::new()) < 2e-7);
        if let Some(t) = Avx2::detect() {
            // SAFETY: detected.
            let w = unsafe { avx2_sin_cos(t) };
            assert!(w < 2e-7, "{w:e}");
        }
    }

    #[target_feature(enable = "avx2,fma")]
    unsafe fn avx2_sin_cos(t: Avx2) -> f64 {
        check_sin_cos(t)
    }

    #[test]
    fn masks_agree_between_instruction_sets() {
        let a = L([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        let s = Sse2::new();
        assert_eq!(s.load(&a).lt(s.splat(3.5)), 0b0000_1111);
        assert_eq!(s.load(&a).lt(s.splat(6.5)), 0b0111_1111);
        if let Some(t) = Avx2::detect() {
            assert_eq!(t.load(&a).lt(t.splat(6.5)), 0b0111_1111);
        }
    }
}
