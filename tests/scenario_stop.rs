//! A scenario run's stop flag (`RunOptions::stop`, issue 31): raised from another
//! thread in the middle of a long simulation, it cancels the run with an error that says
//! so and leaves no output file (`OnStop::Cancel`, Python's `run_scenario`), or ends the
//! simulation and finishes the files with what was simulated (`OnStop::FinishFiles`,
//! `armsim run`'s Ctrl-C).

use armsim::scenarios::{run_file_with, OnStop, RunOptions};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The bundled planar 2R scenario with a simulation of 5000 s at 0.2 ms steps (minutes
/// of work), written to `dir/long.toml`.
fn long_scenario(dir: &Path) -> PathBuf {
    let robot = root().join("robots/planar_2r.toml");
    let text = std::fs::read_to_string(root().join("scenarios/planar_2r.toml"))
        .unwrap()
        .replace("../robots/planar_2r.toml", robot.to_str().unwrap())
        .replace("dt = 0.001", "dt = 0.0002\nduration = 5000.0");
    let path = dir.join("long.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Runs `scenario` with a stop flag raised 0.3 s after the start.
fn run_stopped_after_a_while(
    scenario: &Path,
    out: &Path,
    on_stop: OnStop,
) -> Result<armsim::io::report::Report, armsim::scenarios::ScenarioError> {
    let stop = Arc::new(AtomicBool::new(false));
    let opts = RunOptions {
        out_dir: Some(out.to_path_buf()),
        stop: Some(stop.clone()),
        on_stop,
        ..Default::default()
    };
    std::thread::scope(|s| {
        s.spawn(|| {
            std::thread::sleep(Duration::from_millis(300));
            stop.store(true, Ordering::Relaxed);
        });
        run_file_with(scenario, &opts)
    })
}

fn files_in(dir: &Path) -> Vec<String> {
    match std::fs::read_dir(dir) {
        Ok(rd) => rd
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect(),
        Err(_) => Vec::new(),
    }
}

#[test]
fn a_raised_stop_flag_cancels_the_run_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("armsim_stop_cancel_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = long_scenario(&dir);
    let out = dir.join("out");
    let Err(e) = run_stopped_after_a_while(&scenario, &out, OnStop::Cancel) else {
        panic!("a cancelled run is an error");
    };
    let msg = e.to_string();
    assert!(msg.contains("cancelled"), "{msg}");
    assert!(msg.contains("no output file written"), "{msg}");
    // No recording, report, plot or temporary file: at most the empty directory.
    assert_eq!(files_in(&out), Vec::<String>::new());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_raised_stop_flag_can_instead_finish_the_files_with_what_was_simulated() {
    let dir = std::env::temp_dir().join(format!("armsim_stop_finish_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = long_scenario(&dir);
    let out = dir.join("out");
    let report = run_stopped_after_a_while(&scenario, &out, OnStop::FinishFiles)
        .unwrap_or_else(|e| panic!("{e}"));
    let sim = &report.json["simulation"];
    assert_eq!(sim["interrupted"], true);
    let t = sim["sim_time_s"].as_f64().unwrap();
    assert!(t > 0.0 && t < 5000.0, "simulated {t} s of 5000");
    let files = files_in(&out);
    assert!(files.contains(&"planar_2r.json".to_string()), "{files:?}");
    assert!(files.contains(&"planar_2r.mcap".to_string()), "{files:?}");
    assert!(!files.iter().any(|f| f.contains(".tmp")), "{files:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_unraised_flag_changes_nothing() {
    let run = |stop: Option<Arc<AtomicBool>>| {
        let opts = RunOptions {
            write_files: false,
            stop,
            ..Default::default()
        };
        run_file_with(&root().join("scenarios/planar_2r.toml"), &opts).unwrap()
    };
    let with = run(Some(Arc::new(AtomicBool::new(false))));
    let without = run(None);
    assert_eq!(with.json["simulation"]["interrupted"], false);
    assert_eq!(
        with.json["simulation"]["final_q"],
        without.json["simulation"]["final_q"]
    );
}
