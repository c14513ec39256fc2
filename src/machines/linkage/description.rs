//! The description of a planar linkage: ground points, moving links with named points and
//! inertia, joints (pins and sliders) and the driver.
//!
//! Coordinates (Haug 1989, §3.1; Nikravesh 1988, §3.2): each moving link `i` has
//! `q_i = (x_i, y_i, θ_i)`, the position of its centre of mass and the angle of its frame.
//! A link's frame is the one its points are given in; `θ_i` is the angle of that frame's
//! x axis from the ground x axis, counter-clockwise positive. A point with link-frame
//! coordinates `p` is at `r_P = r_i + A(θ_i) (p − c_i)` (`c_i` the centre of mass in the
//! link frame, `A` the rotation), with `ṙ_P = ṙ_i + θ̇_i perp(A s)` and
//! `r̈_P = r̈_i + θ̈_i perp(A s) − θ̇_i² A s`, `s = p − c_i`.
//!
//! The ground has no coordinates: its "link" index is [`GROUND`] and its points are world
//! points.

use crate::machines::linkage::higher_pair::{ContactProfile, HigherPair};
use crate::machines::linkage::planar::{perp, rotate, Vec2};
use nalgebra::DVector;
use std::collections::HashMap;

/// Index of the ground in joint and driver fields.
pub const GROUND: usize = usize::MAX;

/// A moving rigid link.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarLink {
    /// Name (as in the scenario file).
    pub name: String,
    /// Named points in the link frame.
    pub points: Vec<(String, Vec2)>,
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the link frame.
    pub com: Vec2,
    /// Moment of inertia about the centre of mass (kg m²).
    pub inertia: f64,
}

impl PlanarLink {
    /// A massless link with the given points.
    pub fn new(name: impl Into<String>, points: Vec<(String, Vec2)>) -> Self {
        Self {
            name: name.into(),
            points,
            mass: 0.0,
            com: Vec2::zeros(),
            inertia: 0.0,
        }
    }

    /// A binary link: `a` at the origin and `b` at `(length, 0)`.
    pub fn binary(name: impl Into<String>, a: &str, b: &str, length: f64) -> Self {
        Self::new(
            name,
            vec![
                (a.to_string(), Vec2::zeros()),
                (b.to_string(), Vec2::new(length, 0.0)),
            ],
        )
    }

    /// The same link with mass, centre of mass (link frame) and inertia about it.
    pub fn with_mass(mut self, mass: f64, com: Vec2, inertia: f64) -> Self {
        self.mass = mass;
        self.com = com;
        self.inertia = inertia;
        self
    }

    /// PlanarLink-frame coordinates of the named point.
    pub fn point(&self, name: &str) -> Option<Vec2> {
        self.points.iter().find(|(n, _)| n == name).map(|(_, p)| *p)
    }
}

/// A slider: point `p` of `link` stays on the line through `through` along `dir`, both
/// fixed in `guide`; a prismatic slider also keeps `θ_link − θ_guide = angle`, a pin in a
/// slot lets the link turn.
#[derive(Clone, Debug, PartialEq)]
pub struct Slider {
    /// Name for reports.
    pub name: String,
    /// The sliding link.
    pub link: usize,
    /// The sliding point, in the link frame.
    pub p: Vec2,
    /// The link carrying the line ([`GROUND`] for a fixed guide).
    pub guide: usize,
    /// A point of the line, in the guide frame.
    pub through: Vec2,
    /// Unit direction of the line, in the guide frame.
    pub dir: Vec2,
    /// `Some(angle)` for a prismatic joint (`θ_link − θ_guide = angle`), `None` for a pin
    /// in a slot.
    pub prismatic: Option<f64>,
}

/// A joint.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanarJoint {
    /// Pin: point `pa` of link `a` coincides with point `pb` of link `b` (either may be
    /// [`GROUND`], whose points are world points).
    Revolute {
        /// The point's name.
        name: String,
        /// First link.
        a: usize,
        /// The point in `a`'s frame.
        pa: Vec2,
        /// Second link.
        b: usize,
        /// The point in `b`'s frame.
        pb: Vec2,
    },
    /// A slider (prismatic joint or pin in a slot).
    Slider(Slider),
    /// A higher pair (cam contact) of a circle and a circle or a line.
    Contact(HigherPair),
}

