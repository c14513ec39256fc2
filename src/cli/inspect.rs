//! `armsim info`, `fk`, `jacobian`, `bench` and `chain`: the model, its placements and
//! Jacobians, timings of one algorithm, and the generated benchmark chain.

use crate::cli::{limit, link_id, load, parse_values, print_json, rows, ModelArgs};
use armsim::core::spatial::matrix_to_rpy;
use armsim::kinematics::{self, Expressed};
use armsim::model::data::Data;
use armsim::model::{chain, Model};
use armsim::studies::bench::{self, Algo};
use clap::ValueEnum;
use nalgebra::DMatrix;
use serde_json::{json, Value};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct FkArgs {
    #[command(flatten)]
    pub m: ModelArgs,
    /// Joint values, comma separated, in `armsim info` order (rad or m).
    #[arg(long, allow_hyphen_values = true)]
    pub q: String,
}

#[derive(clap::Args)]
pub struct JacobianArgs {
    #[command(flatten)]
    pub m: ModelArgs,
    /// Joint values, comma separated.
    #[arg(long, allow_hyphen_values = true)]
    pub q: String,
    /// Link whose frame's Jacobian is wanted.
    #[arg(long)]
    pub frame: String,
    /// world: world axes, world origin; local: frame axes and origin;
    /// world-aligned: world axes, frame origin.
    #[arg(long, value_enum, default_value = "world")]
    pub expressed: ExpressedArg,
    /// Joint velocities: also print the Jacobian's time derivative.
    #[arg(long, allow_hyphen_values = true)]
    pub qd: Option<String>,
}

#[derive(clap::Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub m: ModelArgs,
    /// Algorithm to time.
    #[arg(long, value_enum)]
    pub algo: AlgoArg,
    /// Number of timed calls (at most 10^9 without --force).
    #[arg(long, default_value_t = 220_000)]
    pub iters: usize,
    /// Run even when --iters exceeds the budget of 10^9 calls.
    #[arg(long)]
    pub force: bool,
}

/// The most timed calls `bench` makes without `--force`.
pub const MAX_BENCH_ITERS: usize = 1_000_000_000;

