//! The linkage part of a linkage scenario, read section by section: the links,
//! the ground points, the sliders, the driver, the sweep, the assembly (from `[guess]`,
//! checked to be a regular position from which the sweep's start is reachable), and the
//! outputs asked for (four-bar, coupler curves, kinetostatics, counterweight).

use crate::core::diag::fmt_num;
use crate::core::diag::{all_finite, LocatedError as ScenarioError};
use crate::machines::linkage::description::{Driver, Linkage, PlanarLink, Slider, GROUND};
use crate::machines::linkage::position::{solve_position, NewtonOptions};
use crate::machines::linkage::sweep::SweepOptions;
use crate::machines::linkage::Vec2;
use crate::scenarios::linkage::contacts_section::parse_contacts;
use crate::scenarios::linkage::linkage_scenario::{MechanismScenario, NAME};
use crate::scenarios::linkage::linkage_spec::{
    body_of, moving_link, text_line_of_table, unit, LinkSpec, Spec, SweepSpec,
};
use crate::scenarios::linkage::loads_section::{parse_counterweight, parse_kineto};
use crate::scenarios::source::Source;
use crate::scenarios::source::MAX_SCALE_RATIO;
use nalgebra::DVector;
use std::collections::HashMap;
use toml::Spanned;

/// Parses the linkage sections into a [`MechanismScenario`] (assembled once).
pub(super) fn parse_mechanism(
    cx: &Source,
    spec: &Spec,
) -> Result<MechanismScenario, ScenarioError> {
    let (links, link_lines) = parse_links(cx, spec)?;
    let ground = parse_ground(cx, spec)?;
    let sliders = parse_sliders(cx, spec, &links)?;
    let (driver, angle_input, dspan) = parse_driver(cx, spec, &links, &link_lines)?;
    let d = spec.driver.as_ref().expect("parsed").get_ref();
    let lname = spec.name.clone().unwrap_or_else(|| NAME.into());
    let contacts = parse_contacts(
        cx,
        &spec.contacts,
        &links,
        &ground,
        spec.kinetostatics.is_some(),
    )?;
    let mut linkage = Linkage::with_shared_pins(lname, ground, links, sliders, driver);
    contacts.add_to(&mut linkage);
    linkage
        .validate()
        .map_err(|e| cx.err(link_lines[0], "links", e.to_string()))?;
    let guides = crate::scenarios::linkage::loads_section::parse_guide_contacts(
        cx,
        spec,
        &linkage,
        spec.kinetostatics.is_some(),
    )?;

    let sw = parse_sweep(cx, spec, angle_input)?;
    let (from, to, step, assemble_at) = (sw.from, sw.to, sw.step, sw.assemble_at);
    let newton = NewtonOptions::default();
    let q0 = parse_guess(cx, spec, &linkage, &link_lines)?;
    contacts.sides_from_guess(&mut linkage, &q0);
    let assembly = assemble(cx, spec, &linkage, &link_lines, &dspan, &sw, &q0, newton)?;
    let max_step = check_assembly(cx, &linkage, &assembly, &sw, newton)?;
    let rkey = if angle_input {
        "report_at_deg"
    } else {
        "report_at"
    };
    report_points_in_reach(cx, (&sw.span, "sweep", rkey), &sw.report_at, &sw, max_step)?;
    let (four_bar, coupler_curves) = parse_curves(cx, spec, &linkage)?;
    let report_at = sw.report_at.clone();
    let kinetostatics = match &spec.kinetostatics {
        None => {
            if let Some(l) = spec.loads.first() {
                return Err(cx.err(
                    cx.line(&l.span()),
                    "loads",
                    "loads need a [kinetostatics] table",
                ));
            }
            None
        }
        Some(k) => Some(parse_kineto(
            cx,
            k,
            &spec.loads,
            &linkage,
            angle_input,
            &report_at,
        )?),
    };
    if let (Some(k), Some(ks)) = (&spec.kinetostatics, &kinetostatics) {
        let at = (&k.span(), "kinetostatics", rkey);
        report_points_in_reach(cx, at, &ks.report_at, &sw, max_step)?;
    }
    let counterweight = parse_counterweight(cx, spec, &linkage, kinetostatics.is_some())?;
    let instant_centres = match &spec.instant_centres {
        None => None,
        Some(c) => {
            let at = parse_centres_at(cx, c, angle_input, &report_at)?;
            report_points_in_reach(cx, (&c.span(), "instant_centres", rkey), &at, &sw, max_step)?;
            Some(at)
        }
    };
    Ok(MechanismScenario {
        guides,
        linkage,
        assembly,
        sweep: SweepOptions {
            from,
            to,
            step,
            assemble_at,
            newton,
        },
        angle_input,
        speed: d.speed,
        acceleration: d.acceleration,
        report_at,
        four_bar,
        coupler_curves,
        kinetostatics,
        counterweight,
        instant_centres,
    })
}

