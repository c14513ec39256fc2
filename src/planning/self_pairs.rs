//! Which link pairs the planner checks for self-collision.
//!
//! - With an SRDF: every pair of links that carry spheres, minus its
//!   `<disable_collisions>` pairs and minus the *adjacent* pairs below (as armsim's collision
//!   module does: the spheres of two links one joint apart overlap at the joint by
//!   construction in spherized models, e.g. the UR5's `wrist_2_link` and `fts_robotside`).
//! - Without: the pairs of the allowed-collision matrix ([`crate::planning::acm`], computed as
//!   MoveIt's Setup Assistant computes one) are the disabled ones, through the same
//!   function.
//!
//! Links on one body never move relative to each other: such pairs are always dropped.

use crate::model::{Model, WORLD};
use crate::planning::spheres::SphereModel;
use std::collections::HashSet;

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
