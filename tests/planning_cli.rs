//! `armsim plan`: the JSON contract (joint names, one result per problem with the agreed
//! keys, paths from the exact start to the exact goal), `--moveit-dir` over a shown MBM
//! folder in order, the same paths on one or two threads, `--passes`, `--out`, and bad
//! input: non-zero exit, a `FILE:LINE:` message, nothing written, never a panic.

mod plan_common;

use armsim::planning::moveit;
use plan_common::{bench, Robot};
mod common;
use common::{armsim, cli_json as json};
use serde_json::Value;
use std::path::{Path, PathBuf};

const PANDA: &str = "robots/spherized/panda_spherized.urdf";
const PANDA_SRDF: &str = "robots/spherized/panda.srdf";

fn fails_with(args: &[&str], needle: &str) -> String {
    let o = armsim(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success(), "{args:?} succeeded");
    assert!(
        err.contains(needle),
        "{args:?}: stderr lacks '{needle}': {err}"
    );
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    assert!(o.stdout.is_empty(), "{args:?} wrote to stdout");
    err
}

fn scene_dir(robot: &str, scene: &str) -> String {
    bench().join(robot).join(scene).display().to_string()
}

/// A fresh scratch folder for this test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("armsim_plan_cli_{}_{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Scene and request files of Panda `table_pick` problem 0001 (solved by the straight edge).
fn table_pick_0001() -> (String, String) {
    let dir = bench().join("panda/table_pick");
    let file = |f: &str| dir.join(f).display().to_string();
    (file("scene0001.yaml"), file("request0001.yaml"))
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn plan_json_names_the_joints_and_gives_each_result_the_agreed_keys() {
    let dir = bench().join("panda/table_pick");
    let (scene, request) = (dir.join("scene0002.yaml"), dir.join("request0002.yaml"));
    let v = json(&[
        "plan",
        PANDA,
        "--srdf",
        PANDA_SRDF,
        "--moveit-scene",
        scene.to_str().unwrap(),
        "--moveit-request",
        request.to_str().unwrap(),
        "--json",
    ]);
    let joints: Vec<&str> = v["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    let expected: Vec<String> = (1..=7).map(|k| format!("panda_joint{k}")).collect();
    assert_eq!(joints, expected);
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), 1);
    let r = &results[0];
    let mut keys: Vec<&str> = r.as_object().unwrap().keys().map(|k| k.as_str()).collect();
    keys.sort_unstable();
    assert_eq!(
        keys,
        [
            "cost",
            "cost_initial",
            "goal",
            "improvements",
            "iterations",
            "path",
            "plan_time_us",
            "problem",
            "reason",
            "scene",
            "simplify_time_us",
            "status"
        ]
    );
    assert_eq!(r["problem"], "0002");
    assert_eq!(r["scene"], "table_pick");
    assert_eq!(r["status"], "solved");
    assert!(r["reason"].is_null());
    assert!(r["plan_time_us"].as_f64().unwrap() > 0.0);
    // The path runs from the request's exact start to its exact goal.
    let robot = Robot::load("panda");
    let (req, _) = moveit::load_request(&request, &robot.model).unwrap();
    let path: Vec<Vec<f64>> = r["path"].as_array().unwrap().iter().map(f64s).collect();
    assert!(path.len() >= 2);
    assert_eq!(path[0], req.start);
    assert_eq!(path.last().unwrap(), &req.goal);
    assert!(path.iter().all(|p| p.len() == 7));
    let len = plan_common::path_length(&path);
    assert!((r["cost"].as_f64().unwrap() - len).abs() < 1e-5 * len);
    assert_eq!(
        v["summary"].as_array().unwrap().last().unwrap()["solved"],
        1
    );
}