impl PlanarJoint {
    /// The joint's name.
    pub fn name(&self) -> &str {
        match self {
            PlanarJoint::Revolute { name, .. } => name,
            PlanarJoint::Slider(s) => &s.name,
            PlanarJoint::Contact(c) => &c.name,
        }
    }

    /// Number of constraint equations.
    pub fn rows(&self) -> usize {
        match self {
            PlanarJoint::Revolute { .. } => 2,
            PlanarJoint::Slider(s) => 1 + usize::from(s.prismatic.is_some()),
            PlanarJoint::Contact(_) => 1,
        }
    }
}

/// The input.
#[derive(Clone, Debug, PartialEq)]
pub enum Driver {
    /// `θ_link − θ_relative_to = s` (a crank angle; `relative_to` is usually the ground).
    Angle {
        /// Driven link.
        link: usize,
        /// Reference link or [`GROUND`].
        relative_to: usize,
    },
    /// `u · (r_P − p0) = s`: the position of point `p` of `link` along a ground line.
    Slide {
        /// Driven link.
        link: usize,
        /// The point, in the link frame.
        p: Vec2,
        /// A point of the line (world).
        through: Vec2,
        /// Unit direction (world).
        dir: Vec2,
    },
}

/// What is wrong with a linkage description.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinkageError {
    /// A field is out of range or inconsistent; `what` names it.
    #[error("{what}: {message}")]
    Invalid {
        /// The link, joint or field.
        what: String,
        /// What is wrong.
        message: String,
    },
}

/// A link of [`Linkage::coordinates_from_points`] with no guessed point and no ground
/// point, so nothing places it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("link '{link}' has no guessed point")]
pub struct NoGuessedPoint {
    /// The link's name.
    pub link: String,
}

fn invalid(what: impl Into<String>, message: impl Into<String>) -> LinkageError {
    LinkageError::Invalid {
        what: what.into(),
        message: message.into(),
    }
}

/// A higher pair's bodies differ and exist, its radii are finite and ≥ 0, a line's
/// direction is a unit vector and two circles do not close at a zero centre distance.
fn check_contact(c: &HigherPair, body_ok: &dyn Fn(usize) -> bool) -> Result<(), LinkageError> {
    let what = format!("contact '{}'", c.name);
    if !body_ok(c.a) || !body_ok(c.b) || c.a == c.b {
        return Err(invalid(what, "bad link indices"));
    }
    let finite = |v: &Vec2| v.x.is_finite() && v.y.is_finite();
    if !(finite(&c.centre) && c.radius.is_finite() && c.radius >= 0.0) {
        return Err(invalid(
            what,
            "the circle needs a finite centre and a radius ≥ 0",
        ));
    }
    match &c.other {
        ContactProfile::Circle { centre, radius } => {
            if !(finite(centre) && radius.is_finite() && *radius >= 0.0) {
                return Err(invalid(
                    what,
                    "the circle needs a finite centre and a radius ≥ 0",
                ));
            }
            if c.centre_distance().unwrap_or(0.0) <= 0.0 {
                return Err(invalid(
                    what,
                    "the circles close at centre distance 0 (two points, or equal radii inside): no common normal",
                ));
            }
        }
        ContactProfile::Line { through, dir } => {
            if !finite(through) || (dir.norm() - 1.0).abs() > 1e-12 {
                return Err(invalid(
                    what,
                    "the line needs a finite point and a unit direction",
                ));
            }
        }
    }
    Ok(())
}

