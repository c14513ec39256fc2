//! `kind = "cam"` scenario files (format in `docs/machines.md`): a motion law
//! (`[motion]`) or an eccentric disc (`[eccentric]`), a `[follower]` and optional
//! `[limits]` on the pressure angle; parsed with spans so that every error is located.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::report::Report;
use crate::machines::cams::eccentric::{Eccentric, EccentricFollower};
use crate::machines::cams::profile::CamFollower;
use crate::scenarios::cam_motion::{motion, MotionSpec};
use crate::scenarios::cam_profile_section::{profile_cam, ProfileFollowerIn, ProfileSpec};
use crate::scenarios::cam_report::{report, Cam, CamScenario};
use crate::scenarios::source::{in_range, Source};
use serde::Deserialize;
use std::fmt::Write;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    speed_rpm: Option<Spanned<f64>>,
    steps: Option<Spanned<i64>>,
    motion: Option<Spanned<MotionSpec>>,
    eccentric: Option<Spanned<EccSpec>>,
    profile: Option<Spanned<ProfileSpec>>,
    follower: Spanned<FollowerSpec>,
    limits: Option<Spanned<LimitSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EccSpec {
    radius: f64,
    eccentricity: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FollowerSpec {
    #[serde(rename = "type")]
    kind: String,
    motion: Option<String>,
    #[serde(default)]
    offset: f64,
    roller_radius: Option<f64>,
    base_radius: Option<f64>,
    arm: Option<f64>,
    pivot_distance: Option<f64>,
    face_offset: Option<f64>,
    face_angle_deg: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LimitSpec {
    pressure_angle_deg: f64,
    return_pressure_angle_deg: Option<f64>,
}

/// Runs a cam scenario.
pub fn run(path: &Path, text: &str, out_dir: Option<&Path>) -> Result<Report, ScenarioError> {
    let file = path.display().to_string();
    let sc = parse(&file, text)?;
    let mut r = report(&sc, NAME);
    let panels = crate::io::plots::machine_plots::cam_panels(&r.json);
    if let Some(p) = crate::scenarios::kit::write_plot(
        out_dir,
        &format!("{}_cam", sc.name),
        &sc.name,
        &panels,
        2,
    )
    .map_err(|m| ScenarioError::new(&file, None, "plot", m))?
    {
        let _ = writeln!(r.text, "plot: {}", p.display());
    }
    Ok(r)
}

/// A follower-side error at `follower.<key>`.
type FollowerErr<'a> = dyn Fn(&str, String) -> ScenarioError + 'a;
/// A required positive length of the follower table.
type PositiveLen<'a> = dyn Fn(&str, Option<f64>) -> Result<f64, ScenarioError> + 'a;

/// The follower an eccentric disc drives: a translating flat face, an oscillating flat
/// face clear of the disc, or a translating knife/roller whose axis meets the disc.
fn eccentric_follower(
    fo: &FollowerSpec,
    moving: &str,
    (roller, es): (f64, &EccSpec),
    ferr: &FollowerErr,
    positive: &PositiveLen,
) -> Result<EccentricFollower, ScenarioError> {
    Ok(match (fo.kind.as_str(), moving) {
        ("flat", "translating") => EccentricFollower::Flat,
        ("flat", "oscillating") => {
            let d = positive("pivot_distance", fo.pivot_distance)?;
            let fo_ = fo.face_offset.ok_or_else(|| {
                ferr(
                    "face_offset",
                    "missing: the face's distance from the pivot".into(),
                )
            })?;
            if !in_range(fo_.abs(), 0.0, 1e7) || d <= es.eccentricity + es.radius {
                return Err(ferr(
                    "pivot_distance",
                    "the pivot must lie outside the disc's reach (d > a + R)".into(),
                ));
            }
            EccentricFollower::OscillatingFlat {
                pivot: d,
                face_offset: fo_,
            }
        }
        (_, "translating") => {
            if fo.offset.abs() + es.eccentricity >= es.radius + roller {
                return Err(ferr(
                    "offset",
                    "the follower axis misses the disc (|e| + a ≥ R + r)".into(),
                ));
            }
            EccentricFollower::Translating {
                offset: fo.offset,
                roller,
            }
        }
        _ => {
            return Err(ferr(
                "motion",
                "an eccentric cam drives a translating follower or an oscillating flat face".into(),
            ))
        }
    })
}

/// The follower of a law cam: a translating flat face, a translating knife/roller (offset
/// inside the base circle) or an oscillating arm that reaches the base circle.
fn law_follower(
    fo: &FollowerSpec,
    moving: &str,
    roller: f64,
    ferr: &FollowerErr,
    positive: &PositiveLen,
) -> Result<CamFollower, ScenarioError> {
    Ok(match (fo.kind.as_str(), moving) {
        ("flat", "translating") => CamFollower::Flat {
            rb: positive("base_radius", fo.base_radius)?,
            face_angle: flat_face_angle(fo, ferr)?,
        },
        ("flat", _) => {
            return Err(ferr(
                "motion",
                "a flat face on a law cam must translate (oscillating flat faces: [eccentric])"
                    .into(),
            ))
        }
        (_, "translating") => {
            let r0 = positive("base_radius", fo.base_radius)?;
            if fo.offset.abs() >= r0 {
                return Err(ferr(
                    "offset",
                    format!(
                        "|e| = {} must be less than the base radius {r0}",
                        fo.offset.abs()
                    ),
                ));
            }
            CamFollower::Translating {
                offset: fo.offset,
                roller,
                r0,
            }
        }
        _ => {
            let arm = positive("arm", fo.arm)?;
            let pivot = positive("pivot_distance", fo.pivot_distance)?;
            let r0 = positive("base_radius", fo.base_radius)?;
            if r0 <= (arm - pivot).abs() || r0 >= arm + pivot {
                return Err(ferr(
                    "base_radius",
                    "the arm cannot reach the base circle (|l − d| < r0 < l + d)".into(),
                ));
            }
            CamFollower::Oscillating {
                arm,
                pivot,
                roller,
                r0,
            }
        }
    })
}

/// `follower.face_angle_deg` (rad; 0 when absent), within ±80°.
fn flat_face_angle(fo: &FollowerSpec, ferr: &FollowerErr) -> Result<f64, ScenarioError> {
    match fo.face_angle_deg {
        None => Ok(0.0),
        Some(b) if b.is_finite() && b.abs() < 80.0 => Ok(b.to_radians()),
        Some(b) => Err(ferr(
            "face_angle_deg",
            format!("the face normal's angle to the stroke must lie within ±80°, got {b}"),
        )),
    }
}

fn scenario_file_name(name: Option<&str>, file: &str) -> String {
    name.map(str::to_string).unwrap_or_else(|| {
        Path::new(file)
            .file_stem()
            .map_or(NAME.into(), |s| s.to_string_lossy().into_owned())
    })
}

/// The `[limits]` pressure angles (rad), rise and return.
fn pressure_limits(cx: &Source, l: &Spanned<LimitSpec>) -> Result<(f64, f64), ScenarioError> {
    let ls = l.get_ref();
    let a = ls.pressure_angle_deg;
    let b = ls.return_pressure_angle_deg.unwrap_or(a);
    for (k, v) in [("pressure_angle_deg", a), ("return_pressure_angle_deg", b)] {
        if !in_range(v, 1.0, 89.0) {
            return Err(cx.field(
                l.span(),
                k,
                format!("limits.{k}"),
                "must be between 1° and 89°",
            ));
        }
    }
    Ok((a.to_radians(), b.to_radians()))
}

/// The cam speed (rad/s, default 1) and the steps per turn (default 360).
fn speed_and_steps(cx: &Source, f: &FileSpec) -> Result<(f64, usize), ScenarioError> {
    let omega = match &f.speed_rpm {
        None => 1.0,
        Some(n) if in_range(*n.get_ref(), 1e-9, 1e7) => n.get_ref() * std::f64::consts::PI / 30.0,
        Some(n) => return Err(cx.at(n.span(), "speed_rpm", "must be a positive speed")),
    };
    let steps = match &f.steps {
        None => 360,
        Some(n) if (8..=100_000).contains(n.get_ref()) => *n.get_ref() as usize,
        Some(n) => return Err(cx.at(n.span(), "steps", "expected 8 … 100000 steps per turn")),
    };
    Ok((omega, steps))
}

/// Parses and checks `text` (the contents of `file`).
pub fn parse(file: &str, text: &str) -> Result<CamScenario, ScenarioError> {
    let cx = Source::new(file, text);
    let f: FileSpec = toml::from_str(text).map_err(|e| cx.toml(&e))?;
    let (omega, steps) = speed_and_steps(&cx, &f)?;
    let fs = &f.follower;
    let fo = fs.get_ref();
    let ferr = |k: &str, m: String| cx.field(fs.span(), k, format!("follower.{k}"), m);
    let moving = fo.motion.clone().unwrap_or_else(|| "translating".into());
    if !matches!(moving.as_str(), "translating" | "oscillating") {
        return Err(ferr(
            "motion",
            format!("expected \"translating\" or \"oscillating\", got \"{moving}\""),
        ));
    }
    let positive = |k: &str, v: Option<f64>| -> Result<f64, ScenarioError> {
        match v {
            Some(x) if in_range(x, 1e-9, 1e7) => Ok(x),
            Some(x) => Err(ferr(k, format!("must be a positive length, got {x}"))),
            None => Err(ferr(k, "missing".into())),
        }
    };
    let roller = match (fo.kind.as_str(), fo.roller_radius) {
        ("roller", r) => positive("roller_radius", r)?,
        ("knife", None) | ("flat", None) => 0.0,
        ("knife" | "flat", Some(_)) => {
            return Err(ferr(
                "roller_radius",
                format!("a {} follower has no roller", fo.kind),
            ))
        }
        (other, _) => {
            return Err(ferr(
                "type",
                format!("expected \"knife\", \"roller\" or \"flat\", got \"{other}\""),
            ))
        }
    };
    if fo.face_angle_deg.is_some()
        && (fo.kind != "flat" || moving != "translating" || f.eccentric.is_some())
    {
        return Err(ferr(
            "face_angle_deg",
            "applies only to a translating flat face on a [motion] or [profile] cam".into(),
        ));
    }
    if let Some(ps) = &f.profile {
        if f.motion.is_some() || f.eccentric.is_some() {
            return Err(cx.at(
                ps.span(),
                "profile",
                "give one of [motion], [eccentric] or [profile]",
            ));
        }
        if let Some(l) = &f.limits {
            return Err(cx.at(
                l.span(),
                "limits",
                "does not apply to a [profile] cam (the limits size a law cam)",
            ));
        }
        for (k, given) in [
            ("base_radius", fo.base_radius.is_some()),
            ("face_offset", fo.face_offset.is_some()),
        ] {
            if given {
                return Err(ferr(
                    k,
                    "does not apply to a [profile] cam (the profile sets it)".into(),
                ));
            }
        }
        let arm_pivot = match (fo.arm, fo.pivot_distance) {
            (None, None) => None,
            (a, d) => Some((positive("arm", a)?, positive("pivot_distance", d)?)),
        };
        let face_angle = flat_face_angle(fo, &ferr)?;
        let pin = ProfileFollowerIn {
            kind: fo.kind.clone(),
            moving: moving.clone(),
            roller,
            offset: fo.offset,
            face_angle,
            arm_pivot,
        };
        let (m, follower) = profile_cam(&cx, ps, &pin)?;
        return Ok(CamScenario {
            name: scenario_file_name(f.name.as_deref(), file),
            omega,
            steps,
            cam: Cam::Law(m, follower),
            limits: None,
        });
    }
    if !fo.offset.is_finite() {
        return Err(ferr("offset", "not a finite number".into()));
    }
    let cam =
        match (&f.motion, &f.eccentric) {
            (Some(_), Some(e)) => {
                return Err(cx.at(
                    e.span(),
                    "eccentric",
                    "give either [motion] or [eccentric], not both",
                ))
            }
            (None, None) => return Err(cx.top(
                "kind",
                "a cam needs a [motion] table (a follower law), an [eccentric] disc or a [profile]",
            )),
            (None, Some(e)) => {
                let es = e.get_ref();
                let eerr = |k: &str, m: &str| cx.field(e.span(), k, format!("eccentric.{k}"), m);
                if !in_range(es.radius, 1e-9, 1e7) {
                    return Err(eerr("radius", "must be a positive length"));
                }
                if !in_range(es.eccentricity, 1e-9, 1e7) || es.eccentricity >= es.radius + roller {
                    return Err(eerr(
                        "eccentricity",
                        "must be positive and less than the disc radius (+ roller)",
                    ));
                }
                let follower = eccentric_follower(fo, &moving, (roller, es), &ferr, &positive)?;
                Cam::Eccentric(Eccentric {
                    radius: es.radius,
                    eccentricity: es.eccentricity,
                    follower,
                })
            }
            (Some(ms), None) => {
                let m = motion(&cx, ms, &moving)?;
                let follower = law_follower(fo, &moving, roller, &ferr, &positive)?;
                Cam::Law(m, follower)
            }
        };
    let limits = f
        .limits
        .as_ref()
        .map(|l| pressure_limits(&cx, l))
        .transpose()?;
    Ok(CamScenario {
        name: scenario_file_name(f.name.as_deref(), file),
        omega,
        steps,
        cam,
        limits,
    })
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "cam";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, opts| run(path, text, opts.out_dir.as_deref()),
};
