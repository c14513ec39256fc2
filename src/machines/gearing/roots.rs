//! Roots rotors (the lobed rotors of a Roots blower or pump; ch. 8): two equal rotors of
//! `n` lobes turning at equal and opposite speeds on pitch circles `R = A/2`. Each lobe's
//! tip is an epicycloid arch and each gap a hypocycloid arch traced by one rolling circle
//! `r` on the pitch circle ([`super::cycloids`]), so a lobe of one rotor is conjugate to
//! a gap of the other at every angle. The `2n` arches share the pitch circle:
//!
//! ```text
//! 2π r = 2π R/(2n)  ⇒  r = R/(2n),  tip R_a = R + 2r = R(1 + 1/n),  root R_f = R(1 − 1/n)
//! R_a + R_f = A (each tip sweeps the other rotor's root)
//! rotor area  A_r = π R² + n π r² [(3R + 2r) − (3R − 2r)]/R = π R² (1 + 1/(2n²))
//! per rotor and revolution the casing carries its n pockets, π R_a² − A_r;
//! displacement V = 2 (π R_a² − A_r) L,  flow Q = V n_rpm
//! ```

use super::cycloids::rotated;
use super::cycloids::{epicycloid, epicycloid_arch_area, hypocycloid, hypocycloid_arch_area};
use std::f64::consts::{FRAC_PI_2, PI};

/// The data of a Roots pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootsSpec {
    /// Lobes per rotor.
    pub lobes: u32,
    /// Centre distance `A` (mm).
    pub centre_distance: f64,
    /// Rotor length `L` (mm), for the displacement.
    pub length: Option<f64>,
    /// Speed (rpm), for the flow.
    pub speed_rpm: Option<f64>,
}

/// A Roots pair's geometry and displacement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootsPair {
    /// Pitch radius `R` (mm).
    pub pitch_radius: f64,
    /// Rolling-circle radius `r = R/(2n)` (mm).
    pub rolling_radius: f64,
    /// Tip radius, the casing bore (mm).
    pub tip_radius: f64,
    /// Root radius (mm).
    pub root_radius: f64,
    /// Rotor cross-section area (mm²).
    pub rotor_area: f64,
    /// Casing bore area `π R_a²` (mm²).
    pub bore_area: f64,
    /// One pocket between two lobes and the casing, `(π R_a² − A_r)/n` (mm²).
    pub pocket_area: f64,
    /// The rotor's share of its bore, `A_r/(π R_a²)`.
    pub fill_ratio: f64,
    /// Displacement per revolution, both rotors (mm³), with a length.
    pub displacement: Option<f64>,
    /// Flow (m³/min), with a length and a speed.
    pub flow_m3_per_min: Option<f64>,
}

/// Checks a spec, naming the key at fault.
pub fn check(spec: &RootsSpec) -> Result<(), (&'static str, String)> {
    if !(2..=12).contains(&spec.lobes) {
        return Err(("lobes", "a Roots rotor has 2 … 12 lobes".into()));
    }
    if !(spec.centre_distance > 0.0 && spec.centre_distance <= 1e7) {
        return Err(("centre_distance", "must be a positive distance (mm)".into()));
    }
    if let Some(l) = spec.length {
        if !(l > 0.0 && l <= 1e7) {
            return Err((
                "face_width",
                "the rotor length must be positive (mm)".into(),
            ));
        }
    }
    if let Some(n) = spec.speed_rpm {
        if !(n > 0.0 && n <= 1e6) {
            return Err(("speed_rpm", "must be a positive speed (rpm)".into()));
        }
        if spec.length.is_none() {
            return Err((
                "speed_rpm",
                "the flow needs the rotor length face_width (mm)".into(),
            ));
        }
    }
    Ok(())
}

/// The pair's geometry (module docs); call [`check`] first.
pub fn roots_pair(spec: &RootsSpec) -> RootsPair {
    let n = spec.lobes as f64;
    let big_r = spec.centre_distance / 2.0;
    let r = big_r / (2.0 * n);
    let ra = big_r + 2.0 * r;
    let rotor =
        PI * big_r * big_r + n * (epicycloid_arch_area(big_r, r) - hypocycloid_arch_area(big_r, r));
    let bore = PI * ra * ra;
    let displacement = spec.length.map(|l| 2.0 * (bore - rotor) * l);
    RootsPair {
        pitch_radius: big_r,
        rolling_radius: r,
        tip_radius: ra,
        root_radius: big_r - 2.0 * r,
        rotor_area: rotor,
        bore_area: bore,
        pocket_area: (bore - rotor) / n,
        fill_ratio: rotor / bore,
        displacement,
        flow_m3_per_min: displacement
            .zip(spec.speed_rpm)
            .map(|(v, rpm)| v * 1e-9 * rpm),
    }
}

/// The right flank of one lobe (lobe centre line on +y), from the middle of the gap to
/// the lobe's tip: `n` points of hypocycloid half-arch, then `n` of epicycloid half-arch.
pub fn roots_flank(g: &RootsPair, n: usize) -> Vec<[f64; 2]> {
    let n = n.max(2);
    let (big_r, r) = (g.pitch_radius, g.rolling_radius);
    let half_arch = PI * r / big_r;
    let beta0 = FRAC_PI_2 - half_arch;
    let mut out = Vec::with_capacity(2 * n);
    for i in 0..n {
        let phi = half_arch * (1.0 - i as f64 / (n - 1) as f64);
        let q = hypocycloid(big_r, r, phi);
        out.push(rotated([q[0], -q[1]], beta0));
    }
    for i in 1..=n {
        let phi = half_arch * i as f64 / n as f64;
        out.push(rotated(epicycloid(big_r, r, phi), beta0));
    }
    out
}

/// The whole rotor outline (counter-clockwise, `2n` points per flank), lobe 0 on +y.
pub fn roots_outline(g: &RootsPair, lobes: u32, n: usize) -> Vec<[f64; 2]> {
    let right = roots_flank(g, n);
    let left: Vec<[f64; 2]> = right.iter().rev().map(|p| [-p[0], p[1]]).collect();
    // One lobe counter-clockwise: the right flank up, the left flank down.
    let lobe: Vec<[f64; 2]> = right.iter().chain(left.iter().skip(1)).copied().collect();
    let step = std::f64::consts::TAU / lobes as f64;
    (0..lobes)
        .flat_map(|k| {
            lobe[..lobe.len() - 1]
                .iter()
                .map(move |&p| rotated(p, step * k as f64))
        })
        .collect()
}
