//! The robot's collision model for planning: spheres per link, in the frame of the body
//! that carries them, with a bounding sphere per link and the motion-bound coefficients of
//! continuous checking.
//!
//! **Sources.** A link's `<collision>` spheres are taken as given (the spherized Panda and
//! UR5 of the benchmark); boxes, cylinders and capsules are covered by
//! [`crate::planning::spherize::cover`] with overshoot at most [`SphereOptions::max_overshoot`].
//! Meshes (resolved relative to the model file, as [`crate::collision`] does) are covered
//! the same way from their signed distance ([`crate::planning::mesh_sdf`]): closed meshes with the
//! same two guarantees; open meshes on their surface only (a note in
//! [`SphereModel::warnings`]). A mesh that cannot be found or read is reported there and
//! left unchecked.
//!
//! **Motion bound.** Along a straight joint-space segment, the centre `c` of a sphere on
//! body `b` moves with speed `‖ċ‖ ≤ Σ_k |q̇_k| ρ_k`, the sum over the movable ancestors `k`
//! of `b` (itself included): a revolute joint moves `c` at `|q̇_k| · dist(c, axis_k)` and
//! `dist(c, axis_k) ≤ |c − o_k| ≤ Σ_{m ∈ k→b, m ≠ k} (|t_m| + s_m) + |p|`, the chain of
//! placement translations `t_m` down to the body, the largest slides `s_m` of the
//! prismatic joints among them (over their limits) and the centre's offset `p` in the body
//! frame (triangle inequality, whatever the configuration); a prismatic joint moves it at
//! `|q̇_k|`. Mimic bodies add `|multiplier| ρ_k` to their master's coordinate.
//! [`SphereModel::rho`] stores, per sphere, these coefficients per coordinate.

use crate::collision::mesh::load_mesh;
use crate::collision::resolve::{resolve_with, NotFound, PackagePaths};
use crate::core::diag::LocatedError;
use crate::core::spatial::{Se3, Vec3};
use crate::model::{Model, Shape, WORLD};
use crate::planning::mesh_sdf::{MeshSdf, MeshSdfError};
use crate::planning::spherize::{cover, cover_sdf, Primitive};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The range of [`SphereOptions::max_overshoot`] the front ends accept (m): below 0.1 mm
/// the cover of a robot's meshes takes minutes and millions of spheres; above 10 cm the
/// spheres no longer describe an arm.
pub const OVERSHOOT_RANGE: (f64, f64) = (1e-4, 0.1);

/// How to build the sphere model.
#[derive(Clone, Debug)]
pub struct SphereOptions {
    /// Largest distance a generated sphere may reach outside the primitive it covers (m).
    pub max_overshoot: f64,
    /// Directories searched first for `package://` mesh URIs (then the environment and
    /// the model file's ancestors, as [`crate::collision`] does).
    pub package_path: Vec<PathBuf>,
    /// Smaller overshoots for some links, by link name (the planner's set-up refines the
    /// links of pairs whose spheres touch where their geometry does not).
    pub link_overshoot: Vec<(String, f64)>,
}

impl Default for SphereOptions {
    fn default() -> Self {
        Self {
            max_overshoot: 0.01,
            package_path: Vec::new(),
            link_overshoot: Vec::new(),
        }
    }
}

impl SphereOptions {
    /// The overshoot of link `name`'s cover.
    pub fn overshoot_of(&self, name: &str) -> f64 {
        self.link_overshoot
            .iter()
            .filter(|(n, _)| n == name)
            .map(|&(_, d)| d)
            .fold(self.max_overshoot, f64::min)
    }
}

/// One collision sphere.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    /// Centre in the frame of the carrying body (the world for world-fixed links).
    pub center: [f32; 3],
    /// Radius (m).
    pub radius: f32,
}

/// The spheres of one link.
#[derive(Clone, Debug)]
pub struct LinkSpheres {
    /// Link index in the model.
    pub link: usize,
    /// Carrying body, or [`WORLD`].
    pub body: usize,
    /// Index range into [`SphereModel::spheres`].
    pub first: usize,
    /// One past the last sphere.
    pub end: usize,
    /// Bounding sphere of the link's spheres, in the body frame.
    pub bound: Sphere,
}

