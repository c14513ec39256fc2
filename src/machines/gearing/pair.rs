//! Involute spur and helical pairs (docs/reference_data.md §M2): radii, tooth thickness,
//! profile shift, working pressure angle and centre distance, contact ratio, undercut,
//! pointed teeth and interference, for external pairs, internal pairs and a pinion with a
//! rack. Helical gears are computed in the transverse plane (`m_t = m_n / cos β`,
//! `tan α_t = tan α_n / cos β`) plus the overlap ratio `ε_β = B sin β/(π m_n)`.

use crate::machines::gearing::involute::{
    bisect, internal_thickness_at, inv, inv_inverse, thickness_at,
};
use std::f64::consts::PI;

/// Which pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairKind {
    /// Two external gears.
    External,
    /// A pinion (gear 1) inside an internal gear (gear 2).
    Internal,
    /// A pinion with a rack.
    Rack,
}

/// The data of a pair. Angles in radians, lengths in mm.
#[derive(Clone, Debug, PartialEq)]
pub struct PairSpec {
    /// Kind.
    pub kind: PairKind,
    /// Normal module.
    pub module: f64,
    /// Tooth counts (the rack's is ignored).
    pub teeth: [u32; 2],
    /// Normal pressure angle.
    pub pressure_angle: f64,
    /// Addendum coefficient `h_a*`.
    pub addendum: f64,
    /// Clearance coefficient `c*`.
    pub clearance: f64,
    /// Profile shift coefficients (the rack's is its withdrawal in modules).
    pub shift: [f64; 2],
    /// Helix angle (0 = spur).
    pub helix: f64,
    /// Face width (for the overlap ratio).
    pub face_width: Option<f64>,
    /// Mounting centre distance: `None` = without backlash for the shifts.
    pub centre_distance: Option<f64>,
}

/// One gear of a pair.
#[derive(Clone, Debug, PartialEq)]
pub struct GearGeometry {
    /// Teeth.
    pub teeth: u32,
    /// Shift coefficient.
    pub shift: f64,
    /// Pitch radius `m_t z/2`.
    pub r: f64,
    /// Base radius `r cos α_t`.
    pub rb: f64,
    /// Tip radius (with the tip reduction of a shifted pair).
    pub ra: f64,
    /// Root radius.
    pub rf: f64,
    /// Transverse tooth thickness on the pitch circle.
    pub s: f64,
    /// An internal gear (its teeth point towards the centre, its tip circle is inside).
    pub internal: bool,
    /// Tooth thickness at the tip (arc); NaN when the tip circle lies inside the base
    /// circle (no involute there).
    pub s_tip: f64,
    /// Virtual tooth count `z / cos³ β`.
    pub zv: f64,
    /// Fewest teeth without undercut by the book's rule, `round(2 h_a*/sin² α) cos³ β`.
    pub z_min: f64,
    /// Smallest shift without undercut, the book's rule `(z_min − z)/z_min` with
    /// `z_min = round(2 h_a*/sin² α) cos³ β` (17 cos³ β for 20°).
    pub x_min: f64,
    /// Undercut by that rule.
    pub undercut: bool,
    /// Undercut by the exact rack-cutter condition `(h_a* − x) m_n > r sin² α_t`.
    pub undercut_exact: bool,
    /// Shift that makes the tooth pointed with the tip radius held at the unshifted
    /// blank's `r + h_a* m`.
    pub pointed_shift_fixed_tip: Option<f64>,
    /// Shift that makes the tooth pointed when the tip grows with it, `r + (h_a* + x) m`.
    pub pointed_shift_growing_tip: Option<f64>,
    /// Root circle inside the base circle.
    pub root_inside_base: bool,
    /// Largest tip radius whose contact stays on the line of action `N₁N₂` (external
    /// pairs: `√(r_b² + N₁N₂²)`).
    pub max_tip_radius: Option<f64>,
}

