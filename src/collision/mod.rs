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
//! **Meshes** (see [`mesh`] and [`resolve`]): URIs relative to the model file, absolute,
//! `file://` or `package://` (searched in [`CollisionOptions::package_path`], then
//! `ROS_PACKAGE_PATH`, `AMENT_PREFIX_PATH` and the model's folder tree). A mesh that
//! cannot be *found* is, by default, skipped with a warning naming the model file, link
//! and URI, and the links left without any shape are listed by
//! [`CollisionModel::unprotected_links`]; [`MissingMeshes::Error`] makes it an error. A mesh that is found but
//! cannot be read is always an error.
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

pub mod mesh;
mod obstacle;
pub mod resolve;
mod shape;
mod trajectory;

pub use obstacle::{Obstacle, ObstacleShape, ObstacleSpec};
pub use shape::{CollisionShape, ShapeKind};
pub use trajectory::{DistanceSample, TrajectoryCollision, TrajectoryOptions, TrajectoryReport};

use crate::data::Data;
use crate::kinematics::forward_kinematics;
use crate::model::{Model, Shape, WORLD};
use crate::spatial::Se3;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::{Pose, Vector};
use serde::{Deserialize, Serialize};
use shape::{
    aabb_gap, distance_and_points, intersects, signed_distance, signed_distance_below, to_pose,
    within, Placed, Scratch,
};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

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
        let r = crate::spatial::Mat3::new(
            m.x_axis.x, m.y_axis.x, m.z_axis.x, m.x_axis.y, m.y_axis.y, m.z_axis.y, m.x_axis.z,
            m.y_axis.z, m.z_axis.z,
        );
        Se3::new(r, shape::to_vec3(p.translation))
    }
}

/// Base directory of a model's relative mesh URIs.
fn model_dir(model: &Model) -> Option<PathBuf> {
    Path::new(&model.source)
        .parent()
        .map(Path::to_path_buf)
        .filter(|p| !p.as_os_str().is_empty())
}

type MeshKey = (PathBuf, [u64; 3]);

/// Builds the shape of a geometry, loading (and caching) mesh files. `Ok(Err(why))`: the
/// mesh file was not found; `Err((is_mesh, why))`: a mesh that cannot be read, or a bad
/// primitive.
fn build_shape(
    shape: &Shape,
    base: Option<&Path>,
    pkgs: &resolve::PackagePaths,
    opts: &CollisionOptions,
    cache: &mut HashMap<MeshKey, CollisionShape>,
    notes: &mut Vec<String>,
) -> Result<Result<CollisionShape, String>, (bool, String)> {
    match shape {
        Shape::Mesh { uri, scale } => {
            let path = match resolve::resolve_with(uri, base, pkgs) {
                Ok(p) => p,
                Err(e) => return Ok(Err(e.0)),
            };
            let key = (path.clone(), scale.map(f64::to_bits));
            if let Some(s) = cache.get(&key) {
                return Ok(Ok(s.clone()));
            }
            let data =
                mesh::load_mesh(&path).map_err(|e| (true, format!("{}: {e}", path.display())))?;
            let (s, note) = CollisionShape::from_mesh(&data, *scale, opts.convex_hulls)
                .map_err(|e| (true, format!("{}: {e}", path.display())))?;
            if let Some(n) = note {
                notes.push(format!("{}: {n}", path.display()));
            }
            cache.insert(key, s.clone());
            Ok(Ok(s))
        }
        _ => CollisionShape::primitive(shape)
            .map(Ok)
            .map_err(|e| (false, e)),
    }
}

