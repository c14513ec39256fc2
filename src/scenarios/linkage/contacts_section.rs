//! The `[[contacts]]` section of a linkage scenario: cam contacts (higher pairs) between
//! two bodies, each with a circle (`circle = { centre, radius }`) or a flat face
//! (`line = { through, direction }`) in its own frame, read into
//! [`crate::machines::linkage::higher_pair::HigherPair`]s; every error names the file,
//! the line and the key, and keys that do not apply to the pair are refused.

use crate::core::diag::{all_finite, LocatedError as ScenarioError};
use crate::machines::linkage::description::{Linkage, PlanarJoint, PlanarLink, GROUND};
use crate::machines::linkage::higher_pair::{ContactProfile, HigherPair};
use crate::machines::linkage::{contact_rows, Vec2};
use crate::scenarios::linkage::contacts_spec::{ContactSpec, PointRef, ProfileSpec};
use crate::scenarios::linkage::linkage_scenario::PinFriction;
use crate::scenarios::linkage::linkage_spec::{body_of, unit};
use crate::scenarios::source::Source;
use nalgebra::DVector;
use toml::Spanned;

/// The parsed contacts, with those whose side (circle–line) is to be taken from the
/// guessed position.
pub(super) struct Contacts {
    pairs: Vec<HigherPair>,
    side_from_guess: Vec<bool>,
}

/// A profile as read: a circle or a line of one body.
enum Read {
    Circle(Vec2, f64),
    Line(Vec2, Vec2),
}

/// Reads `[[contacts]]` against the links (the ground's points are `ground`).
pub(super) fn parse_contacts(
    cx: &Source,
    contacts: &[Spanned<ContactSpec>],
    links: &[PlanarLink],
    ground: &[(String, Vec2)],
    has_kinetostatics: bool,
) -> Result<Contacts, ScenarioError> {
    let mut out = Contacts {
        pairs: Vec::new(),
        side_from_guess: Vec::new(),
    };
    for (k, sp) in contacts.iter().enumerate() {
        let (s, span) = (sp.get_ref(), sp.span());
        let key = format!("contacts[{k}]");
        let err =
            |field: &str, m: String| cx.err(cx.key_line(&span, field), format!("{key}.{field}"), m);
        let name = s
            .name
            .clone()
            .unwrap_or_else(|| format!("contact {}", k + 1));
        if out.pairs.iter().any(|p| p.name == name) {
            return Err(err("name", format!("'{name}' is given twice")));
        }
        let mut bodies = [GROUND; 2];
        for (i, n) in s.links.iter().enumerate() {
            bodies[i] = body_of(links, n)
                .ok_or_else(|| err("links", format!("no link '{n}' (or \"ground\")")))?;
        }
        if bodies[0] == bodies[1] {
            return Err(err("links", "a contact needs two different bodies".into()));
        }
        let mut read = Vec::new();
        for (i, p) in s.profiles.iter().enumerate() {
            let pts = if bodies[i] == GROUND {
                ground
            } else {
                &links[bodies[i]].points
            };
            read.push(
                profile(p, pts, &s.links[i]).map_err(|m| err("profiles", format!("[{i}]: {m}")))?,
            );
        }
        let (mut pair, infer) =
            pair_of(name, bodies, read, s.side.as_deref()).map_err(|m| err(m.0, m.1))?;
        if let Some(f) = s.friction_coefficient {
            if !(0.0..=1.0).contains(&f) {
                return Err(err(
                    "friction_coefficient",
                    format!("must be in [0, 1], got {f}"),
                ));
            }
            if !has_kinetostatics {
                return Err(err(
                    "friction_coefficient",
                    "contact friction needs a [kinetostatics] table (it acts on the contact force)"
                        .into(),
                ));
            }
            pair.friction = Some(f);
        }
        out.pairs.push(pair);
        out.side_from_guess.push(infer);
    }
    Ok(out)
}

/// One profile: exactly one of `circle` and `line`, finite, radius ≥ 0, direction ≠ 0.
fn profile(p: &ProfileSpec, points: &[(String, Vec2)], body: &str) -> Result<Read, String> {
    let at = |r: &PointRef| -> Result<Vec2, String> {
        match r {
            PointRef::At(v) if all_finite(v) => Ok(Vec2::new(v[0], v[1])),
            PointRef::At(_) => Err("non-finite coordinates".into()),
            PointRef::Named(n) => points
                .iter()
                .find(|(m, _)| m == n)
                .map(|(_, v)| *v)
                .ok_or_else(|| format!("'{body}' has no point '{n}'")),
        }
    };
    match (&p.circle, &p.line) {
        (Some(c), None) => {
            if !(c.radius.is_finite() && (0.0..=1e3).contains(&c.radius)) {
                return Err(format!(
                    "circle.radius must be in 0 … 1000 m (0: a knife point), got {}",
                    c.radius
                ));
            }
            Ok(Read::Circle(at(&c.centre)?, c.radius))
        }
        (None, Some(l)) => {
            let dir = unit(l.direction)
                .ok_or_else(|| "line.direction must be a non-zero vector".to_string())?;
            Ok(Read::Line(at(&l.through)?, dir))
        }
        (Some(_), Some(_)) => Err("give `circle` or `line`, not both".into()),
        (None, None) => {
            Err("give `circle = { centre, radius }` or `line = { through, direction }`".into())
        }
    }
}

