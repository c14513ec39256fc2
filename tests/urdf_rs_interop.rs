//! armsim's `Model` and the ecosystem's `urdf_rs::Robot` carry the same robot both ways.
//!
//! Every URDF that urdf-rs reads (the bundled robots, and the example-robot-data files of
//! the test venv `target/pyvenv` when it exists) is loaded by armsim's own reader and
//! through `Model::from_urdf_rs`; a model is handed to urdf-rs with `Model::to_urdf_rs`
//! and back. "The same model" is checked on what the algorithms see: the coordinate names
//! and limits, the placement of every link by forward kinematics, and the inverse
//! dynamics and mass matrix at random states.

use armsim::dynamics::{crba, rnea};
use armsim::kinematics::{forward_kinematics, frame_placement};
use armsim::model::{LoadOptions, Model};
use armsim::Data;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn urdfs_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            urdfs_under(&p, out);
        } else if p.extension().is_some_and(|x| x == "urdf") {
            out.push(p);
        }
    }
}

/// The bundled URDFs, and the example-robot-data ones when the test venv has them.
fn urdf_files() -> (Vec<PathBuf>, usize) {
    let mut files = Vec::new();
    for e in std::fs::read_dir(root().join("robots")).unwrap().flatten() {
        if e.path().extension().is_some_and(|x| x == "urdf") {
            files.push(e.path());
        }
    }
    let bundled = files.len();
    let erd = root().join(
        "target/pyvenv/lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data/robots",
    );
    if erd.is_dir() {
        urdfs_under(&erd, &mut files);
    } else {
        println!("note: {} is absent: bundled robots only", erd.display());
    }
    files.sort();
    (files, bundled)
}