#[derive(clap::Args)]
pub struct ChainArgs {
    /// Number of joints.
    pub n: usize,
    /// Output file (default: standard output).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum ExpressedArg {
    World,
    Local,
    WorldAligned,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum AlgoArg {
    Fk,
    Jacobians,
    Rnea,
    /// RNEA on batches of states, eight at a time in SIMD lanes (time per state).
    RneaBatch,
    Crba,
    /// CRBA on batches of states, eight at a time in SIMD lanes (time per state).
    CrbaBatch,
    Aba,
    /// ABA on batches of states, eight at a time in SIMD lanes (time per state).
    AbaBatch,
    Lagrange,
}

/// `armsim info`.
pub fn info_cmd(m: &ModelArgs) -> Result<(), String> {
    info(&load(m)?, m.json)
}

/// `armsim fk`.
pub fn fk_cmd(a: &FkArgs) -> Result<(), String> {
    fk(&load(&a.m)?, &a.q, a.m.json)
}

/// `armsim jacobian`.
pub fn jacobian_cmd(a: &JacobianArgs) -> Result<(), String> {
    jacobian(
        &load(&a.m)?,
        &a.q,
        &a.frame,
        a.expressed,
        a.qd.as_deref(),
        a.m.json,
    )
}

/// `armsim bench`.
pub fn bench_run(a: &BenchArgs) -> Result<(), String> {
    if a.iters > MAX_BENCH_ITERS && !a.force {
        return Err(format!(
            "--iters: {} calls is more than the budget of 10^9: lower it, or pass --force to run it",
            a.iters
        ));
    }
    bench_cmd(&load(&a.m)?, a.algo, a.iters, a.m.json)
}

/// `armsim chain`: the generated N-joint chain as URDF.
pub fn chain_cmd(a: &ChainArgs) -> Result<(), String> {
    let n = a.n;
    if n == 0 || n > 1_000_000 {
        return Err(format!("chain: N must be between 1 and 1000000, got {n}"));
    }
    let text = chain::chain_urdf(n);
    match &a.out {
        None => {
            print!("{text}");
            Ok(())
        }
        Some(p) => armsim::core::files::write_atomic(p, text.as_bytes())
            .map_err(|e| format!("{}: cannot write: {e}", p.display())),
    }
}

fn info(model: &Model, as_json: bool) -> Result<(), String> {
    let movable: Vec<_> = model
        .joints
        .iter()
        .filter(|j| j.jtype.is_movable())
        .collect();
    if as_json {
        let joints: Vec<Value> = movable
            .iter()
            .map(|j| {
                let mut o = json!({
                    "name": j.name,
                    "type": j.jtype.as_str(),
                    "parent": model.links[j.parent_link].name,
                    "child": model.links[j.child_link].name,
                    "lower": limit(j.limits.lower),
                    "upper": limit(j.limits.upper),
                    "velocity": limit(j.limits.velocity),
                    "effort": limit(j.limits.effort),
                });
                if let Some((master, mult, off)) = j.mimic {
                    o["mimic"] = json!({
                        "joint": model.joints[master].name,
                        "multiplier": mult,
                        "offset": off,
                    });
                }
                o
            })
            .collect();
        let fixed: Vec<Value> = model
            .joints
            .iter()
            .filter(|j| !j.jtype.is_movable())
            .map(|j| {
                json!({
                    "name": j.name,
                    "parent": model.links[j.parent_link].name,
                    "child": model.links[j.child_link].name,
                })
            })
            .collect();
        print_json(&json!({
            "name": model.name,
            "source": model.source,
            "dof": model.nv,
            "coordinates": model.dof_names(),
            "links": model.links.iter().map(|l| l.name.as_str()).collect::<Vec<_>>(),
            "joints": joints,
            "fixed_joints": fixed,
        }));
        return Ok(());
    }
    println!("model   {} ({})", model.name, model.source);
    println!("dof     {}", model.nv);
    println!("links   {}", model.links.len());
    println!(
        "{:<4} {:<24} {:<10} {:<20} {:<20} {:>10} {:>10} {:>9} {:>9}",
        "#", "joint", "type", "parent", "child", "lower", "upper", "velocity", "effort"
    );
    for j in &movable {
        let idx = j.dof.map(|d| d.to_string()).unwrap_or_else(|| "-".into());
        print!(
            "{:<4} {:<24} {:<10} {:<20} {:<20} {:>10.4} {:>10.4} {:>9.3} {:>9.2}",
            idx,
            j.name,
            j.jtype.as_str(),
            model.links[j.parent_link].name,
            model.links[j.child_link].name,
            j.limits.lower,
            j.limits.upper,
            j.limits.velocity,
            j.limits.effort
        );
        if let Some((master, mult, off)) = j.mimic {
            print!("  mimic {} × {mult} + {off}", model.joints[master].name);
        }
        println!();
    }
    let nfixed = model.joints.len() - movable.len();
    if nfixed > 0 {
        println!("({nfixed} fixed joints folded away; their links stay queryable frames)");
    }
    Ok(())
}

fn fk(model: &Model, q: &str, as_json: bool) -> Result<(), String> {
    let q = parse_values(model, "q", q)?;
    if !model.within_limits(&q, 1e-12) {
        eprintln!("warning: q is outside the joint limits");
    }
    let mut data = Data::new(model);
    kinematics::forward_kinematics(model, &mut data, &q);
    kinematics::update_frames(model, &mut data);
    if as_json {
        let mut frames = serde_json::Map::new();
        for (l, link) in model.links.iter().enumerate() {
            let t = &data.o_m_f[l];
            frames.insert(
                link.name.clone(),
                json!({"translation": [t.trans.x, t.trans.y, t.trans.z], "rotation": t.rotation_rows()}),
            );
        }
        print_json(&json!({"joints": model.dof_names(), "frames": frames}));
        return Ok(());
    }
    println!(
        "{:<24} {:>12} {:>12} {:>12} {:>10} {:>10} {:>10}",
        "link", "x (m)", "y (m)", "z (m)", "roll", "pitch", "yaw"
    );
    for (l, link) in model.links.iter().enumerate() {
        let t = &data.o_m_f[l];
        let rpy = matrix_to_rpy(&t.rot);
        // `+ 0.0` turns -0.0 into 0.0 for display.
        println!(
            "{:<24} {:>12.6} {:>12.6} {:>12.6} {:>10.5} {:>10.5} {:>10.5}",
            link.name,
            t.trans.x + 0.0,
            t.trans.y + 0.0,
            t.trans.z + 0.0,
            rpy[0] + 0.0,
            rpy[1] + 0.0,
            rpy[2] + 0.0
        );
    }
    Ok(())
}

fn jacobian(
    model: &Model,
    q: &str,
    frame: &str,
    expressed: ExpressedArg,
    qd: Option<&str>,
    as_json: bool,
) -> Result<(), String> {
    let q = parse_values(model, "q", q)?;
    let qd = qd.map(|s| parse_values(model, "qd", s)).transpose()?;
    let link = link_id(model, frame)?;
    let expressed = match expressed {
        ExpressedArg::World => Expressed::World,
        ExpressedArg::Local => Expressed::Local,
        ExpressedArg::WorldAligned => Expressed::WorldAligned,
    };
    let mut data = Data::new(model);
    let mut j = DMatrix::zeros(6, model.nv);
    let mut dj = DMatrix::zeros(6, model.nv);
    match &qd {
        Some(qd) => {
            kinematics::compute_joint_jacobians_time_variation(model, &mut data, &q, qd);
            kinematics::frame_jacobian_time_variation(model, &data, link, expressed, &mut dj);
        }
        None => kinematics::compute_joint_jacobians(model, &mut data, &q),
    }
    kinematics::frame_jacobian(model, &data, link, expressed, &mut j);
    let translational = j.rows(0, 3).into_owned();
    let manip = kinematics::manipulability(&j);
    let cond = kinematics::condition_number(&translational);
    if as_json {
        let mut o = json!({
            "joints": model.dof_names(),
            "frame": frame,
            "expressed": expressed.as_str(),
            "jacobian": rows(&j),
            "manipulability": manip,
            "condition_number_translational": limit(cond),
        });
        if qd.is_some() {
            o["jacobian_dot"] = json!(rows(&dj));
        }
        print_json(&o);
        return Ok(());
    }
    println!(
        "Jacobian of '{frame}' ({}), rows vx vy vz wx wy wz; columns {}",
        expressed.as_str(),
        model.dof_names().join(" ")
    );
    let print = |m: &DMatrix<f64>| {
        for (r, label) in ["vx", "vy", "vz", "wx", "wy", "wz"].iter().enumerate() {
            print!("{label:>3}");
            for c in 0..m.ncols() {
                print!(" {:>11.6}", m[(r, c)]);
            }
            println!();
        }
    };
    print(&j);
    if qd.is_some() {
        println!("time derivative:");
        print(&dj);
    }
    println!("manipulability {manip:.6e}, translational condition number {cond:.6e}");
    Ok(())
}

fn bench_cmd(model: &Model, algo: AlgoArg, iters: usize, as_json: bool) -> Result<(), String> {
    if iters == 0 {
        return Err("--iters must be positive".into());
    }
    if matches!(algo, AlgoArg::Crba | AlgoArg::CrbaBatch | AlgoArg::Lagrange)
        || (matches!(algo, AlgoArg::Aba | AlgoArg::AbaBatch) && model.has_mimic)
    {
        armsim::model::data::dense_fits(model).map_err(|m| format!("{}: {m}", model.source))?;
    }
    let algo = match algo {
        AlgoArg::Fk => Algo::Fk,
        AlgoArg::Jacobians => Algo::Jacobians,
        AlgoArg::Rnea => Algo::Rnea,
        AlgoArg::RneaBatch => Algo::RneaBatch,
        AlgoArg::Crba => Algo::Crba,
        AlgoArg::CrbaBatch => Algo::CrbaBatch,
        AlgoArg::Lagrange => Algo::Lagrange,
        AlgoArg::Aba | AlgoArg::AbaBatch => {
            if model.has_mimic {
                return Err(format!(
                    "{}: ABA needs one coordinate per joint but the model has mimic joints; use --ignore-mimic",
                    model.source
                ));
            }
            if matches!(algo, AlgoArg::AbaBatch) {
                Algo::AbaBatch
            } else {
                Algo::Aba
            }
        }
    };
    let ns = bench::ns_per_call(model, algo, iters);
    if as_json {
        print_json(&json!({
            "model": model.name,
            "algo": algo.as_str(),
            "dof": model.nv,
            "ns_per_call": ns,
            "iters": iters,
        }));
    } else {
        // A batched "call" is one state of a SIMD pass over eight.
        let unit = if algo.is_batch() { "state" } else { "call" };
        println!(
            "{} {} (dof {}): {:.1} ns per {unit} (median of {} rounds, {} {unit}s)",
            model.name,
            algo.as_str(),
            model.nv,
            ns,
            bench::ROUNDS,
            iters
        );
    }
    Ok(())
}
