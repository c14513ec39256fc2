//! Torsional drivetrain chains (docs/reference_data.md §S3): rigid disks on massless shafts with
//! absolute and relative damping, `J φ̈ + B φ̇ + K φ = M(t)`. One algorithm per file:
//!
//! - [`torsional_chain`]: the model, its matrices, and the same chain as an armsim
//!   [`crate::model::Model`] (coaxial revolute joints, coordinates = twists);
//! - [`gear_stages`]: gear stages and referral to the input speed (`× i²`);
//! - [`modes`]: undamped modes, `K x = p² J x` (symmetric eigen of `J^{-1/2} K J^{-1/2}`);
//! - [`damped`]: damped complex modes, `(λ² J + λ B + K) x = 0` via the 2n state form;
//! - [`forced`]: forced steady state per engine order, speed sweeps, critical speeds;
//! - [`time`]: RK4 time integration (no allocation per step) and the periodic-steady-state
//!   check against [`forced`];
//! - [`identify`]: damping identification from shaft-torque amplitudes
//!   (Levenberg–Marquardt, standard errors from `σ² (JᵀJ)⁻¹`);
//! - [`holzer`]: Holzer transfer matrices, residual torque, node-count bisection;
//! - [`lr`]: Rutishauser's LR iteration (a second eigenvalue route);
//! - [`absorber`]: tuned absorber and Lanchester damper closed forms.
//!
//! ```
//! use armsim::machines::vibration::torsional::torsional_chain::TorsionalChain;
//! use armsim::machines::vibration::torsional::modes::undamped_modes;
//! // Two disks on one shaft: p² = c (1/J1 + 1/J2).
//! let c = TorsionalChain::unnamed(vec![2.0, 3.0], vec![600.0]).unwrap();
//! let m = undamped_modes(&c);
//! assert_eq!(m[0].omega, 0.0);
//! assert!((m[1].omega - (600.0_f64 * (0.5 + 1.0 / 3.0)).sqrt()).abs() < 1e-12);
//! ```

pub mod absorber;
pub mod damped;
pub mod forced;
pub mod gear_stages;
pub mod holzer;
pub mod identify;
pub mod lr;
pub mod modes;
pub mod time;
pub mod torsional_chain;
pub use crate::machines::vibration::torsional::damped::{damped_modes, DampedMode, DampedModes};
pub use crate::machines::vibration::torsional::forced::{
    critical_speeds, harmonic_response, sweep, Excitation, HarmonicResponse,
};
pub use crate::machines::vibration::torsional::gear_stages::{GearStage, GearedChain, Referral};
pub use crate::machines::vibration::torsional::modes::{undamped_modes, Mode, CPM_PER_RAD_S};
pub use crate::machines::vibration::torsional::torsional_chain::{ChainError, TorsionalChain};
