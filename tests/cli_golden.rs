//! Golden outputs of every model command on the bundled UR5 (and the planar 2R for the
//! workspace), recorded with the binary before the CLI was split into `src/cli/`: text
//! outputs must match byte for byte, JSON outputs too once the wall-clock fields
//! (`time_us`, `time_s`) are set aside. Regenerate only for an intended contract change.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

const Q: &str = "0.1,-1.2,1.4,-0.3,1.5,0.2";

fn golden(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/cli_golden")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn armsim(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_armsim"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run armsim");
    assert!(
        o.status.success(),
        "armsim {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).expect("utf-8")
}

/// `v` without the wall-clock fields.
fn steady(mut v: Value) -> Value {
    fn strip(v: &mut Value) {
        match v {
            Value::Object(m) => {
                m.remove("time_us");
                m.remove("time_s");
                m.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

fn same_json(name: &str, args: &[&str]) {
    let want: Value = serde_json::from_str(&golden(name)).unwrap();
    let got: Value = serde_json::from_str(&armsim(args)).unwrap();
    assert_eq!(steady(got), steady(want), "{name}: armsim {args:?}");
}

fn same_text(name: &str, args: &[&str]) {
    assert_eq!(armsim(args), golden(name), "{name}: armsim {args:?}");
}

#[test]
fn info_outputs_are_unchanged() {
    same_json("info.json", &["info", "robots/ur5.urdf", "--json"]);
    same_text("info.txt", &["info", "robots/ur5.urdf"]);
}

#[test]
fn fk_outputs_are_unchanged() {
    same_json("fk.json", &["fk", "robots/ur5.urdf", "--q", Q, "--json"]);
    same_text("fk.txt", &["fk", "robots/ur5.urdf", "--q", Q]);
}

#[test]
fn jacobian_outputs_are_unchanged() {
    let qd = "0.1,0.2,0.3,0.4,0.5,0.6";
    same_json(
        "jacobian.json",
        &[
            "jacobian",
            "robots/ur5.urdf",
            "--q",
            Q,
            "--frame",
            "tool0",
            "--expressed",
            "world-aligned",
            "--qd",
            qd,
            "--json",
        ],
    );
    same_text(
        "jacobian.txt",
        &["jacobian", "robots/ur5.urdf", "--q", Q, "--frame", "tool0"],
    );
}

#[test]
fn dynamics_outputs_are_unchanged_energies_included() {
    let v = "0.1,0.2,0.3,0.4,0.5,0.6";
    same_json(
        "dynamics.json",
        &[
            "dynamics",
            "robots/ur5.urdf",
            "--q",
            Q,
            "--v",
            v,
            "--a",
            "1,0,-1,0.5,0,0.2",
            "--tau",
            "1,2,3,4,5,6",
            "--payload",
            "tool0,1.5,0,0,0.1",
            "--json",
        ],
    );
    same_text(
        "dynamics.txt",
        &[
            "dynamics",
            "robots/ur5.urdf",
            "--q",
            Q,
            "--v",
            v,
            "--rotor",
            "--friction",
        ],
    );
}

#[test]
fn ik_outputs_are_unchanged() {
    let target = ["--link", "tool0", "--target", "0.4,0.1,0.3,0,1,0,0"];
    let mut args = vec!["ik", "robots/ur5.urdf"];
    args.extend(target);
    args.push("--json");
    same_json("ik.json", &args);
    args.push("--analytic");
    same_json("ik_analytic.json", &args);
}

#[test]
fn chain_and_workspace_outputs_are_unchanged() {
    same_text("chain3.urdf", &["chain", "3"]);
    same_json(
        "workspace.json",
        &[
            "workspace",
            "robots/planar_2r.toml",
            "--samples",
            "4096",
            "--replicates",
            "4",
            "--json",
        ],
    );
}

#[test]
fn the_golden_comparison_sees_a_changed_number() {
    let want: Value = serde_json::from_str(&golden("dynamics.json")).unwrap();
    let mut changed = want.clone();
    changed["kinetic_energy"] = serde_json::json!(want["kinetic_energy"].as_f64().unwrap() + 1e-12);
    assert_ne!(steady(changed), steady(want));
}
