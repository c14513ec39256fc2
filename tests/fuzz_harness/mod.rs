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
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// File names the inputs are given under (the extension picks the model loader).
pub const URDF_FILE: &str = "fuzz.urdf";
/// File name of DH-table inputs.
pub const DH_FILE: &str = "fuzz_dh.toml";
/// File name of MCAP inputs.
pub const MCAP_FILE: &str = "fuzz.mcap";

/// The repository root: this file is compiled into `tests/fuzz_smoke.rs` (manifest at the
/// root) and into the cargo-fuzz targets (manifest in `fuzz/`).
pub fn repo_root() -> &'static Path {
    static ROOT: OnceLock<PathBuf> = OnceLock::new();
    ROOT.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        if dir.join("robots").is_dir() {
            dir
        } else {
            dir.parent().map(Path::to_path_buf).unwrap_or(dir)
        }
    })
}

/// The name scenario inputs are given: `<repo>/scenarios/fuzz_scenario.toml`, so that an
/// arm scenario's `model.file = "../robots/…"` reaches the bundled robots and the arm
/// loader runs all the way through model loading, IK and planning checks.
pub fn scenario_file() -> &'static str {
    static FILE: OnceLock<String> = OnceLock::new();
    FILE.get_or_init(|| {
        repo_root()
            .join("scenarios/fuzz_scenario.toml")
            .display()
            .to_string()
    })
}

/// Largest inputs the targets are fuzzed with (`-max_len`), also used by the smoke test.
pub const URDF_MAX_LEN: usize = 64 * 1024;
/// Largest DH table and scenario inputs.
pub const TOML_MAX_LEN: usize = 8 * 1024;
/// Largest MCAP inputs (the seed recordings are 11 and 29 KiB).
pub const MCAP_MAX_LEN: usize = 64 * 1024;

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
                gravity_torque(&m, &mut data, &q);
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

/// The `scenario_loader` target: parse and validate any scenario (arm, linkage,
/// torsional) as `armsim run` does before running it.
pub fn scenario(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        let file = scenario_file();
        if let Err(e) = armsim::scenario::check(file, text) {
            assert_eq!(e.file, file, "error names another file: {e}");
            check_message(file, &e.to_string());
        }
    }
}

/// The `mcap_reader` target: read the bytes as a recording, as `armsim view` does; on
/// success, turn every transform into a pose (what the viewer draws) and load the robot
/// description the recording carries as a model (what `view` builds geometry from).
pub fn mcap(data: &[u8]) {
    use armsim::recording::{mcap_in, tf::to_se3};
    match mcap_in::read_mcap_bytes(data, Path::new(MCAP_FILE)) {
        Ok(rec) => {
            let frames = rec.frames.iter().flat_map(|f| &f.tf);
            for t in rec.header.static_tf.iter().chain(frames) {
                let _ = to_se3(t);
            }
            if let Some(text) = &rec.header.robot_description {
                model(text, "robot_description.urdf");
            }
        }
        Err(e) => {
            let msg = e.to_string();
            check_message(MCAP_FILE, &msg);
            // The reader turns a decoder panic into an error; under the fuzzer the panic
            // hook aborts first, here the message gives it away.
            assert!(!msg.contains("panicked"), "{msg}");
        }
    }
}
