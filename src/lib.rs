//! # armsim
//!
//! Robot manipulator kinematics and dynamics in f64: an immutable [`model::Model`] built
//! from URDF or Denavit–Hartenberg tables, a reusable [`data::Data`] workspace, and one
//! algorithm per file. See the README for the command-line tool.
//!
//! ```
//! use armsim::{model::Model, data::Data, kinematics};
//! let (model, _warnings) = Model::build(armsim::model::chain::chain_spec(3)).unwrap();
//! let mut data = Data::new(&model);
//! kinematics::forward_kinematics(&model, &mut data, &[0.3, 0.0, 0.2]);
//! let tip = kinematics::frame_placement(&model, &data, model.link_id("link3").unwrap());
//! assert!((tip.trans.z - 0.2).abs() < 1e-12);
//! ```

pub mod arm;
pub mod bench;
pub mod collision;
pub mod data;
pub mod drivetrain;
pub mod dynamics;
pub mod fastmath;
pub mod io;
pub mod kinematics;
pub mod mechanism;
pub mod model;
pub mod planning;
pub mod recording;
pub mod scenario;
pub mod scenario_kit;
pub mod sim;
pub mod spatial;
pub mod tradeoffs;
pub mod trajectory;
pub mod workspace;
