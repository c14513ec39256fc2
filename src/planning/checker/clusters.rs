//! Body clusters: the link groups carried by one body, behind one bounding sphere.
//!
//! A hand with its fingers, a force sensor and a flange is often a dozen link groups on
//! one body. Each batch places the cluster's sphere once and tests it against the
//! obstacles the groups can reach; an obstacle it misses is skipped for every group of the
//! cluster. Self pairs between one group and the groups of a cluster come in runs; a run
//! whose group bound misses the cluster's sphere is skipped whole. The cluster's sphere
//! contains each group's bound, and its inflation is at least each group's (its speed cap
//! is the largest of theirs per coordinate, its centre speed plus `|ω| R` bounds theirs), so
//! nothing that could hit is skipped: the answers are those of the group-by-group checks.

use crate::planning::spheres::{Sphere, SphereModel};
use std::ops::Range;

/// One cluster.
#[derive(Clone, Debug)]
pub(super) struct Cluster {
    /// Its groups (contiguous: groups are ordered by body).
    pub groups: Range<usize>,
    /// The sphere around every group's spheres, in the body frame.
    pub bound: Sphere,
    /// Obstacles any of its groups can reach.
    pub reachable: Vec<usize>,
    /// `rho[k]`: the largest speed bound of its points per unit rate of coordinate `k`.
    pub rho: Vec<f32>,
}

/// A run of consecutive self pairs: one group against groups of one cluster (or a single
/// pair, `cluster: None`).
#[derive(Clone, Debug)]
pub(super) struct PairRun {
    /// The first side's group.
    pub group: usize,
    /// The cluster holding every second side, when the run has two pairs or more.
    pub cluster: Option<usize>,
    /// Indices into the checker's self pairs.
    pub pairs: Range<usize>,
}

/// The clusters of a sphere model and the runs of its self pairs.
#[derive(Clone, Debug, Default)]
pub(super) struct Clusters {
    /// Clusters of two groups or more.
    pub list: Vec<Cluster>,
    /// Per group, its cluster.
    pub of: Vec<Option<usize>>,
    /// The self pairs in runs, in their order.
    pub runs: Vec<PairRun>,
}

impl Clusters {
    /// Clusters of `sm`'s moving bodies that carry two groups or more; `reachable[g]` are
    /// the obstacles group `g` can reach.
    pub fn new(sm: &SphereModel, reachable: &[Vec<usize>], pairs: &[(usize, usize)]) -> Self {
        let mut list = Vec::new();
        let mut of = vec![None; sm.links.len()];
        let mut g = 0;
        while g < sm.links.len() {
            let body = sm.links[g].body;
            let end = (g..sm.links.len())
                .find(|&e| sm.links[e].body != body)
                .unwrap_or(sm.links.len());
            if body != crate::model::WORLD && end - g >= 2 {
                for o in &mut of[g..end] {
                    *o = Some(list.len());
                }
                list.push(cluster(sm, reachable, g..end));
            }
            g = end;
        }
        let runs = runs(pairs, &of);
        Clusters { list, of, runs }
    }
}

impl Clusters {
    /// No clusters: every group and every self pair checked on its own.
    pub fn none(groups: usize, pairs: &[(usize, usize)]) -> Self {
        let of = vec![None; groups];
        let runs = runs(pairs, &of);
        Clusters {
            list: Vec::new(),
            of,
            runs,
        }
    }
}

/// The cluster of `groups`: centre the mean of their sphere centres, radius reaching every
/// sphere.
fn cluster(sm: &SphereModel, reachable: &[Vec<usize>], groups: Range<usize>) -> Cluster {
    let spheres = &sm.spheres[sm.links[groups.start].first..sm.links[groups.end - 1].end];
    let n = spheres.len().max(1) as f64;
    let mut c = [0.0f64; 3];
    for s in spheres {
        for (ck, &x) in c.iter_mut().zip(&s.center) {
            *ck += f64::from(x) / n;
        }
    }
    let radius = spheres
        .iter()
        .map(|s| {
            let d = (0..3)
                .map(|k| (f64::from(s.center[k]) - c[k]).powi(2))
                .sum::<f64>();
            d.sqrt() + f64::from(s.radius)
        })
        .fold(0.0, f64::max);
    let mut all: Vec<usize> = groups.clone().flat_map(|g| reachable[g].clone()).collect();
    all.sort_unstable();
    all.dedup();
    let nv = sm.nv;
    let rho = (0..nv)
        .map(|k| {
            groups
                .clone()
                .map(|g| sm.link_rho[g * nv + k])
                .fold(0.0, f32::max)
        })
        .collect();
    Cluster {
        groups,
        // Rounded outwards so that f32 rounding never shrinks it below a group's bound.
        bound: Sphere {
            center: c.map(|x| x as f32),
            radius: (radius * (1.0 + 1e-6) + 1e-6) as f32,
        },
        reachable: all,
        rho,
    }
}

/// The self pairs cut into maximal runs of one first group against one cluster.
fn runs(pairs: &[(usize, usize)], of: &[Option<usize>]) -> Vec<PairRun> {
    let mut out: Vec<PairRun> = Vec::new();
    for (i, &(ga, gb)) in pairs.iter().enumerate() {
        if let Some(last) = out.last_mut() {
            let (pa, pb) = pairs[last.pairs.start];
            if pa == ga && of[gb].is_some() && of[gb] == of[pb] && of[ga] != of[gb] {
                last.pairs.end = i + 1;
                last.cluster = of[gb];
                continue;
            }
        }
        out.push(PairRun {
            group: ga,
            cluster: None,
            pairs: i..i + 1,
        });
    }
    out
}
