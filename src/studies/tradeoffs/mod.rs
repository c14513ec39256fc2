//! The trade-offs report (`armsim tradeoffs`): eight measured studies of what accuracy,
//! robustness and features cost in time, each a table, at least one plot and a reading of
//! the numbers, written as `tradeoffs.md` plus PNGs.
//!
//! This module owns the study driver ([`run`]) and the machine description
//! ([`MachineInfo`]); it re-exports the sizes of the three modes ([`StudyMode`], from
//! `study_options.rs`) and the shared measurement helpers ([`Stats`], [`time_calls`], from
//! `study_timing.rs`). The studies live one per file:
//!
//! - [`ik`]: IK tolerance × method (numeric damped least squares, QP, analytic) on the UR5;
//! - [`integrators`]: step size × integrator on a rigid and an elastic-joint iiwa 14;
//! - [`formulations`]: RNEA, CRBA + Cholesky, ABA and the Lagrange forms against DOF;
//! - [`workspace`]: samples × random/Sobol' against workspace closed forms;
//! - [`effects`]: the cost of each physical effect against the bare rigid model;
//! - [`rotor`]: finite elements against critical-speed error on two flexible rotors
//!   (closed form, exact transfer matrices), written by [`rotor_report`];
//! - [`derivatives_study`]: the analytical dynamics derivatives against forward and central
//!   finite differences over the step h (and a Ridders-extrapolated reference) on the UR5,
//!   Panda, iiwa 14 and generated chains, with the differences in [`difference_quotients`],
//!   written by [`derivatives_report`];
//! - [`planning_study`]: path cost against planning time for RRT-Connect and the
//!   optimising mode (AORRTC) at growing budgets on bundled MotionBenchMaker problems,
//!   beside VAMP's recorded figures, written by [`planning_report`];
//!
//! and [`report`] (Markdown and file output) and [`plot`] (plotters charts) turn the
//! results into the report. Timings are medians over rounds (the machines are shared):
//! the report quotes medians and 99th percentiles and never asserts on them.

pub mod derivatives_report;
pub mod derivatives_study;
pub mod difference_quotients;
pub mod effects_study;
pub mod formulations;
pub mod ik_study;
pub mod integrators;
pub mod markdown;
pub mod planning_report;
pub mod planning_study;
mod report_numbers;
mod report_plots;
pub mod rotor_report;
pub mod rotor_study;
pub mod workspace_study;

mod bundled_robots;
mod study_options;
mod study_timing;

pub use study_options::{Options, StudyMode};
pub use study_timing::{log_slope, time_calls, time_rounds, Stats};

use serde::Serialize;
use std::time::Instant;

/// The machine and build the report was measured on.
#[derive(Clone, Debug, Serialize)]
pub struct MachineInfo {
    /// CPU model (`/proc/cpuinfo`).
    pub cpu: String,
    /// Logical processors listed in `/proc/cpuinfo`.
    pub cores: usize,
    /// Threads available to this process.
    pub available_threads: usize,
    /// Load averages at the start (`/proc/loadavg`), if readable.
    pub load_start: Option<String>,
    /// Load averages at the end.
    pub load_end: Option<String>,
    /// Start time, UTC (`YYYY-MM-DD HH:MM UTC`).
    pub date: String,
    /// armsim version.
    pub version: String,
    /// Operating system and architecture.
    pub os: String,
}

impl MachineInfo {
    /// Reads the machine description now.
    pub fn probe() -> Self {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let cpu = cpuinfo
            .lines()
            .find(|l| l.starts_with("model name"))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_string())
            .unwrap_or_else(|| "unknown".into());
        let cores = cpuinfo
            .lines()
            .filter(|l| l.starts_with("processor"))
            .count();
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        MachineInfo {
            cpu,
            cores: if cores > 0 { cores } else { threads },
            available_threads: threads,
            load_start: load_average(),
            load_end: None,
            date: utc_now(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
        }
    }
}

/// The three load averages from `/proc/loadavg`.
pub fn load_average() -> Option<String> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    let v: Vec<&str> = s.split_whitespace().take(3).collect();
    (v.len() == 3).then(|| v.join(" "))
}

/// `YYYY-MM-DD HH:MM UTC` from the system clock (civil-from-days, H. Hinnant).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02} UTC",
        rem / 3600,
        (rem % 3600) / 60
    )
}

/// Everything the report shows.
#[derive(Clone, Debug, Serialize)]
pub struct TradeoffsReport {
    /// StudyMode the studies ran in.
    pub mode: StudyMode,
    /// Machine and build.
    pub machine: MachineInfo,
    /// Study 1.
    pub ik: ik_study::IkStudy,
    /// Study 2.
    pub integrators: integrators::IntegratorStudy,
    /// Study 3.
    pub formulations: formulations::FormulationStudy,
    /// Study 4.
    pub workspace: workspace_study::WorkspaceStudy,
    /// Study 5.
    pub effects: effects_study::EffectStudy,
    /// Study 6.
    pub rotor: rotor_study::RotorStudy,
    /// Study 7.
    pub derivatives: derivatives_study::DerivativeStudy,
    /// Study 8.
    pub planning: planning_study::PlanningStudy,
    /// Wall time of each study (s).
    pub study_seconds: Vec<(String, f64)>,
    /// Wall time of all studies (s).
    pub total_seconds: f64,
}

/// Runs the eight studies at the sizes of `opts.mode`.
pub fn run(opts: &Options) -> Result<TradeoffsReport, String> {
    let start = Instant::now();
    let mut machine = MachineInfo::probe();
    let mut study_seconds = Vec::new();
    let mut timed = |name: &str, t: Instant| {
        let s = t.elapsed().as_secs_f64();
        opts.say(format!("{name} done in {s:.1} s"));
        study_seconds.push((name.to_string(), s));
    };
    let t = Instant::now();
    let ik = ik_study::run(opts, &ik_study::IkConfig::for_mode(opts.mode))?;
    timed("ik", t);
    let t = Instant::now();
    let integrators = integrators::run(opts, &integrators::IntegratorConfig::for_mode(opts.mode))?;
    timed("integrators", t);
    let t = Instant::now();
    let formulations =
        formulations::run(opts, &formulations::FormulationConfig::for_mode(opts.mode))?;
    timed("formulations", t);
    let t = Instant::now();
    let workspace =
        workspace_study::run(opts, &workspace_study::WorkspaceConfig::for_mode(opts.mode))?;
    timed("workspace", t);
    let t = Instant::now();
    let effects = effects_study::run(opts, &effects_study::EffectConfig::for_mode(opts.mode))?;
    timed("effects", t);
    let t = Instant::now();
    let rotor = rotor_study::run(opts, &rotor_study::RotorConfig::for_mode(opts.mode))?;
    timed("rotor", t);
    let t = Instant::now();
    let derivatives = derivatives_study::run(
        opts,
        &derivatives_study::DerivativeConfig::for_mode(opts.mode),
    )?;
    timed("derivatives", t);
    let t = Instant::now();
    let planning = planning_study::run(opts, &planning_study::PlanningConfig::for_mode(opts.mode))?;
    timed("planning", t);
    machine.load_end = load_average();
    Ok(TradeoffsReport {
        mode: opts.mode,
        machine,
        ik,
        integrators,
        formulations,
        workspace,
        effects,
        rotor,
        derivatives,
        planning,
        study_seconds,
        total_seconds: start.elapsed().as_secs_f64(),
    })
}
