//! A cam given by its profile (problem book ch. 11, the analysis problems): circular
//! arcs, straight segments and polygons in the cam frame, and the follower motion they
//! produce.
//!
//! The cam turns counter-clockwise by `φ` (a cam-frame point `p` is at `R(φ) p`). A roller
//! of radius `r` (`r = 0`: a knife edge) rests where the cam dilated by `r` ends along the
//! follower's path; that boundary lies at distance `r` from the profile curve, so the
//! follower's position is the extreme point, along its path, of the set of points at
//! distance `r` from the curve: the circles of radius `R ± r` about each arc's centre
//! (in the arc's directions), the segments moved by `±r` along their normal, and circles of
//! radius `r` about every end point.
//!
//! - translating knife/roller, axis `x = e`: the highest point `y(φ)` on the axis;
//! - translating flat face with normal `n = (sin β, cos β)`: the support function
//!   `p(φ) = max_p (R(−φ) n)·p`, and `y = p / cos β`;
//! - oscillating knife/roller, arm `l` about `(d, 0)`, roller centre
//!   `(d − l cos ψ, l sin ψ)`: the largest `ψ` on that circle.
//!
//! `s = y − min y` (or `ψ − min ψ`). The derivatives `s'`, `s''`, `s'''` are central
//! differences, one-sided next to the angles where the contact moves to another element
//! (found by bisection), so jumps of the curvature show as jumps of `s''`.

use crate::machines::cams::laws::Displacement;
use crate::machines::cams::profile::rot;
use std::f64::consts::PI;

type P = [f64; 2];

/// One element of a cam profile (cam frame at `φ = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProfileElement {
    /// A circular arc from direction `from` counter-clockwise to `to` (rad) about `centre`.
    Arc {
        /// Centre.
        centre: P,
        /// Radius.
        radius: f64,
        /// Start direction (rad).
        from: f64,
        /// End direction (rad), reached counter-clockwise.
        to: f64,
    },
    /// A straight segment.
    Segment(P, P),
}

/// The follower a given profile drives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProfileFollower {
    /// Translating knife (`roller = 0`) or roller on the axis `x = offset`.
    Translating {
        /// Axis offset `e`.
        offset: f64,
        /// Roller radius.
        roller: f64,
    },
    /// Translating flat face, normal inclined by `face_angle` to the stroke.
    Flat {
        /// `β` (rad).
        face_angle: f64,
    },
    /// Oscillating knife or roller: arm `l` about the pivot `(d, 0)`.
    Oscillating {
        /// Arm `l`.
        arm: f64,
        /// Pivot distance `d`.
        pivot: f64,
        /// Roller radius.
        roller: f64,
    },
}

/// A primitive of the offset set: a circle (or an arc of it) or a segment.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Prim {
    Circle {
        c: P,
        r: f64,
        range: Option<(f64, f64)>,
    },
    Seg(P, P),
}

/// Why a profile drives no follower.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ProfileError(pub String);

/// The follower motion of a given profile.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileMotion {
    prims: Vec<(Prim, usize)>,
    follower: ProfileFollower,
    /// `min` of the follower's coordinate (y, support/cos β or ψ) over the turn.
    base: f64,
    lift: f64,
    /// Angles where the contact changes element (rad, ascending).
    switches: Vec<f64>,
}

fn in_range(a: f64, (from, to): (f64, f64)) -> bool {
    let span = (to - from).rem_euclid(2.0 * PI);
    let span = if span == 0.0 { 2.0 * PI } else { span };
    (a - from).rem_euclid(2.0 * PI) <= span + 1e-12
}

fn dot(a: P, b: P) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1]]
}

