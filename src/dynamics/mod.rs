//! Rigid-body dynamics: Newton–Euler (RNEA), the mass matrix (CRBA), forward dynamics
//! (ABA, and CRBA + Cholesky), energies. Each algorithm is one file citing the equations
//! it implements; all write into [`crate::data::Data`] and allocate nothing per call.

mod aba;
mod crba;
mod energy;
mod forward;
mod rnea;

pub use aba::aba;
pub use crba::crba;
pub use energy::{kinetic_energy, potential_energy};
pub use forward::{
    cholesky_in_place, cholesky_solve_in_place, forward_dynamics, forward_dynamics_crba,
    SingularMassMatrix,
};
pub use rnea::{bias, gravity_torque, rnea};