impl CollisionModel {
    /// Builds the scene of `model` with `obstacles` (see the module docs and
    /// [`CollisionOptions`]). Warnings (skipped meshes, flat meshes without a hull) are in
    /// [`CollisionModel::warnings`].
    pub fn new(
        model: &Model,
        obstacles: Vec<Obstacle>,
        opts: &CollisionOptions,
    ) -> Result<CollisionModel, CollisionError> {
        if !(opts.margin.is_finite() && opts.margin >= 0.0) {
            return Err(CollisionError::Options(format!(
                "margin must be finite and >= 0, got {}",
                opts.margin
            )));
        }
        let base = model_dir(model);
        let pkgs = resolve::PackagePaths::from_env(opts.package_path.clone());
        let mut cache: HashMap<MeshKey, CollisionShape> = HashMap::new();
        let mut warnings = Vec::new();
        let mut notes = Vec::new();
        let mut objects = Vec::new();
        let mut unprotected = Vec::new();
        for (li, link) in model.links.iter().enumerate() {
            let before = objects.len();
            for g in &link.collisions {
                let built = build_shape(
                    &g.shape,
                    base.as_deref(),
                    &pkgs,
                    opts,
                    &mut cache,
                    &mut notes,
                );
                let uri = match &g.shape {
                    Shape::Mesh { uri, .. } => uri.clone(),
                    _ => String::new(),
                };
                let cs = match built {
                    Ok(Ok(cs)) => cs,
                    Ok(Err(missing)) => {
                        if opts.missing_meshes == MissingMeshes::Error {
                            return Err(CollisionError::Mesh {
                                model: model.source.clone(),
                                link: link.name.clone(),
                                uri,
                                reason: missing,
                            });
                        }
                        warnings.push(format!(
                            "{}: link '{}': collision mesh '{}' skipped: {}",
                            model.source, link.name, uri, missing
                        ));
                        continue;
                    }
                    Err((true, reason)) => {
                        return Err(CollisionError::Mesh {
                            model: model.source.clone(),
                            link: link.name.clone(),
                            uri,
                            reason,
                        })
                    }
                    Err((false, reason)) => {
                        return Err(CollisionError::Geometry {
                            model: model.source.clone(),
                            link: link.name.clone(),
                            reason,
                        })
                    }
                };
                objects.push(Object {
                    owner: Body::Link(li),
                    body: link.body,
                    local: link.offset.mul(&g.origin).mul(&cs.frame),
                    center: cs.shape.compute_local_bounding_sphere().center,
                    shape: cs,
                });
            }
            if !link.collisions.is_empty() && objects.len() == before {
                unprotected.push(link.name.clone());
            }
        }
        if !unprotected.is_empty() {
            warnings.push(format!(
                "{}: {} link(s) without any collision shape (not protected): {}",
                model.source,
                unprotected.len(),
                unprotected.join(", ")
            ));
        }
        let n_robot = objects.len();

        // Obstacles.
        let mut names: HashMap<&str, Body> = model
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| (l.name.as_str(), Body::Link(i)))
            .collect();
        for (k, ob) in obstacles.iter().enumerate() {
            let err = |reason: String| CollisionError::Obstacle {
                name: ob.name.clone(),
                reason,
            };
            if ob.name.is_empty() {
                return Err(err("empty name".to_string()));
            }
            match names.insert(ob.name.as_str(), Body::Obstacle(k)) {
                Some(Body::Link(_)) => return Err(err("a link has the same name".to_string())),
                Some(Body::Obstacle(_)) => return Err(err("duplicate obstacle name".to_string())),
                None => {}
            }
            let base = opts.obstacle_dir.as_deref();
            let cs = match build_shape(&ob.shape, base, &pkgs, opts, &mut cache, &mut notes) {
                Ok(Ok(cs)) => cs,
                Ok(Err(reason)) | Err((_, reason)) => return Err(err(reason)),
            };
            let r = ob.pose.rot;
            if !(r.iter().chain(ob.pose.trans.iter()).all(|x| x.is_finite())
                && (r.transpose() * r - crate::spatial::Mat3::identity()).norm() < 1e-9)
            {
                return Err(err("pose: not a finite rigid transform".to_string()));
            }
            objects.push(Object {
                owner: Body::Obstacle(k),
                body: WORLD,
                local: ob.pose.mul(&cs.frame),
                center: cs.shape.compute_local_bounding_sphere().center,
                shape: cs,
            });
        }
        warnings.extend(notes);

        // Disabled pairs.
        let mut disabled: HashSet<(Body, Body)> = HashSet::new();
        for [a, b] in &opts.disabled_pairs {
            let err = |reason: &str| CollisionError::DisabledPair {
                a: a.clone(),
                b: b.clone(),
                reason: reason.to_string(),
            };
            let (Some(&ba), Some(&bb)) = (names.get(a.as_str()), names.get(b.as_str())) else {
                let unknown = if names.contains_key(a.as_str()) { b } else { a };
                return Err(err(&format!(
                    "'{unknown}' is neither a link nor an obstacle"
                )));
            };
            if matches!((ba, bb), (Body::Obstacle(_), Body::Obstacle(_))) {
                return Err(err("obstacles are never tested against each other"));
            }
            disabled.insert((ba.min(bb), ba.max(bb)));
        }

