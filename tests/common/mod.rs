//! Helpers shared by the integration tests.
#![allow(dead_code)]

#[cfg(feature = "rerun")]
pub mod rrd;

use armsim::core::spatial::{Mat3, Se3, Vec3};
use armsim::model::Model;
use std::path::PathBuf;

/// The crate's root folder (where the tests run `armsim`).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the `armsim` binary with `args` from the crate root.
pub fn armsim(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_armsim"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("run armsim")
}

/// `armsim ARGS` from the crate root, its standard output parsed as JSON; fails the test
/// on a non-zero exit (with the program's standard error) or output that is not JSON.
pub fn cli_json(args: &[&str]) -> serde_json::Value {
    let o = armsim(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{args:?}: not JSON: {e}"))
}

/// `armsim run REL --json` from the crate root, parsed; fails the test on a non-zero exit
/// with the program's standard error.
pub fn run_json(rel: &str) -> serde_json::Value {
    cli_json(&["run", rel, "--json"])
}

/// What [`armsim::scenarios::check`] (parsing and validation, no run) must say of a broken
/// scenario that `armsim run` refuses.
pub enum CheckSays<'a> {
    /// It refuses the file at the same key.
    SameKey,
    /// It refuses the file.
    Refuses,
    /// It refuses the file unless the error is one the run finds (these keys).
    RefusesUnlessRunKey(&'a [&'a str]),
    /// Nothing asked: the errors are found by the run.
    NotAsked,
}

/// Checks the broken scenarios `tests/broken_scenarios/<prefix>*.toml`: each entry
/// `(file, line, key, message part)` fails `armsim run` with that location and message,
/// `scenario::check` says what `check` asks, and every file of the prefix is listed.
pub fn assert_broken_scenarios(
    prefix: &str,
    broken: &[(&str, usize, &str, &str)],
    check: CheckSays,
) {
    let dir = root().join("tests/broken_scenarios");
    for (file, line, key, msg) in broken {
        let path = dir.join(file);
        let e = armsim::scenarios::run_file(&path)
            .err()
            .unwrap_or_else(|| panic!("{file}: expected an error"));
        assert_eq!(e.line, Some(*line), "{file}: {e}");
        assert_eq!(e.key, *key, "{file}: {e}");
        assert!(e.message.contains(msg), "{file}: {e}");
        let text = std::fs::read_to_string(&path).unwrap();
        let checked = armsim::scenarios::check(file, &text).err().map(|e| e.key);
        match check {
            CheckSays::SameKey => assert_eq!(checked, Some(key.to_string()), "{file}: check"),
            CheckSays::Refuses => assert!(checked.is_some(), "{file}: check passes"),
            CheckSays::RefusesUnlessRunKey(keys) => assert!(
                checked.is_some() || keys.contains(key),
                "{file}: check passes"
            ),
            CheckSays::NotAsked => {}
        }
    }
    let listed: Vec<&str> = broken.iter().map(|b| b.0).collect();
    assert_lists_every_broken_scenario(prefix, &listed);
}

/// Asserts that `listed` names exactly the files `tests/broken_scenarios/<prefix>*.toml`
/// (in any order), so that a broken scenario added there cannot go untested.
pub fn assert_lists_every_broken_scenario(prefix: &str, listed: &[&str]) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/broken_scenarios");
    let mut listed: Vec<&str> = listed.to_vec();
    listed.sort_unstable();
    let mut present: Vec<String> = std::fs::read_dir(&dir)
        .expect("tests/broken_scenarios exists")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(prefix) && n.ends_with(".toml"))
        .collect();
    present.sort();
    assert_eq!(present, listed, "every {prefix}*.toml is listed");
}

/// Every model file in `robots/`, sorted.
pub fn robot_files() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("robots");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("robots/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            matches!(
                p.extension().and_then(|e| e.to_str()),
                Some("urdf") | Some("toml")
            )
        })
        .collect();
    v.sort();
    v
}

