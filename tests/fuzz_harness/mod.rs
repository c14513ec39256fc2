//! What each fuzz target does with one input, shared by the cargo-fuzz targets in
//! `fuzz/fuzz_targets/` (included with `#[path]`) and by the stable-toolchain smoke test
//! `tests/fuzz_smoke.rs`, so both exercise exactly the same entry points.
//!
//! A target must never panic, hang or allocate without bound on any input; a refused
//! input must give an error whose message starts with the file name it was given.
#![allow(dead_code)]

use armsim::data::Data;
use armsim::dynamics::gravity_torque;
use armsim::kinematics::{forward_kinematics, update_frames};
use armsim::model::{Model, ModelError};
use armsim::spatial::Vec3;

/// File names the inputs are given under (the extension picks the model loader).
pub const URDF_FILE: &str = "fuzz.urdf";
/// File name of DH-table inputs.
pub const DH_FILE: &str = "fuzz_dh.toml";
/// File name of scenario inputs.
pub const SCENARIO_FILE: &str = "fuzz_scenario.toml";

/// Largest inputs the targets are fuzzed with (`-max_len`), also used by the smoke test.
pub const URDF_MAX_LEN: usize = 64 * 1024;
/// Largest DH table and scenario inputs.
pub const TOML_MAX_LEN: usize = 8 * 1024;

/// Panics unless `msg` (a rendered error) names `file` first.
fn check_message(file: &str, msg: &str) {
    assert!(
        msg.starts_with(&format!("{file}:")),
        "error does not start with the file name '{file}': {msg}"
    );
}

fn check_model_error(file: &str, e: &ModelError) {
    assert_eq!(e.file, file, "error names another file: {e}");
    check_message(file, &e.to_string());
}

/// A configuration inside the limits: the middle of finite limits, else 0 clamped.
fn q_inside(model: &Model) -> Vec<f64> {
    (0..model.nv)
        .map(|k| {
            let (lo, hi) = (model.lower[k], model.upper[k]);
            if lo.is_finite() && hi.is_finite() {
                0.5 * lo + 0.5 * hi
            } else {
                0.0f64.clamp(lo, hi)
            }
        })
        .collect()
}

/// Parses model text as `file`; on success builds the model (and, if it has mimic
/// joints, the model with them as independent coordinates, as `--ignore-mimic` does) and
/// runs forward kinematics and RNEA gravity torques on it.
fn model(text: &str, file: &str) {
    let spec = match Model::spec_from_str(text, file) {
        Ok(spec) => spec,
        Err(e) => return check_model_error(file, &e),
    };
    let mut specs = vec![spec];
    if specs[0].joints.iter().any(|j| j.mimic.is_some()) {
        let mut no_mimic = specs[0].clone();
        for j in &mut no_mimic.joints {
            j.mimic = None;
        }
        specs.push(no_mimic);
    }
    for spec in specs {
        match Model::build(spec) {
            Ok((m, warnings)) => {
                for w in &warnings {
                    check_model_error(file, w);
                }
                let mut data = Data::new(&m);
                let q = q_inside(&m);
                forward_kinematics(&m, &mut data, &q);
                update_frames(&m, &mut data);
                gravity_torque(&m, &mut data, &q, &Vec3::new(0.0, 0.0, -9.81));
            }
            Err(e) => check_model_error(file, &e),
        }
    }
}

/// The `urdf_loader` target.
pub fn urdf(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        model(text, URDF_FILE);
    }
}

/// The `dh_loader` target.
pub fn dh(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        model(text, DH_FILE);
    }
}

/// The `scenario_loader` target: parse and validate (linkage and torsional scenarios;
/// arm scenarios are refused until their loader lands).
pub fn scenario(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Err(e) = armsim::scenario::check(SCENARIO_FILE, text) {
            assert_eq!(e.file, SCENARIO_FILE, "error names another file: {e}");
            check_message(SCENARIO_FILE, &e.to_string());
        }
    }
}
