//! The `[two_position]` section of `kind = "synthesis"` files (`docs/synthesis.md`):
//! a four-bar through two crank/rocker position pairs with the frame and the crank or the
//! rocker given, or through two positions of its coupler with the fixed pivots on a given
//! line ([`crate::machines::synthesis::two_position`]). The result is run through the
//! linkage solver from the first position to the second and the rocker's error there is
//! reported.

use crate::core::diag::LocatedError as ScenarioError;
use crate::machines::linkage::{fourbar, wrap_angle, Vec2};
use crate::machines::synthesis::two_position::{self as two, GivenLink};
use crate::machines::synthesis::verify::RockerTrack;
use crate::scenarios::source::Source;
use serde::Deserialize;
use serde_json::{json, Value};
use std::fmt::Write;
use toml::Spanned;

type F = Spanned<f64>;
type Point = [F; 2];

const K: &str = "two_position";

/// Most solver steps (as the other synthesis sections).
const MAX_SAMPLES: usize = 100_000;

/// The keys of `[two_position]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoPositionIn {
    frame: Option<F>,
    precision_deg: Option<Spanned<Vec<[F; 2]>>>,
    crank: Option<F>,
    rocker: Option<F>,
    coupler_positions: Option<Spanned<[[Point; 2]; 2]>>,
    pivot_line: Option<Spanned<PivotLineIn>>,
    samples: Option<Spanned<usize>>,
}

/// `pivot_line = { point = [x, y], direction_deg = α }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PivotLineIn {
    point: Point,
    direction_deg: F,
}

/// A parsed `[two_position]` section.
#[derive(Clone, Debug)]
pub enum TwoPositionSpec {
    /// Two `(φ, ψ)` pairs (rad), the frame and the given link.
    Function {
        /// `(φ, ψ)` (rad).
        points: [(f64, f64); 2],
        /// Frame `d`.
        frame: f64,
        /// The crank or the rocker.
        given: GivenLink,
        /// Solver steps from the first position to the second.
        samples: usize,
    },
    /// Two coupler positions `(B, C)` and the pivot line (point, direction in rad).
    Coupler {
        /// `(B, C)` in each position.
        positions: [(Vec2, Vec2); 2],
        /// A point of the pivot line and its direction (rad).
        line: (Vec2, f64),
        /// Solver steps from the first position to the second.
        samples: usize,
    },
}

fn refuse<T>(
    ctx: &Source,
    v: Option<&Spanned<T>>,
    key: &str,
    why: &str,
) -> Result<(), ScenarioError> {
    match v {
        Some(v) => Err(ctx.at(v.span(), format!("{K}.{key}"), why.to_string())),
        None => Ok(()),
    }
}

fn point(ctx: &Source, p: &Point, key: &str) -> Result<Vec2, ScenarioError> {
    Ok(Vec2::new(
        ctx.finite(&p[0], &format!("{key}[0]"))?,
        ctx.finite(&p[1], &format!("{key}[1]"))?,
    ))
}

/// The `[two_position]` section: `precision_deg` with `frame` and `crank` or `rocker`, or
/// `coupler_positions` with an optional `pivot_line` (default: the x axis).
pub fn parse_two_position(
    ctx: &Source,
    s: &TwoPositionIn,
) -> Result<TwoPositionSpec, ScenarioError> {
    let samples = ctx.optional(
        s.samples.as_ref(),
        "two_position.samples",
        360,
        |n| (2..=MAX_SAMPLES).contains(&n),
        "must lie in 2..=100000",
    )?;
    let Some(cp) = &s.coupler_positions else {
        let why = "applies only to `coupler_positions`";
        refuse(ctx, s.pivot_line.as_ref(), "pivot_line", why)?;
        return parse_function(ctx, s, samples);
    };
    let why = "does not apply to `coupler_positions` (the pivots come from the pivot line)";
    refuse(ctx, s.frame.as_ref(), "frame", why)?;
    refuse(ctx, s.crank.as_ref(), "crank", why)?;
    refuse(ctx, s.rocker.as_ref(), "rocker", why)?;
    refuse(ctx, s.precision_deg.as_ref(), "precision_deg", why)?;
    let c = cp.get_ref();
    let mut positions = [(Vec2::zeros(), Vec2::zeros()); 2];
    for (i, pos) in c.iter().enumerate() {
        positions[i] = (
            point(ctx, &pos[0], &format!("{K}.coupler_positions[{i}][0]"))?,
            point(ctx, &pos[1], &format!("{K}.coupler_positions[{i}][1]"))?,
        );
    }
    let line = match &s.pivot_line {
        None => (Vec2::zeros(), 0.0),
        Some(l) => {
            let l = l.get_ref();
            (
                point(ctx, &l.point, "two_position.pivot_line.point")?,
                ctx.angle_deg(&l.direction_deg, "two_position.pivot_line.direction_deg")?
                    .to_radians(),
            )
        }
    };
    Ok(TwoPositionSpec::Coupler {
        positions,
        line,
        samples,
    })
}

