//! Collision checking along a sampled trajectory `(t_k, q_k)`.
//!
//! Between samples the configuration is the linear interpolation of `q` in time (for
//! continuous joints too: the angle is interpolated, not wrapped). Each sample is checked
//! (optionally also intermediate configurations, [`TrajectoryOptions::max_step`] apart in
//! the largest joint change); at the first configuration found in collision, the time of
//! first contact is refined by bisection between the last free configuration and it,
//! until the bracket is shorter than [`TrajectoryOptions::time_tolerance`]. The reported
//! time is the bracket's upper end (in collision), so it lies within the tolerance after
//! the true contact time — provided the contact does not start and end between two
//! checked configurations (a collision shorter than the checking step can be missed; use
//! `max_step` to bound the step).
//!
//! The minimum distances (environment and self, signed) are recorded at every sample,
//! for plotting, with their overall minima.

use crate::collision::collision_error::CollisionError;
use crate::collision::collision_scene::{Body, CollisionData, CollisionModel, PairDistance, Scope};
use crate::model::Model;
use serde::{Deserialize, Serialize};

/// Trajectory check settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrajectoryOptions {
    /// Pairs looked at (collisions and distances).
    pub scope: Scope,
    /// Bisection stops when the bracket on the first contact time is shorter (s).
    pub time_tolerance: f64,
    /// Largest joint change (rad or m, any joint) between checked configurations:
    /// segments are subdivided. `None`: the samples only.
    pub max_step: Option<f64>,
    /// Record the minimum distances at every sample.
    pub distances: bool,
}

impl Default for TrajectoryOptions {
    fn default() -> Self {
        Self {
            scope: Scope::All,
            time_tolerance: 1e-6,
            max_step: None,
            distances: true,
        }
    }
}

/// The first collision along a trajectory.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrajectoryCollision {
    /// First time found in collision: the upper end of the bisection bracket (s).
    pub time: f64,
    /// Last time known free: the lower end of the bracket (`None` when the first sample
    /// is already in collision).
    pub last_free: Option<f64>,
    /// Sample index `k` with `time` in `(t[k-1], t[k]]` (0 for the first sample).
    pub sample: usize,
    /// Names of the most penetrating pair at `time` (a link, then a link or an obstacle).
    pub names: (String, String),
    /// Every pair in collision at `time`, most penetrating first.
    pub pairs: Vec<PairDistance>,
    /// The configuration at `time`.
    pub q: Vec<f64>,
}

/// Minimum distances at one sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DistanceSample {
    /// Sample time (s).
    pub time: f64,
    /// Robot against environment (`None` without environment pairs in scope).
    pub environment: Option<PairDistance>,
    /// Robot against itself (`None` without self pairs in scope).
    pub self_collision: Option<PairDistance>,
}

/// Result of [`CollisionModel::check_trajectory`].
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TrajectoryReport {
    /// The first collision, if any.
    pub first_collision: Option<TrajectoryCollision>,
    /// Minimum distances at every sample (empty when not asked for).
    pub distances: Vec<DistanceSample>,
    /// Smallest environment distance over the samples, and its time.
    pub min_environment: Option<(f64, PairDistance)>,
    /// Smallest self distance over the samples, and its time.
    pub min_self: Option<(f64, PairDistance)>,
    /// Configurations placed (samples, sub-steps and bisection steps).
    pub configurations_checked: usize,
}

fn lerp_into(out: &mut [f64], a: &[f64], b: &[f64], u: f64) {
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        *o = x + u * (y - x);
    }
}

fn keep_min(slot: &mut Option<(f64, PairDistance)>, t: f64, d: Option<PairDistance>) {
    if let Some(d) = d {
        if slot.is_none_or(|(_, m)| d.distance < m.distance) {
            *slot = Some((t, d));
        }
    }
}

impl CollisionModel {
    /// Places the interpolated configuration `u ∈ [0, 1]` of segment `(a, b)` and tests it.
    fn collides_at(
        &self,
        model: &Model,
        cd: &mut CollisionData,
        a: &[f64],
        b: &[f64],
        u: f64,
        scope: Scope,
    ) -> bool {
        let mut q = std::mem::take(&mut cd.q);
        lerp_into(&mut q, a, b, u);
        self.update(model, cd, &q);
        cd.q = q;
        self.first_collision(cd, scope).is_some()
    }

    /// Checks a sampled trajectory (see the module docs): `times` strictly increasing,
    /// `qs[k]` the configuration at `times[k]`.
    pub fn check_trajectory<Q: AsRef<[f64]>>(
        &self,
        model: &Model,
        cd: &mut CollisionData,
        times: &[f64],
        qs: &[Q],
        opts: &TrajectoryOptions,
    ) -> Result<TrajectoryReport, CollisionError> {
        check_inputs(model, times, qs, opts)?;
        let scope = opts.scope;
        let mut report = TrajectoryReport::default();
        if opts.distances {
            report.distances.reserve(times.len());
        }
        let mut checked = 0usize;
        for k in 0..times.len() {
            let qk = qs[k].as_ref();
            if report.first_collision.is_none() {
                let qp = (k > 0).then(|| qs[k - 1].as_ref());
                let bracket = self.first_bracket(model, cd, qp, qk, opts, &mut checked);
                if let Some(bracket) = bracket {
                    let segment = qp.map(|q_prev| Segment {
                        q_prev,
                        t_prev: times[k - 1],
                        bracket,
                    });
                    let hit = self.locate_collision(
                        model,
                        cd,
                        segment,
                        (qk, times[k], k),
                        opts,
                        &mut checked,
                    );
                    report.first_collision = Some(hit);
                    // Back to the sample for the distances below.
                    self.update(model, cd, qk);
                }
            } else if opts.distances {
                self.update(model, cd, qk);
                checked += 1;
            }
            if opts.distances {
                self.record_distances(cd, scope, times[k], &mut report);
            }
            if report.first_collision.is_some() && !opts.distances {
                break;
            }
        }
        report.configurations_checked = checked;
        Ok(report)
    }

