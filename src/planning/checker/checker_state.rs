//! The checker's state, shared by the files that implement its stages: the [`Checker`]
//! itself (bodies in f32, spheres, obstacles, self pairs, motion-bound tables, clusters,
//! settings), its per-thread [`CheckScratch`], the settings ([`CheckOptions`],
//! [`EdgeMode`], [`CLEARANCE_RAMP`]) and the exact stage's [`ExactPairs`] and
//! [`ExactScratch`] (which hold a checker of their own). The methods live with the stage
//! they belong to (`mod.rs`, `batch.rs`, `motion.rs`, `edge.rs`, `exact.rs`).

use crate::collision::{Certifier, CollisionData, CollisionModel, SegmentScratch};
use crate::model::Model;
use crate::planning::checker::clusters::Clusters;
use crate::planning::environment::Environment;
use crate::planning::lanes::{Mask, P3m, PoseM, L};
#[cfg(target_arch = "x86_64")]
use crate::planning::simd::Avx2;
use crate::planning::spheres::SphereModel;
use std::sync::Arc;

/// One body of the kinematic tree in f32.
#[derive(Clone, Copy, Debug)]
pub(super) struct Body {
    pub(super) parent: usize,
    pub(super) rot: [[f32; 3]; 3],
    pub(super) rot_identity: bool,
    pub(super) trans: [f32; 3],
    pub(super) axis: usize,
    pub(super) revolute: bool,
    pub(super) q_index: usize,
    pub(super) mult: f32,
    pub(super) offset: f32,
}

/// How an edge is checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeMode {
    /// Continuously: nothing penetrates by more than the tolerance anywhere on the edge.
    Continuous,
    /// At points only (`search_resolution` per unit), as sampling planners usually do:
    /// fast, but the edge may graze an obstacle between two points. The lanes the points
    /// leave idle in the last batch (4 of 16 for 12 points) check the centres of intervals,
    /// at no extra cost.
    Discrete,
    /// As [`EdgeMode::Discrete`], with the idle lanes' points in the first step out of `a`:
    /// `a` is a task's start or goal (a tree's root), where the arm is close to the
    /// obstacles on purpose (a grasp), and leaving it can sweep the hand through the
    /// grasped object within that one step.
    DiscreteLeavingEnd,
}

impl EdgeMode {
    /// The mode of an edge out of a tree node: a root (a task's start or goal) is left with
    /// [`EdgeMode::DiscreteLeavingEnd`] where the search checks discretely.
    pub fn leaving(self, root: bool) -> EdgeMode {
        match self {
            EdgeMode::Discrete if root => EdgeMode::DiscreteLeavingEnd,
            m => m,
        }
    }
}

/// Joint-space distance from the path's ends over which the demanded clearance grows from
/// zero to its full value (rad).
pub const CLEARANCE_RAMP: f32 = 0.3;

/// Settings of the checker.
#[derive(Clone, Copy, Debug)]
pub struct CheckOptions {
    /// Edge intervals per unit of joint-space distance (the coarse level; finer where
    /// needed).
    pub resolution: f32,
    /// Points per unit of joint-space distance of the discrete checks
    /// ([`EdgeMode::Discrete`]). The planner searches with them and then checks the path's
    /// edges continuously, so they only need to turn away most colliding edges: 8 (a
    /// quarter of VAMP's 32) cuts the Panda and UR5 plan-time medians by 15 % against 16,
    /// with the same success; the edges they let through are re-planned.
    pub search_resolution: f32,
    /// Penetration the continuous check allows (m); the exact checks allow none.
    pub tolerance: f32,
    /// Distance from the obstacles that checks made with [`CheckScratch::keep_clearance`]
    /// set demand (m), ramped down near the path's ends ([`CLEARANCE_RAMP`]): the simplifier
    /// keeps it so that a smooth curve through the simplified waypoints has room to cut
    /// corners. Zero by default (MotionBenchMaker semantics).
    pub clearance: f32,
}

impl Default for CheckOptions {
    fn default() -> Self {
        Self {
            resolution: 8.0,
            search_resolution: 8.0,
            tolerance: 5e-5,
            clearance: 0.0,
        }
    }
}

