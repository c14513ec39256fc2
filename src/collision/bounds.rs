//! The bounds that continuous certification ([`crate::collision::certify`]) rests on, built once
//! per scene: per shape a convex stand-in and a bounding sphere, and per tested pair the
//! motion coefficients `ρ` of its relative motion.
//!
//! **Lower bounds of a pair's distance at one configuration**, cheapest first
//! ([`Level`]):
//! 1. `Ball`: the larger of the gap between the shapes' bounding spheres and the gap
//!    between their world boxes (a box of a triangle mesh is its local box turned: still
//!    a box around it).
//! 2. `Hull`: the GJK distance between the convex hulls of the shapes (a triangle mesh
//!    lies inside its hull, so the hull distance is at most the mesh distance; for two
//!    convex shapes it *is* the distance when positive).
//! 3. `Exact`: the signed distance of the shapes themselves (see [`crate::collision::shape`]).
//!
//! **Motion coefficients** (the same argument as [`crate::planning::spheres`], for a
//! shape's bounding sphere instead of a sphere centre): a point `p` of a shape on body
//! `b`, within `R` of the shape's bounding-sphere centre `c`, moves at most at
//! `Σ_k |q̇_k| ρ_k`, the sum over the movable joints `k` between the pair's deepest common
//! ancestor and `b` (the joints above move both shapes rigidly and change no distance): a
//! revolute joint moves `p` at `|q̇_k| · dist(p, axis_k) ≤ |q̇_k| (|c − o_k| + R)` and
//! `|c − o_k|` is bounded by `|c|` (body frame) plus the chain of placement translations
//! and prismatic strokes down to `b`; a prismatic joint moves it at `|q̇_k|`; mimic joints
//! scale by `|multiplier|`. Along *any* curve `q(t)` the distance of the pair therefore
//! changes by at most `Σ_k ρ_k ∫ |q̇_k| dt`.

use crate::collision::collision_scene::{Body, CollisionModel, Scope};
use crate::collision::shape::{convex_distance, signed_distance_under, Placed, Scratch, ShapeKind};
use crate::model::{Model, WORLD};
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query;
use parry3d_f64::shape::SharedShape;
use serde::Serialize;

/// How hard a lower bound was worked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Level {
    /// Bounding spheres and boxes.
    Ball,
    /// Convex hulls.
    Hull,
    /// The shapes themselves.
    Exact,
}

/// How many pair distance evaluations each level ran.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Evaluations {
    /// Bounding sphere and box gaps.
    pub spheres: usize,
    /// Convex hull (GJK) distances.
    pub hulls: usize,
    /// Exact shape distances (meshes near contact).
    pub exact: usize,
}

/// The per-scene data of continuous certification (see the module docs): build once with
/// [`CollisionModel::certifier`], then certify any number of motions with it.
#[derive(Clone, Debug)]
pub struct Certifier {
    /// Per shape: its convex hull when it is a triangle mesh (`None`: convex already).
    pub(crate) hulls: Vec<Option<SharedShape>>,
    /// Per shape: bounding-sphere centre (parry shape frame) and radius.
    pub(crate) balls: Vec<(Vector, f64)>,
    /// The tested shape pairs of the scope, self pairs first.
    pub(crate) pairs: Vec<[u32; 2]>,
    /// How many of `pairs` are self pairs.
    pub(crate) n_self: usize,
    /// Per pair, `nv` motion coefficients.
    pub(crate) rho: Vec<f64>,
    pub(crate) nv: usize,
    pub(crate) scope: Scope,
}

impl CollisionModel {
    /// The certification data of this scene for the pairs of `scope` (convex hulls of the
    /// triangle meshes, motion coefficients per pair).
    pub fn certifier(&self, model: &Model, scope: Scope) -> Certifier {
        let hulls = self
            .objects
            .iter()
            .map(|o| match o.shape.kind {
                ShapeKind::TriMesh { .. } => o
                    .shape
                    .shape
                    .as_trimesh()
                    .and_then(|m| SharedShape::convex_hull(m.vertices())),
                _ => None,
            })
            .collect();
        let balls = self
            .objects
            .iter()
            .map(|o| {
                let s = o.shape.shape.compute_local_bounding_sphere();
                (s.center, s.radius)
            })
            .collect::<Vec<_>>();
        let [selfs, envs] = self.lists(scope);
        let pairs: Vec<[u32; 2]> = selfs.iter().chain(envs).copied().collect();
        let nv = model.nv;
        let mut rho = vec![0.0; pairs.len() * nv];
        for (p, &[i, j]) in pairs.iter().enumerate() {
            let (oi, oj) = (&self.objects[i as usize], &self.objects[j as usize]);
            let stop = model.common_ancestor(oi.body, oj.body);
            let out = &mut rho[p * nv..(p + 1) * nv];
            for (o, k) in [(oi, i), (oj, j)] {
                if o.body != WORLD {
                    let (c, r) = balls[k as usize];
                    let cb = o.local.act_point(&crate::collision::shape::to_vec3(c));
                    chain_rho(model, cb.norm() + r, o.body, stop, out);
                }
            }
        }
        Certifier {
            hulls,
            balls,
            n_self: selfs.len(),
            pairs,
            rho,
            nv,
            scope,
        }
    }
}

/// Adds to `out[k]` the coefficients of a ball of radius `reach` around a point of `body`
/// (`reach` = its distance to the body origin plus the radius), for the joints from
/// `body` up to, not including, the joint of `stop`.
fn chain_rho(model: &Model, mut reach: f64, body: usize, stop: usize, out: &mut [f64]) {
    for b in model.support(body).take_while(|&b| b != stop) {
        let coef = if model.kind[b].is_revolute() {
            reach
        } else {
            1.0
        };
        let k = model.q_index[b];
        out[k] += model.q_mult[b].abs() * coef * (1.0 + 1e-9);
        reach += model.placement[b].trans.norm() + model.stroke(b, model.lower[k], model.upper[k]);
    }
}

