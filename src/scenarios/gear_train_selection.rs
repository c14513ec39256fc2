//! The `[selection]` table of a `kind = "gear_train"` file (format in `docs/machines.md`):
//! a required ratio and the train's conditions in, standard tooth counts out
//! ([`crate::machines::gearing::tooth_selection`]). Such a file describes no train
//! (`[[gear]]`, `[[carrier]]`, `[[mesh]]`, … are refused next to it).

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::report::Report;
use crate::machines::gearing::tooth_selection::{select, Requirement, Selection, TrainScheme};
use crate::scenarios::source::Source;
use serde::Deserialize;
use serde_json::{json, Value};
use std::fmt::Write as _;
use toml::Spanned;

/// The `[selection]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SelectionSpec {
    scheme: Spanned<String>,
    ratio: Spanned<f64>,
    tolerance: Option<Spanned<f64>>,
    min_teeth: Option<Spanned<usize>>,
    max_teeth: Option<Spanned<usize>>,
    planets: Option<Spanned<usize>>,
    addendum: Option<Spanned<f64>>,
    coaxial: Option<Spanned<bool>>,
    candidates: Option<Spanned<usize>>,
}

/// A read `[selection]`.
#[derive(Clone, Debug, PartialEq)]
pub struct SelectionScenario {
    /// Scenario name.
    pub name: String,
    /// What is required.
    pub req: Requirement,
    /// The admissible sets, best first.
    pub found: Vec<Selection>,
}

/// Largest `max_teeth` of the schemes searched over three free counts.
const MAX_TEETH_CUBIC: usize = 200;

/// Reads and solves the `[selection]` table at `span` of `file`.
pub fn read(
    cx: &Source,
    name: String,
    span: std::ops::Range<usize>,
    s: &SelectionSpec,
) -> Result<SelectionScenario, ScenarioError> {
    let coaxial = s.coaxial.as_ref().map(|c| (*c.get_ref(), c.span()));
    let scheme = match s.scheme.get_ref().as_str() {
        "two_stage" => TrainScheme::TwoStage {
            coaxial: coaxial.as_ref().is_some_and(|c| c.0),
        },
        "planetary" => TrainScheme::Planetary,
        "compound_planetary" => TrainScheme::CompoundPlanetary,
        other => {
            return Err(cx.at(
                s.scheme.span(),
                "selection.scheme",
                format!("expected two_stage, planetary or compound_planetary, got \"{other}\""),
            ))
        }
    };
    let planetary = !matches!(scheme, TrainScheme::TwoStage { .. });
    if let (Some((_, sp)), true) = (&coaxial, planetary) {
        return Err(cx.at(
            sp.clone(),
            "selection.coaxial",
            "a planetary scheme is coaxial by construction: `coaxial` is for two_stage",
        ));
    }
    if let (Some(p), false) = (&s.planets, planetary) {
        return Err(cx.at(
            p.span(),
            "selection.planets",
            "`planets` is for the planetary schemes",
        ));
    }
    let ratio = if planetary {
        cx.between(&s.ratio, "selection.ratio", 1.0, 1e4)?
    } else {
        cx.between(&s.ratio, "selection.ratio", 0.0, 1e4)?
    };
    let tolerance = match &s.tolerance {
        None => 0.0,
        Some(t) => {
            let x = cx.non_negative(t, "selection.tolerance")?;
            if x > 0.1 {
                return Err(cx.at(
                    t.span(),
                    "selection.tolerance",
                    "must be at most 0.1 (a relative ratio error)",
                ));
            }
            x
        }
    };
    let min_teeth = cx.count(s.min_teeth.as_ref(), "selection.min_teeth", 17, 1..=1000)?;
    let hi_cap = match scheme {
        TrainScheme::Planetary => 1000,
        _ => MAX_TEETH_CUBIC,
    };
    let max_teeth = cx.count(
        s.max_teeth.as_ref(),
        "selection.max_teeth",
        hi_cap.min(150),
        min_teeth..=hi_cap,
    )?;
    let planets = cx.count(s.planets.as_ref(), "selection.planets", 1, 1..=64)?;
    let addendum = match &s.addendum {
        None => 1.0,
        Some(a) => cx.between(a, "selection.addendum", 0.0, 10.0)?,
    };
    let limit = cx.count(s.candidates.as_ref(), "selection.candidates", 5, 1..=100)?;
    let req = Requirement {
        scheme,
        ratio,
        tolerance,
        min_teeth: min_teeth as u32,
        max_teeth: max_teeth as u32,
        planets: planets as u32,
        addendum,
    };
    let found = select(&req, limit);
    if found.is_empty() {
        return Err(cx.at(
            span,
            "selection.ratio",
            format!(
                "no {} tooth counts in {min_teeth} … {max_teeth} reach u = {ratio} within {tolerance} and meet the conditions: widen `tolerance` or `max_teeth`",
                scheme.name()
            ),
        ));
    }
    Ok(SelectionScenario { name, req, found })
}

fn selection_json(req: &Requirement, s: &Selection) -> Value {
    let names = req.scheme.gear_names();
    json!({
        "teeth": names.iter().zip(&s.teeth).map(|(n, z)| json!({"gear": n, "teeth": z})).collect::<Vec<_>>(),
        "ratio": s.ratio,
        "error": s.error,
        "conditions": s.conditions.iter().map(|(c, v)| json!({"condition": c, "value": v})).collect::<Vec<_>>(),
    })
}

/// The report: the best set, then the other candidates.
pub fn report(sc: &SelectionScenario, kind: &str) -> Report {
    let req = &sc.req;
    let mut text = String::new();
    let _ = writeln!(
        text,
        "Tooth selection '{}': {} u = {}, tolerance {}, z = {} … {}{}",
        sc.name,
        req.scheme.name(),
        req.ratio,
        req.tolerance,
        req.min_teeth,
        req.max_teeth,
        if req.planets > 1 {
            format!(", {} planets", req.planets)
        } else {
            String::new()
        }
    );
    for (i, s) in sc.found.iter().enumerate() {
        let z: Vec<String> = req
            .scheme
            .gear_names()
            .iter()
            .zip(&s.teeth)
            .map(|(n, z)| format!("z{n} = {z}"))
            .collect();
        let _ = writeln!(
            text,
            "{} {}: u' = {:.6}, error {:+.4} %",
            if i == 0 { "best " } else { "      " },
            z.join(", "),
            s.ratio,
            100.0 * s.error
        );
    }
    let json = json!({
        "scenario": sc.name,
        "kind": kind,
        "selection": {
            "scheme": req.scheme.name(),
            "ratio": req.ratio,
            "tolerance": req.tolerance,
            "min_teeth": req.min_teeth,
            "max_teeth": req.max_teeth,
            "planets": req.planets,
            "gears": req.scheme.gear_names(),
            "best": selection_json(req, &sc.found[0]),
            "candidates": sc.found.iter().map(|s| selection_json(req, s)).collect::<Vec<_>>(),
        }
    });
    Report { json, text }
}
