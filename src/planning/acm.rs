//! The allowed-collision matrix (ACM): which link pairs the self-collision checks skip when
//! no SRDF is given, computed the way MoveIt's Setup Assistant computes its default
//! `<disable_collisions>` (`compute_default_collisions.cpp`), in the same four passes:
//!
//! 1. **Adjacent**: links on one body (rigidly attached), or on bodies one joint apart;
//!    a body without collision geometry passes adjacency through (its parent's links are
//!    adjacent to its children's links), as the assistant's connection graph does.
//! 2. **Default**: pairs in collision at the default configuration (each joint at 0, or at
//!    the middle of its range when 0 is outside it: MoveIt's default positions).
//! 3. **Always**: pairs in collision in at least [`AcmOptions::always_fraction`] of
//!    [`AcmOptions::always_samples`] random configurations.
//! 4. **Never**: pairs never in collision over [`AcmOptions::samples`] random
//!    configurations of the joint box (seeded: the same model gives the same matrix).
//!
//! **Which geometry.** Every pass decides on the exact collision geometry (parry,
//! [`CollisionModel`]), as the assistant does on its meshes, so a pair is neither dropped
//! nor kept because the sphere cover's overshoot makes neighbours touch. The planner's
//! sphere cover (which contains the geometry) is the filter in front: where the spheres
//! of a pair do not touch, the geometry does not either, and the exact test is skipped.
//! Without an exact model (no mesh could be read) the spheres decide, which drops fewer
//! pairs as *Never* and more as *Default* and *Always*. As the assistant's, *Never* is a
//! claim about the samples, not a proof: a pair that collides only in a sliver of the
//! joint space may be missed by both.
//!
//! **Cost.** The sphere tests run bounding sphere first, then each sphere of one link
//! against the other link's bound, then sphere against sphere, and a pair is not tested
//! again once it has touched; the samples are split over the rayon threads. The exact
//! tests run only on the few pairs whose spheres touch at the default configuration or in
//! nearly every sample.

use crate::collision::{CollisionData, CollisionModel};
use crate::core::spatial::{Se3, Vec3};
use crate::kinematics::forward_kinematics;
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use crate::planning::sampler::{bounds, uniform, Rng};
use crate::planning::spheres::SphereModel;
use rayon::prelude::*;
use std::collections::HashSet;
use std::sync::atomic::{AtomicBool, Ordering};

/// Why a pair is disabled (the SRDF's `reason` attribute).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub enum Reason {
    /// One joint apart, or rigidly attached.
    Adjacent,
    /// In collision at the default configuration.
    Default,
    /// In collision in nearly every sampled configuration.
    Always,
    /// Never in collision over the samples.
    Never,
}

impl Reason {
    /// The SRDF spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Reason::Adjacent => "Adjacent",
            Reason::Default => "Default",
            Reason::Always => "Always",
            Reason::Never => "Never",
        }
    }
}

/// A disabled pair.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AcmPair {
    /// First link.
    pub link1: String,
    /// Second link.
    pub link2: String,
    /// Why.
    pub reason: Reason,
}

/// The most pair tests (candidate pairs × (*Never* + *Always* samples)) [`compute`] runs
/// unless told otherwise ([`AcmOptions::max_pair_tests`]): 2·10⁸, a few seconds on two
/// cores. A 50-link robot at the default 10 000 samples makes about 1.2·10⁷; a 1 000-link
/// star 5·10⁹ (over 30 s).
pub const MAX_PAIR_TESTS: u64 = 200_000_000;

