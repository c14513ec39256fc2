//! `kind = "synthesis"` scenarios (format in `docs/synthesis.md`): limit-position and
//! time-ratio synthesis of a crank-rocker, an offset slider-crank and a slotted-lever
//! quick return, and Freudenstein three-point function generation. Every result is run
//! through the linkage solver ([`crate::machines::synthesis::verify`]) and both are reported.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::plots::panels::{Panel, Series, PALETTE};
use crate::io::report::Report;
use crate::machines::linkage::fourbar;
use crate::machines::synthesis::verify::{self as chk, RockerTrack};
use crate::machines::synthesis::{self as syn, Function, FunctionMap, ShaperSize};
use crate::scenarios::kit::{finish_with_plot, scenario_name};
use crate::scenarios::source::Source;
use crate::scenarios::synthesis_crank_rocker::{
    crank_rocker_json, parse_crank_rocker, CrankRockerIn, CrankRockerSpec,
};
use crate::scenarios::synthesis_two_position::{
    parse_two_position, two_position_json, TwoPositionIn, TwoPositionSpec,
};
use serde::Deserialize;
use serde_json::{json, Value};
use std::fmt::Write;
use std::path::Path;
use toml::Spanned;

type F = Spanned<f64>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    crank_rocker: Option<CrankRockerIn>,
    two_position: Option<TwoPositionIn>,
    slider_crank: Option<SliderCrankIn>,
    shaper: Option<ShaperIn>,
    function: Option<FunctionIn>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SliderCrankIn {
    stroke: F,
    time_ratio: F,
    rod_ratio: Option<F>,
    offset: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ShaperIn {
    stroke: F,
    frame: Option<F>,
    crank: Option<F>,
    time_ratio: Option<F>,
    velocity_ratio: Option<F>,
    rod: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FunctionIn {
    frame: F,
    precision_deg: Option<Spanned<Vec<[F; 2]>>>,
    function: Option<Spanned<String>>,
    exponent: Option<F>,
    x_range: Option<Spanned<[F; 2]>>,
    crank_range_deg: Option<Spanned<[F; 2]>>,
    rocker_range_deg: Option<Spanned<[F; 2]>>,
    precision_x: Option<Spanned<[F; 3]>>,
    samples: Option<Spanned<usize>>,
}

/// A parsed function-generation section.
#[derive(Clone, Debug)]
pub struct FunctionSpec {
    frame: f64,
    /// `(φ, ψ)` (rad).
    points: [(f64, f64); 3],
    map: Option<FunctionMap>,
    precision_x: Vec<f64>,
    samples: usize,
}

/// A parsed and validated synthesis scenario.
#[derive(Clone, Debug)]
pub struct SynthesisScenario {
    /// The scenario's name.
    pub name: String,
    crank_rocker: Option<CrankRockerSpec>,
    two_position: Option<TwoPositionSpec>,
    slider_crank: Option<(f64, f64, Result<f64, f64>)>,
    shaper: Option<ShaperSpec>,
    function: Option<FunctionSpec>,
}

/// Most samples of a structural-error sweep.
pub const MAX_SAMPLES: usize = 100_000;

/// Runs a synthesis scenario; plots go to `out_dir` when given.
pub fn run(path: &Path, text: &str, out_dir: Option<&Path>) -> Result<Report, ScenarioError> {
    crate::scenarios::kit::parse_and_report(path, text, out_dir, parse, report)
}

/// The `[slider_crank]` section: stroke, time ratio, and the rod ratio (`Ok`) or the offset
/// (`Err`).
fn parse_slider_crank(
    ctx: &Source,
    s: &SliderCrankIn,
) -> Result<(f64, f64, Result<f64, f64>), ScenarioError> {
    let h = ctx.length(&s.stroke, "slider_crank.stroke")?;
    let k = ctx.ratio(&s.time_ratio, "slider_crank.time_ratio", true)?;
    let (by_ratio, v) = ctx.one_of(
        "slider_crank",
        ("rod_ratio", s.rod_ratio.as_ref()),
        ("offset", s.offset.as_ref()),
    )?;
    let which = if by_ratio {
        let r = ctx.between(v, "slider_crank.rod_ratio", 0.0, 1.0)?;
        if r < 1.0 / crate::scenarios::source::MAX_SCALE_RATIO {
            return Err(ctx.at(
                v.span(),
                "slider_crank.rod_ratio",
                format!(
                    "{} is out of range: the crank and the rod of one mechanism lie within a \
                     factor 1e9 of each other (at least 1e-9)",
                    crate::core::diag::fmt_num(r)
                ),
            ));
        }
        Ok(r)
    } else {
        let e = ctx.length(v, "slider_crank.offset")?;
        ctx.same_scale(v, "slider_crank.offset", (h, "slider_crank.stroke"))?;
        Err(e)
    };
    Ok((h, k, which))
}

/// A parsed `[shaper]` section: stroke, frame or crank, the time or velocity ratio (and
/// whether it is the velocity ratio), rod.
type ShaperSpec = (f64, ShaperSize, f64, bool, Option<f64>);

/// The `[shaper]` section: stroke, frame or crank, the time or velocity ratio, rod.
fn parse_shaper(ctx: &Source, s: &ShaperIn) -> Result<ShaperSpec, ScenarioError> {
    let h = ctx.length(&s.stroke, "shaper.stroke")?;
    let (by_frame, size) = ctx.one_of(
        "shaper",
        ("frame", s.frame.as_ref()),
        ("crank", s.crank.as_ref()),
    )?;
    let size_key = if by_frame {
        "shaper.frame"
    } else {
        "shaper.crank"
    };
    let d = ctx.length(size, size_key)?;
    ctx.same_scale(&s.stroke, "shaper.stroke", (d, size_key))?;
    let (by_time, v) = ctx.one_of(
        "shaper",
        ("time_ratio", s.time_ratio.as_ref()),
        ("velocity_ratio", s.velocity_ratio.as_ref()),
    )?;
    let key = if by_time {
        "shaper.time_ratio"
    } else {
        "shaper.velocity_ratio"
    };
    let k = ctx.ratio(v, key, false)?;
    let rod = s
        .rod
        .as_ref()
        .map(|r| {
            ctx.same_scale(r, "shaper.rod", (d, size_key))?;
            ctx.length(r, "shaper.rod")
        })
        .transpose()?;
    let size = if by_frame {
        ShaperSize::Frame(d)
    } else {
        ShaperSize::Crank(d)
    };
    Ok((h, size, k, !by_time, rod))
}

/// Parses and validates `text` (the contents of `file`).
pub fn parse(file: &str, text: &str) -> Result<SynthesisScenario, ScenarioError> {
    let ctx = Source::new(file, text);
    let f: File = ctx.parse()?;
    ctx.any_section(
        &[
            f.crank_rocker.is_some(),
            f.two_position.is_some(),
            f.slider_crank.is_some(),
            f.shaper.is_some(),
            f.function.is_some(),
        ],
        "nothing to synthesise: add [crank_rocker], [two_position], [slider_crank], [shaper] or [function]",
    )?;
    let crank_rocker = f
        .crank_rocker
        .as_ref()
        .map(|x| parse_crank_rocker(&ctx, x))
        .transpose()?;
    let two_position = f
        .two_position
        .as_ref()
        .map(|x| parse_two_position(&ctx, x))
        .transpose()?;
    let slider_crank = f
        .slider_crank
        .as_ref()
        .map(|x| parse_slider_crank(&ctx, x))
        .transpose()?;
    let shaper = f
        .shaper
        .as_ref()
        .map(|x| parse_shaper(&ctx, x))
        .transpose()?;
    let function = f
        .function
        .as_ref()
        .map(|s| parse_function(&ctx, s))
        .transpose()?;
    Ok(SynthesisScenario {
        name: scenario_name(f.name.as_deref(), file),
        crank_rocker,
        two_position,
        slider_crank,
        shaper,
        function,
    })
}

/// A `[start, end]` pair of finite numbers; angles (`degrees`) within
/// ±[`MAX_ANGLE_DEG`](crate::scenarios::source::MAX_ANGLE_DEG).
fn pair(
    ctx: &Source,
    v: &Spanned<[F; 2]>,
    key: &str,
    degrees: bool,
) -> Result<[f64; 2], ScenarioError> {
    let a = v.get_ref();
    let one = |x: &F, k: String| {
        if degrees {
            ctx.angle_deg(x, &k)
        } else {
            ctx.finite(x, &k)
        }
    };
    Ok([
        one(&a[0], format!("{key}[0]"))?,
        one(&a[1], format!("{key}[1]"))?,
    ])
}

fn parse_function(ctx: &Source, s: &FunctionIn) -> Result<FunctionSpec, ScenarioError> {
    let frame = ctx.length(&s.frame, "function.frame")?;
    let samples = match &s.samples {
        None => 360,
        Some(n) if *n.get_ref() >= 2 && *n.get_ref() <= MAX_SAMPLES => *n.get_ref(),
        Some(n) => {
            return Err(ctx.at(
                n.span(),
                "function.samples",
                format!("must lie in 2..={MAX_SAMPLES}"),
            ))
        }
    };
    match (&s.precision_deg, &s.function) {
        (Some(p), None) => function_by_points(ctx, p, frame, samples),
        (None, Some(name)) => function_by_name(ctx, s, name, frame, samples),
        (Some(p), Some(_)) => Err(ctx.at(
            p.span(),
            "function.precision_deg",
            "give either `precision_deg` or `function`, not both",
        )),
        (None, None) => Err(ctx.section(
            "function",
            "missing: `precision_deg` (three crank/rocker pairs) or `function` with its ranges",
        )),
    }
}

/// `[function]` given by three precision points `[crank, rocker]` (degrees).
fn function_by_points(
    ctx: &Source,
    p: &Spanned<Vec<[F; 2]>>,
    frame: f64,
    samples: usize,
) -> Result<FunctionSpec, ScenarioError> {
    let pts = p.get_ref();
    if pts.len() != 3 {
        return Err(ctx.at(
            p.span(),
            "function.precision_deg",
            format!(
                "needs exactly three [crank, rocker] pairs, got {}",
                pts.len()
            ),
        ));
    }
    let mut points = [(0.0, 0.0); 3];
    for (i, pair) in pts.iter().enumerate() {
        let k = format!("function.precision_deg[{i}]");
        points[i] = (
            ctx.angle_deg(&pair[0], &k)?.to_radians(),
            ctx.angle_deg(&pair[1], &k)?.to_radians(),
        );
    }
    Ok(FunctionSpec {
        frame,
        points,
        map: None,
        precision_x: Vec::new(),
        samples,
    })
}

/// `[function]` given by a named function `y = f(x)` over `x_range`, mapped linearly to
/// the crank and rocker ranges, with Chebyshev (or the given) precision points.
fn function_by_name(
    ctx: &Source,
    s: &FunctionIn,
    name: &Spanned<String>,
    frame: f64,
    samples: usize,
) -> Result<FunctionSpec, ScenarioError> {
    let exp = s
        .exponent
        .as_ref()
        .map(|e| ctx.finite(e, "function.exponent"))
        .transpose()?;
    let f = Function::from_name(name.get_ref(), exp).ok_or_else(|| {
        ctx.at(
            name.span(),
            "function.function",
            format!(
                "unknown function '{}' (expected one of {}; `power` needs `exponent`)",
                name.get_ref(),
                Function::NAMES
            ),
        )
    })?;
    fn need<'a>(
        ctx: &Source,
        v: &'a Option<Spanned<[F; 2]>>,
        key: &str,
    ) -> Result<&'a Spanned<[F; 2]>, ScenarioError> {
        v.as_ref()
            .ok_or_else(|| ctx.section("function", format!("missing: `{key}` (with `function`)")))
    }
    let x = pair(
        ctx,
        need(ctx, &s.x_range, "x_range")?,
        "function.x_range",
        false,
    )?;
    let phi = pair(
        ctx,
        need(ctx, &s.crank_range_deg, "crank_range_deg")?,
        "function.crank_range_deg",
        true,
    )?;
    let psi = pair(
        ctx,
        need(ctx, &s.rocker_range_deg, "rocker_range_deg")?,
        "function.rocker_range_deg",
        true,
    )?;
    let xr = s.x_range.as_ref().map(|v| v.span()).unwrap_or(0..0);
    let (y0, y1) = (f.eval(x[0]), f.eval(x[1]));
    if x[0] == x[1] || !y0.is_finite() || !y1.is_finite() || y0 == y1 {
        return Err(ctx.at(
            xr,
            "function.x_range",
            format!("the function must be finite and differ at the two ends (f = {y0}, {y1})"),
        ));
    }
    if phi[0] == phi[1] || psi[0] == psi[1] {
        return Err(ctx.section("function", "the crank and rocker ranges must not be empty"));
    }
    let map = FunctionMap {
        f,
        x,
        phi: [phi[0].to_radians(), phi[1].to_radians()],
        psi: [psi[0].to_radians(), psi[1].to_radians()],
    };
    let px = match &s.precision_x {
        Some(p) => {
            let a = p.get_ref();
            let mut v = Vec::new();
            for (i, xi) in a.iter().enumerate() {
                v.push(ctx.finite(xi, &format!("function.precision_x[{i}]"))?);
            }
            v
        }
        None => syn::chebyshev_points(x[0], x[1], 3),
    };
    for (i, xi) in px.iter().enumerate() {
        if !f.eval(*xi).is_finite() {
            return Err(ctx.section(
                "function",
                format!("f is not finite at precision point {i} (x = {xi})"),
            ));
        }
    }
    let points = [0, 1, 2].map(|i| (map.phi_of(px[i]), map.psi_of(px[i])));
    Ok(FunctionSpec {
        frame,
        points,
        map: Some(map),
        precision_x: px,
        samples,
    })
}

