//! Helpers of the planner tests: the MotionBenchMaker data (at `../shared/benchmarks/
//! motion-planning` beside the clone), the spherized robots with their SRDF pairs, an
//! impossible problem, and an independent f64 re-check of a path.
//!
//! The re-check shares nothing with the planner's checker: FK is armsim's f64
//! `kinematics::forward_kinematics`, the spheres are read from `model.links[..].collisions`,
//! the obstacle distances are exact signed distances written here, and the self-collision
//! pairs are every pair of links on bodies neither the same nor one joint apart that the
//! SRDF does not disable.
#![allow(dead_code)]

use armsim::collision::Obstacle;
use armsim::core::spatial::{Mat3, Se3, Vec3};
use armsim::kinematics;
use armsim::model::data::Data;
use armsim::model::{Model, Shape, WORLD};
use armsim::planning::moveit;
use armsim::planning::srdf;
use std::collections::HashSet;
use std::path::PathBuf;

/// The crate root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The benchmark folder; panics with where it was looked for when missing.
pub fn bench() -> PathBuf {
    let d = root().join("../shared/benchmarks/motion-planning");
    assert!(
        d.is_dir(),
        "the motion-planning benchmark data is expected at {} \
         (../shared/benchmarks/motion-planning beside the clone)",
        d.display()
    );
    d
}

/// A spherized benchmark robot with its SRDF's disabled pairs.
pub struct Robot {
    /// `panda` or `ur5`.
    pub name: String,
    /// The model.
    pub model: Model,
    /// SRDF disabled pairs (link names).
    pub disabled: Vec<(String, String)>,
    /// The root link's name (a scene frame).
    pub root: String,
}

impl Robot {
    /// Loads `robots/spherized/{name}_spherized.urdf` and `{name}.srdf`.
    pub fn load(name: &str) -> Robot {
        let dir = root().join("robots/spherized");
        let model = Model::load(dir.join(format!("{name}_spherized.urdf")))
            .unwrap_or_else(|e| panic!("{e}"))
            .0;
        let (disabled, _) = srdf::load_disabled_pairs(dir.join(format!("{name}.srdf")), &model)
            .unwrap_or_else(|e| panic!("{e}"));
        let root = model
            .links
            .iter()
            .find(|l| l.parent_joint.is_none())
            .unwrap()
            .name
            .clone();
        Robot {
            name: name.to_string(),
            model,
            disabled,
            root,
        }
    }
}

/// One benchmark problem, read.
pub struct Problem {
    /// `NNNN`.
    pub id: String,
    /// Obstacles.
    pub obstacles: Vec<Obstacle>,
    /// Start.
    pub start: Vec<f64>,
    /// Goal.
    pub goal: Vec<f64>,
    /// validity.json's verdict.
    pub valid: bool,
}

/// Every problem of `robot`/`scene`, in order.
pub fn problems(robot: &Robot, scene: &str) -> Vec<Problem> {
    let dir = bench().join(&robot.name);
    let validity = moveit::load_validity(dir.join("validity.json")).unwrap();
    moveit::problem_pairs(dir.join(scene))
        .unwrap()
        .into_iter()
        .map(|p| {
            let obstacles = moveit::load_scene_in(&p.scene, &[robot.root.as_str()])
                .unwrap_or_else(|e| panic!("{e}"));
            let (req, _) =
                moveit::load_request(&p.request, &robot.model).unwrap_or_else(|e| panic!("{e}"));
            let valid = validity
                .is_valid(scene, &p.id)
                .unwrap_or_else(|| panic!("{scene} {} not in validity.json", p.id));
            Problem {
                id: p.id,
                obstacles,
                start: req.start,
                goal: req.goal,
                valid,
            }
        })
        .collect()
}

/// A Panda posture turned to `yaw` about the base: upper arm vertical, forearm forward
/// (towards `yaw`), hand pointing down.
pub fn panda_upright(yaw: f64) -> Vec<f64> {
    vec![yaw, 0.0, 0.0, -0.5, 0.0, 1.0, 0.785]
}

/// An impossible Panda problem: a block beside the base (x ∈ ±0.01, y ∈ [−0.2, −0.1],
/// z ∈ [0.25, 0.42]). `panda_link1` carries a sphere of radius 0.06 at 0.08 m from the base
/// axis at z = 0.333, which meets the block whenever joint 1 is within about ±0.7 rad of 0
/// (at yaw 0 it is 4 cm deep); joint 1 cannot go round the other way (limits ±2.97 rad).
/// So the start (yaw +1.5) and the goal (yaw −1.5), both free, are in different components
/// of free space. The base link (a sphere of radius 0.08 up to z = 0.13) does not touch
/// the block, nor does the rest of the arm, upright, at the start and the goal.
pub fn panda_wall_problem() -> (Vec<Obstacle>, Vec<f64>, Vec<f64>) {
    let wall = Obstacle::new(
        "block",
        Shape::Box {
            size: [0.02, 0.1, 0.17],
        },
        Se3::new(Mat3::identity(), Vec3::new(0.0, -0.15, 0.335)),
    );
    (vec![wall], panda_upright(1.5), panda_upright(-1.5))
}

