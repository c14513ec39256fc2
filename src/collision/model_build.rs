//! Building a [`CollisionModel`]: the links' shapes (meshes loaded once and cached, missing
//! ones skipped or refused), the obstacles' shapes, the disabled pairs by name, and the
//! self and environment pair lists (see the module docs for which pairs are tested).

use crate::collision::collision_error::CollisionError;
use crate::collision::collision_scene::{
    Body, CollisionModel, CollisionOptions, MissingMeshes, Object,
};
use crate::collision::mesh;
use crate::collision::obstacle::{Obstacle, ObstacleSpec};
use crate::collision::resolve;
use crate::collision::shape::CollisionShape;
use crate::collision::shape_error::ShapeError;
use crate::core::diag::LocatedError;
use crate::model::{Model, Shape, WORLD};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// Base directory of a model's relative mesh URIs.
fn model_dir(model: &Model) -> Option<PathBuf> {
    Path::new(&model.source)
        .parent()
        .map(Path::to_path_buf)
        .filter(|p| !p.as_os_str().is_empty())
}

type MeshKey = (PathBuf, [u64; 3]);

/// Why a geometry got no shape.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum ShapeFailure {
    /// The mesh file was not found (skipped or refused, [`MissingMeshes`]).
    #[error("{0}")]
    Missing(String),
    /// The mesh file cannot be read.
    #[error("{0}")]
    Unreadable(LocatedError),
    /// The mesh read cannot become a shape (its scale).
    #[error("{path}: {problem}")]
    BadMesh {
        /// The mesh file.
        path: String,
        /// What is wrong.
        problem: ShapeError,
    },
    /// A bad primitive.
    #[error("{0}")]
    BadPrimitive(ShapeError),
}

/// Builds the shape of a geometry, loading (and caching) mesh files.
fn build_shape(
    shape: &Shape,
    base: Option<&Path>,
    pkgs: &resolve::PackagePaths,
    opts: &CollisionOptions,
    cache: &mut HashMap<MeshKey, CollisionShape>,
    notes: &mut Vec<String>,
) -> Result<CollisionShape, ShapeFailure> {
    match shape {
        Shape::Mesh { uri, scale } => {
            let path =
                resolve::resolve_with(uri, base, pkgs).map_err(|e| ShapeFailure::Missing(e.0))?;
            let key = (path.clone(), scale.map(f64::to_bits));
            if let Some(s) = cache.get(&key) {
                return Ok(s.clone());
            }
            let data = mesh::load_mesh(&path).map_err(ShapeFailure::Unreadable)?;
            // What the reader skipped (a DAE instance naming no geometry): a warning, an
            // error where missing meshes are (`--strict`).
            let file = path.display().to_string();
            if let Some(w) = data.warnings.first() {
                if opts.missing_meshes == MissingMeshes::Error {
                    return Err(ShapeFailure::Unreadable(w.clone().in_file(&file)));
                }
            }
            notes.extend(
                data.warnings
                    .iter()
                    .map(|w| w.clone().in_file(&file).to_string()),
            );
            let (s, note) =
                CollisionShape::from_mesh(&data, *scale, opts.convex_hulls).map_err(|problem| {
                    ShapeFailure::BadMesh {
                        path: path.display().to_string(),
                        problem,
                    }
                })?;
            if let Some(n) = note {
                notes.push(format!("{}: {n}", path.display()));
            }
            cache.insert(key, s.clone());
            Ok(s)
        }
        _ => CollisionShape::primitive(shape).map_err(ShapeFailure::BadPrimitive),
    }
}

/// Loads shapes for one scene: the package search path, the mesh cache and the notes
/// loading leaves (flat meshes kept without a hull).
struct ShapeLoader<'o> {
    opts: &'o CollisionOptions,
    pkgs: resolve::PackagePaths,
    cache: HashMap<MeshKey, CollisionShape>,
    notes: Vec<String>,
}

impl<'o> ShapeLoader<'o> {
    fn new(opts: &'o CollisionOptions) -> Self {
        Self {
            opts,
            pkgs: resolve::PackagePaths::from_env(opts.package_path.clone()),
            cache: HashMap::new(),
            notes: Vec::new(),
        }
    }

    /// [`build_shape`] with relative mesh paths starting at `base`.
    fn load(&mut self, shape: &Shape, base: Option<&Path>) -> Result<CollisionShape, ShapeFailure> {
        build_shape(
            shape,
            base,
            &self.pkgs,
            self.opts,
            &mut self.cache,
            &mut self.notes,
        )
    }
}