/// Why [`compute`] gave no matrix.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AcmError {
    /// The stop flag was raised during the sampling.
    #[error("interrupted while computing the allowed-collision matrix")]
    Interrupted,
    /// The sampling would run more pair tests than [`AcmOptions::max_pair_tests`]; checked
    /// before any configuration is sampled.
    #[error(
        "the allowed-collision matrix would test {pairs} link pairs in {configs} random \
         configurations ({tests} pair tests), more than the budget of {budget}: at most \
         {fit} samples fit it (MoveIt's Setup Assistant samples 10000 by default; fewer decide \
         fewer pairs as never colliding)"
    )]
    OverBudget {
        /// Candidate pairs (not adjacent).
        pairs: usize,
        /// *Never* plus *Always* samples.
        configs: usize,
        /// Their product.
        tests: u64,
        /// The budget.
        budget: u64,
        /// The most *Never* samples that fit the budget (beside the *Always* ones).
        fit: u64,
    },
}

/// Settings of [`compute`].
#[derive(Clone, Debug)]
pub struct AcmOptions {
    /// Random configurations of the *Never* pass (the assistant's default density).
    pub samples: usize,
    /// The most pair tests the sampling may run (see [`MAX_PAIR_TESTS`]); `None`: no
    /// limit (`--force`).
    pub max_pair_tests: Option<u64>,
    /// Random configurations of the *Always* pass.
    pub always_samples: usize,
    /// Fraction of the *Always* samples a pair must collide in (the assistant's 0.95).
    pub always_fraction: f64,
    /// Seed of the samples.
    pub seed: u64,
}

impl Default for AcmOptions {
    fn default() -> Self {
        Self {
            samples: 10_000,
            max_pair_tests: Some(MAX_PAIR_TESTS),
            always_samples: 200,
            always_fraction: 0.95,
            seed: 0,
        }
    }
}

/// The computed matrix.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Acm {
    /// Disabled pairs, by reason then name.
    pub disabled: Vec<AcmPair>,
    /// Pairs left checked (link names).
    pub checked: Vec<(String, String)>,
    /// Samples of the *Never* pass.
    pub samples: usize,
    /// Whether *Default* and *Always* were decided on the exact geometry (otherwise on the
    /// spheres: no exact collision model could be built).
    pub exact: bool,
}

impl Acm {
    /// The disabled pairs as name pairs (what [`crate::planning::self_pairs::from_disabled`]
    /// takes).
    pub fn disabled_names(&self) -> Vec<(String, String)> {
        self.disabled
            .iter()
            .map(|p| (p.link1.clone(), p.link2.clone()))
            .collect()
    }

    /// How many pairs each reason disabled.
    pub fn counts(&self) -> [(Reason, usize); 4] {
        [
            Reason::Adjacent,
            Reason::Default,
            Reason::Always,
            Reason::Never,
        ]
        .map(|r| (r, self.disabled.iter().filter(|p| p.reason == r).count()))
    }

    /// The matrix as an SRDF (`<disable_collisions>` with reasons), for MoveIt or `--srdf`.
    pub fn to_srdf(&self, robot: &str) -> String {
        let esc = |s: &str| {
            s.replace('&', "&amp;")
                .replace('<', "&lt;")
                .replace('"', "&quot;")
        };
        let mut out = format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- Allowed-collision matrix computed by armsim \
             ({} samples; adjacent, default, always and never-colliding pairs, as the MoveIt Setup \
             Assistant computes them). -->\n<robot name=\"{}\">\n",
            self.samples,
            esc(robot)
        );
        for p in &self.disabled {
            out += &format!(
                "  <disable_collisions link1=\"{}\" link2=\"{}\" reason=\"{}\"/>\n",
                esc(&p.link1),
                esc(&p.link2),
                p.reason.as_str()
            );
        }
        out + "</robot>\n"
    }
}

/// MoveIt's default configuration: 0 where the limits allow it, else the middle.
pub fn default_configuration(model: &Model) -> Vec<f64> {
    (0..model.nv)
        .map(|k| {
            let (lo, hi) = (model.lower[k], model.upper[k]);
            if (lo.is_nan() || lo <= 0.0) && (hi.is_nan() || hi >= 0.0) {
                0.0
            } else {
                let (lo, hi) = bounds(model, k);
                0.5 * (lo + hi)
            }
        })
        .collect()
}

