//! Two-position synthesis of a four-bar (problem book ch. 7):
//!
//! - **By two crank/rocker position pairs** with the frame `d` and one more link given.
//!   Freudenstein's equation `K1 cos ψ − K2 cos φ + K3 = cos(φ − ψ)` has three unknowns;
//!   with the rocker `c` given, `K2 = d/c` is known and the two pairs give the linear
//!   2 × 2 system `K1 cos ψ_i + K3 = cos(φ_i − ψ_i) + K2 cos φ_i`; with the crank `a`
//!   given, `K1 = d/a` is known and `−K2 cos φ_i + K3 = cos(φ_i − ψ_i) − K1 cos ψ_i`.
//!   Then `a = d/K1`, `c = d/K2`, `b² = a² + c² + d² − 2 a c K3`.
//! - **By two positions of the coupler** `B₁C₁`, `B₂C₂` (body guidance): the fixed pivot
//!   `A` of the crank is equidistant from `B₁` and `B₂`, so it lies on their perpendicular
//!   bisector, and `D` on that of `C₁C₂`; with the fixed pivots on a given line (the
//!   frame line of the drawing) each is where its bisector crosses the line. Then
//!   `a = |AB₁|`, `b = |B₁C₁|`, `c = |DC₁|`, `d = |AD|`.

use super::{fail, four_bar_from_coefficients, SynthesisError};
use crate::machines::linkage::{cross, wrap_angle, Vec2};

/// The link given beside the frame in a two-position function synthesis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GivenLink {
    /// The crank `a`.
    Crank(f64),
    /// The rocker `c`.
    Rocker(f64),
}

/// A four-bar from two crank/rocker position pairs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TwoPositionFourBar {
    /// Freudenstein's `[K1, K2, K3]`.
    pub coefficients: [f64; 3],
    /// Crank `a = d/K1` (signed: negative points the other way).
    pub crank: f64,
    /// Coupler `b`.
    pub coupler: f64,
    /// Rocker `c = d/K2` (signed).
    pub rocker: f64,
    /// Frame `d`.
    pub frame: f64,
}

/// The four-bar of frame `d` through the two `(φ, ψ)` pairs `points` (rad), with the link
/// `given` (Freudenstein's convention: `A` at the origin, `D = (d, 0)`).
pub fn four_bar_from_two_positions(
    points: [(f64, f64); 2],
    d: f64,
    given: GivenLink,
) -> Result<TwoPositionFourBar, SynthesisError> {
    // Rows `[p_i, 1] · [x, K3] = r_i`, x the unknown of K1 / K2.
    let row = |(phi, psi): (f64, f64)| -> (f64, f64) {
        match given {
            GivenLink::Rocker(c) => (psi.cos(), (phi - psi).cos() + d / c * phi.cos()),
            GivenLink::Crank(a) => (-phi.cos(), (phi - psi).cos() - d / a * psi.cos()),
        }
    };
    let ((p1, r1), (p2, r2)) = (row(points[0]), row(points[1]));
    let det = p1 - p2;
    if det.abs() <= 1e-9 {
        return fail(match given {
            GivenLink::Rocker(_) => {
                "the two rocker angles have equal cosines: K1 is not determined"
            }
            GivenLink::Crank(_) => "the two crank angles have equal cosines: K2 is not determined",
        });
    }
    let x = (r1 - r2) / det;
    let k3 = r1 - p1 * x;
    let k = match given {
        GivenLink::Rocker(c) => [x, d / c, k3],
        GivenLink::Crank(a) => [d / a, x, k3],
    };
    let b = four_bar_from_coefficients(k, d)?[1];
    Ok(TwoPositionFourBar {
        coefficients: k,
        crank: d / k[0],
        coupler: b,
        rocker: d / k[1],
        frame: d,
    })
}

/// The largest relative difference of the two given coupler lengths.
pub const MAX_COUPLER_MISMATCH: f64 = 0.01;

