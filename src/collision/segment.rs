//! Conservative advancement along a straight joint-space segment `q(t) = a + t Δ`,
//! `t ∈ [t₀, t₁]`: a planner's edge check on the exact geometry, pair by pair.
//!
//! Along the segment a pair's distance changes by at most `v |dt|`, `v = Σ_k ρ_k |Δ_k|`
//! (the pair's motion coefficients, [`crate::collision::bounds`]). So a lower bound `d` of the
//! distance at `t` proves the pair apart up to `t + (d + tol)/v` with at most `tol` of
//! penetration, and the march jumps there (Mirtich's conservative advancement).
//!
//! The bound is the cheapest that moves the march on: bounding balls and boxes, then the
//! convex hulls (GJK, warm-started), and the exact shapes only when the hulls are within
//! [`EXACT_BELOW`] of each other (nearly touching hulls give short steps; the exact
//! distance of non-convex meshes is often much larger). An exact distance ≤ 0 is a
//! collision; a march that needs more than [`MAX_STEPS`] steps is refused, conservatively.

use crate::collision::bounds::{Certifier, Evaluations, Level};
use crate::collision::collision_scene::{CollisionData, CollisionModel};
use crate::collision::shape::{to_pose, Scratch};
use crate::model::{Model, WORLD};
use parry3d_f64::math::{Pose, Vector};

/// Hull distance (m) under which the exact shapes are measured.
pub const EXACT_BELOW: f64 = 2e-3;

/// Largest distance (m) an exact measurement looks for: a bounded query prunes more, and
/// a larger bound would only lengthen one step.
pub const EXACT_BOUND: f64 = 1e-2;

/// Most steps of one pair's march before the segment is refused.
pub const MAX_STEPS: usize = 4096;

/// Per-thread buffers of [`Certifier::segment_free`].
#[derive(Clone, Debug, Default)]
pub struct SegmentScratch {
    q: Vec<f64>,
    scratch: Scratch,
    hints: Vec<Vector>,
    /// Pair distance evaluations per level, summed over the calls.
    pub evaluations: Evaluations,
}

impl Certifier {
    /// Whether every pair of this certifier stays apart (penetration ≤ `tol`) along
    /// `q(t) = a + t Δ` for `t ∈ [t0, t1]` (see the module docs).
    #[allow(clippy::too_many_arguments)]
    pub fn segment_free(
        &self,
        cm: &CollisionModel,
        model: &Model,
        cd: &mut CollisionData,
        a: &[f64],
        delta: &[f64],
        (t0, t1): (f64, f64),
        tol: f64,
        s: &mut SegmentScratch,
    ) -> bool {
        s.q.resize(model.nv, 0.0);
        s.hints.resize(self.pairs.len(), Vector::ZERO);
        (0..self.pairs.len()).all(|p| {
            let v = self.motion(p, delta.iter().map(|d| d.abs()));
            self.march_segment(cm, model, cd, p, (a, delta, v), (t0, t1), tol, s)
        })
    }

    /// One pair's march over `[t0, t1]`; `v` is its speed bound per unit `t`.
    #[allow(clippy::too_many_arguments)]
    fn march_segment(
        &self,
        cm: &CollisionModel,
        model: &Model,
        cd: &mut CollisionData,
        p: usize,
        (a, delta, v): (&[f64], &[f64], f64),
        (t0, t1): (f64, f64),
        tol: f64,
        s: &mut SegmentScratch,
    ) -> bool {
        let [i, j] = self.pairs[p];
        let mut t = t0;
        for _ in 0..MAX_STEPS {
            for (q, (&ak, &dk)) in s.q.iter_mut().zip(a.iter().zip(delta)) {
                *q = ak + t * dk;
            }
            crate::kinematics::forward_kinematics(model, &mut cd.kin, &s.q);
            let (pa, pb) = (place(cm, cd, i), place(cm, cd, j));
            // Enough to finish the segment from here.
            let need = v * (t1 - t) + tol;
            let (mut d, level, mut exact) = self.lower_bound(
                cm,
                p,
                &pa,
                &pb,
                need,
                Level::Hull,
                &mut s.hints[p],
                &mut s.scratch,
                &mut s.evaluations,
            );
            if d <= need && d < EXACT_BELOW && level == Level::Hull && !exact {
                let bound = need.min(EXACT_BOUND);
                (d, _, exact) = self.lower_bound(
                    cm,
                    p,
                    &pa,
                    &pb,
                    bound,
                    Level::Exact,
                    &mut s.hints[p],
                    &mut s.scratch,
                    &mut s.evaluations,
                );
            }
            if exact && d <= 0.0 {
                return false;
            }
            if d > need || v == 0.0 {
                return true;
            }
            t += (d.max(0.0) + tol) / v;
            if t >= t1 {
                return true;
            }
        }
        false
    }
}

/// The world pose of shape `k` after forward kinematics into `cd.kin` (static shapes
/// keep the pose [`CollisionData::new`] gave them).
fn place(cm: &CollisionModel, cd: &CollisionData, k: u32) -> Pose {
    let o = &cm.objects[k as usize];
    if o.body == WORLD {
        cd.poses[k as usize]
    } else {
        to_pose(&cd.kin.o_m_i[o.body].mul(&o.local))
    }
}
