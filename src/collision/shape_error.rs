//! [`ShapeError`]: why a geometry cannot become a collision shape (a primitive's
//! dimension, a mesh's scale, a triangle mesh parry refuses).

/// Why a geometry cannot become a collision shape.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// A dimension that must be finite and positive (a box size, a radius, a length).
    #[error("{what} must be finite and positive, got {value}")]
    NotPositive {
        /// The dimension, e.g. `box size[1]`, `sphere radius`.
        what: String,
        /// The value given.
        value: f64,
    },
    /// A dimension beyond [`crate::collision::shape::MAX_COORD`].
    #[error("{what} of {value:e} m is larger than the {max:e} m accepted for collision geometry")]
    TooLarge {
        /// The dimension.
        what: String,
        /// The value given.
        value: f64,
        /// The limit.
        max: f64,
    },
    /// A capsule length that is negative or not finite.
    #[error("capsule length must be finite, >= 0 and at most 1e9 m, got {0}")]
    CapsuleLength(f64),
    /// A mesh given where a primitive was expected.
    #[error("a mesh needs its file loaded")]
    MeshNotLoaded,
    /// A mesh scale with a zero or non-finite factor.
    #[error("mesh scale must be finite and non-zero, got {0:?}")]
    MeshScale([f64; 3]),
    /// A mesh scale that takes a vertex beyond the limit
    /// ([`crate::collision::MAX_COORD`]).
    #[error(
        "mesh scale {scale:?} takes a vertex to ({:e}, {:e}, {:e}), beyond the {limit:e} m \
         accepted for collision geometry",
        .vertex[0], .vertex[1], .vertex[2]
    )]
    BeyondRange {
        /// The scale.
        scale: [f64; 3],
        /// The scaled vertex.
        vertex: [f64; 3],
        /// The farthest a vertex may lie from the mesh origin (m).
        limit: f64,
    },
    /// A triangle mesh parry refuses (its error, debug-printed).
    #[error("invalid triangle mesh: {0}")]
    InvalidTriMesh(String),
}
