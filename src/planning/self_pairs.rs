//! Which link pairs the planner checks for self-collision.
//!
//! - With an SRDF: every pair of links that carry spheres, minus its
//!   `<disable_collisions>` pairs and minus the *adjacent* pairs below (as armsim's collision
//!   module does: the spheres of two links one joint apart overlap at the joint by
//!   construction in spherized models, e.g. the UR5's `wrist_2_link` and `fts_robotside`).
//! - Without: minus the *adjacent* pairs (links on the same body, or on a body and its
//!   parent body, world-fixed links counting as the world's) and minus the pairs that never
//!   touch over random samples of the joint box (as MoveIt's setup assistant does: such
//!   pairs are taken to be unable to collide). The caller reports this choice.
//!
//! Links on one body never move relative to each other: such pairs are always dropped.

use super::spheres::SphereModel;
use super::srdf::NamePair;
use crate::model::{Model, WORLD};
use std::collections::HashSet;

/// How the pairs were chosen, for the report.
#[derive(Clone, Debug, PartialEq)]
pub enum PairSource {
    /// From the SRDF's disabled pairs.
    Srdf,
    /// Adjacent pairs and pairs never in contact over this many random samples dropped.
    Sampled(usize),
}

/// Link-group index pairs `(a, b)`, `a < b`, to check; every pair of links on bodies that
/// are neither the same nor one joint apart, minus `disabled` (link names, either order).
pub fn from_disabled(
    model: &Model,
    sm: &SphereModel,
    disabled: &[(String, String)],
) -> Vec<(usize, usize)> {
    let off: HashSet<(&str, &str)> = disabled
        .iter()
        .flat_map(|(a, b)| [(a.as_str(), b.as_str()), (b.as_str(), a.as_str())])
        .collect();
    let mut out = Vec::new();
    for a in 0..sm.links.len() {
        for b in a + 1..sm.links.len() {
            let (la, lb) = (&sm.links[a], &sm.links[b]);
            if adjacent(model, la.body, lb.body) {
                continue;
            }
            let (na, nb) = (&model.links[la.link].name, &model.links[lb.link].name);
            if !off.contains(&(na.as_str(), nb.as_str())) {
                out.push((a, b));
            }
        }
    }
    out
}

/// Whether two bodies (or [`WORLD`]) are one joint apart.
fn adjacent(model: &Model, a: usize, b: usize) -> bool {
    let parent = |x: usize| if x == WORLD { WORLD } else { model.parent[x] };
    a == b || (b != WORLD && parent(b) == a) || (a != WORLD && parent(a) == b)
}

/// The pairs without an SRDF (see the module docs), with `samples` random configurations
/// from the joint box (seeded, so the choice is reproducible). Returns the pairs and the
/// names of the dropped ones.
pub fn sampled(
    model: &Model,
    sm: &SphereModel,
    samples: usize,
    seed: u64,
) -> (Vec<(usize, usize)>, Vec<NamePair>) {
    // Every pair on non-adjacent bodies.
    let all = from_disabled(model, sm, &[]);
    let mut touched = vec![false; all.len()];
    let mut rng = super::sampler::Rng::new(seed);
    let mut q = vec![0.0; model.nv];
    for _ in 0..samples {
        for (k, x) in q.iter_mut().enumerate() {
            let (lo, hi) = super::sampler::bounds(model, k);
            *x = lo + (hi - lo) * rng.next_f64();
        }
        let c = sm.world_centers(model, &q);
        for (p, &(a, b)) in all.iter().enumerate() {
            if touched[p] {
                continue;
            }
            let (la, lb) = (&sm.links[a], &sm.links[b]);
            touched[p] = (la.first..la.end).any(|i| {
                (lb.first..lb.end).any(|j| {
                    (c[i] - c[j]).norm() < (sm.spheres[i].radius + sm.spheres[j].radius) as f64
                })
            });
        }
    }
    let mut keep = Vec::new();
    let mut dropped = Vec::new();
    for (p, &(a, b)) in all.iter().enumerate() {
        let (la, lb) = (&sm.links[a], &sm.links[b]);
        if touched[p] {
            keep.push((a, b));
        } else {
            dropped.push((
                model.links[la.link].name.clone(),
                model.links[lb.link].name.clone(),
            ));
        }
    }
    (keep, dropped)
}
