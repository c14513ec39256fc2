//! `kind = "flywheel"` scenarios (format in `docs/flywheel.md`): flywheel sizing from a
//! turning-moment diagram over one period (with the time-domain check, another shaft and
//! the rim), a work stroke against a speed-dependent motor, and an overload's
//! deceleration limit ([`crate::machines::flywheel::design`]).

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::plots::panels::{Panel, Series, PALETTE};
use crate::io::report::Report;
use crate::machines::flywheel::design::{self as fd, Torque};
use crate::machines::flywheel::machine_motion::Characteristic;
use crate::scenarios::kit::{finish_with_plot, scenario_name};
use crate::scenarios::source::Source;
use serde::Deserialize;
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;
use toml::Spanned;

type F = Spanned<f64>;
/// A `[[angle_deg, value], ...]` table with its span.
type Table = Spanned<Vec<[F; 2]>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    cycle: Option<CycleIn>,
    stroke: Option<StrokeIn>,
    overload: Option<OverloadIn>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CycleIn {
    period_deg: Option<F>,
    drive: Option<F>,
    drive_deg: Option<Spanned<Vec<[F; 2]>>>,
    load: Option<F>,
    load_deg: Option<Spanned<Vec<[F; 2]>>>,
    speed: Option<F>,
    speed_rpm: Option<F>,
    speed_fluctuation: Option<F>,
    speed_band: Option<Spanned<[F; 2]>>,
    machine_inertia: Option<F>,
    points: Option<Spanned<usize>>,
    transfer_speed: Option<F>,
    rim_diameter: Option<F>,
    density: Option<F>,
    time_check_periods: Option<Spanned<usize>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StrokeIn {
    drive: Spanned<Vec<F>>,
    load: F,
    angle_deg: Option<F>,
    duration: Option<F>,
    speed_band: Spanned<[F; 2]>,
    machine_inertia: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OverloadIn {
    drive: F,
    load: F,
    max_deceleration: F,
    machine_inertia: Option<F>,
}

/// A parsed cycle section.
#[derive(Clone, Debug)]
struct Cycle {
    period: f64,
    drive: Torque,
    load: Torque,
    omega: f64,
    delta: f64,
    machine: f64,
    points: usize,
    transfer: Option<f64>,
    rim: Option<(f64, f64)>,
    periods: usize,
}

/// A parsed and validated flywheel scenario.
#[derive(Clone, Debug)]
pub struct FlywheelDesignScenario {
    /// Its name.
    pub name: String,
    cycle: Option<Cycle>,
    stroke: Option<(Characteristic, f64, fd::StrokeSpan, [f64; 2], f64)>,
    overload: Option<(f64, f64, f64, f64)>,
}

/// Most integration points of a cycle.
pub const MAX_POINTS: usize = 1_000_000;
/// Most periods of a time check.
pub const MAX_PERIODS: usize = 1000;

/// Runs a flywheel scenario; plots go to `out_dir` when given.
pub fn run(path: &Path, text: &str, out_dir: Option<&Path>) -> Result<Report, ScenarioError> {
    crate::scenarios::kit::parse_and_report(path, text, out_dir, parse, report)
}

fn table(
    ctx: &Source,
    t: &Spanned<Vec<[F; 2]>>,
    key: &str,
    period: f64,
) -> Result<Torque, ScenarioError> {
    let rows = t.get_ref();
    if rows.is_empty() {
        return Err(ctx.at(t.span(), key, "needs at least one [angle_deg, torque] row"));
    }
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let k = format!("{key}[{i}]");
        let (a, m) = (ctx.finite(&r[0], &k)?.to_radians(), ctx.finite(&r[1], &k)?);
        if a < -1e-12 || a > period + 1e-12 {
            return Err(ctx.at(
                r[0].span(),
                k,
                format!(
                    "angle {} deg lies outside the period [0, {}]",
                    a.to_degrees(),
                    period.to_degrees()
                ),
            ));
        }
        if out.last().is_some_and(|p| a < p.0) {
            return Err(ctx.at(r[0].span(), k, "angles must not decrease"));
        }
        out.push((a.clamp(0.0, period), m));
    }
    Ok(Torque::Table(out))
}

fn torque(
    ctx: &Source,
    c: (Option<&F>, Option<&Table>),
    name: &str,
    period: f64,
) -> Result<Option<Torque>, ScenarioError> {
    match c {
        (Some(v), None) => Ok(Some(Torque::Constant(
            ctx.finite(v, &format!("cycle.{name}"))?,
        ))),
        (None, Some(t)) => Ok(Some(table(ctx, t, &format!("cycle.{name}_deg"), period)?)),
        (Some(v), Some(_)) => Err(ctx.at(
            v.span(),
            format!("cycle.{name}"),
            format!("give either `{name}` or `{name}_deg`, not both"),
        )),
        (None, None) => Ok(None),
    }
}

fn parse_cycle(ctx: &Source, c: &CycleIn) -> Result<Cycle, ScenarioError> {
    let period = match &c.period_deg {
        Some(p) => ctx.positive(p, "cycle.period_deg")?.to_radians(),
        None => 2.0 * PI,
    };
    let drive = torque(
        ctx,
        (c.drive.as_ref(), c.drive_deg.as_ref()),
        "drive",
        period,
    )?
    .ok_or_else(|| ctx.section("cycle", "missing: `drive` (N m) or `drive_deg` (a table)"))?;
    let load = torque(ctx, (c.load.as_ref(), c.load_deg.as_ref()), "load", period)?;
    if load.is_none() && matches!(drive, Torque::Constant(_)) {
        return Err(ctx.section(
            "cycle",
            "a constant drive without a load has no fluctuation: give `load` or `load_deg`",
        ));
    }
    let (omega, delta) = cycle_speed(ctx, c)?;
    let machine = ctx.non_negative_or(c.machine_inertia.as_ref(), "cycle.machine_inertia", 0.0)?;
    let points = ctx.count(c.points.as_ref(), "cycle.points", 3600, 1..=MAX_POINTS)?;
    let periods = ctx.count(
        c.time_check_periods.as_ref(),
        "cycle.time_check_periods",
        3,
        1..=MAX_PERIODS,
    )?;
    let transfer = ctx.positive_opt(c.transfer_speed.as_ref(), "cycle.transfer_speed")?;
    if let (Some(d), None) = (&c.density, &c.rim_diameter) {
        return Err(ctx.at(
            d.span(),
            "cycle.density",
            "applies to the rim only: give `rim_diameter` with it",
        ));
    }
    let rho = ctx
        .positive_opt(c.density.as_ref(), "cycle.density")?
        .unwrap_or(7850.0);
    let rim = ctx
        .positive_opt(c.rim_diameter.as_ref(), "cycle.rim_diameter")?
        .map(|d| (d, rho));
    Ok(Cycle {
        period,
        drive,
        load: load.unwrap_or(Torque::Constant(f64::NAN)),
        omega,
        delta,
        machine,
        points,
        transfer,
        rim,
        periods,
    })
}

/// The cycle's mean speed and fluctuation: `speed` (or `speed_rpm`) with
/// `speed_fluctuation`, or a `speed_band`.
fn cycle_speed(ctx: &Source, c: &CycleIn) -> Result<(f64, f64), ScenarioError> {
    let omega = match (&c.speed, &c.speed_rpm, &c.speed_band) {
        (Some(w), None, _) => Some(ctx.positive(w, "cycle.speed")?),
        (None, Some(n), _) => Some(ctx.positive(n, "cycle.speed_rpm")? * PI / 30.0),
        (Some(_), Some(n), _) => {
            return Err(ctx.at(
                n.span(),
                "cycle.speed_rpm",
                "give either `speed` or `speed_rpm`, not both",
            ))
        }
        (None, None, _) => None,
    };
    match (omega, &c.speed_fluctuation, &c.speed_band) {
        (Some(w), Some(d), None) => Ok((w, ctx.between(d, "cycle.speed_fluctuation", 0.0, 2.0)?)),
        (None, None, Some(b)) => {
            let lo = ctx.positive(&b.get_ref()[0], "cycle.speed_band[0]")?;
            let hi = ctx.positive(&b.get_ref()[1], "cycle.speed_band[1]")?;
            if hi <= lo {
                return Err(ctx.at(
                    b.span(),
                    "cycle.speed_band",
                    "needs [lowest, highest] speed with lowest < highest",
                ));
            }
            Ok(((lo + hi) / 2.0, 2.0 * (hi - lo) / (hi + lo)))
        }
        (_, _, Some(b)) => Err(ctx.at(
            b.span(),
            "cycle.speed_band",
            "give either `speed_band` or a speed with `speed_fluctuation`, not both",
        )),
        _ => Err(ctx.section(
            "cycle",
            "missing: `speed` (or `speed_rpm`) with `speed_fluctuation`, or `speed_band`",
        )),
    }
}

/// Parses and validates `text` (the contents of `file`).
pub fn parse(file: &str, text: &str) -> Result<FlywheelDesignScenario, ScenarioError> {
    let ctx = Source::new(file, text);
    let f: File = ctx.parse()?;
    ctx.any_section(
        &[f.cycle.is_some(), f.stroke.is_some(), f.overload.is_some()],
        "nothing to size: add [cycle], [stroke] or [overload]",
    )?;
    let cycle = f
        .cycle
        .as_ref()
        .map(|c| steady_cycle(&ctx, parse_cycle(&ctx, c)?))
        .transpose()?;
    let stroke = f
        .stroke
        .as_ref()
        .map(|s| parse_stroke(&ctx, s))
        .transpose()?;
    let overload = f
        .overload
        .as_ref()
        .map(|o| parse_overload(&ctx, o))
        .transpose()?;
    Ok(FlywheelDesignScenario {
        name: scenario_name(f.name.as_deref(), file),
        cycle,
        stroke,
        overload,
    })
}

/// A cycle with its load set (none given: the constant that does the drive's work) and
/// checked for a steady state (zero net work over a period).
fn steady_cycle(ctx: &Source, mut c: Cycle) -> Result<Cycle, ScenarioError> {
    if matches!(c.load, Torque::Constant(x) if x.is_nan()) {
        let s = fd::size_cycle(
            &c.drive,
            &Torque::Constant(0.0),
            c.period,
            c.points,
            (c.omega, c.delta),
            0.0,
        );
        c.load = Torque::Constant(s.mean_drive);
    }
    let s = fd::size_cycle(
        &c.drive,
        &c.load,
        c.period,
        c.points,
        (c.omega, c.delta),
        c.machine,
    );
    let scale = s
        .energy_fluctuation
        .max(s.mean_drive.abs() * c.period)
        .max(1e-300);
    if s.cycle_work.abs() > 1e-6 * scale {
        return Err(ctx.section("cycle", format!(
            "the net work over a period is {:.6e} J, not zero: no steady state (leave out the load to use the drive's mean)",
            s.cycle_work
        )));
    }
    Ok(c)
}

/// The `[stroke]` section: drive characteristic, load, angle, speed band, machine inertia.
#[allow(clippy::type_complexity)]
fn parse_stroke(
    ctx: &Source,
    s: &StrokeIn,
) -> Result<(Characteristic, f64, fd::StrokeSpan, [f64; 2], f64), ScenarioError> {
    let coeffs = ctx.finite_list(&s.drive, "stroke.drive")?;
    if coeffs.is_empty() {
        return Err(ctx.at(
            s.drive.span(),
            "stroke.drive",
            "needs the coefficients of M_d(ω) = Σ c_k ω^k",
        ));
    }
    let load = ctx.finite(&s.load, "stroke.load")?;
    let span = match (&s.angle_deg, &s.duration) {
        (Some(a), None) => fd::StrokeSpan::Angle(ctx.positive(a, "stroke.angle_deg")?.to_radians()),
        (None, Some(t)) => fd::StrokeSpan::Duration(ctx.positive(t, "stroke.duration")?),
        (Some(_), Some(t)) => {
            return Err(ctx.at(
                t.span(),
                "stroke.duration",
                "give either `angle_deg` or `duration` (s), not both",
            ))
        }
        (None, None) => {
            return Err(ctx.section(
                "stroke",
                "missing: `angle_deg` (the stroke's angle) or `duration` (s)",
            ))
        }
    };
    let b = s.speed_band.get_ref();
    let band = [
        ctx.positive(&b[0], "stroke.speed_band[0]")?,
        ctx.positive(&b[1], "stroke.speed_band[1]")?,
    ];
    if band[0] >= band[1] {
        return Err(ctx.at(
            s.speed_band.span(),
            "stroke.speed_band",
            "needs [lowest, highest] speed with lowest < highest",
        ));
    }
    let machine = s
        .machine_inertia
        .as_ref()
        .map(|v| ctx.non_negative(v, "stroke.machine_inertia"))
        .transpose()?
        .unwrap_or(0.0);
    let drive = Characteristic(coeffs);
    if fd::size_stroke(&drive, load, span, band, machine).is_none() {
        return Err(ctx.at(
            s.speed_band.span(),
            "stroke.speed_band",
            "the motor torque equals the load inside the band: the speed cannot cross it",
        ));
    }
    Ok((drive, load, span, band, machine))
}

/// The `[overload]` section: drive, load, largest deceleration, machine inertia.
fn parse_overload(ctx: &Source, o: &OverloadIn) -> Result<(f64, f64, f64, f64), ScenarioError> {
    Ok((
        ctx.finite(&o.drive, "overload.drive")?,
        ctx.finite(&o.load, "overload.load")?,
        ctx.positive(&o.max_deceleration, "overload.max_deceleration")?,
        o.machine_inertia
            .as_ref()
            .map(|v| ctx.non_negative(v, "overload.machine_inertia"))
            .transpose()?
            .unwrap_or(0.0),
    ))
}

fn cycle_json(c: &Cycle, text: &mut String, panels: &mut Vec<Panel>) -> Value {
    let s = fd::size_cycle(
        &c.drive,
        &c.load,
        c.period,
        c.points,
        (c.omega, c.delta),
        c.machine,
    );
    let e_min = s.energy.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let w0 = (s.speed_band[0].powi(2) - 2.0 * e_min / s.required_inertia).sqrt();
    let tc = fd::time_check(
        &c.drive,
        &c.load,
        c.period,
        s.required_inertia,
        w0,
        (c.periods, 2000),
    );
    writeln!(
        text,
        "cycle: period {:.1}°, mean speed {:.4} rad/s, δ = {:.5}, band [{:.4}, {:.4}] rad/s",
        s.period_deg, s.mean_speed, s.speed_fluctuation, s.speed_band[0], s.speed_band[1]
    )
    .ok();
    writeln!(
        text,
        "  mean drive {:.4} N m, mean load {:.4} N m; ΔE = {:.4} J (max at {:.2}°, min at {:.2}°)",
        s.mean_drive, s.mean_load, s.energy_fluctuation, s.max_energy_at_deg, s.min_energy_at_deg
    )
    .ok();
    writeln!(
        text,
        "  required J = {:.5} kg m², machine {:.5}, flywheel {:.5} kg m² (GD² = {:.3} N m²)",
        s.required_inertia, s.machine_inertia, s.flywheel_inertia, s.gd2
    )
    .ok();
    writeln!(
        text,
        "  time check (RK4, {} periods): band [{:.4}, {:.4}] rad/s, δ = {:.5}",
        tc.periods, tc.speed_band[0], tc.speed_band[1], tc.speed_fluctuation
    )
    .ok();
    let mut v = serde_json::to_value(&s).unwrap_or(Value::Null);
    v["time_check"] = serde_json::to_value(&tc).unwrap_or(Value::Null);
    v["transferred"] = match c.transfer {
        Some(w2) => {
            let j2 = fd::transfer_inertia(s.flywheel_inertia, c.omega, w2);
            writeln!(
                text,
                "  on a shaft at {w2:.4} rad/s: flywheel {j2:.6} kg m²"
            )
            .ok();
            json!({ "speed": w2, "inertia": j2 })
        }
        None => Value::Null,
    };
    v["rim"] = match c.rim {
        Some((d, rho)) => {
            let r = fd::rim(s.flywheel_inertia, d, rho, s.speed_band[1]);
            writeln!(
                text,
                "  rim D = {d} m: mass {:.3} kg, rim speed {:.3} m/s, hoop stress {:.4e} Pa",
                r.mass, r.rim_speed, r.hoop_stress
            )
            .ok();
            json!({ "diameter": r.diameter, "density": rho, "mass": r.mass, "rim_speed": r.rim_speed, "hoop_stress": r.hoop_stress })
        }
        None => Value::Null,
    };
    cycle_panels(c, &s, &tc, panels);
    v
}

/// The cycle's plots: turning-moment diagram, energy over the period, time check.
fn cycle_panels(c: &Cycle, s: &fd::CycleSizing, tc: &fd::TimeCheck, panels: &mut Vec<Panel>) {
    let every = (s.energy.len() / 300).max(1);
    let thin: Vec<(f64, f64)> = s
        .energy
        .iter()
        .step_by(every)
        .chain(s.energy.last())
        .copied()
        .collect();
    let curve = |t: &Torque| -> Vec<(f64, f64)> {
        thin.iter()
            .map(|(deg, _)| (*deg, t.eval(deg.to_radians(), c.period)))
            .collect()
    };
    panels.push(Panel {
        title: "turning-moment diagram".into(),
        x_desc: "angle (deg)".into(),
        y_desc: "torque (N m)".into(),
        series: vec![
            Series {
                label: "drive".into(),
                points: curve(&c.drive),
                color: PALETTE[0],
                dashed: false,
            },
            Series {
                label: "load".into(),
                points: curve(&c.load),
                color: PALETTE[1],
                dashed: false,
            },
        ],
        ..Default::default()
    });
    panels.push(Panel {
        title: "energy over the period".into(),
        x_desc: "angle (deg)".into(),
        y_desc: "E (J)".into(),
        series: vec![Series {
            label: "∫(M_d − M_c) dφ".into(),
            points: thin.clone(),
            color: PALETTE[2],
            dashed: false,
        }],
        ..Default::default()
    });
    panels.push(Panel {
        title: "time check".into(),
        x_desc: "t (s)".into(),
        y_desc: "ω (rad/s)".into(),
        series: vec![Series {
            label: "RK4".into(),
            points: tc
                .history
                .iter()
                .step_by((tc.history.len() / 600).max(1))
                .copied()
                .collect(),
            color: PALETTE[3],
            dashed: false,
        }],
        ..Default::default()
    });
}

/// Computes the report of a parsed scenario.
pub fn report(
    ctx: &Source,
    sc: &FlywheelDesignScenario,
    out_dir: Option<&Path>,
) -> Result<Report, ScenarioError> {
    let mut text = format!("flywheel: {}\n", sc.name);
    let mut j = json!({ "kind": NAME, "name": sc.name });
    let mut panels = Vec::new();
    if let Some(c) = &sc.cycle {
        j["cycle"] = cycle_json(c, &mut text, &mut panels);
    }
    if let Some((drive, load, span, band, machine)) = &sc.stroke {
        let s = fd::size_stroke(drive, *load, *span, *band, *machine).ok_or_else(|| {
            ctx.section("stroke", "the motor torque equals the load inside the band")
        })?;
        let (length, integrand) = match span {
            fd::StrokeSpan::Angle(a) => (format!("{:.2}°", a.to_degrees()), "ω dω"),
            fd::StrokeSpan::Duration(t) => (format!("{t} s"), "dω"),
        };
        writeln!(text, "stroke: {length} against {load} N m, speed {:.4} → {:.4} rad/s: ∫{integrand}/(M_d − M_c) = {:.6}{}", band[1], band[0], s.integral, s.integral_closed_form.map(|c| format!(" (closed form {c:.6})")).unwrap_or_default()).ok();
        writeln!(text, "  required J = {:.5} kg m², flywheel {:.5} kg m²; time check: speed after the stroke {:.4} rad/s in {:.4} s over {:.2}°", s.required_inertia, s.flywheel_inertia, s.time_check_speed, s.time_check_duration, s.time_check_angle.to_degrees()).ok();
        let mut v = serde_json::to_value(&s).unwrap_or(Value::Null);
        v["angle_deg"] = json!(s.time_check_angle.to_degrees());
        v["given"] = json!(match span {
            fd::StrokeSpan::Angle(_) => "angle",
            fd::StrokeSpan::Duration(_) => "duration",
        });
        v["speed_band"] = json!(band);
        v["machine_inertia"] = json!(machine);
        j["stroke"] = v;
    }
    if let Some((d, l, eps, machine)) = sc.overload {
        let (jt, jf) = fd::overload_inertia(d, l, eps, machine);
        writeln!(text, "overload: |M_d − M_c| = {:.4} N m, ε ≤ {eps} rad/s²: J ≥ {jt:.5} kg m², flywheel {jf:.5} kg m²", (d - l).abs()).ok();
        j["overload"] = json!({ "required_inertia": jt, "machine_inertia": machine, "flywheel_inertia": jf, "gd2": 4.0 * fd::G * jf });
    }
    finish_with_plot(ctx, out_dir, (&sc.name, NAME), (&panels, 1), j, text)
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "flywheel";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, opts| run(path, text, opts.out_dir.as_deref()),
};
