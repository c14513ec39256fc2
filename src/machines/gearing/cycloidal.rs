//! Cycloidal spur pairs (ch. 8): each tooth's face (above the pitch circle) is an
//! epicycloid and its flank (below) a hypocycloid, traced by rolling circles that roll on
//! the pitch circles. The rolling circle `ρ₁` rolls inside gear 1 (tracing its flank) and
//! outside gear 2 (tracing its face); `ρ₂` the other way round. The path of contact lies
//! on the two rolling circles, so (module docs of [`super::cycloids`]):
//!
//! ```text
//! r_k = m z_k/2,  r_ak = r_k + h_a* m,  r_fk = r_k − (h_a* + c*) m,  p = π m,  s = p/2
//! on ρ₁ (gear 1 flank, gear 2 face), up to gear 2's tip:
//!     cos θ₁ = ((r₂ + ρ₁)² + ρ₁² − r_a2²)/(2ρ₁(r₂ + ρ₁)),  arc a₁ = ρ₁ θ₁
//! on ρ₂ likewise with gear 1's tip;   ε = (a₁ + a₂)/p,  α_max,k = θ_k/2
//! flank shape: ρ = r/2 radial, ρ < r/2 widening toward the root, ρ > r/2 narrowing
//! tip thickness s_a = 2 r_a (s/(2r) − δ_a), δ_a the face's polar angle at the tip
//! ```
//!
//! A face can rise only to `r + 2ρ` (the arch's top), so `h_a* m ≤ 2ρ` of the mate.

use super::cycloids::{
    epicycloid, epicycloid_angle_at, hypocycloid, hypocycloid_angle_at, polar_angle, rotated,
};
use std::f64::consts::{FRAC_PI_2, PI};

/// The data of a cycloidal pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CycloidalSpec {
    /// Module (mm).
    pub module: f64,
    /// Tooth counts.
    pub teeth: [u32; 2],
    /// Rolling-circle radii (mm): `ρ_k` rolls inside gear `k` (its flank) and outside
    /// the mate (the mate's face).
    pub rolling: [f64; 2],
    /// Addendum factor `h_a*`.
    pub addendum: f64,
    /// Clearance factor `c*`.
    pub clearance: f64,
}

/// The shape of a hypocycloidal flank.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CycloidFlank {
    /// `ρ = r/2`: a straight radial flank.
    Radial,
    /// `ρ < r/2`: the tooth widens toward the root.
    Widening,
    /// `ρ > r/2`: the tooth narrows toward the root (weak, undercut-like).
    Narrowing,
}

impl CycloidFlank {
    /// The name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Radial => "radial",
            Self::Widening => "widening",
            Self::Narrowing => "narrowing",
        }
    }
}

/// One gear of a cycloidal pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CycloidalGear {
    /// Teeth.
    pub teeth: u32,
    /// Pitch radius (mm).
    pub r: f64,
    /// Tip radius (mm).
    pub ra: f64,
    /// Root radius (mm).
    pub rf: f64,
    /// The rolling circle of the flank (mm).
    pub rho_flank: f64,
    /// The rolling circle of the face (the mate's flank circle, mm).
    pub rho_face: f64,
    /// Tooth thickness on the pitch circle (arc, mm).
    pub s: f64,
    /// Tooth thickness on the tip circle (arc, mm).
    pub s_tip: f64,
    /// Flank shape.
    pub flank: CycloidFlank,
    /// The lowest radius of the flank in contact (mm).
    pub lowest_contact: f64,
    /// The highest radius the face could reach, `r + 2ρ_face` (mm).
    pub face_limit: f64,
}

/// A cycloidal pair's geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CycloidalPair {
    /// The two gears.
    pub gears: [CycloidalGear; 2],
    /// Centre distance `r₁ + r₂` (mm).
    pub centre_distance: f64,
    /// Circular pitch (mm).
    pub pitch: f64,
    /// Rolling angles `θ₁`, `θ₂` at the ends of contact on `ρ₁`, `ρ₂` (rad).
    pub rolling_angles: [f64; 2],
    /// Arcs of action on the pitch circles along `ρ₁` and `ρ₂`, `ρ_k θ_k` (mm).
    pub arcs: [f64; 2],
    /// Transverse contact ratio.
    pub contact_ratio: f64,
    /// The largest pressure angles `θ_k/2` on each rolling circle (rad).
    pub max_pressure_angles: [f64; 2],
}

