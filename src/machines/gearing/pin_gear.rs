//! Pin gearing (lantern gear; ch. 8): a pin wheel of `z₁` round pins of radius `r_c`
//! on its pitch circle `r₁` meshes with a gear of `z₂` teeth. Relative to the gear, a pin
//! centre traces the epicycloid of the pin wheel's pitch circle rolling outside the gear's
//! (`ρ = r₁` on `r = r₂`, [`super::cycloids`]); the tooth space is everything the pin
//! sweeps, so the flank is the inner equidistant of that epicycloid at `r_c`, with the
//! pin's own circle at the bottom of the space where the equidistant loops (near the
//! cusp the epicycloid's radius of curvature `4ρ(r + ρ) sin(θ/2)/(r + 2ρ)` is below
//! `r_c`).
//!
//! The space is computed as that union: at a radius `R` its half-angle is
//! `max_φ [ψ(φ) + acos((R² + e² − r_c²)/(2 R e))]` over the pin positions `φ` (gear angle
//! from the line of centres) with `|e − R| ≤ r_c`, `e = |E(φ)|`, `ψ` its polar angle. The
//! maximising `φ` is the pin in contact at that radius; where it is `0` the pin lies on
//! the line of centres at the bottom of the space (no working contact). So:
//!
//! ```text
//! r_k = m z_k/2 = p z_k/(2π),  A = r₁ + r₂,  root r_f2 = r₂ − r_c
//! pointed tip: half-angle(R) = π/z₂;  tooth thickness s(R) = R (2π/z₂ − 2 half-angle(R))
//! contact from the first working radius to the tip: ε = (φ_tip − φ_start) z₂/(2π)
//! pressure angle at a contact  α = θ/2 = (r₂ φ/r₁)/2  (θ the pin wheel's turn)
//! ```
//!
//! Contact is on one side of the line of centres only (the pin wheel's profile is its
//! pitch point), the classical property of pin gearing.

use super::cycloids::{epicycloid, epicycloid_angle_at, polar_angle};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The data of a pin pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinGearSpec {
    /// Module `p/π` (mm).
    pub module: f64,
    /// Pins `z₁` and gear teeth `z₂`.
    pub teeth: [u32; 2],
    /// Pin radius `r_c` (mm).
    pub pin_radius: f64,
    /// Tip radius of the gear (mm); `None`: the pointed tooth.
    pub tip_radius: Option<f64>,
}

/// A pin pair's geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinGearPair {
    /// Pitch radii `r₁` (pin circle) and `r₂` (mm).
    pub r: [f64; 2],
    /// Circular pitch (mm).
    pub pitch: f64,
    /// Centre distance (mm).
    pub centre_distance: f64,
    /// Root radius of the gear, `r₂ − r_c` (mm).
    pub root_radius: f64,
    /// The radius where the tooth becomes pointed (mm).
    pub pointed_tip_radius: f64,
    /// The tip radius used (mm).
    pub tip_radius: f64,
    /// Tooth thickness on the pitch circle (arc, mm).
    pub thickness_pitch: f64,
    /// Tooth thickness on the tip circle (arc, mm).
    pub thickness_tip: f64,
    /// The lowest radius of the working (enveloped) flank (mm).
    pub working_start_radius: f64,
    /// Gear angles from the line of centres where contact starts and ends (rad).
    pub contact_angles: [f64; 2],
    /// Contact ratio.
    pub contact_ratio: f64,
    /// Pressure angles at the start and the end of contact (rad).
    pub pressure_angles: [f64; 2],
}

/// The pin path and the half-angle of the tooth space at a radius.
#[derive(Clone, Copy, Debug)]
struct Space {
    r1: f64,
    r2: f64,
    rc: f64,
}

impl Space {
    /// `ψ + δ` of the pin at gear angle `phi` at radius `big_r` (−∞ if it misses).
    fn reach(&self, phi: f64, big_r: f64) -> f64 {
        let e = epicycloid(self.r2, self.r1, phi);
        let d = e[0].hypot(e[1]);
        if (d - big_r).abs() > self.rc {
            return f64::NEG_INFINITY;
        }
        let c = (big_r * big_r + d * d - self.rc * self.rc) / (2.0 * big_r * d);
        polar_angle(e) + c.clamp(-1.0, 1.0).acos()
    }

    /// `(half-angle, φ of the pin in contact)` at radius `big_r`: the pins that reach
    /// that radius are those with `|e − R| ≤ r_c`, an interval of `φ` since `e` grows with
    /// `φ` along the half arch; it is sampled and the best sample refined.
    fn half_angle(&self, big_r: f64) -> (f64, f64) {
        const N: usize = 720;
        let (r1, r2, rc) = (self.r1, self.r2, self.rc);
        let lo_r = (big_r - rc).max(r2);
        let hi_r = (big_r + rc).min(r2 + 2.0 * r1);
        let at = |x: f64| epicycloid_angle_at(r2, r1, x).unwrap_or(PI) * r1 / r2;
        let (lo, hi) = (at(lo_r), at(hi_r));
        let mut best = (self.reach(0.0, big_r), 0.0);
        if lo_r > hi_r {
            return best;
        }
        let mut k_best = None;
        for k in 0..=N {
            let phi = lo + (hi - lo) * k as f64 / N as f64;
            let v = self.reach(phi, big_r);
            if v > best.0 {
                (best, k_best) = ((v, phi), Some(k));
            }
        }
        let Some(k) = k_best else {
            return best;
        };
        // Golden-section refinement between the neighbours of the best sample.
        let step = (hi - lo) / N as f64;
        let (mut a, mut b) = (
            lo + step * k.saturating_sub(1) as f64,
            lo + step * (k + 1).min(N) as f64,
        );
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..60 {
            let (x1, x2) = (b - g * (b - a), a + g * (b - a));
            if self.reach(x1, big_r) >= self.reach(x2, big_r) {
                b = x2;
            } else {
                a = x1;
            }
        }
        let mid = 0.5 * (a + b);
        let v = self.reach(mid, big_r);
        if v > best.0 {
            best = (v, mid);
        }
        best
    }
}