#[test]
fn plan_moveit_dir_plans_every_pair_of_a_folder_in_order() {
    let dir = scene_dir("panda", "table_pick");
    let args = ["plan", PANDA, "--srdf", PANDA_SRDF, "--moveit-dir", &dir];
    let v = json(&[&args[..], &["--json"]].concat());
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), 100);
    let validity = moveit::load_validity(bench().join("panda/validity.json")).unwrap();
    for (k, r) in results.iter().enumerate() {
        let id = format!("{:04}", k + 1);
        assert_eq!(r["problem"], id.as_str());
        let valid = validity.is_valid("table_pick", &id).unwrap();
        if valid {
            assert_eq!(r["status"], "solved", "{id}: {}", r["reason"]);
        } else {
            // 0041: the goal is in collision (validity.json, and the planner agrees).
            assert_eq!(r["status"], "invalid_goal", "{id}");
            assert!(r["path"].as_array().unwrap().is_empty());
        }
    }
    let all = &v["summary"].as_array().unwrap()[0];
    assert_eq!(
        (all["solved"].as_u64(), all["valid"].as_u64()),
        (Some(99), Some(99))
    );
    assert_eq!(all["total"], 100);
    // The text summary: the anchor's columns, one row for the folder.
    let o = armsim(&args);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("| scene | solved/valid/total | plan med | plan mean | plan p95 |"));
    assert!(text.contains("| table_pick | 99/99/100 |"), "{text}");
    assert!(
        text.contains("0041 invalid_goal: goal is in collision"),
        "{text}"
    );
}

/// Everything of a result but its times.
fn untimed(v: &Value) -> Vec<Value> {
    v["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            let mut r = r.clone();
            let o = r.as_object_mut().unwrap();
            o.remove("plan_time_us");
            o.remove("simplify_time_us");
            for i in o["improvements"].as_array_mut().unwrap() {
                i.as_object_mut().unwrap().remove("time_us");
            }
            r
        })
        .collect()
}

#[test]
fn plan_gives_the_same_paths_on_one_and_two_threads_and_over_passes() {
    let dir = scene_dir("panda", "box");
    let run = |extra: &[&str]| {
        let base = [
            "plan",
            PANDA,
            "--srdf",
            PANDA_SRDF,
            "--moveit-dir",
            &dir,
            "--json",
        ];
        json(&[&base[..], extra].concat())
    };
    let one = run(&["--threads", "1", "--seed", "3"]);
    let two = run(&["--threads", "2", "--seed", "3", "--passes", "2"]);
    let (a, b) = (untimed(&one), untimed(&two));
    assert_eq!(a.len(), 100);
    assert!(a.iter().any(|r| r["iterations"].as_u64().unwrap() > 0));
    assert_eq!(a, b, "paths differ between 1 and 2 threads");
    assert_eq!(two["passes"], 2);
}

