//! The collision check of a planned scenario motion, with the grasped part on the tool
//! between its attach and detach times, and the planned tool path for the recording.
//!
//! The motion is sampled every 10 ms (50 to 20 000 samples) and checked with the parry
//! scene ([`CollisionModel::check_trajectory`]: continuous between samples, bisecting to
//! the first contact). With a part, the samples inside `[attach, detach]` are checked with
//! a second scene whose model carries the part as a box on the tool link
//! ([`super::planned::with_part`]); the reports are merged (first collision in time, the
//! smallest distances, configurations summed).

use super::plan::Plan;
use super::planned::with_part;
use super::scene::Scene;
use crate::collision::{
    CollisionData, CollisionModel, CollisionOptions, Scope, TrajectoryOptions, TrajectoryReport,
};
use crate::data::Data;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::Model;
use crate::recording::PointCloud;
use crate::trajectory::Trajectory;
use serde_json::{json, Map, Value};

fn named(names: &[String], v: &[f64]) -> Value {
    Value::Object(
        names
            .iter()
            .zip(v)
            .map(|(n, x)| (n.clone(), json!(x)))
            .collect::<Map<_, _>>(),
    )
}

/// One scene's check of the samples `range`.
fn check_range(
    model: &Model,
    cm: &CollisionModel,
    times: &[f64],
    qs: &[Vec<f64>],
    range: std::ops::Range<usize>,
    opts: &TrajectoryOptions,
) -> Result<TrajectoryReport, String> {
    let mut cd = CollisionData::new(model, cm);
    cm.check_trajectory(model, &mut cd, &times[range.clone()], &qs[range], opts)
        .map_err(|e| e.to_string())
}

/// Merges `b` (later in time) into `a`.
fn merge(a: &mut TrajectoryReport, b: TrajectoryReport) {
    if a.first_collision.is_none() {
        a.first_collision = b.first_collision;
    }
    let keep = |x: &mut Option<(f64, crate::collision::PairDistance)>, y| {
        if let Some((t, d)) = y {
            let d: crate::collision::PairDistance = d;
            if x.as_ref().is_none_or(|(_, m)| d.distance < m.distance) {
                *x = Some((t, d));
            }
        }
    };
    keep(&mut a.min_environment, b.min_environment);
    keep(&mut a.min_self, b.min_self);
    a.configurations_checked += b.configurations_checked;
}

/// The collision check of `plan` (the report's `collisions` JSON); `warnings` gets the
/// scene's building warnings.
pub fn check_collisions(
    scene: &Scene,
    plan: &Plan,
    copts: &CollisionOptions,
    warnings: &mut Vec<String>,
) -> Result<Value, String> {
    let model = &scene.model;
    let n = model.nv;
    let names = model.dof_names();
    let traj = &plan.trajectory;
    let duration = traj.duration();
    let cm =
        CollisionModel::from_specs(model, &scene.obstacles, copts).map_err(|e| e.to_string())?;
    warnings.extend(cm.warnings().iter().cloned());
    let k = ((duration / 0.01).ceil() as usize).clamp(50, 20_000);
    let mut times: Vec<f64> = (0..=k).map(|i| duration * i as f64 / k as f64).collect();
    // The attach and detach instants are samples, so each scene checks its own interval.
    if let Some((a, b)) = plan.carry {
        times.extend([a, b]);
        times.sort_by(f64::total_cmp);
        times.dedup();
    }
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let qs: Vec<Vec<f64>> = times
        .iter()
        .map(|&t| {
            traj.sample(t, &mut q, &mut qd, &mut qdd);
            q.clone()
        })
        .collect();
    let scope = if scene.self_collision {
        Scope::All
    } else {
        Scope::Environment
    };
    let topts = TrajectoryOptions {
        scope,
        time_tolerance: 1e-4,
        max_step: Some(scene.collision_max_step),
        distances: true,
    };
    let end = times.len();
    let (rep, carried) = match (plan.carry, &scene.part) {
        (Some((a, b)), Some(part)) => {
            let ia = times.iter().position(|&t| t == a).expect("inserted");
            let ib = times.iter().position(|&t| t == b).expect("inserted");
            let pm = with_part(model, scene.tool, part);
            let cp = CollisionModel::from_specs(&pm, &scene.obstacles, copts)
                .map_err(|e| e.to_string())?;
            let mut rep = check_range(model, &cm, &times, &qs, 0..ia + 1, &topts)?;
            merge(
                &mut rep,
                check_range(&pm, &cp, &times, &qs, ia..ib + 1, &topts)?,
            );
            merge(
                &mut rep,
                check_range(model, &cm, &times, &qs, ib..end, &topts)?,
            );
            (rep, Some([a, b]))
        }
        _ => (check_range(model, &cm, &times, &qs, 0..end, &topts)?, None),
    };
    let pd = |t: f64, p: &crate::collision::PairDistance| {
        json!({
            "time": t,
            "pair": [cm.body_name(p.a), cm.body_name(p.b)],
            "distance": p.distance,
        })
    };
    Ok(json!({
        "checked": true,
        "collision_free": rep.first_collision.is_none(),
        "first": rep.first_collision.as_ref().map(|c| json!({
            "time": c.time,
            "last_free": c.last_free,
            "pair": [c.names.0, c.names.1],
            "depth": c.pairs.first().map(|p| -p.distance),
            "pairs": c.pairs.iter().map(|p| json!([cm.body_name(p.a), cm.body_name(p.b), p.distance])).collect::<Vec<_>>(),
            "q": named(&names, &c.q),
        })),
        "min_environment": rep.min_environment.as_ref().map(|(t, p)| pd(*t, p)),
        "min_self": rep.min_self.as_ref().map(|(t, p)| pd(*t, p)),
        "pairs_tested": cm.tested_pairs(scope).len(),
        "configurations_checked": rep.configurations_checked,
        "unprotected_links": cm.unprotected_links(),
        "part_checked_s": carried,
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
