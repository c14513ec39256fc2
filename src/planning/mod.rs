//! Collision-free motion planning: the robot as spheres, obstacles as exact primitives,
//! batched (SIMD) collision checks with a continuous-safety bound, RRT-Connect, and path
//! simplification; MoveIt planning scenes/requests and SRDF self-collision pairs as input.
//!
//! Layer: above `model` and `kinematics`, beside `collision` and `trajectory`.

pub mod acm;
pub mod aorrtc;
pub mod checker;
pub mod constrained_rrt;
pub mod cover_cache;
pub mod environment;
pub mod improve;
pub mod informed;
mod lane_values;
pub mod lanes;
pub mod mesh_sdf;
pub mod moveit;
pub mod path_constraints;
pub mod plan_error;
pub mod plan_options;
pub mod planner;
pub mod pose_goal;
pub mod projection;
pub mod repair;
pub mod rrt;
pub mod sampler;
pub mod self_pairs;
pub mod setup;
pub mod simd;
pub mod simplify;
pub mod spheres;
pub mod spherize;
pub mod srdf;
pub mod walls;

pub use checker::{CheckOptions, CheckScratch, Checker};
pub use planner::{PlanOptions, PlanResult, PlanStatus, Planner};
pub use setup::{Contact, PairSource, PlanningRobot};
