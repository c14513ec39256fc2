//! A `type = "plan"` scenario task with `goal_pose` and `[[task.path_constraints]]`:
//! `armsim plan --scenario` reaches the pose (checked by forward kinematics to 1e-6 m and
//! rad), the path keeps the constraints at densely re-sampled points, the timed motion
//! `armsim run` plays keeps them too, and bad keys are refused with the file, line and key.

mod common;
use armsim::core::spatial::Se3;
use armsim::kinematics::ik::rotation_log;
use armsim::kinematics::{forward_kinematics, frame_placement};
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::motion::Trajectory;
use common::cli_json as json;
use std::path::{Path, PathBuf};

const H: f64 = std::f64::consts::FRAC_PI_2;
const START: [f64; 6] = [-1.0, -H, H, -H, -H, 0.0];
/// The goal pose of the task (scene axes = the UR5's base: base at the origin).
const GOAL_XYZ: [f64; 3] = [0.25, -0.35, 0.3];
const GOAL_RPY: [f64; 3] = [std::f64::consts::PI, 0.0, -2.2];
/// The box the tool origin stays in (centre, full size; the start has it at (0.355,
/// −0.351, 0.432)) and the tool's z-axis tolerance.
const BOX_XYZ: [f64; 3] = [0.3, -0.35, 0.37];
const BOX_SIZE: [f64; 3] = [0.3, 0.2, 0.3];
const TOL: f64 = 0.15;

fn scenario_text(model: &Path, extra_task: &str, timing: &str) -> String {
    format!(
        r#"name = "ur5_pose_goal"
effects = []

[model]
file = "{model}"
tool = "tool0"

[initial]
q = {START:?}

[planner]
seed = 2
time_limit_ms = 5000

[task]
type = "plan"
goal_pose = {{ xyz = {GOAL_XYZ:?}, rpy = {GOAL_RPY:?} }}
{extra_task}
[[task.path_constraints]]
type = "axis"
axis = [0.0, 0.0, 1.0]
direction = [0.0, 0.0, -1.0]
tolerance = {TOL}

[[task.path_constraints]]
type = "position"
shape = "box"
size = {BOX_SIZE:?}
xyz = {BOX_XYZ:?}

[trajectory]
type = "{timing}"

[simulation]
enabled = false
"#,
        model = model.display()
    )
}

fn write(name: &str, text: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("armsim_scn_goals_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn ur5() -> (PathBuf, Model) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/ur5.urdf");
    let m = Model::load(&p).unwrap().0;
    (p, m)
}

fn tool_pose(m: &Model, q: &[f64]) -> Se3 {
    let mut d = Data::new(m);
    forward_kinematics(m, &mut d, q);
    frame_placement(m, &d, m.link_id("tool0").unwrap())
}

/// The worst axis angle (rad) and box excess (m) over `n` points per straight edge.
fn worst_along(m: &Model, path: &[Vec<f64>], n: usize) -> (f64, f64) {
    let (mut ang, mut out) = (0.0f64, f64::NEG_INFINITY);
    for w in path.windows(2) {
        for i in 0..=n {
            let t = i as f64 / n as f64;
            let q: Vec<f64> = w[0]
                .iter()
                .zip(&w[1])
                .map(|(a, b)| a + t * (b - a))
                .collect();
            let (a, o) = violation(m, &q);
            ang = ang.max(a);
            out = out.max(o);
        }
    }
    (ang, out)
}

/// Angle of the tool z axis from straight down, and how far the tool origin is outside
/// the box (negative inside).
fn violation(m: &Model, q: &[f64]) -> (f64, f64) {
    let p = tool_pose(m, q);
    let z = p.rot.column(2);
    let ang = (-z[2]).clamp(-1.0, 1.0).acos();
    let out = (0..3)
        .map(|k| (p.trans[k] - BOX_XYZ[k]).abs() - BOX_SIZE[k] / 2.0)
        .fold(f64::NEG_INFINITY, f64::max);
    (ang, out)
}

