//! Disc cams driven by a motion law (docs/reference_data.md §M3): the follower displacement,
//! the pitch and working profiles in the cam frame, their radii of curvature, the
//! pressure angle over the whole turn, and the minimum base radius and best offset by
//! search (the admissible region of CAMLAN's `s–s'` diagram).
//!
//! Frames: the cam turns by `φ` about the origin; the fixed frame has the translating
//! follower's axis along +y at offset `e` (x), or the oscillating follower's pivot at
//! `(d, 0)`. A cam-frame point is `R(−φ) p`. With `q(φ)` the follower point in the fixed
//! frame, the pitch curve is `P = R(−φ) q`, `P' = R(−φ)(q' − J q)`,
//! `P'' = R(−φ)(q'' − 2J q' − q)` (`J` the quarter turn), and its radius of curvature is
//! `ρ = −|P'|³ / (P' × P'')` (positive where the cam is convex).
//!
//! A flat face whose normal is inclined by `β` to the stroke touches the cam where its
//! support function `p = cos β (R_b / cos β + s)` says: `ρ = p + p_θθ = R_b + cos β (s + s'')`
//! and the pressure angle is `β` throughout.

use crate::machines::cams::laws::Displacement;

/// The follower.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CamFollower {
    /// Translating knife-edge (`roller = 0`) or roller, axis offset `e`, pitch-circle
    /// (prime) radius `r0`.
    Translating {
        /// Offset `e`.
        offset: f64,
        /// Roller radius (0 = knife edge).
        roller: f64,
        /// Base (prime) radius of the pitch curve.
        r0: f64,
    },
    /// Translating flat face, base radius `rb` of the profile; the face's normal is
    /// inclined by `face_angle` to the stroke (0: a face perpendicular to the stroke).
    Flat {
        /// Base radius: the face's distance from the cam centre at `s = 0`.
        rb: f64,
        /// Inclination `β` of the face normal to the stroke (rad): the pressure angle.
        face_angle: f64,
    },
    /// Oscillating knife-edge or roller: arm `l`, pivot at distance `d`; the motion's
    /// stroke is the swing in radians.
    Oscillating {
        /// Arm.
        arm: f64,
        /// Pivot distance.
        pivot: f64,
        /// Roller radius (0 = knife edge).
        roller: f64,
        /// Base (prime) radius.
        r0: f64,
    },
}

/// One sample of the turn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CamSample {
    /// Cam angle (rad).
    pub phi: f64,
    /// `[s, s', s'', s''']` (mm or rad, per radian of cam angle).
    pub s: [f64; 4],
    /// CamFollower point (pitch curve) in the cam frame.
    pub pitch: [f64; 2],
    /// Working profile point in the cam frame.
    pub working: [f64; 2],
    /// Pressure angle (rad; signed for translating followers by the book's formula).
    pub pressure_angle: f64,
    /// Radius of curvature of the pitch curve (flat face: of the profile).
    pub rho_pitch: f64,
    /// Radius of curvature of the working profile.
    pub rho_working: f64,
}

