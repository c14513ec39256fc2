//! Self pairs decided on the exact collision geometry: the link pairs whose sphere covers
//! touch where their meshes do not ([`crate::planning::setup`] finds them). A UR5's upper
//! arm pointing down passes its base 7 mm away; covers of 5 mm overshoot touch there, and
//! would wall the configuration space off along the whole band of shoulder angles.
//!
//! Such a pair is checked in two stages. Its spheres first, in a checker of their own
//! (same lanes and motion bounds as the main one): where they do not touch, neither do
//! the meshes. Where they do, the exact geometry decides:
//! - a configuration is free when no shape pair of the two links intersects
//!   ([`CollisionModel::links_collide`]);
//! - on an edge `a → b`, the parts the spheres cannot clear are found by halving (down to
//!   [`PIECE`] of joint-space length), and each is checked by conservative advancement
//!   on the convex hulls and, where those nearly touch, the shapes themselves
//!   ([`crate::collision::Certifier::segment_free`]; at most the checker's tolerance of penetration).
//!
//! Discrete edge checks (the search's) that fail on the spheres are decided at their
//! points, on the exact geometry; the planner checks its path continuously afterwards.

use crate::collision::{CollisionData, CollisionModel, SegmentScratch};
use crate::model::Model;
use crate::planning::checker::checker_state::{Checker, EdgeMode, ExactPairs, ExactScratch};
use std::sync::Arc;

/// Longest piece of an edge (joint-space length) checked on the exact geometry at once.
pub const PIECE: f32 = 0.1;

impl ExactPairs {
    /// The exact stage for the link pairs `links` of `model`: `spheres` checks their
    /// sphere covers (a checker with no obstacles and these pairs only), `cm` holds the
    /// exact geometry.
    pub fn new(
        model: Arc<Model>,
        cm: &CollisionModel,
        links: Vec<(usize, usize)>,
        spheres: Checker,
    ) -> ExactPairs {
        let mut certifier = cm.certifier(&model, crate::collision::Scope::SelfCollision);
        certifier.retain_link_pairs(cm, &links);
        ExactPairs {
            model,
            cm: cm.clone(),
            certifier,
            links,
            spheres,
        }
    }

    /// Buffers for one thread.
    pub fn scratch(&self) -> ExactScratch {
        let nv = self.model.nv;
        ExactScratch {
            cd: CollisionData::new(&self.model, &self.cm),
            spheres: self.spheres.scratch(),
            a: vec![0.0; nv],
            delta: vec![0.0; nv],
            ends: [vec![0.0; nv], vec![0.0; nv]],
            pieces: Vec::new(),
            segment: SegmentScratch::default(),
            exact_checks: 0,
        }
    }

    /// Whether no pair touches at `q`.
    pub fn config_free(&self, q: &[f32], s: &mut ExactScratch) -> bool {
        if self.spheres.config_free(q, &mut s.spheres) {
            return true;
        }
        s.exact_checks += 1;
        for (x, &v) in s.a.iter_mut().zip(q) {
            *x = f64::from(v);
        }
        self.cm.update(&self.model, &mut s.cd, &s.a);
        !self
            .links
            .iter()
            .any(|&(a, b)| self.cm.links_collide(&s.cd, a, b))
    }

    /// Whether no pair touches anywhere on the edge `a → b`.
    pub fn edge_free(&self, a: &[f32], b: &[f32], mode: EdgeMode, s: &mut ExactScratch) -> bool {
        if self.spheres.edge_free(a, b, mode, &mut s.spheres) {
            return true;
        }
        s.exact_checks += 1;
        if mode != EdgeMode::Continuous {
            return self.points_free(a, b, s);
        }
        self.edge_free_pieces(a, b, s)
    }

    /// The discrete check of the search on the exact geometry: the points `k/n` of the
    /// edge, `k = 1..n`, `n = ⌈‖b − a‖ · search_resolution⌉` (the main checker's).
    fn points_free(&self, a: &[f32], b: &[f32], s: &mut ExactScratch) -> bool {
        let len = a.iter().zip(b).map(|(x, y)| (y - x) * (y - x)).sum::<f32>();
        let n = ((len.sqrt() * self.spheres.opts.search_resolution).ceil() as usize).max(1);
        let mut q = std::mem::take(&mut s.ends[0]);
        let free = (1..=n).all(|k| {
            let t = k as f32 / n as f32;
            for (x, (&ak, &bk)) in q.iter_mut().zip(a.iter().zip(b)) {
                *x = ak + t * (bk - ak);
            }
            self.config_free(&q, s)
        });
        s.ends[0] = q;
        free
    }

    /// The continuous check on the exact geometry (see the module docs).
    fn edge_free_pieces(&self, a: &[f32], b: &[f32], s: &mut ExactScratch) -> bool {
        let mut len = 0.0f32;
        for k in 0..a.len() {
            s.a[k] = f64::from(a[k]);
            s.delta[k] = f64::from(b[k]) - f64::from(a[k]);
            len += (b[k] - a[k]) * (b[k] - a[k]);
        }
        let len = len.sqrt();
        s.pieces.clear();
        s.pieces.push((0.0, 1.0));
        while let Some((t0, t1)) = s.pieces.pop() {
            if (t1 - t0) * len <= PIECE {
                let free = self.certifier.segment_free(
                    &self.cm,
                    &self.model,
                    &mut s.cd,
                    &s.a,
                    &s.delta,
                    (f64::from(t0), f64::from(t1)),
                    f64::from(self.spheres.opts.tolerance),
                    &mut s.segment,
                );
                if !free {
                    return false;
                }
                continue;
            }
            let tm = 0.5 * (t0 + t1);
            for (u0, u1) in [(t0, tm), (tm, t1)] {
                for (e, u) in s.ends.iter_mut().zip([u0, u1]) {
                    for (x, (&ak, &bk)) in e.iter_mut().zip(a.iter().zip(b)) {
                        *x = ak + u * (bk - ak);
                    }
                }
                let [e0, e1] = &s.ends;
                let free = self
                    .spheres
                    .edge_free(e0, e1, EdgeMode::Continuous, &mut s.spheres);
                if !free {
                    s.pieces.push((u0, u1));
                }
            }
        }
        true
    }
}

impl Checker {
    /// This checker with the exact stage `exact` after its own checks (see the module
    /// docs); the pairs of `exact` should not be among its own self pairs.
    pub fn with_exact(mut self, exact: ExactPairs) -> Checker {
        self.exact = Some(Arc::new(exact));
        self
    }

    /// The exact stage, if any.
    pub fn exact(&self) -> Option<&ExactPairs> {
        self.exact.as_deref()
    }
}
