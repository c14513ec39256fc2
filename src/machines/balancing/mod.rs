//! Balancing: rotor correction masses and slider-crank counterweights.
//!
//! **Rotors** (Norton, *Design of Machinery*, §§12.1–12.4; Shigley & Uicker, *Theory of
//! Machines and Mechanisms*, ch. 15). A mass `m_i` at radius `r_i`, angle `φ_i` and
//! axial position `z_i` has the unbalance `U_i = m_i r_i (cos φ_i, sin φ_i)` (kg m).
//! - Single plane (static): one correction `U_c = −Σ U_i`.
//! - Two planes `L`, `R` (dynamic): moments about `L` give
//!   `U_R (z_R − z_L) = −Σ U_i (z_i − z_L)`, forces `U_L = −Σ U_i − U_R`; each
//!   correction mass is `|U| / r` at the angle of `U`.
//! - Bearing loads at speed `ω` (bearings `A`, `B`): `F_B (z_B − z_A) = ω² Σ U_i (z_i − z_A)`,
//!   `F_A = ω² Σ U_i − F_B` ([`bearing_forces`]).
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
//! A second counterweight on the rod beyond the crank pin balances it fully
//! ([`slider_crank_full_balance`]).

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

/// Dynamic bearing loads of a rigid rotor turning at `ω` in bearings at `z_a`, `z_b`:
/// each mass pulls with `F_i = m_i r_i ω²` (turning with the rotor); moments about `A`
/// give `F_B (z_B − z_A) = Σ F_i (z_i − z_A)`, forces `F_A = Σ F_i − F_B`. Returns the
/// forces the shaft puts on the bearings `A`, `B` (the reactions are their opposites).
pub fn bearing_forces(masses: &[RotorMass], omega: f64, za: f64, zb: f64) -> [Vec2; 2] {
    let (f, m) = resultant(masses, za);
    let w2 = omega * omega;
    let b = m * (w2 / (zb - za));
    [f * w2 - b, b]
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

/// Full static balancing of a slider-crank by two counterweights (Lanchester's method;
/// Shigley & Uicker §16.4): the total centre of mass stays at the crank pivot, so the
/// shaking force vanishes at any speed. In the rod's frame (origin at the crank pin `B`)
/// the rod and the slider (its mass at the piston pin `C`) have the first moment
/// `S = m₂ c₂ + m₃ C`; a mass `m_r = |S|/e` at `−e S/|S|` (distance `e` beyond the crank
/// pin) brings their centre of mass to `B`. Then in the crank's frame (origin at the pivot
/// `O`) `T = m₁ c₁ + (m₂ + m₃ + m_r) B`, and `m_c = |T|/ρ` at `−ρ T/|T|` brings everything
/// to `O`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FullBalance {
    /// Rod counterweight mass `m_r` (kg).
    pub rod_mass: f64,
    /// Its position in the rod's frame relative to the crank pin (m).
    pub rod_position: [f64; 2],
    /// Crank counterweight mass `m_c` (kg).
    pub crank_mass: f64,
    /// Its position in the crank's frame relative to the pivot (m).
    pub crank_position: [f64; 2],
}

/// See [`FullBalance`]: `crank = (m₁, c₁, B)` (the crank's centre of mass and its pin,
/// relative to the pivot), `rod = (m₂, c₂, C)` (relative to the crank pin), the slider
/// mass `m₃`, the counterweights' distances `e` (rod) and `ρ` (crank).
pub fn slider_crank_full_balance(
    crank: (f64, Vec2, Vec2),
    rod: (f64, Vec2, Vec2),
    slider_mass: f64,
    rod_radius: f64,
    crank_radius: f64,
) -> FullBalance {
    let (m1, c1, b) = crank;
    let (m2, c2, c) = rod;
    let s = c2 * m2 + c * slider_mass;
    let mr = s.norm() / rod_radius;
    let pr = if mr > 0.0 {
        -s / s.norm() * rod_radius
    } else {
        Vec2::zeros()
    };
    let t = c1 * m1 + b * (m2 + slider_mass + mr);
    let mc = t.norm() / crank_radius;
    let pc = if mc > 0.0 {
        -t / t.norm() * crank_radius
    } else {
        Vec2::zeros()
    };
    FullBalance {
        rod_mass: mr,
        rod_position: [pr.x, pr.y],
        crank_mass: mc,
        crank_position: [pc.x, pc.y],
    }
}

/// Lanchester's counter-rotating gear balancers for a slider-crank's reciprocating force
/// (its rotating masses balanced on the crank). Along the slide line that force is
/// `m_rec r ω² (cos φ + λ cos 2φ)` to first order in `λ = r/l`; a harmonic `A cos nφ` is two
/// vectors of length `A/2` turning at `±nω`, so two masses on gears turning at `±nω` (meeting
/// on the line, opposite the harmonic's peak, at `φ = 0`) cancel it with
/// `m_g r_g (nω)² = A/2`: primary (`n = 1`) `m_g r_g = m_rec r/2` per gear, secondary
/// (`n = 2`) `m_g r_g = m_rec r λ/8` per gear. Returns `[primary, secondary]` (kg m).
pub fn gear_balancers(reciprocating_mass: f64, r: f64, l: f64) -> [f64; 2] {
    let mr = reciprocating_mass * r;
    [mr / 2.0, mr * (r / l) / 8.0]
}

/// The balancers' force along the slide line at crank angle `φ` (from the line, toward the
/// slider), `−m_rec r ω² [p cos φ + s λ cos 2φ]` with `p`, `s` 1 for a pair present.
pub fn gear_balancer_force(
    m_rec: f64,
    r: f64,
    l: f64,
    omega: f64,
    phi: f64,
    pairs: [bool; 2],
) -> f64 {
    let a = m_rec * r * omega * omega;
    let p = if pairs[0] { phi.cos() } else { 0.0 };
    let s = if pairs[1] {
        r / l * (2.0 * phi).cos()
    } else {
        0.0
    };
    -a * (p + s)
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