/// `[instant_centres]`: the inputs to report at (degrees for an angle driver, metres for
/// a slide), the sweep's `report_at` by default; at least one.
fn parse_centres_at(
    cx: &Source,
    c: &Spanned<crate::scenarios::linkage::linkage_spec::CentresSpec>,
    angle_input: bool,
    sweep_report: &[f64],
) -> Result<Vec<f64>, ScenarioError> {
    let span = c.span();
    let s = c.get_ref();
    let (wrong, right) = if angle_input {
        ("report_at", "an angle driver: use report_at_deg")
    } else {
        ("report_at_deg", "a slide driver: use report_at (m)")
    };
    let given_wrong = if angle_input {
        !s.report_at.is_empty()
    } else {
        !s.report_at_deg.is_empty()
    };
    if given_wrong {
        return Err(cx.err(
            cx.key_line(&span, wrong),
            format!("instant_centres.{wrong}"),
            right,
        ));
    }
    let at: Vec<f64> = if angle_input {
        s.report_at_deg.iter().map(|x| x.to_radians()).collect()
    } else {
        s.report_at.clone()
    };
    let at = if at.is_empty() {
        sweep_report.to_vec()
    } else {
        at
    };
    if at.is_empty() {
        return Err(cx.err(
            cx.line(&span),
            "instant_centres",
            "no input to report at: give report_at_deg (or report_at) here or in [sweep]",
        ));
    }
    Ok(at)
}

/// The links in file order, with the line each starts on.
fn parse_links(cx: &Source, spec: &Spec) -> Result<(Vec<PlanarLink>, Vec<usize>), ScenarioError> {
    let links_spec = spec.links.as_ref().expect("checked by the caller");
    // File order (the map is sorted by name): by span.
    let mut order: Vec<(&String, &Spanned<LinkSpec>)> = links_spec.iter().collect();
    order.sort_by_key(|(_, s)| s.span().start);
    if order.is_empty() {
        let line = text_line_of_table(cx.text, "links").unwrap_or(1);
        return Err(cx.err(line, "links", "[links] is empty: a linkage needs links"));
    }
    let mut links = Vec::new();
    let mut link_lines = Vec::new();
    for (n, s) in &order {
        if n.as_str() == "ground" {
            return Err(cx.err(
                cx.line(&s.span()),
                "links.ground",
                "`ground` is reserved: use [ground]",
            ));
        }
        links.push(parse_link(cx, n, s)?);
        link_lines.push(cx.line(&s.span()));
    }
    same_scale(cx, spec, &order)?;
    Ok((links, link_lines))
}

/// Every link `length` lies within [`MAX_SCALE_RATIO`] of the mechanism's size (the
/// largest length or coordinate of the links and the ground).
fn same_scale(
    cx: &Source,
    spec: &Spec,
    order: &[(&String, &Spanned<LinkSpec>)],
) -> Result<(), ScenarioError> {
    let coords = order
        .iter()
        .flat_map(|(_, s)| s.get_ref().points.iter().flatten().flat_map(|(_, p)| *p))
        .chain(spec.ground.iter().flatten().flat_map(|(_, p)| *p.get_ref()));
    let lengths = order.iter().filter_map(|(_, s)| s.get_ref().length);
    let size = lengths
        .chain(coords)
        .filter(|x| x.is_finite())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    for ((n, s), len) in order
        .iter()
        .zip(order.iter().map(|(_, s)| s.get_ref().length))
    {
        let Some(len) = len else { continue };
        if len < size / MAX_SCALE_RATIO {
            return Err(cx.err(
                cx.key_line(&s.span(), "length"),
                format!("links.{n}.length"),
                format!(
                    "{} is {} times the mechanism's size ({}, its largest length or \
                     coordinate): the lengths of one mechanism lie within a factor {} of each \
                     other",
                    fmt_num(len),
                    fmt_num(len / size),
                    fmt_num(size),
                    fmt_num(MAX_SCALE_RATIO)
                ),
            ));
        }
    }
    Ok(())
}