/// Spheres of every link, grouped by link, groups ordered by carrying body.
#[derive(Clone, Debug)]
pub struct SphereModel {
    /// All spheres.
    pub spheres: Vec<Sphere>,
    /// Groups, world-fixed links first, then by body.
    pub links: Vec<LinkSpheres>,
    /// `rho[s * nv + k]`: the speed bound of sphere `s` per unit rate of coordinate `k`.
    pub rho: Vec<f32>,
    /// Per link group, the largest `rho` per coordinate over its spheres (`links.len() × nv`).
    pub link_rho: Vec<f32>,
    /// Number of coordinates.
    pub nv: usize,
    /// Links left without spheres, with the reason (a mesh file that is not there).
    pub warnings: Vec<String>,
    /// Mesh files that are there but cannot be used (unreadable, corrupt, a scale that
    /// leaves no distance), with the reason: the planner refuses these, as the collision
    /// check of `run` does, rather than leave their links unchecked.
    pub broken: Vec<String>,
}

impl SphereModel {
    /// Builds the sphere model of `model`'s collision geometry.
    pub fn new(model: &Model, opts: &SphereOptions) -> SphereModel {
        let mut order: Vec<usize> = (0..model.links.len()).collect();
        order.sort_by_key(|&l| match model.links[l].body {
            WORLD => 0,
            b => b + 1,
        });
        let mut spheres = Vec::new();
        let mut links = Vec::new();
        let mut warnings = Vec::new();
        let mut broken = Vec::new();
        let mut meshes = MeshCovers {
            packages: PackagePaths::from_env(opts.package_path.clone()),
            done: cover_cache(),
        };
        meshes.prepare(model, opts);
        for l in order {
            let link = &model.links[l];
            let first = spheres.len();
            for g in &link.collisions {
                let prim = match &g.shape {
                    Shape::Sphere { radius } => Primitive::Sphere(*radius),
                    Shape::Box { size } => Primitive::Box(size.map(|s| s / 2.0)),
                    Shape::Cylinder { radius, length } => {
                        Primitive::Cylinder(*radius, length / 2.0)
                    }
                    Shape::Capsule { radius, length } => Primitive::Capsule(*radius, length / 2.0),
                    Shape::Mesh { uri, scale } => {
                        let to_body = link.offset.mul(&g.origin);
                        match meshes.cover(model, uri, *scale, opts.overshoot_of(&link.name)) {
                            Ok((cover, note)) => {
                                if let Some(n) = note {
                                    warnings.push(format!("link '{}': {n}", link.name));
                                }
                                push_spheres(&mut spheres, &to_body, cover);
                            }
                            Err(e @ CoverError::NotFound(_)) => warnings.push(format!(
                                "link '{}': mesh '{uri}' is not spherized ({e}); the planner does not check it",
                                link.name
                            )),
                            Err(e) => broken.push(format!("link '{}': mesh '{uri}': {e}", link.name)),
                        }
                        continue;
                    }
                };
                let to_body = link.offset.mul(&g.origin);
                let delta = opts.overshoot_of(&link.name);
                let (cover, used) = cover(&prim, delta);
                if used > delta {
                    warnings.push(format!(
                        "link '{}': a primitive this large is covered with overshoot {used:.4} m \
                         (more than the {} m asked for)",
                        link.name, delta
                    ));
                }
                push_spheres(&mut spheres, &to_body, cover);
            }
            if spheres.len() > first {
                let bound = bounding_sphere(&spheres[first..]);
                links.push(LinkSpheres {
                    link: l,
                    body: link.body,
                    first,
                    end: spheres.len(),
                    bound,
                });
            }
        }
        let rho = motion_bounds(model, &links, &spheres);
        let nv = model.nv;
        let mut link_rho = vec![0.0f32; links.len() * nv];
        for (g, ls) in links.iter().enumerate() {
            for s in ls.first..ls.end {
                for k in 0..nv {
                    let v = &mut link_rho[g * nv + k];
                    *v = v.max(rho[s * nv + k]);
                }
            }
        }
        SphereModel {
            spheres,
            links,
            rho,
            link_rho,
            nv,
            warnings,
            broken,
        }
    }