/// A computed pair.
#[derive(Clone, Debug, PartialEq)]
pub struct PairGeometry {
    /// Transverse module.
    pub mt: f64,
    /// Transverse pressure angle.
    pub alpha_t: f64,
    /// Working (transverse) pressure angle.
    pub alpha_w: f64,
    /// Standard centre distance `m_t (z₁ ± z₂)/2`.
    pub a0: f64,
    /// Working centre distance.
    pub centre_distance: f64,
    /// Centre-distance factor `y = (A − a₀)/m`.
    pub y: f64,
    /// Tip reduction `Δy = x₁ + x₂ − y` (≥ 0).
    pub tip_reduction: f64,
    /// The gears (one for a rack pair).
    pub gears: Vec<GearGeometry>,
    /// Transverse pitch `π m_t` and base pitch `π m_t cos α_t`.
    pub pitch: f64,
    /// Base pitch.
    pub base_pitch: f64,
    /// Theoretical line of action `N₁N₂ = A sin α_w` (external and internal pairs).
    pub line_of_action: Option<f64>,
    /// Transverse contact ratio.
    pub eps_alpha: f64,
    /// Overlap ratio.
    pub eps_beta: f64,
    /// Tip interference: a tip reaches past the other gear's tangency point (external:
    /// `r_a > √(r_b² + N₁N₂²)`; internal: `O₂N₁ = √(r_b2² + N₁N₂²) > r_a2`).
    pub interference: bool,
    /// Internal pairs: `O₂N₁`.
    pub o2n1: Option<f64>,
    /// Internal pairs: the smallest pinion without tip interference for this ratio,
    /// exactly (`2h_a*(i + √(i² − (2i − 1) sin²α))/((2i − 1) sin²α)`) and by the book's
    /// rule `4i h_a*/((2i − 1) sin²α)`.
    pub internal_min_pinion: Option<(f64, f64)>,
}

impl PairGeometry {
    /// `ε_α + ε_β`.
    pub fn eps(&self) -> f64 {
        self.eps_alpha + self.eps_beta
    }
}

/// Checks the spec; the message names the key.
pub fn validate(p: &PairSpec) -> Result<(), (&'static str, String)> {
    let pos = |x: f64| x.is_finite() && x > 0.0;
    if !pos(p.module) {
        return Err((
            "module",
            format!("must be a positive module (mm), got {}", p.module),
        ));
    }
    if !(p.pressure_angle.is_finite() && p.pressure_angle > 0.01 && p.pressure_angle < 0.8) {
        return Err(("pressure_angle_deg", "must be between 0.6° and 45°".into()));
    }
    if !(p.helix.is_finite() && p.helix.abs() < 1.4) {
        return Err(("helix_angle_deg", "must be between −80° and 80°".into()));
    }
    if !(p.addendum.is_finite() && p.addendum > 0.0 && p.addendum < 3.0) {
        return Err(("addendum", "must be in (0, 3)".into()));
    }
    if !(p.clearance.is_finite() && (0.0..1.0).contains(&p.clearance)) {
        return Err(("clearance", "must be in [0, 1)".into()));
    }
    if p.shift.iter().any(|x| !x.is_finite() || x.abs() > 5.0) {
        return Err(("shift", "must be finite, |x| ≤ 5".into()));
    }
    let n = if p.kind == PairKind::Rack { 1 } else { 2 };
    if p.teeth[..n].iter().any(|&z| !(3..=100_000).contains(&z)) {
        return Err(("teeth", "tooth counts must be 3 … 100000".into()));
    }
    if p.kind == PairKind::Internal {
        if p.teeth[1] <= p.teeth[0] {
            return Err((
                "teeth",
                "the internal gear (second) needs more teeth than the pinion".into(),
            ));
        }
        if p.shift != [0.0, 0.0] {
            return Err(("shift", "shifted internal pairs are not supported".into()));
        }
    }
    if let Some(a) = p.centre_distance {
        if !pos(a) {
            return Err(("centre_distance", "must be a positive distance (mm)".into()));
        }
    }
    if let Some(b) = p.face_width {
        if !(b.is_finite() && b >= 0.0) {
            return Err(("face_width", "must be ≥ 0".into()));
        }
    }
    Ok(())
}