/// The ground points.
fn parse_ground(cx: &Source, spec: &Spec) -> Result<Vec<(String, Vec2)>, ScenarioError> {
    let mut ground = Vec::new();
    for (n, p) in spec.ground.iter().flatten() {
        if !all_finite(p.get_ref()) {
            return Err(cx.err(
                cx.line(&p.span()),
                format!("ground.{n}"),
                "non-finite coordinates",
            ));
        }
        ground.push((n.clone(), Vec2::new(p.get_ref()[0], p.get_ref()[1])));
    }
    Ok(ground)
}

/// The sliders (prismatic or pin-in-slot), each on a link and a guide.
fn parse_sliders(
    cx: &Source,
    spec: &Spec,
    links: &[PlanarLink],
) -> Result<Vec<Slider>, ScenarioError> {
    let mut sliders = Vec::new();
    for (k, sp) in spec.sliders.iter().enumerate() {
        let s = sp.get_ref();
        let key = format!("sliders[{k}]");
        let span = sp.span();
        let link = moving_link(cx, links, &s.link, &span, (&key, "link"))?;
        let guide = body_of(links, &s.guide).ok_or_else(|| {
            cx.err(
                cx.key_line(&span, "guide"),
                format!("{key}.guide"),
                format!("no link '{}'", s.guide),
            )
        })?;
        if guide == link {
            return Err(cx.err(
                cx.key_line(&span, "guide"),
                format!("{key}.guide"),
                "a link cannot slide on itself",
            ));
        }
        let p = links[link].point(&s.point).ok_or_else(|| {
            cx.err(
                cx.key_line(&span, "point"),
                format!("{key}.point"),
                format!("link '{}' has no point '{}'", s.link, s.point),
            )
        })?;
        let dir = unit(s.direction).ok_or_else(|| {
            cx.err(
                cx.key_line(&span, "direction"),
                format!("{key}.direction"),
                "must be a non-zero vector",
            )
        })?;
        if !all_finite(&s.through) {
            return Err(cx.err(
                cx.key_line(&span, "through"),
                format!("{key}.through"),
                "non-finite",
            ));
        }
        let prismatic = match s.kind.as_str() {
            "prismatic" => Some(s.angle_deg.unwrap_or(0.0).to_radians()),
            "pin_in_slot" => None,
            other => {
                return Err(cx.err(
                    cx.key_line(&span, "type"),
                    format!("{key}.type"),
                    format!(
                        "unknown slider type '{other}' (expected \"prismatic\" or \"pin_in_slot\")"
                    ),
                ))
            }
        };
        sliders.push(Slider {
            name: s.point.clone(),
            link,
            p,
            guide,
            through: Vec2::new(s.through[0], s.through[1]),
            dir,
            prismatic,
        });
    }
    Ok(sliders)
}

