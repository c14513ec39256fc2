//! Collision checking: self-collision among the robot's links, collision with
//! environment obstacles, signed minimum distances with the pair achieving them, and the
//! first collision along a sampled trajectory.
//!
//! Built on parry3d-f64 0.31. Its API is in glam types (`glamx::DPose3`, `DVec3`, `DQuat`):
//! they are converted at this module's boundary (private `shape.rs`), and nothing public
//! here exposes them; parry no longer uses nalgebra, so the tree keeps one nalgebra.
//!
//! - [`CollisionModel`] (immutable, built once): a shape for every `<collision>` of every
//!   link (box, cylinder, sphere, capsule, or a mesh from STL/OBJ/DAE, optionally replaced
//!   by its convex hull, see [`CollisionOptions`]) and for every [`Obstacle`], and the
//!   lists of pairs to test.
//! - [`CollisionData`] (per thread): the kinematics workspace, world poses and bounding
//!   volumes of the shapes, and scratch space. [`CollisionModel::update`],
//!   [`CollisionModel::first_collision`] and [`CollisionModel::min_distance`] allocate
//!   nothing once it is warm, except parry's `contact` on overlapping triangle meshes.
//!
//! **Pairs.** Environment pairs: every robot shape against every obstacle. Self pairs:
//! every two shapes on non-adjacent links. Two links are *adjacent* when they ride on
//! the same body (rigidly attached, e.g. through fixed joints, including links fixed to
//! the world) or on bodies one joint apart (a body and its parent body, or a body
//! attached to the world and a world-fixed link). [`CollisionOptions::disabled_pairs`]
//! removes further pairs by name (link–link or link–obstacle). Obstacles are never
//! tested against each other.
//!
//! **Distances are signed**: positive separation, negative penetration (minus the
//! shortest translation that separates the pair). A pair is *in collision* when its
//! signed distance is ≤ [`CollisionOptions::margin`] (0 by default: touching counts).
//! - Two spheres/capsules: closed form (segment–segment distance minus the radii), exact
//!   both ways.
//! - A capsule against a box, cylinder or convex hull: the capsule's segment against the
//!   shape (GJK, EPA when overlapping) minus the radius, exact both ways.
//! - Two triangle meshes apart: closed-form triangle–triangle distances over both meshes'
//!   box trees descended together (private `mesh_pair.rs`), exact to rounding; a query
//!   that only asks whether the distance is below a bound uses parry's `closest_points`.
//! - Other pairs: parry's `distance` when apart (spheres by point projection, exact; GJK
//!   otherwise, relative accuracy 1.5e-7); when overlapping, GJK+EPA for convex pairs
//!   (exact for polytopes), parry's `contact` for spheres (exact) and triangle meshes (the
//!   deepest *triangle* contact: crossing surfaces report a depth near 0 — use convex
//!   hulls when depths matter).
//! - A shape wholly inside a *closed* triangle mesh touches no triangle: a containment
//!   test catches it, reported as minus its distance to the enclosing surface (a lower
//!   bound of the depth). Open meshes are surfaces only.
//!
//! **Broad phase**: world AABBs and bounding spheres of the moving shapes are refreshed
//! per configuration (static shapes are placed once); a pair is tested only when its boxes
//! are within the margin. The minimum-distance search visits pairs by increasing lower
//! bound (the larger of the box gap and the sphere gap), stops when the bound exceeds the
//! best distance so far, and asks each remaining pair only whether it beats that distance
//! (GJK stops at the first separating plane that proves it does not).
//!
//! **Continuous certification** of a timed trajectory ([`Certifier`], built once per scene
//! by [`CollisionModel::certifier`]): every tested pair proven apart at every instant of
//! the curve, not only at samples, from a bound of the joint path length between samples
//! (sampled velocities and an acceleration bound) and per-pair motion coefficients, with
//! bounding volumes, convex hulls and exact shapes near contact only; the exact closest
//! approaches over the samples by branch and bound (see `certify.rs`, `bounds.rs`,
//! `closest.rs`).
//!
//! **Meshes** (see [`mesh`] and [`resolve`]): URIs relative to the model file, absolute,
//! `file://` or `package://` (searched in [`CollisionOptions::package_path`], then
//! `ROS_PACKAGE_PATH`, `AMENT_PREFIX_PATH` and the model's folder tree). A mesh that
//! cannot be *found* is, by default, skipped with a warning naming the model file, link
//! and URI, and the links left without any shape are listed by
//! [`CollisionModel::unprotected_links`]; [`MissingMeshes::Error`] makes it an error. A mesh that
//! is found but cannot be read is always an error.
//!
//! ```
//! use armsim::collision::{CollisionData, CollisionModel, CollisionOptions, Obstacle, Scope};
//! use armsim::model::Model;
//! let (model, _) = Model::build(armsim::model::chain::chain_spec(2)).unwrap();
//! let wall = Obstacle::cuboid("wall", [0.1, 1.0, 1.0], [2.0, 0.0, 0.0]);
//! let cm = CollisionModel::new(&model, vec![wall], &CollisionOptions::default()).unwrap();
//! let mut cd = CollisionData::new(&model, &cm);
//! cm.update(&model, &mut cd, &[0.0, 0.0]);
//! assert!(cm.first_collision(&cd, Scope::All).is_none());
//! ```

mod bounds;
mod certify;
mod closest;
mod closest_features;
mod collision_error;
mod collision_scene;
pub mod mesh;
mod mesh_pair;
mod model_build;
mod obstacle;
mod query;
pub mod resolve;
mod segment;
mod shape;
mod shape_error;
mod trajectory;

pub use bounds::{half_path_bound, Certifier, Evaluations};
pub use certify::{
    Certificate, CertifiedMotion, CertifyOptions, ClearanceBound, SampleFn, SampleMin,
};
pub use obstacle::{Obstacle, ObstacleShape, ObstacleSpec};
pub use segment::SegmentScratch;
pub use shape::{CollisionShape, ShapeKind, MAX_COORD};
pub use shape_error::ShapeError;
pub use trajectory::{DistanceSample, TrajectoryCollision, TrajectoryOptions, TrajectoryReport};

pub use collision_error::CollisionError;
pub use collision_scene::{
    Body, CollisionData, CollisionModel, CollisionOptions, Distances, MissingMeshes, PairDistance,
    Scope,
};