/// Raised when the matrix's computation changes, so old cached matrices are not read.
const CACHE_VERSION: u32 = 1;

/// [`compute`], kept on disk ([`crate::planning::cover_cache`]) under a fingerprint of the model's
/// URDF text, the sphere cover (which stands for the mesh files' contents), whether the
/// exact geometry was built, the options and [`CACHE_VERSION`]; a model without URDF text
/// (a DH table) is computed every time.
pub fn compute_cached(
    model: &Model,
    sm: &SphereModel,
    exact: Option<&CollisionModel>,
    opts: &AcmOptions,
    stop: &AtomicBool,
) -> Result<Acm, AcmError> {
    let Some(urdf) = &model.urdf_text else {
        return compute(model, sm, exact, opts, stop);
    };
    let spheres: Vec<u8> = sm
        .spheres
        .iter()
        .flat_map(|s| {
            s.center
                .iter()
                .chain([&s.radius])
                .flat_map(|x| x.to_le_bytes())
        })
        .collect();
    let groups: Vec<u8> = sm
        .links
        .iter()
        .flat_map(|l| {
            [l.link as u64, l.end as u64]
                .into_iter()
                .flat_map(u64::to_le_bytes)
        })
        .collect();
    let settings = format!(
        "{CACHE_VERSION} {} {} {} {} {}",
        opts.samples,
        opts.always_samples,
        opts.always_fraction,
        opts.seed,
        exact.is_some()
    );
    let key = crate::planning::cover_cache::fingerprint([
        urdf.as_bytes(),
        &spheres,
        &groups,
        settings.as_bytes(),
    ]);
    let name = format!("acm-{key:016x}.json");
    if let Some(acm) = crate::planning::cover_cache::load_text(&name)
        .and_then(|t| serde_json::from_str::<Acm>(&t).ok())
    {
        return Ok(acm);
    }
    let acm = compute(model, sm, exact, opts, stop)?;
    if let Ok(text) = serde_json::to_string(&acm) {
        crate::planning::cover_cache::store_text(&name, &text);
    }
    Ok(acm)
}

