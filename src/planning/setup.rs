//! The robot half of a planner, built once and shared by every query and thread: the
//! sphere model of the collision geometry, the self-collision pairs (from an SRDF, or from
//! the allowed-collision matrix computed as MoveIt's Setup Assistant computes it,
//! [`crate::planning::acm`]), and the exact collision model that names what a rejected start or
//! goal touches. A scene (the obstacles) is given per query
//! ([`crate::planning::Planner::set_obstacles`]).
//!
//! Set-up reports its own time ([`PlanningRobot::setup_time_s`]); the search time limit
//! starts with the query. The matrix's sampling polls the stop flag of the options.

use crate::collision::{CollisionData, CollisionModel, CollisionOptions};
use crate::model::Model;
use crate::planning::acm::{self, Acm, AcmOptions, SpherePoser};
use crate::planning::environment::Environment;
use crate::planning::plan_error::PlanSetupError;
use crate::planning::self_pairs;
use crate::planning::spheres::SphereModel;
use crate::planning::spherize::Primitive;
use crate::planning::PlanOptions;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

/// How the self-collision pairs were chosen, for the report.
#[derive(Clone, Debug)]
pub enum PairSource {
    /// From the SRDF's disabled pairs.
    Srdf,
    /// From the computed allowed-collision matrix.
    Computed(Box<Acm>),
}

/// The robot half of a planner (see the module docs).
#[derive(Debug)]
pub struct PlanningRobot {
    /// The model.
    pub model: Arc<Model>,
    /// Its collision geometry as spheres.
    pub spheres: SphereModel,
    /// Link-group pairs checked for self-collision.
    pub self_pairs: Vec<(usize, usize)>,
    /// Those of them whose sphere covers still touch where their exact geometry does not
    /// after [`refine`]: decided on the exact geometry where their spheres touch
    /// ([`crate::planning::checker::ExactPairs`]).
    pub exact_pairs: Vec<(usize, usize)>,
    /// The cover their first stage checks: the links of those pairs at half their
    /// overshoot (down to [`FINE_OVERSHOOT`]), so that the exact geometry is measured only
    /// where they come within a few millimetres.
    pub exact_spheres: SphereModel,
    /// How they were chosen.
    pub pair_source: PairSource,
    /// The exact geometry (parry), when it could be built: names the real distance of a
    /// pair the spheres find touching.
    pub exact: Option<CollisionModel>,
    /// Sphere cover, exact model and matrix (s).
    pub setup_time_s: f64,
    /// The sphere options the cover was finally built with (the links [`refine`]
    /// covered again, with their overshoot): another robot half of the same links can
    /// start from them.
    pub sphere_options: crate::planning::spheres::SphereOptions,
}

/// What a configuration touches: a pair of links or a link and an obstacle, with the
/// spheres' overlap and, for a link pair, the exact geometry's signed distance.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Contact {
    /// A link.
    pub a: String,
    /// A link or an obstacle.
    pub b: String,
    /// Largest overlap of two spheres (m).
    pub depth: f64,
    /// Signed distance of the exact geometry (m; negative: penetration), link pairs only.
    pub exact_distance: Option<f64>,
}

impl std::fmt::Display for Contact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "'{}' and '{}' overlap by {:.1} mm (sphere model)",
            self.a,
            self.b,
            self.depth * 1e3
        )?;
        match self.exact_distance {
            Some(d) if d > 0.0 => write!(
                f,
                "; their collision geometry is {:.1} mm apart: the spheres' overshoot \
                 (max_overshoot) makes them touch",
                d * 1e3
            ),
            Some(d) => write!(
                f,
                "; their collision geometry penetrates by {:.1} mm",
                -d * 1e3
            ),
            None => Ok(()),
        }
    }
}

impl PlanningRobot {
    /// Builds the robot half for `model`: `disabled` lists an SRDF's disabled pairs;
    /// `None` computes the allowed-collision matrix. Fails when the model has no geometry
    /// the planner can use (naming each unusable geometry and why), or when the stop flag
    /// is raised during the matrix's sampling.
    pub fn new(
        model: &Model,
        disabled: Option<&[(String, String)]>,
        opts: &PlanOptions,
    ) -> Result<PlanningRobot, PlanSetupError> {
        Self::with_extra_disabled(model, disabled, &[], opts)
    }

