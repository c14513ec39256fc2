//! Rigid-body dynamics: Newton–Euler (RNEA, also on eight states in SIMD lanes), the mass matrix (CRBA, also in SIMD lanes), forward dynamics
//! (ABA, also in SIMD lanes, and CRBA + Cholesky), `M⁻¹`, the analytical derivatives of inverse and forward
//! dynamics (Carpentier & Mansard, also with the scene's effects) and the linearised
//! integration step built on them (A, B for MPC), energies, the centre of mass and its
//! Jacobian, the switchable effects, and the two Lagrange
//! formulations (the textbook's trace form and the energy/Christoffel form) with the
//! Coriolis matrix. Each algorithm is one file citing the equations it implements.
//!
//! The public signatures read like Pinocchio's: `rnea(&model, &mut data, q, v, a)`,
//! `aba(&model, &mut data, q, v, tau)`, `crba(&model, &mut data, q)` take gravity
//! (`model.gravity`) and the rotor armature (`model.armature`) from the model; the
//! `*_with_forces` variants add one external wrench per body. [`forward_dynamics`] is the
//! checked dispatcher (ABA, or CRBA + Cholesky with mimic joints). [`Effects`] composes
//! switchable effects on top of the rigid model (its own gravity, friction, rotors,
//! elasticity, payload, wrenches).
//!
//! The
//! recursive algorithms and the effects write into [`crate::model::data::Data`] and allocate
//! nothing per call; the Lagrange forms are slow O(n⁴)/O(n³) references and allocate.

mod aba;
mod aba_derivatives;
pub mod aba_lanes;
mod center_of_mass;
mod crba;
pub mod crba_lanes;
mod discrete_linearisation;
mod effects;
mod effects_derivatives;
mod energy;
mod forward;
mod lagrange_energy;
mod lagrange_trace;
mod lane_inertia;
mod lane_spatial;
mod minverse;
mod rnea;
mod rnea_derivatives;
mod rnea_derivatives_chain;
pub mod rnea_lanes;
mod terms;

pub use crate::core::linalg::{cholesky_in_place, cholesky_solve_in_place, SingularMassMatrix};
pub use crate::model::data::{EffectRuns, EffectSet};
pub use aba::{aba, aba_with_forces};
pub use aba_derivatives::{aba_derivatives, AbaPartials};
pub use aba_lanes::{aba_rows, AbaLanes};
pub use center_of_mass::{center_of_mass, jacobian_center_of_mass, total_mass};
pub use crba::crba;
pub(crate) use crba::crba_impl;
pub use crba_lanes::{crba_rows, CrbaLanes};
pub use discrete_linearisation::{LinearisationError, StepLinearisation, StepScheme};
pub use effects::{
    inverse_dynamics, mass_matrix, Effects, EffectsError, Elasticity, ExternalWrench, Friction,
    Payload, Rotor,
};
pub use effects_derivatives::{forward_dynamics_derivatives, inverse_dynamics_derivatives};
pub(crate) use energy::kinetic_energy_gradient_impl;
pub use energy::{energies_with, kinetic_energy, kinetic_energy_gradient, potential_energy};
pub use forward::{
    elastic_forward_dynamics, forward_dynamics, forward_dynamics_crba, forward_dynamics_with,
};
pub use lagrange_energy::{
    coriolis_matrix, gravity_torque_energy, lagrange_energy, mass_matrix_derivatives,
    mass_matrix_energy,
};
pub use lagrange_trace::{lagrange_trace, mass_matrix_trace};
pub use minverse::compute_minverse;
pub(crate) use rnea::rnea_impl;
pub use rnea::{bias, gravity_torque, rnea, rnea_with_forces};
pub use rnea_derivatives::{rnea_derivatives, rnea_derivatives_with_forces, RneaPartials};
pub use rnea_lanes::{rnea_rows, RneaLanes};
pub(crate) use terms::Terms;