/// The driver, whether it turns (`true`) or slides, and its span.
fn parse_driver(
    cx: &Source,
    spec: &Spec,
    links: &[PlanarLink],
    link_lines: &[usize],
) -> Result<(Driver, bool, std::ops::Range<usize>), ScenarioError> {
    let Some(dsp) = &spec.driver else {
        return Err(cx.err(
            link_lines[0],
            "driver",
            "missing [driver]: which link is the input",
        ));
    };
    let dspan = dsp.span();
    let d = dsp.get_ref();
    let dlink = moving_link(cx, links, &d.link, &dspan, ("driver", "link"))?;
    if !(d.speed.is_finite() && d.acceleration.is_finite()) {
        return Err(cx.err(cx.key_line(&dspan, "speed"), "driver.speed", "non-finite"));
    }
    let (driver, angle_input) = match d.kind.as_str() {
        "angle" => {
            let rel = match &d.relative_to {
                None => GROUND,
                Some(n) => body_of(links, n).ok_or_else(|| {
                    cx.err(
                        cx.key_line(&dspan, "relative_to"),
                        "driver.relative_to",
                        format!("no link '{n}'"),
                    )
                })?,
            };
            if rel == dlink {
                return Err(cx.err(
                    cx.key_line(&dspan, "relative_to"),
                    "driver.relative_to",
                    "the driven link itself",
                ));
            }
            (
                Driver::Angle {
                    link: dlink,
                    relative_to: rel,
                },
                true,
            )
        }
        "slide" => {
            let pn = d.point.as_ref().ok_or_else(|| {
                cx.err(
                    cx.line(&dspan),
                    "driver.point",
                    "missing: a slide driver needs the driven `point`",
                )
            })?;
            let p = links[dlink].point(pn).ok_or_else(|| {
                cx.err(
                    cx.key_line(&dspan, "point"),
                    "driver.point",
                    format!("link '{}' has no point '{pn}'", d.link),
                )
            })?;
            let through = d
                .through
                .ok_or_else(|| cx.err(cx.line(&dspan), "driver.through", "missing"))?;
            let dir = d
                .direction
                .and_then(unit)
                .ok_or_else(|| cx.err(cx.line(&dspan), "driver.direction", "missing or zero"))?;
            (
                Driver::Slide {
                    link: dlink,
                    p,
                    through: Vec2::new(through[0], through[1]),
                    dir,
                },
                false,
            )
        }
        other => {
            return Err(cx.err(
                cx.key_line(&dspan, "type"),
                "driver.type",
                format!("unknown driver type '{other}' (expected \"angle\" or \"slide\")"),
            ))
        }
    };
    Ok((driver, angle_input, dspan))
}

/// The sweep, in radians or metres.
struct SweepRange {
    span: std::ops::Range<usize>,
    angle_input: bool,
    from: f64,
    to: f64,
    step: f64,
    assemble_at: f64,
    report_at: Vec<f64>,
}

/// The `[sweep]` (degrees for an angle driver, metres for a slide).
fn parse_sweep(cx: &Source, spec: &Spec, angle_input: bool) -> Result<SweepRange, ScenarioError> {
    let default_sweep = Spanned::new(0..0, SweepSpec::default());
    let ssp = spec.sweep.as_ref().unwrap_or(&default_sweep);
    let sspan = ssp.span();
    let s = ssp.get_ref();
    let deg_keys = s.from_deg.is_some()
        || s.to_deg.is_some()
        || s.step_deg.is_some()
        || s.assemble_at_deg.is_some()
        || !s.report_at_deg.is_empty();
    let lin_keys = s.from.is_some()
        || s.to.is_some()
        || s.step.is_some()
        || s.assemble_at.is_some()
        || !s.report_at.is_empty();
    if angle_input && lin_keys {
        return Err(cx.err(
            cx.line(&sspan),
            "sweep",
            "an angle driver sweeps in degrees: use from_deg, to_deg, step_deg, assemble_at_deg, report_at_deg",
        ));
    }
    if !angle_input && deg_keys {
        return Err(cx.err(
            cx.line(&sspan),
            "sweep",
            "a slide driver sweeps in metres: use from, to, step, assemble_at, report_at",
        ));
    }
    let (from, to, step, assemble_at, report_at) = if angle_input {
        let from = s.from_deg.unwrap_or(0.0);
        (
            from.to_radians(),
            s.to_deg.unwrap_or(from + 360.0).to_radians(),
            s.step_deg.unwrap_or(1.0).to_radians(),
            s.assemble_at_deg.unwrap_or(from).to_radians(),
            s.report_at_deg
                .iter()
                .map(|x| x.to_radians())
                .collect::<Vec<_>>(),
        )
    } else {
        let from = s.from.ok_or_else(|| {
            cx.err(
                cx.line(&sspan),
                "sweep.from",
                "missing: where the slide sweep starts (m)",
            )
        })?;
        let to = s.to.ok_or_else(|| {
            cx.err(
                cx.line(&sspan),
                "sweep.to",
                "missing: where the slide sweep ends (m)",
            )
        })?;
        (
            from,
            to,
            s.step.unwrap_or((to - from).abs() / 100.0),
            s.assemble_at.unwrap_or(from),
            s.report_at.clone(),
        )
    };
    let step_key = if angle_input { "step_deg" } else { "step" };
    if !(step.is_finite() && step > 0.0 && all_finite(&[from, to, assemble_at])) {
        return Err(cx.err(
            cx.key_line(&sspan, step_key),
            format!("sweep.{step_key}"),
            "the sweep needs finite bounds and a positive step",
        ));
    }
    if (to - from).abs() / step > 1e6 {
        return Err(cx.err(
            cx.key_line(&sspan, step_key),
            format!("sweep.{step_key}"),
            "more than a million steps",
        ));
    }
    Ok(SweepRange {
        span: sspan,
        angle_input,
        from,
        to,
        step,
        assemble_at,
        report_at,
    })
}

