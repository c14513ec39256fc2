//! The CLI's JSON contracts (other tools script against them), its text output, and its
//! behaviour on bad or extreme input: non-zero exit with a message, never a panic.

mod common;
use common::{armsim, cli_json as json};
use std::process::Command;

fn fails_with(args: &[&str], needle: &str) {
    let o = armsim(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} succeeded");
    assert!(
        err.contains(needle),
        "{args:?}: stderr lacks '{needle}': {err}"
    );
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
}

const UR5_Q: &str = "0.1,-1.2,1.3,-0.4,0.5,0.6";

#[test]
fn info_json_lists_joints_in_coordinate_order_with_limits_and_mimic() {
    let v = json(&["info", "robots/panda.urdf", "--json"]);
    assert_eq!(v["name"], "panda");
    assert_eq!(v["dof"], 8);
    let joints = v["joints"].as_array().unwrap();
    let coords: Vec<&str> = v["coordinates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect();
    assert_eq!(coords.len(), 8);
    for key in [
        "name", "type", "parent", "child", "lower", "upper", "velocity", "effort",
    ] {
        assert!(
            joints.iter().all(|j| j.get(key).is_some()),
            "joint without '{key}'"
        );
    }
    let j1 = &joints[0];
    assert_eq!(
        (j1["name"].as_str(), j1["type"].as_str()),
        (Some("panda_joint1"), Some("revolute"))
    );
    assert!((j1["upper"].as_f64().unwrap() - 2.8973).abs() < 1e-9);
    let f2 = joints
        .iter()
        .find(|j| j["name"] == "panda_finger_joint2")
        .unwrap();
    assert_eq!(f2["mimic"]["joint"], "panda_finger_joint1");
    assert_eq!(f2["mimic"]["multiplier"], 1.0);
    // Movable non-mimic joints, in the listed order, are the coordinates.
    let indep: Vec<&str> = joints
        .iter()
        .filter(|j| j.get("mimic").is_none())
        .map(|j| j["name"].as_str().unwrap())
        .collect();
    assert_eq!(indep, coords);
    // --ignore-mimic makes the finger a coordinate (Pinocchio's default).
    assert_eq!(
        json(&["info", "robots/panda.urdf", "--json", "--ignore-mimic"])["dof"],
        9
    );
}

/// A frame of `armsim fk --json`: its `translation` and its row-major `rotation`.
fn frame_pose(frame: &serde_json::Value) -> (Vec<f64>, Vec<Vec<f64>>) {
    let numbers = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let rows = frame["rotation"].as_array().unwrap();
    (
        numbers(&frame["translation"]),
        rows.iter().map(numbers).collect(),
    )
}

#[test]
fn fk_json_gives_world_translation_and_row_major_rotation() {
    let v = json(&["fk", "robots/ur5.urdf", "--q", UR5_Q, "--json"]);
    assert_eq!(v["joints"].as_array().unwrap().len(), 6);
    assert_eq!(v["joints"][0], "shoulder_pan_joint");
    let (t, r) = frame_pose(&v["frames"]["tool0"]);
    // Against the library.
    let (m, _) =
        armsim::model::Model::load(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf"))
            .unwrap();
    let mut d = armsim::model::data::Data::new(&m);
    let q: Vec<f64> = UR5_Q.split(',').map(|x| x.parse().unwrap()).collect();
    armsim::kinematics::forward_kinematics(&m, &mut d, &q);
    let p = armsim::kinematics::frame_placement(&m, &d, m.link_id("tool0").unwrap());
    for i in 0..3 {
        assert!((t[i] - p.trans[i]).abs() < 1e-15);
        for (j, rij) in r[i].iter().enumerate() {
            assert!((rij - p.rot[(i, j)]).abs() < 1e-15, "row-major rotation");
        }
    }
    // Negative numbers parse, text output is the default.
    let o = armsim(&["fk", "robots/ur5.urdf", "--q", "-0.1,-1,-1,-1,-1,-1"]);
    assert!(o.status.success() && String::from_utf8_lossy(&o.stdout).contains("tool0"));
}

#[test]
fn jacobian_json_has_six_rows_per_expression_and_a_derivative_with_qd() {
    for ex in ["world", "local", "world-aligned"] {
        let v = json(&[
            "jacobian",
            "robots/ur5.urdf",
            "--q",
            UR5_Q,
            "--frame",
            "tool0",
            "--expressed",
            ex,
            "--json",
        ]);
        assert_eq!(v["expressed"], ex);
        assert_eq!(v["frame"], "tool0");
        assert_eq!(v["joints"].as_array().unwrap().len(), 6);
        let j = v["jacobian"].as_array().unwrap();
        assert_eq!(j.len(), 6);
        assert!(j.iter().all(|row| row.as_array().unwrap().len() == 6));
    }
    let v = json(&[
        "jacobian",
        "robots/ur5.urdf",
        "--q",
        UR5_Q,
        "--frame",
        "tool0",
        "--qd",
        "1,0,0,0,0,0",
        "--json",
    ]);
    assert_eq!(v["jacobian_dot"].as_array().unwrap().len(), 6);
    assert!(v["manipulability"].as_f64().unwrap() > 0.0);
}

#[test]
fn bench_json_reports_ns_per_call_for_every_algorithm() {
    for algo in [
        "fk",
        "jacobians",
        "rnea",
        "rnea-batch",
        "crba",
        "crba-batch",
        "aba",
        "aba-batch",
        "lagrange",
    ] {
        let v = json(&[
            "bench",
            "robots/ur5.urdf",
            "--algo",
            algo,
            "--iters",
            "2200",
            "--json",
        ]);
        assert_eq!(v["algo"], algo);
        assert_eq!(v["model"], "ur5");
        assert_eq!(v["dof"], 6);
        let ns = v["ns_per_call"].as_f64().unwrap();
        assert!(ns > 1.0 && ns < 1e7, "{algo}: {ns}");
    }
    for algo in ["aba", "aba-batch"] {
        fails_with(
            &["bench", "robots/panda.urdf", "--algo", algo],
            "--ignore-mimic",
        );
    }
}

#[test]
fn dynamics_json_contract_and_forward_dynamics() {
    let v = json(&[
        "dynamics",
        "robots/ur5.urdf",
        "--q",
        UR5_Q,
        "--v",
        "0.1,0.2,0.3,0.4,0.5,0.6",
        "--a",
        "1,1,1,1,1,1",
        "--tau",
        "10,20,5,1,1,1",
        "--json",
    ]);
    for key in [
        "joints",
        "tau",
        "mass_matrix",
        "bias",
        "gravity",
        "kinetic_energy",
        "potential_energy",
        "qdd",
        "effects",
    ] {
        assert!(v.get(key).is_some(), "missing '{key}'");
    }
    assert_eq!(v["effects"], serde_json::json!(["gravity"]));
    assert_eq!(v["mass_matrix"].as_array().unwrap().len(), 6);
    // Library cross-check of tau.
    let (mut m, _) =
        armsim::model::Model::load(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf"))
            .unwrap();
    m.gravity = armsim::core::spatial::Vec3::new(0.0, 0.0, -9.81);
    let mut d = armsim::model::data::Data::new(&m);
    let q: Vec<f64> = UR5_Q.split(',').map(|x| x.parse().unwrap()).collect();
    let tau =
        armsim::dynamics::rnea(&m, &mut d, &q, &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6], &[1.0; 6]).to_vec();
    for k in 0..6 {
        assert!((v["tau"][k].as_f64().unwrap() - tau[k]).abs() < 1e-12);
    }
    // The Lagrange references give the same torques.
    for method in ["lagrange-trace", "lagrange-energy"] {
        let w = json(&[
            "dynamics",
            "robots/ur5.urdf",
            "--q",
            UR5_Q,
            "--v",
            "0.1,0.2,0.3,0.4,0.5,0.6",
            "--a",
            "1,1,1,1,1,1",
            "--method",
            method,
            "--json",
        ]);
        for k in 0..6 {
            assert!((w["tau"][k].as_f64().unwrap() - tau[k]).abs() < 1e-9 * tau[k].abs().max(1.0));
        }
    }
    // Effects are named in the output.
    let w = json(&[
        "dynamics",
        "robots/puma560.toml",
        "--q",
        "0,0,0,0,0,0",
        "--rotor",
        "--friction",
        "--payload",
        "link6,2.0",
        "--json",
    ]);
    assert_eq!(
        w["effects"],
        serde_json::json!(["gravity", "friction", "rotor_inertia", "payload"])
    );
}

#[test]
fn dynamics_stays_finite_on_extreme_inputs() {
    for (q, v) in [
        ("1e6,-1e6,1e6,-1e6,1e6,-1e6", "0,0,0,0,0,0"),
        ("-1e6,1e6,3.2e5,0,-7e5,1e6", "1e3,-1e3,1e3,-1e3,1e3,-1e3"),
    ] {
        let out = json(&[
            "dynamics",
            "robots/ur5.urdf",
            "--q",
            q,
            "--v",
            v,
            "--a",
            v,
            "--tau",
            "1,1,1,1,1,1",
            "--json",
        ]);
        for key in ["tau", "bias", "gravity", "qdd"] {
            let vals = out[key].as_array().unwrap();
            assert!(
                vals.iter().all(|x| x.as_f64().is_some_and(f64::is_finite)),
                "{key} not finite: {vals:?}"
            );
        }
        assert!(out["kinetic_energy"].as_f64().unwrap().is_finite());
    }
}

#[test]
fn bad_input_exits_non_zero_with_a_message() {
    fails_with(
        &["fk", "robots/ur5.urdf", "--q", "1,2"],
        "expected 6 values",
    );
    fails_with(
        &["fk", "robots/ur5.urdf", "--q", "1,2,3,4,5,nan"],
        "not a finite number",
    );
    fails_with(
        &["fk", "robots/ur5.urdf", "--q", "1,2,3,4,5,x"],
        "'x' is not a number",
    );
    fails_with(
        &[
            "jacobian",
            "robots/ur5.urdf",
            "--q",
            UR5_Q,
            "--frame",
            "nope",
        ],
        "link 'nope' does not exist",
    );
    fails_with(
        &[
            "dynamics",
            "robots/scara.toml",
            "--q",
            "0,0,0.1,0",
            "--tau",
            "1,1,1,1",
        ],
        "forward dynamics",
    );
    fails_with(
        &[
            "dynamics",
            "robots/ur5.urdf",
            "--q",
            UR5_Q,
            "--gravity",
            "0,0",
        ],
        "--gravity",
    );
    fails_with(
        &[
            "dynamics",
            "robots/ur5.urdf",
            "--q",
            UR5_Q,
            "--payload",
            "tool0,-1",
        ],
        "--payload",
    );
    fails_with(
        &["info", "robots/does_not_exist.urdf"],
        "robots/does_not_exist.urdf",
    );
    fails_with(&["info", "README.md"], "unknown model format");
    fails_with(&["chain", "0"], "chain");
}

#[test]
fn a_closed_output_pipe_is_not_a_panic() {
    // `armsim info big.urdf | head -1`: the reader goes away before the output is written.
    let dir = std::env::temp_dir().join(format!("armsim-pipe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("chain.urdf");
    let o = armsim(&["chain", "3000", "--out", file.to_str().unwrap()]);
    assert!(o.status.success());
    let mut child = Command::new(env!("CARGO_BIN_EXE_armsim"))
        .args(["info", file.to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert!(out.status.success(), "exit {:?}: {err}", out.status);
    std::fs::remove_dir_all(&dir).ok();
}

/// A reachable UR5 tool pose as `x,y,z,qw,qx,qy,qz`: FK of [`UR5_Q`] by the CLI.
fn ur5_tool_target() -> String {
    // A reachable UR5 target: FK of a known configuration.
    let fk = json(&["fk", "robots/ur5.urdf", "--q", UR5_Q, "--json"]);
    let (p, r) = frame_pose(&fk["frames"]["tool0"]);
    let m = nalgebra::Matrix3::from_fn(|i, j| r[i][j]);
    let q = nalgebra::UnitQuaternion::from_matrix(&m);
    format!("{},{},{},{},{},{},{}", p[0], p[1], p[2], q.w, q.i, q.j, q.k)
}

#[test]
fn ik_json_contract_numeric_and_analytic() {
    let target = ur5_tool_target();
    for extra in [&[][..], &["--analytic"][..]] {
        let mut args = vec![
            "ik",
            "robots/ur5.urdf",
            "--link",
            "tool0",
            "--target",
            target.as_str(),
            "--json",
        ];
        args.extend_from_slice(extra);
        let v = json(&args);
        assert_eq!(v["joints"].as_array().unwrap().len(), 6);
        let res = &v["results"][0];
        for key in [
            "q",
            "status",
            "position_error",
            "rotation_error",
            "iterations",
            "time_us",
        ] {
            assert!(res.get(key).is_some(), "{extra:?}: missing '{key}'");
        }
        assert_eq!(res["status"], "converged");
        assert!(res["position_error"].as_f64().unwrap() < 1e-6);
        if extra.is_empty() {
            continue;
        }
        let sols = res["solutions"].as_array().unwrap();
        assert!(
            sols.len() >= 2 && sols.len() <= 8 && sols.len().is_multiple_of(2),
            "{} branches",
            sols.len()
        );
        // The generating configuration is among the branches.
        let q0: Vec<f64> = UR5_Q.split(',').map(|x| x.parse().unwrap()).collect();
        assert!(sols.iter().any(
            |s| s["q"]
                .as_array()
                .unwrap()
                .iter()
                .zip(&q0)
                .all(|(a, b)| (a.as_f64().unwrap() - b).abs() < 1e-8)
        ));
    }
}

#[test]
fn ik_targets_csv_gives_one_result_per_row_in_order() {
    let target = ur5_tool_target();
    // A CSV of targets: one result per row, in order; a header row is skipped.
    let dir = std::env::temp_dir().join(format!("armsim-ik-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("targets.csv");
    std::fs::write(
        &csv,
        format!("x,y,z,qw,qx,qy,qz\n{target}\n3,0,0,1,0,0,0\n"),
    )
    .unwrap();
    let v = json(&[
        "ik",
        "robots/ur5.urdf",
        "--link",
        "tool0",
        "--targets",
        csv.to_str().unwrap(),
        "--json",
    ]);
    let res = v["results"].as_array().unwrap();
    assert_eq!(res.len(), 2);
    assert_eq!(res[0]["status"], "converged");
    assert_eq!(res[1]["status"], "unreachable");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn ik_bad_targets_and_unsupported_analytic_arms_are_refused() {
    fails_with(
        &[
            "ik",
            "robots/ur5.urdf",
            "--link",
            "tool0",
            "--target",
            "1,2,3",
        ],
        "expected 7 values",
    );
    fails_with(
        &[
            "ik",
            "robots/ur5.urdf",
            "--link",
            "tool0",
            "--target",
            "1,2,3,0,0,0,0",
        ],
        "quaternion is zero",
    );
    fails_with(
        &[
            "ik",
            "robots/iiwa14.urdf",
            "--link",
            "iiwa_link_ee",
            "--target",
            "0.5,0,0.5,1,0,0,0",
            "--analytic",
        ],
        "does not support",
    );
}

#[test]
fn workspace_json_contract() {
    let v = json(&[
        "workspace",
        "robots/planar_2r.toml",
        "--samples",
        "200000",
        "--json",
    ]);
    for key in [
        "samples",
        "volume_m3",
        "volume_stderr",
        "voxel",
        "bbox",
        "time_s",
        "area_m2",
        "area_interval_m2",
        "volume_interval_m3",
        "interval_kind",
        "samples_needed",
        "joint_names",
    ] {
        assert!(v.get(key).is_some(), "missing '{key}'");
    }
    // Covered: a two-sided interval around the area that holds π.
    assert_eq!(v["interval_kind"], "interval");
    let (lo, hi) = (
        v["area_interval_m2"][0].as_f64().unwrap(),
        v["area_interval_m2"][1].as_f64().unwrap(),
    );
    assert!(
        lo <= std::f64::consts::PI && std::f64::consts::PI <= hi,
        "[{lo}, {hi}]"
    );
    // Uniform rods of 0.5 m: a disc of radius 1 m; raw voxel estimates overshoot by the
    // documented voxel bias, the corrected estimate is within a few standard errors.
    let area = v["area_m2"].as_f64().unwrap();
    assert!((area - std::f64::consts::PI).abs() < 0.15, "{area}");
    assert_eq!(v["voxel"], 0.02);
    fails_with(&["workspace", "robots/ur5.urdf", "--voxel", "0"], "--voxel");
    fails_with(
        &["workspace", "robots/ur5.urdf", "--method", "grid"],
        "--method",
    );
    fails_with(
        &["workspace", "robots/ur5.urdf", "--target-rel-error", "0"],
        "--target-rel-error",
    );
}

/// Too few samples: a lower bound (null upper end), the samples needed, and the text
/// output says "lower bound". Adaptive mode doubles until the interval is narrow enough.
#[test]
fn workspace_lower_bound_and_adaptive_mode() {
    let rrp = "robots/textbook_spherical_rrp.toml";
    let v = json(&[
        "workspace",
        rrp,
        "--samples",
        "4096",
        "--voxel",
        "0.1",
        "--json",
    ]);
    assert_eq!(v["interval_kind"], "lower_bound");
    assert!(v["volume_interval_m3"][1].is_null());
    assert!(v["volume_interval_m3"][0].as_f64().unwrap() <= 9.83);
    assert!(v["samples_needed"].as_u64().unwrap() > 4096);
    let out = armsim(&["workspace", rrp, "--samples", "4096", "--voxel", "0.1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("lower bound"), "{text}");
    let v = json(&[
        "workspace",
        "robots/planar_2r.toml",
        "--samples",
        "4096",
        "--voxel",
        "0.05",
        "--target-rel-error",
        "0.05",
        "--json",
    ]);
    assert_eq!(v["target_reached"], true);
    assert_eq!(v["interval_kind"], "interval");
    let area = v["area_m2"].as_f64().unwrap();
    let (lo, hi) = (
        v["area_interval_m2"][0].as_f64().unwrap(),
        v["area_interval_m2"][1].as_f64().unwrap(),
    );
    assert!(0.5 * (hi - lo) <= 0.05 * area, "[{lo}, {hi}] around {area}");
    assert!(lo <= std::f64::consts::PI && std::f64::consts::PI <= hi);
    assert!(v["samples"].as_u64().unwrap() > 4096);
}

/// Issue 28: the samples and calls a command will make are budgeted before the work
/// starts (`--force` overrides the sample and call budgets), and the refusal names the
/// option and the budget.
#[test]
fn work_budgets_refuse_before_the_work_starts() {
    let ur5 = "robots/ur5.urdf";
    let t0 = std::time::Instant::now();
    fails_with(
        &[
            "workspace",
            ur5,
            "--samples",
            "1000000000000000",
            "--method",
            "random",
        ],
        "--samples: 1000000000000000 samples would be drawn, more than the budget of 2^32",
    );
    fails_with(
        &[
            "workspace",
            ur5,
            "--samples",
            "1000",
            "--replicates",
            "1000000000",
        ],
        "--replicates: 1000000000 replicates is more than the limit of 1024",
    );
    fails_with(
        &[
            "workspace",
            ur5,
            "--target-rel-error",
            "1e-12",
            "--max-samples",
            "18446744073709551615",
        ],
        "--max-samples: 18446744073709551615 samples would be drawn",
    );
    fails_with(
        &[
            "bench",
            ur5,
            "--algo",
            "rnea",
            "--iters",
            "1000000000000000",
        ],
        "--iters: 1000000000000000 calls is more than the budget of 10^9",
    );
    assert!(t0.elapsed().as_secs() < 20, "the refusals did work first");
}

/// Issue 28: a result that overflows is an error naming the quantity, the joint and the
/// inputs, never NaN printed with exit 0; large finite results print in `e` notation.
#[test]
fn non_finite_dynamics_results_are_errors() {
    let ur5 = "robots/ur5.urdf";
    fails_with(
        &["dynamics", ur5, "--q", "0,0,0,0,0,0", "--v", "1e200,0,0,0,0,0"],
        "the tau of joint 'shoulder_pan_joint' is not finite (NaN): the inputs overflow floating-point arithmetic (largest |q| 0, |v| 1e200",
    );
    fails_with(
        &[
            "dynamics",
            ur5,
            "--q",
            "0,0,0,0,0,0",
            "--tau",
            "0,0,0,1e308,0,0",
        ],
        "is not finite",
    );
    let o = armsim(&[
        "dynamics",
        ur5,
        "--q",
        "0,0,0,0,0,0",
        "--tau",
        "1e308,0,0,0,0,0",
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(text.contains("2.974033e307"), "{text}");
    assert!(text.lines().all(|l| l.len() < 200), "{text}");
}

/// Issue 28: messages give the right reason. A quaternion whose squared norm overflows is
/// scaled first (it is a rotation, not "zero"); a coordinate that moves no mass is named
/// by its joint, not only by a pivot index.
#[test]
fn messages_name_the_joint_and_the_real_reason() {
    let huge = json(&[
        "ik",
        "robots/ur5.urdf",
        "--link",
        "tool0",
        "--target",
        "0.3,0.2,0.4,1e200,1e200,0,0",
        "--json",
    ]);
    let unit = json(&[
        "ik",
        "robots/ur5.urdf",
        "--link",
        "tool0",
        "--target",
        "0.3,0.2,0.4,1,1,0,0",
        "--json",
    ]);
    let (h, u) = (&huge["results"][0], &unit["results"][0]);
    assert_eq!(h["status"], "converged", "{huge}");
    assert_eq!(h["q"], u["q"], "{huge}");
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/planar_2r.toml"),
    )
    .unwrap();
    // The second link without mass or inertia.
    let k = text.rfind("mass = 1.0").unwrap();
    let massless = format!(
        "{}mass = 0.0{}",
        &text[..k],
        &text[k + "mass = 1.0".len()..]
    );
    let k = massless.rfind("inertia = [").unwrap();
    let end = k + massless[k..].find('\n').unwrap();
    let massless = format!(
        "{}inertia = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]{}",
        &massless[..k],
        &massless[end..]
    );
    let dir = std::env::temp_dir().join(format!("armsim_massless_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("massless.toml");
    std::fs::write(&p, massless).unwrap();
    fails_with(
        &[
            "dynamics",
            p.to_str().unwrap(),
            "--q",
            "0,0",
            "--tau",
            "1,1",
        ],
        "not positive definite at coordinate 1 (joint 'joint2')",
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A result that is not finite is an error naming the file, never a printed NaN with exit
/// 0: a two-plane balance whose mass lies 1e308 m along the shaft gives an infinite
/// moment. Nothing goes to standard output.
#[test]
fn a_non_finite_result_is_an_error_not_a_printed_nan() {
    let dir = std::env::temp_dir().join(format!("armsim_nonfinite_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string("scenarios/rotor_two_plane_balancing.toml").unwrap();
    let bad = text.replace(
        "positions = [0.0, 0.1, 0.2, 0.3]",
        "positions = [0.0, 0.1, 0.2, 1e308]",
    );
    assert_ne!(bad, text);
    let f = dir.join("far_mass.toml");
    std::fs::write(&f, bad).unwrap();
    let o = armsim(&["run", f.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(
        err.contains("far_mass.toml") && err.contains("result: a result is not finite"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 28: far targets (squared distances overflow) are refused by the target reader and
/// unreachable for the closed forms, never a panic; an IK CSV has one header row.
#[test]
fn far_ik_targets_and_a_second_csv_header_are_refused() {
    fails_with(
        &[
            "ik",
            "robots/ur5.urdf",
            "--link",
            "tool0",
            "--target",
            "1e300,0,0.4,1,0,0,0",
            "--analytic",
        ],
        "--target: the position coordinate 1e300 m is beyond the 1e9 m accepted for a target",
    );
    let dir = std::env::temp_dir().join(format!("armsim-csv2-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("t.csv");
    std::fs::write(
        &csv,
        "x,y,z,qw,qx,qy,qz\nx,y,z,qw,qx,qy,qz\n0.3,0,0.4,1,0,0,0\n",
    )
    .unwrap();
    fails_with(
        &[
            "ik",
            "robots/ur5.urdf",
            "--link",
            "tool0",
            "--targets",
            csv.to_str().unwrap(),
        ],
        "t.csv:2: 'x,y,z,qw,qx,qy,qz' has a value that is not a number",
    );
    std::fs::remove_dir_all(&dir).ok();
    // The library: a target beyond reach is unreachable, not a panic in a clamp.
    let (model, _) = armsim::Model::load(common::root().join("robots/ur5.urdf")).unwrap();
    let solver =
        armsim::kinematics::ik::analytic::AnalyticSolver::new(&model, model.links.len() - 1);
    if let Ok(s) = solver {
        let far = armsim::core::spatial::Se3::from_translation(armsim::core::spatial::Vec3::new(
            1e200, 0.0, 0.4,
        ));
        let r = s.solve(&far, &Default::default());
        assert!(
            matches!(
                r,
                Err(armsim::kinematics::ik::analytic::IkError::Unreachable(_))
            ),
            "{r:?}"
        );
    }
}

/// Issue 28: a model too large for the dense algorithms (two nv × nv matrices) is refused
/// by the commands that need them, with the budget; kinematics still runs on it.
#[test]
fn dense_algorithms_refuse_models_over_their_size() {
    let dir = std::env::temp_dir().join(format!("armsim-dense-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("c9000.urdf");
    let f = file.to_str().unwrap();
    assert!(armsim(&["chain", "9000", "--out", f]).status.success());
    let budget = "the model has 9000 degrees of freedom: the dense algorithms";
    fails_with(&["bench", f, "--algo", "crba", "--iters", "1"], budget);
    fails_with(
        &["ik", f, "--link", "link9000", "--target", "0,0,1,1,0,0,0"],
        budget,
    );
    let q = vec!["0"; 9000].join(",");
    fails_with(&["dynamics", f, "--q", &q], budget);
    fails_with(
        &[
            "workspace",
            "robots/planar_2r.toml",
            "--samples",
            "4096",
            "--max-samples",
            "0",
        ],
        "--max-samples: applies to adaptive sampling only",
    );
    fails_with(
        &[
            "workspace",
            "robots/planar_2r.toml",
            "--samples",
            "4096",
            "--target-rel-error",
            "0.01",
            "--max-samples",
            "0",
        ],
        "--max-samples: 0 is below the first round's 4096 samples",
    );
    let o = armsim(&["bench", f, "--algo", "fk", "--iters", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_dir_all(&dir).ok();
}
