//! The collision check of a planned scenario motion, with the grasped part on the tool
//! between its attach and detach times, its certificate, and the planned tool path for
//! the recording.
//!
//! - **Limits pass** ([`limits_pass`]): the motion sampled densely (the torque check's
//!   step) for the worst margin of every limit — position, velocity, acceleration, jerk
//!   when a jerk limit is set, torque from the torque check — each with its value, limit,
//!   joint and time; and the per-joint acceleration bound the collision certificate rests
//!   on: `1.25 ×` the largest `|q̈|` found, and at least the acceleration limit (the 25 %
//!   covers what `q̈` may do between two dense samples).
//! - **Collisions** ([`check_collisions`]): the motion is sampled every 10 ms (50 to
//!   20 000 samples) and certified continuously between samples with the parry scene
//!   ([`crate::collision::Certifier`]: the joint path length over each half-interval
//!   bounded from the sampled velocities and the acceleration bound, turned into a
//!   per-pair displacement bound; bounding volumes, then convex hulls, then exact meshes
//!   only near contact; bisection where the samples cannot prove an interval). With a
//!   part, the samples inside `[attach, detach]` are certified with a second scene whose
//!   model carries the part as a box on the tool link
//!   ([`crate::scenarios::arm::planner_setup::with_part`]); the results are merged (first collision
//!   in time, the smallest distances, counts summed). The minimum distances are the exact ones over
//!   the samples.

use crate::collision::{
    Certificate, CertifiedMotion, Certifier, CertifyOptions, ClearanceBound, CollisionData,
    CollisionModel, CollisionOptions, SampleMin, Scope,
};
use crate::io::record::PointCloud;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::Model;
use crate::motion::{TorqueReport, Trajectory};
use crate::scenarios::arm::planner_setup::with_part;
use crate::scenarios::arm::scene::Scene;
use crate::scenarios::arm::task_motion::Plan;
use serde_json::{json, Map, Value};
use std::cell::RefCell;

/// The per-joint values `v` as a JSON object keyed by joint name.
pub(crate) fn named(names: &[String], v: &[f64]) -> Value {
    Value::Object(
        names
            .iter()
            .zip(v)
            .map(|(n, x)| (n.clone(), json!(x)))
            .collect::<Map<_, _>>(),
    )
}

/// The optional per-joint jerk limit of the scene (`[limits] jerk`, rad/s³ or m/s³).
pub fn jerk_limit(scene: &Scene) -> Option<&[f64]> {
    scene.limits.jerk.as_deref()
}

/// The worst margin of one limit: `limit − |value|` (or the distance to the nearer
/// position bound), with where it occurs.
#[derive(Clone, Debug)]
struct Worst {
    margin: f64,
    value: f64,
    limit: f64,
    joint: usize,
    time: f64,
}

impl Worst {
    fn new() -> Self {
        Worst {
            margin: f64::INFINITY,
            value: f64::NAN,
            limit: f64::NAN,
            joint: 0,
            time: f64::NAN,
        }
    }

    fn see(&mut self, margin: f64, value: f64, limit: f64, joint: usize, time: f64) {
        if margin < self.margin {
            *self = Worst {
                margin,
                value,
                limit,
                joint,
                time,
            };
        }
    }

    fn json(&self, names: &[String]) -> Value {
        json!({
            "margin": self.margin,
            "value": self.value,
            "limit": self.limit,
            "joint": names[self.joint],
            "time": self.time,
            "ok": self.margin >= 0.0,
        })
    }
}

/// The dense limits pass (see the module docs): the per-joint acceleration bound of the
/// collision certificate and the limits part of the certificate (JSON).
pub fn limits_pass(
    scene: &Scene,
    plan: &Plan,
    torque: &TorqueReport,
    jerk: Option<&[f64]>,
) -> (Vec<f64>, Value) {
    let model = &scene.model;
    let (n, names) = (model.nv, model.dof_names());
    let traj = &plan.trajectory;
    let duration = traj.duration();
    let steps = ((duration / scene.check_dt).ceil() as usize).max(1);
    let (mut q, mut qd, mut qdd, mut prev) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut pos, mut vel, mut acc, mut jrk) =
        (Worst::new(), Worst::new(), Worst::new(), Worst::new());
    let mut peak = vec![0.0f64; n];
    let lim = &scene.limits;
    for i in 0..=steps {
        let t = duration * i as f64 / steps as f64;
        traj.sample(t, &mut q, &mut qd, &mut qdd);
        for j in 0..n {
            let (lo, hi) = (scene.lower[j], scene.upper[j]);
            let (m, l) = if q[j] - lo < hi - q[j] {
                (q[j] - lo, lo)
            } else {
                (hi - q[j], hi)
            };
            pos.see(m, q[j], l, j, t);
            vel.see(
                scene.check_velocity[j] - qd[j].abs(),
                qd[j],
                scene.check_velocity[j],
                j,
                t,
            );
            acc.see(
                lim.acceleration[j] - qdd[j].abs(),
                qdd[j],
                lim.acceleration[j],
                j,
                t,
            );
            peak[j] = peak[j].max(qdd[j].abs());
            if let (Some(jl), true) = (jerk, i > 0) {
                let x = (qdd[j] - prev[j]) * steps as f64 / duration;
                jrk.see(jl[j] - x.abs(), x, jl[j], j, t);
            }
        }
        prev.copy_from_slice(&qdd);
    }
    let mut tq = Worst::new();
    for (j, row) in torque.joints.iter().enumerate() {
        tq.see(
            row.limit - row.peak_torque,
            row.peak_torque,
            row.limit,
            j,
            row.peak_torque_time_s,
        );
    }
    let bound: Vec<f64> = peak
        .iter()
        .zip(&lim.acceleration)
        .map(|(p, a)| (1.25 * p).max(*a))
        .collect();
    let ok = [&pos, &vel, &acc, &tq].iter().all(|w| w.margin >= 0.0)
        && (jerk.is_none() || jrk.margin >= 0.0);
    let jerk = jerk.map(|_| jrk.json(&names));
    let limits = json!({
        "sampled_every_s": duration / steps as f64,
        "position": pos.json(&names),
        "velocity": vel.json(&names),
        "acceleration": acc.json(&names),
        "jerk": jerk,
        "torque": tq.json(&names),
        "ok": ok,
    });
    (bound, limits)
}