/// A four-bar that carries its coupler through two given positions.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CouplerGuidance {
    /// Crank pivot `A`.
    pub crank_pivot: [f64; 2],
    /// Rocker pivot `D`.
    pub rocker_pivot: [f64; 2],
    /// Crank `|AB|`.
    pub crank: f64,
    /// Coupler `|BC|` (the mean of the two positions).
    pub coupler: f64,
    /// `(|B₂C₂| − |B₁C₁|)/|B₁C₁|`: zero for exact data, at most 1 %.
    pub coupler_mismatch: f64,
    /// Rocker `|DC|`.
    pub rocker: f64,
    /// Frame `|AD|`.
    pub frame: f64,
    /// Crank turn `∠B₁AB₂` (deg, signed counter-clockwise).
    pub crank_turn_deg: f64,
    /// Rocker turn `∠C₁DC₂` (deg, signed).
    pub rocker_turn_deg: f64,
    /// Coupler turn from `B₁C₁` to `B₂C₂` (deg, signed).
    pub coupler_turn_deg: f64,
    /// In the solver's frame (`A` at the origin, `D` on +x): crank and rocker angles at
    /// the two positions (deg).
    pub positions_deg: [[f64; 2]; 2],
}

/// The point where the perpendicular bisector of `p1 p2` crosses the line through
/// `o` along the unit vector `u`.
fn bisector_on_line(
    p1: Vec2,
    p2: Vec2,
    o: Vec2,
    u: Vec2,
    what: &str,
) -> Result<Vec2, SynthesisError> {
    let chord = p2 - p1;
    let len = chord.norm();
    if len <= 1e-12 * p1.norm().max(p2.norm()).max(1.0) {
        return fail(format!(
            "{what}: the two positions coincide, so the pivot is anywhere"
        ));
    }
    // (o + t u − m) · chord = 0.
    let m = (p1 + p2) / 2.0;
    let den = u.dot(&chord);
    if den.abs() <= 1e-12 * len {
        return fail(format!(
            "{what}: the perpendicular bisector is parallel to the pivot line (no pivot on it)"
        ));
    }
    Ok(o + u * ((m - o).dot(&chord) / den))
}

fn angle_of(v: Vec2) -> f64 {
    v.y.atan2(v.x)
}

/// The four-bar whose coupler `BC` passes through `B₁C₁` and `B₂C₂`, with both fixed
/// pivots on the line through `o` in direction `dir` (rad).
pub fn four_bar_from_coupler_positions(
    (b1, c1): (Vec2, Vec2),
    (b2, c2): (Vec2, Vec2),
    o: Vec2,
    dir: f64,
) -> Result<CouplerGuidance, SynthesisError> {
    let (l1, l2) = ((c1 - b1).norm(), (c2 - b2).norm());
    if l1 <= 0.0 || l2 <= 0.0 {
        return fail("B and C coincide: the coupler has no length");
    }
    // Rounded data give slightly different lengths; more than 1 % is another body.
    let mismatch = (l2 - l1) / l1;
    if mismatch.abs() > MAX_COUPLER_MISMATCH {
        return fail(format!(
            "|BC| is {l1} in the first position and {l2} in the second: not one rigid coupler (more than 1 % apart)"
        ));
    }
    let coupler = (l1 + l2) / 2.0;
    let u = Vec2::new(dir.cos(), dir.sin());
    let a = bisector_on_line(b1, b2, o, u, "crank pivot A (from B₁, B₂)")?;
    let d = bisector_on_line(c1, c2, o, u, "rocker pivot D (from C₁, C₂)")?;
    let frame = (d - a).norm();
    if frame <= 1e-12 * coupler {
        return fail("both pivots fall on one point: no frame");
    }
    let turn = |p: Vec2, q: Vec2| cross(&p, &q).atan2(p.dot(&q)).to_degrees();
    let ad = angle_of(d - a);
    let local = |p: Vec2, from: Vec2| wrap_angle(angle_of(p - from) - ad).to_degrees();
    Ok(CouplerGuidance {
        crank_pivot: [a.x, a.y],
        rocker_pivot: [d.x, d.y],
        crank: (b1 - a).norm(),
        coupler,
        coupler_mismatch: mismatch,
        rocker: (c1 - d).norm(),
        frame,
        crank_turn_deg: turn(b1 - a, b2 - a),
        rocker_turn_deg: turn(c1 - d, c2 - d),
        coupler_turn_deg: turn(c1 - b1, c2 - b2),
        positions_deg: [[local(b1, a), local(c1, d)], [local(b2, a), local(c2, d)]],
    })
}
