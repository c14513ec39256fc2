//! Closed-chain planar mechanisms: loop closure with branch tracking, velocities and
//! accelerations through the constraint Jacobian, kinetostatics, balancing.
//! (Being written: see the issue on the textbook systems.)

pub mod scenario;
