//! Torsional drivetrain chains: natural modes, damped modes, forced response, damping
//! identification. (Being written: see the issue on the textbook systems.)

pub mod scenario;
