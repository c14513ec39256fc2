//! `armsim workspace`: the reachable workspace of a link (volume or area with its 95 %
//! interval, or a lower bound when under-sampled; boundary, extras), and its CSV, MCAP and Rerun
//! outputs.

use crate::cli::scenario_cmd::need_rerun;
use crate::cli::{link_id, load, print_json, ModelArgs};
use armsim::model::Model;
use serde_json::json;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct WorkspaceArgs {
    #[command(flatten)]
    pub m: ModelArgs,
    /// The link whose origin is sampled (default: the deepest link).
    #[arg(long)]
    pub link: Option<String>,
    /// Number of joint-space samples (split into replicates; in adaptive mode the
    /// first budget tried).
    #[arg(long, default_value_t = 1 << 22)]
    pub samples: u64,
    /// Adaptive mode: double the samples until the interval's half-width is at most
    /// this fraction of the estimate (e.g. 0.01), within --max-samples.
    #[arg(long)]
    pub target_rel_error: Option<f64>,
    /// Adaptive mode: the most samples to draw (default 2^30).
    #[arg(long)]
    pub max_samples: Option<u64>,
    /// Voxel edge (m).
    #[arg(long, default_value_t = 0.02)]
    pub voxel: f64,
    /// Sampling: random or sobol (scrambled).
    #[arg(long, default_value = "sobol")]
    pub method: String,
    /// Independent replicates for the standard error.
    #[arg(long, default_value_t = 8)]
    pub replicates: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Run even when the samples drawn exceed the work budget (2^32 samples).
    #[arg(long)]
    pub force: bool,
    /// Also manipulability, condition number and dexterity per voxel.
    #[arg(long)]
    pub extras: bool,
    /// Write the sampled tool points as CSV (atomically).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write a Rerun file (.rrd): the reachable boundary and a section through the
    /// base coloured by manipulability, the robot inside, the sampled points hidden.
    #[arg(long)]
    pub rerun: Option<PathBuf>,
}

/// `armsim workspace`.
pub fn run(a: &WorkspaceArgs) -> Result<(), String> {
    use armsim::workspace::{sample_workspace, Sampling, WorkspaceOptions};
    let model = &load(&a.m)?;
    let (link, samples, voxel, method) = (a.link.clone(), a.samples, a.voxel, a.method.as_str());
    let (replicates, seed, extras, as_json) = (a.replicates, a.seed, a.extras, a.m.json);
    let (out, rerun) = (a.out.clone(), a.rerun.clone());
    if let Some(p) = &rerun {
        need_rerun()?;
        check_output_dir(p)?;
    }
    if let Some(l) = &link {
        link_id(model, l)?;
    }
    if !(voxel > 0.0 && voxel.is_finite()) {
        return Err(format!("--voxel: {voxel} is not a positive length"));
    }
    if let Some(t) = a.target_rel_error {
        if !(t > 0.0 && t < 1.0) {
            return Err(format!(
                "--target-rel-error: {t} is not a fraction in (0, 1)"
            ));
        }
    }
    if samples == 0 || replicates < 2 {
        return Err(
            "--samples must be positive and --replicates at least 2 (for the standard error)"
                .into(),
        );
    }
    check_budget(a)?;
    let sampling: Sampling = method.parse().map_err(|e| format!("--method: {e}"))?;
    let opts = WorkspaceOptions {
        samples,
        target_rel_error: a.target_rel_error,
        max_samples: Some(a.max_samples.unwrap_or(DEFAULT_MAX_SAMPLES)),
        replicates,
        sampling,
        seed,
        voxel,
        tool: link,
        extras,
        keep_points: if out.is_some() || rerun.is_some() {
            200_000
        } else {
            0
        },
        quiet: as_json,
        ..Default::default()
    };
    let r = sample_workspace(model, &opts).map_err(|e| format!("{}: {e}", model.source))?;
    let mut written = Vec::new();
    if let Some(p) = &out {
        if p.extension().and_then(|e| e.to_str()) == Some("mcap") {
            write_workspace_mcap(model, &r, p)?;
        } else {
            r.write_points_csv(p)
                .map_err(|e| format!("{}: cannot write: {e}", p.display()))?;
        }
        written.push(p.display().to_string());
    }
    if let Some(p) = &rerun {
        workspace_rerun(model, &r, p)?;
        written.push(p.display().to_string());
    }
    if as_json {
        let mut v = serde_json::to_value(&r).map_err(|e| e.to_string())?;
        v["outputs"] = json!(written);
        print_json(&v);
        return Ok(());
    }
    println!(
        "{} workspace of '{}' ({} samples in {} replicates, {:?} sampling, voxel {} m, {:.2} s)",
        r.robot, r.tool, r.samples, r.replicates, r.sampling, r.voxel, r.time_s
    );
    for line in armsim::workspace::summary_lines(&r) {
        println!("{line}");
    }
    println!(
        "boundary voxels {}, occupied {}",
        r.boundary_voxels, r.occupied_voxels
    );
    println!(
        "bounding box [{:.4}, {:.4}, {:.4}] – [{:.4}, {:.4}, {:.4}]",
        r.bbox[0][0], r.bbox[0][1], r.bbox[0][2], r.bbox[1][0], r.bbox[1][1], r.bbox[1][2]
    );
    for w in &r.warnings {
        println!("warning: {w}");
    }
    for p in written {
        println!("wrote {p}");
    }
    Ok(())
}