#[test]
fn plan_scenario_reaches_the_goal_pose_and_keeps_the_constraints() {
    let (urdf, m) = ur5();
    let file = write("goal_pose.toml", &scenario_text(&urdf, "", "quintic"));
    let f = file.display().to_string();
    let u = urdf.display().to_string();
    let v = json(&["plan", &u, "--scenario", &f, "--json"]);
    let r = &v["results"][0];
    assert_eq!(r["status"], "solved", "{r}");
    let path: Vec<Vec<f64>> = serde_json::from_value(r["path"].clone()).unwrap();
    for (a, b) in path[0].iter().zip(START) {
        assert_eq!(*a, b);
    }
    // The pose reached, by forward kinematics, against the file's numbers.
    let goal = Se3::from_xyz_rpy(GOAL_XYZ, GOAL_RPY);
    let end = tool_pose(&m, path.last().unwrap());
    let ep = (end.trans - goal.trans).norm();
    let er = rotation_log(&(goal.rot * end.rot.transpose())).norm();
    assert!(ep < 1e-6 && er < 1e-6, "pose error {ep:e} m, {er:e} rad");
    // The constraints at 200 points per edge of the path.
    let (ang, out) = worst_along(&m, &path, 200);
    assert!(ang <= TOL + 1e-9, "axis {ang} rad > {TOL}");
    assert!(out <= 1e-9, "tool origin {out} m outside the box");
    // The start holds them with room (the check is not vacuous: the goal tilts nothing,
    // the box is tight on y).
    assert!(violation(&m, &START).0 < 1e-4);
    // The timed motion `armsim run` plays: straight joint segments through the same via
    // points, so the constraints hold over the whole trajectory too.
    let text = std::fs::read_to_string(&file).unwrap();
    let scene = armsim::scenarios::arm::load(&file, &text).unwrap();
    let plan = armsim::scenarios::arm::task_motion::plan(&scene).unwrap();
    assert_eq!(plan.planned_segments.len(), 1);
    assert_eq!(plan.planned_segments[0].result.path, path);
    let traj = &plan.trajectory;
    let (mut q, mut qd, mut qdd) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
    let n = 2000;
    let (mut ang, mut out) = (0.0f64, f64::NEG_INFINITY);
    for i in 0..=n {
        traj.sample(
            traj.duration() * i as f64 / n as f64,
            &mut q,
            &mut qd,
            &mut qdd,
        );
        let (a, o) = violation(&m, &q);
        ang = ang.max(a);
        out = out.max(o);
    }
    assert!(ang <= TOL + 1e-6, "timed motion: axis {ang} rad");
    assert!(out <= 1e-6, "timed motion: {out} m outside the box");
    let last = tool_pose(&m, &q);
    assert!((last.trans - goal.trans).norm() < 1e-6);
}

#[test]
fn bad_goal_pose_and_constraint_keys_are_refused_with_file_line_and_key() {
    let (urdf, _) = ur5();
    let base = scenario_text(&urdf, "", "quintic");
    let load = |text: &str| {
        let p = write("bad.toml", text);
        armsim::scenarios::arm::load(&p, text)
            .err()
            .map(|e| e.to_string())
    };
    let cases = [
        (
            base.replace(&format!("tolerance = {TOL}"), "tolerance = 4.0"),
            "task.path_constraints[0].tolerance: must be an angle in (0, π) rad, got 4",
        ),
        (
            base.replace("tolerance = ", "radius = 0.1\ntolerance = "),
            "task.path_constraints[0].radius: does not apply to an axis constraint",
        ),
        (
            base.replace(
                "direction = [0.0, 0.0, -1.0]",
                "direction = [0.0, 0.0, 0.0]",
            ),
            "task.path_constraints[0].direction: must not be the zero vector",
        ),
        (
            base.replace("size = [0.3", "size = [-0.5"),
            "task.path_constraints[1].size: must be a size",
        ),
        (
            base.replace("xyz = [0.3, -0.35", "xyz = [nan, -0.35"),
            "task.path_constraints[1].xyz: expected three finite numbers",
        ),
        (
            base.replace("shape = \"box\"", "shape = \"cone\""),
            "task.path_constraints[1].shape: expected \"box\", \"sphere\" or \"cylinder\"",
        ),
        (
            base.replace("type = \"axis\"", "type = \"axis\"\nlink = \"nope\""),
            "task.path_constraints[0].link: no link \"nope\"",
        ),
        (
            base.replace(
                "[task]\n",
                "[task]\ngoal_q = [0.0, -1.0, 1.0, 0.0, 1.0, 0.0]\n",
            ),
            "task.goal: task type 'plan' needs exactly one of",
        ),
        (
            base.replace("seed = 2", "seed = 2\nalgorithm = \"aorrtc\""),
            "planner.algorithm: \"aorrtc\" plans to joint goals without path constraints",
        ),
        (
            base.replace("type = \"plan\"", "type = \"line\"")
                .replace("goal_pose =", "goal ="),
            "task.path_constraints: does not apply to a 'line' task",
        ),
    ];
    for (text, needle) in cases {
        let e = load(&text).unwrap_or_else(|| panic!("accepted: {needle}"));
        assert!(
            e.contains(needle) && e.contains("bad.toml:"),
            "{needle}: {e}"
        );
    }
    // A timing that leaves the straight edges is refused when the task is planned.
    let text = scenario_text(&urdf, "", "minimum_jerk");
    let p = write("minjerk.toml", &text);
    let scene = armsim::scenarios::arm::load(&p, &text).unwrap();
    let e = armsim::scenarios::arm::task_motion::plan(&scene)
        .err()
        .expect("minimum_jerk accepted")
        .to_string();
    assert!(
        e.contains("task.path_constraints: the minimum_jerk timing leaves"),
        "{e}"
    );
}
