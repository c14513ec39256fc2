//! Collision-free motion planning: the robot as spheres, obstacles as exact primitives,
//! batched (SIMD) collision checks with a continuous-safety bound, RRT-Connect, and path
//! simplification; MoveIt planning scenes/requests and SRDF self-collision pairs as input.
//!
//! Layer: above `model` and `kinematics`, beside `collision` and `trajectory`.

pub mod error;
pub mod moveit;
pub mod srdf;
