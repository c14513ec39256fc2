//! `kind = "torsional"` scenarios: a torsional chain with optional engine excitation,
//! speed sweep, time-domain check and damping identification (format in
//! `docs/drivetrain.md`). The run reports the undamped modes (checked by Holzer and by
//! the LR iteration), the damped modes, the forced response per order over the speed
//! range, the critical-speed table, the time-domain check and the identification.
//!
//! Every error names the file, the line and the key (`chain.inertia[3]`, `engine.cylinders[0]`,
//! `identification.measurements[2].between`): values are read with their spans.

pub use crate::scenarios::torsional::torsional_report::report;

mod torsional_report;
mod torsional_scenario;

use torsional_scenario::Identification;
pub use torsional_scenario::TorsionalScenario;

use crate::core::diag::{line_at, LocatedError as ScenarioError};
use crate::io::report::Report;
use crate::machines::vibration::torsional::forced::Excitation;
use crate::machines::vibration::torsional::identify::{DampingParameter, Measurement};
use crate::machines::vibration::torsional::modes::undamped_modes;
use crate::machines::vibration::torsional::torsional_chain::{ChainError, TorsionalChain};
use crate::scenarios::source::Source;
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

type SVec<T> = Spanned<Vec<Spanned<T>>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioFile {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    chain: ChainSection,
    engine: Option<Spanned<EngineSection>>,
    excitation: Option<Spanned<ExcitationSection>>,
    sweep: Option<Spanned<SweepSection>>,
    time_check: Option<Spanned<TimeCheckSection>>,
    identification: Option<Spanned<IdentSection>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ChainSection {
    names: SVec<String>,
    inertia: SVec<f64>,
    stiffness: SVec<f64>,
    absolute_damping: Option<SVec<f64>>,
    relative_damping: Option<SVec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EngineSection {
    cylinders: SVec<String>,
    firing_angles_deg: SVec<f64>,
    rated_speed_rpm: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExcitationSection {
    orders: SVec<f64>,
    amplitude: SVec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepSection {
    speed_range_rpm: Spanned<[f64; 2]>,
    points: Spanned<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TimeCheckSection {
    order: Spanned<f64>,
    speed_rpm: Spanned<f64>,
    periods: Spanned<usize>,
    steps_per_period: Spanned<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IdentSection {
    parameters: Vec<Spanned<ParamSection>>,
    measurements: Vec<Spanned<MeasSection>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamSection {
    name: String,
    #[serde(default)]
    absolute: Vec<Spanned<String>>,
    #[serde(default)]
    relative: Vec<Spanned<[String; 2]>>,
    initial: Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeasSection {
    order: Spanned<f64>,
    speed_rpm: Spanned<f64>,
    between: Spanned<[String; 2]>,
    torque: Spanned<f64>,
}

fn vals<T: Clone>(v: &SVec<T>) -> Vec<T> {
    v.get_ref().iter().map(|s| s.get_ref().clone()).collect()
}

fn finite(x: f64) -> bool {
    x.is_finite()
}

/// Most disks a chain may have: the damped-mode and LR analyses take time growing as
/// `n⁴` (about 2 s at 200 disks, a minute at 500).
pub const MAX_DISKS: usize = 200;

/// Bound on a sweep's `points × orders × (2 n)³` (each point and order solves a dense
/// `2n × 2n` system): about a minute of work.
pub const MAX_SWEEP_WORK: f64 = 1e11;

/// Most RK4 steps of a time check (`periods × steps_per_period`), as for machine motion.
pub const MAX_TIME_STEPS: f64 = 1e7;

/// Runs a torsional-chain scenario: [`parse`], then [`report`].
pub fn run(path: &Path, text: &str) -> Result<Report, ScenarioError> {
    report(&parse(&path.display().to_string(), text)?, NAME)
}

/// The `[chain]` table: names, inertias, stiffnesses and dampers, validated, at most
/// [`MAX_DISKS`] disks.
fn parse_chain(ctx: &Source, ch: &ChainSection) -> Result<TorsionalChain, ScenarioError> {
    let n = ch.inertia.get_ref().len();
    let zeros_or = |v: &Option<SVec<f64>>, len: usize| v.as_ref().map_or(vec![0.0; len], vals);
    let chain = TorsionalChain {
        names: vals(&ch.names),
        inertia: vals(&ch.inertia),
        stiffness: vals(&ch.stiffness),
        absolute_damping: zeros_or(&ch.absolute_damping, n),
        relative_damping: zeros_or(&ch.relative_damping, n.saturating_sub(1)),
    };
    chain.validate().map_err(|e| {
        let arr: Option<&SVec<f64>> = match e.field.as_str() {
            "inertia" => Some(&ch.inertia),
            "stiffness" => Some(&ch.stiffness),
            "absolute_damping" => ch.absolute_damping.as_ref(),
            "relative_damping" => ch.relative_damping.as_ref(),
            _ => None,
        };
        let span = match (arr, e.index) {
            (Some(a), Some(i)) => a.get_ref()[i].span(),
            (Some(a), None) => a.span(),
            (None, Some(i)) if e.field == "names" => ch.names.get_ref()[i].span(),
            _ => ch.names.span(),
        };
        let key = match e.index {
            Some(i) => format!("chain.{}[{i}]", e.field),
            None => format!("chain.{}", e.field),
        };
        ctx.at(span, key, e.message)
    })?;
    if n > MAX_DISKS {
        return Err(ctx.at(
            ch.inertia.span(),
            "chain.inertia",
            format!(
                "{n} disks: at most {MAX_DISKS} (the mode analyses take time growing as the fourth power of the number of disks)"
            ),
        ));
    }
    Ok(chain)
}

/// The index of the disk called `name`.
fn disk(
    ctx: &Source,
    chain: &TorsionalChain,
    name: &Spanned<String>,
    key: String,
) -> Result<usize, ScenarioError> {
    chain
        .names
        .iter()
        .position(|x| x == name.get_ref())
        .ok_or_else(|| {
            ctx.at(
                name.span(),
                key,
                format!("'{}' is not a disk of the chain", name.get_ref()),
            )
        })
}

/// The index of the shaft between two adjacent disks.
fn shaft(
    ctx: &Source,
    chain: &TorsionalChain,
    pair: &Spanned<[String; 2]>,
    key: String,
) -> Result<usize, ScenarioError> {
    let [a, b] = pair.get_ref();
    let ia = chain.names.iter().position(|x| x == a);
    let ib = chain.names.iter().position(|x| x == b);
    match (ia, ib) {
        (Some(i), Some(j)) if j == i + 1 => Ok(i),
        (Some(i), Some(j)) if i == j + 1 => Ok(j),
        _ => Err(ctx.at(
            pair.span(),
            key,
            format!("'{a}' and '{b}' are not adjacent disks of the chain (no shaft between them)"),
        )),
    }
}

/// The `[engine]` table: rated speed, the cylinders' disks and their firing angles.
#[allow(clippy::type_complexity)]
fn parse_engine(
    ctx: &Source,
    chain: &TorsionalChain,
    e: &EngineSection,
) -> Result<(Option<f64>, Vec<usize>, Vec<f64>), ScenarioError> {
    let mut rated = None;
    let mut cylinders = Vec::new();
    for (i, c) in e.cylinders.get_ref().iter().enumerate() {
        cylinders.push(disk(ctx, chain, c, format!("engine.cylinders[{i}]"))?);
    }
    let angles = vals(&e.firing_angles_deg);
    if angles.len() != cylinders.len() {
        return Err(ctx.at(
            e.firing_angles_deg.span(),
            "engine.firing_angles_deg",
            format!(
                "{} firing angles for {} cylinders",
                angles.len(),
                cylinders.len()
            ),
        ));
    }
    if let Some((i, s)) = e
        .firing_angles_deg
        .get_ref()
        .iter()
        .enumerate()
        .find(|(_, s)| !finite(*s.get_ref()))
    {
        return Err(ctx.at(
            s.span(),
            format!("engine.firing_angles_deg[{i}]"),
            "not a finite number",
        ));
    }
    if let Some(r) = &e.rated_speed_rpm {
        if !(r.get_ref().is_finite() && *r.get_ref() > 0.0) {
            return Err(ctx.at(
                r.span(),
                "engine.rated_speed_rpm",
                "must be a positive speed",
            ));
        }
        rated = Some(*r.get_ref());
    }
    Ok((rated, cylinders, angles))
}

/// The `[excitation]` table: the orders and amplitudes of the engine's harmonics.
fn parse_excitation(
    ctx: &Source,
    xs: &ExcitationSection,
    (cylinders, angles): (&[usize], &[f64]),
    n: usize,
) -> Result<Excitation, ScenarioError> {
    let exc = Excitation {
        cylinders: cylinders.to_vec(),
        firing_angles_deg: angles.to_vec(),
        orders: vals(&xs.orders),
        amplitudes: vals(&xs.amplitude),
    };
    exc.validate(n).map_err(|e: ChainError| {
        let (arr, field) = match e.field.as_str() {
            "orders" => (&xs.orders, "orders"),
            _ => (&xs.amplitude, "amplitude"),
        };
        match e.index {
            Some(i) => ctx.at(
                arr.get_ref()[i].span(),
                format!("excitation.{field}[{i}]"),
                e.message,
            ),
            None => ctx.at(arr.span(), format!("excitation.{field}"), e.message),
        }
    })?;
    Ok(exc)
}

/// The `[sweep]` speeds (rpm), evenly spaced over the range; the work is bounded.
fn sweep_speeds(
    ctx: &Source,
    sw: &SweepSection,
    exc: Option<&Excitation>,
    n: usize,
) -> Result<Vec<f64>, ScenarioError> {
    if exc.is_none() {
        return Err(ctx.section("sweep", "a sweep needs an [excitation] table"));
    }
    let [lo, hi] = *sw.speed_range_rpm.get_ref();
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > lo) {
        return Err(ctx.at(
            sw.speed_range_rpm.span(),
            "sweep.speed_range_rpm",
            format!("expected [low, high] with 0 < low < high, got [{lo}, {hi}]"),
        ));
    }
    let p = *sw.points.get_ref();
    if !(2..=100_000).contains(&p) {
        return Err(ctx.at(
            sw.points.span(),
            "sweep.points",
            format!("expected 2 … 100000 points, got {p}"),
        ));
    }
    // Each point and order solves a dense 2n × 2n system.
    let orders = exc.map_or(0, |e| e.orders.len());
    let work = p as f64 * orders as f64 * (2.0 * n as f64).powi(3);
    if work > MAX_SWEEP_WORK {
        return Err(ctx.at(
            sw.points.span(),
            "sweep.points",
            format!(
                "{p} points × {orders} orders on {n} disks is too much work (points × orders × (2 × disks)³ = {work:.1e}, at most {MAX_SWEEP_WORK:.0e}): use fewer points or orders"
            ),
        ));
    }
    Ok((0..p)
        .map(|i| lo + (hi - lo) * i as f64 / (p - 1) as f64)
        .collect())
}

/// The `[time_check]` settings: the order (as its index), speed, periods and steps per
/// period, the step short enough for RK4 on the highest mode.
fn parse_time_check(
    ctx: &Source,
    tc: &TimeCheckSection,
    exc: Option<&Excitation>,
    chain: &TorsionalChain,
) -> Result<(usize, f64, usize, usize), ScenarioError> {
    let Some(ex) = exc else {
        return Err(ctx.section("time_check", "a time check needs an [excitation] table"));
    };
    let order = *tc.order.get_ref();
    let Some(oi) = ex.orders.iter().position(|&o| o == order) else {
        return Err(ctx.at(
            tc.order.span(),
            "time_check.order",
            format!("order {order} is not in excitation.orders"),
        ));
    };
    let sp = *tc.speed_rpm.get_ref();
    if !(sp.is_finite() && sp > 0.0) {
        return Err(ctx.at(
            tc.speed_rpm.span(),
            "time_check.speed_rpm",
            "must be a positive speed",
        ));
    }
    let periods = *tc.periods.get_ref();
    if !(2..=1_000_000).contains(&periods) {
        return Err(ctx.at(
            tc.periods.span(),
            "time_check.periods",
            "expected 2 … 1000000",
        ));
    }
    let spp = *tc.steps_per_period.get_ref();
    if !(8..=1_000_000).contains(&spp) {
        return Err(ctx.at(
            tc.steps_per_period.span(),
            "time_check.steps_per_period",
            "expected 8 … 1000000",
        ));
    }
    if periods as f64 * spp as f64 > MAX_TIME_STEPS {
        return Err(ctx.at(
            tc.periods.span(),
            "time_check.periods",
            format!(
                "{periods} periods × {spp} steps per period: at most {MAX_TIME_STEPS:.0e} RK4 steps in all"
            ),
        ));
    }
    // RK4 is stable for |λ h| ≲ 2.8; refuse steps that would blow up.
    let top = undamped_modes(chain).last().map_or(0.0, |m| m.omega);
    let h = 60.0 / (order * sp) / spp as f64;
    if top * h > 2.5 {
        return Err(ctx.at(
            tc.steps_per_period.span(),
            "time_check.steps_per_period",
            format!(
                "step {h:.3e} s is too long for the highest mode ({:.1} rad/s): RK4 needs ω h < 2.8; use at least {} steps per period",
                top,
                (top * 60.0 / (order * sp) / 2.5).ceil() as usize
            ),
        ));
    }
    Ok((oi, sp, periods, spp))
}

/// The dampers to fit: the chain without them, each parameter's dampers, the initial
/// values.
#[allow(clippy::type_complexity)]
fn damping_parameters(
    ctx: &Source,
    chain: &TorsionalChain,
    id: &IdentSection,
) -> Result<(TorsionalChain, Vec<DampingParameter>, Vec<f64>), ScenarioError> {
    let mut base = chain.clone();
    let mut params = Vec::new();
    let mut initial = Vec::new();
    for (pi, p) in id.parameters.iter().enumerate() {
        let ps = p.get_ref();
        let mut dp = DampingParameter {
            name: ps.name.clone(),
            absolute: Vec::new(),
            relative: Vec::new(),
        };
        for (i, d) in ps.absolute.iter().enumerate() {
            let k = disk(
                ctx,
                chain,
                d,
                format!("identification.parameters[{pi}].absolute[{i}]"),
            )?;
            base.absolute_damping[k] = 0.0;
            dp.absolute.push((k, 1.0));
        }
        for (i, s) in ps.relative.iter().enumerate() {
            let k = shaft(
                ctx,
                chain,
                s,
                format!("identification.parameters[{pi}].relative[{i}]"),
            )?;
            base.relative_damping[k] = 0.0;
            dp.relative.push((k, 1.0));
        }
        if dp.absolute.is_empty() && dp.relative.is_empty() {
            return Err(ctx.at(
                p.span(),
                format!("identification.parameters[{pi}]"),
                "names no damper (give `absolute` disks or `relative` disk pairs)",
            ));
        }
        let init = *ps.initial.get_ref();
        if !(init.is_finite() && init > 0.0) {
            return Err(ctx.at(
                ps.initial.span(),
                format!("identification.parameters[{pi}].initial"),
                "must be a positive number",
            ));
        }
        initial.push(init);
        params.push(dp);
    }
    Ok((base, params, initial))
}

/// The measured torque amplitudes: order, speed, shaft and amplitude each.
fn measurements(
    ctx: &Source,
    chain: &TorsionalChain,
    id: &IdentSection,
    ex: &Excitation,
) -> Result<Vec<Measurement>, ScenarioError> {
    let mut data = Vec::new();
    for (mi, m) in id.measurements.iter().enumerate() {
        let ms = m.get_ref();
        let order = *ms.order.get_ref();
        if !ex.orders.contains(&order) {
            return Err(ctx.at(
                ms.order.span(),
                format!("identification.measurements[{mi}].order"),
                format!("order {order} is not in excitation.orders"),
            ));
        }
        let sp = *ms.speed_rpm.get_ref();
        if !(sp.is_finite() && sp > 0.0) {
            return Err(ctx.at(
                ms.speed_rpm.span(),
                format!("identification.measurements[{mi}].speed_rpm"),
                "must be a positive speed",
            ));
        }
        let tq = *ms.torque.get_ref();
        if !(tq.is_finite() && tq > 0.0) {
            return Err(ctx.at(
                ms.torque.span(),
                format!("identification.measurements[{mi}].torque"),
                "must be a positive torque amplitude",
            ));
        }
        let s = shaft(
            ctx,
            chain,
            &ms.between,
            format!("identification.measurements[{mi}].between"),
        )?;
        data.push(Measurement {
            order,
            speed_rpm: sp,
            shaft: s,
            torque: tq,
        });
    }
    Ok(data)
}

/// The `[identification]` table: the dampers to fit and the measurements.
fn parse_identification(
    ctx: &Source,
    idn: &Spanned<IdentSection>,
    exc: Option<&Excitation>,
    chain: &TorsionalChain,
) -> Result<Identification, ScenarioError> {
    let id = idn.get_ref();
    let Some(ex) = exc else {
        return Err(ctx.section(
            "identification",
            "identification needs an [excitation] table",
        ));
    };
    if id.parameters.is_empty() {
        return Err(ctx.at(
            idn.span(),
            "identification.parameters",
            "no parameters to fit",
        ));
    }
    let (base, params, initial) = damping_parameters(ctx, chain, id)?;
    let data = measurements(ctx, chain, id, ex)?;
    if data.len() <= params.len() {
        return Err(ctx.at(
            idn.span(),
            "identification.measurements",
            format!(
                "{} measurements for {} parameters: need more",
                data.len(),
                params.len()
            ),
        ));
    }
    // Nominal values: what the [chain] table says for those dampers.
    let nominal: Vec<f64> = params
        .iter()
        .map(|p| {
            p.absolute
                .first()
                .map(|&(k, _)| chain.absolute_damping[k])
                .or_else(|| p.relative.first().map(|&(k, _)| chain.relative_damping[k]))
                .unwrap_or(0.0)
        })
        .collect();
    Ok(Identification {
        base,
        params,
        data,
        initial,
        nominal,
        line: line_at(ctx.text, idn.span().start),
    })
}

/// Parses and validates `text` (the contents of `file`) without the analyses (the modes
/// of the chain are computed only to check a time step).
pub fn parse(file: &str, text: &str) -> Result<TorsionalScenario, ScenarioError> {
    let ctx = Source::new(file, text);
    let sc: ScenarioFile =
        toml::from_str(text).map_err(|e| ScenarioError::from_toml(ctx.file, text, &e))?;

    let chain = parse_chain(&ctx, &sc.chain)?;
    let n = chain.inertia.len();
    let (rated, cylinders, angles) = match &sc.engine {
        None => (None, Vec::new(), Vec::new()),
        Some(eng) => parse_engine(&ctx, &chain, eng.get_ref())?,
    };
    let exc = match &sc.excitation {
        None => None,
        Some(x) => {
            if sc.engine.is_none() {
                return Err(ctx.section(
                    "excitation",
                    "an excitation needs an [engine] table (cylinders and firing angles)",
                ));
            }
            Some(parse_excitation(
                &ctx,
                x.get_ref(),
                (&cylinders, &angles),
                n,
            )?)
        }
    };
    let speeds = sc
        .sweep
        .as_ref()
        .map(|s| sweep_speeds(&ctx, s.get_ref(), exc.as_ref(), n))
        .transpose()?;
    let time_check = sc
        .time_check
        .as_ref()
        .map(|t| parse_time_check(&ctx, t.get_ref(), exc.as_ref(), &chain))
        .transpose()?;
    let ident = sc
        .identification
        .as_ref()
        .map(|idn| parse_identification(&ctx, idn, exc.as_ref(), &chain))
        .transpose()?;
    Ok(TorsionalScenario {
        name: sc.name.clone().unwrap_or_else(|| ctx.file.to_string()),
        file: ctx.file.to_string(),
        chain,
        rated,
        exc,
        speeds,
        time_check,
        ident,
    })
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "torsional";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, _opts| run(path, text),
};
