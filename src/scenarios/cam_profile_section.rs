//! The `[profile]` section of `kind = "cam"` files (`docs/machines.md`): a cam given by
//! its profile — circular `arcs`, straight `segments` and a closed polygon of `points` in
//! the cam frame — and the follower it drives
//! ([`crate::machines::cams::given_profile`]).

use crate::core::diag::LocatedError as ScenarioError;
use crate::machines::cams::given_profile::{ProfileElement, ProfileFollower, ProfileMotion};
use crate::machines::cams::motion_table::CamMotion;
use crate::machines::cams::profile::CamFollower;
use crate::scenarios::source::{in_range, Source};
use serde::Deserialize;
use toml::Spanned;

/// Most elements of a profile (arcs, segments and polygon sides together).
pub const MAX_PROFILE_ELEMENTS: usize = 10_000;

/// The keys of `[profile]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileSpec {
    arcs: Option<Vec<ArcSpec>>,
    segments: Option<Vec<[[f64; 2]; 2]>>,
    points: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ArcSpec {
    centre: [f64; 2],
    radius: f64,
    from_deg: f64,
    to_deg: f64,
}

/// The follower keys a profile cam uses (from `[follower]`).
pub struct ProfileFollowerIn {
    /// `knife`, `roller` or `flat`.
    pub kind: String,
    /// `translating` or `oscillating`.
    pub moving: String,
    /// Roller radius (0 for knife and flat).
    pub roller: f64,
    /// Axis offset (translating knife/roller).
    pub offset: f64,
    /// Face angle (rad, flat).
    pub face_angle: f64,
    /// Arm and pivot distance (oscillating).
    pub arm_pivot: Option<(f64, f64)>,
}

const LIMIT: f64 = 1e7;

fn point_ok(p: &[f64; 2]) -> bool {
    p.iter().all(|x| x.is_finite() && x.abs() <= LIMIT)
}

/// The elements of `[profile]`, each number checked.
fn elements(cx: &Source, ps: &Spanned<ProfileSpec>) -> Result<Vec<ProfileElement>, ScenarioError> {
    let p = ps.get_ref();
    let err = |k: &str, m: String| cx.field(ps.span(), k, format!("profile.{k}"), m);
    let count = p.arcs.as_ref().map_or(0, Vec::len)
        + p.segments.as_ref().map_or(0, Vec::len)
        + p.points.as_ref().map_or(0, Vec::len);
    if count == 0 {
        return Err(err(
            "arcs",
            "missing: give `arcs`, `segments` or `points`".into(),
        ));
    }
    if count > MAX_PROFILE_ELEMENTS {
        return Err(err(
            "points",
            format!("{count} elements: at most {MAX_PROFILE_ELEMENTS}"),
        ));
    }
    let mut out = Vec::with_capacity(count);
    for (i, a) in p.arcs.iter().flatten().enumerate() {
        if !point_ok(&a.centre) || !in_range(a.radius, 1e-9, LIMIT) {
            return Err(err(
                "arcs",
                format!("arc {i}: a finite centre and a positive radius (at most 1e7)"),
            ));
        }
        if !(in_range(a.from_deg, -3600.0, 3600.0) && in_range(a.to_deg, -3600.0, 3600.0)) {
            return Err(err(
                "arcs",
                format!("arc {i}: from_deg and to_deg lie within ±3600°"),
            ));
        }
        out.push(ProfileElement::Arc {
            centre: a.centre,
            radius: a.radius,
            from: a.from_deg.to_radians(),
            to: a.to_deg.to_radians(),
        });
    }
    for (i, s) in p.segments.iter().flatten().enumerate() {
        if !point_ok(&s[0]) || !point_ok(&s[1]) || s[0] == s[1] {
            return Err(err(
                "segments",
                format!("segment {i}: two distinct finite end points"),
            ));
        }
        out.push(ProfileElement::Segment(s[0], s[1]));
    }
    if let Some(pts) = &p.points {
        if pts.len() < 3 {
            return Err(err(
                "points",
                "a polygon needs at least three points".into(),
            ));
        }
        for (i, q) in pts.iter().enumerate() {
            let next = &pts[(i + 1) % pts.len()];
            if !point_ok(q) {
                return Err(err(
                    "points",
                    format!("point {i}: finite coordinates within ±1e7"),
                ));
            }
            if q != next {
                out.push(ProfileElement::Segment(*q, *next));
            }
        }
    }
    Ok(out)
}

/// The motion a `[profile]` gives the follower, and the follower's geometry for the
/// report (its base radius from the profile).
pub fn profile_cam(
    cx: &Source,
    ps: &Spanned<ProfileSpec>,
    fo: &ProfileFollowerIn,
) -> Result<(CamMotion, CamFollower), ScenarioError> {
    let els = elements(cx, ps)?;
    let follower = match (fo.kind.as_str(), fo.moving.as_str(), fo.arm_pivot) {
        ("flat", "translating", _) => ProfileFollower::Flat {
            face_angle: fo.face_angle,
        },
        (_, "translating", _) => ProfileFollower::Translating {
            offset: fo.offset,
            roller: fo.roller,
        },
        ("flat", _, _) => {
            return Err(cx.section("follower", "a flat face on a [profile] cam must translate"))
        }
        (_, _, Some((arm, pivot))) => ProfileFollower::Oscillating {
            arm,
            pivot,
            roller: fo.roller,
        },
        _ => {
            return Err(cx.section(
                "follower",
                "an oscillating follower needs `arm` and `pivot_distance`",
            ))
        }
    };
    let m = ProfileMotion::new(&els, follower).map_err(|e| cx.section("profile", e.0))?;
    let base = m.base();
    let cf = match follower {
        ProfileFollower::Flat { face_angle } => CamFollower::Flat {
            rb: base * face_angle.cos(),
            face_angle,
        },
        ProfileFollower::Translating { offset, roller } => CamFollower::Translating {
            offset,
            roller,
            r0: (base * base + offset * offset).sqrt(),
        },
        ProfileFollower::Oscillating { arm, pivot, roller } => CamFollower::Oscillating {
            arm,
            pivot,
            roller,
            r0: (arm * arm + pivot * pivot - 2.0 * arm * pivot * base.cos()).sqrt(),
        },
    };
    if let CamFollower::Translating { offset, r0, .. } = cf {
        if base <= 0.0 || offset.abs() >= r0 {
            return Err(cx.section("profile", "the follower's axis passes through the cam centre's side of the profile (its lowest position is at or below the centre)"));
        }
    }
    Ok((CamMotion::Profile(m), cf))
}