/// Whether two bodies ([`WORLD`] for world-fixed links) are the same or one joint apart:
/// such link pairs are not checked (the spheres of links one joint apart overlap at the
/// joint by construction, e.g. the UR5's `wrist_2_link` and `fts_robotside`, which its
/// SRDF does not list).
fn adjacent(model: &Model, a: usize, b: usize) -> bool {
    let parent = |x: usize| if x == WORLD { WORLD } else { model.parent[x] };
    a == b || (a != WORLD && parent(a) == b) || (b != WORLD && parent(b) == a)
}

/// A link's spheres for the re-check, in the frame of its body.
struct RefLink {
    name: String,
    body: usize,
    spheres: Vec<(Vec3, f64)>,
    bound_center: Vec3,
    bound_radius: f64,
}

/// An obstacle ready for signed distances: world → obstacle frame, and its shape.
struct RefObstacle {
    name: String,
    to_local: Se3,
    shape: Shape,
}

/// The independent re-checker of one robot in one scene.
pub struct Recheck<'m> {
    model: &'m Model,
    links: Vec<RefLink>,
    pairs: Vec<(usize, usize)>,
    obstacles: Vec<RefObstacle>,
    data: Data,
    centers: Vec<Vec<Vec3>>,
    bounds: Vec<Vec3>,
}

/// What a re-check of a path found.
#[derive(Debug, Default, Clone, Copy)]
pub struct RecheckReport {
    /// Largest penetration (m) over every checked configuration (negative: clearance).
    pub max_penetration: f64,
    /// Configurations checked.
    pub points: usize,
}

/// Signed distance from `p` (obstacle frame) to the shape: negative inside.
pub fn signed_distance(shape: &Shape, p: &Vec3) -> f64 {
    match *shape {
        Shape::Box { size } => {
            let q = [
                p.x.abs() - size[0] / 2.0,
                p.y.abs() - size[1] / 2.0,
                p.z.abs() - size[2] / 2.0,
            ];
            let outside = q.iter().map(|v| v.max(0.0).powi(2)).sum::<f64>().sqrt();
            outside + q[0].max(q[1]).max(q[2]).min(0.0)
        }
        Shape::Cylinder { radius, length } => {
            let dr = p.x.hypot(p.y) - radius;
            let dz = p.z.abs() - length / 2.0;
            dr.max(0.0).hypot(dz.max(0.0)) + dr.max(dz).min(0.0)
        }
        Shape::Sphere { radius } => p.norm() - radius,
        Shape::Capsule { radius, length } => {
            let z = p.z.clamp(-length / 2.0, length / 2.0);
            (p - Vec3::new(0.0, 0.0, z)).norm() - radius
        }
        Shape::Mesh { .. } => panic!("mesh obstacles are not in the benchmark"),
    }
}

