//! The Python extension `armsim._armsim`: Pinocchio-style functions on `Model`/`Data`
//! (kinematics, frame velocities and accelerations, dynamics with wrenches and payload,
//! energies, the Coriolis matrix, the centre of mass),
//! the `Robot` facade, batches on rayon without the GIL (interruptible by Ctrl-C), scenario
//! runs and workspace sampling. The package `armsim` (python/armsim) re-exports it and adds the Python
//! parts (report dicts, `armsim.distributed`).

mod algorithms;
mod applied_loads;
mod args;
mod batch;
mod com;
mod convert;
mod dyn_calls;
mod errors;
mod frame_motion;
mod ik;
mod interrupt;
mod lagrangian;
mod linearise;
mod model;
mod obstacles;
mod plan;
mod pose_dicts;
mod robot;
mod tasks;

use pyo3::prelude::*;

#[pymodule]
fn _armsim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ArmsimError", py.get_type::<errors::ArmsimError>())?;
    m.add("LoaderWarning", py.get_type::<errors::LoaderWarning>())?;
    m.add("IK_KEYWORDS", ik::IK_KEYWORDS)?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<model::PyData>()?;
    m.add_class::<robot::PyRobot>()?;
    m.add_class::<ik::IkResult>()?;
    m.add_class::<plan::PyPlanner>()?;
    m.add_function(wrap_pyfunction!(algorithms::forward_kinematics, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::frame_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::rnea, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::aba, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::crba, m)?)?;
    m.add_function(wrap_pyfunction!(
        algorithms::compute_generalized_gravity,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(algorithms::nonlinear_effects, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::rnea_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::aba_derivatives, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::compute_minverse, m)?)?;
    m.add_function(wrap_pyfunction!(linearise::linearise_step, m)?)?;
    m.add_function(wrap_pyfunction!(frame_motion::frame_velocity, m)?)?;
    m.add_function(wrap_pyfunction!(frame_motion::frame_acceleration, m)?)?;
    m.add_function(wrap_pyfunction!(
        frame_motion::frame_classical_acceleration,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(
        frame_motion::frame_jacobian_time_variation,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(lagrangian::compute_kinetic_energy, m)?)?;
    m.add_function(wrap_pyfunction!(lagrangian::compute_potential_energy, m)?)?;
    m.add_function(wrap_pyfunction!(lagrangian::compute_coriolis_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(com::center_of_mass, m)?)?;
    m.add_function(wrap_pyfunction!(com::jacobian_center_of_mass, m)?)?;
    m.add_function(wrap_pyfunction!(applied_loads::inverse_dynamics, m)?)?;
    m.add_function(wrap_pyfunction!(applied_loads::forward_dynamics, m)?)?;
    m.add_function(wrap_pyfunction!(batch::rnea_batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch::crba_batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch::aba_batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch::gravity_batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch::fk_batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch::jacobian_batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch::ik_batch, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan_py, m)?)?;
    m.add_function(wrap_pyfunction!(tasks::run_scenario_json, m)?)?;
    m.add_function(wrap_pyfunction!(tasks::workspace_json, m)?)?;
    m.add_function(wrap_pyfunction!(tasks::sample_poses, m)?)?;
    Ok(())
}
