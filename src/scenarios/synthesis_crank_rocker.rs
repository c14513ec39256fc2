//! The `[crank_rocker]` section of `kind = "synthesis"` files (`docs/synthesis.md`): a
//! crank-rocker from its two rocker limit positions and the crank pivot's direction or the
//! time ratio, or from one limit position, the pivot's direction and the time ratio. Each
//! solution is run through the linkage solver and both are reported.

use crate::core::diag::LocatedError as ScenarioError;
use crate::machines::linkage::fourbar;
use crate::machines::linkage::Vec2;
use crate::machines::synthesis::verify as chk;
use crate::machines::synthesis::{self as syn, RockerLimit};
use crate::scenarios::source::Source;
use serde::Deserialize;
use serde_json::{json, Value};
use std::fmt::Write;
use toml::Spanned;

type F = Spanned<f64>;

/// The keys of `[crank_rocker]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrankRockerIn {
    rocker: F,
    rocker_limits_deg: Option<Spanned<[F; 2]>>,
    rocker_limit_deg: Option<F>,
    limit: Option<Spanned<String>>,
    frame: F,
    pivot_direction_deg: Option<F>,
    time_ratio: Option<F>,
}

/// What a crank-rocker section asks for.
#[derive(Clone, Debug)]
enum CrankRockerTask {
    /// Both limits (rad) and the crank pivot.
    Pivot([f64; 2], Vec2),
    /// Both limits (rad) and the time ratio.
    TimeRatio([f64; 2], f64),
    /// One limit (rad), which one if known, the time ratio and the crank pivot.
    OneLimit {
        limit: f64,
        which: Option<RockerLimit>,
        k: f64,
        pivot: Vec2,
    },
}

/// A parsed crank-rocker section.
#[derive(Clone, Debug)]
pub struct CrankRockerSpec {
    rocker: f64,
    frame: f64,
    task: CrankRockerTask,
}

const K: &str = "crank_rocker";

fn pivot_at(ctx: &Source, v: &F, frame: f64) -> Result<Vec2, ScenarioError> {
    let a = ctx
        .angle_deg(v, "crank_rocker.pivot_direction_deg")?
        .to_radians();
    Ok(Vec2::new(frame * a.cos(), frame * a.sin()))
}

/// The `[crank_rocker]` section: rocker, frame, and either both limit positions with the
/// pivot direction or the time ratio, or one limit position with both.
pub fn parse_crank_rocker(
    ctx: &Source,
    s: &CrankRockerIn,
) -> Result<CrankRockerSpec, ScenarioError> {
    let rocker = ctx.length(&s.rocker, "crank_rocker.rocker")?;
    let frame = ctx.length(&s.frame, "crank_rocker.frame")?;
    ctx.same_scale(
        &s.rocker,
        "crank_rocker.rocker",
        (frame, "crank_rocker.frame"),
    )?;
    let task = match (&s.rocker_limits_deg, &s.rocker_limit_deg) {
        (Some(lim), None) => two_limits(ctx, s, lim, frame)?,
        (None, Some(one)) => one_limit(ctx, s, one, frame)?,
        (Some(_), Some(one)) => {
            return Err(ctx.at(
                one.span(),
                "crank_rocker.rocker_limit_deg",
                "give either `rocker_limits_deg` (both limits) or `rocker_limit_deg` (one), not both",
            ))
        }
        (None, None) => {
            return Err(ctx.section(
                K,
                "missing: give `rocker_limits_deg` (both limit positions) or `rocker_limit_deg` (one, with `time_ratio` and `pivot_direction_deg`)",
            ))
        }
    };
    Ok(CrankRockerSpec {
        rocker,
        frame,
        task,
    })
}

fn two_limits(
    ctx: &Source,
    s: &CrankRockerIn,
    lim: &Spanned<[F; 2]>,
    frame: f64,
) -> Result<CrankRockerTask, ScenarioError> {
    if let Some(l) = &s.limit {
        return Err(ctx.at(
            l.span(),
            "crank_rocker.limit",
            "applies only to one given limit (`rocker_limit_deg`); both limits are given",
        ));
    }
    let v = lim.get_ref();
    let limits = [
        ctx.angle_deg(&v[0], "crank_rocker.rocker_limits_deg[0]")?
            .to_radians(),
        ctx.angle_deg(&v[1], "crank_rocker.rocker_limits_deg[1]")?
            .to_radians(),
    ];
    if crate::machines::linkage::wrap_angle(limits[0] - limits[1]).abs() < 1e-9 {
        return Err(ctx.at(
            lim.span(),
            "crank_rocker.rocker_limits_deg",
            "the two limit positions coincide",
        ));
    }
    let (by_dir, v) = ctx.one_of(
        K,
        ("pivot_direction_deg", s.pivot_direction_deg.as_ref()),
        ("time_ratio", s.time_ratio.as_ref()),
    )?;
    Ok(if by_dir {
        CrankRockerTask::Pivot(limits, pivot_at(ctx, v, frame)?)
    } else {
        CrankRockerTask::TimeRatio(limits, ctx.ratio(v, "crank_rocker.time_ratio", false)?)
    })
}