/// The ACM of `model` (see the module docs): `sm` is the planner's sphere cover, `exact`
/// the exact collision geometry when it could be built. `stop` ends the sampling early
/// ([`AcmError::Interrupted`]); more pair tests than [`AcmOptions::max_pair_tests`] are
/// refused before the first sample ([`AcmError::OverBudget`]).
pub fn compute(
    model: &Model,
    sm: &SphereModel,
    exact: Option<&CollisionModel>,
    opts: &AcmOptions,
    stop: &AtomicBool,
) -> Result<Acm, AcmError> {
    let groups = sm.links.len();
    let mut reason: Vec<Option<Reason>> = vec![None; groups * groups];
    let pair_index = |a: usize, b: usize| a.min(b) * groups + a.max(b);
    let up = geometric_parents(model, sm);
    let mut candidates = Vec::new();
    for a in 0..groups {
        for b in a + 1..groups {
            let (ba, bb) = (sm.links[a].body, sm.links[b].body);
            let parent = |x: usize| if x == WORLD { None } else { Some(up[x]) };
            if ba == bb || parent(bb) == Some(ba) || parent(ba) == Some(bb) {
                reason[pair_index(a, b)] = Some(Reason::Adjacent);
            } else {
                candidates.push((a, b));
            }
        }
    }
    check_budget(candidates.len(), opts)?;
    // 2. Default.
    let q0 = default_configuration(model);
    let mut poser = SpherePoser::new(model, sm);
    poser.place(model, sm, &q0);
    let touching: Vec<(usize, usize)> = candidates
        .iter()
        .copied()
        .filter(|&(a, b)| poser.touch(sm, a, b))
        .collect();
    let mut ex = exact.map(|cm| (cm, CollisionData::new(model, cm)));
    if let Some((cm, cd)) = ex.as_mut() {
        cm.update(model, cd, &q0);
    }
    for &(a, b) in &touching {
        let hit = match ex.as_ref() {
            Some((cm, cd)) => cm.links_collide(cd, sm.links[a].link, sm.links[b].link),
            None => true,
        };
        if hit {
            reason[pair_index(a, b)] = Some(Reason::Default);
        }
    }
    candidates.retain(|&(a, b)| reason[pair_index(a, b)].is_none());
    // 3. Always.
    let configs = sample_configs(model, opts.always_samples, opts.seed ^ 0xa1a5);
    let need = (opts.always_fraction * opts.always_samples as f64).ceil() as usize;
    let mut sphere_hits = vec![0usize; candidates.len()];
    for q in &configs {
        poser.place(model, sm, q);
        for (h, &(a, b)) in sphere_hits.iter_mut().zip(&candidates) {
            *h += poser.touch(sm, a, b) as usize;
        }
    }
    for (&(a, b), &sphere) in candidates.iter().zip(&sphere_hits) {
        if sphere < need || opts.always_samples == 0 {
            continue;
        }
        let hits = match ex.as_mut() {
            None => sphere,
            Some((cm, cd)) => {
                let (la, lb) = (sm.links[a].link, sm.links[b].link);
                let mut hits = 0;
                for (i, q) in configs.iter().enumerate() {
                    if hits + (configs.len() - i) < need {
                        break;
                    }
                    cm.update(model, cd, q);
                    hits += cm.links_collide(cd, la, lb) as usize;
                }
                hits
            }
        };
        if hits >= need {
            reason[pair_index(a, b)] = Some(Reason::Always);
        }
    }
    candidates.retain(|&(a, b)| reason[pair_index(a, b)].is_none());
    // 4. Never.
    let touched =
        never_pass(model, sm, exact, &candidates, opts, stop).ok_or(AcmError::Interrupted)?;
    for (&(a, b), t) in candidates.iter().zip(&touched) {
        if !t {
            reason[pair_index(a, b)] = Some(Reason::Never);
        }
    }
    Ok(collect(model, sm, &reason, opts.samples, exact.is_some()))
}

/// Refuses more pair tests than the budget: `pairs` candidates in every *Never* and
/// *Always* sample.
fn check_budget(pairs: usize, opts: &AcmOptions) -> Result<(), AcmError> {
    let Some(budget) = opts.max_pair_tests else {
        return Ok(());
    };
    let configs = opts.samples.saturating_add(opts.always_samples);
    let tests = (pairs as u64).saturating_mul(configs as u64);
    if tests <= budget {
        return Ok(());
    }
    Err(AcmError::OverBudget {
        pairs,
        configs,
        tests,
        budget,
        fit: (budget / pairs.max(1) as u64).saturating_sub(opts.always_samples as u64),
    })
}

/// The disabled and checked pairs, by reason and name.
fn collect(
    model: &Model,
    sm: &SphereModel,
    reason: &[Option<Reason>],
    samples: usize,
    exact: bool,
) -> Acm {
    let groups = sm.links.len();
    let name = |g: usize| model.links[sm.links[g].link].name.clone();
    let mut disabled = Vec::new();
    let mut checked = Vec::new();
    let mut seen = HashSet::new();
    for a in 0..groups {
        for b in a + 1..groups {
            let (na, nb) = (name(a), name(b));
            let (n1, n2) = if na <= nb { (na, nb) } else { (nb, na) };
            if !seen.insert((n1.clone(), n2.clone())) {
                continue;
            }
            match reason[a * groups + b] {
                Some(r) => disabled.push(AcmPair {
                    link1: n1,
                    link2: n2,
                    reason: r,
                }),
                None => checked.push((n1, n2)),
            }
        }
    }
    disabled.sort_by(|x, y| (x.reason, &x.link1, &x.link2).cmp(&(y.reason, &y.link1, &y.link2)));
    checked.sort();
    Acm {
        disabled,
        checked,
        samples,
        exact,
    }
}

