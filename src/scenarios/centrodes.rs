//! `kind = "centrodes"` scenarios (format in `docs/centrodes.md`): the fixed and moving
//! centrodes of a four-bar's coupler, a slider-crank's rod or a slotted lever's block,
//! traced by the linkage
//! solver over a turn of the crank ([`crate::machines::instant_centres`]), with Kennedy's
//! construction as the check and the rolling (equal arc length) condition.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::plots::panels::{Panel, Series, PALETTE};
use crate::io::report::Report;
use crate::machines::centrode_fit::{classify, CurveFit, CurveKind};
use crate::machines::instant_centres::{
    all_centres, arc_lengths, line_intersection, relative_centrodes, three_centres_error,
    CentrePoint,
};
use crate::machines::linkage::catalog;
use crate::machines::linkage::continuation::sweep_through;
use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::description::GROUND;
use crate::machines::linkage::position::NewtonOptions;
use crate::machines::linkage::sweep::{State, SweepOptions};
use crate::machines::linkage::Vec2;
use crate::scenarios::kit::{finish_with_plot, scenario_name};
use crate::scenarios::source::Source;
use nalgebra::DVector;
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
    four_bar: Option<FourBarIn>,
    slider_crank: Option<SliderCrankIn>,
    slotted_lever: Option<SlottedLeverIn>,
    scotch_yoke: Option<ScotchYokeIn>,
    link: Option<Spanned<String>>,
    relative_to: Option<Spanned<String>>,
    step_deg: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScotchYokeIn {
    crank: F,
    start_deg: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SlottedLeverIn {
    frame: F,
    crank: F,
    start_deg: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FourBarIn {
    frame: F,
    crank: F,
    coupler: F,
    rocker: F,
    assembly: Option<Spanned<i64>>,
    start_deg: Option<F>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SliderCrankIn {
    crank: F,
    rod: F,
    offset: Option<F>,
    start_deg: Option<F>,
}

/// A parsed centrode scenario.
#[derive(Clone, Debug)]
pub struct CentrodesScenario {
    /// Its name.
    pub name: String,
    /// `(g, a, b, c, mode, start)` or `None` for a slider-crank.
    four_bar: Option<(f64, f64, f64, f64, f64, f64)>,
    slider_crank: Option<(f64, f64, f64, f64)>,
    /// `(g, r, start)`.
    slotted_lever: Option<(f64, f64, f64)>,
    /// `(r, start)`.
    scotch_yoke: Option<(f64, f64)>,
    /// The link whose centrodes are traced.
    link: String,
    /// The link it moves relative to (`ground`: the frame).
    relative_to: String,
    step: f64,
}

/// The links of each mechanism, its default traced link and default reference.
fn mechanism_links(section: &str) -> (&'static [&'static str], &'static str, &'static str) {
    match section {
        "four_bar" => (&["ground", "AB", "BC", "DC"], "BC", "ground"),
        "slider_crank" => (&["ground", "AB", "BC", "slider"], "BC", "ground"),
        "slotted_lever" => (&["ground", "AB", "block", "lever"], "block", "ground"),
        _ => (&["ground", "AB", "yoke"], "AB", "yoke"),
    }
}

/// `link` and `relative_to`: names of the mechanism's links (defaults per mechanism),
/// different from each other.
fn link_pair(ctx: &Source, f: &File, section: &str) -> Result<(String, String), ScenarioError> {
    let (names, dl, dr) = mechanism_links(section);
    let pick = |v: &Option<Spanned<String>>, key: &str, default: &str| match v {
        None => Ok(default.to_string()),
        Some(n) if names.contains(&n.get_ref().as_str()) => Ok(n.get_ref().clone()),
        Some(n) => Err(ctx.at(
            n.span(),
            key,
            format!(
                "no link '{}' in the {section} (its links: {})",
                n.get_ref(),
                names.join(", ")
            ),
        )),
    };
    let link = pick(&f.link, "link", dl)?;
    let rel = pick(&f.relative_to, "relative_to", dr)?;
    if link == rel {
        let at = f
            .relative_to
            .as_ref()
            .or(f.link.as_ref())
            .expect("one was given");
        return Err(ctx.at(
            at.span(),
            if f.relative_to.is_some() {
                "relative_to"
            } else {
                "link"
            },
            format!("link and relative_to are both '{link}': give two different links"),
        ));
    }
    Ok((link, rel))
}

/// Parses and validates `text` (the contents of `file`).
pub fn parse(file: &str, text: &str) -> Result<CentrodesScenario, ScenarioError> {
    let ctx = Source::new(file, text);
    let f: File = ctx.parse()?;
    let step = f
        .step_deg
        .as_ref()
        .map(|s| ctx.between(s, "step_deg", 0.001, 90.0))
        .transpose()?
        .unwrap_or(1.0)
        .to_radians();
    let four_bar = f
        .four_bar
        .as_ref()
        .map(|fb| four_bar_input(&ctx, fb))
        .transpose()?;
    let slider_crank = match &f.slider_crank {
        None => None,
        Some(s) => Some((
            ctx.length(&s.crank, "slider_crank.crank")?,
            {
                let rod = ctx.length(&s.rod, "slider_crank.rod")?;
                ctx.same_scale(
                    &s.rod,
                    "slider_crank.rod",
                    (*s.crank.get_ref(), "slider_crank.crank"),
                )?;
                rod
            },
            s.offset
                .as_ref()
                .map(|o| ctx.finite(o, "slider_crank.offset"))
                .transpose()?
                .unwrap_or(0.0),
            s.start_deg
                .as_ref()
                .map(|x| ctx.angle_deg(x, "slider_crank.start_deg"))
                .transpose()?
                .unwrap_or(45.0)
                .to_radians(),
        )),
    };
    let slotted_lever = match &f.slotted_lever {
        None => None,
        Some(s) => Some((
            ctx.length(&s.frame, "slotted_lever.frame")?,
            {
                let crank = ctx.length(&s.crank, "slotted_lever.crank")?;
                ctx.same_scale(
                    &s.crank,
                    "slotted_lever.crank",
                    (*s.frame.get_ref(), "slotted_lever.frame"),
                )?;
                crank
            },
            s.start_deg
                .as_ref()
                .map(|x| ctx.angle_deg(x, "slotted_lever.start_deg"))
                .transpose()?
                .unwrap_or(45.0)
                .to_radians(),
        )),
    };
    let scotch_yoke = match &f.scotch_yoke {
        None => None,
        Some(s) => Some((
            ctx.length(&s.crank, "scotch_yoke.crank")?,
            s.start_deg
                .as_ref()
                .map(|x| ctx.angle_deg(x, "scotch_yoke.start_deg"))
                .transpose()?
                .unwrap_or(45.0)
                .to_radians(),
        )),
    };
    let given = [
        ("four_bar", four_bar.is_some()),
        ("slider_crank", slider_crank.is_some()),
        ("slotted_lever", slotted_lever.is_some()),
        ("scotch_yoke", scotch_yoke.is_some()),
    ];
    match given.iter().filter(|g| g.1).count() {
        0 => Err(ScenarioError::new(
            file,
            Some(1),
            "file",
            "no mechanism: add [four_bar], [slider_crank], [slotted_lever] or [scotch_yoke]",
        )),
        1 => {
            let section = given.iter().find(|g| g.1).expect("one").0;
            let (link, relative_to) = link_pair(&ctx, &f, section)?;
            Ok(CentrodesScenario {
                name: scenario_name(f.name.as_deref(), file),
                four_bar,
                slider_crank,
                slotted_lever,
                scotch_yoke,
                link,
                relative_to,
                step,
            })
        }
        _ => Err(ctx.section(
            given.iter().rev().find(|g| g.1).map_or("file", |g| g.0),
            "more than one mechanism: give one of [four_bar], [slider_crank], [slotted_lever] and [scotch_yoke], not both",
        )),
    }
}

/// Runs a centrode scenario; plots go to `out_dir` when given.
pub fn run(path: &Path, text: &str, out_dir: Option<&Path>) -> Result<Report, ScenarioError> {
    crate::scenarios::kit::parse_and_report(path, text, out_dir, parse, report)
}

fn pt(p: Option<Vec2>) -> Value {
    p.map_or(Value::Null, |p| json!([p.x, p.y]))
}

/// The mechanism assembled at its start angle: the linkage, the assembled coordinates,
/// the start angle and the section it came from.
fn assemble(
    ctx: &Source,
    sc: &CentrodesScenario,
) -> Result<(Linkage, DVector<f64>, f64, &'static str), ScenarioError> {
    if let Some((g, a, b, c, mode, s0)) = sc.four_bar {
        let l = catalog::four_bar(g, a, b, c);
        let q = catalog::four_bar_guess(&l, (g, a, b, c), s0, mode).ok_or_else(|| {
            ctx.section(
                "four_bar",
                format!(
                    "the four-bar does not close at the start angle {:.3}°",
                    s0.to_degrees()
                ),
            )
        })?;
        Ok((l, q, s0, "four_bar"))
    } else if let Some((r, s0)) = sc.scotch_yoke {
        let l = catalog::scotch_yoke(r);
        let q = catalog::scotch_yoke_guess(&l, r, s0);
        Ok((l, q, s0, "scotch_yoke"))
    } else if let Some((g, r, s0)) = sc.slotted_lever {
        let l = catalog::slotted_lever(g, r);
        let q = catalog::slotted_lever_guess(&l, g, r, s0).ok_or_else(|| {
            ctx.section(
                "slotted_lever",
                "at the start angle the crank pin is on the lever pivot: pick another start_deg",
            )
        })?;
        Ok((l, q, s0, "slotted_lever"))
    } else {
        let (r, rod, e, s0) = sc.slider_crank.expect("one mechanism");
        if r + e.abs() > rod * (1.0 + 1e-12) {
            return Err(ctx.section(
                "slider_crank",
                "the crank cannot turn fully (crank + |offset| > rod)",
            ));
        }
        let l = catalog::slider_crank(r, rod, e);
        let q = catalog::slider_crank_guess(&l, r, rod, e, s0, 1.0);
        Ok((l, q, s0, "slider_crank"))
    }
}

/// The largest distance between the fixed centrode and Kennedy's instant centre over
/// the sweep (points farther than 1000 link lengths left out).
fn kennedy_error(
    l: &Linkage,
    sc: &CentrodesScenario,
    samples: &[State],
    pts: &[CentrePoint],
) -> f64 {
    // Kennedy: the crank line A–B meets the rocker line D–C (or the normal to the slide
    // at C, or the normal to the slot through the lever pivot C) in the link's instant
    // centre.
    let mut kennedy_err = 0.0f64;
    for (st, p) in samples.iter().zip(pts) {
        let pos = |n: &str| {
            let (bb, lp) = l.find_point(n).expect("catalog point");
            l.point_position(&st.q, bb, &lp)
        };
        let (a, b) = (Vec2::zeros(), pos("B"));
        let (c, other) = if sc.four_bar.is_some() {
            (pos("C"), l.ground[1].1)
        } else if sc.slotted_lever.is_some() {
            let c = l.ground[1].1;
            let th = st.q[3 * 2 + 2];
            (c, c + Vec2::new(-th.sin(), th.cos()))
        } else {
            let c = pos("C");
            (c, c + Vec2::new(0.0, 1.0))
        };
        if let (Some(k), Some(f)) = (line_intersection(a, b, other, c), p.fixed) {
            if k.norm() < 1e3 * l.length_scale() {
                kennedy_err = kennedy_err.max((k - f).norm());
            }
        }
    }
    kennedy_err
}

/// Computes the report of a parsed scenario.
pub fn report(
    ctx: &Source,
    sc: &CentrodesScenario,
    out_dir: Option<&Path>,
) -> Result<Report, ScenarioError> {
    let (l, guess, start, section) = assemble(ctx, sc)?;
    let opts = SweepOptions {
        from: 0.0,
        to: std::f64::consts::TAU,
        step: sc.step,
        assemble_at: start,
        newton: NewtonOptions::default(),
    };
    let (sw, passed) = sweep_through(&l, &guess, &opts)
        .map_err(|e| ctx.section(section, format!("the linkage solver: {}", e.in_degrees())))?;
    let body_of = |n: &str| l.link_id(n).unwrap_or(GROUND);
    let (body, reference) = (body_of(&sc.link), body_of(&sc.relative_to));
    let pts = relative_centrodes(&l, body, reference, &sw.samples);
    // Kennedy's construction is written for the mechanism's own traced link on the frame.
    let default = mechanism_links(section);
    let kennedy = (section != "scotch_yoke" && sc.link == default.1 && reference == GROUND)
        .then(|| kennedy_error(&l, sc, &sw.samples, &pts));
    let three = sw
        .samples
        .iter()
        .map(|st| three_centres_error(&all_centres(&l, &st.q, &st.dq)))
        .fold(0.0, f64::max);
    let (af, am) = arc_lengths(&pts);
    let infinite: Vec<f64> = pts
        .iter()
        .filter(|p| p.fixed.is_none())
        .map(|p| p.input.to_degrees())
        .collect();
    let scale = l.length_scale();
    let fit = |f: &dyn Fn(&CentrePoint) -> Option<Vec2>| {
        let v: Vec<Vec2> = pts
            .iter()
            .filter_map(f)
            .filter(|p| p.norm() < 1e3 * scale)
            .collect();
        classify(&v, 1e-6 * scale)
    };
    let (fit_fixed, fit_moving) = (fit(&|p| p.fixed), fit(&|p| p.moving));
    let mut text = format!(
        "centrodes: {} ({}): {} relative to {}\n",
        sc.name, l.name, sc.link, sc.relative_to
    );
    writeln!(
        text,
        "  {} positions over a turn; instant centre at infinity at {:?}°",
        pts.len(),
        infinite
    )
    .ok();
    if !passed.is_empty() {
        let deg: Vec<f64> = passed.iter().map(|x| x.to_degrees()).collect();
        writeln!(text, "  continued through change points at {deg:?}°").ok();
    }
    if let Some(k) = kennedy {
        writeln!(text, "  Kennedy's construction agrees within {k:.3e}").ok();
    }
    writeln!(text, "  three-centres lines within {three:.3e}; arc lengths fixed {af:.6}, moving {am:.6} (finite runs)").ok();
    for (what, f) in [("fixed", &fit_fixed), ("moving", &fit_moving)] {
        if let Some(f) = f {
            writeln!(text, "  {what} centrode: {}", fit_text(f)).ok();
        }
    }
    let j = json!({
        "kind": NAME, "name": sc.name, "mechanism": section,
        "link": sc.link,
        "relative_to": sc.relative_to,
        "input_deg": pts.iter().map(|p| p.input.to_degrees()).collect::<Vec<_>>(),
        "fixed": pts.iter().map(|p| pt(p.fixed)).collect::<Vec<_>>(),
        "moving": pts.iter().map(|p| pt(p.moving)).collect::<Vec<_>>(),
        "at_infinity_deg": infinite,
        "kennedy_max_error": kennedy,
        "three_centres_max_error": three,
        "arc_length_fixed": af, "arc_length_moving": am,
        "fit": {"fixed": fit_fixed.as_ref().map(fit_json), "moving": fit_moving.as_ref().map(fit_json)},
        "continued_through_deg": passed.iter().map(|x| x.to_degrees()).collect::<Vec<_>>(),
        "stopped": sw.stopped.as_ref().map(|e| e.in_degrees()),
    });
    if let Some(e) = &sw.stopped {
        writeln!(text, "  the sweep stopped: {}", e.in_degrees()).ok();
    }
    let panels = plot_panels(&pts, 20.0 * l.length_scale(), &sc.relative_to, &sc.link);
    finish_with_plot(ctx, out_dir, (&sc.name, NAME), (&panels, 2), j, text)
}

/// The two centrodes' panels (points farther than `clip` from the origin left out).
fn plot_panels(pts: &[CentrePoint], clip: f64, reference: &str, link: &str) -> Vec<Panel> {
    let series = |f: &dyn Fn(&CentrePoint) -> Option<Vec2>, label: &str, k: usize| Series {
        label: label.into(),
        points: pts
            .iter()
            .filter_map(f)
            .filter(|p| p.norm() < clip)
            .map(|p| (p.x, p.y))
            .collect(),
        color: PALETTE[k],
        dashed: false,
    };
    vec![
        Panel {
            title: format!("fixed centrode ({reference} frame)"),
            x_desc: "x".into(),
            y_desc: "y".into(),
            series: vec![series(&|p| p.fixed, "fixed", 0)],
            equal_aspect: true,
            ..Default::default()
        },
        Panel {
            title: format!("moving centrode ({link} frame)"),
            x_desc: "x".into(),
            y_desc: "y".into(),
            series: vec![series(&|p| p.moving, "moving", 1)],
            equal_aspect: true,
            ..Default::default()
        },
    ]
}

/// A fitted centrode as JSON.
fn fit_json(f: &CurveFit) -> Value {
    json!({
        "kind": f.kind.name(),
        "mean": [f.mean.x, f.mean.y],
        "spread": f.spread,
        "circle": f.circle.map(|c| json!({"centre": [c.centre.x, c.centre.y], "radius": c.radius, "max_residual": c.max_residual})),
        "line": f.line.map(|c| json!({"point": [c.point.x, c.point.y], "direction": [c.direction.x, c.direction.y], "max_residual": c.max_residual})),
    })
}

/// A fitted centrode in the text report.
fn fit_text(f: &CurveFit) -> String {
    match (f.kind, f.circle, f.line) {
        (CurveKind::Point, _, _) => format!("the point ({:.6}, {:.6})", f.mean.x, f.mean.y),
        (CurveKind::Line, _, Some(l)) => format!(
            "a line through ({:.6}, {:.6}) along ({:.6}, {:.6}), residual {:.1e}",
            l.point.x, l.point.y, l.direction.x, l.direction.y, l.max_residual
        ),
        (CurveKind::Circle, Some(c), _) => format!(
            "a circle, centre ({:.6}, {:.6}), radius {:.6}, residual {:.1e}",
            c.centre.x, c.centre.y, c.radius, c.max_residual
        ),
        _ => format!(
            "a curve (best circle residual {})",
            f.circle
                .map_or("-".into(), |c| format!("{:.1e}", c.max_residual))
        ),
    }
}

/// The four-bar's frame, crank, coupler, rocker, assembly mode and start angle (rad),
/// checked.
fn four_bar_input(
    ctx: &Source,
    fb: &FourBarIn,
) -> Result<(f64, f64, f64, f64, f64, f64), ScenarioError> {
    let mode = match &fb.assembly {
        None => 1.0,
        Some(m) if *m.get_ref() == 1 || *m.get_ref() == -1 => *m.get_ref() as f64,
        Some(m) => {
            return Err(ctx.at(
                m.span(),
                "four_bar.assembly",
                "must be 1 or -1 (the sign of (D − B) × (C − B))",
            ))
        }
    };
    let frame = ctx.length(&fb.frame, "four_bar.frame")?;
    for (v, k) in [
        (&fb.crank, "four_bar.crank"),
        (&fb.coupler, "four_bar.coupler"),
        (&fb.rocker, "four_bar.rocker"),
    ] {
        ctx.length(v, k)?;
        ctx.same_scale(v, k, (frame, "four_bar.frame"))?;
    }
    Ok((
        frame,
        *fb.crank.get_ref(),
        *fb.coupler.get_ref(),
        *fb.rocker.get_ref(),
        mode,
        fb.start_deg
            .as_ref()
            .map(|s| ctx.angle_deg(s, "four_bar.start_deg"))
            .transpose()?
            .unwrap_or(45.0)
            .to_radians(),
    ))
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "centrodes";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, opts| run(path, text, opts.out_dir.as_deref()),
};
