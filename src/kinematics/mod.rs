//! Kinematics: forward kinematics (placements, velocities, accelerations), geometric
//! Jacobians and their time derivatives in three expressions, and the dexterity measures;
//! one link's position ([`fk_lanes`]) or pose ([`pose_lanes`]) for eight configurations at
//! once in SIMD lanes.

mod fk;
pub mod fk_lanes;
pub mod ik;
mod jacobian;
mod manipulability;
pub mod pose_lanes;
pub mod spatial_loop;

pub(crate) use fk::{body_q, body_rate, joint_motion};
pub use fk::{
    forward_kinematics, forward_kinematics_acc, forward_kinematics_vel, frame_acceleration,
    frame_classical_acceleration, frame_placement, frame_velocity, joint_transform, update_frames,
};
pub(crate) use jacobian::world_subspace;
pub use jacobian::{
    compute_frame_jacobian, compute_joint_jacobians, compute_joint_jacobians_time_variation,
    frame_jacobian, frame_jacobian_time_variation, Expressed,
};
pub use manipulability::{condition_number, manipulability};
