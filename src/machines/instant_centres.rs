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
//!
//! **Between any two bodies** `i`, `j` (the ground included): the velocity field of body
//! `k` per unit input is `v_k(P) = r'_k + θ'_k perp(P − r_k)`; the relative centre `P_ij`
//! is the point where `v_i = v_j`. With the relative velocity `u = v_i(r) − v_j(r)` at a
//! reference point `r` and `Δθ' = θ'_i − θ'_j`, `P_ij = r + perp(u)/Δθ'`; where
//! `Δθ' = 0` the relative motion is a translation and `P_ij` lies at infinity,
//! perpendicular to `u`. Any point `M` then has `v_i(M) − v_j(M) = Δθ' perp(M − P_ij)`,
//! and the three centres `P_ij`, `P_jk`, `P_ik` of three bodies lie on one line
//! (Aronhold–Kennedy). The relative centrodes: `P_ij` in `j`'s frame (fixed) and in `i`'s
//! frame (moving).

use crate::machines::linkage::description::{Linkage, GROUND};
use crate::machines::linkage::sweep::State;
use crate::machines::linkage::{perp, rotate, Vec2};
use nalgebra::DVector;

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

/// The relative instant centre `P_ij` of two bodies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RelativeCentre {
    /// A finite point (world coordinates).
    Point(Vec2),
    /// At infinity in this unit direction: the relative motion is a translation.
    AtInfinity(Vec2),
    /// No relative motion at all (a locked state: the rates vanish).
    Undefined,
}

impl RelativeCentre {
    /// The finite point, if any.
    pub fn point(&self) -> Option<Vec2> {
        match self {
            RelativeCentre::Point(p) => Some(*p),
            _ => None,
        }
    }
}

/// `(r'_k, θ'_k, r_k)`: the rate of body `k`'s reference point, its angular rate and the
/// point (the ground: zeros).
fn field(q: &DVector<f64>, dq: &DVector<f64>, k: usize) -> (Vec2, f64, Vec2) {
    if k == GROUND {
        (Vec2::zeros(), 0.0, Vec2::zeros())
    } else {
        (
            Vec2::new(dq[3 * k], dq[3 * k + 1]),
            dq[3 * k + 2],
            Vec2::new(q[3 * k], q[3 * k + 1]),
        )
    }
}

/// The velocity of the point at `p` (world) moving with body `k`, per unit input:
/// `v_k(P) = r'_k + θ'_k perp(P − r_k)`.
pub fn body_point_rate(q: &DVector<f64>, dq: &DVector<f64>, k: usize, p: &Vec2) -> Vec2 {
    let (dr, dth, r) = field(q, dq, k);
    dr + perp(&(p - r)) * dth
}

/// The relative instant centre `P_ij` of bodies `i` and `j` ([`GROUND`] allowed) at
/// coordinates `q` with rates `dq` per unit input: `P_ij = r + perp(u)/Δθ'` (module doc).
pub fn relative_centre(
    l: &Linkage,
    i: usize,
    j: usize,
    q: &DVector<f64>,
    dq: &DVector<f64>,
) -> RelativeCentre {
    let r = if i != GROUND {
        field(q, dq, i).2
    } else {
        field(q, dq, j).2
    };
    let u = body_point_rate(q, dq, i, &r) - body_point_rate(q, dq, j, &r);
    let dth = field(q, dq, i).1 - field(q, dq, j).1;
    let scale = l.length_scale();
    let motion = (0..l.links.len())
        .map(|k| {
            field(q, dq, k)
                .0
                .norm()
                .max(field(q, dq, k).1.abs() * scale)
        })
        .fold(0.0, f64::max);
    if u.norm() <= 1e-12 * motion && dth.abs() * scale <= 1e-12 * motion {
        return RelativeCentre::Undefined;
    }
    if dth.abs() * scale <= 1e-9 * u.norm() {
        return RelativeCentre::AtInfinity(perp(&u) / u.norm());
    }
    RelativeCentre::Point(r + perp(&u) / dth)
}

/// World point `p` in the frame of body `b` (the link frame of its points; the ground:
/// unchanged).
pub fn to_body_frame(l: &Linkage, q: &DVector<f64>, b: usize, p: &Vec2) -> Vec2 {
    if b == GROUND {
        return *p;
    }
    let r = Vec2::new(q[3 * b], q[3 * b + 1]);
    rotate(-q[3 * b + 2], &(p - r)) + l.links[b].com
}

