//! `armsim` command-line tool: a thin layer over the library. Every command exits
//! non-zero with a message naming the file, the element and the problem on bad input,
//! and never panics on user input.

#[macro_use]
mod cli;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

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

#[derive(Subcommand)]
enum Cmd {
    /// Name, DOF, links and joints in the joint order every other command uses.
    Info(cli::ModelArgs),
    /// World placement of every link frame at configuration q.
    Fk(cli::inspect::FkArgs),
    /// Geometric Jacobian of a link frame (rows: linear x y z, angular x y z).
    Jacobian(cli::inspect::JacobianArgs),
    /// Joint torques, mass matrix, bias, gravity torques and energies at (q, v, a); with
    /// --tau also the forward-dynamics accelerations.
    Dynamics(cli::dynamics::DynamicsArgs),
    /// Inverse kinematics of a link frame for one target pose or a CSV file of targets.
    Ik(cli::ik_cmd::IkArgs),
    /// Reachable workspace of a link: voxel volume (or area for planar arms) with a 95 %
    /// interval (or a lower bound when under-sampled), boundary, manipulability, dexterity.
    Workspace(cli::workspace_cmd::WorkspaceArgs),
    /// Show a recording (MCAP) in Rerun: write an .rrd file, or spawn the viewer (the
    /// `rerun` program on PATH, from `pip install rerun-sdk==0.36.3`).
    View(cli::scenario_cmd::ViewArgs),
    /// Run a scenario file end to end and print its summary (or JSON).
    Run(cli::scenario_cmd::RunArgs),
    /// Time one algorithm (median ns per call over random states inside the limits).
    Bench(cli::inspect::BenchArgs),
    /// Measure the trade-offs report: IK tolerance × method, integrator step × method,
    /// dynamics formulations vs DOF, workspace samples × scheme, cost of each effect,
    /// flexible-rotor elements × critical-speed error, analytical dynamics derivatives vs finite
    /// differences.
    /// Writes DIR/tradeoffs.md, DIR/tradeoffs.json and the plots (DIR/*.png).
    Tradeoffs(cli::scenario_cmd::TradeoffsArgs),
    /// Plan collision-free motions (RRT-Connect on the robot's collision spheres) for MoveIt
    /// problems: one scene + request, or every pair of benchmark folders.
    Plan(cli::plan_cmd::PlanArgs),
    /// Compute the allowed-collision matrix of a URDF (adjacent, default, always and
    /// never-colliding link pairs, as MoveIt's Setup Assistant does) and write it as an SRDF.
    Srdf(cli::srdf_cmd::SrdfArgs),
    /// Write the generated N-joint benchmark chain as URDF.
    Chain(cli::inspect::ChainArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli).and_then(|()| cli::flush_stdout()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Calls the command's module with its arguments.
fn run(cli: Cli) -> Result<(), String> {
    match cli.cmd {
        Cmd::Info(m) => cli::inspect::info_cmd(&m),
        Cmd::Fk(a) => cli::inspect::fk_cmd(&a),
        Cmd::Jacobian(a) => cli::inspect::jacobian_cmd(&a),
        Cmd::Dynamics(a) => cli::dynamics::run(&a),
        Cmd::Workspace(a) => cli::workspace_cmd::run(&a),
        Cmd::View(a) => cli::scenario_cmd::view(&a),
        Cmd::Ik(a) => cli::ik_cmd::run(&a),
        Cmd::Run(a) => cli::scenario_cmd::run(&a),
        Cmd::Bench(a) => cli::inspect::bench_run(&a),
        Cmd::Tradeoffs(a) => cli::scenario_cmd::tradeoffs(&a),
        Cmd::Plan(args) => {
            let text = cli::plan_cmd::run(&args)?;
            print!("{text}");
            Ok(())
        }
        Cmd::Srdf(a) => {
            let text = cli::srdf_cmd::run(&a)?;
            print!("{text}");
            Ok(())
        }
        Cmd::Chain(a) => cli::inspect::chain_cmd(&a),
    }
}
