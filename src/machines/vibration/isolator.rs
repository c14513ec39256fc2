//! Vibration isolation (docs/reference_data.md §M8; textbook vol. 2 ch. 17): the 1-DOF mount
//! an arm base or a machine stands on, its transmissibility with viscous or hysteretic
//! (rubber) damping, isolator selection, shock mounts, and the dynamic absorber.
//!
//! Notation: `p² = c/m`, damping ratio `ε = b/(2 m p)`, frequency ratio `q = ω/p`.
//!
//! - Force (and base-motion) transmissibility (17.19):
//!   `TR = sqrt(1 + 4ε²q²) / sqrt((1 − q²)² + 4ε²q²)`, one at `q = 0` and `q = √2`;
//!   peak at `q* = sqrt(2/(1 + sqrt(1 + 8ε²)))` (17.20). Amplitude `A c/P0 = 1/sqrt(…)`,
//!   peak at `q = sqrt(1 − 2ε²)`. Rubber: `ε = ε0/q`.
//! - Rotating unbalance `P0 = m0 a ω²`, `Q = m0 a p²`: `R0/Q = q² TR(q)` (17.27).
//! - Impact (velocity `v`, `ε = sin θ`): `R(t) = (m p v / cos θ) e^{−p t sin θ}
//!   sin(p t cos θ + 2θ)`; `R_max = m p v exp(−(π/2 − 3θ) tan θ)` for `ε < 0.5`, else
//!   `2 ε m p v` (17.42–17.44); the optimum solves `sin 2θ + 2θ = π/3`.
//!   A blow `m1 v1` on the mounted mass `m2` gives it `v = (1 + λ) m1 v1/(m1 + m2)`.
//! - Absorber (`m_a = μ m`, tuning `f = p_a/p`, damping ratio `ζ = b/(2 m_a p)`):
//!   Den Hartog's amplitude of the main mass, the invariant points (roots of
//!   `(2 + μ) q⁴ − 2 [f²(1 + μ) + 1] q² + 2 f² = 0`), equal heights at `f = 1/(1 + μ)`,
//!   optimum damping `sqrt(3μ/(8 (1 + μ)³))`, rigid absorber resonance `1/sqrt(1 + μ)`.

use nalgebra::{Complex, Matrix2, Vector2};
use std::f64::consts::PI;

/// Force transmissibility with viscous damping ratio `eps`.
pub fn transmissibility(q: f64, eps: f64) -> f64 {
    ((1.0 + 4.0 * eps * eps * q * q) / ((1.0 - q * q).powi(2) + 4.0 * eps * eps * q * q)).sqrt()
}

/// Force transmissibility of a hysteretic (rubber) mount with `ε = eps0/q`.
pub fn transmissibility_hysteretic(q: f64, eps0: f64) -> f64 {
    ((1.0 + 4.0 * eps0 * eps0) / ((1.0 - q * q).powi(2) + 4.0 * eps0 * eps0)).sqrt()
}

/// Amplitude factor `A c / P0`.
pub fn amplitude_factor(q: f64, eps: f64) -> f64 {
    1.0 / ((1.0 - q * q).powi(2) + 4.0 * eps * eps * q * q).sqrt()
}

/// `(q*, TR(q*))`: the transmissibility peak (17.20).
pub fn transmissibility_peak(eps: f64) -> (f64, f64) {
    let q = (2.0 / (1.0 + (1.0 + 8.0 * eps * eps).sqrt())).sqrt();
    (q, transmissibility(q, eps))
}

/// `(q, A c/P0)` at the amplitude peak (`eps < 1/√2`).
pub fn amplitude_peak(eps: f64) -> (f64, f64) {
    let q = (1.0 - 2.0 * eps * eps).max(0.0).sqrt();
    (q, amplitude_factor(q, eps))
}

/// `R0/Q = q² TR(q)`: the force transmitted by a rotating unbalance.
pub fn unbalance_force_ratio(q: f64, eps: f64) -> f64 {
    q * q * transmissibility(q, eps)
}

/// The smallest `q > √2` with `TR(q) ≤ target` (bisection; closed form
/// `sqrt(1 + 1/TR)` when undamped). `None` unless `0 < target < 1`.
pub fn required_ratio(target: f64, eps: f64) -> Option<f64> {
    if !(target > 0.0 && target < 1.0) {
        return None;
    }
    if eps == 0.0 {
        return Some((1.0 + 1.0 / target).sqrt());
    }
    let (mut lo, mut hi) = (2f64.sqrt(), 2f64.sqrt());
    while transmissibility(hi, eps) > target {
        hi *= 2.0;
        if hi > 1e9 {
            return None;
        }
    }
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if transmissibility(m, eps) > target {
            lo = m;
        } else {
            hi = m;
        }
    }
    Some(hi)
}

/// Transmitted force of an impact mount: `R(t)/(m p v)`.
pub fn impact_force(pt: f64, eps: f64) -> f64 {
    let th = eps.asin();
    (-pt * th.sin()).exp() * (pt * th.cos() + 2.0 * th).sin() / th.cos()
}