/// Reusable buffers of one thread's checks (no allocation once warm).
#[derive(Clone, Debug, Default)]
pub struct CheckScratch {
    pub(super) poses: Vec<PoseM>,
    pub(super) centers: Vec<P3m>,
    pub(super) bounds: Vec<P3m>,
    pub(super) placed: Vec<bool>,
    /// Per body, its world twist `(ω, v)` per unit of the edge parameter.
    pub(super) twist: Vec<[P3m; 2]>,
    /// Per sphere and per group bound, the inflation of the current batch.
    pub(super) infl: Vec<L>,
    pub(super) bound_infl: Vec<L>,
    /// Per body, its coordinate's change over the edge (mimic multiplier included).
    pub(super) body_delta: Vec<f32>,
    /// `Σ |body_delta|`.
    pub(super) l1: f32,
    /// Per coordinate, `|b_k − a_k|` of the edge.
    pub(super) abs_delta: Vec<f32>,
    /// Whether a continuous edge check is under way (twists and speeds are set).
    pub(super) moving: bool,
    /// Whether the obstacle checks demand [`CheckOptions::clearance`].
    pub keep_clearance: bool,
    /// The path's start and goal (`2 nv`): the clearance demanded of a configuration grows
    /// from zero at them to the full value [`CLEARANCE_RAMP`] away (joint-space distance),
    /// since a task puts the arm close to the obstacles there on purpose (a pick, a place).
    pub ends: Vec<f32>,
    pub(super) speed: Vec<f32>,
    pub(super) link_speed: Vec<f32>,
    /// Per self pair, its relative speed bound over the edge.
    pub(super) pair_speed: Vec<f32>,
    /// Per cluster: its sphere's centre, inflation and speed cap in this batch.
    pub(super) cluster_bounds: Vec<P3m>,
    pub(super) cluster_infl: Vec<L>,
    pub(super) cluster_speed: Vec<f32>,
    /// Per obstacle: whether the cluster being checked may touch it.
    pub(super) near: Vec<bool>,
    /// Intervals whose inflated check failed, to refine.
    pub(super) stack: Vec<Piece>,
    /// Per link group, the lanes of this batch that must check it against the obstacles
    /// (a refined interval checks only what failed on the interval it came from).
    pub(super) need: Vec<Mask>,
    /// The lanes of this batch that must check the self pairs.
    pub(super) need_pairs: Mask,
    /// Per link group, the lanes where its inflated check failed in this batch (not
    /// exactly: those are to refine).
    pub(super) group_fail: Vec<Mask>,
    /// The lanes where a self pair's inflated check failed in this batch.
    pub(super) pairs_fail: Mask,
    pub(super) q: Vec<L>,
    /// Edge checks done.
    pub edges: u64,
    /// Batches of eight configurations checked.
    pub batches: u64,
    /// Link groups checked against their obstacles, and self-pair passes, over the
    /// batches (a measure of the batches' work).
    pub group_checks: u64,
    /// The exact stage's buffers, when the checker has one.
    pub exact: Option<Box<ExactScratch>>,
}

/// An interval of a continuous edge check, to refine: centre `t`, half-width `h` (in the
/// edge parameter), and the checks that failed inflated on it ([`Piece::items`]): what
/// passed covers every sub-interval too, so its pieces check only these.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Piece {
    pub(super) t: f32,
    pub(super) h: f32,
    /// Bit `min(g, 62)` for link group `g` against the obstacles (groups from 62 on share
    /// bit 62), bit 63 for the self pairs.
    pub(super) items: u64,
}

/// [`Piece::items`]' bit of the self pairs.
pub(super) const PAIRS_BIT: u64 = 1 << 63;

/// [`Piece::items`]' bit of link group `g`.
#[inline(always)]
pub(super) fn group_bit(g: usize) -> u64 {
    1 << g.min(62)
}

/// The robot's spheres, the obstacles, the self-collision pairs and the f32 kinematics.
#[derive(Clone, Debug)]
pub struct Checker {
    pub(super) bodies: Vec<Body>,
    /// The robot's spheres.
    pub spheres: SphereModel,
    /// The obstacles.
    pub env: Environment,
    /// Link-group pairs checked for self-collision.
    pub self_pairs: Vec<(usize, usize)>,
    /// The motion bounds of spheres, groups, self pairs (relative,
    /// [`crate::planning::spheres::pair_rho`]) and clusters, transposed.
    pub(super) speed_tables: SpeedTables,
    /// Per link group, the obstacles its bounding sphere can ever reach.
    pub(super) reachable: Vec<Vec<usize>>,
    /// Groups sharing a body, behind one sphere (see [`clusters`]).
    pub(super) clusters: Clusters,
    /// Settings.
    pub opts: CheckOptions,
    #[cfg(target_arch = "x86_64")]
    pub(super) avx2: Option<Avx2>,
    /// The AVX2 code runs in its AVX-512 VL instantiation (see [`crate::planning::simd`]).
    #[cfg(target_arch = "x86_64")]
    pub(super) avx512vl: bool,
    /// Self pairs decided on the exact geometry after this checker's own checks.
    pub(super) exact: Option<Arc<ExactPairs>>,
    /// A refined interval checks only what failed on the interval it came from
    /// ([`Piece::items`]; off only to compare, [`Checker::refine_every_check`]).
    pub(super) selective: bool,
}

/// The motion-bound tables `ρ` of the spheres, link groups, self pairs and clusters,
/// transposed: coordinate-major, `table[k · n + i] = ρ_{i,k}` for `n` rows.
#[derive(Clone, Debug, Default)]
pub(super) struct SpeedTables {
    pub(super) sphere: Vec<f32>,
    pub(super) link: Vec<f32>,
    pub(super) pair: Vec<f32>,
    pub(super) cluster: Vec<f32>,
}

/// The exact stage of a [`Checker`]: self pairs decided on the exact collision geometry
/// (see [`ExactPairs::new`]).
#[derive(Clone, Debug)]
pub struct ExactPairs {
    pub(super) model: Arc<Model>,
    pub(super) cm: CollisionModel,
    pub(super) certifier: Certifier,
    /// The pairs, as link indices into `Model::links`.
    pub(super) links: Vec<(usize, usize)>,
    /// The pairs' spheres alone: the first stage.
    pub(super) spheres: Checker,
}

/// Per-thread buffers of the exact stage.
#[derive(Clone, Debug)]
pub struct ExactScratch {
    pub(super) cd: CollisionData,
    pub(super) spheres: CheckScratch,
    pub(super) a: Vec<f64>,
    pub(super) delta: Vec<f64>,
    /// The ends of a piece of the edge (f32, for the spheres).
    pub(super) ends: [Vec<f32>; 2],
    pub(super) pieces: Vec<(f32, f32)>,
    pub(super) segment: SegmentScratch,
    /// Configurations and edges the spheres could not clear, decided on the meshes.
    pub exact_checks: u64,
}
