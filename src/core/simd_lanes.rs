//! Eight `f64` values per quantity, one per SIMD lane (struct of arrays), and what every
//! lane kernel shares: the instruction sets they are compiled for ([`Isa`], detected at run
//! time; the binary stays baseline x86-64), a branch-free `sin_cos` per lane and the range
//! check it needs.
//!
//! A lane loop is a straight line over `[f64; 8]`, which the compiler turns into one
//! AVX-512 register, two AVX2 registers or four SSE2 registers. No fused multiply-add is
//! written and Rust never contracts `a * b + c`, so every instruction set gives bitwise the
//! same results. Users: batched FK ([`crate::kinematics::fk_lanes`]), the workspace
//! sampler, batched inverse dynamics ([`crate::dynamics::rnea_lanes`]).

// Lane loops index several arrays by the lane: an explicit index keeps the scalar code's
// operations visible.
#![allow(clippy::needless_range_loop)]

/// Lanes per batch.
pub const LANES: usize = 8;

/// The instruction sets the lane code is compiled for, lowest first. Every one gives
/// bitwise the same results.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum Isa {
    /// Baseline x86-64 (SSE2), or portable code elsewhere.
    #[default]
    Baseline,
    /// AVX2 + FMA (two 256-bit registers per eight `f64` lanes).
    Avx2,
    /// AVX-512 F, VL and DQ (one 512-bit register per eight `f64` lanes, 64-bit integer
    /// products for the random streams).
    Avx512,
}

impl Isa {
    /// The best instruction set this CPU supports.
    pub fn detected() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f")
                && is_x86_feature_detected!("avx512vl")
                && is_x86_feature_detected!("avx512dq")
                && is_x86_feature_detected!("avx2")
                && is_x86_feature_detected!("fma")
            {
                return Isa::Avx512;
            }
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                return Isa::Avx2;
            }
        }
        Isa::Baseline
    }

    /// The detected instruction set, at most `max` (to compare instruction sets, or to
    /// reproduce a baseline run).
    pub fn at_most(max: Option<Isa>) -> Isa {
        let best = Isa::detected();
        max.map_or(best, |m| best.min(m))
    }
}

/// Eight values, one per lane.
pub type Lanes = [f64; LANES];

/// `(sin x, cos x)` per lane, [`crate::core::fastmath::sin_cos`]'s algorithm (valid for
/// `|x| ≤ 1e5`; the caller checks).
#[inline(always)]
pub fn sin_cos8(x: &Lanes) -> (Lanes, Lanes) {
    use crate::core::fastmath::{C, FRAC_2_PI, PIO2_1, PIO2_2, PIO2_3, S};
    const SHIFTER: f64 = 6_755_399_441_055_744.0;
    let mut so = [0.0; LANES];
    let mut co = [0.0; LANES];
    for l in 0..LANES {
        let x = x[l];
        let t = x * FRAC_2_PI + SHIFTER;
        // The low mantissa bits of `t` are k (two's complement): no float-to-int
        // conversion, which AVX2 lacks for 64-bit integers.
        let kb = t.to_bits();
        let kf = t - SHIFTER;
        let r = ((x - kf * PIO2_1) - kf * PIO2_2) - kf * PIO2_3;
        let z = r * r;
        let ps = ((((S[0] * z + S[1]) * z + S[2]) * z + S[3]) * z + S[4]) * z + S[5];
        let s = r + r * z * ps;
        let pc = ((((C[0] * z + C[1]) * z + C[2]) * z + C[3]) * z + C[4]) * z + C[5];
        let c = 1.0 - 0.5 * z + z * z * pc;
        let swap = kb & 1 != 0;
        let (sv, cv) = if swap { (c, s) } else { (s, c) };
        let sin_neg = (kb & 2) << 62;
        let cos_neg = (kb.wrapping_add(1) & 2) << 62;
        so[l] = f64::from_bits(sv.to_bits() ^ sin_neg);
        co[l] = f64::from_bits(cv.to_bits() ^ cos_neg);
    }
    (so, co)
}

/// Whether every lane's joint value is in the range of the branch-free `sin_cos`
/// (`|x| ≤ 1e5`; checked on the coordinates with a margin for gear ratios and offsets),
/// and finite; the caller falls back to the scalar FK otherwise.
#[inline(always)]
pub fn lanes_in_range(q: &[Lanes]) -> bool {
    // No early exit: a straight line of compares (SIMD); NaN fails.
    let mut ok = true;
    for v in q {
        for x in v {
            ok &= x.abs() <= 1e4;
        }
    }
    ok
}

/// One lane array on a cache line of its own (64 bytes, 64-aligned: an AVX-512 load of
/// it never straddles two lines).
#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct Line(Lanes);

/// A vector of lane arrays, each cache-line aligned, read and written as `[Lanes]`.
#[derive(Clone)]
pub struct LaneBuf(Vec<Line>);

impl LaneBuf {
    /// `n` lane arrays of zeros.
    pub fn zeros(n: usize) -> LaneBuf {
        LaneBuf(vec![Line([0.0; LANES]); n])
    }
}

impl std::ops::Deref for LaneBuf {
    type Target = [Lanes];
    fn deref(&self) -> &[Lanes] {
        // SAFETY: `Line` is `repr(C)` around one `Lanes` with no padding (size 64 =
        // alignment), so `len` lines are `len` valid, more strictly aligned `Lanes`.
        unsafe { std::slice::from_raw_parts(self.0.as_ptr().cast::<Lanes>(), self.0.len()) }
    }
}

impl std::ops::DerefMut for LaneBuf {
    fn deref_mut(&mut self) -> &mut [Lanes] {
        // SAFETY: as in `deref`; the borrow of `self` is exclusive.
        unsafe { std::slice::from_raw_parts_mut(self.0.as_mut_ptr().cast::<Lanes>(), self.0.len()) }
    }
}