/// `R_max/(m p v)` in closed form (17.44).
pub fn impact_peak(eps: f64) -> f64 {
    if eps >= 0.5 {
        2.0 * eps
    } else {
        let th = eps.asin();
        (-(PI / 2.0 - 3.0 * th) * th.tan()).exp()
    }
}

/// `(R_max/(m p v), p t at the maximum)` by RK4 of `x'' + 2ε x' + x = 0`, `x(0) = 0`,
/// `x'(0) = 1` (time in `1/p`), `R = x + 2ε x'`, over two undamped periods.
pub fn impact_peak_by_integration(eps: f64, steps: usize) -> (f64, f64) {
    let h = 4.0 * PI / steps as f64;
    let f = |x: f64, v: f64| (v, -x - 2.0 * eps * v);
    let (mut x, mut v, mut t) = (0.0, 1.0, 0.0);
    let mut best = (2.0 * eps, 0.0);
    for _ in 0..steps {
        let (k1x, k1v) = f(x, v);
        let (k2x, k2v) = f(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
        let (k3x, k3v) = f(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
        let (k4x, k4v) = f(x + h * k3x, v + h * k3v);
        x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
        v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        t += h;
        let r = x + 2.0 * eps * v;
        if r > best.0 {
            best = (r, t);
        }
    }
    best
}

/// The optimum impact damping: `θ` with `sin 2θ + 2θ = π/3`, returned as `(θ, ε = sin θ)`.
pub fn impact_optimum() -> (f64, f64) {
    let (mut lo, mut hi) = (0.0, PI / 6.0);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if (2.0 * m).sin() + 2.0 * m < PI / 3.0 {
            lo = m;
        } else {
            hi = m;
        }
    }
    (lo, lo.sin())
}

/// Speed given to a mounted mass `m2` by a blow of `m1` at `v1` (17.55).
pub fn impact_velocity(m1: f64, v1: f64, m2: f64, lambda: f64) -> f64 {
    (1.0 + lambda) * m1 * v1 / (m1 + m2)
}

/// Den Hartog's amplitude `A c / P0` of the main mass with an absorber of mass ratio
/// `mu`, tuning `f` and damping ratio `zeta` (`b = 2 ζ m_a p`: Den Hartog's
/// `c_c = 2 m Ω_n` with the absorber's mass and the main system's frequency), at `q`.
pub fn absorber_amplitude(q: f64, mu: f64, f: f64, zeta: f64) -> f64 {
    let (g2, f2) = (q * q, f * f);
    let num = (2.0 * zeta * q).powi(2) + (g2 - f2).powi(2);
    let den = (2.0 * zeta * q).powi(2) * (g2 - 1.0 + mu * g2).powi(2)
        + (mu * f2 * g2 - (g2 - 1.0) * (g2 - f2)).powi(2);
    (num / den).sqrt()
}

/// The same amplitude by solving the two-mass system directly (complex 2 × 2): main
/// mass 1, stiffness 1, absorber `mu`, spring `mu f²`, damper `2 mu zeta` (time in `1/p`).
pub fn absorber_amplitude_direct(q: f64, mu: f64, f: f64, zeta: f64) -> f64 {
    let ka = mu * f * f;
    let cb = Complex::new(ka, 2.0 * mu * zeta * q);
    let a = Matrix2::new(
        Complex::new(1.0 - q * q, 0.0) + cb,
        -cb,
        -cb,
        Complex::new(-mu * q * q, 0.0) + cb,
    );
    let rhs = Vector2::new(Complex::new(1.0, 0.0), Complex::new(0.0, 0.0));
    a.lu().solve(&rhs).map_or(f64::INFINITY, |x| x[0].norm())
}

/// The absorber's characteristic values.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AbsorberDesign {
    /// Mass ratio `μ`.
    pub mass_ratio: f64,
    /// Equal-height tuning `1/(1 + μ)`.
    pub optimum_tuning: f64,
    /// Den Hartog's optimum damping ratio.
    pub optimum_damping: f64,
    /// Invariant points `q1 < q2` for the tuning used.
    pub invariant_points: [f64; 2],
    /// `A c / P0` there (`1/|1 − (1 + μ) q²|`).
    pub invariant_heights: [f64; 2],
    /// Resonance with a rigidly coupled absorber, `1/sqrt(1 + μ)`.
    pub rigid_resonance: f64,
}

/// The absorber of mass ratio `mu` tuned to `f`.
pub fn absorber(mu: f64, f: f64) -> AbsorberDesign {
    let (a, b, c) = (2.0 + mu, -2.0 * (f * f * (1.0 + mu) + 1.0), 2.0 * f * f);
    let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
    let (r1, r2) = ((-b - disc) / (2.0 * a), (-b + disc) / (2.0 * a));
    let (q1, q2) = (r1.sqrt(), r2.sqrt());
    let h = |q: f64| 1.0 / (1.0 - (1.0 + mu) * q * q).abs();
    AbsorberDesign {
        mass_ratio: mu,
        optimum_tuning: 1.0 / (1.0 + mu),
        optimum_damping: (3.0 * mu / (8.0 * (1.0 + mu).powi(3))).sqrt(),
        invariant_points: [q1, q2],
        invariant_heights: [h(q1), h(q2)],
        rigid_resonance: 1.0 / (1.0 + mu).sqrt(),
    }
}