/// Loads a file under the crate root, panicking with the loader's message.
pub fn load(rel: &str) -> Model {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel);
    match Model::load(&p) {
        Ok((m, _)) => m,
        Err(e) => panic!("{e}"),
    }
}

/// Angular velocity from a rotation derivative: `[ω]× = Ṙ Rᵀ`.
pub fn omega(r_dot: &Mat3, r: &Mat3) -> Vec3 {
    let w = r_dot * r.transpose();
    Vec3::new(
        0.5 * (w[(2, 1)] - w[(1, 2)]),
        0.5 * (w[(0, 2)] - w[(2, 0)]),
        0.5 * (w[(1, 0)] - w[(0, 1)]),
    )
}

/// Largest absolute difference between two poses (rotation entries and translation).
pub fn pose_diff(a: &Se3, b: &Se3) -> f64 {
    (a.rot - b.rot)
        .abs()
        .max()
        .max((a.trans - b.trans).abs().max())
}

/// `n` values uniform in `(-s, s)`.
pub fn rand_vec(rng: &mut rand::rngs::SmallRng, n: usize, s: f64) -> Vec<f64> {
    use rand::Rng;
    (0..n).map(|_| rng.random_range(-s..s)).collect()
}

/// Every robot in `robots/`, the mimic gripper and a generated `chain_len`-joint chain.
pub fn test_models(chain_len: usize) -> Vec<(String, Model)> {
    let mut v: Vec<(String, Model)> = robot_files()
        .into_iter()
        .map(|f| (f.display().to_string(), Model::load(&f).unwrap().0))
        .collect();
    v.push((
        "mimic_gripper".into(),
        load("tests/data/mimic_gripper.urdf"),
    ));
    v.push((
        format!("chain_{chain_len}"),
        Model::build(armsim::model::chain::chain_spec(chain_len))
            .unwrap()
            .0,
    ));
    v
}

/// One continuous joint about z carrying a 1 kg body whose inertia about every axis
/// through its centre (on the axis) is `jl`: `M = jl`.
pub fn single_joint(jl: f64) -> Model {
    use armsim::core::spatial::Inertia;
    use armsim::model::{JointSpec, JointType, LinkSpec, ModelSpec};
    let base = LinkSpec::new("base");
    let mut arm = LinkSpec::new("arm");
    arm.inertial = Inertia::new(
        1.0,
        Vec3::zeros(),
        Mat3::from_diagonal(&Vec3::new(jl, jl, jl)),
    );
    let j = JointSpec::new("joint", JointType::Continuous, "base", "arm");
    Model::build(ModelSpec {
        name: "one".into(),
        source: "<test>".into(),
        root_offset: Se3::identity(),
        links: vec![base, arm],
        joints: vec![j],
        urdf_text: None,
        gravity: None,
        warnings: Vec::new(),
    })
    .unwrap()
    .0
}

/// The textbook closed form of `robots/planar_2r.toml` (two uniform 0.5 m links of 2 kg
/// and 1 kg, gravity 9.81 along −z, docs/reference_data.md §S1): the mass matrix
/// `[m11, m12, m22]` and the inverse dynamics `τ = M q̈ + h(q, q̇) + g(q)`.
pub fn planar_2r_closed_form(q: &[f64], qd: &[f64], qdd: &[f64]) -> ([f64; 3], [f64; 2]) {
    let (l, m1, m2, g) = (0.5f64, 2.0f64, 1.0f64, 9.81f64);
    let (c2, s2) = (q[1].cos(), q[1].sin());
    let m11 = m1 * l * l / 3.0 + m2 * l * l * (4.0 / 3.0 + c2);
    let m12 = m2 * l * l * (1.0 / 3.0 + c2 / 2.0);
    let m22 = m2 * l * l / 3.0;
    let h1 = -m2 * l * l * s2 * (qd[0] * qd[1] + qd[1] * qd[1] / 2.0);
    let h2 = m2 * l * l * s2 * qd[0] * qd[0] / 2.0;
    let g1 = (m1 / 2.0 + m2) * g * l * q[0].cos() + m2 / 2.0 * g * l * (q[0] + q[1]).cos();
    let g2 = m2 / 2.0 * g * l * (q[0] + q[1]).cos();
    let tau = [
        m11 * qdd[0] + m12 * qdd[1] + h1 + g1,
        m12 * qdd[0] + m22 * qdd[1] + h2 + g2,
    ];
    ([m11, m12, m22], tau)
}