/// Checks a spec, naming the key at fault: positive module and factors, `0 < ρ_k < r_k`,
/// roots outside the centre, faces that can reach the tips, teeth not pointed.
pub fn check(spec: &CycloidalSpec) -> Result<(), (&'static str, String)> {
    let m = spec.module;
    let r = spec.teeth.map(|z| m * z as f64 / 2.0);
    if !(spec.addendum > 0.0 && spec.addendum <= 3.0) {
        return Err(("addendum", "h_a* must be in (0, 3]".into()));
    }
    if !(spec.clearance >= 0.0 && spec.clearance <= 1.0) {
        return Err(("clearance", "c* must be in [0, 1]".into()));
    }
    for (k, (&rk, &rho)) in r.iter().zip(&spec.rolling).enumerate() {
        if !(rho > 0.0 && rho < rk) {
            return Err((
                "rolling_radii",
                format!(
                    "ρ{} = {rho} mm must lie between 0 and gear {}'s pitch radius {} mm \
                     (it rolls inside that gear)",
                    k + 1,
                    k + 1,
                    rk
                ),
            ));
        }
        if rk - (spec.addendum + spec.clearance) * m <= 0.0 {
            return Err((
                "teeth",
                format!("gear {}: the root circle would pass the centre", k + 1),
            ));
        }
        if spec.addendum * m > 2.0 * rho + 1e-12 * m {
            let mate = 2 - k;
            return Err((
                "rolling_radii",
                format!(
                    "ρ{} = {rho} mm traces gear {mate}'s face only up to 2ρ = {} mm above its \
                     pitch circle; the addendum h_a* m = {} mm needs ρ{} ≥ {} mm",
                    k + 1,
                    2.0 * rho,
                    spec.addendum * m,
                    k + 1,
                    spec.addendum * m / 2.0
                ),
            ));
        }
    }
    let g = cycloidal_pair(spec);
    if let Some(k) = (0..2).find(|&k| g.gears[k].s_tip.is_nan() || g.gears[k].s_tip <= 0.0) {
        return Err((
            "addendum",
            format!(
                "gear {}'s teeth are pointed below the tip circle (tip thickness {:.4} mm); \
                 lower h_a* or change the rolling circles",
                k + 1,
                g.gears[k].s_tip
            ),
        ));
    }
    Ok(())
}

/// The pair's geometry (module docs); call [`check`] first.
pub fn cycloidal_pair(spec: &CycloidalSpec) -> CycloidalPair {
    let m = spec.module;
    let p = PI * m;
    let r = spec.teeth.map(|z| m * z as f64 / 2.0);
    let ra = r.map(|x| x + spec.addendum * m);
    let rho = spec.rolling;
    // On ρ₁ the contact runs to gear 2's tip; on ρ₂ to gear 1's.
    let theta = [
        epicycloid_angle_at(r[1], rho[0], ra[1]).unwrap_or(PI),
        epicycloid_angle_at(r[0], rho[1], ra[0]).unwrap_or(PI),
    ];
    let arcs = [rho[0] * theta[0], rho[1] * theta[1]];
    let gear = |k: usize| {
        let (rk, own, face) = (r[k], rho[k], rho[1 - k]);
        let th_face = theta[1 - k];
        let delta = polar_angle(epicycloid(rk, face, th_face * face / rk));
        let flank = if (own - rk / 2.0).abs() <= 1e-9 * rk {
            CycloidFlank::Radial
        } else if own < rk / 2.0 {
            CycloidFlank::Widening
        } else {
            CycloidFlank::Narrowing
        };
        let th = theta[k];
        CycloidalGear {
            teeth: spec.teeth[k],
            r: rk,
            ra: ra[k],
            rf: rk - (spec.addendum + spec.clearance) * m,
            rho_flank: own,
            rho_face: face,
            s: p / 2.0,
            s_tip: 2.0 * ra[k] * (p / 4.0 / rk - delta),
            flank,
            lowest_contact: ((rk - own).powi(2) + own * own + 2.0 * own * (rk - own) * th.cos())
                .sqrt(),
            face_limit: rk + 2.0 * face,
        }
    };
    CycloidalPair {
        gears: [gear(0), gear(1)],
        centre_distance: r[0] + r[1],
        pitch: p,
        rolling_angles: theta,
        arcs,
        contact_ratio: (arcs[0] + arcs[1]) / p,
        max_pressure_angles: theta.map(|t| t / 2.0),
    }
}

/// The right flank of one tooth (tooth centre line on +y), from the root circle to the
/// tip: `n` points of hypocycloid (continued radially if its arch ends above the root)
/// and `n` points of epicycloid.
pub fn cycloidal_flank(g: &CycloidalGear, n: usize) -> Vec<[f64; 2]> {
    let n = n.max(2);
    let beta0 = FRAC_PI_2 - g.s / (2.0 * g.r);
    let (r, own, face) = (g.r, g.rho_flank, g.rho_face);
    let bottom = (r - 2.0 * own).abs();
    let th_root = if g.rf <= bottom {
        PI
    } else {
        hypocycloid_angle_at(r, own, g.rf).unwrap_or(PI)
    };
    let mut out = Vec::with_capacity(2 * n + 1);
    let deepest = {
        let q = hypocycloid(r, own, th_root * own / r);
        rotated([q[0], -q[1]], beta0)
    };
    if g.rf < bottom {
        let a = polar_angle(deepest);
        out.push([g.rf * a.cos(), g.rf * a.sin()]);
    }
    for i in 0..n {
        let th = th_root * (1.0 - i as f64 / (n - 1) as f64);
        let q = hypocycloid(r, own, th * own / r);
        out.push(rotated([q[0], -q[1]], beta0));
    }
    let th_tip = epicycloid_angle_at(r, face, g.ra).unwrap_or(PI);
    for i in 1..=n {
        let th = th_tip * i as f64 / n as f64;
        out.push(rotated(epicycloid(r, face, th * face / r), beta0));
    }
    out
}
