//! Study 4, workspace sampling: samples (`8 × 2^k`, about 1e2 to 1e6) × sampling scheme
//! (independent random, Owen-scrambled Sobol') against the error of the workspace
//! measure, the error the sampler reports for itself, and time, on two arms with closed
//! forms:
//!
//! - the planar 2R with `l1 = 0.6`, `l2 = 0.3` (continuous joints): the annulus between
//!   radii 0.3 and 0.9, area `π (0.9² − 0.3²)`, at two pixel sizes (a coarse grid covers
//!   sooner but keeps a larger discretisation error: the two trade against each other);
//! - the textbook spherical R-R-P: the shell sector `r ∈ [0.6, 1.5]`, elevation
//!   `[−45°, 60°]`, azimuth `[−170°, 170°]`, volume
//!   `(r₂³ − r₁³)/3 · (sin 60° + sin 45°) · 340°`.
//!
//! The estimate is [`crate::workspace::sample_workspace`]'s headline (8 replicates,
//! randomly shifted grids; the pooled raw occupancy's error is listed beside it). Its own
//! error estimate is the 95 % interval (the band: its half-width), infinite while only a
//! lower bound is given. Each cell is repeated over several seeds; the table gives the
//! mean absolute error, the median band and how often the truth fell inside the reported
//! interval. A separate convergence run shows one run's estimate and interval after every
//! doubling of the samples.

use crate::model::Model;
use crate::studies::tradeoffs::study_options::Options;
use crate::studies::tradeoffs::study_timing::Stats;
use crate::workspace::{sample_workspace, Sampling, WorkspaceOptions};
use serde::Serialize;
use std::f64::consts::PI;

/// Sizes of the workspace study.
#[derive(Clone, Debug)]
pub struct WorkspaceConfig {
    /// Exponents `k` of the per-replicate sample count `2^k`.
    pub exponents: Vec<u32>,
    /// Replicates per estimate.
    pub replicates: usize,
    /// Seeds per cell.
    pub seeds: usize,
    /// Pixel edges (m) of the planar 2R runs (one case each).
    pub voxels_2r: Vec<f64>,
    /// Voxel edge (m) of the spherical R-R-P runs (none: not run).
    pub voxel_rrp: Option<f64>,
    /// Samples of the convergence run (one R-R-P run at 5 cm whose doublings give the
    /// estimate and interval against samples).
    pub convergence_samples: u64,
}

impl WorkspaceConfig {
    /// The sizes of `mode`.
    pub fn for_mode(mode: crate::studies::tradeoffs::study_options::StudyMode) -> Self {
        match mode {
            crate::studies::tradeoffs::study_options::StudyMode::Tiny => WorkspaceConfig {
                exponents: vec![6, 9, 12],
                replicates: 8,
                seeds: 3,
                voxels_2r: vec![0.05],
                voxel_rrp: None,
                convergence_samples: 1 << 18,
            },
            crate::studies::tradeoffs::study_options::StudyMode::Quick => WorkspaceConfig {
                exponents: (4..=14).collect(),
                replicates: 8,
                seeds: 4,
                voxels_2r: vec![0.05, 0.03],
                voxel_rrp: Some(0.25),
                convergence_samples: 1 << 22,
            },
            crate::studies::tradeoffs::study_options::StudyMode::Full => WorkspaceConfig {
                exponents: (4..=17).collect(),
                replicates: 8,
                seeds: 8,
                voxels_2r: vec![0.05, 0.02],
                voxel_rrp: Some(0.15),
                convergence_samples: 1 << 25,
            },
        }
    }
}

