//! Outputs: the report every run returns ([`report`]), pictures ([`plots`]) and
//! recordings ([`record`]: MCAP in and out as ROS 2 messages, Rerun, the URDF written for
//! `/robot_description`). Algorithms below this layer never draw or write files.
pub mod plots;
pub mod record;
pub mod report;
