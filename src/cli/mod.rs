//! The commands of the `armsim` binary, one file per command group; `src/main.rs` holds
//! the clap structs' dispatch. Every command reads its clap `Args` struct directly.
//!
//! - [`inspect`] holds `info`, `fk`, `jacobian`, `bench` and `chain`;
//! - [`dynamics`] holds `dynamics`;
//! - [`ik`] holds `ik` (numeric and analytic);
//! - [`workspace`] holds `workspace`;
//! - [`scenario`] holds `run`, `view` and `tradeoffs`;
//! - [`plan`] (with [`plan_report`]) holds `plan`.

pub mod ik_cmd;
pub mod plan_cmd;
pub mod plan_report;
pub mod plan_scenario;
pub mod scenario_cmd;
pub mod srdf_cmd;
pub mod workspace_cmd;

// Standard output is collected and written once at the end, so that a closed pipe
// (`armsim info big.urdf | head`) ends the program quietly instead of panicking in
// `println!`. These shadow the std macros for the
// command modules declared below them (and for main.rs).
thread_local! {
    pub(crate) static OUT: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

macro_rules! println {
    () => {
        $crate::cli::OUT.with(|o| o.borrow_mut().push('\n'))
    };
    ($($t:tt)*) => {
        $crate::cli::OUT.with(|o| {
            use std::fmt::Write as _;
            let _ = writeln!(o.borrow_mut(), $($t)*);
        })
    };
}

macro_rules! print {
    ($($t:tt)*) => {
        $crate::cli::OUT.with(|o| {
            use std::fmt::Write as _;
            let _ = write!(o.borrow_mut(), $($t)*);
        })
    };
}

pub mod dynamics;
pub mod inspect;

use armsim::model::{LoadOptions, Model};
use nalgebra::DMatrix;
use serde_json::{json, Value};
use std::path::PathBuf;

/// Writes the collected output; a closed pipe is not an error.
pub fn flush_stdout() -> Result<(), String> {
    use std::io::Write as _;
    let text = OUT.with(|o| std::mem::take(&mut *o.borrow_mut()));
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(format!("cannot write output: {e}"))
        }
        _ => Ok(()),
    }
}

#[derive(clap::Args)]
pub struct ModelArgs {
    /// Model file: URDF (.urdf) or DH table (.toml).
    pub model: PathBuf,
    /// Treat model warnings (e.g. an inertia breaking the triangle inequality) as errors.
    #[arg(long)]
    pub strict: bool,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Treat mimic joints as independent coordinates (Pinocchio's default).
    #[arg(long)]
    pub ignore_mimic: bool,
}

pub fn load(m: &ModelArgs) -> Result<Model, String> {
    let opts = LoadOptions {
        strict: m.strict,
        ignore_mimic: m.ignore_mimic,
    };
    let (model, warnings) = Model::load_with(&m.model, &opts).map_err(|e| e.to_string())?;
    for w in warnings {
        eprintln!("warning: {w}");
    }
    Ok(model)
}

/// Parses `v1,v2,…` into exactly `model.nv` finite numbers.
pub fn parse_values(model: &Model, what: &str, s: &str) -> Result<Vec<f64>, String> {
    let vals: Vec<f64> = if s.trim().is_empty() {
        Vec::new()
    } else {
        s.split(',')
            .map(|t| {
                let t = t.trim();
                match t.parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(x),
                    Ok(_) => Err(format!("--{what}: '{t}' is not a finite number")),
                    Err(_) => Err(format!("--{what}: '{t}' is not a number")),
                }
            })
            .collect::<Result<_, _>>()?
    };
    if vals.len() != model.nv {
        return Err(format!(
            "--{what}: expected {} values (joints {}), got {}",
            model.nv,
            model.dof_names().join(", "),
            vals.len()
        ));
    }
    Ok(vals)
}

pub fn link_id(model: &Model, name: &str) -> Result<usize, String> {
    model.link_id(name).ok_or_else(|| {
        let names: Vec<&str> = model.links.iter().map(|l| l.name.as_str()).collect();
        format!(
            "{}: link '{name}' does not exist (links: {})",
            model.source,
            names.join(", ")
        )
    })
}

pub fn print_json(v: &Value) {
    println!("{}", serde_json::to_string_pretty(v).unwrap_or_default());
}

pub fn limit(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

pub fn rows(j: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..j.nrows())
        .map(|r| (0..j.ncols()).map(|c| j[(r, c)]).collect())
        .collect()
}