/// One (arm, sampling, N) cell, over the seeds.
#[derive(Clone, Debug, Serialize)]
pub struct WorkspaceRow {
    /// Arm ("2R annulus", "R-R-P shell").
    pub case: String,
    /// Sampling scheme.
    pub sampling: Sampling,
    /// Total samples per estimate (replicates × per replicate).
    pub samples: u64,
    /// Seeds run.
    pub seeds: usize,
    /// Mean of `|estimate − truth|` (m² or m³).
    pub mean_abs_error: f64,
    /// The same relative to the truth.
    pub mean_rel_error: f64,
    /// Mean `|raw occupancy − truth|` (no bias correction), relative to the truth.
    pub mean_rel_error_raw: f64,
    /// Mean reported noise scale `σ` of the estimate (the replicates' spread).
    pub mean_stderr: f64,
    /// Median half-width of the reported 95 % interval (∞ while only a lower bound is
    /// given).
    pub median_band: f64,
    /// Fraction of seeds whose band was finite.
    pub converged_fraction: f64,
    /// Among the seeds with a finite band, the fraction whose reported interval
    /// contained the truth (`None` when no band was finite).
    pub covered_fraction: Option<f64>,
    /// Time per estimate (s).
    pub time_s: Stats,
}

/// One arm.
#[derive(Clone, Debug, Serialize)]
pub struct WorkspaceCase {
    /// Short name.
    pub name: String,
    /// What it is and what is measured.
    pub description: String,
    /// The closed form.
    pub truth: f64,
    /// Unit of the measure.
    pub unit: &'static str,
    /// Voxel (pixel) edge (m).
    pub voxel: f64,
}

/// Result of the workspace study.
#[derive(Clone, Debug, Serialize)]
pub struct WorkspaceStudy {
    /// The arms.
    pub cases: Vec<WorkspaceCase>,
    /// Replicates per estimate.
    pub replicates: usize,
    /// Rayon threads each estimate used.
    pub threads: usize,
    /// Rows, case-major, then sampling, then N.
    pub rows: Vec<WorkspaceRow>,
    /// The convergence run.
    pub convergence: ConvergenceRun,
}

/// One run's estimate and interval after every doubling of the samples, against a
/// closed form.
#[derive(Clone, Debug, Serialize)]
pub struct ConvergenceRun {
    /// What was measured.
    pub case: String,
    /// The closed form.
    pub truth: f64,
    /// Voxel edge (m).
    pub voxel: f64,
    /// The series (samples, estimate, interval).
    pub points: Vec<crate::workspace::ConvergencePoint>,
}

/// The closed-form volume of the textbook spherical R-R-P: the shell sector
/// `r ∈ [0.6, 1.5]`, elevation `[−45°, 60°]`, azimuth `[−170°, 170°]`.
pub fn rrp_truth() -> f64 {
    (1.5f64.powi(3) - 0.6f64.powi(3)) / 3.0
        * (60f64.to_radians().sin() + 45f64.to_radians().sin())
        * 340f64.to_radians()
}

/// The convergence run: Sobol', 8 replicates, 5 cm voxels.
fn convergence_run(opts: &Options, samples: u64) -> Result<ConvergenceRun, String> {
    let model =
        crate::studies::tradeoffs::bundled_robots::bundled_robot("textbook_spherical_rrp.toml")?;
    let voxel = 0.05;
    opts.say(format!("workspace: convergence run, R-R-P, N = {samples}"));
    let o = WorkspaceOptions {
        samples,
        seed: opts.seed,
        voxel,
        extras: false,
        quiet: true,
        ..Default::default()
    };
    let r = sample_workspace(&model, &o).map_err(|e| e.to_string())?;
    Ok(ConvergenceRun {
        case: "textbook spherical R-R-P shell".into(),
        truth: rrp_truth(),
        voxel,
        points: r.convergence,
    })
}

impl WorkspaceStudy {
    /// Rows of one arm and scheme, by increasing N.
    pub fn series(&self, case: &str, sampling: Sampling) -> Vec<&WorkspaceRow> {
        self.rows
            .iter()
            .filter(|r| r.case == case && r.sampling == sampling)
            .collect()
    }
}

/// The planar 2R of `robots/planar_2r.toml` with link lengths `l1`, `l2`.
pub fn planar_2r(l1: f64, l2: f64) -> Result<Model, String> {
    let text = crate::studies::tradeoffs::bundled_robots::robot_text("planar_2r.toml")?;
    if text.matches("a = 0.5").count() != 2 {
        return Err("planar_2r.toml: expected two 'a = 0.5' lines".into());
    }
    let text = text.replacen("a = 0.5", &format!("a = {l1}"), 1).replacen(
        "a = 0.5",
        &format!("a = {l2}"),
        1,
    );
    crate::studies::tradeoffs::bundled_robots::model_from_text(
        &text,
        "planar_2r (lengths changed).toml",
    )
}