/// Per body, the nearest ancestor body that carries a link group, or [`WORLD`]: bodies
/// without geometry pass adjacency on to their children.
fn geometric_parents(model: &Model, sm: &SphereModel) -> Vec<usize> {
    let nb = model.nbodies();
    let mut has = vec![false; nb];
    for ls in sm.links.iter().filter(|ls| ls.body != WORLD) {
        has[ls.body] = true;
    }
    (0..nb)
        .map(|b| {
            let mut p = model.parent[b];
            while p != WORLD && !has[p] {
                p = model.parent[p];
            }
            p
        })
        .collect()
}

/// Uniform random configurations in the joint box.
pub fn sample_configs(model: &Model, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let mut q = vec![0.0; model.nv];
            uniform(model, &mut rng, &mut q);
            q
        })
        .collect()
}

/// For each candidate pair, whether it touched (the spheres first, then the exact
/// geometry where there is one) in any of `opts.samples` random configurations (split over the
/// rayon threads in fixed chunks: the answer does not depend on the thread count). `None` when
/// `stop` was raised.
fn never_pass(
    model: &Model,
    sm: &SphereModel,
    exact: Option<&CollisionModel>,
    candidates: &[(usize, usize)],
    opts: &AcmOptions,
    stop: &AtomicBool,
) -> Option<Vec<bool>> {
    const CHUNK: usize = 500;
    let chunks = opts.samples.div_ceil(CHUNK);
    let parts: Vec<Vec<bool>> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut touched = vec![false; candidates.len()];
            if stop.load(Ordering::Relaxed) {
                return touched;
            }
            let mut rng = Rng::new(opts.seed.wrapping_add(c as u64));
            let mut poser = SpherePoser::new(model, sm);
            let mut cd = exact.map(|cm| CollisionData::new(model, cm));
            let mut q = vec![0.0; model.nv];
            let n = CHUNK.min(opts.samples - c * CHUNK);
            for _ in 0..n {
                uniform(model, &mut rng, &mut q);
                poser.place(model, sm, &q);
                let mut placed = false;
                for (t, &(a, b)) in touched.iter_mut().zip(candidates) {
                    if *t || !poser.touch(sm, a, b) {
                        continue;
                    }
                    // The spheres touch: the exact geometry decides, as the assistant's.
                    *t = match (exact, cd.as_mut()) {
                        (Some(cm), Some(cd)) => {
                            if !placed {
                                cm.update(model, cd, &q);
                                placed = true;
                            }
                            cm.links_collide(cd, sm.links[a].link, sm.links[b].link)
                        }
                        _ => true,
                    };
                }
            }
            touched
        })
        .collect();
    if stop.load(Ordering::Relaxed) {
        return None;
    }
    let mut out = vec![false; candidates.len()];
    for p in parts {
        for (o, t) in out.iter_mut().zip(p) {
            *o |= t;
        }
    }
    Some(out)
}

/// World sphere centres and link bounds at one configuration, in reused buffers.
pub struct SpherePoser {
    data: Data,
    centers: Vec<Vec3>,
    bounds: Vec<Vec3>,
}

impl SpherePoser {
    /// Buffers for `sm`.
    pub fn new(model: &Model, sm: &SphereModel) -> SpherePoser {
        SpherePoser {
            data: Data::new(model),
            centers: vec![Vec3::zeros(); sm.len()],
            bounds: vec![Vec3::zeros(); sm.links.len()],
        }
    }