/// A small deterministic generator for the random states.
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn within(&mut self, lo: f64, hi: f64) -> f64 {
        let (lo, hi) = (lo.max(-3.0), hi.min(3.0));
        lo + (hi - lo) * self.unit()
    }
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a == b) || (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// Asserts that `b` is the robot `a` is: same coordinates and limits, every link of `a`
/// in `b` at the same place, the same `τ = RNEA(q, v, a)` and `M(q)` at random states.
/// `b` may have extra links (the massless frames a DH model needs in URDF).
fn assert_same_robot(a: &Model, b: &Model, what: &str) {
    assert_eq!(a.dof_names(), b.dof_names(), "{what}: coordinates");
    for (name, x, y) in [
        ("lower", &a.lower, &b.lower),
        ("upper", &a.upper, &b.upper),
        ("velocity", &a.velocity_limit, &b.velocity_limit),
        ("effort", &a.effort_limit, &b.effort_limit),
    ] {
        for (i, (p, q)) in x.iter().zip(y).enumerate() {
            assert!(close(*p, *q, 1e-12), "{what}: {name} limit {i}: {p} vs {q}");
        }
    }
    let (mut da, mut db) = (Data::new(a), Data::new(b));
    let mut rng = Lcg(7);
    for _ in 0..4 {
        let q: Vec<f64> = (0..a.nv)
            .map(|i| rng.within(a.lower[i], a.upper[i]))
            .collect();
        let v: Vec<f64> = (0..a.nv).map(|_| rng.within(-1.0, 1.0)).collect();
        let acc: Vec<f64> = (0..a.nv).map(|_| rng.within(-1.0, 1.0)).collect();
        forward_kinematics(a, &mut da, &q);
        forward_kinematics(b, &mut db, &q);
        for (la, link) in a.links.iter().enumerate() {
            let lb = b
                .link_id(&link.name)
                .unwrap_or_else(|| panic!("{what}: link '{}' is missing", link.name));
            let (pa, pb) = (frame_placement(a, &da, la), frame_placement(b, &db, lb));
            let dt = (pa.trans - pb.trans).norm();
            let dr = (pa.rot - pb.rot).norm();
            assert!(
                dt < 1e-12 && dr < 1e-12,
                "{what}: link '{}' moved by {dt:e} m, {dr:e}",
                link.name
            );
        }
        let ta = rnea(a, &mut da, &q, &v, &acc).to_vec();
        let tb = rnea(b, &mut db, &q, &v, &acc).to_vec();
        for (i, (x, y)) in ta.iter().zip(&tb).enumerate() {
            assert!(close(*x, *y, 1e-10), "{what}: tau[{i}] {x} vs {y}");
        }
        let ma = crba(a, &mut da, &q).clone();
        let mb = crba(b, &mut db, &q).clone();
        let scale = 1.0 + ma.amax();
        assert!(
            (ma - mb).amax() <= 1e-10 * scale,
            "{what}: mass matrices differ"
        );
    }
}

#[test]
fn model_from_urdf_rs_equals_model_from_text() {
    let (files, bundled) = urdf_files();
    let (mut compared, mut refused) = (0, Vec::new());
    for (k, f) in files.iter().enumerate() {
        let Ok((text_model, _)) = Model::load(f) else {
            continue; // not a robot armsim loads (none among these, but not this test's job)
        };
        let robot = match urdf_rs::read_file(f) {
            Ok(r) => r,
            Err(e) => {
                assert!(
                    k >= bundled,
                    "urdf-rs refuses the bundled {}: {e}",
                    f.display()
                );
                refused.push(format!("{}: {e}", f.display()));
                continue;
            }
        };
        let (rs_model, _) = Model::from_urdf_rs(&robot)
            .unwrap_or_else(|e| panic!("{}: from_urdf_rs: {e}", f.display()));
        assert_same_robot(&text_model, &rs_model, &f.display().to_string());
        compared += 1;
    }
    println!(
        "{compared} URDFs the same both ways; urdf-rs refuses {}:",
        refused.len()
    );
    for r in &refused {
        println!("  {r}");
    }
    assert!(
        compared >= bundled,
        "only {compared} of {} compared",
        files.len()
    );
}

#[test]
fn model_to_urdf_rs_and_back_is_the_same_model() {
    let (mut files, _) = urdf_files();
    for e in std::fs::read_dir(root().join("robots")).unwrap().flatten() {
        if e.path().extension().is_some_and(|x| x == "toml") {
            files.push(e.path()); // DH tables: URDF needs extra frames for them
        }
    }
    let mut n = 0;
    for f in &files {
        let Ok((model, _)) = Model::load(f) else {
            continue;
        };
        let robot = model.to_urdf_rs();
        let (back, _) = Model::from_urdf_rs(&robot)
            .unwrap_or_else(|e| panic!("{}: back from urdf_rs: {e}", f.display()));
        assert_same_robot(&model, &back, &format!("{} via urdf_rs", f.display()));
        n += 1;
    }
    assert!(n >= 15, "only {n} models went through urdf_rs and back");
}

#[test]
fn urdf_text_written_by_urdf_rs_loads_in_armsims_reader_as_the_same_model() {
    for name in [
        "ur5.urdf",
        "panda.urdf",
        "iiwa14.urdf",
        "puma560.toml",
        "scara.toml",
    ] {
        let (model, _) = Model::load(root().join("robots").join(name)).unwrap();
        let text = urdf_rs::write_to_string(&model.to_urdf_rs()).unwrap();
        let (back, _) = Model::load_str(&text, &format!("{name}.urdf"), &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{name}: urdf-rs's text: {e}\n{text}"));
        assert_same_robot(&model, &back, &format!("{name} as urdf-rs writes it"));
    }
}

#[test]
fn the_checker_sees_a_moved_joint() {
    let (model, _) = Model::load(root().join("robots/ur5.urdf")).unwrap();
    let mut robot = model.to_urdf_rs();
    let j = robot
        .joints
        .iter_mut()
        .find(|j| j.name == "elbow_joint")
        .unwrap();
    j.origin.xyz.0[2] += 1e-6;
    let (moved, _) = Model::from_urdf_rs(&robot).unwrap();
    let r = std::panic::catch_unwind(|| assert_same_robot(&model, &moved, "moved"));
    assert!(r.is_err(), "a joint moved by 1 µm went unnoticed");
}
