//! `kind = "flexible_rotor"` scenarios (format in `docs/flexible_rotor.md`): critical
//! speeds and mode shapes by finite elements checked by transfer matrices, the rigid-rotor
//! limit, the unbalance response over speeds with each mode's amplification, and N / N + 2
//! plane modal balancing.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::plots::panels::{Panel, Series, PALETTE};
use crate::io::report::Report;
use crate::machines::balancing::modal::{modal_amplification, modal_balance};
use crate::machines::vibration::rotor::{
    fe_modes, unbalance_response, Bearing, Disc, FlexibleRotor, RotorMode, Segment,
};
use crate::machines::vibration::rotor_transfer::critical_speeds;
use crate::scenarios::kit::{finish_with_plot, scenario_name};
use crate::scenarios::source::Source;
use serde::Deserialize;
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;
use toml::Spanned;

type F = Spanned<f64>;
/// Planes, target mode index, other mode indices, rigid-body conditions, modal unbalance.
type Balancing = (Vec<f64>, usize, Vec<usize>, bool, f64);

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    shaft: ShaftIn,
    #[serde(default)]
    discs: Vec<Spanned<DiscIn>>,
    bearings: Spanned<Vec<Spanned<BearingIn>>>,
    analysis: Option<AnalysisIn>,
    response: Option<ResponseIn>,
    modal_balancing: Option<BalancingIn>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ShaftIn {
    youngs_modulus: Option<F>,
    density: Option<F>,
    segments: Spanned<Vec<Spanned<SegmentIn>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentIn {
    length: F,
    diameter: Option<F>,
    inner_diameter: Option<F>,
    ei: Option<F>,
    mass_per_length: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DiscIn {
    at: F,
    mass: F,
    unbalance: Option<F>,
    phase_deg: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BearingIn {
    at: F,
    stiffness: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AnalysisIn {
    modes: Option<Spanned<usize>>,
    elements: Option<Spanned<usize>>,
    max_speed_rpm: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ResponseIn {
    speeds_rpm: Option<Spanned<Vec<F>>>,
    /// Speeds as multiples of the first critical speed ω1 (the texts' `ω/ω1`).
    speed_ratios: Option<Spanned<Vec<F>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BalancingIn {
    planes: Spanned<Vec<F>>,
    mode: Spanned<usize>,
    other_modes: Option<Spanned<Vec<Spanned<usize>>>>,
    rigid_body: Option<bool>,
    modal_unbalance: Option<F>,
}

/// A parsed and validated flexible-rotor scenario.
#[derive(Clone, Debug)]
pub struct FlexibleRotorScenario {
    /// Its name.
    pub name: String,
    /// The rotor.
    pub rotor: FlexibleRotor,
    /// Modes to report.
    pub modes: usize,
    /// Finite elements (about).
    pub elements: usize,
    max_speed: Option<f64>,
    speeds: Vec<f64>,
    /// Response speeds as multiples of ω1 (after `speeds`).
    ratios: Vec<f64>,
    balancing: Option<Balancing>,
}

/// Most finite elements (a dense eigenproblem of twice as many DOFs).
pub const MAX_ELEMENTS: usize = 400;
/// Most modes reported.
pub const MAX_MODES: usize = 20;
/// Most response speeds.
pub const MAX_SPEEDS: usize = 10_000;

/// Runs a flexible-rotor scenario; plots go to `out_dir` when given.
pub fn run(path: &Path, text: &str, out_dir: Option<&Path>) -> Result<Report, ScenarioError> {
    crate::scenarios::kit::parse_and_report(path, text, out_dir, parse, report)
}

fn segment(
    ctx: &Source,
    s: &Spanned<SegmentIn>,
    i: usize,
    mat: (Option<f64>, Option<f64>),
) -> Result<Segment, ScenarioError> {
    let k = format!("shaft.segments[{i}]");
    let v = s.get_ref();
    let len = ctx.positive(&v.length, &format!("{k}.length"))?;
    match (&v.diameter, &v.ei, &v.mass_per_length) {
        (Some(d), None, None) => {
            let d = ctx.positive(d, &format!("{k}.diameter"))?;
            let di = v
                .inner_diameter
                .as_ref()
                .map(|x| ctx.non_negative(x, &format!("{k}.inner_diameter")))
                .transpose()?
                .unwrap_or(0.0);
            if di >= d {
                return Err(ctx.at(
                    s.span(),
                    format!("{k}.inner_diameter"),
                    "must be smaller than the diameter",
                ));
            }
            let (Some(e), Some(rho)) = mat else {
                return Err(ctx.section(
                    "shaft",
                    "a segment given by its diameter needs `youngs_modulus` and `density`",
                ));
            };
            Ok(Segment::circular(len, d, di, e, rho))
        }
        (None, Some(_), Some(_)) if v.inner_diameter.is_some() => Err(ctx.at(
            s.span(),
            format!("{k}.inner_diameter"),
            "does not apply to a segment given by `ei` and `mass_per_length` (it goes with \
             `diameter`)",
        )),
        (None, Some(ei), Some(mu)) => Ok(Segment {
            length: len,
            ei: ctx.positive(ei, &format!("{k}.ei"))?,
            mu: ctx.positive(mu, &format!("{k}.mass_per_length"))?,
        }),
        _ => Err(ctx.at(
            s.span(),
            k,
            "give either `diameter` (with the shaft's material) or both `ei` and `mass_per_length`",
        )),
    }
}

/// A position along the shaft `[0, len]` (rounding outside by 1e-12 relative is clamped).
fn on_shaft(ctx: &Source, v: &F, key: String, len: f64) -> Result<f64, ScenarioError> {
    let x = ctx.finite(v, &key)?;
    if !(-1e-12 * len..=len * (1.0 + 1e-12)).contains(&x) {
        return Err(ctx.at(
            v.span(),
            key,
            format!("{x} lies outside the shaft [0, {len}]"),
        ));
    }
    Ok(x.clamp(0.0, len))
}

/// The `[[discs]]`: position, mass, unbalance and its phase.
fn parse_discs(
    ctx: &Source,
    discs: &[Spanned<DiscIn>],
    len: f64,
) -> Result<Vec<Disc>, ScenarioError> {
    let mut out = Vec::new();
    for (i, d) in discs.iter().enumerate() {
        let k = format!("discs[{i}]");
        let v = d.get_ref();
        out.push(Disc {
            at: on_shaft(ctx, &v.at, format!("{k}.at"), len)?,
            mass: ctx.non_negative(&v.mass, &format!("{k}.mass"))?,
            unbalance: ctx.non_negative_or(v.unbalance.as_ref(), &format!("{k}.unbalance"), 0.0)?,
            phase: v
                .phase_deg
                .as_ref()
                .map(|p| ctx.angle_deg(p, &format!("{k}.phase_deg")))
                .transpose()?
                .unwrap_or(0.0)
                .to_radians(),
        });
    }
    Ok(out)
}

/// The `[[bearings]]`: position and stiffness (none: rigid).
fn parse_bearings(
    ctx: &Source,
    bearings: &[Spanned<BearingIn>],
    len: f64,
) -> Result<Vec<Bearing>, ScenarioError> {
    let mut out = Vec::new();
    for (i, b) in bearings.iter().enumerate() {
        let k = format!("bearings[{i}]");
        let v = b.get_ref();
        out.push(Bearing {
            at: on_shaft(ctx, &v.at, format!("{k}.at"), len)?,
            stiffness: ctx.positive_opt(v.stiffness.as_ref(), &format!("{k}.stiffness"))?,
        });
    }
    Ok(out)
}

/// The `[response]` speeds: in rpm (→ rad/s) and as multiples of ω1, each list 1 …
/// [`MAX_SPEEDS`] long when given, at least one given.
fn response_speeds(ctx: &Source, r: &ResponseIn) -> Result<(Vec<f64>, Vec<f64>), ScenarioError> {
    let list = |l: &Option<Spanned<Vec<F>>>, key: &str| -> Result<Vec<f64>, ScenarioError> {
        let Some(l) = l else { return Ok(Vec::new()) };
        let v = l.get_ref();
        if v.is_empty() || v.len() > MAX_SPEEDS {
            return Err(ctx.at(l.span(), key, format!("needs 1..={MAX_SPEEDS} speeds")));
        }
        v.iter()
            .enumerate()
            .map(|(i, s)| ctx.positive(s, &format!("{key}[{i}]")))
            .collect()
    };
    let rpm = list(&r.speeds_rpm, "response.speeds_rpm")?;
    let ratios = list(&r.speed_ratios, "response.speed_ratios")?;
    if let Some(x) = ratios.iter().find(|x| **x > 1e3) {
        let l = r.speed_ratios.as_ref().map_or(0..0, |l| l.span());
        return Err(ctx.at(
            l,
            "response.speed_ratios",
            format!("{x} times the first critical speed: at most 1000"),
        ));
    }
    if rpm.is_empty() && ratios.is_empty() {
        return Err(ctx.section(
            "response",
            "give speeds_rpm, or speed_ratios (multiples of the first critical speed), or both",
        ));
    }
    Ok((rpm.iter().map(|n| n * PI / 30.0).collect(), ratios))
}

/// The `[modal_balancing]` section: planes, target mode, other modes kept, rigid-body
/// conditions, modal unbalance.
fn parse_balancing(
    ctx: &Source,
    b: &BalancingIn,
    modes: usize,
    len: f64,
) -> Result<Balancing, ScenarioError> {
    let planes = b
        .planes
        .get_ref()
        .iter()
        .enumerate()
        .map(|(i, p)| on_shaft(ctx, p, format!("modal_balancing.planes[{i}]"), len))
        .collect::<Result<Vec<_>, _>>()?;
    let mode = *b.mode.get_ref();
    let check_mode = |m: usize, span: std::ops::Range<usize>, key: &str| {
        if m == 0 || m > modes {
            Err(ctx.at(
                span,
                key,
                format!("mode {m} is not among the {modes} computed (analysis.modes)"),
            ))
        } else {
            Ok(m - 1)
        }
    };
    let target = check_mode(mode, b.mode.span(), "modal_balancing.mode")?;
    let mut others = Vec::new();
    if let Some(o) = &b.other_modes {
        for (i, m) in o.get_ref().iter().enumerate() {
            let k = format!("modal_balancing.other_modes[{i}]");
            let j = check_mode(*m.get_ref(), m.span(), &k)?;
            if j == target || others.contains(&j) {
                return Err(ctx.at(m.span(), k, "repeats a mode"));
            }
            others.push(j);
        }
    }
    let rigid = b.rigid_body.unwrap_or(true);
    let need = 1 + others.len() + if rigid { 2 } else { 0 };
    if planes.len() != need {
        return Err(ctx.at(
            b.planes.span(),
            "modal_balancing.planes",
            format!(
                "{} planes given, {need} needed (the mode, {} other modes{})",
                planes.len(),
                others.len(),
                if rigid { ", force and moment" } else { "" }
            ),
        ));
    }
    let au = b
        .modal_unbalance
        .as_ref()
        .map(|v| ctx.finite(v, "modal_balancing.modal_unbalance"))
        .transpose()?
        .unwrap_or(1.0);
    Ok((planes, target, others, rigid, au))
}

/// The shaft's material is refused when no segment is given by its diameter (the key
/// would not apply).
fn material_applies(ctx: &Source, shaft: &ShaftIn) -> Result<(), ScenarioError> {
    let segments = shaft.segments.get_ref();
    let by_diameter = segments.iter().any(|s| s.get_ref().diameter.is_some());
    for (key, v) in [
        ("shaft.youngs_modulus", &shaft.youngs_modulus),
        ("shaft.density", &shaft.density),
    ] {
        if let (Some(v), false) = (v, by_diameter) {
            return Err(ctx.at(
                v.span(),
                key,
                "applies to segments given by `diameter` only; every segment here gives `ei` \
                 and `mass_per_length`",
            ));
        }
    }
    Ok(())
}

/// Parses and validates `text` (the contents of `file`).
pub fn parse(file: &str, text: &str) -> Result<FlexibleRotorScenario, ScenarioError> {
    let ctx = Source::new(file, text);
    let f: File = ctx.parse()?;
    let e = f
        .shaft
        .youngs_modulus
        .as_ref()
        .map(|v| ctx.positive(v, "shaft.youngs_modulus"))
        .transpose()?;
    let rho = f
        .shaft
        .density
        .as_ref()
        .map(|v| ctx.positive(v, "shaft.density"))
        .transpose()?;
    if f.shaft.segments.get_ref().is_empty() {
        return Err(ctx.at(
            f.shaft.segments.span(),
            "shaft.segments",
            "needs at least one segment",
        ));
    }
    let segments = f
        .shaft
        .segments
        .get_ref()
        .iter()
        .enumerate()
        .map(|(i, s)| segment(&ctx, s, i, (e, rho)))
        .collect::<Result<Vec<_>, _>>()?;
    material_applies(&ctx, &f.shaft)?;
    let len: f64 = segments.iter().map(|s| s.length).sum();
    let discs = parse_discs(&ctx, &f.discs, len)?;
    let bearings = parse_bearings(&ctx, f.bearings.get_ref(), len)?;
    let rigid = bearings.iter().filter(|b| b.stiffness.is_none()).count();
    if bearings.len() < 2 && rigid < 2 {
        return Err(ctx.at(
            f.bearings.span(),
            "bearings",
            "needs at least two bearings (a shaft on fewer has rigid-body modes at speed 0)",
        ));
    }
    let an = f.analysis.as_ref();
    let modes = ctx.count(
        an.and_then(|a| a.modes.as_ref()),
        "analysis.modes",
        3,
        1..=MAX_MODES,
    )?;
    let elements = ctx.count(
        an.and_then(|a| a.elements.as_ref()),
        "analysis.elements",
        60,
        2..=MAX_ELEMENTS,
    )?;
    let max_speed = an
        .and_then(|a| a.max_speed_rpm.as_ref())
        .map(|v| ctx.positive(v, "analysis.max_speed_rpm"))
        .transpose()?
        .map(|n| n * PI / 30.0);
    let (speeds, ratios) = match &f.response {
        None => (Vec::new(), Vec::new()),
        Some(r) => response_speeds(&ctx, r)?,
    };
    let rotor = FlexibleRotor {
        segments,
        discs,
        bearings,
    };
    if fe_modes(&rotor, elements, 1).is_none() {
        return Err(ctx.section("shaft", "the rotor has no positive-definite mass matrix"));
    }
    let balancing = f
        .modal_balancing
        .as_ref()
        .map(|b| parse_balancing(&ctx, b, modes, len))
        .transpose()?;
    Ok(FlexibleRotorScenario {
        name: scenario_name(f.name.as_deref(), file),
        rotor,
        modes,
        elements,
        max_speed,
        speeds,
        ratios,
        balancing,
    })
}

/// The unbalance response at the scenario's speeds: one JSON row per speed (largest
/// deflection, at the discs, modal amplification; `critical` where the solve is singular),
/// a text line and the response plot.
fn unbalance_rows(
    sc: &FlexibleRotorScenario,
    speeds: &[f64],
    fe: &[RotorMode],
    text: &mut String,
    panels: &mut Vec<Panel>,
) -> Value {
    let mut rows = Vec::new();
    let mut peak = Vec::new();
    for &w in speeds {
        // At a mode's critical speed (to rounding) the amplification is unbounded: the
        // row says `critical`, as where the solve is singular, never a null amplification.
        let modal: Vec<f64> = fe.iter().map(|m| modal_amplification(m.omega, w)).collect();
        let at_mode = fe
            .iter()
            .zip(&modal)
            .position(|(m, a)| !a.is_finite() || (m.omega - w).abs() <= 1e-9 * m.omega);
        let response = unbalance_response(&sc.rotor, sc.elements, w)
            .filter(|(_, amp)| amp.iter().all(|a| a.is_finite()));
        let (Some((x, amp)), None) = (response, at_mode) else {
            let mut row = json!({ "speed_rpm": w * 30.0 / PI, "critical": true });
            if let Some(k) = at_mode {
                row["critical_mode"] = json!(k + 1);
            }
            rows.push(row);
            continue;
        };
        let at_discs: Vec<f64> = sc
            .rotor
            .discs
            .iter()
            .map(|d| {
                let k = x
                    .iter()
                    .enumerate()
                    .min_by(|a, b| (a.1 - d.at).abs().total_cmp(&(b.1 - d.at).abs()))
                    .map(|(i, _)| i)
                    .unwrap_or(0);
                amp[k]
            })
            .collect();
        let maxa = amp.iter().fold(0.0f64, |m, v| m.max(*v));
        peak.push((w * 30.0 / PI, maxa));
        rows.push(
            json!({ "speed_rpm": w * 30.0 / PI, "max_amplitude": maxa, "at_discs": at_discs,
                          "amplification": modal }),
        );
    }
    writeln!(
        text,
        "  unbalance response at {} speeds (largest deflection {:.4e} m)",
        speeds.len(),
        peak.iter().fold(0.0f64, |m, p| m.max(p.1))
    )
    .ok();
    panels.push(Panel {
        title: "unbalance response".into(),
        x_desc: "speed (rpm)".into(),
        y_desc: "largest deflection (m)".into(),
        log_y: true,
        series: vec![Series {
            label: "direct solve".into(),
            points: peak,
            color: PALETTE[0],
            dashed: false,
        }],
        ..Default::default()
    });
    json!(rows)
}

/// Computes the report of a parsed scenario.
pub fn report(
    ctx: &Source,
    sc: &FlexibleRotorScenario,
    out_dir: Option<&Path>,
) -> Result<Report, ScenarioError> {
    let fe = fe_modes(&sc.rotor, sc.elements, sc.modes)
        .ok_or_else(|| ctx.section("shaft", "the eigenproblem failed"))?;
    let top = fe.last().map_or(1.0, |m| m.omega) * 1.3;
    let tm = critical_speeds(&sc.rotor, top, 4000);
    let mut text = format!(
        "flexible rotor: {} ({} m, {} discs, {} bearings; {} finite elements)\n",
        sc.name,
        sc.rotor.length(),
        sc.rotor.discs.len(),
        sc.rotor.bearings.len(),
        fe[0].x.len() - 1
    );
    let mut modes = Vec::new();
    let mut shapes = Vec::new();
    for (i, m) in fe.iter().enumerate() {
        let t = tm.get(i).copied();
        writeln!(
            text,
            "  mode {}: {:.4} rad/s = {:.2} rpm (transfer matrix {})",
            i + 1,
            m.omega,
            m.omega * 30.0 / PI,
            t.map(|w| format!("{w:.4} rad/s"))
                .unwrap_or_else(|| "not found".into())
        )
        .ok();
        let every = (m.x.len() / 200).max(1);
        modes.push(json!({
            "omega": m.omega, "rpm": m.omega * 30.0 / PI, "transfer_matrix_omega": t,
            "modal_mass": m.modal_mass,
            "shape": { "x": m.x.iter().step_by(every).collect::<Vec<_>>(), "y": m.y.iter().step_by(every).collect::<Vec<_>>() },
        }));
        shapes.push(Series {
            label: format!("mode {} ({:.0} rpm)", i + 1, m.omega * 30.0 / PI),
            points: m.x.iter().copied().zip(m.y.iter().copied()).collect(),
            color: PALETTE[i % PALETTE.len()],
            dashed: false,
        });
    }
    let w1 = fe[0].omega;
    writeln!(
        text,
        "  rigid-rotor limit 0.8 ω1 = {:.4} rad/s ({:.1} rpm)",
        0.8 * w1,
        0.8 * w1 * 30.0 / PI
    )
    .ok();
    let mut j = json!({ "kind": NAME, "name": sc.name, "length": sc.rotor.length(), "elements": fe[0].x.len() - 1, "modes": modes, "rigid_limit": 0.8 * w1 });
    if let Some(ws) = sc.max_speed {
        let rigid = ws <= 0.8 * w1;
        writeln!(
            text,
            "  top speed {:.4} rad/s: {}",
            ws,
            if rigid {
                "rigid rotor"
            } else {
                "flexible rotor (above 0.8 ω1)"
            }
        )
        .ok();
        j["max_speed"] = json!(ws);
        j["rigid"] = json!(rigid);
    }
    let mut panels = vec![Panel {
        title: "mode shapes".into(),
        x_desc: "x (m)".into(),
        y_desc: "deflection (largest 1)".into(),
        series: shapes,
        ..Default::default()
    }];
    // Speeds given as multiples of ω1 follow those given in rpm.
    let speeds: Vec<f64> = (sc.speeds.iter().copied())
        .chain(
            sc.ratios
                .iter()
                .map(|r| r * fe.first().map_or(0.0, |m| m.omega)),
        )
        .collect();
    if !speeds.is_empty() {
        let mut rows = unbalance_rows(sc, &speeds, &fe, &mut text, &mut panels);
        if let (Some(m1), Some(list)) = (fe.first(), rows.as_array_mut()) {
            for (row, w) in list.iter_mut().zip(&speeds) {
                row["frequency_ratio"] = json!(w / m1.omega);
            }
        }
        j["response"] = rows;
    }
    if let Some((planes, target, others, rigid, au)) = &sc.balancing {
        let x = modal_balance(&fe, planes, *target, others, *rigid, *au).ok_or_else(|| ctx.section("modal_balancing", "the balancing equations are singular (a plane at a node of a mode, or two planes at one place)"))?;
        writeln!(
            text,
            "  modal balancing of mode {}: X = {:?} kg m",
            target + 1,
            x.iter().map(|v| format!("{v:.5}")).collect::<Vec<_>>()
        )
        .ok();
        j["modal_balancing"] = json!({ "mode": target + 1, "other_modes": others.iter().map(|o| o + 1).collect::<Vec<_>>(), "rigid_body": rigid, "planes": planes, "masses": x,
            "force_sum": x.iter().sum::<f64>(), "moment_sum": x.iter().zip(planes).map(|(a, b)| a * b).sum::<f64>() });
    }
    finish_with_plot(ctx, out_dir, (&sc.name, "rotor"), (&panels, 1), j, text)
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "flexible_rotor";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, opts| run(path, text, opts.out_dir.as_deref()),
};
