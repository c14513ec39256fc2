//! Involute functions (docs/reference_data.md §M2): `inv x = tan x − x` and its inverse,
//! tooth thickness at any radius, the point where a tooth becomes pointed, and points of
//! the involute flank.

/// `inv x = tan x − x` (radians).
pub fn inv(x: f64) -> f64 {
    x.tan() - x
}

/// The angle in `[0, π/2)` whose involute function is `v ≥ 0` (Newton from a cube-root
/// start; converges to machine precision in a few steps).
pub fn inv_inverse(v: f64) -> f64 {
    if v <= 0.0 {
        return 0.0;
    }
    // inv x ≈ x³/3 for small x.
    let mut x = (3.0 * v).cbrt().min(1.4);
    for _ in 0..60 {
        let t = x.tan();
        // d/dx (tan x − x) = tan² x.
        let dx = (t - x - v) / (t * t).max(1e-300);
        x = (x - dx).clamp(1e-12, std::f64::consts::FRAC_PI_2 - 1e-9);
        if dx.abs() < 1e-16 {
            break;
        }
    }
    x
}

/// The involute of base radius `r_b` at the radius `r_y ≥ r_b`: pressure angle
/// `cos α_y = r_b/r_y`, involute function (the polar angle from the involute's start)
/// `θ_y = inv α_y = tan α_y − α_y`, roll angle `tan α_y` (the base-circle arc unwound,
/// over `r_b`) and radius of curvature `ρ_y = r_b tan α_y = √(r_y² − r_b²)` (the length
/// of the generating line from its tangent point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InvoluteAt {
    /// `r_y`.
    pub radius: f64,
    /// `α_y` (rad).
    pub pressure_angle: f64,
    /// `inv α_y` (rad).
    pub involute: f64,
    /// `tan α_y` (rad).
    pub roll_angle: f64,
    /// `ρ_y`.
    pub curvature_radius: f64,
}

/// See [`InvoluteAt`]; `None` inside the base circle (no involute there).
pub fn involute_at(rb: f64, ry: f64) -> Option<InvoluteAt> {
    if !(ry >= rb && rb > 0.0) {
        return None;
    }
    let alpha = (rb / ry).acos();
    Some(InvoluteAt {
        radius: ry,
        pressure_angle: alpha,
        involute: inv(alpha),
        roll_angle: alpha.tan(),
        curvature_radius: (ry * ry - rb * rb).sqrt(),
    })
}

/// Thickness (arc) at radius `ry ≥ rb` of a tooth whose thickness at the pitch radius `r`
/// is `s`: `s_y = 2 r_y (s/(2r) + inv α − inv α_y)`, `cos α_y = r_b/r_y`.
pub fn thickness_at(s: f64, r: f64, rb: f64, ry: f64) -> f64 {
    let alpha = (rb / r).acos();
    let ay = (rb / ry).clamp(-1.0, 1.0).acos();
    2.0 * ry * (s / (2.0 * r) + inv(alpha) - inv(ay))
}

/// Thickness (arc) at radius `ry ≥ rb` of an internal gear's tooth whose thickness at the
/// pitch radius `r` is `s`: the tooth is the space of an external involute, so it thins
/// towards the centre, `s_y = 2 r_y (s/(2r) − inv α + inv α_y)`.
pub fn internal_thickness_at(s: f64, r: f64, rb: f64, ry: f64) -> f64 {
    let alpha = (rb / r).acos();
    let ay = (rb / ry).clamp(-1.0, 1.0).acos();
    2.0 * ry * (s / (2.0 * r) - inv(alpha) + inv(ay))
}

/// The root of `f` in `[lo, hi]` by bisection (`f(lo)`, `f(hi)` of opposite signs).
pub fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> Option<f64> {
    let (mut flo, fhi) = (f(lo), f(hi));
    if !(flo.is_finite() && fhi.is_finite()) || flo * fhi > 0.0 {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let fm = f(mid);
        if (fm < 0.0) == (flo < 0.0) {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-14 * (1.0 + lo.abs()) {
            break;
        }
    }
    Some(0.5 * (lo + hi))
}

/// `n` points `(x, y)` of one involute flank from the base circle (or `r_from`, if
/// larger) to `r_to`, the tooth's centre line along +y: the right flank of a tooth of
/// half-angle `s/(2r) + inv α` at the base.
pub fn flank_points(s: f64, r: f64, rb: f64, r_from: f64, r_to: f64, n: usize) -> Vec<[f64; 2]> {
    let half_base = s / (2.0 * r) + inv((rb / r).acos());
    let r0 = r_from.max(rb);
    (0..n)
        .map(|k| {
            let ry = r0 + (r_to - r0) * k as f64 / (n.max(2) - 1) as f64;
            let ay = (rb / ry).clamp(-1.0, 1.0).acos();
            let phi = half_base - inv(ay);
            [ry * phi.sin(), ry * phi.cos()]
        })
        .collect()
}
