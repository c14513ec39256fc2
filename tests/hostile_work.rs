//! Work a hostile but well-formed input asks for (issue 28, "work the user asked for"):
//! an IK CSV of thousands of unreachable rows, a scenario listing 10⁶ waypoints, an SRDF
//! computed for a 1 000-link star. Each is refused before the work with a message naming
//! the file or argument, the count and the budget; each test shows the refusal comes
//! before the work (nothing solved, the rest of the file unread, the sampling not
//! started), not by timing it. The budgets are listed in `RELIABILITY.md` ("Value ranges
//! and work budgets").

use armsim::model::Model;
use armsim::planning::acm::{self, AcmError, AcmOptions, MAX_PAIR_TESTS};
use armsim::planning::spheres::SphereModel;
use armsim::planning::PlanOptions;
use armsim::scenarios::arm::scene::MAX_TASK_STEPS;
use armsim::scenarios::arm::task_prescan::check;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::AtomicBool;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh scratch directory for one test.
fn scratch(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("armsim_h28w_{}_{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `armsim ARGS` from the crate root, without the on-disk caches.
fn armsim(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_armsim"))
        .current_dir(root())
        .env("ARMSIM_NO_CACHE", "1")
        .args(args)
        .output()
        .unwrap()
}

/// Exit status 1, no panic, standard error containing every needle; returns the
/// standard output and error.
fn refused(o: &Output, needles: &[&str]) -> (String, String) {
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "not refused: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "stderr lacks '{n}': {err}");
    }
    (out, err)
}

/// An IK CSV of 20 000 unreachable rows spent its 50 ms on each (about 500 s). Targets ×
/// `--budget-ms` is at most 60 s of solver time without `--force`, checked row by row
/// while the file is read: the file is refused at target 1 201, before anything is solved.
#[test]
fn ik_batch_over_its_work_budget_is_refused_before_solving() {
    let dir = scratch("ik");
    let csv = dir.join("far.csv");
    let mut text = String::from("x,y,z,qw,qx,qy,qz\n");
    for _ in 0..20_000 {
        text += "3,0,0,1,0,0,0\n"; // 3 m away: the UR5 reaches about 1 m
    }
    // Past the limit, a row that does not parse: the reader never gets there.
    text += "not,a,pose\n";
    std::fs::write(&csv, &text).unwrap();
    let c = csv.to_str().unwrap();
    let ik = |extra: &[&str]| {
        let mut args = vec!["ik", "robots/ur5.urdf", "--link", "tool0"];
        args.extend_from_slice(extra);
        armsim(&args)
    };
    let (out, err) = refused(
        &ik(&["--targets", c]),
        &[
            &format!("{c}:1202: target 1201 is over the work budget"),
            "at --budget-ms 50 each",
            "at most 1200 targets fit the 60 s of solver time",
            "or pass --force to run it",
        ],
    );
    assert!(out.is_empty(), "something was solved: {out}");
    assert!(!err.contains("not,a,pose"), "{err}");
    // A lower per-target budget fits more rows: at 2 ms, 30 000 fit, so the reader goes
    // on to the bad row at the end (and refuses it, still before solving anything).
    let (out, _) = refused(
        &ik(&["--targets", c, "--budget-ms", "2"]),
        &[&format!(
            "{c}:20002: 'not,a,pose' has a value that is not a number"
        )],
    );
    assert!(out.is_empty(), "{out}");
    // One target with a budget over the minute: refused, and run with --force.
    let target = "0.3,0.2,0.4"; // within reach, position only
    refused(
        &ik(&[
            "--target",
            target,
            "--position-only",
            "--budget-ms",
            "100000",
        ]),
        &[
            "--budget-ms: target 1 is over the work budget",
            "at most 0 targets fit",
        ],
    );
    let o = ik(&[
        "--target",
        target,
        "--position-only",
        "--budget-ms",
        "1e5",
        "--force",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("target 0: "));
    // A budget Duration cannot hold is refused whatever --force says.
    refused(
        &ik(&[
            "--target",
            target,
            "--position-only",
            "--budget-ms",
            "1e300",
            "--force",
        ]),
        &["--budget-ms: 1e300 is not a positive number of at most 1e9 ms"],
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A scenario whose task lists 10⁶ waypoints was parsed whole (seconds, over 30 s on a
/// loaded machine) before the 10 000-waypoint limit refused it. The list is counted in the
/// text before the TOML parser runs: the error names entry 10 001's line, and a TOML error
/// placed after it in the file is never reached.
#[test]
fn a_million_waypoints_are_refused_at_the_first_entry_over_the_limit() {
    let dir = scratch("waypoints");
    let src =
        std::fs::read_to_string(root().join("scenarios/planar_2r_geared_shoulder.toml")).unwrap();
    let rows: Vec<String> = (0..1_000_000)
        .map(|i| format!("[{}.0, 30.0]", i % 90))
        .collect();
    let head = "waypoints = [[-90.0, 0.0], [0.0, 30.0]]";
    assert!(src.contains(head));
    let line = src[..src.find(head).unwrap()].lines().count() + 1;
    let text = src.replace(head, &format!("waypoints = [\n{}\n]", rows.join(",\n")))
        // A TOML error after the list: a parser that read the whole file would name it.
        + "\n[broken\n";
    let file = dir.join("many_waypoints.toml");
    std::fs::write(&file, text).unwrap();
    let f = file.to_str().unwrap();
    // Entry 10 001 is on line `line + 10 001` (the list opens on `line`).
    refused(
        &armsim(&["run", f]),
        &[&format!(
            "{f}:{}: task.waypoints: entry 10001: more than the 10000 entries one task accepts \
             (refused before the rest of the file is read)",
            line + 10_001
        )],
    );
    // The scan follows every bundled scenario to its end: a list over the limit appended
    // after it is found (a quote in a comment once stopped the scan early).
    let over = format!(
        "\n[task]\nsteps = [{}]\n",
        vec!["{ dwell = 1.0 }"; 10_001].join(", ")
    );
    let mut seen = 0;
    for entry in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let text = std::fs::read_to_string(&path).unwrap() + &over;
            let e = armsim::scenarios::arm::task_prescan::check("s.toml", &text);
            let e = e.expect_err(&path.display().to_string()).to_string();
            assert!(
                e.contains("task.steps: entry 10001"),
                "{}: {e}",
                path.display()
            );
            seen += 1;
        }
    }
    assert!(seen >= 40, "{seen} scenarios");
    // The library's entry (the fuzz target's) says the same.
    let text = std::fs::read_to_string(&file).unwrap();
    let e = armsim::scenarios::check(f, &text).unwrap_err().to_string();
    assert!(e.contains("task.waypoints: entry 10001"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A URDF star: `n` links with a 2 cm box each, on a 10 m circle around a base without
/// geometry (no two ever touch; no two are adjacent).
fn star(dir: &Path, n: usize) -> PathBuf {
    let mut s = String::from("<robot name=\"star\">\n  <link name=\"base\"/>\n");
    for i in 0..n {
        let a = i as f64 * std::f64::consts::TAU / n as f64;
        s += &format!(
            "  <link name=\"l{i}\"><collision><geometry><box size=\"0.02 0.02 0.02\"/>\
             </geometry></collision></link>\n  <joint name=\"j{i}\" type=\"revolute\">\
             <parent link=\"base\"/><child link=\"l{i}\"/><origin xyz=\"{} {} 0\"/>\
             <axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>\
             </joint>\n",
            10.0 * a.cos(),
            10.0 * a.sin()
        );
    }
    let p = dir.join(format!("star{n}.urdf"));
    std::fs::write(&p, s + "</robot>\n").unwrap();
    p
}

/// `srdf` on a 1 000-link star sampled 10⁴ configurations against ~5·10⁵ pairs (over
/// 30 s). Pairs × (never + always samples) is at most 2·10⁸ pair tests without `--force`,
/// checked before the first sample; `--samples` (MoveIt's sampling density) lowers it.
#[test]
fn srdf_over_its_pair_test_budget_is_refused_before_sampling() {
    let dir = scratch("srdf");
    let big = star(&dir, 1000);
    let b = big.to_str().unwrap();
    let (out, _) = refused(
        &armsim(&["srdf", b]),
        &[
            &format!(
                "{b}: the allowed-collision matrix would test 499500 link pairs in 10200 random \
             configurations (5094900000 pair tests), more than the budget of 200000000: at \
             most 200 samples fit it"
            ),
            "lower --samples, or pass --force to run it",
        ],
    );
    assert!(out.is_empty(), "{out}");
    refused(
        &armsim(&["srdf", b, "--samples", "0"]),
        &["--samples: expected 1 to 1000000 configurations, got 0"],
    );
    // The library refuses before sampling: with the stop flag already raised, a matrix
    // over the budget is refused, one within it is interrupted (the sampling started).
    let (model, _) = Model::load(&big).unwrap();
    let spheres = SphereModel::new(&model, &PlanOptions::default().spheres);
    let stop = AtomicBool::new(true);
    let over = AcmOptions::default();
    assert_eq!(over.max_pair_tests, Some(MAX_PAIR_TESTS));
    let e = acm::compute(&model, &spheres, None, &over, &stop).unwrap_err();
    assert!(
        matches!(
            e,
            AcmError::OverBudget {
                pairs: 499_500,
                configs: 10_200,
                fit: 200,
                ..
            }
        ),
        "{e:?}"
    );
    let within = AcmOptions {
        samples: 150,
        ..Default::default()
    };
    let e = acm::compute(&model, &spheres, None, &within, &stop).unwrap_err();
    assert_eq!(e, AcmError::Interrupted);
    // Within the budget the command runs: 20 links, every pair never colliding.
    let small = star(&dir, 20);
    let o = armsim(&[
        "srdf",
        small.to_str().unwrap(),
        "--samples",
        "500",
        "--json",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["samples"], 500);
    let disabled = v["disabled"].as_array().unwrap();
    assert_eq!(disabled.len(), 190, "{v}");
    assert!(disabled.iter().all(|p| p["reason"] == "Never"), "{v}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `n` waypoint rows, one a line.
fn rows(n: usize) -> String {
    (0..n)
        .map(|i| format!("[{i}.0, 1.0]"))
        .collect::<Vec<_>>()
        .join(",\n  ")
}

/// The task-list scan (`scenarios::arm::task_prescan`) on its own: what it counts and
/// what it steps over.
#[test]
fn task_list_scan_counts_task_lists_only_and_steps_over_strings_and_comments() {
    let ok = format!("[task]\nwaypoints = [\n  {}\n]\n", rows(MAX_TASK_STEPS));
    assert!(check("f.toml", &ok).is_ok());
    let bad = format!(
        "# a [task] in a comment\nname = \"x [y\" # ]\n[task]\ntype = 'joint_waypoints'\n\
         waypoints = [\n  {}\n]\n",
        rows(MAX_TASK_STEPS + 5)
    );
    let e = check("f.toml", &bad).unwrap_err().to_string();
    // Entry 10001 is on line 5 + 10001.
    let line = 5 + MAX_TASK_STEPS + 1;
    assert_eq!(
        e,
        format!(
            "f.toml:{line}: task.waypoints: entry 10001: more than the 10000 entries one \
             task accepts (refused before the rest of the file is read)"
        )
    );
    // Dotted keys, quoted keys, strings with brackets and commas inside entries.
    let dotted = format!(
        "task.\"poses\" = [{}]\n",
        (0..=MAX_TASK_STEPS)
            .map(|_| "{ xyz = [0, 0, \"],[\"], rpy = [] }")
            .collect::<Vec<_>>()
            .join(", ")
    );
    let e = check("f.toml", &dotted).unwrap_err().to_string();
    assert!(e.starts_with("f.toml:1: task.poses: entry 10001:"), "{e}");
    // A comment after a value may hold an unpaired quote.
    let quoted = format!("x = [1, 2] # it's\ny = 3 # \"\n{bad}");
    assert!(check("f.toml", &quoted).is_err());
    // The same list under another table is not a task list.
    let other = format!("[sweep]\nwaypoints = [{}]\n", rows(MAX_TASK_STEPS + 1));
    assert!(check("f.toml", &other).is_ok());
    // A trailing comma is not an entry; multi-line strings are stepped over.
    let trailing = format!(
        "note = \"\"\"\n[task]\nwaypoints = [\n\"\"\"\n[task]\nsteps = [{},]\n",
        rows(MAX_TASK_STEPS)
    );
    assert!(check("f.toml", &trailing).is_ok());
}