fn one_limit(
    ctx: &Source,
    s: &CrankRockerIn,
    one: &F,
    frame: f64,
) -> Result<CrankRockerTask, ScenarioError> {
    let need = |key: &str| {
        ctx.section(
            K,
            format!("missing: `{key}` (one limit position needs both `time_ratio` and `pivot_direction_deg`)"),
        )
    };
    let k = ctx.ratio(
        s.time_ratio.as_ref().ok_or_else(|| need("time_ratio"))?,
        "crank_rocker.time_ratio",
        false,
    )?;
    let pivot = pivot_at(
        ctx,
        s.pivot_direction_deg
            .as_ref()
            .ok_or_else(|| need("pivot_direction_deg"))?,
        frame,
    )?;
    let which = match &s.limit {
        None => None,
        Some(w) => Some(match w.get_ref().as_str() {
            "extended" => RockerLimit::Extended,
            "folded" => RockerLimit::Folded,
            other => {
                return Err(ctx.at(
                    w.span(),
                    "crank_rocker.limit",
                    format!("unknown limit '{other}' (expected extended or folded)"),
                ))
            }
        }),
    };
    Ok(CrankRockerTask::OneLimit {
        limit: ctx
            .angle_deg(one, "crank_rocker.rocker_limit_deg")?
            .to_radians(),
        which,
        k,
        pivot,
    })
}

/// The report of a `[crank_rocker]` section: every solution, checked by the linkage solver.
pub fn crank_rocker_json(
    ctx: &Source,
    s: &CrankRockerSpec,
    text: &mut String,
) -> Result<Value, ScenarioError> {
    let err = |m: String| ctx.section("crank_rocker", m);
    let sols = match s.task {
        CrankRockerTask::Pivot(limits, p) => {
            vec![syn::crank_rocker_from_pivot(s.rocker, limits, p).map_err(|e| err(e.0))?]
        }
        CrankRockerTask::TimeRatio(limits, k) => {
            syn::crank_rockers_from_time_ratio(s.rocker, limits, k, s.frame)
                .map_err(|e| err(e.0))?
        }
        CrankRockerTask::OneLimit {
            limit,
            which,
            k,
            pivot,
        } => syn::crank_rockers_from_one_limit(s.rocker, limit, which, k, pivot)
            .map_err(|e| err(e.0))?,
    };
    let mut out = Vec::new();
    writeln!(
        text,
        "crank-rocker ({} solution{}):",
        sols.len(),
        if sols.len() == 1 { "" } else { "s" }
    )
    .ok();
    for (i, sol) in sols.iter().enumerate() {
        // The solver's frame: A at the origin, D on the +x axis.
        let beta = sol.frame_angle_deg.to_radians();
        let pivot = Vec2::new(sol.pivot[0], sol.pivot[1]);
        let ce = Vec2::new(
            s.rocker * sol.limit_angles_deg[0].to_radians().cos(),
            s.rocker * sol.limit_angles_deg[0].to_radians().sin(),
        );
        let ce_l = crate::machines::linkage::rotate(-beta, &(ce - pivot));
        let phi_ext = ce_l.y.atan2(ce_l.x);
        let dims = (sol.frame, sol.crank, sol.coupler, sol.rocker);
        let check = chk::check_four_bar(dims, phi_ext, ce_l)
            .map_err(|m| err(format!("solution {i}: the linkage solver: {m}")))?;
        let class = fourbar::classify(sol.frame, sol.crank, sol.coupler, sol.rocker);
        let (mu0, mu180) =
            fourbar::transmission_extremes(sol.frame, sol.crank, sol.coupler, sol.rocker);
        let pa = |m: Option<f64>| m.map(|m| (90.0 - m.to_degrees()).abs());
        writeln!(
            text,
            "  [{i}] A = ({:.5}, {:.5}) from D: crank a = {:.5}, coupler b = {:.5}, rocker c = {:.5}, frame d = {:.5} ({})",
            sol.pivot[0], sol.pivot[1], sol.crank, sol.coupler, sol.rocker, sol.frame, class.kind
        )
        .ok();
        writeln!(
            text,
            "      AC' = {:.5}, AC'' = {:.5}, θ = {:.3}°, K = {:.4}; pressure angle at C', C'' = {:.2}°, {:.2}°",
            sol.extended, sol.folded, sol.theta_deg, sol.time_ratio, sol.pressure_at_limits_deg[0], sol.pressure_at_limits_deg[1]
        )
        .ok();
        writeln!(
            text,
            "      linkage solver: swing {:.4}°, θ = {:.3}°, K = {:.4}; largest pressure angle {:.2}° at crank {:.1}° (closed form at 0°/180°: {:.2}°/{:.2}°)",
            check.travel, check.theta_deg, check.time_ratio, check.max_pressure_angle_deg, check.max_pressure_at_deg,
            pa(mu0).unwrap_or(f64::NAN), pa(mu180).unwrap_or(f64::NAN)
        )
        .ok();
        let mut v = serde_json::to_value(sol).unwrap_or(Value::Null);
        v["grashof"] = json!(class.kind);
        v["pressure_angle_at_crank_0_deg"] = json!(pa(mu0));
        v["pressure_angle_at_crank_180_deg"] = json!(pa(mu180));
        v["check"] = json!({
            "swing_deg": check.travel,
            "theta_deg": check.theta_deg,
            "time_ratio": check.time_ratio,
            "limit_crank_deg": check.crank_deg,
            "max_pressure_angle_deg": check.max_pressure_angle_deg,
            "max_pressure_at_crank_deg": check.max_pressure_at_deg,
        });
        out.push(v);
    }
    Ok(json!({ "solutions": out }))
}
