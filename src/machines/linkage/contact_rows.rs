//! The constraint row of a higher pair ([`crate::machines::linkage::higher_pair`]) in
//! body coordinates: `Φ`, its Jacobian row, `γ` of `Φ_q q̈ = γ`, and the contact's
//! point, normal and sliding velocity at a state.
//!
//! With `ν` the common normal (into `a`), `s_a` the arm of `a`'s centre `c_a` from `a`'s
//! centre of mass (`A s` world) and `ω` the angular rates:
//! - circle–circle, `Φ = σ (|d| − R)`, `d = c_a − c_b`: `Φ_q` has `[νᵀ, ν · perp(A_a s_a)]`
//!   for `a` and `[−νᵀ, −ν · perp(A_b s_b)]` for `b`;
//!   `γ = ν · (A_a s_a ω_a² − A_b s_b ω_b²) − σ (|ḋ|² − (n · ḋ)²)/|d|`
//!   (from `Φ̈ = σ (n · d̈ + (|ḋ|² − (n · ḋ)²)/|d|)`);
//! - circle–line, `Φ = ν · e − r_a`, `e = c_a − Q`, `ν = σ A_b perp(u)` turning with `b`:
//!   `[νᵀ, ν · perp(A_a s_a)]` for `a`, `[−νᵀ, perp(ν) · e − ν · perp(A_b s_Q)]` for `b`;
//!   `γ = ω_b² ν · e − 2 ω_b perp(ν) · ė + ν · (A_a s_a ω_a² − A_b s_Q ω_b²)`
//!   (the slider's point-on-line row shifted by `r_a`, Haug 1989 §3.3.3).
//!
//! The tests check `Φ_q` and `γ` against finite differences.

use crate::machines::linkage::description::{Linkage, GROUND};
use crate::machines::linkage::higher_pair::{
    ContactGeometry, ContactProfile, HigherPair, WorldProfile,
};
use crate::machines::linkage::planar::{perp, rotate, Vec2};
use nalgebra::DVector;

fn omega(qd: &DVector<f64>, b: usize) -> f64 {
    if b == GROUND {
        0.0
    } else {
        qd[3 * b + 2]
    }
}

/// `b`'s profile in world coordinates at `q`.
pub fn world_profile(l: &Linkage, q: &DVector<f64>, c: &HigherPair) -> WorldProfile {
    match &c.other {
        ContactProfile::Circle { centre, .. } => {
            WorldProfile::Circle(l.point_position(q, c.b, centre))
        }
        ContactProfile::Line { through, dir } => {
            let (_, th) = l.pose(q, c.b);
            WorldProfile::Line(l.point_position(q, c.b, through), rotate(th, &perp(dir)))
        }
    }
}

/// The contact's gap, normal and point at `q`.
pub fn geometry(l: &Linkage, q: &DVector<f64>, c: &HigherPair) -> ContactGeometry {
    c.geometry(l.point_position(q, c.a, &c.centre), world_profile(l, q, c))
}

/// The point of `b`'s profile the row refers to (a circle's centre or the line's point),
/// in `b`'s frame.
fn b_point(c: &HigherPair) -> Vec2 {
    match &c.other {
        ContactProfile::Circle { centre, .. } => *centre,
        ContactProfile::Line { through, .. } => *through,
    }
}

/// The Jacobian row of the pair: `(body, ∂Φ/∂x, ∂Φ/∂y, ∂Φ/∂θ)` for `a` and `b` (the
/// ground's entry is to be skipped by the caller).
pub fn jacobian_entries(l: &Linkage, q: &DVector<f64>, c: &HigherPair) -> [(usize, Vec2, f64); 2] {
    let g = geometry(l, q, c);
    let nu = g.normal;
    let ta = nu.dot(&perp(&l.arm(q, c.a, &c.centre)));
    let bp = b_point(c);
    let tb = match &c.other {
        ContactProfile::Circle { .. } => -nu.dot(&perp(&l.arm(q, c.b, &bp))),
        ContactProfile::Line { .. } => {
            let e = l.point_position(q, c.a, &c.centre) - l.point_position(q, c.b, &bp);
            perp(&nu).dot(&e) - nu.dot(&perp(&l.arm(q, c.b, &bp)))
        }
    };
    [(c.a, nu, ta), (c.b, -nu, tb)]
}

/// `γ` of the pair's row at `(q, q̇)`.
pub fn gamma(l: &Linkage, q: &DVector<f64>, qd: &DVector<f64>, c: &HigherPair) -> f64 {
    let g = geometry(l, q, c);
    let nu = g.normal;
    let bp = b_point(c);
    let (wa, wb) = (omega(qd, c.a), omega(qd, c.b));
    let arm_b = if c.b == GROUND {
        Vec2::zeros()
    } else {
        l.arm(q, c.b, &bp)
    };
    let arm_a = if c.a == GROUND {
        Vec2::zeros()
    } else {
        l.arm(q, c.a, &c.centre)
    };
    let centripetal = nu.dot(&(arm_a * (wa * wa) - arm_b * (wb * wb)));
    let ed = l.point_velocity(q, qd, c.a, &c.centre) - l.point_velocity(q, qd, c.b, &bp);
    match &c.other {
        ContactProfile::Circle { .. } => {
            let n = nu * c.side;
            centripetal - c.side * (ed.norm_squared() - n.dot(&ed).powi(2)) / g.distance
        }
        ContactProfile::Line { .. } => {
            let e = l.point_position(q, c.a, &c.centre) - l.point_position(q, c.b, &bp);
            wb * wb * nu.dot(&e) - 2.0 * wb * perp(&nu).dot(&ed) + centripetal
        }
    }
}

/// World velocity of the point of body `b` that is at world position `p`.
pub fn body_velocity_at(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    b: usize,
    p: &Vec2,
) -> Vec2 {
    if b == GROUND {
        return Vec2::zeros();
    }
    let (r, _) = l.pose(q, b);
    Vec2::new(qd[3 * b], qd[3 * b + 1]) + perp(&(p - r)) * qd[3 * b + 2]
}

/// The sliding velocity at the contact: the tangential component, along `perp(ν)`, of
/// `a`'s contact point's velocity relative to `b`'s.
pub fn sliding_velocity(l: &Linkage, q: &DVector<f64>, qd: &DVector<f64>, c: &HigherPair) -> f64 {
    let g = geometry(l, q, c);
    let v = body_velocity_at(l, q, qd, c.a, &g.point) - body_velocity_at(l, q, qd, c.b, &g.point);
    perp(&g.normal).dot(&v)
}

/// A world point `p` in the frame of body `b` (world for the ground).
pub fn to_body_frame(l: &Linkage, q: &DVector<f64>, b: usize, p: &Vec2) -> Vec2 {
    if b == GROUND {
        return *p;
    }
    let (r, th) = l.pose(q, b);
    rotate(-th, &(p - r)) + l.links[b].com
}
