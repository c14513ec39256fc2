//! The circular eccentric cam (docs/reference_data.md §M3, CM-1 and CM-5): a disc of radius
//! `R` whose centre `A` turns at eccentricity `a` about the cam axis `O`, at
//! `A = (−a sin φ, −a cos φ)` (the follower at its lowest at `φ = 0`).
//!
//! - Translating knife/roller at offset `e`: the follower point lies on the circle of
//!   radius `R + r_r` about `A`: `y = −a cos φ + √((R + r_r)² − (e + a sin φ)²)`,
//!   `s = y − y(0)`, `sin α = (e + a sin φ)/(R + r_r)` (centred: `AB − (R + r_r − a)`).
//! - Translating flat face: `s = a (1 − cos φ)`, `α = 0`.
//! - Oscillating flat face, pivot `C` at distance `d` from `O`, face at distance `f` from
//!   `C` (O and C on one side): `d sin θ + a sin(φ − θ) = R − f`, solved for the face angle
//!   `θ` by Newton from the previous angle; the pressure angle is between the face normal
//!   and the velocity of the contact point as a point of the follower.

/// The follower on an eccentric cam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EccentricFollower {
    /// Translating knife (roller 0) or roller, offset `e`.
    Translating {
        /// Offset.
        offset: f64,
        /// Roller radius.
        roller: f64,
    },
    /// Translating flat face.
    Flat,
    /// Oscillating flat face: pivot distance `d`, face offset `f` from the pivot.
    OscillatingFlat {
        /// Pivot distance.
        pivot: f64,
        /// Face offset.
        face_offset: f64,
    },
}

/// An eccentric cam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eccentric {
    /// Disc radius `R`.
    pub radius: f64,
    /// Eccentricity `a`.
    pub eccentricity: f64,
    /// Follower.
    pub follower: EccentricFollower,
}

/// Displacement (mm, or the face angle θ in rad) and pressure angle (rad) at `φ`;
/// `theta_prev` seeds the oscillating solve.
pub fn eval(c: &Eccentric, phi: f64, theta_prev: f64) -> Option<(f64, f64)> {
    let (r, a) = (c.radius, c.eccentricity);
    match c.follower {
        EccentricFollower::Translating { offset, roller } => {
            let rp = r + roller;
            let y = |p: f64| {
                let d = rp * rp - (offset + a * p.sin()).powi(2);
                (d >= 0.0).then(|| -a * p.cos() + d.sqrt())
            };
            Some((y(phi)? - y(0.0)?, ((offset + a * phi.sin()) / rp).asin()))
        }
        EccentricFollower::Flat => Some((a * (1.0 - phi.cos()), 0.0)),
        EccentricFollower::OscillatingFlat {
            pivot: d,
            face_offset: f,
        } => {
            let g = |t: f64| d * t.sin() + a * (phi - t).sin() - (r - f);
            let dg = |t: f64| d * t.cos() - a * (phi - t).cos();
            let mut t = theta_prev;
            for _ in 0..50 {
                let step = g(t) / dg(t);
                t -= step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
            if g(t).abs() > 1e-9 {
                return None;
            }
            // C at the origin, O at (−d, 0), A = O + a (cos φ, sin φ), face normal
            // n = (−sin θ, cos θ), face n·p = −f; contact K = A − R n.
            let n = [-t.sin(), t.cos()];
            let aa = [-d + a * phi.cos(), a * phi.sin()];
            let k = [aa[0] - r * n[0], aa[1] - r * n[1]];
            let v = [-k[1], k[0]];
            let cosang = (n[0] * v[0] + n[1] * v[1]).abs() / (v[0] * v[0] + v[1] * v[1]).sqrt();
            Some((t, cosang.clamp(0.0, 1.0).acos()))
        }
    }
}

/// The starting face angle of an oscillating flat follower at `φ = 0`:
/// `(d − a) sin θ = R − f`.
pub fn initial_theta(c: &Eccentric) -> f64 {
    match c.follower {
        EccentricFollower::OscillatingFlat { pivot, face_offset } => ((c.radius - face_offset)
            / (pivot - c.eccentricity))
            .clamp(-1.0, 1.0)
            .asin(),
        _ => 0.0,
    }
}