fn parse_function(
    ctx: &Source,
    s: &TwoPositionIn,
    samples: usize,
) -> Result<TwoPositionSpec, ScenarioError> {
    let missing = |key: &str| {
        ctx.section(
            K,
            format!("missing: `{key}` (give `precision_deg`, `frame` and `crank` or `rocker`, or `coupler_positions`)"),
        )
    };
    let p = s
        .precision_deg
        .as_ref()
        .ok_or_else(|| missing("precision_deg"))?;
    let frame = ctx.length(
        s.frame.as_ref().ok_or_else(|| missing("frame"))?,
        "two_position.frame",
    )?;
    if p.get_ref().len() != 2 {
        return Err(ctx.at(
            p.span(),
            "two_position.precision_deg",
            format!(
                "needs exactly two [crank, rocker] pairs, got {}",
                p.get_ref().len()
            ),
        ));
    }
    let mut points = [(0.0, 0.0); 2];
    for (i, pair) in p.get_ref().iter().enumerate() {
        let key = format!("two_position.precision_deg[{i}]");
        points[i] = (
            ctx.angle_deg(&pair[0], &key)?.to_radians(),
            ctx.angle_deg(&pair[1], &key)?.to_radians(),
        );
    }
    let (by_crank, v) = ctx.one_of(
        K,
        ("crank", s.crank.as_ref()),
        ("rocker", s.rocker.as_ref()),
    )?;
    let key = if by_crank {
        "two_position.crank"
    } else {
        "two_position.rocker"
    };
    let len = ctx.length(v, key)?;
    ctx.same_scale(v, key, (frame, "two_position.frame"))?;
    let given = if by_crank {
        GivenLink::Crank(len)
    } else {
        GivenLink::Rocker(len)
    };
    Ok(TwoPositionSpec::Function {
        points,
        frame,
        given,
        samples,
    })
}

/// Runs `(a, b, c, d)` from `start = (φ₁, ψ₁)` to crank angle `phi_end` and returns the
/// rocker's error there against `psi_end` (deg).
fn solver_error(
    dims: (f64, f64, f64, f64),
    start: (f64, f64),
    (phi_end, psi_end): (f64, f64),
    samples: usize,
) -> Result<f64, String> {
    let t = RockerTrack::new(dims, [start.0, phi_end], start.1, samples)
        .map_err(|m| format!("the linkage solver: {m}"))?;
    let got = t
        .psi_at(phi_end)
        .ok_or("the linkage solver does not reach the second position")?;
    Ok(wrap_angle(got - psi_end).abs().to_degrees())
}

/// The report of a `[two_position]` section.
pub fn two_position_json(
    ctx: &Source,
    s: &TwoPositionSpec,
    text: &mut String,
) -> Result<Value, ScenarioError> {
    let err = |m: String| ctx.section(K, m);
    match s {
        TwoPositionSpec::Function {
            points,
            frame,
            given,
            samples,
        } => {
            let r =
                two::four_bar_from_two_positions(*points, *frame, *given).map_err(|e| err(e.0))?;
            let dims = (r.crank, r.coupler, r.rocker, r.frame);
            let e = solver_error(dims, points[0], points[1], *samples).map_err(err)?;
            let class = fourbar::classify(r.frame, r.crank.abs(), r.coupler, r.rocker.abs());
            writeln!(
                text,
                "two-position four-bar: K1 = {:.5}, K2 = {:.5}, K3 = {:.5}; crank a = {:.5}, coupler b = {:.5}, rocker c = {:.5}, frame d = {:.5} ({})\n  linkage solver from the first position to the second: rocker error {e:.1e}°",
                r.coefficients[0], r.coefficients[1], r.coefficients[2], r.crank, r.coupler, r.rocker, r.frame, class.kind
            )
            .ok();
            let mut v = serde_json::to_value(&r).unwrap_or(Value::Null);
            v["grashof"] = json!(class.kind);
            v["precision_points"] = json!(points
                .iter()
                .map(|(p, q)| json!({"crank_deg": p.to_degrees(), "rocker_deg": q.to_degrees()}))
                .collect::<Vec<_>>());
            v["check"] = json!({ "rocker_error_at_second_deg": e });
            Ok(v)
        }
        TwoPositionSpec::Coupler {
            positions,
            line,
            samples,
        } => {
            let r =
                two::four_bar_from_coupler_positions(positions[0], positions[1], line.0, line.1)
                    .map_err(|e| err(e.0))?;
            let dims = (r.crank, r.coupler, r.rocker, r.frame);
            let [[p1, q1], [_, q2]] = r.positions_deg;
            let phi_end = p1 + r.crank_turn_deg;
            let e = solver_error(
                dims,
                (p1.to_radians(), q1.to_radians()),
                (phi_end.to_radians(), q2.to_radians()),
                *samples,
            )
            .map_err(err)?;
            let class = fourbar::classify(r.frame, r.crank, r.coupler, r.rocker);
            writeln!(
                text,
                "two coupler positions: A = ({:.5}, {:.5}), D = ({:.5}, {:.5}); crank a = {:.5}, coupler b = {:.5}, rocker c = {:.5}, frame d = {:.5} ({})\n  crank turns {:.3}°, rocker {:.3}°, coupler {:.3}°; linkage solver from the first position to the second: rocker error {e:.1e}°",
                r.crank_pivot[0], r.crank_pivot[1], r.rocker_pivot[0], r.rocker_pivot[1], r.crank, r.coupler, r.rocker, r.frame, class.kind,
                r.crank_turn_deg, r.rocker_turn_deg, r.coupler_turn_deg
            )
            .ok();
            let mut v = serde_json::to_value(&r).unwrap_or(Value::Null);
            v["grashof"] = json!(class.kind);
            v["check"] = json!({ "rocker_error_at_second_deg": e });
            Ok(v)
        }
    }
}