fn slider_crank_json(
    ctx: &Source,
    (h, k, which): (f64, f64, Result<f64, f64>),
    text: &mut String,
) -> Result<Value, ScenarioError> {
    let err = |m: String| ctx.section("slider_crank", m);
    let d = match which {
        Ok(lambda) => syn::slider_crank_from_ratio(h, k, lambda),
        Err(e) => syn::slider_crank_from_offset(h, k, e),
    }
    .map_err(|e| err(e.0))?;
    let c = chk::check_slider_crank(d.crank, d.rod, d.offset)
        .map_err(|m| err(format!("the linkage solver: {m}")))?;
    writeln!(
        text,
        "slider-crank: crank r = {:.5}, rod l = {:.5}, offset e = {:.5}; θ = {:.3}°, K = {:.4}, largest pressure angle {:.2}°",
        d.crank, d.rod, d.offset, d.theta_deg, d.time_ratio, d.max_pressure_angle_deg
    )
    .ok();
    writeln!(
        text,
        "  linkage solver: stroke {:.5}, θ = {:.3}°, K = {:.4}, largest pressure angle {:.2}°",
        c.travel, c.theta_deg, c.time_ratio, c.max_pressure_angle_deg
    )
    .ok();
    let mut v = serde_json::to_value(&d).unwrap_or(Value::Null);
    v["check"] = json!({
        "stroke": c.travel,
        "theta_deg": c.theta_deg,
        "time_ratio": c.time_ratio,
        "max_pressure_angle_deg": c.max_pressure_angle_deg,
    });
    Ok(v)
}