    /// [`PlanningRobot::new`] with `extra` pairs disabled besides the SRDF's or the
    /// matrix's (a scenario's own `disabled_pairs`).
    pub fn with_extra_disabled(
        model: &Model,
        disabled: Option<&[(String, String)]>,
        extra: &[(String, String)],
        opts: &PlanOptions,
    ) -> Result<PlanningRobot, PlanSetupError> {
        let t0 = Instant::now();
        let mut sopts = opts.spheres.clone();
        let spheres = SphereModel::new(model, &sopts);
        if !spheres.broken.is_empty() {
            return Err(PlanSetupError::BrokenMesh {
                model: model.name.clone(),
                problems: spheres.broken.clone(),
            });
        }
        if spheres.is_empty() {
            return Err(PlanSetupError::NoGeometry {
                model: model.name.clone(),
                unusable: spheres.warnings.clone(),
            });
        }
        let copts = CollisionOptions {
            package_path: opts.spheres.package_path.clone(),
            ..Default::default()
        };
        let exact = CollisionModel::new(model, Vec::new(), &copts).ok();
        let no_stop = AtomicBool::new(false);
        let stop = opts.stop.as_deref().unwrap_or(&no_stop);
        let (pairs, pair_source) = match disabled {
            Some(d) => {
                let off: Vec<(String, String)> = d.iter().chain(extra).cloned().collect();
                (
                    self_pairs::from_disabled(model, &spheres, &off),
                    PairSource::Srdf,
                )
            }
            None => {
                let aopts = AcmOptions {
                    seed: opts.seed,
                    samples: opts.acm_samples,
                    max_pair_tests: opts.acm_max_pair_tests,
                    ..Default::default()
                };
                let acm = acm::compute_cached(model, &spheres, exact.as_ref(), &aopts, stop)
                    .map_err(|e| match e {
                        acm::AcmError::Interrupted => PlanSetupError::Interrupted,
                        problem => PlanSetupError::AcmOverBudget {
                            model: model.name.clone(),
                            problem,
                        },
                    })?;
                let mut off = acm.disabled_names();
                off.extend(extra.iter().cloned());
                let pairs = self_pairs::from_disabled(model, &spheres, &off);
                (pairs, PairSource::Computed(Box::new(acm)))
            }
        };
        let (spheres, exact_pairs) = match &exact {
            Some(cm) => refine(model, &mut sopts, spheres, cm, &pairs, opts.seed),
            None => (spheres, Vec::new()),
        };
        let exact_spheres = fine_cover(model, &sopts, &spheres, &exact_pairs);
        Ok(PlanningRobot {
            model: Arc::new(model.clone()),
            spheres,
            self_pairs: pairs,
            exact_pairs,
            exact_spheres,
            pair_source,
            exact,
            setup_time_s: t0.elapsed().as_secs_f64(),
            sphere_options: sopts,
        })
    }

    /// The collision checker of this robot among the obstacles of `env`.
    pub fn checker(
        &self,
        env: Environment,
        opts: crate::planning::CheckOptions,
    ) -> crate::planning::Checker {
        let own: Vec<(usize, usize)> = self
            .self_pairs
            .iter()
            .filter(|p| !self.exact_pairs.contains(p))
            .copied()
            .collect();
        let checker =
            crate::planning::Checker::new(&self.model, self.spheres.clone(), env, own, opts);
        match &self.exact {
            Some(cm) if !self.exact_pairs.is_empty() => {
                let spheres = crate::planning::Checker::new(
                    &self.model,
                    self.exact_spheres.clone(),
                    Environment::default(),
                    self.exact_pairs.clone(),
                    opts,
                );
                let links = self
                    .exact_pairs
                    .iter()
                    .map(|&(a, b)| (self.spheres.links[a].link, self.spheres.links[b].link))
                    .collect();
                checker.with_exact(crate::planning::checker::ExactPairs::new(
                    self.model.clone(),
                    cm,
                    links,
                    spheres,
                ))
            }
            _ => checker,
        }
    }

