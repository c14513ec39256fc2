//! `armsim srdf`: the allowed-collision matrix of a model, computed as MoveIt's Setup
//! Assistant computes one ([`armsim::planning::acm`]), written as an SRDF with the reason
//! of every disabled pair, for `armsim plan --srdf` or for MoveIt.

use armsim::planning::{PairSource, PlanOptions, PlanningRobot};
use std::path::PathBuf;

/// Arguments of `armsim srdf`.
#[derive(clap::Args, Debug)]
pub struct SrdfArgs {
    /// Robot model (URDF).
    pub model: PathBuf,
    /// Write the SRDF to this file (atomically) instead of standard output.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seed of the random configurations.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Overshoot of the sphere cover that decides the never-colliding pairs (m).
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    pub max_overshoot: f64,
    /// Print the pairs and their reasons as JSON instead of the SRDF.
    #[arg(long)]
    pub json: bool,
    /// Treat model warnings as errors.
    #[arg(long)]
    pub strict: bool,
    /// Random configurations that decide the never-colliding pairs (MoveIt's Setup
    /// Assistant's sampling density; 1 to 10^6). Pairs × samples is bounded by a budget of
    /// 2·10^8 pair tests without --force.
    #[arg(long, default_value_t = 10_000)]
    pub samples: usize,
    /// Sample a model whose pairs × samples is over the budget of 2·10^8 pair tests.
    #[arg(long)]
    pub force: bool,
}

/// The most `--samples` accepted (MoveIt's Setup Assistant's density slider stops at
/// 100 000).
const MAX_SAMPLES: usize = 1_000_000;

/// Runs the command; returns what goes to standard output (empty with `--out`).
pub fn run(a: &SrdfArgs) -> Result<String, String> {
    let (lo, hi) = armsim::planning::spheres::OVERSHOOT_RANGE;
    if !(a.max_overshoot.is_finite() && a.max_overshoot >= lo && a.max_overshoot <= hi) {
        return Err(format!(
            "--max-overshoot: expected {lo} to {hi} m, got {}",
            a.max_overshoot
        ));
    }
    if a.samples == 0 || a.samples > MAX_SAMPLES {
        return Err(format!(
            "--samples: expected 1 to {MAX_SAMPLES} configurations, got {}",
            a.samples
        ));
    }
    let model = crate::cli::plan_cmd::load_model(&a.model, a.strict)?;
    armsim::core::interrupt::install().map_err(|e| e.to_string())?;
    let mut opts = PlanOptions {
        seed: a.seed,
        stop: Some(armsim::core::interrupt::flag()),
        acm_samples: a.samples,
        acm_max_pair_tests: (!a.force).then_some(armsim::planning::acm::MAX_PAIR_TESTS),
        ..Default::default()
    };
    opts.spheres.max_overshoot = a.max_overshoot;
    let robot = PlanningRobot::new(&model, None, &opts).map_err(|e| match e {
        armsim::planning::plan_error::PlanSetupError::AcmOverBudget { problem, .. } => format!(
            "{}: {problem}: lower --samples, or pass --force to run it",
            a.model.display()
        ),
        e => format!("{}: {e}", a.model.display()),
    })?;
    if let Some(w) = robot.spheres.warnings.first().filter(|_| a.strict) {
        // A collision mesh left out of the sphere model leaves its link unprotected.
        return Err(format!("{}: --strict: {w}", a.model.display()));
    }
    for w in &robot.spheres.warnings {
        eprintln!("warning: {}: {w}", a.model.display());
    }
    let PairSource::Computed(acm) = &robot.pair_source else {
        return Err("internal: no matrix was computed".into());
    };
    eprintln!(
        "note: {}",
        crate::cli::plan_cmd::acm_note(acm, robot.setup_time_s)
    );
    let text = if a.json {
        let v = serde_json::json!({
            "model": model.name,
            "source": a.model.display().to_string(),
            "samples": acm.samples,
            "exact_geometry": acm.exact,
            "disabled": acm.disabled,
            "checked": acm.checked,
            "setup_s": robot.setup_time_s,
        });
        serde_json::to_string_pretty(&v).map_err(|e| e.to_string())? + "\n"
    } else {
        acm.to_srdf(&model.name)
    };
    crate::cli::plan_cmd::write_or_return(a.out.as_deref(), text)
}