fn shaper_json(
    ctx: &Source,
    (h, size, k, by_v, rod): ShaperSpec,
    text: &mut String,
) -> Result<Value, ScenarioError> {
    let err = |m: String| ctx.section("shaper", m);
    let s = syn::shaper(h, size, k, by_v, rod).map_err(|e| err(e.0))?;
    let c = chk::check_slotted_lever(s.frame, s.crank, s.lever)
        .map_err(|m| err(format!("the linkage solver: {m}")))?;
    writeln!(
        text,
        "shaper: crank r = {:.5}, lever L = {:.5}, swing ψ = {:.3}°, K = {:.4}, K_v = {:.4}, sagitta {:.4}{}",
        s.crank, s.lever, s.swing_deg, s.time_ratio, s.velocity_ratio, s.sagitta,
        s.max_rod_angle_deg.map(|a| format!(", largest rod angle {a:.2}°")).unwrap_or_default()
    )
    .ok();
    writeln!(
        text,
        "  linkage solver: lever swing {:.4}°, K = {:.4}",
        c.travel, c.time_ratio
    )
    .ok();
    let mut v = serde_json::to_value(&s).unwrap_or(Value::Null);
    v["check"] = json!({ "swing_deg": c.travel, "time_ratio": c.time_ratio });
    Ok(v)
}