/// The bound on a joint's path length over a half-interval of length `h/2` that starts or
/// ends at a sample with speed `speed`, when `|q̈| ≤ accel` (see [`crate::collision::certify`]):
/// `speed h/2 + accel h²/8`.
#[inline]
pub fn half_path_bound(speed: f64, accel: f64, h: f64) -> f64 {
    speed.abs() * h / 2.0 + accel * h * h / 8.0
}

impl Certifier {
    /// Keeps only the self pairs between the links of `links` (indices into
    /// `Model::links`, either order); drops every other pair, the environment's included.
    pub fn retain_link_pairs(&mut self, cm: &CollisionModel, links: &[(usize, usize)]) {
        let owner = |k: u32| cm.objects[k as usize].owner;
        let keep = |&[i, j]: &[u32; 2]| {
            links.iter().any(|&(a, b)| {
                let (a, b) = (Body::Link(a), Body::Link(b));
                (owner(i), owner(j)) == (a, b) || (owner(i), owner(j)) == (b, a)
            })
        };
        let nv = self.nv;
        let mut pairs = Vec::new();
        let mut rho = Vec::new();
        for (p, pair) in self.pairs.iter().enumerate().take(self.n_self) {
            if keep(pair) {
                pairs.push(*pair);
                rho.extend_from_slice(&self.rho[p * nv..(p + 1) * nv]);
            }
        }
        self.n_self = pairs.len();
        self.pairs = pairs;
        self.rho = rho;
        self.scope = Scope::SelfCollision;
    }

    /// Number of pairs certified.
    pub fn num_pairs(&self) -> usize {
        self.pairs.len()
    }

    /// The shapes (indices for [`CollisionModel::shape`]) of pair `p`.
    pub fn pair_shapes(&self, p: usize) -> [usize; 2] {
        self.pairs[p].map(|k| k as usize)
    }

    /// The bounding sphere of shape `k`: centre (parry shape frame, see
    /// [`crate::collision::CollisionData::shape_pose`]) and radius.
    pub fn ball(&self, k: usize) -> ([f64; 3], f64) {
        let (c, r) = self.balls[k];
        ([c.x, c.y, c.z], r)
    }

    /// The largest change of any point-to-point distance between the shapes of pair `p`
    /// along a curve whose joint path lengths are `lengths` (`Σ_k ρ_k lengths_k`).
    pub fn motion_bound(&self, p: usize, lengths: &[f64]) -> f64 {
        self.motion(p, lengths.iter().copied())
    }

    /// `Σ_k ρ_k w_k` of pair `p` for per-joint path lengths `w`.
    #[inline]
    pub(crate) fn motion(&self, p: usize, w: impl Iterator<Item = f64>) -> f64 {
        self.rho[p * self.nv..(p + 1) * self.nv]
            .iter()
            .zip(w)
            .map(|(r, x)| r * x)
            .sum()
    }

    /// A lower bound of pair `p`'s signed distance with its shapes at `pa`, `pb`, worked
    /// up from the cheapest level until it exceeds `need` or `level` is reached; returns
    /// the bound, the level reached and whether it is the exact distance. At the exact
    /// level, a distance above `need` is only proven (the bound is then `need`'s next
    /// float); pass `need = ∞` for the exact distance. `hint` is the pair's last
    /// separating direction (GJK's warm start), updated.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn lower_bound(
        &self,
        cm: &CollisionModel,
        p: usize,
        pa: &Pose,
        pb: &Pose,
        need: f64,
        level: Level,
        hint: &mut Vector,
        scratch: &mut Scratch,
        ev: &mut Evaluations,
    ) -> (f64, Level, bool) {
        let [i, j] = self.pairs[p].map(|k| k as usize);
        let (oa, ob) = (&cm.objects[i].shape, &cm.objects[j].shape);
        ev.spheres += 1;
        let (ca, ra) = self.balls[i];
        let (cb, rb) = self.balls[j];
        let ball = (*pa * ca - *pb * cb).length() - ra - rb;
        let (ba, bb) = (oa.aabb(pa), ob.aabb(pb));
        let lb = ball.max(crate::collision::shape::aabb_gap(&ba, &bb));
        if lb > need || level == Level::Ball {
            return (lb, Level::Ball, false);
        }
        ev.hulls += 1;
        let ha = self.hulls[i].as_ref().unwrap_or(&oa.shape);
        let hb = self.hulls[j].as_ref().unwrap_or(&ob.shape);
        let mesh = |k: ShapeKind| matches!(k, ShapeKind::TriMesh { .. });
        let convex = !mesh(oa.kind) && !mesh(ob.kind);
        let hull = match (ha.as_support_map(), hb.as_support_map()) {
            (Some(ga), Some(gb)) => convex_distance(ga, pa, gb, pb, hint, scratch),
            _ => query::distance(pa, &**ha, pb, &**hb).map_or(0.0, |r| r.distance),
        };
        if hull > 0.0 && convex {
            return (hull, Level::Hull, true);
        }
        let lb = lb.max(hull);
        if lb > need || level == Level::Hull {
            return (lb, Level::Hull, false);
        }
        ev.exact += 1;
        let a = Placed {
            shape: oa,
            pose: pa,
            aabb: &ba,
        };
        let b = Placed {
            shape: ob,
            pose: pb,
            aabb: &bb,
        };
        // Only whether the distance exceeds `need` matters above it: a bounded query.
        match signed_distance_under(a, b, need, scratch) {
            Some(d) => (d, Level::Exact, true),
            None => (need.next_up(), Level::Exact, false),
        }
    }
}
