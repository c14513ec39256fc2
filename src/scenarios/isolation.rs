//! `kind = "isolation"` scenarios (format in `docs/isolation.md`): a 1-DOF mount under a
//! harmonic force, a rotating unbalance or base motion; transmissibility tables and
//! curves; isolator selection; impact mounts; the dynamic absorber
//! ([`crate::machines::vibration::isolator`]).

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::plots::panels::{Panel, Series, PALETTE};
use crate::io::report::Report;
use crate::machines::vibration::isolator as iso;
use crate::scenarios::kit::{finish_with_plot, scenario_name};
use crate::scenarios::source::Source;
use serde::Deserialize;
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;
use toml::Spanned;

type F = Spanned<f64>;
type FList = Spanned<Vec<F>>;
/// Mass ratio, tuning, damping ratio (defaults: the optimum), tabulated frequency ratios.
type AbsorberSpec = (f64, Option<f64>, Option<f64>, Vec<f64>);

/// Standard gravity for static deflections (m/s²).
const G: f64 = 9.81;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    mount: Option<MountIn>,
    excitation: Option<ExcitationIn>,
    curves: Option<CurvesIn>,
    selection: Option<SelectionIn>,
    impact: Option<ImpactIn>,
    absorber: Option<AbsorberIn>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MountIn {
    mass: F,
    stiffness: F,
    damping: Option<F>,
    damping_ratio: Option<F>,
    loss_factor: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExcitationIn {
    speed_rpm: Option<F>,
    frequency: Option<F>,
    force: Option<F>,
    unbalance: Option<F>,
    base_amplitude: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CurvesIn {
    damping_ratios: FList,
    frequency_ratios: Option<FList>,
    hysteretic: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SelectionIn {
    mass: F,
    speed_rpm: Option<F>,
    frequency: Option<F>,
    max_transmissibility: F,
    damping_ratio: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ImpactIn {
    mass: F,
    stiffness: F,
    damping_ratio: Option<F>,
    damping_ratios: Option<FList>,
    velocity: Option<F>,
    striking_mass: Option<F>,
    striking_velocity: Option<F>,
    restitution: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AbsorberIn {
    mass_ratio: F,
    tuning: Option<F>,
    damping_ratio: Option<F>,
    frequency_ratios: Option<FList>,
}

/// How the mount dissipates.
#[derive(Clone, Copy, Debug)]
enum Damping {
    Viscous(f64),
    Hysteretic(f64),
}

/// A parsed and validated isolation scenario.
#[derive(Clone, Debug)]
pub struct IsolationScenario {
    /// Its name.
    pub name: String,
    mount: Option<(f64, f64, Damping)>,
    /// Frequency (rad/s) and the load: 0 force, 1 unbalance, 2 base motion.
    excitation: Option<(f64, usize, f64)>,
    curves: Option<(Vec<f64>, Vec<f64>, bool)>,
    selection: Option<(f64, f64, f64, f64)>,
    impact: Option<ImpactSpec>,
    absorber: Option<AbsorberSpec>,
}

/// The `[impact]` section, checked: a mount hit at a velocity, for one damping ratio
/// and/or a sweep of them.
#[derive(Clone, Debug)]
struct ImpactSpec {
    mass: f64,
    stiffness: f64,
    damping_ratio: Option<f64>,
    sweep: Vec<f64>,
    velocity: f64,
}

/// At most this many damping ratios in an impact sweep (each is also integrated, 2·10⁵
/// RK4 steps).
const MAX_IMPACT_SWEEP: usize = 200;

fn speed(ctx: &Source, sec: &str, rpm: Option<&F>, w: Option<&F>) -> Result<f64, ScenarioError> {
    match (rpm, w) {
        (Some(n), None) => Ok(ctx.positive(n, &format!("{sec}.speed_rpm"))? * PI / 30.0),
        (None, Some(w)) => ctx.positive(w, &format!("{sec}.frequency")),
        (Some(_), Some(w)) => Err(ctx.at(
            w.span(),
            format!("{sec}.frequency"),
            "give either `speed_rpm` or `frequency`, not both",
        )),
        (None, None) => Err(ctx.section(sec, "missing: `speed_rpm` or `frequency` (rad/s)")),
    }
}

fn list(ctx: &Source, v: &FList, key: &str, lo: f64) -> Result<Vec<f64>, ScenarioError> {
    if v.get_ref().is_empty() || v.get_ref().len() > 10_000 {
        return Err(ctx.at(v.span(), key, "needs 1 … 10000 values"));
    }
    v.get_ref()
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let y = ctx.finite(x, &format!("{key}[{i}]"))?;
            if y < lo {
                Err(ctx.at(
                    x.span(),
                    format!("{key}[{i}]"),
                    format!("must be at least {lo}, got {y}"),
                ))
            } else {
                Ok(y)
            }
        })
        .collect()
}

/// The `[mount]` section: mass, stiffness and damping.
fn parse_mount(ctx: &Source, m: &MountIn) -> Result<(f64, f64, Damping), ScenarioError> {
    let mass = ctx.positive(&m.mass, "mount.mass")?;
    let c = ctx.positive(&m.stiffness, "mount.stiffness")?;
    let d = match (&m.damping, &m.damping_ratio, &m.loss_factor) {
        (None, None, None) => Damping::Viscous(0.0),
        (Some(b), None, None) => {
            Damping::Viscous(ctx.non_negative(b, "mount.damping")? / (2.0 * (c * mass).sqrt()))
        }
        (None, Some(e), None) => Damping::Viscous(ctx.non_negative(e, "mount.damping_ratio")?),
        (None, None, Some(e)) => Damping::Hysteretic(ctx.non_negative(e, "mount.loss_factor")?),
        _ => {
            return Err(ctx.section(
                "mount",
                "give at most one of `damping`, `damping_ratio`, `loss_factor`",
            ))
        }
    };
    Ok((mass, c, d))
}

/// The `[excitation]` section: speed, which load (0 force, 1 unbalance, 2 base motion) and its
/// size.
fn parse_excitation(
    ctx: &Source,
    e: &ExcitationIn,
    has_mount: bool,
) -> Result<(f64, usize, f64), ScenarioError> {
    if !has_mount {
        return Err(ctx.section("excitation", "needs a [mount]"));
    }
    let w = speed(
        ctx,
        "excitation",
        e.speed_rpm.as_ref(),
        e.frequency.as_ref(),
    )?;
    let loads = [
        ("force", &e.force),
        ("unbalance", &e.unbalance),
        ("base_amplitude", &e.base_amplitude),
    ];
    let given: Vec<usize> = (0..3).filter(|&i| loads[i].1.is_some()).collect();
    if given.len() != 1 {
        return Err(ctx.section(
            "excitation",
            "give exactly one of `force` (N), `unbalance` (kg m) or `base_amplitude` (m)",
        ));
    }
    let k = given[0];
    let v = loads[k]
        .1
        .as_ref()
        .map(|v| ctx.positive(v, &format!("excitation.{}", loads[k].0)))
        .transpose()?
        .unwrap_or(0.0);
    Ok((w, k, v))
}

/// The `[curves]` section: damping ratios, frequency ratios, hysteretic or not.
fn parse_curves(ctx: &Source, c: &CurvesIn) -> Result<(Vec<f64>, Vec<f64>, bool), ScenarioError> {
    Ok((
        list(ctx, &c.damping_ratios, "curves.damping_ratios", 0.0)?,
        c.frequency_ratios
            .as_ref()
            .map(|v| list(ctx, v, "curves.frequency_ratios", 0.0))
            .transpose()?
            .unwrap_or_default(),
        c.hysteretic.unwrap_or(false),
    ))
}

/// The `[selection]` section: mass, speed, largest transmissibility, damping ratio.
fn parse_selection(ctx: &Source, s: &SelectionIn) -> Result<(f64, f64, f64, f64), ScenarioError> {
    let m = ctx.positive(&s.mass, "selection.mass")?;
    let w = speed(ctx, "selection", s.speed_rpm.as_ref(), s.frequency.as_ref())?;
    let tr = ctx.between(
        &s.max_transmissibility,
        "selection.max_transmissibility",
        0.0,
        1.0,
    )?;
    let eps = s
        .damping_ratio
        .as_ref()
        .map(|v| ctx.non_negative(v, "selection.damping_ratio"))
        .transpose()?
        .unwrap_or(0.0);
    if iso::required_ratio(tr, eps).is_none() {
        return Err(ctx.at(
            s.max_transmissibility.span(),
            "selection.max_transmissibility",
            "no frequency ratio reaches it with this damping",
        ));
    }
    Ok((m, w, tr, eps))
}

/// The `[impact]` section: mass, stiffness, damping ratio (or a sweep of them) and impact
/// velocity.
fn parse_impact(ctx: &Source, i: &ImpactIn) -> Result<ImpactSpec, ScenarioError> {
    let m = ctx.positive(&i.mass, "impact.mass")?;
    let c = ctx.positive(&i.stiffness, "impact.stiffness")?;
    let eps = i
        .damping_ratio
        .as_ref()
        .map(|e| ctx.between(e, "impact.damping_ratio", 0.0, 1.0))
        .transpose()?;
    let mut sweep = Vec::new();
    if let Some(list) = &i.damping_ratios {
        if list.get_ref().is_empty() || list.get_ref().len() > MAX_IMPACT_SWEEP {
            return Err(ctx.at(
                list.span(),
                "impact.damping_ratios",
                format!("needs 1 … {MAX_IMPACT_SWEEP} damping ratios"),
            ));
        }
        for (k, e) in list.get_ref().iter().enumerate() {
            sweep.push(ctx.between(e, &format!("impact.damping_ratios[{k}]"), 0.0, 1.0)?);
        }
    }
    if eps.is_none() && sweep.is_empty() {
        return Err(ctx.section(
            "impact",
            "give `damping_ratio`, or `damping_ratios` for a sweep (or both)",
        ));
    }
    let v =
        match (&i.velocity, &i.striking_mass, &i.striking_velocity) {
            (Some(v), None, None) => {
                if let Some(l) = &i.restitution {
                    return Err(ctx.at(
                        l.span(),
                        "impact.restitution",
                        "applies to a striking mass only: give `striking_mass` and \
                         `striking_velocity`, or drop it with `velocity`",
                    ));
                }
                ctx.positive(v, "impact.velocity")?
            }
            (None, Some(m1), Some(v1)) => {
                let lam = i
                    .restitution
                    .as_ref()
                    .map(|l| ctx.non_negative(l, "impact.restitution"))
                    .transpose()?
                    .unwrap_or(0.0);
                if lam > 1.0 {
                    return Err(ctx.at(
                        i.restitution.as_ref().map(|l| l.span()).unwrap_or(0..0),
                        "impact.restitution",
                        "must lie in [0, 1]",
                    ));
                }
                iso::impact_velocity(
                    ctx.positive(m1, "impact.striking_mass")?,
                    ctx.positive(v1, "impact.striking_velocity")?,
                    m,
                    lam,
                )
            }
            _ => return Err(ctx.section(
                "impact",
                "give `velocity`, or `striking_mass` and `striking_velocity` (with `restitution`)",
            )),
        };
    Ok(ImpactSpec {
        mass: m,
        stiffness: c,
        damping_ratio: eps,
        sweep,
        velocity: v,
    })
}

/// The `[absorber]` section: mass ratio, tuning, damping ratio, frequency ratios.
fn parse_absorber(ctx: &Source, a: &AbsorberIn) -> Result<AbsorberSpec, ScenarioError> {
    Ok((
        ctx.positive(&a.mass_ratio, "absorber.mass_ratio")?,
        a.tuning
            .as_ref()
            .map(|v| ctx.positive(v, "absorber.tuning"))
            .transpose()?,
        a.damping_ratio
            .as_ref()
            .map(|v| ctx.non_negative(v, "absorber.damping_ratio"))
            .transpose()?,
        a.frequency_ratios
            .as_ref()
            .map(|v| list(ctx, v, "absorber.frequency_ratios", 0.0))
            .transpose()?
            .unwrap_or_default(),
    ))
}

/// Parses and validates `text` (the contents of `file`).
pub fn parse(file: &str, text: &str) -> Result<IsolationScenario, ScenarioError> {
    let ctx = Source::new(file, text);
    let f: File = ctx.parse()?;
    ctx.any_section(
        &[
            f.mount.is_some(),
            f.excitation.is_some(),
            f.curves.is_some(),
            f.selection.is_some(),
            f.impact.is_some(),
            f.absorber.is_some(),
        ],
        "nothing to compute: add [mount], [curves], [selection], [impact] or [absorber]",
    )?;
    let mount = f.mount.as_ref().map(|x| parse_mount(&ctx, x)).transpose()?;
    let excitation = f
        .excitation
        .as_ref()
        .map(|x| parse_excitation(&ctx, x, mount.is_some()))
        .transpose()?;
    let curves = f
        .curves
        .as_ref()
        .map(|x| parse_curves(&ctx, x))
        .transpose()?;
    let selection = f
        .selection
        .as_ref()
        .map(|x| parse_selection(&ctx, x))
        .transpose()?;
    let impact = f
        .impact
        .as_ref()
        .map(|x| parse_impact(&ctx, x))
        .transpose()?;
    let absorber = f
        .absorber
        .as_ref()
        .map(|x| parse_absorber(&ctx, x))
        .transpose()?;
    Ok(IsolationScenario {
        name: scenario_name(f.name.as_deref(), file),
        mount,
        excitation,
        curves,
        selection,
        impact,
        absorber,
    })
}

/// Runs an isolation scenario; plots go to `out_dir` when given.
pub fn run(path: &Path, text: &str, out_dir: Option<&Path>) -> Result<Report, ScenarioError> {
    crate::scenarios::kit::parse_and_report(path, text, out_dir, parse, report)
}

fn mount_json(sc: &IsolationScenario, text: &mut String) -> Value {
    let Some((m, c, d)) = sc.mount else {
        return Value::Null;
    };
    let p = (c / m).sqrt();
    let (eps, tr): (f64, Box<dyn Fn(f64) -> f64>) = match d {
        Damping::Viscous(e) => (e, Box::new(move |q| iso::transmissibility(q, e))),
        Damping::Hysteretic(e0) => (
            e0,
            Box::new(move |q| iso::transmissibility_hysteretic(q, e0)),
        ),
    };
    writeln!(
        text,
        "mount: p = {p:.4} rad/s ({:.2} rpm), damping {eps:.4}{}, static deflection {:.4e} m",
        p * 30.0 / PI,
        if matches!(d, Damping::Hysteretic(_)) {
            " (hysteretic ε0)"
        } else {
            ""
        },
        G / (p * p)
    )
    .ok();
    let mut v = json!({ "natural_frequency": p, "damping_ratio": eps, "hysteretic": matches!(d, Damping::Hysteretic(_)), "static_deflection": G / (p * p) });
    if let Some((w, kind, load)) = sc.excitation {
        let q = w / p;
        let e = match d {
            Damping::Viscous(e) => e,
            Damping::Hysteretic(e0) => e0 / q,
        };
        let t = tr(q);
        let amp_f = iso::amplitude_factor(q, e);
        let (amp, force) = match kind {
            0 => (load / c * amp_f, load * t),
            1 => (load * w * w / c * amp_f, load * w * w * t),
            _ => (load * t, f64::NAN),
        };
        writeln!(
            text,
            "  excitation at {w:.4} rad/s: q = {q:.4}, TR = {t:.5}, amplitude {amp:.4e} m{}{}",
            if force.is_finite() {
                format!(", transmitted force {force:.4} N")
            } else {
                String::new()
            },
            if q > 2f64.sqrt() {
                " (isolating)"
            } else {
                " (not isolating: q ≤ √2)"
            }
        )
        .ok();
        v["excitation"] = json!({ "frequency": w, "frequency_ratio": q, "transmissibility": t, "amplitude": amp,
            "transmitted_force": force.is_finite().then_some(force), "isolates": q > 2f64.sqrt() });
    }
    v
}

fn curves_json(
    c: &(Vec<f64>, Vec<f64>, bool),
    text: &mut String,
    panels: &mut Vec<Panel>,
) -> Value {
    let (eps_list, qs, hyst) = c;
    let mut out = Vec::new();
    let mut series = Vec::new();
    for (i, &e) in eps_list.iter().enumerate() {
        let tr = |q: f64| {
            if *hyst {
                iso::transmissibility_hysteretic(q, e)
            } else {
                iso::transmissibility(q, e)
            }
        };
        let at: Vec<Value> = qs.iter().map(|&q| {
            let ee = if *hyst { if q > 0.0 { e / q } else { f64::INFINITY } } else { e };
            json!({ "q": q, "transmissibility": tr(q), "amplitude_factor": iso::amplitude_factor(q, ee), "unbalance_force_ratio": q * q * tr(q) })
        }).collect();
        let (pq, pv) = if *hyst {
            (1.0, tr(1.0))
        } else {
            iso::transmissibility_peak(e)
        };
        let ap = (!*hyst && e < 0.5f64.sqrt()).then(|| iso::amplitude_peak(e));
        // Without damping the resonance peak is unbounded: said in words, not as `inf`.
        let peak = |x: f64| {
            if x.is_finite() {
                format!("{x:.4}")
            } else {
                "unbounded (no damping)".into()
            }
        };
        writeln!(
            text,
            "  {} {e}: TR peak {} at q = {pq:.5}{}",
            if *hyst { "loss factor" } else { "ε =" },
            peak(pv),
            ap.map(|(q, a)| format!(", amplitude peak {} at q = {q:.5}", peak(a)))
                .unwrap_or_default()
        )
        .ok();
        out.push(json!({ "damping": e,
            "peak": { "q": pq, "transmissibility": pv, "unbounded": !pv.is_finite() },
            "amplitude_peak": ap.map(|(q, a)| json!({ "q": q, "amplitude_factor": a, "unbounded": !a.is_finite() })),
            "at": at }));
        series.push(Series {
            label: format!("{} = {e}", if *hyst { "ε0" } else { "ε" }),
            points: (1..=400)
                .map(|k| {
                    let q = 4.0 * k as f64 / 400.0;
                    (q, tr(q))
                })
                .filter(|p| p.1.is_finite())
                .collect(),
            color: PALETTE[i % PALETTE.len()],
            dashed: false,
        });
    }
    panels.push(Panel {
        title: "force transmissibility".into(),
        x_desc: "q = ω/p".into(),
        y_desc: "TR".into(),
        log_y: true,
        series,
        ..Default::default()
    });
    json!(out)
}

/// Computes the report of a parsed scenario.
pub fn report(
    ctx: &Source,
    sc: &IsolationScenario,
    out_dir: Option<&Path>,
) -> Result<Report, ScenarioError> {
    let mut text = format!("isolation: {}\n", sc.name);
    let mut j = json!({ "kind": NAME, "name": sc.name });
    let mut panels = Vec::new();
    if sc.mount.is_some() {
        j["mount"] = mount_json(sc, &mut text);
    }
    if let Some(c) = &sc.curves {
        writeln!(text, "transmissibility curves:").ok();
        j["curves"] = curves_json(c, &mut text, &mut panels);
    }
    if let Some((m, w, tr, eps)) = sc.selection {
        let q = iso::required_ratio(tr, eps)
            .ok_or_else(|| ctx.section("selection", "no frequency ratio reaches the target"))?;
        let p = w / q;
        writeln!(text, "selection: q ≥ {q:.4}, p ≤ {p:.4} rad/s, stiffness ≤ {:.4e} N/m, static deflection ≥ {:.4e} m", m * p * p, G / (p * p)).ok();
        j["selection"] = json!({ "frequency": w, "damping_ratio": eps, "frequency_ratio_min": q, "natural_frequency_max": p, "stiffness_max": m * p * p, "static_deflection_min": G / (p * p) });
    }
    if let Some(imp) = &sc.impact {
        j["impact"] = impact_report(imp, &mut text);
    }
    if let Some((mu, f, z, qs)) = &sc.absorber {
        let d = iso::absorber(*mu, f.unwrap_or(1.0 / (1.0 + mu)));
        let tuning = f.unwrap_or(d.optimum_tuning);
        let zeta = z.unwrap_or(d.optimum_damping);
        let sweep: Vec<(f64, f64)> = (1..=4000)
            .map(|k| {
                let q = 2.0 * k as f64 / 4000.0;
                (q, iso::absorber_amplitude(q, *mu, tuning, zeta))
            })
            .collect();
        let peak = sweep
            .iter()
            .fold((0.0, 0.0), |b, p| if p.1 > b.1 { *p } else { b });
        writeln!(text, "absorber μ = {mu}: tuning {tuning:.5} (optimum {:.5}), damping {zeta:.5} (optimum {:.5}); invariant points q = {:.5}, {:.5} at heights {:.4}, {:.4}; rigid resonance {:.5}; largest amplitude {:.4} at q = {:.4}", d.optimum_tuning, d.optimum_damping, d.invariant_points[0], d.invariant_points[1], d.invariant_heights[0], d.invariant_heights[1], d.rigid_resonance, peak.1, peak.0).ok();
        let mut v = serde_json::to_value(&d).unwrap_or(Value::Null);
        v["tuning"] = json!(tuning);
        v["damping_ratio"] = json!(zeta);
        v["peak"] = json!({ "q": peak.0, "amplitude_factor": peak.1 });
        v["response"] = json!(qs.iter().map(|&q| json!({ "q": q, "amplitude_factor": iso::absorber_amplitude(q, *mu, tuning, zeta), "amplitude_factor_direct": iso::absorber_amplitude_direct(q, *mu, tuning, zeta) })).collect::<Vec<_>>());
        panels.push(Panel {
            title: "main mass with absorber".into(),
            x_desc: "q = ω/p".into(),
            y_desc: "A c / P0".into(),
            log_y: true,
            series: vec![Series {
                label: format!("μ = {mu}, ζ = {zeta:.3}"),
                points: sweep.into_iter().step_by(5).collect(),
                color: PALETTE[0],
                dashed: false,
            }],
            ..Default::default()
        });
        j["absorber"] = v;
    }
    finish_with_plot(ctx, out_dir, (&sc.name, NAME), (&panels, 1), j, text)
}

/// The `[impact]` report: the peak transmitted force in closed form and by RK4, for the
/// damping ratio and each of the sweep's, and the optimum damping.
fn impact_report(imp: &ImpactSpec, text: &mut String) -> Value {
    let (m, v) = (imp.mass, imp.velocity);
    let p = (imp.stiffness / m).sqrt();
    let (th, eo) = iso::impact_optimum();
    let row = |eps: f64| {
        let (r, rt) = (
            iso::impact_peak(eps),
            iso::impact_peak_by_integration(eps, 200_000),
        );
        (
            r,
            rt,
            json!({ "damping_ratio": eps, "peak_force": r * m * p * v, "peak_force_ratio": r,
            "peak_force_ratio_by_integration": rt.0, "peak_time": rt.1 / p }),
        )
    };
    let mut j = json!({ "velocity": v, "natural_frequency": p,
        "optimum": { "theta_deg": th.to_degrees(), "damping_ratio": eo, "peak_force_ratio": iso::impact_peak(eo) } });
    if let Some(eps) = imp.damping_ratio {
        let (r, rt, row) = row(eps);
        writeln!(text, "impact: v = {v:.4} m/s, p = {p:.4} rad/s: R_max = {:.4} N ({r:.5} m p v; RK4 {:.5}); optimum ε = {eo:.5} (θ = {:.3}°) gives {:.5} m p v", r * m * p * v, rt.0, th.to_degrees(), iso::impact_peak(eo)).ok();
        for k in [
            "peak_force",
            "peak_force_ratio",
            "peak_force_ratio_by_integration",
            "peak_time",
        ] {
            j[k] = row[k].clone();
        }
    }
    if !imp.sweep.is_empty() {
        writeln!(
            text,
            "impact sweep (v = {v:.4} m/s, p = {p:.4} rad/s; optimum ε = {eo:.5}):"
        )
        .ok();
        let rows: Vec<Value> = imp
            .sweep
            .iter()
            .map(|&eps| {
                let (r, rt, row) = row(eps);
                writeln!(
                    text,
                    "  ε = {eps:.4}: R_max = {:.4} N ({r:.5} m p v; RK4 {:.5})",
                    r * m * p * v,
                    rt.0
                )
                .ok();
                row
            })
            .collect();
        j["sweep"] = json!(rows);
    }
    j
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "isolation";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, opts| run(path, text, opts.out_dir.as_deref()),
};