/// One scene's certificate of the samples `range`.
fn certify_range(
    model: &Model,
    cm: &CollisionModel,
    certifier: &Certifier,
    traj: &dyn Trajectory,
    times: &[f64],
    accel_bound: &[f64],
) -> Result<Certificate, String> {
    let mut cd = CollisionData::new(model, cm);
    let qdd = RefCell::new(vec![0.0; model.nv]);
    let sample =
        |t: f64, q: &mut [f64], qd: &mut [f64]| traj.sample(t, q, qd, &mut qdd.borrow_mut());
    let motion = CertifiedMotion {
        times,
        sample: &sample,
        accel_bound,
    };
    let opts = CertifyOptions {
        min_interval: 1e-7,
        time_tolerance: 1e-4,
    };
    certifier
        .certify(cm, model, &mut cd, &motion, &opts)
        .map_err(|e| e.to_string())
}

/// Merges `b` (later in time) into `a`.
fn merge(a: &mut Certificate, b: Certificate) {
    a.collision_free &= b.collision_free;
    if a.first_collision.is_none() {
        a.first_collision = b.first_collision;
    }
    if a.uncertified.is_none() {
        a.uncertified = b.uncertified;
    }
    a.intervals += b.intervals;
    a.subdivisions += b.subdivisions;
    a.configurations += b.configurations;
    a.evaluations.spheres += b.evaluations.spheres;
    a.evaluations.hulls += b.evaluations.hulls;
    a.evaluations.exact += b.evaluations.exact;
    let keep = |x: &mut Option<SampleMin>, y: Option<SampleMin>| {
        if let Some(y) = y {
            if x.as_ref().is_none_or(|m| y.pair.distance < m.pair.distance) {
                *x = Some(y);
            }
        }
    };
    keep(&mut a.min_environment, b.min_environment);
    keep(&mut a.min_self, b.min_self);
    let low = |x: &mut Option<ClearanceBound>, y: Option<ClearanceBound>| {
        if let Some(y) = y {
            if x.as_ref().is_none_or(|m| y.distance < m.distance) {
                *x = Some(y);
            }
        }
    };
    low(&mut a.clearance_environment, b.clearance_environment);
    low(&mut a.clearance_self, b.clearance_self);
}

