//! Instant centres and centrodes (docs/reference_data.md §M9; problem book ch. 12): the
//! instant centre of a link relative to the ground along a tracked sweep of any linkage,
//! its locus on the ground (the fixed centrode) and on the link (the moving centrode).
//!
//! From the link's coordinates `(r, θ)` and their rates per unit input `(r', θ')`, the
//! point of the link at rest is `P = r + perp(r')/θ'` (`perp` turns by +90°); where
//! `θ' = 0` the centre is at infinity (translation) and the centrode passes through
//! infinity. On the link, `p = A(θ)ᵀ (P − r) + c` (`c` the centre of mass in the link frame).
//! The two centrodes roll on each other without slipping: their arc lengths over any input
//! interval are equal. For a four-bar the centre of the coupler is also Kennedy's
//! intersection of the crank and rocker lines.

use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::sweep::State;
use crate::machines::linkage::{perp, rotate, Vec2};

/// One point of a centrode pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CentrePoint {
    /// Input (rad or m).
    pub input: f64,
    /// Instant centre on the ground (`None` at infinity).
    pub fixed: Option<Vec2>,
    /// The same point in the link's frame.
    pub moving: Option<Vec2>,
}

/// The instant centre of link `b` relative to the ground at state `st`; `None` where the
/// link translates (`|θ'| ≤ tol_ratio · |r'| / length scale`).
pub fn instant_centre(l: &Linkage, b: usize, st: &State) -> CentrePoint {
    let r = Vec2::new(st.q[3 * b], st.q[3 * b + 1]);
    let th = st.q[3 * b + 2];
    let dr = Vec2::new(st.dq[3 * b], st.dq[3 * b + 1]);
    let dth = st.dq[3 * b + 2];
    let scale = l.length_scale();
    if dth.abs() * scale <= 1e-9 * dr.norm() || (dth == 0.0 && dr.norm() == 0.0) {
        return CentrePoint {
            input: st.s,
            fixed: None,
            moving: None,
        };
    }
    let p = r + perp(&dr) / dth;
    let local = rotate(-th, &(p - r)) + l.links[b].com;
    CentrePoint {
        input: st.s,
        fixed: Some(p),
        moving: Some(local),
    }
}

/// Centrode pairs of link `b` over the samples.
pub fn centrodes(l: &Linkage, b: usize, samples: &[State]) -> Vec<CentrePoint> {
    samples.iter().map(|st| instant_centre(l, b, st)).collect()
}

/// Intersection of the line through `a1`, `a2` with the line through `b1`, `b2`
/// (`None` when parallel).
pub fn line_intersection(a1: Vec2, a2: Vec2, b1: Vec2, b2: Vec2) -> Option<Vec2> {
    let (d1, d2) = (a2 - a1, b2 - b1);
    let den = crate::machines::linkage::cross(&d1, &d2);
    let scale = d1.norm() * d2.norm();
    if den.abs() <= 1e-12 * scale {
        return None;
    }
    let t = crate::machines::linkage::cross(&(b1 - a1), &d2) / den;
    Some(a1 + d1 * t)
}

/// Arc lengths `(fixed, moving)` of the finite runs of a centrode pair (segments with an
/// end at infinity are left out of both).
pub fn arc_lengths(pts: &[CentrePoint]) -> (f64, f64) {
    let (mut f, mut m) = (0.0, 0.0);
    for w in pts.windows(2) {
        if let (Some(a), Some(b), Some(c), Some(d)) =
            (w[0].fixed, w[1].fixed, w[0].moving, w[1].moving)
        {
            f += (b - a).norm();
            m += (d - c).norm();
        }
    }
    (f, m)
}
