//! `armsim run` (a scenario file end to end), `armsim view` (a recording to Rerun) and
//! `armsim tradeoffs` (the trade-offs report).

use crate::cli::{flush_stdout, print_json};
use armsim::model::Model;
use std::path::PathBuf;

#[derive(clap::Args, Clone)]
pub struct RunArgs {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    /// Directory for output files.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Exit with status 2 when the verdict is not ok (limits exceeded or a collision).
    #[arg(long)]
    pub check: bool,
    /// Also log the run to Rerun: save this .rrd file (arm scenarios).
    #[arg(long, conflicts_with = "spawn")]
    pub rerun: Option<PathBuf>,
    /// Also log the run to a spawned Rerun viewer (arm scenarios).
    #[arg(long)]
    pub spawn: bool,
    /// Directory searched first for `package://` mesh URIs: one containing packages,
    /// or a package itself (repeatable; then the scenario's `model.package_path`,
    /// ROS_PACKAGE_PATH, AMENT_PREFIX_PATH and the model file's folder tree).
    #[arg(long = "package-path", value_name = "DIR")]
    pub package_path: Vec<PathBuf>,
    /// Keep the mesh URIs of the recording's robot description as the model file
    /// writes them (default: absolute file:// URIs of the files found here).
    #[arg(long)]
    pub keep_mesh_uris: bool,
    /// Treat model warnings as errors, as the model commands' --strict does.
    #[arg(long)]
    pub strict: bool,
}

#[derive(clap::Args)]
pub struct ViewArgs {
    /// Recording file (.mcap).
    pub recording: PathBuf,
    /// Write a Rerun file (.rrd) instead of spawning the viewer.
    #[arg(long, conflicts_with = "spawn")]
    pub save: Option<PathBuf>,
    /// Spawn the Rerun viewer and stream to it (the default without --save).
    #[arg(long)]
    pub spawn: bool,
    /// Model file for the geometry (default: the URDF stored in the recording).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Directory mesh URIs are resolved from (default: the model file's directory).
    #[arg(long)]
    pub mesh_dir: Option<PathBuf>,
}

#[derive(clap::Args)]
pub struct TradeoffsArgs {
    /// Output directory.
    #[arg(long, default_value = "tradeoffs")]
    pub out: PathBuf,
    /// Reduced sizes (about 3 minutes on 2 cores instead of about 20).
    #[arg(long)]
    pub quick: bool,
    /// Smoke-test sizes (seconds; coarse numbers). For the tests.
    #[arg(long, hide = true, conflicts_with = "quick")]
    pub tiny: bool,
    /// No progress lines on standard error.
    #[arg(long)]
    pub quiet: bool,
}

/// `armsim run`: runs the scenario, prints its report; exit status 2 with `--check` when
/// the verdict is not ok, 130 when interrupted.
pub fn run(a: &RunArgs) -> Result<(), String> {
    let RunArgs {
        scenario,
        out,
        json,
        check,
        rerun,
        spawn,
        package_path,
        keep_mesh_uris,
        strict,
    } = a.clone();
    if rerun.is_some() || spawn {
        need_rerun()?;
    }
    if let Some(dir) = &out {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    }
    // Ctrl-C stops the simulation; the run still writes its files (a second one
    // exits at once).
    armsim::core::interrupt::install().map_err(|e| e.to_string())?;
    let opts = armsim::scenarios::arm::RunOptions {
        out_dir: out,
        stop: Some(armsim::core::interrupt::flag()),
        on_stop: armsim::scenarios::OnStop::FinishFiles,
        rerun: match (rerun, spawn) {
            (Some(p), _) => Some(armsim::io::record::rerun::rerun_out::RerunSink::Save(p)),
            (None, true) => Some(armsim::io::record::rerun::rerun_out::RerunSink::Spawn),
            (None, false) => None,
        },
        package_path,
        keep_mesh_uris,
        strict,
        ..Default::default()
    };
    let report = armsim::scenarios::run_file_with(&scenario, &opts).map_err(|e| e.to_string())?;
    if json {
        print_json(&report.json);
    } else {
        print!("{}", report.text);
    }
    if armsim::core::interrupt::requested() {
        let _ = flush_stdout();
        eprintln!("interrupted: the files hold what was simulated until then");
        std::process::exit(130);
    }
    if check && report.json.get("ok").and_then(|v| v.as_bool()) == Some(false) {
        let _ = flush_stdout();
        std::process::exit(2);
    }
    Ok(())
}

/// `armsim view`: an MCAP recording to Rerun.
pub fn view(a: &ViewArgs) -> Result<(), String> {
    let recording = a.recording.as_path();
    let save = a.save.clone();
    let (model, mesh_dir) = (a.model.as_deref(), a.mesh_dir.as_deref());
    use armsim::io::record::mcap_in;
    use armsim::io::record::rerun::rerun_out;
    need_rerun()?;
    let rec = mcap_in::read_mcap(recording).map_err(|e| e.to_string())?;
    let spec = match model {
        Some(p) => Some(Model::read_spec(p).map_err(|e| e.to_string())?),
        None => None,
    };
    let sink = match save {
        Some(p) => rerun_out::RerunSink::Save(p),
        None => rerun_out::RerunSink::Spawn,
    };
    let report =
        rerun_out::log_recording(&rec, spec.as_ref(), mesh_dir, &sink).map_err(|e| match e {
            rerun_out::RerunError::TooLarge(_) => format!("{}: {e}", recording.display()),
            _ => e.to_string(),
        })?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    let what = format!(
        "{} links, {} frames, {} visuals, {} points, {} collision events",
        report.links.len(),
        report.frames,
        report.visuals,
        report.points,
        rec.collisions.len()
    );
    match (&sink, report.bytes) {
        (rerun_out::RerunSink::Save(p), Some(n)) => {
            println!("wrote {} ({n} bytes): {what}", p.display())
        }
        _ => println!("sent to the Rerun viewer: {what}"),
    }
    Ok(())
}

/// `armsim tradeoffs`: runs the studies, writes the report, prints the files written.
pub fn tradeoffs(a: &TradeoffsArgs) -> Result<(), String> {
    let (out, quick, tiny, quiet) = (a.out.as_path(), a.quick, a.tiny, a.quiet);
    use armsim::studies::tradeoffs::{self, Options, StudyMode};
    let mode = if tiny {
        StudyMode::Tiny
    } else if quick {
        StudyMode::Quick
    } else {
        StudyMode::Full
    };
    // Fail on an unwritable directory before spending minutes measuring.
    std::fs::create_dir_all(out).map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
    let opts = Options {
        progress: !quiet,
        ..Options::new(mode)
    };
    opts.say(format!(
        "{} mode, writing into {}",
        mode.as_str(),
        out.display()
    ));
    let report = tradeoffs::run(&opts)?;
    let written = tradeoffs::markdown::write(&report, out)?;
    println!(
        "trade-offs report ({} mode) measured in {:.1} s",
        mode.as_str(),
        report.total_seconds
    );
    for p in written {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// Refuses at once (before any work) in a build without the `rerun` feature.
pub fn need_rerun() -> Result<(), String> {
    if armsim::io::record::rerun::rerun_sink::AVAILABLE {
        Ok(())
    } else {
        Err(armsim::io::record::rerun::rerun_sink::RerunError::NotBuilt.to_string())
    }
}
