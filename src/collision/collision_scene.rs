//! The collision scene's data: the immutable [`CollisionModel`] (its shapes as objects on
//! bodies, pair lists, margin, warnings), the per-thread [`CollisionData`], the bodies and
//! pairs queries name ([`Body`], [`Scope`], [`PairDistance`], [`Distances`]) and the scene
//! options ([`CollisionOptions`], [`MissingMeshes`]). Building is in `model_build.rs`,
//! the queries in `query.rs`.

use crate::collision::obstacle::Obstacle;
use crate::collision::shape::{to_pose, to_vec3, CollisionShape, Scratch};
use crate::core::spatial::Se3;
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Pose, Vector};
use serde::{Deserialize, Serialize};
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
    /// (see [`crate::collision::resolve`]).
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

/// One shape of the scene.
#[derive(Clone, Debug)]
pub(super) struct Object {
    pub(super) owner: Body,
    /// Body carrying the shape, or [`WORLD`] (static: robot links fixed to the world, and
    /// obstacles).
    pub(super) body: usize,
    /// Body frame (world for static shapes) → parry shape frame.
    pub(super) local: Se3,
    pub(super) shape: CollisionShape,
    /// Centre of the local bounding sphere, in the parry shape frame.
    pub(super) center: Vector,
}

/// The immutable collision scene of a model (see [`crate::collision`]).
#[derive(Clone, Debug)]
pub struct CollisionModel {
    pub(super) objects: Vec<Object>,
    /// Indices of the objects that move with the robot.
    pub(super) moving: Vec<u32>,
    pub(super) link_names: Vec<String>,
    pub(super) obstacles: Vec<Obstacle>,
    pub(super) self_pairs: Vec<[u32; 2]>,
    pub(super) env_pairs: Vec<[u32; 2]>,
    pub(super) margin: f64,
    pub(super) nv: usize,
    pub(super) nlinks: usize,
    pub(super) warnings: Vec<String>,
    pub(super) unprotected: Vec<String>,
}

/// Per-thread workspace for [`CollisionModel`] queries.
#[derive(Clone, Debug)]
pub struct CollisionData {
    /// Kinematics workspace (body placements after [`CollisionModel::update`]).
    pub kin: Data,
    pub(super) poses: Vec<Pose>,
    pub(super) aabbs: Vec<Aabb>,
    /// World bounding spheres (centre, radius).
    pub(super) spheres: Vec<(Vector, f64)>,
    pub(super) order: Vec<(f64, [u32; 2])>,
    pub(super) scratch: Scratch,
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
        Se3::new(r, to_vec3(p.translation))
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

    pub(super) fn lists(&self, scope: Scope) -> [&[[u32; 2]]; 2] {
        match scope {
            Scope::All => [&self.self_pairs, &self.env_pairs],
            Scope::SelfCollision => [&self.self_pairs, &[]],
            Scope::Environment => [&[], &self.env_pairs],
        }
    }
}