/// The sampled workspace as an MCAP recording: the robot (description, static tf, one
/// frame at the neutral configuration) and the kept tool points as a
/// `sensor_msgs/PointCloud2` with the manipulability of each point.
fn write_workspace_mcap(
    model: &Model,
    r: &armsim::workspace::WorkspaceResult,
    path: &std::path::Path,
) -> Result<(), String> {
    use armsim::io::record::mcap_out::McapWriter;
    use armsim::io::record::{Header, PointCloud};
    let src = std::path::Path::new(&model.source);
    let spec = Model::read_spec(src).map_err(|e| e.to_string())?;
    let name = format!("{}_workspace", model.name);
    let (header, tf) = Header::for_model(&name, src, model, &spec);
    let err = |e: armsim::io::record::record_error::RecordError| e.to_string();
    let mut w = McapWriter::create(path, &header).map_err(err)?;
    let mut data = armsim::model::data::Data::new(model);
    let q = model.neutral();
    let frame = tf.frame_at(model, &mut data, 0.0, &q, &[], &[]);
    w.write_frame(&frame).map_err(err)?;
    let values: Vec<f32> = r.points.iter().map(|s| s.manipulability as f32).collect();
    let cloud = PointCloud {
        t: 0.0,
        frame: model.links[0].name.clone(),
        points: r
            .points
            .iter()
            .map(|s| [s.p[0] as f32, s.p[1] as f32, s.p[2] as f32])
            .collect(),
        values: if values.iter().all(|v| v.is_finite()) {
            values
        } else {
            Vec::new()
        },
    };
    w.write_cloud(&cloud).map_err(err)?;
    w.finish().map_err(err)?;
    Ok(())
}

/// Fails early when the directory of an output file does not exist.
fn check_output_dir(p: &std::path::Path) -> Result<(), String> {
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    if dir.is_dir() {
        Ok(())
    } else {
        Err(format!(
            "{}: directory '{}' does not exist",
            p.display(),
            dir.display()
        ))
    }
}

/// The workspace picture as an .rrd file: the reachable boundary cut away in front of a
/// section through the base, coloured by manipulability, the robot inside, the points
/// hidden (see `recording::rerun_workspace`).
fn workspace_rerun(
    model: &Model,
    r: &armsim::workspace::WorkspaceResult,
    path: &std::path::Path,
) -> Result<(), String> {
    use armsim::io::record::rerun::rerun_out;
    let sink = rerun_out::RerunSink::Save(path.to_path_buf());
    let report = rerun_out::log_workspace_scene(model, r, &sink).map_err(|e| e.to_string())?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// The most samples a workspace run draws without `--force`.
pub const MAX_SAMPLES: u64 = 1 << 32;
/// The most replicates (each keeps its own voxel grid in memory).
pub const MAX_REPLICATES: usize = 1024;

/// `--max-samples` when not given (adaptive mode).
const DEFAULT_MAX_SAMPLES: u64 = 1 << 30;

/// Refuses, before sampling, a run that would draw more than [`MAX_SAMPLES`] samples
/// (each replicate draws at least one; adaptive mode may go up to `--max-samples`) unless
/// `--force`, or that asks for more than [`MAX_REPLICATES`] replicates.
fn check_budget(a: &WorkspaceArgs) -> Result<(), String> {
    if a.replicates > MAX_REPLICATES {
        return Err(format!(
            "--replicates: {} replicates is more than the limit of {MAX_REPLICATES} (each keeps \
             its own voxel grid; 8 to 32 give a standard error)",
            a.replicates
        ));
    }
    let r = a.replicates as u64;
    if a.target_rel_error.is_none() && a.max_samples.is_some() {
        return Err(
            "--max-samples: applies to adaptive sampling only (with --target-rel-error); \
             --samples sets the count otherwise"
                .into(),
        );
    }
    let max_samples = a.max_samples.unwrap_or(DEFAULT_MAX_SAMPLES);
    if a.target_rel_error.is_some() && max_samples < a.samples.max(r) {
        return Err(format!(
            "--max-samples: {max_samples} is below the first round's {} samples: adaptive \
             sampling would stop before its first estimate",
            a.samples.max(r)
        ));
    }
    let (key, drawn) = match a.target_rel_error {
        None => ("--samples", a.samples.max(r)),
        Some(_) => ("--max-samples", max_samples.max(a.samples).max(r)),
    };
    if drawn > MAX_SAMPLES && !a.force {
        return Err(format!(
            "{key}: {} samples would be drawn, more than the budget of 2^32 = {MAX_SAMPLES} \
             (at about 10^7 samples per second, {} s): lower it, or pass --force to run it",
            a.samples.max(drawn),
            armsim::core::diag::fmt_num((drawn as f64 / 1e7).round())
        ));
    }
    Ok(())
}
