//! Balancing: rotor correction masses and slider-crank counterweights.
//!
//! **Rotors** (Norton, *Design of Machinery*, §§12.1–12.4; Shigley & Uicker, *Theory of
//! Machines and Mechanisms*, ch. 15). A mass `m_i` at radius `r_i`, angle `φ_i` and
//! axial position `z_i` has the unbalance `U_i = m_i r_i (cos φ_i, sin φ_i)` (kg m).
//! - Single plane (static): one correction `U_c = −Σ U_i`.
//! - Two planes `L`, `R` (dynamic): moments about `L` give
//!   `U_R (z_R − z_L) = −Σ U_i (z_i − z_L)`, forces `U_L = −Σ U_i − U_R`; each
//!   correction mass is `|U| / r` at the angle of `U`.
//!
//! **Slider-crank** (Norton §13.2–13.4; Shigley & Uicker §16.4). The rod (mass `m₂`,
//! length `l`, centre of mass `b` from the crank pin `B`) is replaced by `m₂ (l − b)/l`
//! at `B` and `m₂ b / l` at the piston pin `C` — exact for the linear momentum, which is
//! all the shaking force depends on. The rotating mass at the crank radius `r` is
//! `m_rot = m₁ c₁ / r + m₂ (l − b)/l` (`c₁` the crank's centre of mass from its pivot),
//! the reciprocating mass `m_rec = m₃ + m₂ b / l`. A counterweight opposite the crank pin
//! with `m_cw r_cw = (m_rot + k m_rec) r` cancels the rotating force and the fraction `k`
//! of the primary reciprocating force, which it turns into a transverse force
//! `k m_rec r ω² sin φ`. The shaking force left on the frame is, exactly,
//! `F = −m_rec a_C − k m_rec r ω² (cos φ, sin φ)` at constant crank speed (crank angle
//! `φ`); `−m_rec a_C` has the primary and secondary parts
//! `m_rec r ω² (cos φ + (r/l) cos 2φ)` to first order in `r/l`.

pub mod modal;
use crate::machines::linkage::description::PlanarLink;
use crate::machines::linkage::Vec2;
use serde::Serialize;

/// A mass on a rotor.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RotorMass {
    /// Mass (kg).
    pub mass: f64,
    /// Radius (m).
    pub radius: f64,
    /// Angle (rad).
    pub angle: f64,
    /// Axial position (m).
    pub position: f64,
}

impl RotorMass {
    /// Unbalance vector `m r (cos φ, sin φ)`.
    pub fn unbalance(&self) -> Vec2 {
        Vec2::new(self.angle.cos(), self.angle.sin()) * (self.mass * self.radius)
    }
}

/// A correction mass.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Correction {
    /// Axial position of its plane (m).
    pub position: f64,
    /// Radius (m).
    pub radius: f64,
    /// Mass (kg).
    pub mass: f64,
    /// Angle (rad).
    pub angle: f64,
}

impl Correction {
    fn from_unbalance(u: Vec2, position: f64, radius: f64) -> Self {
        Self {
            position,
            radius,
            mass: u.norm() / radius,
            angle: u.y.atan2(u.x),
        }
    }

    /// As a rotor mass.
    pub fn as_mass(&self) -> RotorMass {
        RotorMass {
            mass: self.mass,
            radius: self.radius,
            angle: self.angle,
            position: self.position,
        }
    }
}

/// Resultant unbalance `Σ U_i` and its moment `Σ U_i (z_i − z_ref)`.
pub fn resultant(masses: &[RotorMass], z_ref: f64) -> (Vec2, Vec2) {
    masses
        .iter()
        .fold((Vec2::zeros(), Vec2::zeros()), |(f, m), x| {
            let u = x.unbalance();
            (f + u, m + u * (x.position - z_ref))
        })
}

/// Single-plane (static) correction at `radius` in the plane at `position`.
pub fn single_plane(masses: &[RotorMass], position: f64, radius: f64) -> Correction {
    Correction::from_unbalance(-resultant(masses, 0.0).0, position, radius)
}

/// Two-plane (dynamic) corrections in the planes `(position, radius)` `left`, `right`.
pub fn two_plane(masses: &[RotorMass], left: (f64, f64), right: (f64, f64)) -> [Correction; 2] {
    let (f, m) = resultant(masses, left.0);
    let ur = -m / (right.0 - left.0);
    let ul = -f - ur;
    [
        Correction::from_unbalance(ul, left.0, left.1),
        Correction::from_unbalance(ur, right.0, right.1),
    ]
}

/// Slider-crank mass data for counterweighting.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SliderCrankMasses {
    /// Crank radius `r` (m).
    pub crank_radius: f64,
    /// Crank mass `m₁` (kg).
    pub crank_mass: f64,
    /// Crank centre of mass from the pivot toward the pin, `c₁` (m).
    pub crank_com: f64,
    /// Rod length `l` (m).
    pub rod_length: f64,
    /// Rod mass `m₂` (kg).
    pub rod_mass: f64,
    /// Rod centre of mass from the crank pin, `b` (m).
    pub rod_com: f64,
    /// Slider mass `m₃` (kg).
    pub slider_mass: f64,
}

/// A slider-crank counterweight.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Counterweight {
    /// Rotating mass at the crank pin (kg).
    pub rotating_mass: f64,
    /// Reciprocating mass at the piston pin (kg).
    pub reciprocating_mass: f64,
    /// Fraction `k` of the reciprocating mass balanced.
    pub fraction: f64,
    /// `m_cw r_cw` (kg m).
    pub mass_radius: f64,
    /// Counterweight radius (m), opposite the crank pin.
    pub radius: f64,
    /// Counterweight mass (kg).
    pub mass: f64,
}

/// The counterweight balancing the rotating masses and fraction `k` of the reciprocating
/// mass, placed at `radius` opposite the crank pin.
pub fn slider_crank_counterweight(m: &SliderCrankMasses, k: f64, radius: f64) -> Counterweight {
    let rod_pin = m.rod_mass * (m.rod_length - m.rod_com) / m.rod_length;
    let rot = m.crank_mass * m.crank_com / m.crank_radius + rod_pin;
    let rec = m.slider_mass + m.rod_mass * m.rod_com / m.rod_length;
    let mr = (rot + k * rec) * m.crank_radius;
    Counterweight {
        rotating_mass: rot,
        reciprocating_mass: rec,
        fraction: k,
        mass_radius: mr,
        radius,
        mass: mr / radius,
    }
}

/// Adds a point mass `m` at link-frame point `p` to a link (new centre of mass, and the
/// inertia about it by the parallel-axis theorem).
pub fn add_point_mass(link: &mut PlanarLink, m: f64, p: Vec2) {
    let m0 = link.mass;
    let total = m0 + m;
    if total == 0.0 {
        return;
    }
    let c = (link.com * m0 + p * m) / total;
    link.inertia += m0 * (link.com - c).norm_squared() + m * (p - c).norm_squared();
    link.com = c;
    link.mass = total;
}
