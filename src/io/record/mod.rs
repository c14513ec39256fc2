//! Recordings of arm motions: the in-memory [`Recording`] that the scenario runner fills and
//! the MCAP writer (`mcap_out`), the MCAP reader (`mcap_in`) and the Rerun logger
//! (`rerun_out`) share.
//!
//! A recording is a header (joint names, limits, static frames, robot description,
//! metadata, the wall-clock epoch of `t = 0`) and a time-ordered stream of [`Frame`]s,
//! plus optional point clouds, a torque-check table, collision events and the scene's
//! obstacles ([`recording::ObstacleMarker`]). Writers stream frames one at a time so an
//! interrupted run still leaves a valid file.

mod from_ros2;
pub mod mcap_in;
pub mod mcap_out;
pub mod message_error;
mod model_header;
pub mod obstacle_markers;
pub mod record_error;
pub mod recording;
pub mod rerun;
pub mod ros2;
pub mod tf;
pub mod urdf_out;

pub use crate::io::record::recording::{
    CollisionEvent, Frame, Header, PointCloud, Recording, TorqueRow, Transform,
};