    /// Number of spheres.
    pub fn len(&self) -> usize {
        self.spheres.len()
    }

    /// Whether there are no spheres.
    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }

    /// World-frame centres of every sphere at `q`, in f64 (for reference checks and
    /// pictures, not the hot path).
    pub fn world_centers(&self, model: &Model, q: &[f64]) -> Vec<Vec3> {
        let mut data = crate::model::data::Data::new(model);
        crate::kinematics::forward_kinematics(model, &mut data, q);
        let mut out = vec![Vec3::zeros(); self.spheres.len()];
        for ls in &self.links {
            let pose = if ls.body == WORLD {
                Se3::identity()
            } else {
                data.o_m_i[ls.body]
            };
            for (o, sp) in out[ls.first..ls.end]
                .iter_mut()
                .zip(&self.spheres[ls.first..ls.end])
            {
                let c = sp.center;
                *o = pose.act_point(&Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64));
            }
        }
        out
    }
}

/// Adds a cover's spheres, placed by `to_body` (geometry → body frame).
fn push_spheres(spheres: &mut Vec<Sphere>, to_body: &Se3, cover: Vec<([f64; 3], f64)>) {
    for (c, r) in cover {
        let p = to_body.act_point(&Vec3::new(c[0], c[1], c[2]));
        spheres.push(Sphere {
            center: [p.x as f32, p.y as f32, p.z as f32],
            radius: r as f32,
        });
    }
}

/// A cover's spheres `(centre, radius)` and a note (open mesh, raised overshoot).
type NotedCover = (Vec<([f64; 3], f64)>, Option<String>);

/// Why a collision mesh got no sphere cover.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
enum CoverError {
    /// The mesh file was not found.
    #[error("{0}")]
    NotFound(NotFound),
    /// The mesh file cannot be read.
    #[error("{0}")]
    Unreadable(LocatedError),
    /// The mesh read gives no signed distance (its scale, a triangle mesh parry refuses).
    #[error("{path}: {problem}")]
    NoDistance {
        /// The mesh file.
        path: String,
        /// What is wrong.
        problem: MeshSdfError,
    },
}

/// Mesh covers by resolved file (with its length and modification time), scale and
/// overshoot, kept for the process: a mesh used by several links, models or planners is
/// covered once; [`MeshCovers::prepare`] computes every cover a model needs in parallel.
struct MeshCovers {
    packages: PackagePaths,
    done: std::sync::MutexGuard<'static, HashMap<CoverKey, Result<NotedCover, CoverError>>>,
}

/// A cover's resolved file, its length and modification time (ns), scale and overshoot
/// (as bits).
type CoverKey = (PathBuf, u64, u128, [u64; 3], u64);

/// The process's mesh covers.
fn cover_cache() -> std::sync::MutexGuard<'static, HashMap<CoverKey, Result<NotedCover, CoverError>>>
{
    static CACHE: std::sync::OnceLock<
        std::sync::Mutex<HashMap<CoverKey, Result<NotedCover, CoverError>>>,
    > = std::sync::OnceLock::new();
    CACHE
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner())
}

/// The key of a cover of `path`.
fn cover_key(path: PathBuf, scale: [f64; 3], delta: f64) -> CoverKey {
    let meta = std::fs::metadata(&path).ok();
    let len = meta.as_ref().map_or(0, |m| m.len());
    let mtime = meta
        .and_then(|m| m.modified().ok())
        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
        .map_or(0, |d| d.as_nanos());
    (path, len, mtime, scale.map(f64::to_bits), delta.to_bits())
}

impl MeshCovers {
    /// The file of mesh `uri`, resolved relative to the model file (as the collision
    /// module does).
    fn resolve(&self, model: &Model, uri: &str) -> Result<PathBuf, NotFound> {
        let base = Path::new(&model.source)
            .parent()
            .filter(|p| !p.as_os_str().is_empty());
        resolve_with(uri, base, &self.packages)
    }

