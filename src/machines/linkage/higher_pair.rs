//! Higher pairs (cam contacts) between two bodies of a linkage, with circular or flat
//! profiles: a disc, an eccentric or a roller is a circle (radius 0: a knife edge), a
//! flat face is a line. The geometry here is in world coordinates; the constraint rows
//! built from it are in [`crate::machines::linkage::contact_rows`].
//!
//! The pair keeps a circle of centre `c_a`, radius `r_a` on body `a` touching the profile
//! of body `b` (problem book ch. 1 and 3; Artobolevsky, *Theory of Mechanisms*, §§ 9, 13):
//!
//! - circle–circle, `d = c_a − c_b`, `n = d/|d|`: outside `Φ = |d| − (r_a + r_b)`,
//!   inside `Φ = |r_a − r_b| − |d|`, i.e. `Φ = σ (|d| − R)` with `σ = ±1`;
//! - circle–line (through `Q` with unit normal `n = A_b perp(u)`): the centre on the side
//!   `σ = ±1` of the line, `Φ = σ n · (c_a − Q) − r_a`.
//!
//! In both cases `ν = ∂Φ/∂c_a = σ n` is the common normal at the contact, pointing from
//! `b`'s profile into `a`: the constraint force on `a` is `λ ν`, so `λ > 0` presses the
//! profiles together (a real contact) and `λ < 0` would pull them (the pair opens). The
//! contact point is `c_a − r_a ν`, except for a circle `b` inside the circle `a`, where it
//! is `c_a + r_a ν`.
//!
//! **Replacement by lower pairs** (structure, ch. 1): because the profiles are circles and
//! lines, their centres of curvature at the contact are fixed in the bodies, and the pair
//! moves exactly like a fictitious binary link with revolutes at `c_a` and `c_b`
//! (circle–circle, length `R`), or a revolute at `c_a` and a prismatic pair along the
//! line (circle–line: the centre of curvature of a line is at infinity). One higher pair
//! `p₄` (one equation) becomes one link and two lower pairs: `3·1 − 2·2 = −1`, the same
//! mobility.

use crate::machines::linkage::planar::Vec2;

/// The profile of `b` in a higher pair.
#[derive(Clone, Debug, PartialEq)]
pub enum ContactProfile {
    /// A circle (disc, roller, eccentric; radius 0 is a point) in `b`'s frame.
    Circle {
        /// Centre (body frame; world for the ground).
        centre: Vec2,
        /// Radius (m, ≥ 0).
        radius: f64,
    },
    /// A straight flat face in `b`'s frame.
    Line {
        /// A point of the line.
        through: Vec2,
        /// Unit direction.
        dir: Vec2,
    },
}

/// A higher pair: the circle (`centre`, `radius`) of body `a` touches `other` on body `b`.
#[derive(Clone, Debug, PartialEq)]
pub struct HigherPair {
    /// Name (for reports).
    pub name: String,
    /// The body with the circle (a link index or [`crate::machines::linkage::GROUND`]).
    pub a: usize,
    /// Centre of `a`'s circle, in `a`'s frame.
    pub centre: Vec2,
    /// Radius of `a`'s circle (m, ≥ 0).
    pub radius: f64,
    /// The other body.
    pub b: usize,
    /// Its profile.
    pub other: ContactProfile,
    /// `σ`: circle–circle `+1` outside, `−1` inside; circle–line `+1` with the centre on
    /// the left of the line's direction, `−1` on the right.
    pub side: f64,
    /// The contact's own friction coefficient (kinetostatics with friction; `None`: the
    /// joints' coefficient, if any).
    pub friction: Option<f64>,
}

/// `b`'s profile in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WorldProfile {
    /// A circle's world centre.
    Circle(Vec2),
    /// A line's world point and unit normal `A_b perp(u)`.
    Line(Vec2, Vec2),
}

/// The contact at one position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactGeometry {
    /// `Φ` (zero when the profiles touch).
    pub gap: f64,
    /// `ν`: the unit common normal, pointing from `b`'s profile into `a`.
    pub normal: Vec2,
    /// The contact point (world).
    pub point: Vec2,
    /// Circle–circle: `|c_a − c_b|`; circle–line: `0` (unused).
    pub distance: f64,
}

impl HigherPair {
    /// The distance `R` of the centres that closes a circle–circle pair: `r_a + r_b`
    /// outside, `|r_a − r_b|` inside (`None` for a line).
    pub fn centre_distance(&self) -> Option<f64> {
        match &self.other {
            ContactProfile::Circle { radius, .. } if self.side > 0.0 => Some(self.radius + radius),
            ContactProfile::Circle { radius, .. } => Some((self.radius - radius).abs()),
            ContactProfile::Line { .. } => None,
        }
    }

    /// The contact geometry with `a`'s centre at `ca` (world) and `b`'s profile `pb`.
    pub fn geometry(&self, ca: Vec2, pb: WorldProfile) -> ContactGeometry {
        match (pb, &self.other) {
            (WorldProfile::Circle(cb), ContactProfile::Circle { radius: rb, .. }) => {
                let d = ca - cb;
                let dist = d.norm();
                let n = if dist > 0.0 {
                    d / dist
                } else {
                    Vec2::new(1.0, 0.0)
                };
                let big = self.centre_distance().unwrap_or(0.0);
                let nu = n * self.side;
                let b_inside_a = self.side < 0.0 && self.radius > *rb;
                let point = if b_inside_a {
                    ca + nu * self.radius
                } else {
                    ca - nu * self.radius
                };
                ContactGeometry {
                    gap: self.side * (dist - big),
                    normal: nu,
                    point,
                    distance: dist,
                }
            }
            (WorldProfile::Line(q, n), _) => {
                let nu = n * self.side;
                ContactGeometry {
                    gap: nu.dot(&(ca - q)) - self.radius,
                    normal: nu,
                    point: ca - nu * self.radius,
                    distance: 0.0,
                }
            }
            (WorldProfile::Circle(cb), ContactProfile::Line { .. }) => {
                unreachable!("a line profile in world form is a Line, got a circle at {cb}")
            }
        }
    }

    /// The lower pairs replacing this one: `('R', 'R')` for two circles, `('R', 'P')` for a
    /// circle on a line (the revolute on `a` at its centre, then the pair on `b`).
    pub fn replacement_kinds(&self) -> (char, char) {
        match self.other {
            ContactProfile::Circle { .. } => ('R', 'R'),
            ContactProfile::Line { .. } => ('R', 'P'),
        }
    }
}