    /// Places every sphere and link bound at `q`.
    pub fn place(&mut self, model: &Model, sm: &SphereModel, q: &[f64]) {
        forward_kinematics(model, &mut self.data, q);
        let v = |c: [f32; 3]| Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64);
        for (g, ls) in sm.links.iter().enumerate() {
            let pose = if ls.body == WORLD {
                Se3::identity()
            } else {
                self.data.o_m_i[ls.body]
            };
            self.bounds[g] = pose.act_point(&v(ls.bound.center));
            for s in ls.first..ls.end {
                self.centers[s] = pose.act_point(&v(sm.spheres[s].center));
            }
        }
    }

    /// World centre of sphere `s` at the last [`SpherePoser::place`].
    pub fn center(&self, s: usize) -> Vec3 {
        self.centers[s]
    }

    /// Whether groups `a` and `b` overlap (strictly) at the last placement.
    pub fn touch(&self, sm: &SphereModel, a: usize, b: usize) -> bool {
        self.deepest(sm, a, b, false) > 0.0
    }

    /// The largest overlap `r_i + r_j − |c_i − c_j|` of a sphere of `a` with one of `b`
    /// (≤ 0 when apart; without `all`, the first positive overlap found is returned).
    pub fn deepest(&self, sm: &SphereModel, a: usize, b: usize, all: bool) -> f64 {
        let (la, lb) = (&sm.links[a], &sm.links[b]);
        let (ca, cb) = (self.bounds[a], self.bounds[b]);
        let (ra, rb) = (la.bound.radius as f64, lb.bound.radius as f64);
        let gap = (ca - cb).norm() - ra - rb;
        if gap >= 0.0 {
            return -gap;
        }
        let mut best = f64::NEG_INFINITY;
        for i in la.first..la.end {
            let ri = sm.spheres[i].radius as f64;
            let ci = self.centers[i];
            if (ci - cb).norm() >= ri + rb {
                best = best.max(rb + ri - (ci - cb).norm());
                continue;
            }
            for j in lb.first..lb.end {
                let d = ri + sm.spheres[j].radius as f64 - (ci - self.centers[j]).norm();
                if d > best {
                    best = d;
                    if d > 0.0 && !all {
                        return d;
                    }
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn bundled_ur5_meshes_are_spherized_quickly_and_sampled_self_pairs_work() {
        use crate::model::{Model, WORLD};
        use crate::planning::spheres::{SphereModel, SphereOptions};
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let spec = Model::read_spec(&root.join("robots/ur5.urdf")).unwrap();
        let model = Model::build(spec).unwrap().0;
        let opts = SphereOptions {
            max_overshoot: 0.03,
            ..Default::default()
        };
        let t = std::time::Instant::now();
        let sm = SphereModel::new(&model, &opts);
        let secs = t.elapsed().as_secs_f64();
        assert!(sm.warnings.is_empty(), "{:?}", sm.warnings);
        // Every link with a collision mesh has spheres, each within the link's mesh
        // bounding box grown by the overshoot (the centres are grid points of that box).
        let meshed = model
            .links
            .iter()
            .filter(|l| !l.collisions.is_empty())
            .count();
        assert_eq!(sm.links.len(), meshed);
        assert!(secs < 7.0, "{secs} s for {meshed} links");
        // Without an SRDF: the allowed-collision matrix disables every adjacent pair and
        // keeps or disables each other pair for a stated reason.
        let opts = crate::planning::acm::AcmOptions {
            samples: 2000,
            seed: 1,
            ..Default::default()
        };
        let stop = std::sync::atomic::AtomicBool::new(false);
        let acm = crate::planning::acm::compute(&model, &sm, None, &opts, &stop).unwrap();
        let parent = |b: usize| if b == WORLD { WORLD } else { model.parent[b] };
        let far = |a: usize, b: usize| a != b && parent(b) != a && parent(a) != b;
        let mut expect = 0;
        for (i, la) in sm.links.iter().enumerate() {
            for lb in &sm.links[i + 1..] {
                expect += far(la.body, lb.body) as usize;
            }
        }
        assert!(expect >= 10, "{expect}");
        let adjacent = acm.counts()[0].1;
        assert_eq!(acm.checked.len() + acm.disabled.len() - adjacent, expect);
        let body = |n: &str| model.links[model.link_id(n).unwrap()].body;
        for (a, b) in &acm.checked {
            assert!(far(body(a), body(b)), "{a} {b}");
        }
    }
}