/// The start coordinates from `[guess]` and the ground.
fn parse_guess(
    cx: &Source,
    spec: &Spec,
    linkage: &Linkage,
    link_lines: &[usize],
) -> Result<DVector<f64>, ScenarioError> {
    let mut guess = HashMap::new();
    for (n, p) in spec.guess.iter().flatten() {
        if linkage.find_point(n).is_none() {
            return Err(cx.err(
                cx.line(&p.span()),
                format!("guess.{n}"),
                format!("no point '{n}' on any link"),
            ));
        }
        if !all_finite(p.get_ref()) {
            return Err(cx.err(cx.line(&p.span()), format!("guess.{n}"), "non-finite"));
        }
        guess.insert(n.clone(), Vec2::new(p.get_ref()[0], p.get_ref()[1]));
    }
    let guess_line = text_line_of_table(cx.text, "guess").unwrap_or(link_lines[0]);
    let q0 = linkage.coordinates_from_points(&guess, &[]).map_err(|e| {
        cx.err(
            guess_line,
            "guess",
            format!("link '{}' has no point in [guess] or on the ground", e.link),
        )
    })?;
    Ok(q0)
}

/// Solves the position at `assemble_at` from the guess (the error names the joint that
/// does not close).
#[allow(clippy::too_many_arguments)]
fn assemble(
    cx: &Source,
    spec: &Spec,
    linkage: &Linkage,
    link_lines: &[usize],
    dspan: &std::ops::Range<usize>,
    sw: &SweepRange,
    q0: &DVector<f64>,
    newton: NewtonOptions,
) -> Result<DVector<f64>, ScenarioError> {
    let (angle_input, assemble_at) = (sw.angle_input, sw.assemble_at);
    let assembly = match solve_position(linkage, q0, assemble_at, &newton) {
        Ok(sol) => sol.q,
        Err(e) => {
            let n_contacts = spec.contacts.len();
            let n_pins = linkage.joints.len() - spec.sliders.len() - n_contacts;
            let n_lower = linkage.joints.len() - n_contacts;
            let (line, key) = match e.joint {
                Some(k) if k >= n_lower => (
                    cx.line(&spec.contacts[k - n_lower].span()),
                    format!("contacts[{}]", k - n_lower),
                ),
                Some(k) if k >= n_pins => (
                    cx.line(&spec.sliders[k - n_pins].span()),
                    format!("sliders[{}]", k - n_pins),
                ),
                Some(k) => match &linkage.joints[k] {
                    crate::machines::linkage::PlanarJoint::Revolute { b, .. } if *b != GROUND => {
                        (link_lines[*b], format!("links.{}", linkage.links[*b].name))
                    }
                    _ => (cx.line(dspan), "driver".to_string()),
                },
                None => (cx.line(dspan), "driver".to_string()),
            };
            let at = if angle_input {
                format!("{}°", assemble_at.to_degrees())
            } else {
                format!("{assemble_at} m")
            };
            return Err(cx.err(
                line,
                key,
                format!(
                    "the linkage cannot be assembled at input {at}: {} is off by {:.4} (check the link lengths, the ground points and [guess])",
                    e.what, e.residual
                ),
            ));
        }
    };
    Ok(assembly)
}

