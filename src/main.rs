//! `armsim` command-line tool: a thin layer over the library. Every command exits
//! non-zero with a message naming the file, the element and the problem on bad input,
//! and never panics on user input.

mod cli;

use armsim::bench::{self, Algo};
use armsim::data::Data;
use armsim::dynamics::{self, Effects, Friction, Payload, Rotor};
use armsim::kinematics::{self, Expressed};
use armsim::model::{chain, LoadOptions, Model};
use armsim::spatial::{matrix_to_rpy, Inertia, Mat3, Se3, Vec3};
use clap::{Parser, Subcommand, ValueEnum};
use nalgebra::DMatrix;
use serde_json::{json, Value};
use std::path::PathBuf;
use std::process::ExitCode;

// Standard output is collected and written once at the end, so that a closed pipe
// (`armsim info big.urdf | head`) ends the program quietly instead of panicking in
// `println!`. These shadow the std macros for this file.
thread_local! {
    static OUT: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

macro_rules! println {
    () => {
        OUT.with(|o| o.borrow_mut().push('\n'))
    };
    ($($t:tt)*) => {
        OUT.with(|o| {
            use std::fmt::Write as _;
            let _ = writeln!(o.borrow_mut(), $($t)*);
        })
    };
}

macro_rules! print {
    ($($t:tt)*) => {
        OUT.with(|o| {
            use std::fmt::Write as _;
            let _ = write!(o.borrow_mut(), $($t)*);
        })
    };
}

/// Writes the collected output; a closed pipe is not an error.
fn flush_stdout() -> Result<(), String> {
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

#[derive(Parser)]
#[command(
    name = "armsim",
    version,
    about = "Robot manipulator kinematics and dynamics"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(clap::Args)]
struct ModelArgs {
    /// Model file: URDF (.urdf) or DH table (.toml).
    model: PathBuf,
    /// Treat model warnings (e.g. an inertia breaking the triangle inequality) as errors.
    #[arg(long)]
    strict: bool,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Treat mimic joints as independent coordinates (Pinocchio's default).
    #[arg(long)]
    ignore_mimic: bool,
}

#[derive(Subcommand)]
enum Cmd {
    /// Name, DOF, links and joints in the joint order every other command uses.
    Info {
        #[command(flatten)]
        m: ModelArgs,
    },
    /// World placement of every link frame at configuration q.
    Fk {
        #[command(flatten)]
        m: ModelArgs,
        /// Joint values, comma separated, in `armsim info` order (rad or m).
        #[arg(long, allow_hyphen_values = true)]
        q: String,
    },
    /// Geometric Jacobian of a link frame (rows: linear x y z, angular x y z).
    Jacobian {
        #[command(flatten)]
        m: ModelArgs,
        /// Joint values, comma separated.
        #[arg(long, allow_hyphen_values = true)]
        q: String,
        /// Link whose frame's Jacobian is wanted.
        #[arg(long)]
        frame: String,
        /// world: world axes, world origin; local: frame axes and origin;
        /// world-aligned: world axes, frame origin.
        #[arg(long, value_enum, default_value = "world")]
        expressed: ExpressedArg,
        /// Joint velocities: also print the Jacobian's time derivative.
        #[arg(long, allow_hyphen_values = true)]
        qd: Option<String>,
    },
    /// Joint torques, mass matrix, bias, gravity torques and energies at (q, v, a); with
    /// --tau also the forward-dynamics accelerations.
    Dynamics {
        #[command(flatten)]
        m: ModelArgs,
        /// Joint positions, comma separated.
        #[arg(long, allow_hyphen_values = true)]
        q: String,
        /// Joint velocities (default zeros).
        #[arg(long, allow_hyphen_values = true)]
        v: Option<String>,
        /// Joint accelerations (default zeros).
        #[arg(long, allow_hyphen_values = true)]
        a: Option<String>,
        /// Joint torques: also compute q̈ by forward dynamics.
        #[arg(long, allow_hyphen_values = true)]
        tau: Option<String>,
        /// Gravity vector x,y,z (default: the model's, (0, 0, -9.81)).
        #[arg(long, allow_hyphen_values = true)]
        gravity: Option<String>,
        /// Include joint friction from the model file (<dynamics damping friction>).
        #[arg(long)]
        friction: bool,
        /// Include rotor inertia and gearing from the model file (motor_inertia, gear_ratio).
        #[arg(long)]
        rotor: bool,
        /// Gear efficiency for --rotor, in (0, 1].
        #[arg(long, default_value_t = 1.0)]
        efficiency: f64,
        /// Payload: LINK,MASS[,cx,cy,cz] (point mass at the COM in the link frame).
        #[arg(long, allow_hyphen_values = true)]
        payload: Option<String>,
        /// Formulation for tau: rnea (default), lagrange-trace or lagrange-energy (slow
        /// references; rigid model with gravity only).
        #[arg(long, value_enum, default_value = "rnea")]
        method: MethodArg,
    },
    /// Inverse kinematics of a link frame for one target pose or a CSV file of targets.
    Ik {
        #[command(flatten)]
        m: ModelArgs,
        /// The link whose frame should reach the target.
        #[arg(long)]
        link: String,
        /// Target x,y,z,qw,qx,qy,qz (world frame; quaternion w first).
        #[arg(long, allow_hyphen_values = true)]
        target: Option<String>,
        /// CSV file of targets, rows x,y,z,qw,qx,qy,qz (an optional header row).
        #[arg(long)]
        targets: Option<PathBuf>,
        /// Position only (the quaternion, if given, is ignored).
        #[arg(long)]
        position_only: bool,
        /// Tolerance for position (m) and rotation (rad).
        #[arg(long, default_value_t = 1e-6)]
        tol: f64,
        /// Start configuration (default: the middle of the limits).
        #[arg(long, allow_hyphen_values = true)]
        seed_q: Option<String>,
        /// Random restarts allowed per target.
        #[arg(long, default_value_t = 200)]
        restarts: usize,
        /// Time budget per target (ms).
        #[arg(long, default_value_t = 50.0)]
        budget_ms: f64,
        /// Let iterates leave the joint limits.
        #[arg(long)]
        no_limits: bool,
        /// Closed-form IK (UR family, spherical-wrist 6R, textbook R-R-P, planar 2R): every
        /// branch inside the limits; `q` is the branch nearest the start configuration.
        #[arg(long)]
        analytic: bool,
    },
    /// Reachable workspace of a link: voxel volume (or area for planar arms) with its
    /// standard error and voxel-size bias, boundary, manipulability, dexterity.
    Workspace {
        #[command(flatten)]
        m: ModelArgs,
        /// The link whose origin is sampled (default: the deepest link).
        #[arg(long)]
        link: Option<String>,
        /// Number of joint-space samples (split into replicates).
        #[arg(long, default_value_t = 1 << 22)]
        samples: u64,
        /// Voxel edge (m).
        #[arg(long, default_value_t = 0.02)]
        voxel: f64,
        /// Sampling: random or sobol (scrambled).
        #[arg(long, default_value = "sobol")]
        method: String,
        /// Independent replicates for the standard error.
        #[arg(long, default_value_t = 8)]
        replicates: usize,
        /// Seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Also manipulability, condition number and dexterity per voxel.
        #[arg(long)]
        extras: bool,
        /// Write the sampled tool points as CSV (atomically).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write a Rerun file (.rrd): the reachable boundary and a section through the
        /// base coloured by manipulability, the robot inside, the sampled points hidden.
        #[arg(long)]
        rerun: Option<PathBuf>,
    },
    /// Show a recording (MCAP) in Rerun: write an .rrd file, or spawn the viewer (the
    /// `rerun` program on PATH, from `pip install rerun-sdk==0.36.3`).
    View {
        /// Recording file (.mcap).
        recording: PathBuf,
        /// Write a Rerun file (.rrd) instead of spawning the viewer.
        #[arg(long, conflicts_with = "spawn")]
        save: Option<PathBuf>,
        /// Spawn the Rerun viewer and stream to it (the default without --save).
        #[arg(long)]
        spawn: bool,
        /// Model file for the geometry (default: the URDF stored in the recording).
        #[arg(long)]
        model: Option<PathBuf>,
        /// Directory mesh URIs are resolved from (default: the model file's directory).
        #[arg(long)]
        mesh_dir: Option<PathBuf>,
    },
    /// Run a scenario file end to end and print its summary (or JSON).
    Run {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Directory for output files.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
        /// Exit with status 2 when the verdict is not ok (limits exceeded or a collision).
        #[arg(long)]
        check: bool,
        /// Also log the run to Rerun: save this .rrd file (arm scenarios).
        #[arg(long, conflicts_with = "spawn")]
        rerun: Option<PathBuf>,
        /// Also log the run to a spawned Rerun viewer (arm scenarios).
        #[arg(long)]
        spawn: bool,
        /// Directory searched first for `package://` mesh URIs: one containing packages,
        /// or a package itself (repeatable; then the scenario's `model.package_path`,
        /// ROS_PACKAGE_PATH, AMENT_PREFIX_PATH and the model file's folder tree).
        #[arg(long = "package-path", value_name = "DIR")]
        package_path: Vec<PathBuf>,
        /// Keep the mesh URIs of the recording's robot description as the model file
        /// writes them (default: absolute file:// URIs of the files found here).
        #[arg(long)]
        keep_mesh_uris: bool,
    },
    /// Time one algorithm (median ns per call over random states inside the limits).
    Bench {
        #[command(flatten)]
        m: ModelArgs,
        /// Algorithm to time.
        #[arg(long, value_enum)]
        algo: AlgoArg,
        /// Number of timed calls.
        #[arg(long, default_value_t = 220_000)]
        iters: usize,
    },
    /// Measure the trade-offs report: IK tolerance × method, integrator step × method,
    /// dynamics formulations vs DOF, workspace samples × scheme, cost of each effect.
    /// Writes DIR/tradeoffs.md, DIR/tradeoffs.json and the plots (DIR/*.png).
    Tradeoffs {
        /// Output directory.
        #[arg(long, default_value = "tradeoffs")]
        out: PathBuf,
        /// Reduced sizes (about 3 minutes on 2 cores instead of about 20).
        #[arg(long)]
        quick: bool,
        /// Smoke-test sizes (seconds; coarse numbers). For the tests.
        #[arg(long, hide = true, conflicts_with = "quick")]
        tiny: bool,
        /// No progress lines on standard error.
        #[arg(long)]
        quiet: bool,
    },
    /// Plan collision-free motions (RRT-Connect on the robot's collision spheres) for MoveIt
    /// problems: one scene + request, or every pair of benchmark folders.
    Plan(cli::plan::PlanArgs),
    /// Write the generated N-joint benchmark chain as URDF.
    Chain {
        /// Number of joints.
        n: usize,
        /// Output file (default: standard output).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum ExpressedArg {
    World,
    Local,
    WorldAligned,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MethodArg {
    Rnea,
    LagrangeTrace,
    LagrangeEnergy,
}

#[derive(Clone, Copy, ValueEnum)]
enum AlgoArg {
    Fk,
    Jacobians,
    Rnea,
    Crba,
    Aba,
    Lagrange,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli).and_then(|()| flush_stdout()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn load(m: &ModelArgs) -> Result<Model, String> {
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
fn parse_values(model: &Model, what: &str, s: &str) -> Result<Vec<f64>, String> {
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

fn link_id(model: &Model, name: &str) -> Result<usize, String> {
    model.link_id(name).ok_or_else(|| {
        let names: Vec<&str> = model.links.iter().map(|l| l.name.as_str()).collect();
        format!(
            "{}: link '{name}' does not exist (links: {})",
            model.source,
            names.join(", ")
        )
    })
}

fn print_json(v: &Value) {
    println!("{}", serde_json::to_string_pretty(v).unwrap_or_default());
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.cmd {
        Cmd::Info { m } => info(&load(&m)?, m.json),
        Cmd::Fk { m, q } => fk(&load(&m)?, &q, m.json),
        Cmd::Jacobian {
            m,
            q,
            frame,
            expressed,
            qd,
        } => jacobian(&load(&m)?, &q, &frame, expressed, qd.as_deref(), m.json),
        Cmd::Dynamics {
            m,
            q,
            v,
            a,
            tau,
            gravity,
            friction,
            rotor,
            efficiency,
            payload,
            method,
        } => {
            let model = load(&m)?;
            let opts = DynOpts {
                v,
                a,
                tau,
                gravity,
                friction,
                rotor,
                efficiency,
                payload,
                method,
            };
            dynamics_cmd(&model, &q, &opts, m.json)
        }
        Cmd::Workspace {
            m,
            link,
            samples,
            voxel,
            method,
            replicates,
            seed,
            extras,
            out,
            rerun,
        } => {
            let model = load(&m)?;
            let outputs = WsOutputs { csv: out, rerun };
            workspace_cmd(
                &model, link, samples, voxel, &method, replicates, seed, extras, outputs, m.json,
            )
        }
        Cmd::View {
            recording,
            save,
            spawn: _,
            model,
            mesh_dir,
        } => view_cmd(&recording, save, model.as_deref(), mesh_dir.as_deref()),
        Cmd::Ik {
            m,
            link,
            target,
            targets,
            position_only,
            tol,
            seed_q,
            restarts,
            budget_ms,
            no_limits,
            analytic,
        } => {
            let model = load(&m)?;
            let opts = IkCli {
                analytic,
                link,
                target,
                targets,
                position_only,
                tol,
                seed_q,
                restarts,
                budget_ms,
                no_limits,
            };
            ik_cmd(&model, &opts, m.json)
        }
        Cmd::Run {
            scenario,
            out,
            json,
            check,
            rerun,
            spawn,
            package_path,
            keep_mesh_uris,
        } => {
            if rerun.is_some() || spawn {
                need_rerun()?;
            }
            if let Some(dir) = &out {
                std::fs::create_dir_all(dir)
                    .map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
            }
            // Ctrl-C stops the simulation; the run still writes its files (a second one
            // exits at once).
            armsim::recording::interrupt::install().map_err(|e| e.to_string())?;
            let opts = armsim::arm::RunOptions {
                out_dir: out,
                stop: armsim::recording::interrupt::requested,
                rerun: match (rerun, spawn) {
                    (Some(p), _) => Some(armsim::recording::rerun_out::RerunSink::Save(p)),
                    (None, true) => Some(armsim::recording::rerun_out::RerunSink::Spawn),
                    (None, false) => None,
                },
                package_path,
                keep_mesh_uris,
                ..Default::default()
            };
            let report =
                armsim::scenario::run_file_with(&scenario, &opts).map_err(|e| e.to_string())?;
            if json {
                print_json(&report.json);
            } else {
                print!("{}", report.text);
            }
            if armsim::recording::interrupt::requested() {
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
        Cmd::Bench { m, algo, iters } => bench_cmd(&load(&m)?, algo, iters, m.json),
        Cmd::Tradeoffs {
            out,
            quick,
            tiny,
            quiet,
        } => tradeoffs_cmd(&out, quick, tiny, quiet),
        Cmd::Plan(args) => {
            let text = cli::plan::run(&args)?;
            print!("{text}");
            Ok(())
        }
        Cmd::Chain { n, out } => {
            if n == 0 || n > 1_000_000 {
                return Err(format!("chain: N must be between 1 and 1000000, got {n}"));
            }
            let text = chain::chain_urdf(n);
            match out {
                None => {
                    print!("{text}");
                    Ok(())
                }
                Some(p) => armsim::io::write_atomic(&p, text.as_bytes())
                    .map_err(|e| format!("{}: cannot write: {e}", p.display())),
            }
        }
    }
}

fn limit(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
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

fn rows(j: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..j.nrows())
        .map(|r| (0..j.ncols()).map(|c| j[(r, c)]).collect())
        .collect()
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
    let algo = match algo {
        AlgoArg::Fk => Algo::Fk,
        AlgoArg::Jacobians => Algo::Jacobians,
        AlgoArg::Rnea => Algo::Rnea,
        AlgoArg::Crba => Algo::Crba,
        AlgoArg::Lagrange => Algo::Lagrange,
        AlgoArg::Aba => {
            if model.has_mimic {
                return Err(format!(
                    "{}: ABA needs one coordinate per joint but the model has mimic joints; use --ignore-mimic",
                    model.source
                ));
            }
            Algo::Aba
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
        println!(
            "{} {} (dof {}): {:.1} ns per call (median of {} rounds, {} calls)",
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

struct DynOpts {
    v: Option<String>,
    a: Option<String>,
    tau: Option<String>,
    gravity: Option<String>,
    friction: bool,
    rotor: bool,
    efficiency: f64,
    payload: Option<String>,
    method: MethodArg,
}

fn parse_triple(what: &str, s: &str) -> Result<Vec3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("--{what}: expected x,y,z numbers, got '{s}'"))?;
    if v.len() != 3 || !v.iter().all(|x| x.is_finite()) {
        return Err(format!(
            "--{what}: expected three finite numbers x,y,z, got '{s}'"
        ));
    }
    Ok(Vec3::new(v[0], v[1], v[2]))
}

fn parse_payload(model: &Model, s: &str) -> Result<Payload, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 2 && parts.len() != 5 {
        return Err(format!(
            "--payload: expected LINK,MASS[,cx,cy,cz], got '{s}'"
        ));
    }
    let link = link_id(model, parts[0])?;
    let nums: Vec<f64> = parts[1..]
        .iter()
        .map(|t| t.parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("--payload: '{s}' has a value that is not a number"))?;
    if !nums.iter().all(|x| x.is_finite()) || nums[0] < 0.0 {
        return Err(format!(
            "--payload: mass and centre of mass must be finite, mass ≥ 0 ('{s}')"
        ));
    }
    let com = if nums.len() == 4 {
        Vec3::new(nums[1], nums[2], nums[3])
    } else {
        Vec3::zeros()
    };
    Payload::new(model, link, Inertia::new(nums[0], com, Mat3::zeros()))
}

fn dynamics_cmd(model: &Model, q: &str, o: &DynOpts, as_json: bool) -> Result<(), String> {
    let q = parse_values(model, "q", q)?;
    let zeros = vec![0.0; model.nv];
    let v =
        o.v.as_deref()
            .map(|s| parse_values(model, "v", s))
            .transpose()?
            .unwrap_or_else(|| zeros.clone());
    let a =
        o.a.as_deref()
            .map(|s| parse_values(model, "a", s))
            .transpose()?
            .unwrap_or_else(|| zeros.clone());
    let tau_in = o
        .tau
        .as_deref()
        .map(|s| parse_values(model, "tau", s))
        .transpose()?;
    let g = match &o.gravity {
        Some(s) => parse_triple("gravity", s)?,
        None => model.gravity,
    };
    let mut effects = Effects::gravity(g);
    if o.friction {
        effects.friction = Some(Friction::from_model(model));
    }
    if o.rotor {
        if !(o.efficiency > 0.0 && o.efficiency <= 1.0) {
            return Err(format!("--efficiency: {} is not in (0, 1]", o.efficiency));
        }
        effects.rotor = Some(Rotor::from_model(model, o.efficiency));
    }
    if let Some(p) = &o.payload {
        effects.payload = Some(parse_payload(model, p)?);
    }
    effects.validate(model)?;
    if o.method != MethodArg::Rnea && effects.names() != ["gravity"] {
        return Err("--method lagrange-*: the Lagrange references cover the rigid model with gravity only; drop --friction/--rotor/--payload".into());
    }
    let mut data = Data::new(model);
    let tau = match o.method {
        MethodArg::Rnea => {
            dynamics::inverse_dynamics(model, &mut data, &effects, &q, &v, &a).to_vec()
        }
        MethodArg::LagrangeTrace => dynamics::lagrange_trace(model, &mut data, &q, &v, &a, &g),
        MethodArg::LagrangeEnergy => dynamics::lagrange_energy(model, &mut data, &q, &v, &a, &g),
    };
    let bias = dynamics::inverse_dynamics(model, &mut data, &effects, &q, &v, &zeros).to_vec();
    let static_effects = Effects {
        friction: None,
        ..effects.clone()
    };
    let gravity_tau =
        dynamics::inverse_dynamics(model, &mut data, &static_effects, &q, &zeros, &zeros).to_vec();
    let mass = dynamics::mass_matrix(model, &mut data, &effects, &q).clone();
    let ke = 0.5
        * (0..model.nv)
            .map(|i| {
                (0..model.nv)
                    .map(|j| v[i] * mass[(i, j)] * v[j])
                    .sum::<f64>()
            })
            .sum::<f64>();
    let mut pe = dynamics::potential_energy(model, &mut data, &q, &g);
    if let Some(p) = &effects.payload {
        kinematics::forward_kinematics(model, &mut data, &q);
        let c = kinematics::frame_placement(model, &data, p.link).act_point(&p.inertia.com);
        pe -= p.inertia.mass * g.dot(&c);
    }
    let qdd = match &tau_in {
        None => None,
        Some(t) => Some(
            dynamics::forward_dynamics_with(model, &mut data, &effects, &q, &v, t)
                .map_err(|e| format!("{}: forward dynamics: {e}", model.source))?
                .to_vec(),
        ),
    };
    let method = match o.method {
        MethodArg::Rnea => "rnea",
        MethodArg::LagrangeTrace => "lagrange-trace",
        MethodArg::LagrangeEnergy => "lagrange-energy",
    };
    if as_json {
        let mut out = json!({
            "joints": model.dof_names(),
            "effects": effects.names(),
            "method": method,
            "gravity_vector": [g.x, g.y, g.z],
            "tau": tau,
            "mass_matrix": rows(&mass),
            "bias": bias,
            "gravity": gravity_tau,
            "kinetic_energy": ke,
            "potential_energy": pe,
        });
        if let Some(qdd) = &qdd {
            out["qdd"] = json!(qdd);
        }
        print_json(&out);
        return Ok(());
    }
    println!("effects: {} (tau by {method})", effects.names().join(", "));
    println!(
        "{:<24} {:>14} {:>14} {:>14}{}",
        "joint",
        "tau",
        "bias",
        "gravity",
        if qdd.is_some() { "            qdd" } else { "" }
    );
    for (k, name) in model.dof_names().iter().enumerate() {
        print!(
            "{:<24} {:>14.6} {:>14.6} {:>14.6}",
            name, tau[k], bias[k], gravity_tau[k]
        );
        if let Some(qdd) = &qdd {
            print!(" {:>14.6}", qdd[k]);
        }
        println!();
    }
    println!("kinetic energy {ke:.6} J, potential energy {pe:.6} J");
    println!("mass matrix:");
    for r in 0..model.nv {
        println!(
            "  {}",
            (0..model.nv)
                .map(|c| format!("{:>11.6}", mass[(r, c)]))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    Ok(())
}

struct IkCli {
    analytic: bool,
    link: String,
    target: Option<String>,
    targets: Option<PathBuf>,
    position_only: bool,
    tol: f64,
    seed_q: Option<String>,
    restarts: usize,
    budget_ms: f64,
    no_limits: bool,
}

/// A pose from `x,y,z,qw,qx,qy,qz` (or `x,y,z` when only the position matters).
fn parse_pose(s: &str, position_only: bool, what: &str) -> Result<Se3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("{what}: '{s}' has a value that is not a number"))?;
    if !v.iter().all(|x| x.is_finite()) {
        return Err(format!("{what}: '{s}' has a non-finite value"));
    }
    let p = match v.len() {
        3 if position_only => return Ok(Se3::from_translation(Vec3::new(v[0], v[1], v[2]))),
        7 => Vec3::new(v[0], v[1], v[2]),
        n => {
            return Err(format!(
                "{what}: expected 7 values x,y,z,qw,qx,qy,qz{}, got {n}",
                if position_only { " (or x,y,z)" } else { "" }
            ))
        }
    };
    let quat = nalgebra::Quaternion::new(v[3], v[4], v[5], v[6]);
    if quat.norm() < 1e-9 {
        return Err(format!("{what}: the quaternion is zero"));
    }
    let r = nalgebra::UnitQuaternion::from_quaternion(quat).to_rotation_matrix();
    Ok(Se3::new(*r.matrix(), p))
}

fn ik_cmd(model: &Model, o: &IkCli, as_json: bool) -> Result<(), String> {
    use armsim::kinematics::ik::{solve_batch, IkOptions};
    let link = link_id(model, &o.link)?;
    if !(o.tol > 0.0 && o.tol.is_finite()) {
        return Err(format!("--tol: {} is not a positive number", o.tol));
    }
    if !(o.budget_ms > 0.0 && o.budget_ms.is_finite()) {
        return Err(format!(
            "--budget-ms: {} is not a positive number",
            o.budget_ms
        ));
    }
    let seed = o
        .seed_q
        .as_deref()
        .map(|s| parse_values(model, "seed-q", s))
        .transpose()?;
    let targets: Vec<Se3> = match (&o.target, &o.targets) {
        (Some(t), None) => vec![parse_pose(t, o.position_only, "--target")?],
        (None, Some(file)) => {
            let text = armsim::io::read_input_string(file)
                .map_err(|e| format!("{}: cannot read: {e}", file.display()))?;
            let mut out = Vec::new();
            for (i, line) in text.lines().enumerate() {
                let l = line.trim();
                if l.is_empty() || l.starts_with('#') {
                    continue;
                }
                if out.is_empty() && l.chars().next().is_some_and(|c| c.is_ascii_alphabetic()) {
                    continue; // header row
                }
                let what = format!("{}:{}", file.display(), i + 1);
                out.push(parse_pose(l, o.position_only, &what)?);
            }
            if out.is_empty() {
                return Err(format!("{}: no targets", file.display()));
            }
            out
        }
        (Some(_), Some(_)) => return Err("give either --target or --targets, not both".into()),
        (None, None) => {
            return Err("give a --target x,y,z,qw,qx,qy,qz or a --targets FILE.csv".into())
        }
    };
    let opts = IkOptions {
        position_only: o.position_only,
        tol_position: o.tol,
        tol_rotation: o.tol,
        max_restarts: o.restarts,
        time_budget: std::time::Duration::from_secs_f64(o.budget_ms * 1e-3),
        respect_limits: !o.no_limits,
        ..Default::default()
    };
    if o.analytic {
        return ik_analytic_cmd(model, link, &targets, seed.as_deref(), o, as_json);
    }
    let results = solve_batch(model, link, &targets, seed.as_deref(), &opts);
    if as_json {
        let rows: Vec<Value> = results
            .iter()
            .map(|r| {
                json!({
                    "q": r.q,
                    "status": r.status.as_str(),
                    "position_error": limit(r.position_error),
                    "rotation_error": limit(r.rotation_error),
                    "iterations": r.iterations,
                    "restarts": r.restarts,
                    "time_us": r.time_us,
                })
            })
            .collect();
        print_json(&json!({"joints": model.dof_names(), "link": o.link, "results": rows}));
        return Ok(());
    }
    println!("joints: {}", model.dof_names().join(" "));
    for (i, r) in results.iter().enumerate() {
        println!(
            "target {i}: {} after {} iterations, {} restarts, {:.1} µs; position error {:.3e} m, rotation error {:.3e} rad",
            r.status.as_str(),
            r.iterations,
            r.restarts,
            r.time_us,
            r.position_error,
            r.rotation_error
        );
        let q: Vec<String> = r.q.iter().map(|x| format!("{x:.9}")).collect();
        println!("  q = {}", q.join(", "));
    }
    Ok(())
}

/// `armsim ik --analytic`: every closed-form branch inside the limits per target.
fn ik_analytic_cmd(
    model: &Model,
    link: usize,
    targets: &[Se3],
    seed: Option<&[f64]>,
    o: &IkCli,
    as_json: bool,
) -> Result<(), String> {
    use armsim::kinematics::ik::analytic::{AnalyticOptions, AnalyticSolver};
    let solver = AnalyticSolver::new(model, link).map_err(|e| format!("{}: {e}", model.source))?;
    let start_q = seed.map(<[f64]>::to_vec).unwrap_or_else(|| model.neutral());
    let aopts = AnalyticOptions {
        respect_limits: !o.no_limits,
        ..Default::default()
    };
    let mut rows = Vec::new();
    for t in targets {
        let t0 = std::time::Instant::now();
        let sols = solver.solve(t, &aopts);
        let time_us = t0.elapsed().as_secs_f64() * 1e6;
        let row = match sols {
            Ok(sols) if !sols.is_empty() => {
                let dist = |q: &[f64]| {
                    q.iter()
                        .zip(&start_q)
                        .map(|(a, b)| (a - b).powi(2))
                        .sum::<f64>()
                };
                let best = sols
                    .iter()
                    .min_by(|a, b| dist(&a.q).total_cmp(&dist(&b.q)))
                    .expect("non-empty");
                let mut data = Data::new(model);
                kinematics::forward_kinematics(model, &mut data, &best.q);
                let p = kinematics::frame_placement(model, &data, link);
                let pe = (p.trans - t.trans).norm();
                let re = armsim::kinematics::ik::rotation_log(&(t.rot * p.rot.transpose())).norm();
                json!({
                    "q": best.q,
                    "status": "converged",
                    "position_error": pe,
                    "rotation_error": if o.position_only { 0.0 } else { re },
                    "iterations": 0,
                    "time_us": time_us,
                    "solutions": sols.iter().map(|s| json!({"q": s.q, "branch": s.branch, "singular": s.singular})).collect::<Vec<_>>(),
                })
            }
            Ok(_) => {
                json!({"q": start_q, "status": "unreachable", "position_error": null, "rotation_error": null, "iterations": 0, "time_us": time_us, "solutions": [], "reason": "no solution"})
            }
            Err(e) => {
                json!({"q": start_q, "status": "unreachable", "position_error": null, "rotation_error": null, "iterations": 0, "time_us": time_us, "solutions": [], "reason": e.to_string()})
            }
        };
        rows.push(row);
    }
    if as_json {
        print_json(&json!({"joints": model.dof_names(), "link": o.link, "results": rows}));
        return Ok(());
    }
    println!("joints: {}", model.dof_names().join(" "));
    for (i, r) in rows.iter().enumerate() {
        let sols = r["solutions"].as_array().map(Vec::len).unwrap_or(0);
        println!(
            "target {i}: {} ({sols} branch(es) inside the limits, {:.2} µs)",
            r["status"].as_str().unwrap_or(""),
            r["time_us"].as_f64().unwrap_or(0.0)
        );
        for s in r["solutions"].as_array().into_iter().flatten() {
            let q: Vec<String> = s["q"]
                .as_array()
                .into_iter()
                .flatten()
                .map(|x| format!("{:.9}", x.as_f64().unwrap_or(f64::NAN)))
                .collect();
            println!(
                "  {:<36} {}{}",
                s["branch"].as_str().unwrap_or(""),
                q.join(", "),
                if s["singular"].as_bool() == Some(true) {
                    "  (singular)"
                } else {
                    ""
                }
            );
        }
        if let Some(reason) = r.get("reason") {
            println!("  {}", reason.as_str().unwrap_or(""));
        }
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
/// The sampled workspace as an MCAP recording: the robot (description, static tf, one
/// frame at the neutral configuration) and the kept tool points as a
/// `sensor_msgs/PointCloud2` with the manipulability of each point.
fn write_workspace_mcap(
    model: &Model,
    r: &armsim::workspace::WorkspaceResult,
    path: &std::path::Path,
) -> Result<(), String> {
    use armsim::recording::{mcap_out::McapWriter, Header, PointCloud};
    let src = std::path::Path::new(&model.source);
    let spec = Model::read_spec(src).map_err(|e| e.to_string())?;
    let name = format!("{}_workspace", model.name);
    let (header, tf) = Header::for_model(&name, src, model, &spec);
    let err = |e: armsim::recording::error::RecordError| e.to_string();
    let mut w = McapWriter::create(path, &header).map_err(err)?;
    let mut data = armsim::data::Data::new(model);
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

#[allow(clippy::too_many_arguments)] // one per CLI option
fn workspace_cmd(
    model: &Model,
    link: Option<String>,
    samples: u64,
    voxel: f64,
    method: &str,
    replicates: usize,
    seed: u64,
    extras: bool,
    outputs: WsOutputs,
    as_json: bool,
) -> Result<(), String> {
    use armsim::workspace::{sample_workspace, Sampling, WorkspaceOptions};
    let WsOutputs { csv: out, rerun } = outputs;
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
    if samples == 0 || replicates < 2 {
        return Err(
            "--samples must be positive and --replicates at least 2 (for the standard error)"
                .into(),
        );
    }
    let sampling: Sampling = method.parse().map_err(|e| format!("--method: {e}"))?;
    let opts = WorkspaceOptions {
        samples,
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
    let (what, unit) = if r.planar {
        ("area", "m²")
    } else {
        ("volume", "m³")
    };
    println!(
        "{} workspace of '{}' ({} samples in {} replicates, {:?} sampling, voxel {} m, {:.2} s)",
        r.robot, r.tool, r.samples, r.replicates, r.sampling, r.voxel, r.time_s
    );
    println!(
        "{what}: {:.6} {unit} ± {:.6} (standard error)",
        r.measure(),
        r.measure_stderr()
    );
    println!(
        "voxel-size bias ≈ {:.6} {unit}; corrected {:.6} ± {:.6}",
        r.bias.bias, r.bias.corrected, r.bias.corrected_stderr
    );
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

/// `armsim tradeoffs`: runs the studies, writes the report, prints the files written.
fn tradeoffs_cmd(
    out: &std::path::Path,
    quick: bool,
    tiny: bool,
    quiet: bool,
) -> Result<(), String> {
    use armsim::tradeoffs::{self, Mode, Options};
    let mode = if tiny {
        Mode::Tiny
    } else if quick {
        Mode::Quick
    } else {
        Mode::Full
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
    let written = tradeoffs::report::write(&report, out)?;
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

/// Output files of `workspace`.
struct WsOutputs {
    /// Sampled tool points as CSV.
    csv: Option<PathBuf>,
    /// Rerun file.
    rerun: Option<PathBuf>,
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
    use armsim::recording::rerun_out;
    let sink = rerun_out::RerunSink::Save(path.to_path_buf());
    let report = rerun_out::log_workspace_scene(model, r, &sink).map_err(|e| e.to_string())?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// Refuses at once (before any work) in a build without the `rerun` feature.
fn need_rerun() -> Result<(), String> {
    if armsim::recording::rerun_sink::AVAILABLE {
        Ok(())
    } else {
        Err(armsim::recording::rerun_sink::RerunError::NotBuilt.to_string())
    }
}

/// `armsim view`: an MCAP recording to Rerun.
fn view_cmd(
    recording: &std::path::Path,
    save: Option<PathBuf>,
    model: Option<&std::path::Path>,
    mesh_dir: Option<&std::path::Path>,
) -> Result<(), String> {
    use armsim::recording::{mcap_in, rerun_out};
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
    let report = rerun_out::log_recording(&rec, spec.as_ref(), mesh_dir, &sink)
        .map_err(|e| e.to_string())?;
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