/// The collision check of `plan` (the report's `collisions` JSON, its `certificate` without
/// the limits), certified with the per-joint acceleration bound `accel_bound`; `warnings`
/// gets the scene's building warnings.
pub fn check_collisions(
    scene: &Scene,
    plan: &Plan,
    copts: &CollisionOptions,
    accel_bound: &[f64],
    warnings: &mut Vec<String>,
) -> Result<Value, String> {
    let model = &scene.model;
    let names = model.dof_names();
    let traj = &plan.trajectory;
    let duration = traj.duration();
    // With a part, the scene of the arm carrying it too (the meshes loaded once).
    let pm = scene.part.as_ref().map(|p| with_part(model, scene.tool, p));
    let mut scenes = CollisionModel::from_specs_for(
        &[Some(model), pm.as_ref()]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>(),
        &scene.obstacles,
        copts,
    )
    .map_err(|e| e.to_string())?;
    let cp = (scenes.len() > 1).then(|| scenes.pop().expect("two"));
    let cm = scenes.pop().expect("one");
    warnings.extend(cm.warnings().iter().cloned());
    let k = ((duration / 0.01).ceil() as usize).clamp(50, 20_000);
    let mut times: Vec<f64> = (0..=k).map(|i| duration * i as f64 / k as f64).collect();
    // The attach and detach instants are samples, so each scene checks its own interval.
    if let Some((a, b)) = plan.carry {
        times.extend([a, b]);
        times.sort_by(f64::total_cmp);
        times.dedup();
    }
    let scope = if scene.self_collision {
        Scope::All
    } else {
        Scope::Environment
    };
    let end = times.len();
    let ab = accel_bound;
    let bare = cm.certifier(model, scope);
    let (cert, carried) = match (plan.carry, &pm, &cp) {
        (Some((a, b)), Some(pm), Some(cp)) => {
            let ia = times.iter().position(|&t| t == a).expect("inserted");
            let ib = times.iter().position(|&t| t == b).expect("inserted");
            let carrying = cp.certifier(pm, scope);
            let mut c = certify_range(model, &cm, &bare, traj, &times[..=ia], ab)?;
            let during = certify_range(pm, cp, &carrying, traj, &times[ia..=ib], ab)?;
            merge(&mut c, during);
            let after = certify_range(model, &cm, &bare, traj, &times[ib..end], ab)?;
            merge(&mut c, after);
            (c, Some([a, b]))
        }
        _ => (certify_range(model, &cm, &bare, traj, &times, ab)?, None),
    };
    // Body names are the same in both scenes (the part rides on the tool link).
    let pair = |a, b| json!([cm.body_name(a), cm.body_name(b)]);
    let pd = |m: &SampleMin| {
        json!({
            "time": m.time,
            "pair": pair(m.pair.a, m.pair.b),
            "distance": m.pair.distance,
            "points": [m.pair.point_a, m.pair.point_b],
            "q": named(&names, &m.q),
        })
    };
    let bound = |c: &ClearanceBound| json!({"lower_bound": c.distance, "from": c.from, "to": c.to, "pair": pair(c.a, c.b)});
    let smallest = [&cert.min_environment, &cert.min_self]
        .into_iter()
        .flatten()
        .min_by(|x, y| x.pair.distance.total_cmp(&y.pair.distance));
    let uncertified = cert
        .uncertified
        .map(|(a, b, x, y)| json!({"from": a, "to": b, "pair": pair(x, y)}));
    let certificate = json!({
        "method": "continuous along the timed curve: per half-interval joint path length bounded from the sampled velocities and the acceleration bound, times per-pair motion coefficients; bounding spheres and boxes, then convex hulls, then exact meshes near contact; bisection where the samples cannot prove an interval",
        "collision_free_between_samples": cert.collision_free,
        "intervals": cert.intervals,
        "subdivisions": cert.subdivisions,
        "evaluations": cert.evaluations,
        "acceleration_bound": named(&names, accel_bound),
        "min_clearance": smallest.map(pd),
        "clearance_lower_bound": {
            "environment": cert.clearance_environment.as_ref().map(bound),
            "self": cert.clearance_self.as_ref().map(bound),
        },
        "uncertified": uncertified,
    });
    Ok(json!({
        "checked": true,
        "collision_free": cert.collision_free,
        "first": cert.first_collision.as_ref().map(|c| json!({
            "time": c.time,
            "last_free": c.last_free,
            "pair": [c.names.0, c.names.1],
            "depth": c.pairs.first().map(|p| -p.distance),
            "pairs": c.pairs.iter().map(|p| json!([cm.body_name(p.a), cm.body_name(p.b), p.distance])).collect::<Vec<_>>(),
            "q": named(&names, &c.q),
        })),
        "min_environment": cert.min_environment.as_ref().map(pd),
        "min_self": cert.min_self.as_ref().map(pd),
        "pairs_tested": cm.tested_pairs(scope).len(),
        "configurations_checked": cert.configurations,
        "unprotected_links": cm.unprotected_links(),
        "part_checked_s": carried,
        "certificate": certificate,
    }))
}

/// The tool positions (scene frame) along the planned pieces of `plan`, every 5 ms, with
/// their times as values: the planned path in the recording.
pub fn planned_tool_path(scene: &Scene, plan: &Plan) -> Option<PointCloud> {
    let model = &scene.model;
    let n = model.nv;
    let mut data = Data::new(model);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut cloud = PointCloud {
        t: 0.0,
        frame: "world".into(),
        points: Vec::new(),
        values: Vec::new(),
    };
    for p in plan.pieces.iter().filter(|p| p.kind == "planned") {
        let k = ((p.duration_s / 0.005).ceil() as usize).max(2);
        for i in 0..=k {
            let t = p.start_s + p.duration_s * i as f64 / k as f64;
            plan.trajectory.sample(t, &mut q, &mut qd, &mut qdd);
            forward_kinematics(model, &mut data, &q);
            let x = scene
                .base
                .act_point(&frame_placement(model, &data, scene.tool).trans);
            cloud.points.push([x.x as f32, x.y as f32, x.z as f32]);
            cloud.values.push(t as f32);
        }
    }
    (!cloud.points.is_empty()).then_some(cloud)
}