/// Book undercut rule: `z_min = round(2 h_a*/sin² α_n) cos³ β`.
pub fn z_min_book(ha: f64, alpha_n: f64, helix: f64) -> f64 {
    (2.0 * ha / alpha_n.sin().powi(2)).round() * helix.cos().powi(3)
}

/// The pointed-tooth shift of a lone gear: with the tip held at `r + h_a* m` or growing.
fn pointed_shifts(p: &PairSpec, z: f64, mt: f64, at: f64) -> (Option<f64>, Option<f64>) {
    let r = mt * z / 2.0;
    let rb = r * at.cos();
    let s = |x: f64| mt * (PI / 2.0 + 2.0 * x * p.pressure_angle.tan());
    let fixed = r + p.addendum * p.module;
    let f1 = |x: f64| thickness_at(s(x), r, rb, fixed);
    let f2 = |x: f64| thickness_at(s(x), r, rb, r + (p.addendum + x) * p.module);
    (bisect(f1, -4.0, 4.0), bisect(f2, -1.0, 6.0))
}

fn gear(p: &PairSpec, k: usize, mt: f64, at: f64, dy: f64) -> GearGeometry {
    let z = p.teeth[k] as f64;
    let x = p.shift[k];
    let m = p.module;
    let r = mt * z / 2.0;
    let rb = r * at.cos();
    let internal = p.kind == PairKind::Internal && k == 1;
    let (ra, rf) = if internal {
        (r - p.addendum * m, r + (p.addendum + p.clearance) * m)
    } else {
        (
            r + (p.addendum + x - dy) * m,
            r - (p.addendum + p.clearance - x) * m,
        )
    };
    let s = mt * (PI / 2.0 + 2.0 * x * p.pressure_angle.tan());
    let zmin = z_min_book(p.addendum, p.pressure_angle, p.helix);
    let x_min = (zmin - z) / zmin;
    let (pf, pg) = if internal {
        (None, None)
    } else {
        pointed_shifts(p, z, mt, at)
    };
    GearGeometry {
        teeth: p.teeth[k],
        shift: x,
        r,
        rb,
        ra,
        rf,
        s,
        internal,
        s_tip: if ra < rb {
            f64::NAN
        } else if internal {
            internal_thickness_at(s, r, rb, ra)
        } else {
            thickness_at(s, r, rb, ra)
        },
        zv: z / p.helix.cos().powi(3),
        z_min: zmin,
        x_min,
        undercut: !internal && x < x_min - 1e-9,
        undercut_exact: !internal && (p.addendum - x) * m > r * at.sin().powi(2) + 1e-12,
        pointed_shift_fixed_tip: pf,
        pointed_shift_growing_tip: pg,
        root_inside_base: !internal && rf < rb,
        max_tip_radius: None,
    }
}

