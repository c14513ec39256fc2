//! [`CollisionError`]: what goes wrong building a collision scene (a mesh, a primitive,
//! an obstacle, a disabled pair, the options) or checking a trajectory.

/// Errors building a scene or checking a trajectory.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CollisionError {
    /// A collision mesh could not be found (with [`crate::collision::MissingMeshes::Error`]) or read.
    #[error("{model}: link '{link}': collision mesh '{uri}': {reason}")]
    Mesh {
        /// Model file.
        model: String,
        /// Link name.
        link: String,
        /// The URI as written.
        uri: String,
        /// What went wrong.
        reason: String,
    },
    /// A primitive with a bad dimension.
    #[error("{model}: link '{link}': collision geometry: {reason}")]
    Geometry {
        /// Model file.
        model: String,
        /// Link name.
        link: String,
        /// What is wrong.
        reason: String,
    },
    /// A bad obstacle.
    #[error("obstacle '{name}': {reason}")]
    Obstacle {
        /// Obstacle name.
        name: String,
        /// What is wrong.
        reason: String,
    },
    /// A bad disabled pair.
    #[error("disabled pair ('{a}', '{b}'): {reason}")]
    DisabledPair {
        /// First name.
        a: String,
        /// Second name.
        b: String,
        /// What is wrong.
        reason: String,
    },
    /// Bad options.
    #[error("collision options: {0}")]
    Options(String),
    /// Bad trajectory input.
    #[error("trajectory: {0}")]
    Trajectory(String),
}
