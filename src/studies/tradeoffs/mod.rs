//! The trade-offs report (`armsim tradeoffs`): six measured studies of what accuracy,
//! robustness and features cost in time, each a table, at least one plot and a reading of
//! the numbers, written as `tradeoffs.md` plus PNGs.
//!
//! This module owns the study driver ([`run`]), the sizes of the three modes ([`StudyMode`]),
//! the shared measurement helpers ([`Stats`], [`time_calls`]) and the machine description
//! ([`MachineInfo`]). The studies live one per file:
//!
//! - [`ik`]: IK tolerance × method (numeric damped least squares, QP, analytic) on the UR5;
//! - [`integrators`]: step size × integrator on a rigid and an elastic-joint iiwa 14;
//! - [`formulations`]: RNEA, CRBA + Cholesky, ABA and the Lagrange forms against DOF;
//! - [`workspace`]: samples × random/Sobol' against workspace closed forms;
//! - [`effects`]: the cost of each physical effect against the bare rigid model;
//! - [`rotor`]: finite elements against critical-speed error on two flexible rotors
//!   (closed form, exact transfer matrices), written by [`rotor_report`];
//!
//! and [`report`] (Markdown and file output) and [`plot`] (plotters charts) turn the
//! results into the report. Timings are medians over rounds (the machines are shared):
//! the report quotes medians and 99th percentiles and never asserts on them.

pub mod effects_study;
pub mod formulations;
pub mod ik_study;
pub mod integrators;
pub mod markdown;
mod report_plots;
pub mod rotor_report;
pub mod rotor_study;
pub mod workspace_study;

use serde::Serialize;
use std::time::Instant;

/// How big the studies are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StudyMode {
    /// Seconds: the smoke run the tests use (numbers are real but coarse).
    Tiny,
    /// Under 3 minutes on a 2-core machine.
    Quick,
    /// Under 20 minutes on a 2-core machine.
    Full,
}

impl StudyMode {
    /// Name used in the report.
    pub fn as_str(&self) -> &'static str {
        match self {
            StudyMode::Tiny => "tiny",
            StudyMode::Quick => "quick",
            StudyMode::Full => "full",
        }
    }
}

/// Options of [`run`].
#[derive(Clone, Debug)]
pub struct Options {
    /// Study sizes.
    pub mode: StudyMode,
    /// Progress lines on standard error.
    pub progress: bool,
    /// Seed of every random choice (targets, states, sample streams).
    pub seed: u64,
}

impl Options {
    /// `mode` with progress off and the default seed.
    pub fn new(mode: StudyMode) -> Self {
        Self {
            mode,
            progress: false,
            seed: 0x7ade_0ff5,
        }
    }

    /// Prints a progress line to standard error when asked to.
    pub fn say(&self, msg: impl AsRef<str>) {
        if self.progress {
            eprintln!("tradeoffs: {}", msg.as_ref());
        }
    }
}

/// Summary statistics of a sample (times in the caller's unit).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Stats {
    /// Number of values.
    pub count: usize,
    /// Median.
    pub median: f64,
    /// 99th percentile (nearest rank).
    pub p99: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
    /// Mean.
    pub mean: f64,
}