/// A planar linkage.
#[derive(Clone, Debug, PartialEq)]
pub struct Linkage {
    /// Name.
    pub name: String,
    /// Named ground points (world coordinates).
    pub ground: Vec<(String, Vec2)>,
    /// Moving links; link `i` owns coordinates `3i .. 3i + 3`.
    pub links: Vec<PlanarLink>,
    /// Joints, in constraint-row order.
    pub joints: Vec<PlanarJoint>,
    /// The driver (its equation is the last row of `Φ`).
    pub driver: Driver,
}

impl Linkage {
    /// A linkage whose pins are the points shared by name: every point name found on more
    /// than one body (the ground first, then the links in order) pins the first body that
    /// has it to each of the others. Sliders are added after the pins.
    pub fn with_shared_pins(
        name: impl Into<String>,
        ground: Vec<(String, Vec2)>,
        links: Vec<PlanarLink>,
        sliders: Vec<Slider>,
        driver: Driver,
    ) -> Self {
        let mut l = Self {
            name: name.into(),
            ground,
            links,
            joints: Vec::new(),
            driver,
        };
        let mut seen: Vec<String> = Vec::new();
        let bodies: Vec<usize> = std::iter::once(GROUND).chain(0..l.links.len()).collect();
        for &b in &bodies {
            for (pname, _) in l.body_points(b).to_vec() {
                if seen.contains(&pname) {
                    continue;
                }
                seen.push(pname.clone());
                let owners: Vec<(usize, Vec2)> = bodies
                    .iter()
                    .filter_map(|&o| {
                        l.body_points(o)
                            .iter()
                            .find(|(n, _)| *n == pname)
                            .map(|(_, p)| (o, *p))
                    })
                    .collect();
                for &(o, po) in owners.iter().skip(1) {
                    l.joints.push(PlanarJoint::Revolute {
                        name: pname.clone(),
                        a: owners[0].0,
                        pa: owners[0].1,
                        b: o,
                        pb: po,
                    });
                }
            }
        }
        l.joints
            .extend(sliders.into_iter().map(PlanarJoint::Slider));
        l
    }

    /// Number of coordinates (`3 ×` moving links).
    pub fn ncoords(&self) -> usize {
        3 * self.links.len()
    }

    /// Number of constraint equations, the driver's included.
    pub fn nrows(&self) -> usize {
        self.kinematic_rows() + 1
    }

    /// Number of joint constraint equations (without the driver).
    pub fn kinematic_rows(&self) -> usize {
        self.joints.iter().map(PlanarJoint::rows).sum()
    }