        let parent_body = |b: usize| {
            if b == WORLD {
                None
            } else {
                Some(model.parent[b])
            }
        };
        let adjacent = |la: usize, lb: usize| {
            let (ba, bb) = (model.links[la].body, model.links[lb].body);
            ba == bb || parent_body(ba) == Some(bb) || parent_body(bb) == Some(ba)
        };
        let mut self_pairs = Vec::new();
        for i in 0..n_robot {
            for j in i + 1..n_robot {
                let (Body::Link(la), Body::Link(lb)) = (objects[i].owner, objects[j].owner) else {
                    continue;
                };
                let key = (
                    objects[i].owner.min(objects[j].owner),
                    objects[i].owner.max(objects[j].owner),
                );
                if la == lb || adjacent(la, lb) || disabled.contains(&key) {
                    continue;
                }
                self_pairs.push([i as u32, j as u32]);
            }
        }
        let mut env_pairs = Vec::new();
        for i in 0..n_robot {
            for j in n_robot..objects.len() {
                let key = (objects[i].owner, objects[j].owner);
                if !disabled.contains(&key) {
                    env_pairs.push([i as u32, j as u32]);
                }
            }
        }
        let moving = (0..n_robot)
            .filter(|&i| objects[i].body != WORLD)
            .map(|i| i as u32)
            .collect();
        Ok(CollisionModel {
            objects,
            moving,
            link_names: model.links.iter().map(|l| l.name.clone()).collect(),
            obstacles,
            self_pairs,
            env_pairs,
            margin: opts.margin,
            nv: model.nv,
            nlinks: model.links.len(),
            warnings,
            unprotected,
        })
    }

    /// [`CollisionModel::new`] with obstacles described by [`ObstacleSpec`]s.
    pub fn from_specs(
        model: &Model,
        obstacles: &[ObstacleSpec],
        opts: &CollisionOptions,
    ) -> Result<CollisionModel, CollisionError> {
        let obs = obstacles
            .iter()
            .map(ObstacleSpec::to_obstacle)
            .collect::<Result<Vec<_>, _>>()?;
        Self::new(model, obs, opts)
    }

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

    #[inline]
    fn placed<'a>(&'a self, poses: &'a [Pose], aabbs: &'a [Aabb], k: u32) -> Placed<'a> {
        let k = k as usize;
        Placed {
            shape: &self.objects[k].shape,
            pose: &poses[k],
            aabb: &aabbs[k],
        }
    }

    /// Places the robot's shapes at configuration `q` (runs forward kinematics into
    /// `cd.kin`). Every query below reads the last update.
    pub fn update(&self, model: &Model, cd: &mut CollisionData, q: &[f64]) {
        assert!(
            model.nv == self.nv && model.links.len() == self.nlinks,
            "the collision model was built for another model"
        );
        forward_kinematics(model, &mut cd.kin, q);
        for &k in &self.moving {
            let o = &self.objects[k as usize];
            let pose = to_pose(&cd.kin.o_m_i[o.body].mul(&o.local));
            cd.aabbs[k as usize] = o.shape.aabb(&pose);
            cd.spheres[k as usize].0 = pose * o.center;
            cd.poses[k as usize] = pose;
        }
    }

    #[inline]
    fn pair_collides(&self, cd: &CollisionData, [i, j]: [u32; 2]) -> bool {
        let a = self.placed(&cd.poses, &cd.aabbs, i);
        let b = self.placed(&cd.poses, &cd.aabbs, j);
        if self.margin == 0.0 {
            a.aabb.intersects(b.aabb) && intersects(a, b)
        } else {
            aabb_gap(a.aabb, b.aabb) <= self.margin && within(a, b, self.margin)
        }
    }

    /// The first pair found in collision (signed distance ≤ margin), self pairs first;
    /// `None` when collision-free. Stops at the first hit.
    pub fn first_collision(&self, cd: &CollisionData, scope: Scope) -> Option<(Body, Body)> {
        for list in self.lists(scope) {
            for &p in list {
                if self.pair_collides(cd, p) {
                    return Some((
                        self.objects[p[0] as usize].owner,
                        self.objects[p[1] as usize].owner,
                    ));
                }
            }
        }
        None
    }

    /// [`CollisionModel::update`] then whether any pair of `scope` is in collision.
    pub fn in_collision(
        &self,
        model: &Model,
        cd: &mut CollisionData,
        q: &[f64],
        scope: Scope,
    ) -> bool {
        self.update(model, cd, q);
        self.first_collision(cd, scope).is_some()
    }

    /// Every body pair of `scope` in collision, most penetrating first (`out` is
    /// cleared; a body pair with several shape pairs appears once, with its minimum).
    pub fn collisions(&self, cd: &mut CollisionData, scope: Scope, out: &mut Vec<PairDistance>) {
        out.clear();
        for list in self.lists(scope) {
            for &p in list {
                if !self.pair_collides(cd, p) {
                    continue;
                }
                let (d, pa, pb) = distance_and_points(
                    self.placed(&cd.poses, &cd.aabbs, p[0]),
                    self.placed(&cd.poses, &cd.aabbs, p[1]),
                    &mut cd.scratch,
                );
                let (a, b) = (
                    self.objects[p[0] as usize].owner,
                    self.objects[p[1] as usize].owner,
                );
                match out.iter_mut().find(|x| x.a == a && x.b == b) {
                    Some(x) if x.distance <= d => {}
                    Some(x) => {
                        x.distance = d;
                        x.point_a = pa.into();
                        x.point_b = pb.into();
                    }
                    None => out.push(PairDistance {
                        a,
                        b,
                        distance: d,
                        point_a: pa.into(),
                        point_b: pb.into(),
                    }),
                }
            }
        }
        out.sort_by(|x, y| x.distance.total_cmp(&y.distance));
    }

    /// The minimum signed distance over the pairs of `scope` and the pair achieving it
    /// (`None` when the scope has no pair).
    pub fn min_distance(&self, cd: &mut CollisionData, scope: Scope) -> Option<PairDistance> {
        let CollisionData {
            poses,
            aabbs,
            spheres,
            order,
            scratch,
            ..
        } = cd;
        order.clear();
        for list in self.lists(scope) {
            for &p in list {
                let (i, j) = (p[0] as usize, p[1] as usize);
                let (si, sj) = (&spheres[i], &spheres[j]);
                let ball_gap = (si.0 - sj.0).length() - si.1 - sj.1;
                let gap = aabb_gap(&aabbs[i], &aabbs[j]).max(ball_gap);
                order.push((gap, p));
            }
        }
        order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        let mut best = f64::INFINITY;
        let mut arg = None;
        for &(gap, p) in order.iter() {
            // Overlapping boxes (gap 0) may hide any depth: only a positive gap bounds.
            if gap > 0.0 && gap >= best {
                break;
            }
            let a = self.placed(poses, aabbs, p[0]);
            let b = self.placed(poses, aabbs, p[1]);
            if let Some(d) = signed_distance_below(a, b, best, scratch) {
                best = d;
                arg = Some(p);
            }
        }
        let p = arg?;
        let (d, pa, pb) = distance_and_points(
            self.placed(poses, aabbs, p[0]),
            self.placed(poses, aabbs, p[1]),
            scratch,
        );
        Some(PairDistance {
            a: self.objects[p[0] as usize].owner,
            b: self.objects[p[1] as usize].owner,
            distance: d,
            point_a: pa.into(),
            point_b: pb.into(),
        })
    }

    /// [`CollisionModel::update`] then the environment and self minimum distances.
    pub fn distances(&self, model: &Model, cd: &mut CollisionData, q: &[f64]) -> Distances {
        self.update(model, cd, q);
        Distances {
            environment: self.min_distance(cd, Scope::Environment),
            self_collision: self.min_distance(cd, Scope::SelfCollision),
        }
    }

    /// Signed distance between two bodies after the last update, whether or not the
    /// pair is tested (adjacent and disabled pairs included); `None` when either has no
    /// shape.
    pub fn body_distance(&self, cd: &CollisionData, a: Body, b: Body) -> Option<f64> {
        let mut scratch = Scratch::default();
        let ka: Vec<u32> = (0..self.objects.len() as u32)
            .filter(|&k| self.objects[k as usize].owner == a)
            .collect();
        let kb: Vec<u32> = (0..self.objects.len() as u32)
            .filter(|&k| self.objects[k as usize].owner == b)
            .collect();
        ka.iter()
            .flat_map(|&i| kb.iter().map(move |&j| (i, j)))
            .map(|(i, j)| {
                signed_distance(
                    self.placed(&cd.poses, &cd.aabbs, i),
                    self.placed(&cd.poses, &cd.aabbs, j),
                    &mut scratch,
                )
            })
            .min_by(f64::total_cmp)
    }
}