/// Bisection for the root of an increasing `f` on `[lo, hi]`.
fn bisect(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if f(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Checks a spec, naming the key at fault: `0 < r_c < p/4`, a tip above the working
/// flank's start and at most the pointed tip.
pub fn check(spec: &PinGearSpec) -> Result<(), (&'static str, String)> {
    let p = PI * spec.module;
    if !(spec.pin_radius > 0.0 && spec.pin_radius < p / 4.0) {
        return Err((
            "pin_radius",
            format!(
                "must be between 0 and a quarter of the pitch p/4 = {:.4} mm (a pin takes \
                 twice its radius of the pitch, the tooth the rest)",
                p / 4.0
            ),
        ));
    }
    let g = pin_pair(spec);
    let no_flank = g.thickness_pitch.is_nan() || g.thickness_pitch <= 0.0;
    if no_flank || g.working_start_radius.is_nan() || g.working_start_radius >= g.pointed_tip_radius
    {
        return Err((
            "pin_radius",
            format!(
                "the pins leave no working flank: the tooth is pointed at {:.4} mm, below \
                 the working flank's start {:.4} mm",
                g.pointed_tip_radius, g.working_start_radius
            ),
        ));
    }
    if let Some(ra) = spec.tip_radius {
        if !(ra > g.working_start_radius && ra <= g.pointed_tip_radius * (1.0 + 1e-9)) {
            return Err((
                "tip_radius",
                format!(
                    "must lie above the working flank's start {:.4} mm and at most at the \
                     pointed tip {:.4} mm",
                    g.working_start_radius, g.pointed_tip_radius
                ),
            ));
        }
    }
    Ok(())
}

/// The pair's geometry (module docs); call [`check`] first.
pub fn pin_pair(spec: &PinGearSpec) -> PinGearPair {
    let m = spec.module;
    let r = spec.teeth.map(|z| m * z as f64 / 2.0);
    let rc = spec.pin_radius;
    let z2 = spec.teeth[1] as f64;
    let sp = Space {
        r1: r[0],
        r2: r[1],
        rc,
    };
    let top = r[1] + 2.0 * r[0] + rc;
    let pointed = bisect(r[1], top, |x| sp.half_angle(x).0 >= PI / z2);
    let ra = spec.tip_radius.unwrap_or(pointed).min(pointed);
    // The working flank starts where the contact leaves the line of centres.
    // (A pin within a thousandth of its arch from the line of centres counts as on it:
    // the reach is flat there and rounding would decide.)
    let on_line = 1e-3 * PI * r[0] / r[1];
    let start = bisect(r[1] - rc, pointed, |x| sp.half_angle(x).1 > on_line);
    // A contact that leaves the line of centres continuously (thin pins: no loop in the
    // equidistant) starts on it; one that jumps starts at the jump.
    let phi_start = Some(sp.half_angle(start + 1e-9 * r[1]).1)
        .filter(|&phi| phi > 2.0 * on_line)
        .unwrap_or(0.0);
    let phi_end = sp.half_angle(ra).1;
    let thick = |x: f64| x * (TAU / z2 - 2.0 * sp.half_angle(x).0);
    let alpha = |phi: f64| r[1] * phi / r[0] / 2.0;
    PinGearPair {
        r,
        pitch: PI * m,
        centre_distance: r[0] + r[1],
        root_radius: r[1] - rc,
        pointed_tip_radius: pointed,
        tip_radius: ra,
        thickness_pitch: thick(r[1]),
        thickness_tip: thick(ra).max(0.0),
        working_start_radius: start,
        contact_angles: [phi_start, phi_end],
        contact_ratio: (phi_end - phi_start) * z2 / TAU,
        pressure_angles: [alpha(phi_start), alpha(phi_end)],
    }
}

/// The right flank of one gear tooth (tooth centre line on +y) from the root to the tip:
/// `n` radii, each at the tooth's half-angle `π/z₂ − half-angle of the space`.
pub fn pin_gear_flank(spec: &PinGearSpec, g: &PinGearPair, n: usize) -> Vec<[f64; 2]> {
    let n = n.max(2);
    let sp = Space {
        r1: g.r[0],
        r2: g.r[1],
        rc: spec.pin_radius,
    };
    let z2 = spec.teeth[1] as f64;
    (0..n)
        .map(|i| {
            let x = g.root_radius + (g.tip_radius - g.root_radius) * i as f64 / (n - 1) as f64;
            let half = sp.half_angle(x).0.max(0.0);
            let a = FRAC_PI_2 - (PI / z2 - half).max(0.0);
            [x * a.cos(), x * a.sin()]
        })
        .collect()
}

/// One pin of the pin wheel drawn as a tooth (centre line on +y): its right half circle,
/// bottom to top.
pub fn pin_outline(g: &PinGearPair, pin_radius: f64, n: usize) -> Vec<[f64; 2]> {
    let n = n.max(2);
    (0..n)
        .map(|i| {
            let a = -FRAC_PI_2 + PI * i as f64 / (n - 1) as f64;
            [pin_radius * a.cos(), g.r[0] + pin_radius * a.sin()]
        })
        .collect()
}