/// Runs the study.
pub fn run(opts: &Options, cfg: &WorkspaceConfig) -> Result<WorkspaceStudy, String> {
    let (l1, l2) = (0.6f64, 0.3f64);
    let mut cases = Vec::new();
    for &h in &cfg.voxels_2r {
        cases.push((
            WorkspaceCase {
                name: format!("2R annulus, h = {h}"),
                description: format!(
                    "planar 2R, l1 = {l1} m, l2 = {l2} m: area of the annulus between radii {:.1} and {:.1} m",
                    l1 - l2,
                    l1 + l2
                ),
                truth: PI * ((l1 + l2).powi(2) - (l1 - l2).powi(2)),
                unit: "m²",
                voxel: h,
            },
            planar_2r(l1, l2)?,
        ));
    }
    if let Some(h) = cfg.voxel_rrp {
        let truth = rrp_truth();
        cases.push((
            WorkspaceCase {
                name: format!("R-R-P shell, h = {h}"),
                description: "textbook spherical R-R-P: volume of the shell sector r ∈ [0.6, 1.5] m, elevation [−45°, 60°], azimuth [−170°, 170°]".into(),
                truth,
                unit: "m³",
                voxel: h,
            },
            crate::studies::tradeoffs::bundled_robots::bundled_robot("textbook_spherical_rrp.toml")?,
        ));
    }
    let mut rows = Vec::new();
    for (case, model) in &cases {
        for sampling in [Sampling::Random, Sampling::Sobol] {
            for &k in &cfg.exponents {
                let samples = (cfg.replicates as u64) << k;
                opts.say(format!(
                    "workspace: {} {sampling:?} N = {samples}",
                    case.name
                ));
                let (mut err, mut raw, mut se, mut band, mut times) =
                    (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
                let (mut converged, mut covered) = (0usize, 0usize);
                for s in 0..cfg.seeds {
                    let o = WorkspaceOptions {
                        samples,
                        replicates: cfg.replicates,
                        sampling,
                        seed: opts.seed.wrapping_add(1000 * s as u64 + u64::from(k)),
                        voxel: case.voxel,
                        extras: false,
                        quiet: true,
                        ..Default::default()
                    };
                    let r = sample_workspace(model, &o).map_err(|e| e.to_string())?;
                    err.push((r.measure() - case.truth).abs());
                    raw.push((r.pooled - case.truth).abs());
                    se.push(r.measure_stderr());
                    let w = match r.measure_interval() {
                        [Some(lo), Some(hi)] => 0.5 * (hi - lo),
                        _ => f64::INFINITY,
                    };
                    band.push(w);
                    if w.is_finite() {
                        converged += 1;
                        covered += usize::from(r.interval_covers(case.truth));
                    }
                    times.push(r.time_s);
                }
                let n = cfg.seeds.max(1) as f64;
                let mean = |v: &[f64]| v.iter().sum::<f64>() / n;
                rows.push(WorkspaceRow {
                    case: case.name.clone(),
                    sampling,
                    samples,
                    seeds: cfg.seeds,
                    mean_abs_error: mean(&err),
                    mean_rel_error: mean(&err) / case.truth,
                    mean_rel_error_raw: mean(&raw) / case.truth,
                    mean_stderr: mean(&se),
                    median_band: median_with_inf(&band),
                    converged_fraction: converged as f64 / n,
                    covered_fraction: (converged > 0).then(|| covered as f64 / converged as f64),
                    time_s: Stats::of(&times),
                });
            }
        }
    }
    Ok(WorkspaceStudy {
        cases: cases.into_iter().map(|(c, _)| c).collect(),
        replicates: cfg.replicates,
        threads: rayon::current_num_threads(),
        rows,
        convergence: convergence_run(opts, cfg.convergence_samples)?,
    })
}

/// Median that keeps infinities (upper median for even counts).
fn median_with_inf(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