/// The assembly must be a regular position (where the guess picks one branch), and the
/// sweep's start reachable from it on that branch.
fn check_assembly(
    cx: &Source,
    linkage: &Linkage,
    assembly: &DVector<f64>,
    sw: &SweepRange,
    newton: NewtonOptions,
) -> Result<f64, ScenarioError> {
    let (angle_input, sspan) = (sw.angle_input, &sw.span);
    let (from, to, step, assemble_at) = (sw.from, sw.to, sw.step, sw.assemble_at);
    // The assembly must be a regular position (where the guess picks one branch), and the
    // sweep's start reachable from it on that branch.
    {
        let at_key = if angle_input {
            "assemble_at_deg"
        } else {
            "assemble_at"
        };
        let t = crate::machines::linkage::sweep::Tracker::assemble(
            linkage,
            assembly,
            assemble_at,
            newton,
        )
        .map_err(|e| cx.err(cx.line(sspan), "sweep", e.to_string()))?;
        // The tracker moves at most `max_step` at a time: from the assembly to `from`,
        // then over the sweep (at most `step` between samples).
        let tracking_steps =
            (from - assemble_at).abs() / t.max_step + (to - from).abs() / step.min(t.max_step);
        if tracking_steps.is_nan() || tracking_steps > 1e6 {
            let at_key = if angle_input {
                "assemble_at_deg"
            } else {
                "assemble_at"
            };
            return Err(cx.err(
                cx.line(sspan),
                "sweep",
                format!(
                    "more than a million tracking steps from `{at_key}` to the start of the sweep and over it (a tracking step is at most {})",
                    if angle_input {
                        format!("{}°", t.max_step.to_degrees())
                    } else {
                        format!("{} m", t.max_step)
                    }
                ),
            ));
        }
        if t.state().singular {
            return Err(cx.err(
                cx.key_line(sspan, at_key),
                format!("sweep.{at_key}"),
                "the linkage is at a singular position there (branches meet, the guess cannot pick one): assemble at a regular position",
            ));
        }
        let mut t = t;
        let max_step = t.max_step;
        t.advance(from).map_err(|e| {
            let k = if angle_input { "from_deg" } else { "from" };
            let e = if angle_input {
                e.in_degrees()
            } else {
                e.to_string()
            };
            cx.err(
                cx.key_line(sspan, k),
                format!("sweep.{k}"),
                format!("the sweep start is not reachable from the assembly on its branch: {e}"),
            )
        })?;
        Ok(max_step)
    }
}

/// At most this many tracking steps from the sweep to one report point.
const MAX_REPORT_STEPS: f64 = 1e5;

/// Every report point (`section.key`, in the table at `span`) is finite and within
/// [`MAX_REPORT_STEPS`] tracking steps of at most `max_step` of the sweep's range: the
/// report tracks to each point from the nearest sample.
fn report_points_in_reach(
    cx: &Source,
    (span, section, key): (&std::ops::Range<usize>, &str, &str),
    points: &[f64],
    sw: &SweepRange,
    max_step: f64,
) -> Result<(), ScenarioError> {
    let (lo, hi) = (sw.from.min(sw.to), sw.from.max(sw.to));
    let shown = |x: f64| {
        if sw.angle_input {
            format!("{}°", crate::core::diag::fmt_num(x.to_degrees()))
        } else {
            format!("{} m", crate::core::diag::fmt_num(x))
        }
    };
    for (i, &x) in points.iter().enumerate() {
        let err = |m: String| cx.err(cx.key_line(span, key), format!("{section}.{key}[{i}]"), m);
        if !x.is_finite() {
            return Err(err(format!("must be a finite number, got {x}")));
        }
        let away = (lo - x).max(x - hi).max(0.0);
        if away / max_step > MAX_REPORT_STEPS {
            return Err(err(format!(
                "{} lies {} outside the sweep ({} to {}): reporting there would track more \
                 than {} steps of at most {}; report within the sweep",
                shown(x),
                shown(away),
                shown(sw.from),
                shown(sw.to),
                crate::core::diag::fmt_num(MAX_REPORT_STEPS),
                shown(max_step)
            )));
        }
    }
    Ok(())
}

/// The four-bar points and the coupler curves asked for.
type Curves = (Option<[String; 4]>, Vec<String>);