/// Computes a pair (see the module docs). Call [`validate`] first.
pub fn pair(p: &PairSpec) -> PairGeometry {
    let cb = p.helix.cos();
    let mt = p.module / cb;
    let at = (p.pressure_angle.tan() / cb).atan();
    let [z1, z2] = [p.teeth[0] as f64, p.teeth[1] as f64];
    let pb = PI * mt * at.cos();
    match p.kind {
        PairKind::Rack => {
            let mut g = gear(p, 0, mt, at, 0.0);
            g.max_tip_radius = None;
            // Rack withdrawn by D = shift[1] m from the pinion's cutting position.
            let d = p.shift[1] * p.module;
            let eps = ((g.ra * g.ra - g.rb * g.rb).sqrt() - g.r * at.sin()
                + ((p.addendum - g.shift) * p.module - d) / at.sin())
                / pb;
            PairGeometry {
                mt,
                alpha_t: at,
                alpha_w: at,
                a0: g.r + g.shift * p.module,
                centre_distance: g.r + g.shift * p.module + d,
                y: 0.0,
                tip_reduction: 0.0,
                gears: vec![g],
                pitch: PI * mt,
                base_pitch: pb,
                line_of_action: None,
                eps_alpha: eps,
                eps_beta: eps_beta(p),
                interference: false,
                o2n1: None,
                internal_min_pinion: None,
            }
        }
        PairKind::External | PairKind::Internal => {
            let internal = p.kind == PairKind::Internal;
            let a0 = mt * if internal { z2 - z1 } else { z1 + z2 } / 2.0;
            let xs = p.shift[0] + p.shift[1];
            let (aw, a) = match p.centre_distance {
                Some(a) => (((a0 * at.cos()) / a).clamp(-1.0, 1.0).acos(), a),
                None => {
                    let aw = inv_inverse(inv(at) + 2.0 * p.pressure_angle.tan() * xs / (z1 + z2));
                    (aw, a0 * at.cos() / aw.cos())
                }
            };
            let y = (a - a0) / p.module;
            let dy = if internal { 0.0 } else { (xs - y).max(0.0) };
            let mut g1 = gear(p, 0, mt, at, dy);
            let mut g2 = gear(p, 1, mt, at, dy);
            let n1n2 = a * aw.sin();
            let l1 = (g1.ra * g1.ra - g1.rb * g1.rb).max(0.0).sqrt();
            let l2 = (g2.ra * g2.ra - g2.rb * g2.rb).max(0.0).sqrt();
            let (eps, interference, o2n1, imin) = if internal {
                let o2n1 = (g2.rb * g2.rb + n1n2 * n1n2).sqrt();
                let i = z2 / z1;
                let s2 = p.pressure_angle.sin().powi(2);
                let k = (2.0 * i - 1.0) * s2;
                let exact = 2.0 * p.addendum * (i + (i * i - k).sqrt()) / k;
                let book = 4.0 * i * p.addendum / k;
                (
                    (l1 - l2 + n1n2) / pb,
                    o2n1 > g2.ra + 1e-9,
                    Some(o2n1),
                    Some((exact, book)),
                )
            } else {
                g1.max_tip_radius = Some((g1.rb * g1.rb + n1n2 * n1n2).sqrt());
                g2.max_tip_radius = Some((g2.rb * g2.rb + n1n2 * n1n2).sqrt());
                let intf = g1.ra > g1.max_tip_radius.unwrap_or(f64::INFINITY) + 1e-9
                    || g2.ra > g2.max_tip_radius.unwrap_or(f64::INFINITY) + 1e-9;
                ((l1 + l2 - n1n2) / pb, intf, None, None)
            };
            PairGeometry {
                mt,
                alpha_t: at,
                alpha_w: aw,
                a0,
                centre_distance: a,
                y,
                tip_reduction: dy,
                gears: vec![g1, g2],
                pitch: PI * mt,
                base_pitch: pb,
                line_of_action: Some(n1n2),
                eps_alpha: eps,
                eps_beta: eps_beta(p),
                interference,
                o2n1,
                internal_min_pinion: imin,
            }
        }
    }
}

fn eps_beta(p: &PairSpec) -> f64 {
    p.face_width
        .map_or(0.0, |b| b * p.helix.sin().abs() / (PI * p.module))
}

/// Rack withdrawal that brings the contact ratio to `target`:
/// `D = (ε − target) p sin 2α / 2` (spur).
pub fn withdrawal_for(g: &PairGeometry, target: f64) -> f64 {
    (g.eps_alpha - target) * g.pitch * (2.0 * g.alpha_t).sin() / 2.0
}