fn function_json(
    ctx: &Source,
    s: &FunctionSpec,
    text: &mut String,
    panels: &mut Vec<Panel>,
) -> Result<Value, ScenarioError> {
    let err = |m: String| ctx.section("function", m);
    let k = syn::freudenstein_coefficients(&s.points).map_err(|e| err(e.0))?;
    let (a, c) = (s.frame / k[0], s.frame / k[1]);
    let b = syn::four_bar_from_coefficients(k, s.frame).map_err(|e| err(e.0))?[1];
    let class = fourbar::classify(s.frame, a.abs(), b, c.abs());
    writeln!(
        text,
        "function generator: K1 = {:.5}, K2 = {:.5}, K3 = {:.5}",
        k[0], k[1], k[2]
    )
    .ok();
    writeln!(
        text,
        "  crank a = {a:.5}, coupler b = {b:.5}, rocker c = {c:.5}, frame d = {:.5} ({})",
        s.frame, class.kind
    )
    .ok();
    let pts: Vec<Value> = s
        .points
        .iter()
        .enumerate()
        .map(|(i, (p, q))| json!({"x": s.precision_x.get(i), "crank_deg": p.to_degrees(), "rocker_deg": q.to_degrees()}))
        .collect();
    let mut v = json!({
        "coefficients": k,
        "crank": a, "coupler": b, "rocker": c, "frame": s.frame,
        "grashof": class.kind,
        "precision_points": pts,
    });
    let dims = (a, b, c, s.frame);
    match &s.map {
        Some(map) => {
            let e = chk::structural_error(dims, map, &s.precision_x, s.samples)
                .map_err(|m| err(format!("the linkage solver: {m}")))?;
            writeln!(
                text,
                "  structural error (linkage solver): largest {:.4}° of rocker ({:.3e} in y) at x = {:.4}; at the precision points {:?}°",
                e.max_angle_error_deg, e.max_function_error, e.at_x,
                e.at_precision_points_deg.iter().map(|x| format!("{x:.1e}")).collect::<Vec<_>>()
            )
            .ok();
            panels.push(Panel {
                title: "structural error".into(),
                x_desc: "x".into(),
                y_desc: "rocker angle error (deg)".into(),
                series: vec![Series {
                    label: "ψ − ψ ideal".into(),
                    points: e.curve.iter().map(|p| (p[0], p[1])).collect(),
                    color: PALETTE[0],
                    dashed: false,
                }],
                ..Default::default()
            });
            v["structural_error"] = json!({
                "max_angle_error_deg": e.max_angle_error_deg,
                "max_function_error": e.max_function_error,
                "at_x": e.at_x,
                "at_precision_points_deg": e.at_precision_points_deg,
            });
        }
        None => {
            let (phi0, phi1) = (s.points[0].0, s.points[2].0);
            let t = RockerTrack::new(dims, [phi0, phi1], s.points[0].1, s.samples)
                .map_err(|m| err(format!("the linkage solver: {m}")))?;
            let mut errs = Vec::new();
            for (phi, psi) in &s.points {
                let got = t.psi_at(*phi).ok_or_else(|| {
                    err("the linkage solver does not reach a precision point".into())
                })?;
                errs.push(
                    crate::machines::linkage::wrap_angle(got - psi)
                        .abs()
                        .to_degrees(),
                );
            }
            writeln!(
                text,
                "  linkage solver at the precision points: rocker errors {:?}°",
                errs.iter().map(|x| format!("{x:.1e}")).collect::<Vec<_>>()
            )
            .ok();
            v["precision_check_deg"] = json!(errs);
        }
    }
    Ok(v)
}

/// Computes the report of a parsed scenario.
pub fn report(
    ctx: &Source,
    sc: &SynthesisScenario,
    out_dir: Option<&Path>,
) -> Result<Report, ScenarioError> {
    let mut text = format!("synthesis: {}\n", sc.name);
    let mut j = json!({ "kind": NAME, "name": sc.name });
    let mut panels = Vec::new();
    if let Some(s) = &sc.crank_rocker {
        j["crank_rocker"] = crank_rocker_json(ctx, s, &mut text)?;
    }
    if let Some(s) = &sc.two_position {
        j["two_position"] = two_position_json(ctx, s, &mut text)?;
    }
    if let Some(s) = sc.slider_crank {
        j["slider_crank"] = slider_crank_json(ctx, s, &mut text)?;
    }
    if let Some(s) = sc.shaper {
        j["shaper"] = shaper_json(ctx, s, &mut text)?;
    }
    if let Some(s) = &sc.function {
        j["function"] = function_json(ctx, s, &mut text, &mut panels)?;
    }
    finish_with_plot(ctx, out_dir, (&sc.name, NAME), (&panels, 1), j, text)
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "synthesis";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, opts| run(path, text, opts.out_dir.as_deref()),
};