    /// Index of a link by name.
    pub fn link_id(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Name of a body (`"ground"` for [`GROUND`]).
    pub fn body_name(&self, b: usize) -> &str {
        if b == GROUND {
            "ground"
        } else {
            &self.links[b].name
        }
    }

    /// The named points of a body.
    pub fn body_points(&self, b: usize) -> &[(String, Vec2)] {
        if b == GROUND {
            &self.ground
        } else {
            &self.links[b].points
        }
    }

    /// The first body carrying a point of that name, and its coordinates there.
    pub fn find_point(&self, name: &str) -> Option<(usize, Vec2)> {
        std::iter::once(GROUND)
            .chain(0..self.links.len())
            .find_map(|b| {
                self.body_points(b)
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, p)| (b, *p))
            })
    }

    /// `s = p − c`: a link-frame point relative to the centre of mass (world points of the
    /// ground are returned unchanged).
    #[inline]
    pub fn offset(&self, b: usize, p: &Vec2) -> Vec2 {
        if b == GROUND {
            *p
        } else {
            p - self.links[b].com
        }
    }

    /// Position of the centre of mass and angle of body `b`.
    #[inline]
    pub fn pose(&self, q: &DVector<f64>, b: usize) -> (Vec2, f64) {
        if b == GROUND {
            (Vec2::zeros(), 0.0)
        } else {
            (Vec2::new(q[3 * b], q[3 * b + 1]), q[3 * b + 2])
        }
    }

    /// `A(θ_b) s` for a link-frame point `p` of body `b` (the world point for the ground).
    #[inline]
    pub fn arm(&self, q: &DVector<f64>, b: usize, p: &Vec2) -> Vec2 {
        if b == GROUND {
            *p
        } else {
            rotate(q[3 * b + 2], &self.offset(b, p))
        }
    }

    /// World position of point `p` (link frame) of body `b`.
    pub fn point_position(&self, q: &DVector<f64>, b: usize, p: &Vec2) -> Vec2 {
        if b == GROUND {
            return *p;
        }
        self.pose(q, b).0 + self.arm(q, b, p)
    }

    /// World velocity of point `p` of body `b`: `ṙ_i + θ̇_i perp(A s)`.
    pub fn point_velocity(&self, q: &DVector<f64>, qd: &DVector<f64>, b: usize, p: &Vec2) -> Vec2 {
        if b == GROUND {
            return Vec2::zeros();
        }
        Vec2::new(qd[3 * b], qd[3 * b + 1]) + perp(&self.arm(q, b, p)) * qd[3 * b + 2]
    }

    /// World acceleration of point `p` of body `b`: `r̈_i + θ̈_i perp(A s) − θ̇_i² A s`.
    pub fn point_acceleration(
        &self,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
        b: usize,
        p: &Vec2,
    ) -> Vec2 {
        if b == GROUND {
            return Vec2::zeros();
        }
        let a = self.arm(q, b, p);
        let w = qd[3 * b + 2];
        Vec2::new(qdd[3 * b], qdd[3 * b + 1]) + perp(&a) * qdd[3 * b + 2] - a * (w * w)
    }

    /// A characteristic length: the largest distance between two named points of one body
    /// or of a ground point from the origin (at least 1e-3 m). Tolerances scale with it.
    pub fn length_scale(&self) -> f64 {
        let mut l: f64 = 1e-3;
        for (_, p) in &self.ground {
            l = l.max(p.norm());
        }
        for link in &self.links {
            for (_, a) in &link.points {
                for (_, b) in &link.points {
                    l = l.max((a - b).norm());
                }
            }
        }
        l
    }

    /// Coordinates placing each link from world guesses of its points: the angle from the
    /// first two guessed points (measured against their link-frame direction), or
    /// `default_angle` with a single guessed point; ground points count as guessed.
    /// The error names the first link with no guessed point.
    pub fn coordinates_from_points(
        &self,
        guess: &HashMap<String, Vec2>,
        default_angle: &[f64],
    ) -> Result<DVector<f64>, NoGuessedPoint> {
        let mut q = DVector::zeros(self.ncoords());
        for (i, link) in self.links.iter().enumerate() {
            let known: Vec<(Vec2, Vec2)> = link
                .points
                .iter()
                .filter_map(|(n, p)| {
                    guess
                        .get(n)
                        .copied()
                        .or_else(|| self.ground.iter().find(|(g, _)| g == n).map(|(_, w)| *w))
                        .map(|w| (*p, w))
                })
                .collect();
            let Some(&(p0, w0)) = known.first() else {
                return Err(NoGuessedPoint {
                    link: link.name.clone(),
                });
            };
            let theta = match known.iter().skip(1).find(|(p, _)| (p - p0).norm() > 1e-12) {
                Some(&(p1, w1)) => {
                    let dl = p1 - p0;
                    let dw = w1 - w0;
                    dw.y.atan2(dw.x) - dl.y.atan2(dl.x)
                }
                None => default_angle.get(i).copied().unwrap_or(0.0),
            };
            let r = w0 - rotate(theta, &(p0 - link.com));
            q[3 * i] = r.x;
            q[3 * i + 1] = r.y;
            q[3 * i + 2] = theta;
        }
        Ok(q)
    }

    /// Checks the description: finite numbers, non-negative mass and inertia, unit slider
    /// and driver directions, valid indices, distinct points for the driver's link.
    pub fn validate(&self) -> Result<(), LinkageError> {
        let nl = self.links.len();
        let body_ok = |b: usize| b == GROUND || b < nl;
        if nl == 0 {
            return Err(invalid("links", "a linkage needs at least one moving link"));
        }
        for l in &self.links {
            let what = format!("link '{}'", l.name);
            if !(l.mass.is_finite() && l.mass >= 0.0) {
                return Err(invalid(what, format!("mass must be ≥ 0, got {}", l.mass)));
            }
            if !(l.inertia.is_finite() && l.inertia >= 0.0) {
                return Err(invalid(
                    what,
                    format!("inertia must be ≥ 0, got {}", l.inertia),
                ));
            }
            if l.points.is_empty() {
                return Err(invalid(what, "a link needs at least one point"));
            }
            let finite = |v: &Vec2| v.x.is_finite() && v.y.is_finite();
            if !finite(&l.com) || l.points.iter().any(|(_, p)| !finite(p)) {
                return Err(invalid(what, "non-finite coordinates"));
            }
        }
        for j in &self.joints {
            match j {
                PlanarJoint::Revolute { name, a, b, .. } => {
                    if !body_ok(*a) || !body_ok(*b) || a == b {
                        return Err(invalid(format!("joint '{name}'"), "bad link indices"));
                    }
                }
                PlanarJoint::Slider(s) => {
                    if !body_ok(s.guide) || s.link >= nl || s.link == s.guide {
                        return Err(invalid(format!("slider '{}'", s.name), "bad link indices"));
                    }
                    if (s.dir.norm() - 1.0).abs() > 1e-12 {
                        return Err(invalid(
                            format!("slider '{}'", s.name),
                            "direction must be a unit vector",
                        ));
                    }
                }
                PlanarJoint::Contact(c) => check_contact(c, &body_ok)?,
            }
        }
        match &self.driver {
            Driver::Angle { link, relative_to } => {
                if *link >= nl || !body_ok(*relative_to) || link == relative_to {
                    return Err(invalid("driver", "bad link indices"));
                }
            }
            Driver::Slide { link, dir, .. } => {
                if *link >= nl {
                    return Err(invalid("driver", "bad link index"));
                }
                if (dir.norm() - 1.0).abs() > 1e-12 {
                    return Err(invalid("driver", "direction must be a unit vector"));
                }
            }
        }
        Ok(())
    }

    /// The motion `(q, q̇, q̈)` of this linkage in the coordinates of `other`, which has
    /// the same links and joints but other centres of mass (a counterweight added): each
    /// link's new centre of mass moves as that point of the link, the angles are the same.
    pub fn transfer_motion(
        &self,
        other: &Linkage,
        q: &DVector<f64>,
        qd: &DVector<f64>,
        qdd: &DVector<f64>,
    ) -> (DVector<f64>, DVector<f64>, DVector<f64>) {
        let (mut q2, mut qd2, mut qdd2) = (q.clone(), qd.clone(), qdd.clone());
        for (i, link) in other.links.iter().enumerate() {
            let c = link.com;
            let p = self.point_position(q, i, &c);
            let v = self.point_velocity(q, qd, i, &c);
            let a = self.point_acceleration(q, qd, qdd, i, &c);
            q2[3 * i] = p.x;
            q2[3 * i + 1] = p.y;
            qd2[3 * i] = v.x;
            qd2[3 * i + 1] = v.y;
            qdd2[3 * i] = a.x;
            qdd2[3 * i + 1] = a.y;
        }
        (q2, qd2, qdd2)
    }

    /// The driver's link.
    pub fn driven_link(&self) -> usize {
        match &self.driver {
            Driver::Angle { link, .. } | Driver::Slide { link, .. } => *link,
        }
    }

    /// The input value `s` at coordinates `q` (the driver equation's left side).
    pub fn input_value(&self, q: &DVector<f64>) -> f64 {
        match &self.driver {
            Driver::Angle { link, relative_to } => {
                q[3 * link + 2]
                    - if *relative_to == GROUND {
                        0.0
                    } else {
                        q[3 * relative_to + 2]
                    }
            }
            Driver::Slide {
                link,
                p,
                through,
                dir,
            } => dir.dot(&(self.point_position(q, *link, p) - through)),
        }
    }
}