    /// The first sub-interval `(lo, hi)` of segment `qp → qk` (in its parameter `u`) whose
    /// end collides: the sub-steps of at most `max_step`, then the sample `qk` itself
    /// (which is then placed). `None` when all are free.
    fn first_bracket(
        &self,
        model: &Model,
        cd: &mut CollisionData,
        qp: Option<&[f64]>,
        qk: &[f64],
        opts: &TrajectoryOptions,
        checked: &mut usize,
    ) -> Option<(f64, f64)> {
        let scope = opts.scope;
        let mut lo = 0.0;
        if let (Some(qp), Some(h)) = (qp, opts.max_step) {
            let dq = qp
                .iter()
                .zip(qk)
                .map(|(a, b)| (b - a).abs())
                .fold(0.0, f64::max);
            let m = (dq / h).ceil().max(1.0) as usize;
            for s in 1..m {
                let u = s as f64 / m as f64;
                *checked += 1;
                if self.collides_at(model, cd, qp, qk, u, scope) {
                    return Some((lo, u));
                }
                lo = u;
            }
        }
        self.update(model, cd, qk);
        *checked += 1;
        self.first_collision(cd, scope).map(|_| (lo, 1.0))
    }

    /// The first collision of sample `(qk, t_k, k)`: bisected to the time tolerance
    /// within the bracket of the segment that ends there (`None` for the first sample,
    /// which collides as it is), with every colliding pair there.
    fn locate_collision(
        &self,
        model: &Model,
        cd: &mut CollisionData,
        segment: Option<Segment>,
        (qk, t_k, k): (&[f64], f64, usize),
        opts: &TrajectoryOptions,
        checked: &mut usize,
    ) -> TrajectoryCollision {
        let scope = opts.scope;
        let (time, last_free, q) = match segment {
            None => (t_k, None, qk.to_vec()),
            Some(Segment {
                q_prev: qp,
                t_prev,
                bracket: (mut lo, mut hi),
            }) => {
                let dt = t_k - t_prev;
                while (hi - lo) * dt > opts.time_tolerance {
                    let mid = 0.5 * (lo + hi);
                    *checked += 1;
                    if self.collides_at(model, cd, qp, qk, mid, scope) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let mut q = vec![0.0; model.nv];
                lerp_into(&mut q, qp, qk, hi);
                (t_prev + hi * dt, Some(t_prev + lo * dt), q)
            }
        };
        self.update(model, cd, &q);
        let mut pairs = Vec::new();
        self.collisions(cd, scope, &mut pairs);
        let first = pairs
            .first()
            .map_or((Body::Link(0), Body::Link(0)), |p| (p.a, p.b));
        TrajectoryCollision {
            time,
            last_free,
            sample: k,
            names: (
                self.body_name(first.0).to_string(),
                self.body_name(first.1).to_string(),
            ),
            pairs,
            q,
        }
    }

    /// The minimum distances of the placed sample at `time` (those of `scope`), kept in
    /// the per-sample list and the running minima.
    fn record_distances(
        &self,
        cd: &mut CollisionData,
        scope: Scope,
        time: f64,
        report: &mut TrajectoryReport,
    ) {
        let env = if scope == Scope::SelfCollision {
            None
        } else {
            self.min_distance(cd, Scope::Environment)
        };
        let slf = if scope == Scope::Environment {
            None
        } else {
            self.min_distance(cd, Scope::SelfCollision)
        };
        keep_min(&mut report.min_environment, time, env);
        keep_min(&mut report.min_self, time, slf);
        report.distances.push(DistanceSample {
            time,
            environment: env,
            self_collision: slf,
        });
    }
}

/// The segment from the previous sample, and the bracket `(lo, hi)` of its parameter
/// whose end collides.
struct Segment<'a> {
    q_prev: &'a [f64],
    t_prev: f64,
    bracket: (f64, f64),
}

/// Times and configurations of the same non-zero count, configurations of the model's
/// size, everything finite, times strictly increasing, and valid options.
fn check_inputs<Q: AsRef<[f64]>>(
    model: &Model,
    times: &[f64],
    qs: &[Q],
    opts: &TrajectoryOptions,
) -> Result<(), CollisionError> {
    let bad = CollisionError::Trajectory;
    if times.is_empty() || times.len() != qs.len() {
        return Err(bad(format!(
            "{} times and {} configurations (need the same number, at least one)",
            times.len(),
            qs.len()
        )));
    }
    for (k, q) in qs.iter().enumerate() {
        let q = q.as_ref();
        if q.len() != model.nv {
            return Err(bad(format!(
                "sample {k}: {} joint values, the model has {}",
                q.len(),
                model.nv
            )));
        }
        if q.iter().any(|x| !x.is_finite()) || !times[k].is_finite() {
            return Err(bad(format!("sample {k}: non-finite value")));
        }
        if k > 0 && times[k] <= times[k - 1] {
            return Err(bad(format!(
                "sample {k}: time {} does not increase (previous {})",
                times[k],
                times[k - 1]
            )));
        }
    }
    if !(opts.time_tolerance.is_finite() && opts.time_tolerance > 0.0) {
        return Err(bad(format!(
            "time_tolerance must be finite and positive, got {}",
            opts.time_tolerance
        )));
    }
    if let Some(h) = opts.max_step {
        if !(h.is_finite() && h > 0.0) {
            return Err(bad(format!(
                "max_step must be finite and positive, got {h}"
            )));
        }
    }
    Ok(())
}
