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
pub mod mesh;
mod model_build;
mod obstacle;
mod query;
pub mod resolve;
mod segment;
mod shape;
mod trajectory;

pub use bounds::{half_path_bound, Certifier, Evaluations};
pub use certify::{
    Certificate, CertifiedMotion, CertifyOptions, ClearanceBound, SampleFn, SampleMin,
};
pub use obstacle::{Obstacle, ObstacleShape, ObstacleSpec};
pub use segment::SegmentScratch;
pub use shape::{CollisionShape, ShapeKind, MAX_COORD};
pub use trajectory::{DistanceSample, TrajectoryCollision, TrajectoryOptions, TrajectoryReport};

use crate::core::spatial::Se3;
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Pose, Vector};
use serde::{Deserialize, Serialize};
use shape::{to_pose, Scratch};
use std::collections::HashSet;
use std::path::PathBuf;

/// What to do with a mesh file that cannot be found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MissingMeshes {
    /// Skip the geometry with a warning; the link may be left unprotected.
    #[default]
    Warn,
    /// Fail with an error naming the model file, the link and the URI.
    Error,
}

/// Scene options.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CollisionOptions {
    /// Replace every mesh (links and obstacles) by its convex hull: faster, conservative.
    pub convex_hulls: bool,
    /// Missing mesh files: warn and skip (default) or fail.
    pub missing_meshes: MissingMeshes,
    /// Pairs never tested, by name: two links, or a link and an obstacle.
    pub disabled_pairs: Vec<[String; 2]>,
    /// Safety margin (m): a pair is in collision when its signed distance is ≤ margin.
    pub margin: f64,
    /// Directory relative obstacle mesh paths start from (default: the current one).
    pub obstacle_dir: Option<PathBuf>,
    /// Directories searched first for `package://` URIs (each containing packages or being
    /// one), before `ROS_PACKAGE_PATH`, `AMENT_PREFIX_PATH` and the model's folder tree
    /// (see [`resolve`]).
    pub package_path: Vec<PathBuf>,
}

/// Which pairs a query looks at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scope {
    /// Self pairs and environment pairs.
    #[default]
    All,
    /// Robot link against robot link.
    SelfCollision,
    /// Robot link against obstacle.
    Environment,
}

/// A link (index into `Model::links`) or an obstacle (index into
/// [`CollisionModel::obstacles`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Body {
    /// A robot link.
    Link(usize),
    /// An environment obstacle.
    Obstacle(usize),
}

/// The signed distance between two bodies and the world points achieving it. `a` is
/// always a link; `b` a link (self pair) or an obstacle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PairDistance {
    /// First body (a link).
    pub a: Body,
    /// Second body.
    pub b: Body,
    /// Signed distance (m): positive apart, negative penetrating.
    pub distance: f64,
    /// Witness point on `a` (world): closest point, or deepest contact point.
    pub point_a: [f64; 3],
    /// Witness point on `b` (world).
    pub point_b: [f64; 3],
}

/// Minimum distances of one configuration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Distances {
    /// Robot against environment (`None` without obstacles or pairs).
    pub environment: Option<PairDistance>,
    /// Robot against itself (`None` without self pairs).
    pub self_collision: Option<PairDistance>,
}

/// Errors building a scene or checking a trajectory.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CollisionError {
    /// A collision mesh could not be found (with [`MissingMeshes::Error`]) or read.
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

/// One shape of the scene.
#[derive(Clone, Debug)]
struct Object {
    owner: Body,
    /// Body carrying the shape, or [`WORLD`] (static: robot links fixed to the world, and
    /// obstacles).
    body: usize,
    /// Body frame (world for static shapes) → parry shape frame.
    local: Se3,
    shape: CollisionShape,
    /// Centre of the local bounding sphere, in the parry shape frame.
    center: Vector,
}

/// The immutable collision scene of a model (see the module docs).
#[derive(Clone, Debug)]
pub struct CollisionModel {
    objects: Vec<Object>,
    /// Indices of the objects that move with the robot.
    moving: Vec<u32>,
    link_names: Vec<String>,
    obstacles: Vec<Obstacle>,
    self_pairs: Vec<[u32; 2]>,
    env_pairs: Vec<[u32; 2]>,
    margin: f64,
    nv: usize,
    nlinks: usize,
    warnings: Vec<String>,
    unprotected: Vec<String>,
}