/// Every relative centre of the linkage: bodies in the order ground, then the links;
/// pairs `(i, j, P_ij)` with `i` before `j` in that order.
pub fn all_centres(
    l: &Linkage,
    q: &DVector<f64>,
    dq: &DVector<f64>,
) -> Vec<(usize, usize, RelativeCentre)> {
    let bodies: Vec<usize> = std::iter::once(GROUND).chain(0..l.links.len()).collect();
    let mut v = Vec::new();
    for (a, &i) in bodies.iter().enumerate() {
        for &j in &bodies[a + 1..] {
            v.push((i, j, relative_centre(l, i, j, q, dq)));
        }
    }
    v
}

/// The distance of `c` from the line through `a` in direction `d` (unit).
fn off_line(a: Vec2, d: Vec2, c: Vec2) -> f64 {
    crate::machines::linkage::cross(&d, &(c - a)).abs()
}

/// Aronhold–Kennedy check: for every three bodies, the largest distance of a finite
/// centre from the line of the other two (a line through a finite centre along the
/// direction of one at infinity counts; triples with two centres at infinity, or two
/// coinciding finite ones, say nothing and are skipped).
pub fn three_centres_error(centres: &[(usize, usize, RelativeCentre)]) -> f64 {
    let get = |a: usize, b: usize| {
        centres
            .iter()
            .find(|(i, j, _)| (*i == a && *j == b) || (*i == b && *j == a))
            .map(|c| c.2)
    };
    let mut bodies: Vec<usize> = Vec::new();
    for (i, j, _) in centres {
        for b in [*i, *j] {
            if !bodies.contains(&b) {
                bodies.push(b);
            }
        }
    }
    let mut worst = 0.0f64;
    for (x, &i) in bodies.iter().enumerate() {
        for (y, &j) in bodies.iter().enumerate().skip(x + 1) {
            for &k in &bodies[y + 1..] {
                let (Some(a), Some(b), Some(c)) = (get(i, j), get(j, k), get(i, k)) else {
                    continue;
                };
                worst = worst.max(triple_error([a, b, c]));
            }
        }
    }
    worst
}

/// The collinearity error of three centres (see [`three_centres_error`]).
fn triple_error(c: [RelativeCentre; 3]) -> f64 {
    use RelativeCentre::AtInfinity;
    let pts: Vec<Vec2> = c.iter().filter_map(RelativeCentre::point).collect();
    let dirs: Vec<Vec2> = c
        .iter()
        .filter_map(|x| match x {
            AtInfinity(d) => Some(*d),
            _ => None,
        })
        .collect();
    if c.iter().any(|x| matches!(x, RelativeCentre::Undefined)) {
        return 0.0;
    }
    match (pts.len(), dirs.len()) {
        (3, 0) => {
            // The line through the two farthest apart; the distance of the third.
            let pairs = [(0, 1, 2), (0, 2, 1), (1, 2, 0)];
            let &(a, b, o) = pairs
                .iter()
                .max_by(|p, q| {
                    (pts[p.0] - pts[p.1])
                        .norm()
                        .total_cmp(&(pts[q.0] - pts[q.1]).norm())
                })
                .expect("three pairs");
            let d = pts[b] - pts[a];
            if d.norm() == 0.0 {
                return 0.0;
            }
            off_line(pts[a], d / d.norm(), pts[o])
        }
        (2, 1) => off_line(pts[0], dirs[0], pts[1]),
        _ => 0.0,
    }
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

/// Relative centrodes of body `i` against body `j` over the samples: `P_ij` in `j`'s frame
/// (`fixed`) and in `i`'s frame (`moving`); `None` where it is at infinity or undefined.
pub fn relative_centrodes(l: &Linkage, i: usize, j: usize, samples: &[State]) -> Vec<CentrePoint> {
    samples
        .iter()
        .map(|st| {
            let p = relative_centre(l, i, j, &st.q, &st.dq).point();
            CentrePoint {
                input: st.s,
                fixed: p.map(|p| to_body_frame(l, &st.q, j, &p)),
                moving: p.map(|p| to_body_frame(l, &st.q, i, &p)),
            }
        })
        .collect()
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