/// The pair with the circle first; whether its side is left to the guess. The error is
/// `(key, message)`.
fn pair_of(
    name: String,
    bodies: [usize; 2],
    read: Vec<Read>,
    side: Option<&str>,
) -> Result<(HigherPair, bool), (&'static str, String)> {
    let mut it = read.into_iter();
    let (p0, p1) = (it.next().expect("two"), it.next().expect("two"));
    let (a, ca, ra, b, other) = match (p0, p1) {
        (Read::Line(..), Read::Line(..)) => {
            return Err((
                "profiles",
                "two lines do not touch at a point: one profile must be a circle".into(),
            ))
        }
        (Read::Circle(c, r), Read::Circle(c2, r2)) => (
            bodies[0],
            c,
            r,
            bodies[1],
            ContactProfile::Circle {
                centre: c2,
                radius: r2,
            },
        ),
        (Read::Circle(c, r), Read::Line(t, d)) => (
            bodies[0],
            c,
            r,
            bodies[1],
            ContactProfile::Line { through: t, dir: d },
        ),
        (Read::Line(t, d), Read::Circle(c, r)) => (
            bodies[1],
            c,
            r,
            bodies[0],
            ContactProfile::Line { through: t, dir: d },
        ),
    };
    let circles = matches!(other, ContactProfile::Circle { .. });
    let (sigma, infer) = match (circles, side) {
        (true, None | Some("outside")) => (1.0, false),
        (true, Some("inside")) => (-1.0, false),
        (false, None) => (1.0, true),
        (false, Some("left")) => (1.0, false),
        (false, Some("right")) => (-1.0, false),
        (true, Some(o)) => return Err(("side", format!("two circles touch \"outside\" or \"inside\", got \"{o}\""))),
        (false, Some(o)) => return Err(("side", format!("a circle on a line lies \"left\" or \"right\" of the line's direction (default: as in [guess]), got \"{o}\""))),
    };
    let pair = HigherPair {
        name,
        a,
        centre: ca,
        radius: ra,
        b,
        other,
        side: sigma,
        friction: None,
    };
    if circles && pair.centre_distance().unwrap_or(0.0) <= 0.0 {
        return Err(("profiles", "the circles close at centre distance 0 (two knife points, or equal radii inside): no common normal".into()));
    }
    Ok((pair, infer))
}

/// Friction in the contacts only (no `friction_coefficient` in `[kinetostatics]`): the
/// joints' coefficient 0, the contacts' own.
pub(super) fn contact_friction_only(l: &Linkage) -> Option<PinFriction> {
    l.joints
        .iter()
        .any(|j| matches!(j, PlanarJoint::Contact(c) if c.friction.is_some()))
        .then(|| PinFriction {
            coefficient: 0.0,
            default_radius: 0.0,
            radii: vec![0.0; l.joints.len()],
            named: Vec::new(),
        })
}

impl Contacts {
    /// Adds the pairs to the linkage's joints (after the pins and sliders).
    pub(super) fn add_to(&self, l: &mut Linkage) {
        l.joints
            .extend(self.pairs.iter().cloned().map(PlanarJoint::Contact));
    }

    /// Sets each circle–line pair without `side` to the side its circle's centre lies on
    /// at the guessed coordinates `q0` (`+1` exactly on the line).
    pub(super) fn sides_from_guess(&self, l: &mut Linkage, q0: &DVector<f64>) {
        let sides: Vec<(usize, f64)> = l
            .joints
            .iter()
            .enumerate()
            .filter_map(|(j, joint)| {
                let PlanarJoint::Contact(c) = joint else {
                    return None;
                };
                let k = self.pairs.iter().position(|p| p.name == c.name)?;
                if !self.side_from_guess[k] {
                    return None;
                }
                let mut c = c.clone();
                c.side = 1.0;
                let g = contact_rows::geometry(l, q0, &c);
                let centre_off = g.gap + c.radius;
                Some((j, if centre_off < 0.0 { -1.0 } else { 1.0 }))
            })
            .collect();
        for (j, side) in sides {
            if let PlanarJoint::Contact(c) = &mut l.joints[j] {
                c.side = side;
            }
        }
    }
}
