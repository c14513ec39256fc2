//! Fast, branch-free `sin_cos` for joint angles.
//!
//! Cody–Waite reduction by π/2 with fdlibm's three-part constant (exact products for
//! |x| < 2^19), then Cephes' minimax polynomials for sin and cos on [−π/4, π/4]
//! (≤ 1–2 ulp), with the quadrant chosen by selects rather than branches so random joint
//! angles cost no branch mispredictions. Arguments beyond 1e5 rad fall back to libm.

// The constants are quoted digit for digit from fdlibm and Cephes.
#![allow(clippy::excessive_precision)]

pub(crate) const FRAC_2_PI: f64 = std::f64::consts::FRAC_2_PI;
// fdlibm: pi/2 = PIO2_1 + PIO2_2 + PIO2_3 (33 + 33 + 53 bits).
pub(crate) const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
pub(crate) const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
pub(crate) const PIO2_3: f64 = 2.022_266_248_711_166_455_80e-21;

// Cephes sin.c coefficients.
pub(crate) const S: [f64; 6] = [
    1.589_623_015_765_465_680_60e-10,
    -2.505_074_776_285_780_728_66e-8,
    2.755_731_362_138_572_452_13e-6,
    -1.984_126_982_958_953_859_96e-4,
    8.333_333_333_322_118_588_78e-3,
    -1.666_666_666_666_663_072_95e-1,
];
pub(crate) const C: [f64; 6] = [
    -1.135_853_652_138_768_173_00e-11,
    2.087_570_084_197_473_167_78e-9,
    -2.755_731_417_929_673_881_12e-7,
    2.480_158_728_885_170_453_48e-5,
    -1.388_888_888_887_305_641_16e-3,
    4.166_666_666_666_659_292_18e-2,
];

/// `(sin x, cos x)`.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() > 1e5 || !x.is_finite() {
        return x.sin_cos();
    }
    // Round to nearest without a libm call (baseline x86-64 has no roundsd).
    const SHIFTER: f64 = 6_755_399_441_055_744.0; // 1.5 · 2^52
    let kf = (x * FRAC_2_PI + SHIFTER) - SHIFTER;
    let k = kf as i64;
    let r = ((x - kf * PIO2_1) - kf * PIO2_2) - kf * PIO2_3;
    let z = r * r;
    let ps = ((((S[0] * z + S[1]) * z + S[2]) * z + S[3]) * z + S[4]) * z + S[5];
    let s = r + r * z * ps;
    let pc = ((((C[0] * z + C[1]) * z + C[2]) * z + C[3]) * z + C[4]) * z + C[5];
    let c = 1.0 - 0.5 * z + z * z * pc;
    // Quadrant k mod 4: (s, c), (c, −s), (−s, −c), (−c, s).
    let swap = (k & 1) != 0;
    let (sv, cv) = if swap { (c, s) } else { (s, c) };
    let sin_neg = ((k & 2) as u64) << 62;
    let cos_neg = (((k + 1) & 2) as u64) << 62;
    (
        f64::from_bits(sv.to_bits() ^ sin_neg),
        f64::from_bits(cv.to_bits() ^ cos_neg),
    )
}

#[cfg(test)]
mod tests {
    use crate::core::fastmath::*;

    #[test]
    fn matches_libm_to_two_ulp_scale() {
        let mut worst = 0.0f64;
        let n = 2_000_000;
        for i in 0..=n {
            let x = -50.0 + 100.0 * (i as f64) / (n as f64);
            let (s, c) = sin_cos(x);
            let (se, ce) = x.sin_cos();
            worst = worst.max((s - se).abs()).max((c - ce).abs());
        }
        assert!(worst < 4.5e-16, "worst abs error {worst:e}");
        // Quadrant boundaries and special values.
        for x in [
            0.0,
            -0.0,
            1e-300,
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI,
            -std::f64::consts::PI,
            1e5,
            -1e5,
            1e6,
            3.0e9,
        ] {
            let (s, c) = sin_cos(x);
            let (se, ce) = x.sin_cos();
            assert!((s - se).abs() < 1e-15 && (c - ce).abs() < 1e-15, "{x}");
        }
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
    }
}