    /// Computes, on the rayon threads, the covers of every mesh of `model` that
    /// [`MeshCovers::cover`] will ask for.
    fn prepare(&mut self, model: &Model, opts: &SphereOptions) {
        let mut jobs: Vec<(CoverKey, String)> = Vec::new();
        for link in &model.links {
            let delta = opts.overshoot_of(&link.name);
            for g in &link.collisions {
                if let Shape::Mesh { uri, scale } = &g.shape {
                    if let Ok(path) = self.resolve(model, uri) {
                        let key = cover_key(path, *scale, delta);
                        if !self.done.contains_key(&key) && !jobs.iter().any(|(k, _)| *k == key) {
                            jobs.push((key, uri.clone()));
                        }
                    }
                }
            }
        }
        use rayon::prelude::*;
        let covers: Vec<_> = jobs
            .into_par_iter()
            .map(|(key, uri)| {
                let scale = key.3.map(f64::from_bits);
                let c = compute_cover(&key.0, &uri, scale, f64::from_bits(key.4));
                (key, c)
            })
            .collect();
        self.done.extend(covers);
    }

    /// The cover of mesh `uri` and a note for an open mesh.
    fn cover(
        &mut self,
        model: &Model,
        uri: &str,
        scale: [f64; 3],
        delta: f64,
    ) -> Result<NotedCover, CoverError> {
        let path = self.resolve(model, uri).map_err(CoverError::NotFound)?;
        let key = cover_key(path.clone(), scale, delta);
        self.done
            .entry(key)
            .or_insert_with(|| compute_cover(&path, uri, scale, delta))
            .clone()
    }
}

/// The cover of the mesh file `path` (named `uri` in the notes).
fn compute_cover(
    path: &Path,
    uri: &str,
    scale: [f64; 3],
    delta: f64,
) -> Result<NotedCover, CoverError> {
    // Through the input guard: a FIFO or `/dev/zero` must not block or read forever.
    let bytes = crate::core::files::read_input_max(path, crate::core::files::MAX_MESH_BYTES).ok();
    if let Some(c) = bytes
        .as_deref()
        .and_then(|b| crate::planning::cover_cache::load(b, scale, delta))
    {
        return Ok(c);
    }
    let data = load_mesh(path).map_err(CoverError::Unreadable)?;
    let sdf = MeshSdf::new(&data, scale).map_err(|problem| CoverError::NoDistance {
        path: path.display().to_string(),
        problem,
    })?;
    let (spheres, used) = cover_sdf(&|p| sdf.sdf(p), sdf.center, sdf.half, delta);
    let file = path.display().to_string();
    // What the reader skipped (a DAE instance naming no geometry), with the file and line.
    let mut notes: Vec<String> = data
        .warnings
        .iter()
        .map(|w| w.clone().in_file(&file).to_string())
        .collect();
    if !sdf.closed {
        notes.push(format!(
            "mesh '{uri}' is open: its spheres wrap the surface only (no inside)"
        ));
    }
    if used > delta {
        notes.push(format!(
            "mesh '{uri}' is this large: covered with overshoot {used:.4} m (more than the {delta} m asked for)"
        ));
    }
    let note = (!notes.is_empty()).then(|| notes.join("; "));
    if let Some(b) = &bytes {
        crate::planning::cover_cache::store(b, scale, delta, &spheres, note.as_deref());
    }
    Ok((spheres, note))
}

