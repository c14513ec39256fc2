//! Queries on a built scene: placing the shapes at a configuration, the first collision,
//! every colliding pair, the minimum distance by broad-phase bound, and body distances.

use crate::collision::collision_scene::{
    Body, CollisionData, CollisionModel, Distances, PairDistance, Scope,
};
use crate::collision::shape::{
    aabb_gap, distance_and_points, intersects, signed_distance, signed_distance_below, to_pose,
    within, Placed, Scratch,
};
use crate::kinematics::forward_kinematics;
use crate::model::Model;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::math::Pose;

impl CollisionModel {
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

    /// Whether links `a` and `b` (indices into `Model::links`) are in collision at the last
    /// [`CollisionModel::update`]: any of their shape pairs. `false` for a pair the scene
    /// never tests (the same link, adjacent links, a link without shapes).
    pub fn links_collide(&self, cd: &CollisionData, a: usize, b: usize) -> bool {
        let (la, lb) = (Body::Link(a), Body::Link(b));
        self.self_pairs.iter().any(|&p| {
            let (x, y) = (
                self.objects[p[0] as usize].owner,
                self.objects[p[1] as usize].owner,
            );
            ((x == la && y == lb) || (x == lb && y == la)) && self.pair_collides(cd, p)
        })
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