impl Stats {
    /// Statistics of `values` (NaNs ignored; all zeros when empty).
    pub fn of(values: &[f64]) -> Stats {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
        if v.is_empty() {
            return Stats::default();
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        let rank = ((0.99 * n as f64).ceil() as usize).clamp(1, n) - 1;
        Stats {
            count: n,
            median,
            p99: v[rank],
            min: v[0],
            max: v[n - 1],
            mean: v.iter().sum::<f64>() / n as f64,
        }
    }
}

/// Times `f` (called with a running call index, to cycle over prepared inputs): a round is
/// as many calls as take about `round_ns` (calibrated on a warm-up), and the result is
/// the per-call time in nanoseconds over `rounds` rounds (median and p99 across rounds).
/// `f` should not allocate. Rounds are kept short (a fraction of a scheduler slice) so
/// that on a loaded machine most of them run uninterrupted and the median is the
/// uncontended cost, while the p99 shows the interruptions.
pub fn time_calls(rounds: usize, round_ns: f64, f: impl FnMut(usize)) -> Stats {
    Stats::of(&time_rounds(rounds, round_ns, f))
}

/// [`time_calls`] returning the per-call time of every round (ns).
pub fn time_rounds(rounds: usize, round_ns: f64, mut f: impl FnMut(usize)) -> Vec<f64> {
    // Calibrate: double the batch until it takes a tenth of a round.
    let mut k = 0usize;
    let mut batch = 1usize;
    let per_call = loop {
        let t = Instant::now();
        for _ in 0..batch {
            f(k);
            k += 1;
        }
        let ns = t.elapsed().as_nanos() as f64;
        if ns >= 0.1 * round_ns || batch >= 1 << 24 {
            break ns / batch as f64;
        }
        batch *= 2;
    };
    let per_round = ((round_ns / per_call.max(1.0)).ceil() as usize).clamp(1, 1 << 26);
    // Warm-up round.
    for _ in 0..per_round {
        f(k);
        k += 1;
    }
    (0..rounds.max(1))
        .map(|_| {
            let t = Instant::now();
            for _ in 0..per_round {
                f(k);
                k += 1;
            }
            t.elapsed().as_nanos() as f64 / per_round as f64
        })
        .collect()
}

/// Least-squares slope of `log10 y` against `log10 x` over the points with positive,
/// finite coordinates (`None` with fewer than two).
pub fn log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.log10(), y.log10()))
        .collect();
    if p.len() < 2 {
        return None;
    }
    let n = p.len() as f64;
    let (mx, my) = (
        p.iter().map(|a| a.0).sum::<f64>() / n,
        p.iter().map(|a| a.1).sum::<f64>() / n,
    );
    let sxx: f64 = p.iter().map(|a| (a.0 - mx).powi(2)).sum();
    let sxy: f64 = p.iter().map(|a| (a.0 - mx) * (a.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

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
    /// Wall time of each study (s).
    pub study_seconds: Vec<(String, f64)>,
    /// Wall time of all studies (s).
    pub total_seconds: f64,
}

/// Runs the six studies at the sizes of `opts.mode`.
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
        study_seconds,
        total_seconds: start.elapsed().as_secs_f64(),
    })
}

/// The robots the studies use, embedded so the command runs without the source tree.
const ROBOTS: [(&str, &str); 4] = [
    (
        "ur5.urdf",
        include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf")),
    ),
    (
        "iiwa14.urdf",
        include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/iiwa14.urdf")),
    ),
    (
        "planar_2r.toml",
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/planar_2r.toml"
        )),
    ),
    (
        "textbook_spherical_rrp.toml",
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/textbook_spherical_rrp.toml"
        )),
    ),
];

/// The text of a bundled robot file (`robots/NAME`, embedded at build time).
pub(crate) fn robot_text(name: &str) -> Result<&'static str, String> {
    ROBOTS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .ok_or_else(|| format!("robots/{name} is not embedded"))
}

/// Builds a model from the text of a URDF (`.urdf`) or DH table (`.toml`) file.
pub(crate) fn model_from_text(text: &str, file: &str) -> Result<crate::model::Model, String> {
    use crate::model::parse::{dh_table as dh, urdf};
    use crate::model::Model;
    let spec = if file.ends_with(".urdf") {
        urdf::parse(text, file)
    } else {
        dh::parse(text, file)
    }
    .map_err(|e| e.to_string())?;
    Model::build(spec)
        .map(|(m, _)| m)
        .map_err(|e| e.to_string())
}

/// A bundled robot (`robots/NAME`), from the embedded text.
pub(crate) fn bundled_robot(name: &str) -> Result<crate::model::Model, String> {
    model_from_text(robot_text(name)?, &format!("robots/{name}"))
}