impl<'m> Recheck<'m> {
    /// A re-checker for `robot` among `obstacles`.
    pub fn new(robot: &'m Robot, obstacles: &[Obstacle]) -> Recheck<'m> {
        let model = &robot.model;
        let mut links = Vec::new();
        let mut names = Vec::new();
        for l in &model.links {
            let spheres: Vec<(Vec3, f64)> = l
                .collisions
                .iter()
                .map(|g| match g.shape {
                    Shape::Sphere { radius } => (l.offset.act_point(&g.origin.trans), radius),
                    ref s => panic!("link '{}': {s:?} is not a sphere", l.name),
                })
                .collect();
            if spheres.is_empty() {
                continue;
            }
            let n = spheres.len() as f64;
            let c = spheres.iter().fold(Vec3::zeros(), |a, s| a + s.0) / n;
            let r = spheres
                .iter()
                .map(|s| (s.0 - c).norm() + s.1)
                .fold(0.0, f64::max);
            names.push(l.name.clone());
            links.push(RefLink {
                name: l.name.clone(),
                body: l.body,
                spheres,
                bound_center: c,
                bound_radius: r,
            });
        }
        let off: HashSet<(String, String)> = robot
            .disabled
            .iter()
            .flat_map(|(a, b)| [(a.clone(), b.clone()), (b.clone(), a.clone())])
            .collect();
        let mut pairs = Vec::new();
        for a in 0..links.len() {
            for b in a + 1..links.len() {
                if !adjacent(model, links[a].body, links[b].body)
                    && !off.contains(&(names[a].clone(), names[b].clone()))
                {
                    pairs.push((a, b));
                }
            }
        }
        let obstacles = obstacles
            .iter()
            .map(|o| RefObstacle {
                name: o.name.clone(),
                to_local: o.pose.inverse(),
                shape: o.shape.clone(),
            })
            .collect();
        let centers = links
            .iter()
            .map(|l| vec![Vec3::zeros(); l.spheres.len()])
            .collect();
        let bounds = vec![Vec3::zeros(); links.len()];
        Recheck {
            model,
            links,
            pairs,
            obstacles,
            data: Data::new(model),
            centers,
            bounds,
        }
    }

    /// Number of self-collision link pairs checked.
    pub fn pair_count(&self) -> usize {
        self.pairs.len()
    }

    /// The largest penetration (m) at `q`: sphere–obstacle and sphere–sphere (negative:
    /// the smallest clearance, where every bounding sphere was close enough to look).
    pub fn penetration(&mut self, q: &[f64]) -> f64 {
        kinematics::forward_kinematics(self.model, &mut self.data, q);
        for (li, l) in self.links.iter().enumerate() {
            let pose = if l.body == WORLD {
                Se3::identity()
            } else {
                self.data.o_m_i[l.body]
            };
            for (c, s) in self.centers[li].iter_mut().zip(&l.spheres) {
                *c = pose.act_point(&s.0);
            }
            self.bounds[li] = pose.act_point(&l.bound_center);
        }
        let mut worst = f64::NEG_INFINITY;
        for (li, l) in self.links.iter().enumerate() {
            for o in &self.obstacles {
                let b = o.to_local.act_point(&self.bounds[li]);
                if signed_distance(&o.shape, &b) > l.bound_radius {
                    continue;
                }
                for (c, s) in self.centers[li].iter().zip(&l.spheres) {
                    let p = o.to_local.act_point(c);
                    worst = worst.max(s.1 - signed_distance(&o.shape, &p));
                }
            }
        }
        for &(a, b) in &self.pairs {
            let (la, lb) = (&self.links[a], &self.links[b]);
            if (self.bounds[a] - self.bounds[b]).norm() > la.bound_radius + lb.bound_radius {
                continue;
            }
            for (ca, sa) in self.centers[a].iter().zip(&la.spheres) {
                for (cb, sb) in self.centers[b].iter().zip(&lb.spheres) {
                    worst = worst.max(sa.1 + sb.1 - (ca - cb).norm());
                }
            }
        }
        worst
    }

    /// The contacts at `q` (after [`Self::penetration`] placed the spheres): link–obstacle
    /// and link–link, with the penetration (m), for messages.
    pub fn contacts(&mut self, q: &[f64]) -> Vec<(String, f64)> {
        self.penetration(q);
        let mut out = Vec::new();
        for (li, l) in self.links.iter().enumerate() {
            for o in &self.obstacles {
                let pen = self.centers[li]
                    .iter()
                    .zip(&l.spheres)
                    .map(|(c, s)| s.1 - signed_distance(&o.shape, &o.to_local.act_point(c)))
                    .fold(f64::NEG_INFINITY, f64::max);
                if pen > 0.0 {
                    out.push((format!("{} / {}", l.name, o.name), pen));
                }
            }
        }
        for &(a, b) in &self.pairs {
            let (la, lb) = (&self.links[a], &self.links[b]);
            let mut pen = f64::NEG_INFINITY;
            for (ca, sa) in self.centers[a].iter().zip(&la.spheres) {
                for (cb, sb) in self.centers[b].iter().zip(&lb.spheres) {
                    pen = pen.max(sa.1 + sb.1 - (ca - cb).norm());
                }
            }
            if pen > 0.0 {
                out.push((format!("{} / {}", la.name, lb.name), pen));
            }
        }
        out
    }

    /// Re-checks `path` densely: 1000 configurations per unit of joint-space distance
    /// along every segment, ends included. Panics on a waypoint outside the joint limits.
    pub fn path(&mut self, path: &[Vec<f64>]) -> RecheckReport {
        let m = self.model;
        let mut rep = RecheckReport {
            max_penetration: f64::NEG_INFINITY,
            points: 0,
        };
        for (i, w) in path.iter().enumerate() {
            assert_eq!(w.len(), m.nv, "waypoint {i}");
            for (k, &x) in w.iter().enumerate() {
                assert!(
                    x >= m.lower[k] && x <= m.upper[k],
                    "waypoint {i}: coordinate {k} = {x} outside [{}, {}]",
                    m.lower[k],
                    m.upper[k]
                );
            }
        }
        let mut q = vec![0.0; m.nv];
        for (s, seg) in path.windows(2).enumerate() {
            let (a, b) = (&seg[0], &seg[1]);
            let d = a
                .iter()
                .zip(b)
                .map(|(x, y)| (y - x).powi(2))
                .sum::<f64>()
                .sqrt();
            let n = ((d * 1000.0).ceil() as usize).max(1);
            for i in usize::from(s > 0)..=n {
                let t = i as f64 / n as f64;
                for k in 0..m.nv {
                    q[k] = a[k] + t * (b[k] - a[k]);
                }
                rep.max_penetration = rep.max_penetration.max(self.penetration(&q));
                rep.points += 1;
            }
        }
        rep
    }
}

/// Joint-space L2 length of a path.
pub fn path_length(path: &[Vec<f64>]) -> f64 {
    path.windows(2)
        .map(|w| {
            w[0].iter()
                .zip(&w[1])
                .map(|(x, y)| (y - x).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum()
}
