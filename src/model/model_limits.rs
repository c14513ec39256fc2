//! The ranges a model file's numbers must lie in, shared by the URDF and DH readers.

/// Lengths and coordinates a model file may give (m): origins, DH `a` and `d`, centres of
/// mass. Larger ones overflow the kinematics' squared distances long before any robot
/// needs them.
pub const MAX_LENGTH: f64 = 1e9;