/// `R(φ) p`: `p` turned counter-clockwise by `φ`.
pub(crate) fn rot(phi: f64, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = phi.sin_cos();
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

/// `J p` (a quarter turn counter-clockwise).
fn jay(p: [f64; 2]) -> [f64; 2] {
    [-p[1], p[0]]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// CamFollower point and its first two derivatives in φ (fixed frame), with the follower's
/// direction of motion.
fn follower_point(f: &CamFollower, s: [f64; 4]) -> ([f64; 2], [f64; 2], [f64; 2], [f64; 2]) {
    match *f {
        CamFollower::Translating { offset, r0, .. } => {
            let s0 = (r0 * r0 - offset * offset).max(0.0).sqrt();
            ([offset, s0 + s[0]], [0.0, s[1]], [0.0, s[2]], [0.0, 1.0])
        }
        CamFollower::Flat { rb, face_angle } => {
            // The face's support function p = cos β (y₀ + s) with y₀ = R_b / cos β; the
            // contact point is p n + (dp/dθ) t, n = (sin β, cos β), dθ = −dφ.
            let (sb, cb) = face_angle.sin_cos();
            let y = rb / cb + s[0];
            let at = |a: f64, b: f64| [cb * (a * sb + b * cb), cb * (a * cb - b * sb)];
            (at(y, s[1]), at(s[1], s[2]), at(s[2], s[3]), [0.0, 1.0])
        }
        CamFollower::Oscillating { arm, pivot, r0, .. } => {
            let c0 = ((arm * arm + pivot * pivot - r0 * r0) / (2.0 * arm * pivot)).clamp(-1.0, 1.0);
            let psi = c0.acos() + s[0];
            let (sn, cs) = psi.sin_cos();
            let q = [pivot - arm * cs, arm * sn];
            let dq = [arm * sn, arm * cs];
            let q1 = [dq[0] * s[1], dq[1] * s[1]];
            let q2 = [
                arm * cs * s[1] * s[1] + dq[0] * s[2],
                -arm * sn * s[1] * s[1] + dq[1] * s[2],
            ];
            (q, q1, q2, dq)
        }
    }
}

/// The pitch/working point, curvature and pressure angle at `φ`.
pub fn sample(m: &(impl Displacement + ?Sized), f: &CamFollower, phi: f64) -> CamSample {
    let s = m.eval(phi);
    let (q, q1, q2, dir) = follower_point(f, s);
    let jq = jay(q);
    let a = [q1[0] - jq[0], q1[1] - jq[1]];
    let jq1 = jay(q1);
    let b = [q2[0] - 2.0 * jq1[0] - q[0], q2[1] - 2.0 * jq1[1] - q[1]];
    let na = (a[0] * a[0] + a[1] * a[1]).sqrt();
    let k = cross(a, b);
    let rho = match *f {
        // The profile is the envelope of the face: ρ = R_b + s + s'' (signed). The
        // contact point's own curve runs backwards where ρ < 0 (a swallowtail), so its
        // parametric curvature would only give |ρ| there.
        CamFollower::Flat { rb, face_angle } => rb + face_angle.cos() * (s[0] + s[2]),
        _ if k.abs() < 1e-300 => f64::INFINITY,
        _ => -na.powi(3) / k,
    };
    let roller = match *f {
        CamFollower::Translating { roller, .. } | CamFollower::Oscillating { roller, .. } => roller,
        CamFollower::Flat { .. } => 0.0,
    };
    // Outward normal of the pitch curve, in the fixed frame: J t.
    let t = [a[0] / na, a[1] / na];
    let n = jay(t);
    let w = [q[0] - roller * n[0], q[1] - roller * n[1]];
    let pressure = match *f {
        CamFollower::Translating { offset, r0, .. } => {
            let s0 = (r0 * r0 - offset * offset).max(0.0).sqrt();
            ((s[1] - offset) / (s[0] + s0)).atan()
        }
        CamFollower::Flat { face_angle, .. } => face_angle,
        CamFollower::Oscillating { .. } => {
            let dn = (dir[0] * dir[0] + dir[1] * dir[1]).sqrt();
            ((n[0] * dir[0] + n[1] * dir[1]).abs() / dn)
                .clamp(0.0, 1.0)
                .acos()
        }
    };
    CamSample {
        phi,
        s,
        pitch: rot(-phi, q),
        working: rot(-phi, w),
        pressure_angle: pressure,
        rho_pitch: rho,
        rho_working: rho - roller,
    }
}

/// The pressure angle from the geometry alone (a second route): the angle between the
/// pitch curve's normal and the follower's direction of motion, from finite differences of
/// the cam-frame pitch curve.
pub fn pressure_angle_numeric(m: &(impl Displacement + ?Sized), f: &CamFollower, phi: f64) -> f64 {
    let h = 1e-5;
    let p = |x: f64| sample(m, f, x).pitch;
    let (pa, pb) = (p(phi - h), p(phi + h));
    let tc = [(pb[0] - pa[0]) / (2.0 * h), (pb[1] - pa[1]) / (2.0 * h)];
    let t = rot(phi, tc);
    let n = jay(t);
    let (_, _, _, dir) = follower_point(f, m.eval(phi));
    let c = (n[0] * dir[0] + n[1] * dir[1])
        / ((n[0] * n[0] + n[1] * n[1]).sqrt() * (dir[0] * dir[0] + dir[1] * dir[1]).sqrt());
    c.abs().clamp(0.0, 1.0).acos()
}

/// Smallest prime radius of a translating knife/roller follower with offset `e` that
/// keeps `|α| ≤ α_rise` while rising and `≤ α_return` while returning:
/// `s₀ ≥ |s' − e|/tan α − s` at every sample, `r₀ = √(s₀² + e²)`.
pub fn min_prime_radius(
    m: &(impl Displacement + ?Sized),
    e: f64,
    alpha_rise: f64,
    alpha_return: f64,
    n: usize,
) -> f64 {
    let mut s0: f64 = 1e-9;
    for k in 0..n {
        let phi = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
        let s = m.eval(phi);
        let lim = if s[1] >= 0.0 {
            alpha_rise
        } else {
            alpha_return
        };
        s0 = s0.max((s[1] - e).abs() / lim.tan() - s[0]);
    }
    (s0 * s0 + e * e).sqrt()
}

/// The offset that minimises [`min_prime_radius`] (ternary search over `|e| ≤ max|s'|`),
/// with that radius.
pub fn optimum_offset(
    m: &(impl Displacement + ?Sized),
    alpha_rise: f64,
    alpha_return: f64,
    n: usize,
) -> (f64, f64) {
    let vmax = (0..n)
        .map(|k| m.eval(2.0 * std::f64::consts::PI * k as f64 / n as f64)[1].abs())
        .fold(0.0, f64::max);
    let r = |e: f64| min_prime_radius(m, e, alpha_rise, alpha_return, n);
    let (mut lo, mut hi) = (-vmax, vmax);
    for _ in 0..100 {
        let (a, b) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if r(a) <= r(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    let e = 0.5 * (lo + hi);
    (e, r(e))
}

/// Smallest base radius of a flat-faced translating follower whose face normal is inclined
/// by `face_angle` to the stroke: `ρ = R_b + cos β (s + s'') ≥ 0`, so
/// `R_b ≥ cos β max(−(s + s''))`, sampled `n` times per turn plus both sides of every
/// breakpoint of the motion.
pub fn min_flat_base_radius(m: &(impl Displacement + ?Sized), face_angle: f64, n: usize) -> f64 {
    let mut phis: Vec<f64> = (0..n)
        .map(|k| 2.0 * std::f64::consts::PI * k as f64 / n as f64)
        .collect();
    let eps = 1e-9;
    for b in m.breakpoints() {
        phis.push((b - eps).rem_euclid(2.0 * std::f64::consts::PI));
        phis.push(b + eps);
    }
    phis.iter()
        .map(|&p| {
            let s = m.eval(p);
            -(s[0] + s[2])
        })
        .fold(f64::NEG_INFINITY, f64::max)
        * face_angle.cos()
}