fn lerp(a: P, b: P, t: f64) -> P {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

/// The points at distance `r` from `elements`, as primitives tagged with the element.
fn offset_set(elements: &[ProfileElement], r: f64) -> Vec<(Prim, usize)> {
    let mut out = Vec::new();
    for (i, e) in elements.iter().enumerate() {
        match *e {
            ProfileElement::Arc {
                centre,
                radius,
                from,
                to,
            } => {
                let range = Some((from, to));
                out.push((
                    Prim::Circle {
                        c: centre,
                        r: radius + r,
                        range,
                    },
                    i,
                ));
                if r > 0.0 && (radius - r).abs() > 0.0 {
                    let (rr, rg) = if radius > r {
                        (radius - r, range)
                    } else {
                        (r - radius, Some((from + PI, to + PI)))
                    };
                    out.push((
                        Prim::Circle {
                            c: centre,
                            r: rr,
                            range: rg,
                        },
                        i,
                    ));
                }
                for a in [from, to] {
                    let p = [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()];
                    if r > 0.0 {
                        out.push((
                            Prim::Circle {
                                c: p,
                                r,
                                range: None,
                            },
                            i,
                        ));
                    }
                }
            }
            ProfileElement::Segment(a, b) => {
                let d = sub(b, a);
                let len = dot(d, d).sqrt();
                let n = [-d[1] / len * r, d[0] / len * r];
                out.push((Prim::Seg(a, b), i));
                if r > 0.0 {
                    out.push((
                        Prim::Seg([a[0] + n[0], a[1] + n[1]], [b[0] + n[0], b[1] + n[1]]),
                        i,
                    ));
                    out.push((
                        Prim::Seg([a[0] - n[0], a[1] - n[1]], [b[0] - n[0], b[1] - n[1]]),
                        i,
                    ));
                    out.push((
                        Prim::Circle {
                            c: a,
                            r,
                            range: None,
                        },
                        i,
                    ));
                    out.push((
                        Prim::Circle {
                            c: b,
                            r,
                            range: None,
                        },
                        i,
                    ));
                }
            }
        }
    }
    out
}

/// Largest `t` with `o + t w` on the primitive (`w` a unit vector).
fn farthest_on_line(p: &Prim, o: P, w: P) -> Option<f64> {
    match *p {
        Prim::Circle { c, r, range } => {
            let oc = sub(o, c);
            let b = dot(oc, w);
            let disc = b * b - (dot(oc, oc) - r * r);
            if disc < 0.0 {
                return None;
            }
            [-b + disc.sqrt(), -b - disc.sqrt()].into_iter().find(|&t| {
                let q = sub([o[0] + t * w[0], o[1] + t * w[1]], c);
                range.is_none_or(|g| in_range(q[1].atan2(q[0]), g))
            })
        }
        Prim::Seg(a, b) => {
            // o + t w = a + u (b − a): Cramer on [w, −(b − a)].
            let d = sub(b, a);
            let det = -w[0] * d[1] + w[1] * d[0];
            if det.abs() < 1e-300 {
                return None;
            }
            let ao = sub(a, o);
            let t = (-ao[0] * d[1] + ao[1] * d[0]) / det;
            let u = (w[0] * ao[1] - w[1] * ao[0]) / det;
            (-1e-12..=1.0 + 1e-12).contains(&u).then_some(t)
        }
    }
}

/// Largest `ψ` where the circle of radius `l` about `pv` (points `pv + l (−cos ψ, sin ψ)`
/// turned by `rot_back`) meets the primitive.
fn largest_angle_on_circle(p: &Prim, pv: P, l: f64, to_fixed: f64, d: f64) -> Option<f64> {
    let angle = |x: P| {
        let f = rot(to_fixed, x);
        f[1].atan2(d - f[0])
    };
    let pts: Vec<P> = match *p {
        Prim::Circle { c, r, range } => circles_meet(pv, l, c, r)
            .into_iter()
            .filter(|q| range.is_none_or(|g| in_range((q[1] - c[1]).atan2(q[0] - c[0]), g)))
            .collect(),
        Prim::Seg(a, b) => {
            // |a + u (b − a) − pv| = l.
            let (dd, ap) = (sub(b, a), sub(a, pv));
            let (qa, qb, qc) = (dot(dd, dd), 2.0 * dot(ap, dd), dot(ap, ap) - l * l);
            let disc = qb * qb - 4.0 * qa * qc;
            if disc < 0.0 {
                return None;
            }
            [
                (-qb + disc.sqrt()) / (2.0 * qa),
                (-qb - disc.sqrt()) / (2.0 * qa),
            ]
            .into_iter()
            .filter(|u| (-1e-12..=1.0 + 1e-12).contains(u))
            .map(|u| lerp(a, b, u))
            .collect()
        }
    };
    pts.into_iter()
        .map(angle)
        .fold(None, |m, x| Some(m.map_or(x, |m: f64| m.max(x))))
}

/// The points where the circles `(c1, r1)` and `(c2, r2)` meet.
fn circles_meet(c1: P, r1: f64, c2: P, r2: f64) -> Vec<P> {
    let d = sub(c2, c1);
    let dist = dot(d, d).sqrt();
    if dist == 0.0 {
        return Vec::new();
    }
    let x = (r1 * r1 - r2 * r2 + dist * dist) / (2.0 * dist);
    let h2 = r1 * r1 - x * x;
    if h2 < 0.0 {
        return Vec::new();
    }
    let (u, h) = ([d[0] / dist, d[1] / dist], h2.sqrt());
    let base = [c1[0] + u[0] * x, c1[1] + u[1] * x];
    vec![
        [base[0] - u[1] * h, base[1] + u[0] * h],
        [base[0] + u[1] * h, base[1] - u[0] * h],
    ]
}

/// Support value of the primitive in direction `u` (unit).
fn support(p: &Prim, u: P) -> f64 {
    match *p {
        Prim::Circle { c, r, range } => {
            let full = dot(c, u) + r;
            match range {
                Some(g) if !in_range(u[1].atan2(u[0]), g) => {
                    let end = |a: f64| dot([c[0] + r * a.cos(), c[1] + r * a.sin()], u);
                    end(g.0).max(end(g.1))
                }
                _ => full,
            }
        }
        Prim::Seg(a, b) => dot(a, u).max(dot(b, u)),
    }
}

impl ProfileMotion {
    /// The motion `elements` give `follower`.
    pub fn new(
        elements: &[ProfileElement],
        follower: ProfileFollower,
    ) -> Result<Self, ProfileError> {
        if elements.is_empty() {
            return Err(ProfileError("the profile has no elements".into()));
        }
        let roller = match follower {
            ProfileFollower::Translating { roller, .. }
            | ProfileFollower::Oscillating { roller, .. } => roller,
            ProfileFollower::Flat { .. } => 0.0,
        };
        let mut m = Self {
            prims: offset_set(elements, roller),
            follower,
            base: 0.0,
            lift: 0.0,
            switches: Vec::new(),
        };
        let n = 3600;
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut prev: Option<(f64, usize)> = None;
        for k in 0..=n {
            let phi = 2.0 * PI * k as f64 / n as f64;
            let (y, who) = m.raw(phi).ok_or_else(|| {
                ProfileError(format!(
                    "at cam angle {:.2}° the follower's path misses the profile",
                    phi.to_degrees()
                ))
            })?;
            lo = lo.min(y);
            hi = hi.max(y);
            if let Some((p, w)) = prev {
                if w != who && k < n {
                    m.switches.push(m.bisect_switch(p, phi));
                }
            }
            prev = Some((phi, who));
        }
        m.base = lo;
        m.lift = hi - lo;
        if !(m.lift.is_finite() && m.lift > 0.0) {
            return Err(ProfileError(
                "the profile gives the follower no lift (a circle about the cam centre)".into(),
            ));
        }
        Ok(m)
    }

    /// The follower's coordinate at `φ` and the element in contact.
    fn raw(&self, phi: f64) -> Option<(f64, usize)> {
        let best = |f: &dyn Fn(&Prim) -> Option<f64>| {
            self.prims
                .iter()
                .filter_map(|(p, i)| f(p).map(|v| (v, *i)))
                .max_by(|a, b| a.0.total_cmp(&b.0))
        };
        match self.follower {
            ProfileFollower::Translating { offset, .. } => {
                let o = rot(-phi, [offset, 0.0]);
                let w = rot(-phi, [0.0, 1.0]);
                best(&|p| farthest_on_line(p, o, w))
            }
            ProfileFollower::Flat { face_angle } => {
                let u = rot(-phi, [face_angle.sin(), face_angle.cos()]);
                best(&|p| Some(support(p, u))).map(|(v, i)| (v / face_angle.cos(), i))
            }
            ProfileFollower::Oscillating { arm, pivot, .. } => {
                let pv = rot(-phi, [pivot, 0.0]);
                best(&|p| {
                    largest_angle_on_circle(p, pv, arm, phi, pivot).filter(|a| *a > 0.0 && *a < PI)
                })
            }
        }
    }

    fn bisect_switch(&self, mut a: f64, mut b: f64) -> f64 {
        let who = |x: f64| self.raw(x).map(|r| r.1);
        let left = who(a);
        for _ in 0..60 {
            let m = 0.5 * (a + b);
            if who(m) == left {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    }

    fn s(&self, phi: f64) -> f64 {
        self.raw(phi).map_or(f64::NAN, |r| r.0) - self.base
    }

    /// The follower's coordinate at `s = 0`: the prime radius `y` on the axis (translating
    /// knife/roller), the base radius `p/cos β` along the stroke (flat), or `ψ₀` (rad,
    /// oscillating).
    pub fn base(&self) -> f64 {
        self.base
    }
}

impl Displacement for ProfileMotion {
    fn eval(&self, phi: f64) -> [f64; 4] {
        let h = 2e-4;
        let near = self.switches.iter().copied().find(|b| {
            let d = (phi - b + PI).rem_euclid(2.0 * PI) - PI;
            d.abs() < 6.0 * h
        });
        let side = near.map_or(0.0, |b| {
            let d = (phi - b + PI).rem_euclid(2.0 * PI) - PI;
            if d >= 0.0 {
                1.0
            } else {
                -1.0
            }
        });
        if side == 0.0 {
            let f = |k: f64| self.s(phi + k * h);
            let (m2, m1, z, p1, p2) = (f(-2.0), f(-1.0), f(0.0), f(1.0), f(2.0));
            return [
                z,
                (p1 - m1) / (2.0 * h),
                (p1 - 2.0 * z + m1) / (h * h),
                (p2 - 2.0 * p1 + 2.0 * m1 - m2) / (2.0 * h * h * h),
            ];
        }
        // One-sided, stepping away from the switch: fourth order for s' and s'', second
        // for s'''.
        let f = |k: f64| self.s(phi + side * k * h);
        let v = [f(0.0), f(1.0), f(2.0), f(3.0), f(4.0), f(5.0)];
        [
            v[0],
            side * (-25.0 * v[0] + 48.0 * v[1] - 36.0 * v[2] + 16.0 * v[3] - 3.0 * v[4])
                / (12.0 * h),
            (45.0 * v[0] - 154.0 * v[1] + 214.0 * v[2] - 156.0 * v[3] + 61.0 * v[4] - 10.0 * v[5])
                / (12.0 * h * h),
            side * (-5.0 * v[0] + 18.0 * v[1] - 24.0 * v[2] + 14.0 * v[3] - 3.0 * v[4])
                / (2.0 * h * h * h),
        ]
    }

    fn stroke(&self) -> f64 {
        self.lift
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.switches.clone()
    }

    /// A drawn profile is given to a few digits, so its elements meet with small kinks:
    /// jumps below 0.1 % of `lift / (π/2)^order` are taken as the drawing's precision.
    fn derivative_scale(&self, order: usize) -> f64 {
        1e3 * self.lift / (PI / 2.0).powi(order as i32)
    }
}