#[test]
fn plan_out_writes_the_file_and_nothing_to_stdout() {
    let d = scratch("out");
    let out = d.join("plan.json");
    let (scene, request) = table_pick_0001();
    let o = armsim(&[
        "plan",
        PANDA,
        "--srdf",
        PANDA_SRDF,
        "--moveit-scene",
        &scene,
        "--moveit-request",
        &request,
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(o.stdout.is_empty());
    let v: Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(v["results"][0]["status"], "solved");
    // Only the file itself: no temporary left beside it.
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn plan_without_srdf_says_how_it_chose_the_self_pairs() {
    let (scene, request) = table_pick_0001();
    let o = armsim(&[
        "plan",
        PANDA,
        "--moveit-scene",
        &scene,
        "--moveit-request",
        &request,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("no --srdf") && err.contains("random configurations"),
        "{err}"
    );
}

/// Copies problem 0001 of Panda table_pick into `d` as problem `id`, with `edit` applied to
/// the scene text and `edit_req` to the request text.
fn broken_problem(
    d: &Path,
    id: &str,
    edit: &dyn Fn(&str) -> String,
    edit_req: &dyn Fn(&str) -> String,
) {
    let src = bench().join("panda/table_pick");
    let scene = std::fs::read_to_string(src.join("scene0001.yaml")).unwrap();
    let request = std::fs::read_to_string(src.join("request0001.yaml")).unwrap();
    std::fs::write(d.join(format!("scene{id}.yaml")), edit(&scene)).unwrap();
    std::fs::write(d.join(format!("request{id}.yaml")), edit_req(&request)).unwrap();
}

#[test]
fn plan_bad_inputs_fail_with_file_and_line_and_write_nothing() {
    let d = scratch("bad");
    let same = |s: &str| s.to_string();
    // A box with two dimensions, in the second problem of the folder.
    broken_problem(&d, "0001", &same, &same);
    let bad_dims = |s: &str| {
        let t = s.replacen("dimensions: [0.2, 0.02, 0.4]", "dimensions: [0.2, 0.02]", 1);
        assert_ne!(t, s, "the edit applies");
        t
    };
    broken_problem(&d, "0002", &bad_dims, &same);
    let out = d.join("out.json");
    let dir = d.display().to_string();
    let o = out.display().to_string();
    let base = ["plan", PANDA, "--srdf", PANDA_SRDF, "--out", &o];
    let err = fails_with(
        &[&base[..], &["--moveit-dir", &dir]].concat(),
        "scene0002.yaml:",
    );
    assert!(err.contains("dimensions"), "{err}");
    let line = err.split("scene0002.yaml:").nth(1).unwrap();
    assert!(
        line.split(':').next().unwrap().parse::<usize>().is_ok(),
        "no line: {err}"
    );
    assert!(!out.exists(), "output written despite the error");
    // A request naming a joint the model does not have.
    std::fs::remove_file(d.join("scene0002.yaml")).unwrap();
    std::fs::remove_file(d.join("request0002.yaml")).unwrap();
    let bad_joint = |s: &str| s.replacen("panda_joint3", "elbow_joint", 1);
    broken_problem(&d, "0003", &same, &bad_joint);
    let err = fails_with(
        &[&base[..], &["--moveit-dir", &dir]].concat(),
        "request0003.yaml:",
    );
    assert!(err.contains("'elbow_joint' is not in model"), "{err}");
    assert!(!out.exists());
    // A scene without its request.
    std::fs::remove_file(d.join("request0003.yaml")).unwrap();
    fails_with(
        &[&base[..], &["--moveit-dir", &dir]].concat(),
        "has no request0003.yaml",
    );
    // A folder without problems, a missing model, a missing SRDF, bad numbers.
    let empty = scratch("empty");
    let e = empty.display().to_string();
    fails_with(&["plan", PANDA, "--moveit-dir", &e], "no sceneNNNN.yaml");
    let s1 = d.join("scene0001.yaml").display().to_string();
    let r1 = d.join("request0001.yaml").display().to_string();
    let one = [
        "--moveit-scene",
        s1.as_str(),
        "--moveit-request",
        r1.as_str(),
    ];
    fails_with(
        &[&["plan", "robots/nope.urdf"][..], &one].concat(),
        "nope.urdf",
    );
    fails_with(
        &[&["plan", PANDA, "--srdf", "nope.srdf"][..], &one].concat(),
        "nope.srdf",
    );
    for (flag, value) in [
        ("--threads", "0"),
        ("--passes", "0"),
        ("--time-limit-ms", "-5"),
        ("--range", "0"),
        ("--range", "-1"),
        ("--range", "NaN"),
    ] {
        fails_with(&[&["plan", PANDA, flag, value][..], &one].concat(), flag);
    }
    // Clap: a scene without its request, and no problem at all.
    fails_with(&["plan", PANDA, "--moveit-scene", &s1], "--moveit-request");
    fails_with(&["plan", PANDA], "--moveit");
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(&d);
    let _ = std::fs::remove_dir_all(&empty);
}

#[test]
fn plan_time_limit_reaches_the_planner() {
    // Problem 0001 is solved by the straight edge: any limit leaves it solved; the JSON
    // echoes the limit.
    let (scene, request) = table_pick_0001();
    let v = json(&[
        "plan",
        PANDA,
        "--srdf",
        PANDA_SRDF,
        "--moveit-scene",
        &scene,
        "--moveit-request",
        &request,
        "--time-limit-ms",
        "250",
        "--no-simplify",
        "--json",
    ]);
    assert_eq!(v["time_limit_ms"], 250.0);
    assert_eq!(v["simplify"], false);
    assert_eq!(v["range"], 1.0);
    let r = &v["results"][0];
    assert_eq!(r["status"], "solved");
    assert_eq!(r["cost"], r["cost_initial"]);
}

#[test]
fn plan_range_reaches_the_planner() {
    // The UR5 box folder at VAMP's UR5 range (1.5) and at the default (1): the JSON echoes
    // the range, every valid problem is solved either way, and the searches differ.
    let dir = scene_dir("ur5", "box");
    let srdf = "robots/spherized/ur5.srdf";
    let ur5 = "robots/spherized/ur5_spherized.urdf";
    let base = [
        "plan",
        ur5,
        "--srdf",
        srdf,
        "--moveit-dir",
        &dir,
        "--no-simplify",
        "--json",
    ];
    let iterations = |range: Option<&str>| -> (Value, Vec<u64>) {
        let mut args = base.to_vec();
        if let Some(r) = range {
            args.extend(["--range", r]);
        }
        let v = json(&args);
        let it = v["results"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["status"] == "solved")
            .map(|r| r["iterations"].as_u64().unwrap())
            .collect();
        (v, it)
    };
    let (v1, it1) = iterations(None);
    let (v15, it15) = iterations(Some("1.5"));
    assert_eq!(v1["range"], 1.0);
    assert_eq!(v15["range"], 1.5);
    assert_eq!(it1.len(), it15.len(), "solved counts differ");
    assert!(it1.len() >= 90, "only {} solved", it1.len());
    let differ = it1.iter().zip(&it15).filter(|(a, b)| a != b).count();
    assert!(
        differ >= 10,
        "only {differ} searches changed with the range"
    );
}

/// The impossible block problem of `plan_common::panda_wall_problem` as MoveIt files.
fn write_block_problem(d: &Path) -> (PathBuf, PathBuf) {
    let (scene, request) = (d.join("block_scene.yaml"), d.join("block_request.yaml"));
    std::fs::write(
        &scene,
        "world:\n  collision_objects:\n    - id: block\n      header: {frame_id: panda_link0}\n      \
         primitives:\n        - {type: box, dimensions: [0.02, 0.1, 0.17]}\n      \
         primitive_poses:\n        - {position: [0, -0.15, 0.335], orientation: [0, 0, 0, 1]}\n",
    )
    .unwrap();
    let q = |yaw: f64| {
        plan_common::panda_upright(yaw)
            .iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
    };
    let goal: String = q(-1.5)
        .iter()
        .enumerate()
        .map(|(k, x)| {
            format!(
                "      - {{joint_name: panda_joint{}, position: {x}}}\n",
                k + 1
            )
        })
        .collect();
    let names: Vec<String> = (1..=7).map(|k| format!("panda_joint{k}")).collect();
    std::fs::write(
        &request,
        format!(
            "goal_constraints:\n  - joint_constraints:\n{goal}start_state:\n  joint_state:\n    \
             name: [{}]\n    position: [{}]\n",
            names.join(", "),
            q(1.5).join(", ")
        ),
    )
    .unwrap();
    (scene, request)
}

#[test]
fn plan_reports_failed_with_the_reason_under_a_time_limit() {
    let d = scratch("block");
    let (scene, request) = write_block_problem(&d);
    let run = |extra: &[&str]| {
        let base = [
            "plan",
            PANDA,
            "--srdf",
            PANDA_SRDF,
            "--moveit-scene",
            scene.to_str().unwrap(),
            "--moveit-request",
            request.to_str().unwrap(),
        ];
        armsim(&[&base[..], extra].concat())
    };
    let o = run(&["--time-limit-ms", "30", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let r = &v["results"][0];
    assert_eq!(r["problem"], "block_request");
    assert_eq!(r["status"], "failed");
    let why = r["reason"].as_str().unwrap();
    assert!(why.contains("time limit of 30 ms"), "{why}");
    assert!(r["path"].as_array().unwrap().is_empty());
    let t = r["plan_time_us"].as_f64().unwrap();
    assert!((30_000.0..1_000_000.0).contains(&t), "{t} µs");
    // Text: the failure is counted valid but not solved, with its reason.
    let o = run(&["--time-limit-ms", "30"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("| 0/1/1 |"), "{text}");
    assert!(
        text.contains("block_request failed: no path within the time limit"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn plan_scenario_plans_each_planned_move_of_the_task_around_the_crate() {
    let scenario = "scenarios/ur5_pick_and_place.toml";
    let v = json(&["plan", "robots/ur5.urdf", "--scenario", scenario, "--json"]);
    let names: Vec<&str> = v["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    assert_eq!(names[0], "shoulder_pan_joint");
    assert_eq!(names.len(), 6);
    let results = v["results"].as_array().unwrap();
    // Approach, transfer and return: the pick-and-place's three joint moves.
    assert_eq!(results.len(), 3, "{v}");
    // The same moves as `armsim run` plans (one code path, the same seed).
    let text = std::fs::read_to_string(scenario).unwrap();
    let scene = armsim::scenarios::arm::load(Path::new(scenario), &text).unwrap();
    let plan = armsim::scenarios::arm::task_motion::plan(&scene).unwrap();
    for (r, want) in results.iter().zip(&plan.planned_paths) {
        assert_eq!(r["status"], "solved", "{r}");
        assert!(!r["problem"].as_str().unwrap().is_empty(), "{r}");
        let path: Vec<Vec<f64>> = r["path"].as_array().unwrap().iter().map(f64s).collect();
        assert_eq!(&path, want);
        assert!(r["cost"].as_f64().unwrap() <= r["cost_initial"].as_f64().unwrap() + 1e-9);
    }
    // The transfer goes around the crate: more than its two ends.
    assert!(results[1]["path"].as_array().unwrap().len() > 2);
    // The model must be the scenario's.
    fails_with(
        &["plan", PANDA, "--scenario", scenario],
        "scenario's own model",
    );
}

#[test]
fn plan_aorrtc_logs_cheaper_paths_and_refuses_budgets_that_do_not_apply() {
    let dir = scene_dir("panda", "bookshelf_small");
    let base = [
        "plan",
        PANDA,
        "--srdf",
        PANDA_SRDF,
        "--moveit-dir",
        &dir,
        "--json",
    ];
    let opt = ["--planner", "aorrtc", "--budget-iterations", "1500"];
    let first = json(&base);
    let v = json(&[&base[..], &opt[..]].concat());
    assert_eq!(v["planner"], "aorrtc");
    assert_eq!(v["budget_iterations"], 1500);
    assert!(v["budget_ms"].is_null());
    assert_eq!(first["planner"], "rrt-connect");
    let (mut improved, mut cheaper) = (0, 0);
    for (r, f) in v["results"]
        .as_array()
        .unwrap()
        .iter()
        .zip(first["results"].as_array().unwrap())
    {
        if r["status"] != "solved" {
            continue;
        }
        let imp = r["improvements"].as_array().unwrap();
        let costs: Vec<f64> = imp.iter().map(|i| i["cost"].as_f64().unwrap()).collect();
        // The first entry is RRT-Connect's simplified path; each later one is cheaper.
        assert_eq!(costs[0], f["cost"].as_f64().unwrap(), "{}", r["problem"]);
        assert!(costs.windows(2).all(|w| w[1] < w[0]), "{costs:?}");
        assert_eq!(*costs.last().unwrap(), r["cost"].as_f64().unwrap());
        assert_eq!(r["simplify_time_us"], 0.0);
        improved += usize::from(costs.len() > 1);
        cheaper += usize::from(r["cost"].as_f64().unwrap() < f["cost"].as_f64().unwrap() - 1e-9);
    }
    assert!(
        improved >= 20 && improved == cheaper,
        "{improved} improved, {cheaper} cheaper"
    );
    let bad = |extra: &[&str], needle: &str| fails_with(&[&base[..], extra].concat(), needle);
    bad(
        &["--budget-iterations", "100"],
        "--budget-iterations applies to --planner aorrtc",
    );
    bad(
        &["--planner", "rrt-connect", "--budget-ms", "5"],
        "--budget-ms applies",
    );
    bad(
        &["--planner", "rrt*"],
        "--planner: expected rrt-connect or aorrtc, got 'rrt*'",
    );
    bad(
        &["--planner", "aorrtc", "--budget-iterations", "0"],
        "--budget-iterations: expected 1",
    );
    bad(
        &["--planner", "aorrtc", "--budget-ms", "nan"],
        "--budget-ms: expected a positive",
    );
}

#[test]
fn plan_scenario_takes_the_optimising_planner_from_its_table_or_the_command_line() {
    let scenario = "scenarios/ur5_pick_and_place.toml";
    let base = ["plan", "robots/ur5.urdf", "--scenario", scenario, "--json"];
    let first = json(&base);
    let opt = json(
        &[
            &base[..],
            &["--planner", "aorrtc", "--budget-iterations", "800"],
        ]
        .concat(),
    );
    assert_eq!(opt["planner"], "aorrtc");
    assert_eq!(opt["budget_iterations"], 800);
    let pairs = first["results"]
        .as_array()
        .unwrap()
        .iter()
        .zip(opt["results"].as_array().unwrap());
    for (f, o) in pairs {
        assert_eq!(o["status"], "solved", "{o}");
        assert!(
            o["cost"].as_f64().unwrap() <= f["cost"].as_f64().unwrap() + 1e-9,
            "{o}"
        );
    }
    fails_with(
        &[&base[..], &["--budget-ms", "5"]].concat(),
        "apply to the aorrtc planner",
    );
    // The `[planner]` keys, read from the scenario's own text.
    let text = std::fs::read_to_string(scenario).unwrap();
    let with = |keys: &str| text.replacen("[planner]\n", &format!("[planner]\n{keys}\n"), 1);
    let load = |t: &str| armsim::scenarios::arm::load(Path::new(scenario), t);
    let scene = load(&with(
        "algorithm = \"aorrtc\"\nbudget_iterations = 900\nbudget_ms = 40",
    ))
    .unwrap();
    let p = scene.planner.unwrap();
    assert_eq!(
        p.algorithm,
        armsim::planning::plan_options::PlannerKind::Aorrtc
    );
    assert_eq!(p.budget.iterations, 900);
    assert_eq!(p.budget.time, Some(std::time::Duration::from_millis(40)));
    for (keys, needle) in [
        (
            "budget_iterations = 900",
            "planner.budget_iterations: applies to algorithm = \"aorrtc\"",
        ),
        (
            "algorithm = \"rrt*\"",
            "planner.algorithm: expected \"rrt-connect\" or \"aorrtc\"",
        ),
        (
            "algorithm = \"aorrtc\"\nbudget_iterations = 0",
            "planner.budget_iterations: must lie in 1",
        ),
        (
            "algorithm = \"aorrtc\"\nbudget_ms = -1",
            "planner.budget_ms: must be positive",
        ),
    ] {
        let e = load(&with(keys))
            .err()
            .unwrap_or_else(|| panic!("{keys} accepted"))
            .to_string();
        assert!(
            e.contains(needle) && e.contains("ur5_pick_and_place.toml:"),
            "{keys}: {e}"
        );
    }
}
