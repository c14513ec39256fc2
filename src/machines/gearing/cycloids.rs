//! Roulettes of a circle on a circle, the curves of cycloidal, pin and Roots profiles:
//! the epicycloid and hypocycloid traced by a point of a circle of radius `ρ` rolling
//! outside or inside a circle of radius `r` centred at the origin, starting from the
//! point `(r, 0)`. `φ` is the angle the rolling circle's centre has moved round the
//! origin; the rolling circle has then turned by `θ = r φ/ρ` relative to the line of
//! centres (its *rolling angle*).
//!
//! ```text
//! epicycloid:  x = (r + ρ) cos φ − ρ cos((r + ρ)φ/ρ),  y = (r + ρ) sin φ − ρ sin((r + ρ)φ/ρ)
//! hypocycloid: x = (r − ρ) cos φ + ρ cos((r − ρ)φ/ρ),  y = (r − ρ) sin φ − ρ sin((r − ρ)φ/ρ)
//! |OP|² = (r + ρ)² + ρ² − 2ρ(r + ρ) cos θ   (epicycloid)
//! |OP|² = (r − ρ)² + ρ² + 2ρ(r − ρ) cos θ   (hypocycloid)
//! ```
//!
//! The normal at the traced point passes through the rolling circles' point of contact
//! (the instant centre), so the chord from there to the point makes the angle `θ/2` with
//! the common tangent: the pressure angle of cycloidal teeth. One arch (θ from 0 to 2π)
//! encloses with its base circle `π ρ² (3r + 2ρ)/r` (epicycloid) or `π ρ² (3r − 2ρ)/r`
//! (hypocycloid).

use std::f64::consts::PI;

/// The epicycloid's point at the centre angle `phi` (see the module docs).
pub fn epicycloid(r: f64, rho: f64, phi: f64) -> [f64; 2] {
    let k = (r + rho) / rho * phi;
    [
        (r + rho) * phi.cos() - rho * k.cos(),
        (r + rho) * phi.sin() - rho * k.sin(),
    ]
}

/// The hypocycloid's point at the centre angle `phi` (see the module docs).
pub fn hypocycloid(r: f64, rho: f64, phi: f64) -> [f64; 2] {
    let k = (r - rho) / rho * phi;
    [
        (r - rho) * phi.cos() + rho * k.cos(),
        (r - rho) * phi.sin() - rho * k.sin(),
    ]
}

/// The rolling angle `θ ∈ [0, π]` at which the epicycloid reaches the radius `radius`
/// (`r ≤ radius ≤ r + 2ρ`), or `None` outside that range.
pub fn epicycloid_angle_at(r: f64, rho: f64, radius: f64) -> Option<f64> {
    let c = ((r + rho).powi(2) + rho * rho - radius * radius) / (2.0 * rho * (r + rho));
    (-1.0 - 1e-12..=1.0 + 1e-12)
        .contains(&c)
        .then(|| c.clamp(-1.0, 1.0).acos())
}

/// The rolling angle `θ ∈ [0, π]` at which the hypocycloid reaches the radius `radius`
/// (`|r − 2ρ| ≤ radius ≤ r`), or `None` outside that range.
pub fn hypocycloid_angle_at(r: f64, rho: f64, radius: f64) -> Option<f64> {
    let c = (radius * radius - (r - rho).powi(2) - rho * rho) / (2.0 * rho * (r - rho));
    (-1.0 - 1e-12..=1.0 + 1e-12)
        .contains(&c)
        .then(|| c.clamp(-1.0, 1.0).acos())
}

/// The area between one epicycloid arch and its base circle, `π ρ² (3r + 2ρ)/r`.
pub fn epicycloid_arch_area(r: f64, rho: f64) -> f64 {
    PI * rho * rho * (3.0 * r + 2.0 * rho) / r
}

/// The area between the base circle and one hypocycloid arch, `π ρ² (3r − 2ρ)/r`.
pub fn hypocycloid_arch_area(r: f64, rho: f64) -> f64 {
    PI * rho * rho * (3.0 * r - 2.0 * rho) / r
}

/// `p` turned by `angle` about the origin.
pub fn rotated(p: [f64; 2], angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

/// The polar angle of `p`.
pub fn polar_angle(p: [f64; 2]) -> f64 {
    p[1].atan2(p[0])
}

/// The area enclosed by a closed polygon (shoelace; positive counter-clockwise).
pub fn polygon_area(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}