/// Per-thread workspace for [`CollisionModel`] queries.
#[derive(Clone, Debug)]
pub struct CollisionData {
    /// Kinematics workspace (body placements after [`CollisionModel::update`]).
    pub kin: Data,
    poses: Vec<Pose>,
    aabbs: Vec<Aabb>,
    /// World bounding spheres (centre, radius).
    spheres: Vec<(Vector, f64)>,
    order: Vec<(f64, [u32; 2])>,
    scratch: Scratch,
    /// Interpolated configuration (trajectory checks).
    pub(crate) q: Vec<f64>,
}

impl CollisionData {
    /// A workspace for `cm` (built from `model`); static shapes are placed here once.
    pub fn new(model: &Model, cm: &CollisionModel) -> Self {
        let poses: Vec<Pose> = cm
            .objects
            .iter()
            .map(|o| {
                if o.body == WORLD {
                    to_pose(&o.local)
                } else {
                    Pose::IDENTITY
                }
            })
            .collect();
        let aabbs = cm
            .objects
            .iter()
            .zip(&poses)
            .map(|(o, p)| o.shape.aabb(p))
            .collect();
        let spheres = cm
            .objects
            .iter()
            .zip(&poses)
            .map(|(o, p)| {
                let s = o.shape.shape.compute_local_bounding_sphere();
                (*p * s.center, s.radius)
            })
            .collect();
        let npairs = cm.self_pairs.len() + cm.env_pairs.len();
        Self {
            kin: Data::new(model),
            poses,
            aabbs,
            spheres,
            order: Vec::with_capacity(npairs),
            scratch: Scratch::default(),
            q: vec![0.0; model.nv],
        }
    }

    /// World pose (rotation matrix, translation) of shape `k` after the last update.
    pub fn shape_pose(&self, k: usize) -> Se3 {
        let p = &self.poses[k];
        let m = parry3d_f64::math::Matrix::from_quat(p.rotation);
        let r = crate::core::spatial::Mat3::new(
            m.x_axis.x, m.y_axis.x, m.z_axis.x, m.x_axis.y, m.y_axis.y, m.z_axis.y, m.x_axis.z,
            m.y_axis.z, m.z_axis.z,
        );
        Se3::new(r, shape::to_vec3(p.translation))
    }
}

impl CollisionModel {
    /// Warnings from building: skipped meshes (each naming the model file, link and URI),
    /// the summary of unprotected links, flat meshes kept without a hull.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Links that declare collision geometry but got no shape (all their meshes missing).
    pub fn unprotected_links(&self) -> &[String] {
        &self.unprotected
    }

    /// The obstacles, in the order given.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// Name of a link or obstacle.
    pub fn body_name(&self, b: Body) -> &str {
        match b {
            Body::Link(i) => &self.link_names[i],
            Body::Obstacle(i) => &self.obstacles[i].name,
        }
    }

    /// Number of shapes (robot and obstacles).
    pub fn num_shapes(&self) -> usize {
        self.objects.len()
    }

    /// The owner and the shape of shape `k` (`k < num_shapes()`).
    pub fn shape(&self, k: usize) -> (Body, &CollisionShape) {
        (self.objects[k].owner, &self.objects[k].shape)
    }

    /// The distinct body pairs tested in `scope`, in build order (a pair of links with
    /// several shapes appears once).
    pub fn tested_pairs(&self, scope: Scope) -> Vec<(Body, Body)> {
        let mut seen = HashSet::new();
        let mut out = Vec::new();
        for list in self.lists(scope) {
            for &[i, j] in list {
                let p = (
                    self.objects[i as usize].owner,
                    self.objects[j as usize].owner,
                );
                if seen.insert(p) {
                    out.push(p);
                }
            }
        }
        out
    }

    fn lists(&self, scope: Scope) -> [&[[u32; 2]]; 2] {
        match scope {
            Scope::All => [&self.self_pairs, &self.env_pairs],
            Scope::SelfCollision => [&self.self_pairs, &[]],
            Scope::Environment => [&[], &self.env_pairs],
        }
    }
}