    /// Everything configuration `q` touches among the checked self pairs and the
    /// obstacles of `env`, deepest first.
    pub fn contacts(&self, env: &Environment, q: &[f64]) -> Vec<Contact> {
        let (model, sm) = (&*self.model, &self.spheres);
        let mut poser = SpherePoser::new(model, sm);
        poser.place(model, sm, q);
        let name = |g: usize| model.links[sm.links[g].link].name.clone();
        let mut exact = self
            .exact
            .as_ref()
            .map(|cm| (cm, CollisionData::new(model, cm)));
        if let Some((cm, cd)) = exact.as_mut() {
            cm.update(model, cd, q);
        }
        let mut out = Vec::new();
        for &(a, b) in &self.self_pairs {
            let depth = poser.deepest(sm, a, b, true);
            if depth > 0.0 {
                let exact_distance = exact.as_ref().and_then(|(cm, cd)| {
                    cm.body_distance(
                        cd,
                        crate::collision::Body::Link(sm.links[a].link),
                        crate::collision::Body::Link(sm.links[b].link),
                    )
                });
                // A pair decided on the exact geometry touches only when that does.
                let apart = exact_distance.is_some_and(|d| d > 0.0);
                if apart && self.exact_pairs.contains(&(a, b)) {
                    continue;
                }
                out.push(Contact {
                    a: name(a),
                    b: name(b),
                    depth,
                    exact_distance,
                });
            }
        }
        for (o, ob) in env.obstacles.iter().enumerate() {
            let prim = match ob.shape {
                crate::planning::environment::EnvShape::Sphere(r) => Primitive::Sphere(r as f64),
                crate::planning::environment::EnvShape::Box(h) => Primitive::Box(h.map(f64::from)),
                crate::planning::environment::EnvShape::Cylinder(r, h) => {
                    Primitive::Cylinder(r as f64, h as f64)
                }
                crate::planning::environment::EnvShape::Capsule(r, h) => {
                    Primitive::Capsule(r as f64, h as f64)
                }
            };
            for (g, ls) in sm.links.iter().enumerate() {
                let depth = (ls.first..ls.end)
                    .map(|s| {
                        let c = poser.center(s);
                        let d = [c.x, c.y, c.z];
                        let d = [0, 1, 2].map(|k| d[k] - f64::from(ob.center[k]));
                        let local = ob
                            .rot_t
                            .map(|r| (0..3).map(|k| f64::from(r[k]) * d[k]).sum::<f64>());
                        sm.spheres[s].radius as f64 - prim.sdf(local)
                    })
                    .fold(f64::NEG_INFINITY, f64::max);
                if depth > 0.0 {
                    out.push(Contact {
                        a: name(g),
                        b: env.names[o].clone(),
                        depth,
                        exact_distance: None,
                    });
                }
            }
        }
        out.sort_by(|x, y| y.depth.total_cmp(&x.depth));
        out
    }
}

/// Rounds of [`refine`].
const REFINE_ROUNDS: usize = 3;

/// The smallest overshoot [`refine`] goes down to (m).
const MIN_OVERSHOOT: f64 = 0.005;

/// Random configurations [`refine`] looks at (besides the default one).
const REFINE_SAMPLES: usize = 100;