/// The robot's shapes, the warnings about skipped meshes and unprotected links, and the
/// unprotected links.
struct RobotShapes {
    objects: Vec<Object>,
    warnings: Vec<String>,
    unprotected: Vec<String>,
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
        Self::new_with(model, obstacles, opts, &mut ShapeLoader::new(opts))
    }

    /// [`CollisionModel::from_specs`] for several models of one robot (the bare arm and
    /// the arm with a grasped part, say) with the same obstacles: each mesh file is loaded
    /// once for all of them. Loading notes go to the first scene's warnings.
    pub fn from_specs_for(
        models: &[&Model],
        obstacles: &[ObstacleSpec],
        opts: &CollisionOptions,
    ) -> Result<Vec<CollisionModel>, CollisionError> {
        let obs = obstacles
            .iter()
            .map(ObstacleSpec::to_obstacle)
            .collect::<Result<Vec<_>, _>>()?;
        let mut loader = ShapeLoader::new(opts);
        models
            .iter()
            .map(|m| Self::new_with(m, obs.clone(), opts, &mut loader))
            .collect()
    }

    fn new_with(
        model: &Model,
        obstacles: Vec<Obstacle>,
        opts: &CollisionOptions,
        loader: &mut ShapeLoader,
    ) -> Result<CollisionModel, CollisionError> {
        if !(opts.margin.is_finite() && opts.margin >= 0.0) {
            return Err(CollisionError::Options(format!(
                "margin must be finite and >= 0, got {}",
                opts.margin
            )));
        }
        let RobotShapes {
            mut objects,
            mut warnings,
            unprotected,
        } = robot_shapes(model, loader)?;
        let n_robot = objects.len();
        let names = add_obstacles(model, &obstacles, loader, &mut objects)?;
        warnings.append(&mut loader.notes);
        let disabled = disabled_pairs(&names, opts)?;
        let self_pairs = self_pairs(model, &objects[..n_robot], &disabled);
        let env_pairs = env_pairs(&objects, n_robot, &disabled);
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
}

/// A shape for every `<collision>` of every link; a missing mesh is skipped with a
/// warning or refused ([`MissingMeshes`]), a link left without any shape is unprotected.
fn robot_shapes(model: &Model, loader: &mut ShapeLoader) -> Result<RobotShapes, CollisionError> {
    let base = model_dir(model);
    let mut warnings = Vec::new();
    let mut objects = Vec::new();
    let mut unprotected = Vec::new();
    for (li, link) in model.links.iter().enumerate() {
        let before = objects.len();
        for g in &link.collisions {
            let built = loader.load(&g.shape, base.as_deref());
            let uri = match &g.shape {
                Shape::Mesh { uri, .. } => uri.clone(),
                _ => String::new(),
            };
            let cs = match built {
                Ok(cs) => cs,
                Err(ShapeFailure::Missing(missing)) => {
                    if loader.opts.missing_meshes == MissingMeshes::Error {
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
                Err(e @ (ShapeFailure::Unreadable(_) | ShapeFailure::BadMesh { .. })) => {
                    return Err(CollisionError::Mesh {
                        model: model.source.clone(),
                        link: link.name.clone(),
                        uri,
                        reason: e.to_string(),
                    })
                }
                Err(ShapeFailure::BadPrimitive(e)) => {
                    return Err(CollisionError::Geometry {
                        model: model.source.clone(),
                        link: link.name.clone(),
                        reason: e.to_string(),
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
    Ok(RobotShapes {
        objects,
        warnings,
        unprotected,
    })
}

/// Appends the obstacles' shapes (static, in the world) to `objects`, refusing empty,
/// duplicate or link names and poses that are not rigid; returns every body by name.
fn add_obstacles<'a>(
    model: &'a Model,
    obstacles: &'a [Obstacle],
    loader: &mut ShapeLoader<'_>,
    objects: &mut Vec<Object>,
) -> Result<HashMap<&'a str, Body>, CollisionError> {
    let obstacle_dir = loader.opts.obstacle_dir.as_deref();
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
        let cs = loader
            .load(&ob.shape, obstacle_dir)
            .map_err(|e| err(e.to_string()))?;
        let r = ob.pose.rot;
        if !(r.iter().chain(ob.pose.trans.iter()).all(|x| x.is_finite())
            && (r.transpose() * r - crate::core::spatial::Mat3::identity()).norm() < 1e-9)
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
    Ok(names)
}

/// [`CollisionOptions::disabled_pairs`] resolved to bodies (smaller first); a name that is
/// neither a link nor an obstacle, or two obstacles, is an error.
fn disabled_pairs(
    names: &HashMap<&str, Body>,
    opts: &CollisionOptions,
) -> Result<HashSet<(Body, Body)>, CollisionError> {
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
    Ok(disabled)
}

/// Every two robot shapes on different, non-adjacent links whose pair is not disabled.
fn self_pairs(model: &Model, robot: &[Object], disabled: &HashSet<(Body, Body)>) -> Vec<[u32; 2]> {
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
    for i in 0..robot.len() {
        for j in i + 1..robot.len() {
            let (Body::Link(la), Body::Link(lb)) = (robot[i].owner, robot[j].owner) else {
                continue;
            };
            let key = (
                robot[i].owner.min(robot[j].owner),
                robot[i].owner.max(robot[j].owner),
            );
            if la == lb || adjacent(la, lb) || disabled.contains(&key) {
                continue;
            }
            self_pairs.push([i as u32, j as u32]);
        }
    }
    self_pairs
}

/// Every robot shape (the first `n_robot` objects) against every obstacle shape, unless
/// the pair is disabled.
fn env_pairs(
    objects: &[Object],
    n_robot: usize,
    disabled: &HashSet<(Body, Body)>,
) -> Vec<[u32; 2]> {
    let mut env_pairs = Vec::new();
    for i in 0..n_robot {
        for j in n_robot..objects.len() {
            let key = (objects[i].owner, objects[j].owner);
            if !disabled.contains(&key) {
                env_pairs.push([i as u32, j as u32]);
            }
        }
    }
    env_pairs
}