fn parse_curves(cx: &Source, spec: &Spec, linkage: &Linkage) -> Result<Curves, ScenarioError> {
    // Four-bar and coupler curves.
    let four_bar = match &spec.four_bar {
        None => None,
        Some(fb) => {
            let v = fb.get_ref();
            if v.len() != 4 {
                return Err(cx.err(cx.line(&fb.span()), "four_bar", "give four points [O, A, B, C]: input pivot, input pin, coupler-output pin, output pivot"));
            }
            for n in v {
                if linkage.find_point(n).is_none() {
                    return Err(cx.err(cx.line(&fb.span()), "four_bar", format!("no point '{n}'")));
                }
            }
            Some([v[0].clone(), v[1].clone(), v[2].clone(), v[3].clone()])
        }
    };
    let coupler_curves = match &spec.coupler_curves {
        None => Vec::new(),
        Some(c) => {
            for n in c.get_ref() {
                if linkage.find_point(n).is_none() {
                    return Err(cx.err(
                        cx.line(&c.span()),
                        "coupler_curves",
                        format!("no point '{n}'"),
                    ));
                }
            }
            c.get_ref().clone()
        }
    };
    Ok((four_bar, coupler_curves))
}

fn parse_link(
    cx: &Source,
    name: &str,
    sp: &Spanned<LinkSpec>,
) -> Result<PlanarLink, ScenarioError> {
    let line = cx.line(&sp.span());
    let key = format!("links.{name}");
    let s = sp.get_ref();
    let mut points: Vec<(String, Vec2)> = Vec::new();
    if let Some([a, b]) = &s.ends {
        let Some(len) = s.length else {
            return Err(cx.err(
                line,
                format!("{key}.length"),
                "missing: a link with `ends` needs its `length` (m)",
            ));
        };
        let (lo, hi) = crate::scenarios::source::LENGTHS;
        if !(len.is_finite() && len > 0.0) {
            return Err(cx.err(
                cx.key_line(&sp.span(), "length"),
                format!("{key}.length"),
                format!("must be a positive length, got {len}"),
            ));
        }
        if !(lo..=hi).contains(&len) {
            return Err(cx.err(
                cx.key_line(&sp.span(), "length"),
                format!("{key}.length"),
                format!("{len:e} is out of range: a length lies in {lo:e}..{hi:e}"),
            ));
        }
        if a == b {
            return Err(cx.err(line, format!("{key}.ends"), "the two ends must differ"));
        }
        points.push((a.clone(), Vec2::zeros()));
        points.push((b.clone(), Vec2::new(len, 0.0)));
    } else if s.length.is_some() {
        return Err(cx.err(
            cx.key_line(&sp.span(), "length"),
            format!("{key}.length"),
            "`length` needs `ends = [\"P\", \"Q\"]` (the points it separates)",
        ));
    }
    for (pn, p) in s.points.iter().flatten() {
        if !all_finite(p) {
            return Err(cx.err(line, format!("{key}.points.{pn}"), "non-finite coordinates"));
        }
        if points.iter().any(|(n, _)| n == pn) {
            return Err(cx.err(
                line,
                format!("{key}.points.{pn}"),
                "point given twice (also in `ends`)",
            ));
        }
        points.push((pn.clone(), Vec2::new(p[0], p[1])));
    }
    if points.is_empty() {
        return Err(cx.err(line, key, "a link needs `ends` and `length`, or `points`"));
    }
    let mass = s.mass.unwrap_or(0.0);
    let inertia = s.inertia.unwrap_or(0.0);
    for (k, v) in [("mass", mass), ("inertia", inertia)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(cx.err(
                cx.key_line(&sp.span(), k),
                format!("{key}.{k}"),
                format!("must be ≥ 0, got {v}"),
            ));
        }
    }
    let com = match s.com {
        Some(c) if !all_finite(&c) => {
            return Err(cx.err(
                cx.key_line(&sp.span(), "com"),
                format!("{key}.com"),
                "non-finite",
            ))
        }
        Some(c) => Vec2::new(c[0], c[1]),
        None if s.ends.is_some() => (points[0].1 + points[1].1) * 0.5,
        None => Vec2::zeros(),
    };
    Ok(PlanarLink {
        name: name.to_string(),
        points,
        mass,
        com,
        inertia,
    })
}
