//! # armsim
//!
//! Robot manipulator kinematics and dynamics in f64: an immutable [`model::Model`] built
//! from URDF or Denavit–Hartenberg tables, a reusable [`Data`] workspace, and one
//! algorithm per file. See the README for the command-line tool and
//! `docs/architecture.md` for the layers.
//!
//! The common path is the [`Robot`] facade (forward kinematics, Jacobians, inverse and
//! forward dynamics, the mass matrix and IK by frame name, gravity from the model):
//!
//! ```
//! use armsim::{Expressed, IkOptions, Robot, Se3};
//! # fn main() -> Result<(), armsim::RobotError> {
//! let mut robot = Robot::from_file(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf"))?;
//! let tool = robot.frame("tool0")?;
//! let q = [0.0, -1.0, 1.2, -0.4, 1.4, 0.3];
//! let pose: Se3 = robot.fk(&q)?.pose(tool);
//! let j = robot.jacobian(&q, tool, Expressed::WorldAligned)?;
//! assert_eq!(j.shape(), (6, 6));
//! let tau = robot.rnea(&q, &[0.0; 6], &[0.0; 6])?; // gravity from the model
//! assert!(tau[1].abs() > 1.0);
//! let sol = robot.ik(tool, &pose, &IkOptions::default())?;
//! assert!(sol.converged(), "{}", sol.reason);
//! # Ok(())
//! # }
//! ```
//!
//! The [`model::Model`] / [`Data`] functions underneath stay the API for hot loops
//! (as in Pinocchio):
//!
//! ```
//! use armsim::{kinematics, model::Model, Data};
//! let (model, _warnings) = Model::build(armsim::model::chain::chain_spec(3)).unwrap();
//! let mut data = Data::new(&model);
//! kinematics::forward_kinematics(&model, &mut data, &[0.3, 0.0, 0.2]);
//! let tip = kinematics::frame_placement(&model, &data, model.link_id("link3").unwrap());
//! assert!((tip.trans.z - 0.2).abs() < 1e-12);
//! ```

#![warn(missing_docs)]

pub mod collision;
pub mod core;
pub mod dynamics;
pub mod io;
pub mod kinematics;
pub mod machines;
pub mod model;
pub mod motion;
pub mod planning;
pub mod robot;
pub mod scenarios;
pub mod sim;
pub mod studies;
pub mod workspace;

pub use crate::core::spatial::{Force, Mat3, Motion, Se3, Vec3};
pub use crate::model::data::Data;
pub use kinematics::ik::{IkOptions, IkStatus};
pub use kinematics::Expressed;
pub use model::{FrameId, JointId, Model};
pub use nalgebra;
pub use robot::{IkSolution, Placements, Robot, RobotError};