/// Tightens the sphere cover where it makes checked pairs touch that do not: a pair whose
/// spheres overlap while its exact geometry is apart, at the default configuration or in
/// more than 10 % of random configurations, has both links covered again with half their
/// overshoot (down to [`MIN_OVERSHOOT`]), for [`REFINE_ROUNDS`] round(s). Such pairs
/// sit closer than twice the overshoot by design (a UR5's base and upper arm, 16 mm
/// apart): with the coarse cover they would look in contact at nearly every pose. The
/// link groups keep their order, so the pair indices stay valid.
///
/// Returns the cover and the pairs that still touch falsely in any of the configurations
/// with it: those are decided on the exact geometry ([`crate::planning::checker::ExactPairs`]).
fn refine(
    model: &Model,
    sopts: &mut crate::planning::spheres::SphereOptions,
    mut sm: SphereModel,
    cm: &CollisionModel,
    pairs: &[(usize, usize)],
    seed: u64,
) -> (SphereModel, Vec<(usize, usize)>) {
    let mut configs = vec![acm::default_configuration(model)];
    configs.extend(acm::sample_configs(
        model,
        REFINE_SAMPLES,
        seed ^ 0x5eed_f1e7,
    ));
    let mut cd = CollisionData::new(model, cm);
    let mut counts = false_contacts(model, &sm, cm, &mut cd, &configs, pairs);
    for _ in 0..REFINE_ROUNDS {
        let mut halve: Vec<usize> = Vec::new();
        for (&f, &(a, b)) in counts.iter().zip(pairs) {
            if f * 10 > REFINE_SAMPLES {
                halve.extend([sm.links[a].link, sm.links[b].link]);
            }
        }
        halve.sort_unstable();
        halve.dedup();
        let mut changed = false;
        for l in halve {
            let name = &model.links[l].name;
            let now = sopts.overshoot_of(name);
            if now > MIN_OVERSHOOT {
                sopts.link_overshoot.retain(|(n, _)| n != name);
                sopts
                    .link_overshoot
                    .push((name.clone(), (now / 2.0).max(MIN_OVERSHOOT)));
                changed = true;
            }
        }
        if !changed {
            break;
        }
        sm = SphereModel::new(model, sopts);
        counts = false_contacts(model, &sm, cm, &mut cd, &configs, pairs);
    }
    let still = counts.iter().zip(pairs).filter(|(&f, _)| f > 0);
    let still = still.map(|(_, &p)| p).collect();
    (sm, still)
}

/// The smallest overshoot of the exact pairs' first stage (m).
pub const FINE_OVERSHOOT: f64 = 0.0025;

/// The cover of the exact pairs' first stage: their links at half the overshoot of
/// `sopts` (not below [`FINE_OVERSHOOT`]); `coarse` itself when there are no such pairs.
/// The link groups keep their order.
fn fine_cover(
    model: &Model,
    sopts: &crate::planning::spheres::SphereOptions,
    coarse: &SphereModel,
    exact_pairs: &[(usize, usize)],
) -> SphereModel {
    if exact_pairs.is_empty() {
        return coarse.clone();
    }
    let mut fine = sopts.clone();
    for &(a, b) in exact_pairs {
        for g in [a, b] {
            let name = &model.links[coarse.links[g].link].name;
            let now = sopts.overshoot_of(name);
            fine.link_overshoot.retain(|(n, _)| n != name);
            let half = (now / 2.0).max(FINE_OVERSHOOT).min(now);
            fine.link_overshoot.push((name.clone(), half));
        }
    }
    SphereModel::new(model, &fine)
}

/// Per pair, in how many of `configs` its spheres touch while its exact geometry is
/// apart; the first configuration (the default one) counts as [`REFINE_SAMPLES`].
fn false_contacts(
    model: &Model,
    sm: &SphereModel,
    cm: &CollisionModel,
    cd: &mut CollisionData,
    configs: &[Vec<f64>],
    pairs: &[(usize, usize)],
) -> Vec<usize> {
    let mut poser = SpherePoser::new(model, sm);
    let mut counts = vec![0usize; pairs.len()];
    for (i, q) in configs.iter().enumerate() {
        poser.place(model, sm, q);
        let mut updated = false;
        for (f, &(a, b)) in counts.iter_mut().zip(pairs) {
            if !poser.touch(sm, a, b) {
                continue;
            }
            if !updated {
                cm.update(model, cd, q);
                updated = true;
            }
            if !cm.links_collide(cd, sm.links[a].link, sm.links[b].link) {
                *f += if i == 0 { REFINE_SAMPLES } else { 1 };
            }
        }
    }
    counts
}