/// A sphere containing `spheres` (centre at the mean of the centres, radius the farthest
/// reach from it; not minimal, but tight for the elongated clusters of a link).
fn bounding_sphere(spheres: &[Sphere]) -> Sphere {
    let n = spheres.len() as f64;
    let mut c = [0.0f64; 3];
    for s in spheres {
        for (ck, &sk) in c.iter_mut().zip(&s.center) {
            *ck += sk as f64 / n;
        }
    }
    let r = spheres
        .iter()
        .map(|s| {
            let d = (0..3)
                .map(|k| (s.center[k] as f64 - c[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            d + s.radius as f64
        })
        .fold(0.0, f64::max);
    Sphere {
        center: c.map(|x| x as f32),
        // Rounded up so the f32 bound still contains every f32 sphere.
        radius: (r * (1.0 + 1e-6) + 1e-7) as f32,
    }
}

/// The coefficients `ρ` of the module docs, per sphere and coordinate.
fn motion_bounds(model: &Model, links: &[LinkSpheres], spheres: &[Sphere]) -> Vec<f32> {
    let nv = model.nv;
    let mut rho = vec![0.0f32; spheres.len() * nv];
    for ls in links {
        for s in ls.first..ls.end {
            let out = &mut rho[s * nv..(s + 1) * nv];
            chain_rho(model, spheres[s].center, ls.body, WORLD, out);
        }
    }
    rho
}

/// Adds to `out[k]` the coefficients `ρ_k` of a point at `center` (body frame) on `body`,
/// for the joints from `body` up to, not including, the joint of `stop` (an ancestor, or
/// [`WORLD`] for the whole chain).
fn chain_rho(model: &Model, center: [f32; 3], body: usize, stop: usize, out: &mut [f32]) {
    let c = center.map(f64::from);
    // |c − o_k|, bounded by the chain of placement lengths from k down to the body.
    let mut reach = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    for b in model.support(body).take_while(|&b| b != stop) {
        let coef = if model.kind[b].is_revolute() {
            reach
        } else {
            1.0
        };
        let k = model.q_index[b];
        out[k] += (model.q_mult[b].abs() * coef * (1.0 + 1e-6)) as f32;
        reach += model.placement[b].trans.norm() + slide(model, b);
    }
}

/// How far body `b`'s origin can slide over its joint's limits ([`Model::stroke`]).
fn slide(model: &Model, b: usize) -> f64 {
    let k = model.q_index[b];
    model.stroke(b, model.lower[k], model.upper[k])
}

/// A bound on the distance from a point at `center` (frame of `body`) to the origin of
/// `stop`'s placement (`body` or an ancestor of it) in every configuration: `|p|` plus the
/// placements and the prismatic slides on the way, `stop`'s own slide included.
pub fn reach_to(model: &Model, center: [f32; 3], body: usize, stop: usize) -> f64 {
    let c = center.map(f64::from);
    let below: f64 = model
        .support(body)
        .take_while(|&b| b != stop)
        .map(|b| model.placement[b].trans.norm() + slide(model, b))
        .sum();
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() + below + slide(model, stop)
}

/// Relative motion bound of link groups `ga` and `gb` (`nv` coefficients): along a
/// straight joint-space segment, the distance between any point of one and any point of
/// the other changes at most at `Σ_k |q̇_k| ρ_k`. Distances do not change under a rigid
/// motion of both, so only the joints between their deepest common ancestor `C` and each
/// group count: in `C`'s frame a point of `ga` moves with the joints `C → ga` alone, at
/// most at the [`SphereModel::rho`] terms of those joints.
pub fn pair_rho(model: &Model, sm: &SphereModel, ga: usize, gb: usize) -> Vec<f32> {
    let nv = sm.nv;
    let (la, lb) = (&sm.links[ga], &sm.links[gb]);
    let common = if la.body == WORLD || lb.body == WORLD {
        WORLD
    } else {
        model.common_ancestor(la.body, lb.body)
    };
    let mut total = vec![0.0f32; nv];
    let mut one = vec![0.0f32; nv];
    for ls in [la, lb] {
        let mut worst = vec![0.0f32; nv];
        for s in ls.first..ls.end {
            one.fill(0.0);
            chain_rho(model, sm.spheres[s].center, ls.body, common, &mut one);
            for (w, &x) in worst.iter_mut().zip(&one) {
                *w = w.max(x);
            }
        }
        for (t, w) in total.iter_mut().zip(&worst) {
            *t += w;
        }
    }
    total
}
