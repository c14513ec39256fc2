//! What each fuzz target does with one input, shared by the cargo-fuzz targets in
//! `fuzz/fuzz_targets/` (included with `#[path]`) and by the stable-toolchain smoke test
//! `tests/fuzz_smoke.rs`, so both exercise exactly the same entry points.
//!
//! A target must never panic, hang or allocate without bound on any input; a refused
//! input must give an error whose message starts with the file name it was given.
#![allow(dead_code)]

use armsim::dynamics::gravity_torque;
use armsim::kinematics::{forward_kinematics, update_frames};
use armsim::model::data::Data;
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
/// Largest mesh (STL, OBJ, DAE), SRDF and MoveIt YAML inputs.
pub const MESH_MAX_LEN: usize = 64 * 1024;
/// File name of SRDF inputs.
pub const SRDF_FILE: &str = "fuzz.srdf";
/// File name of MoveIt YAML inputs.
pub const YAML_FILE: &str = "fuzz.yaml";

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
        if let Err(e) = armsim::scenarios::check(file, text) {
            assert_eq!(e.file, file, "error names another file: {e}");
            check_message(file, &e.to_string());
        }
    }
}

/// The `mcap_reader` target: read the bytes as a recording, as `armsim view` does; on
/// success, turn every transform into a pose (what the viewer draws) and load the robot
/// description the recording carries as a model (what `view` builds geometry from).
pub fn mcap(data: &[u8]) {
    use armsim::io::record::mcap_in;
    use armsim::io::record::tf::to_se3;
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

/// What every mesh reader must return: an error with a message, or a mesh whose indices
/// are in range and whose coordinates are finite, that the collision layer accepts as a
/// triangle mesh and as a convex hull (no panic) and whose closedness and volume can be computed.
fn mesh(result: Result<armsim::collision::mesh::MeshData, armsim::collision::mesh::MeshError>) {
    match result {
        Ok(m) => {
            let n = m.vertices.len();
            assert!(m.triangles.iter().flatten().all(|&i| (i as usize) < n));
            assert!(m.vertices.iter().flatten().all(|x| x.is_finite()));
            // A reader's warnings (DAE instances naming no geometry) render with the file.
            for w in &m.warnings {
                let shown = w.clone().in_file("fuzz.mesh").to_string();
                assert!(
                    shown.starts_with("fuzz.mesh") && !w.message.is_empty(),
                    "{shown}"
                );
            }
            let _ = (m.is_closed(), m.signed_volume6());
            if !m.triangles.is_empty() {
                use armsim::collision::CollisionShape;
                let _ = CollisionShape::from_mesh(&m, [1.0; 3], false);
                // `--convex-hulls`: parry's hull of the same vertices.
                let _ = CollisionShape::from_mesh(&m, [1.0; 3], true);
            }
        }
        Err(e) => assert!(!e.to_string().is_empty(), "an empty mesh error"),
    }
}

/// The `stl_reader` target: binary or ASCII STL bytes.
pub fn stl(data: &[u8]) {
    mesh(armsim::collision::mesh::read_stl(data));
}

/// The `obj_reader` target: Wavefront OBJ bytes (through `mesh-loader`).
pub fn obj(data: &[u8]) {
    mesh(armsim::collision::mesh::read_obj_bytes(data));
}

/// The `dae_reader` target: COLLADA text.
pub fn dae(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        mesh(armsim::collision::mesh::read_dae(text));
    }
}

/// A bundled model, loaded once (the SRDF and request targets match names against it).
fn bundled(name: &str) -> &'static Model {
    static MODELS: OnceLock<(Model, Model)> = OnceLock::new();
    let (ur5, panda) = MODELS.get_or_init(|| {
        let load = |f: &str| Model::load(repo_root().join("robots").join(f)).unwrap().0;
        (load("ur5.urdf"), load("panda.urdf"))
    });
    if name == "ur5" {
        ur5
    } else {
        panda
    }
}

/// The `srdf_reader` target: parse an SRDF, then filter its pairs against the UR5 and
/// the Panda (unknown links and `<disable_default_collisions>` give warnings).
pub fn srdf(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match armsim::planning::srdf::parse_srdf(text, SRDF_FILE) {
        Ok(s) => {
            for m in [bundled("ur5"), bundled("panda")] {
                let (pairs, warnings) = s.disabled_pairs(m);
                assert!(pairs.len() <= s.disabled.len());
                for w in &warnings {
                    check_model_error(SRDF_FILE, w);
                }
            }
        }
        Err(e) => check_model_error(SRDF_FILE, &e),
    }
}

/// The `moveit_yaml` target: the text as a PlanningScene (the Panda's root link accepted
/// as the world frame) and as a MotionPlanRequest for the Panda.
pub fn moveit(data: &[u8]) {
    use armsim::planning::moveit::{parse_request, parse_scene};
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Err(e) = parse_scene(text, YAML_FILE, &["panda_link0"]) {
        check_model_error(YAML_FILE, &e);
    }
    match parse_request(text, YAML_FILE, bundled("panda")) {
        Ok((_, warnings)) => {
            for w in &warnings {
                check_model_error(YAML_FILE, w);
            }
        }
        Err(e) => check_model_error(YAML_FILE, &e),
    }
}