/// Every effect that has a derivative, on model `m`: tilted gravity, friction with a
/// Stribeck bump (smoothed over 0.05 rad/s so that differences of step 1e-6 resolve it),
/// rotors, a payload on the last body, and world-fixed wrenches on the last body and on
/// a middle one.
pub fn scene_effects(m: &Model, seed: u64) -> armsim::dynamics::Effects {
    use armsim::core::spatial::Inertia;
    use armsim::dynamics::{Effects, ExternalWrench, Friction, Payload, Rotor};
    use rand::{Rng, SeedableRng};
    let n = m.nv;
    let mut rng = rand::rngs::SmallRng::seed_from_u64(seed);
    let mut pick =
        |lo: f64, hi: f64| -> Vec<f64> { (0..n).map(|_| rng.random_range(lo..hi)).collect() };
    let coulomb = pick(0.1, 0.6);
    let stiction = coulomb.iter().map(|c| c + 0.3).collect();
    let on_body = |b: usize| m.links.iter().position(|l| l.body == b).unwrap();
    let (tool, middle) = (on_body(m.nbodies() - 1), on_body(m.nbodies() / 2));
    let payload = Inertia::new(
        1.5,
        Vec3::new(0.02, -0.01, 0.06),
        Mat3::from_diagonal(&Vec3::new(0.004, 0.006, 0.003)),
    );
    Effects {
        gravity: Some(Vec3::new(0.3, -0.2, -9.81)),
        friction: Some(Friction {
            viscous: pick(0.1, 0.8),
            coulomb,
            stiction,
            stribeck_velocity: pick(0.3, 1.0),
            smoothing: 0.05,
        }),
        rotor: Some(Rotor {
            inertia: pick(1e-5, 5e-5),
            gear_ratio: pick(50.0, 120.0),
            efficiency: vec![0.9; n],
        }),
        elasticity: None,
        payload: Some(Payload::new(m, tool, payload).unwrap()),
        external: vec![
            ExternalWrench {
                link: tool,
                force: Vec3::new(3.0, -2.0, 5.0),
                moment: Vec3::new(0.2, 0.1, -0.3),
            },
            ExternalWrench {
                link: middle,
                force: Vec3::new(-1.0, 4.0, 2.0),
                moment: Vec3::new(-0.4, 0.3, 0.5),
            },
        ],
    }
}

/// Central differences of `g` at `x`, column by column.
pub fn central_differences(
    x: &[f64],
    h: f64,
    mut g: impl FnMut(&[f64]) -> Vec<f64>,
) -> nalgebra::DMatrix<f64> {
    let mut out = nalgebra::DMatrix::zeros(g(x).len(), x.len());
    for k in 0..x.len() {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[k] += h;
        xm[k] -= h;
        let (gp, gm) = (g(&xp), g(&xm));
        for r in 0..gp.len() {
            out[(r, k)] = (gp[r] - gm[r]) / (2.0 * h);
        }
    }
    out
}

/// `max |a − b| ≤ tol · max(1, max |b|)`.
pub fn assert_matrix_close(
    what: &str,
    a: &nalgebra::DMatrix<f64>,
    b: &nalgebra::DMatrix<f64>,
    tol: f64,
) {
    assert_eq!(a.shape(), b.shape(), "{what}: shape");
    let scale = b.abs().max().max(1.0);
    let err = (a - b).abs().max();
    assert!(
        err <= tol * scale,
        "{what}: error {err:e} > {tol:e} × {scale:e}"
    );
}
