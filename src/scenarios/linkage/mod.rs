//! `kind = "linkage"` scenarios: the TOML schema, its validation (every error names the
//! file, the line and the key), and [`run`]. The analyses and their output are in
//! [`crate::scenarios::linkage::report`]; `docs/mechanism.md` documents the format.
//!
//! A file holds any of: a linkage (`[ground]`, `[links.*]`, `[[sliders]]`, `[driver]`,
//! `[[contacts]]` (cam contacts), `[guess]`, `[sweep]`, `four_bar`, `coupler_curves`) with optional `[kinetostatics]`,
//! `[[loads]]`, `[counterweight]`, `[flywheel]`; a `[rotor_balance]`; a
//! `[machine_motion]`. Points shared by name between links (or a link and the ground)
//! are pins.

mod contacts_report;
mod contacts_section;
mod contacts_spec;
pub mod friction_report;
mod linkage_scenario;
mod linkage_section;
mod linkage_spec;
mod loads_section;
pub mod report;
mod rotor_machine_sections;

use crate::core::diag::{line_of_key, LocatedError as ScenarioError};
use crate::io::report::Report;
use crate::scenarios::linkage::linkage_section::parse_mechanism;
use crate::scenarios::linkage::loads_section::parse_flywheel;
use crate::scenarios::linkage::rotor_machine_sections::{parse_machine, parse_rotor};
use crate::scenarios::source::Source;
pub use linkage_scenario::{
    CounterweightScenario, FlywheelScenario, KinetostaticsScenario, LinkageScenario,
    MachineScenario, MechanismScenario, RotorScenario, NAME,
};
use linkage_spec::Spec;
use std::path::Path;

/// Parses and validates `text` (the contents of `file`); assembles the linkage once.
pub fn parse(file: &str, text: &str) -> Result<LinkageScenario, ScenarioError> {
    let spec: Spec = toml::from_str(text).map_err(|e| ScenarioError::from_toml(file, text, &e))?;
    let cx = Source::new(file, text);
    let name = spec.name.clone().unwrap_or_else(|| {
        Path::new(file)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or(NAME)
            .to_string()
    });
    let mechanism = match &spec.links {
        Some(_) => Some(parse_mechanism(&cx, &spec)?),
        None => {
            for (key, present) in [
                ("driver", spec.driver.is_some()),
                ("sweep", spec.sweep.is_some()),
                ("kinetostatics", spec.kinetostatics.is_some()),
                ("counterweight", spec.counterweight.is_some()),
            ] {
                if present {
                    let line = text
                        .lines()
                        .position(|l| l.trim() == format!("[{key}]"))
                        .map(|i| i + 1)
                        .unwrap_or(1);
                    return Err(cx.err(
                        line,
                        key,
                        "needs a linkage: no [links.*] tables in the file",
                    ));
                }
            }
            if let Some(c) = spec.contacts.first() {
                return Err(cx.err(
                    cx.line(&c.span()),
                    "contacts",
                    "needs a linkage: no [links.*] tables in the file",
                ));
            }
            None
        }
    };
    let flywheel = match &spec.flywheel {
        Some(f) => Some(parse_flywheel(&cx, f, mechanism.as_ref())?),
        None => None,
    };
    let rotor = match &spec.rotor_balance {
        Some(r) => Some(parse_rotor(&cx, r)?),
        None => None,
    };
    let machine = match &spec.machine_motion {
        Some(m) => Some(parse_machine(&cx, m, mechanism.as_ref())?),
        None => None,
    };
    if mechanism.is_none() && flywheel.is_none() && rotor.is_none() && machine.is_none() {
        return Err(ScenarioError::new(
            file,
            line_of_key(text, "kind"),
            "file",
            "nothing to do: give a linkage ([links.*]), [rotor_balance], [flywheel] or [machine_motion]",
        ));
    }
    Ok(LinkageScenario {
        file: file.to_string(),
        name,
        description: spec.description.clone(),
        mechanism,
        flywheel,
        rotor,
        machine,
    })
}

/// Runs a linkage scenario: parses it and produces the report.
pub fn run(path: &Path, text: &str) -> Result<Report, ScenarioError> {
    let sc = parse(&path.display().to_string(), text)?;
    Ok(crate::scenarios::linkage::report::report(&sc, NAME))
}

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, _opts| run(path, text),
};
