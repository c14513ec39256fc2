//! Step 6 of a run: the report, as the JSON document (`armsim run --json`, the
//! `<name>.json` file) and the human summary.

use crate::motion::{TorqueReport, Trajectory};
use crate::scenarios::arm::checks::named;
use crate::scenarios::arm::contact::ContactReport;
use crate::scenarios::arm::run::write_outputs::OutputContext;
use crate::scenarios::arm::scene::{Scene, Timing};
use crate::scenarios::arm::task_motion::Plan;
use serde_json::{json, Map, Value};
use std::fmt::Write as _;

/// The report's parts that the earlier steps gathered.
pub(super) struct Parts<'a> {
    pub sweep: &'a [(f64, TorqueReport)],
    pub contact_report: &'a Option<ContactReport>,
    pub contact_built: bool,
    pub timings: Map<String, Value>,
    pub warnings: Vec<String>,
    pub outputs: Vec<String>,
}

/// The report JSON.
pub(super) fn report_json(cx: &OutputContext, p: Parts) -> Value {
    let OutputContext {
        scene,
        plan,
        torque,
        collisions,
        sim_json,
        ..
    } = *cx;
    let Parts {
        sweep,
        contact_report,
        contact_built,
        timings,
        warnings,
        outputs,
    } = p;
    let model = &scene.model;
    let names = model.dof_names();
    let n = model.nv;
    let duration = plan.trajectory.duration();
    let sweep_json: Vec<Value> = sweep
    .iter()
    .map(|(m, r)| {
        let worst = r
            .joints
            .iter()
            .min_by(|a, b| a.margin.total_cmp(&b.margin))
            .expect("joints");
        json!({
            "payload_mass": m,
            "ok": r.ok,
            "worst_joint": worst.joint,
            "worst_margin": worst.margin,
            "first_violation_s": r.joints.iter().filter_map(|j| j.first_violation_s).reduce(f64::min),
            "peak_torque": named(&names, &r.joints.iter().map(|j| j.peak_torque).collect::<Vec<_>>()),
        })
    })
    .collect();
    let collision_free = collisions
        .get("collision_free")
        .and_then(Value::as_bool)
        .unwrap_or(true);
    let ok = torque.ok && collision_free;
    let mut j = json!({
        "scenario": scene.name,
        "file": scene.file,
        "description": scene.description,
        "model": {
            "file": scene.model_path.display().to_string(),
            "name": model.name,
            "dof": n,
            "joints": names,
            "tool": model.links[scene.tool].name,
            "base_xyz": [scene.base.trans.x, scene.base.trans.y, scene.base.trans.z],
        },
        "effects": scene.effect_names,
        "plan": {
            "task": scene.task_kind,
            "trajectory": scene.timing.as_str(),
            "duration_s": duration,
            "pieces": plan.pieces,
            "ik_solves": plan.ik_solves,
            "planner": plan.planner,
            "part_carried_s": plan.carry.map(|(a, b)| [a, b]),
            "timed_paths": plan.timed_paths,
        },
        "torque_check": torque.json_rows(),
        "torque_check_ok": torque.ok,
        "torque_check_dt": torque.dt,
        "torque_check_note": scene.contact.is_some().then_some(
            "the planned torques do not include the contact forces (unknown before simulating): see simulation.peak_applied_torque"),
        "payload_sweep": if sweep_json.is_empty() { Value::Null } else { Value::Array(sweep_json) },
        "collisions": collisions,
        "contact": contact_report.as_ref().map(|c| serde_json::to_value(c).expect("serialise")),
        "contact_pipeline_built": contact_built,
        "simulation": sim_json,
        "ok": ok,
        "timings": timings,
        "warnings": warnings,
        "outputs": outputs,
    });
    if !scene.transmissions.is_empty() {
        j["transmissions"] = serde_json::to_value(&scene.transmissions).expect("serialise");
    }
    j
}

pub(super) fn summary(scene: &Scene, plan: &Plan, torque: &TorqueReport, j: &Value) -> String {
    let mut s = String::new();
    summary_plan(&mut s, scene, plan, torque, j);
    summary_collisions(&mut s, j);
    summary_simulation(&mut s, j);
    summary_rest(&mut s, torque, j);
    s
}

/// The scenario, the plan and the torque check (with the payload sweep).
fn summary_plan(s: &mut String, scene: &Scene, plan: &Plan, torque: &TorqueReport, j: &Value) {
    let model = &scene.model;
    let _ = writeln!(s, "scenario {} ({})", scene.name, scene.file);
    if let Some(d) = &scene.description {
        let _ = writeln!(s, "  {d}");
    }
    let _ = writeln!(
        s,
        "model: {} ({} joints, tool {}); effects: {}",
        scene.model_path.display(),
        model.nv,
        model.links[scene.tool].name,
        if scene.effect_names.is_empty() {
            "none (rigid bodies only)".to_string()
        } else {
            scene.effect_names.join(", ")
        }
    );
    let _ = writeln!(
        s,
        "plan: {} timed {}, {} pieces, {:.3} s (planned in {:.1} ms, {} IK solves)",
        scene.task_kind,
        scene.timing.as_str(),
        plan.pieces.len(),
        plan.trajectory.duration(),
        plan.planning_time_s * 1e3,
        plan.ik_solves
    );
    if scene.timing == Timing::TimeOptimal {
        let _ = writeln!(
            s,
            "  (time-optimal under the velocity, acceleration and torque limits)"
        );
    }
    let _ = writeln!(s);
    s.push_str(&torque.table());
    if let Some(Value::Array(sw)) = j.get("payload_sweep") {
        let _ = writeln!(s, "\npayload sweep:");
        for r in sw {
            let _ = writeln!(
                s,
                "  {:>8.3} kg: {} (worst {} margin {:.1} %{})",
                r["payload_mass"].as_f64().unwrap_or(f64::NAN),
                if r["ok"].as_bool() == Some(true) {
                    "ok"
                } else {
                    "LIMITS EXCEEDED"
                },
                r["worst_joint"].as_str().unwrap_or("-"),
                r["worst_margin"].as_f64().unwrap_or(f64::NAN),
                r["first_violation_s"]
                    .as_f64()
                    .map_or(String::new(), |t| format!(", first violation at {t:.3} s"))
            );
        }
        let first_bad = sw.iter().find(|r| r["ok"].as_bool() == Some(false));
        if let Some(r) = first_bad {
            let _ = writeln!(
                s,
                "  the joints are overloaded from {} kg on",
                r["payload_mass"].as_f64().unwrap_or(f64::NAN)
            );
        }
    }
}

/// The collision check.
fn summary_collisions(s: &mut String, j: &Value) {
    let c = &j["collisions"];
    let _ = writeln!(s);
    if c["checked"].as_bool() == Some(true) {
        match c.get("first").filter(|f| !f.is_null()) {
            Some(f) => {
                let _ = writeln!(
                    s,
                    "collisions: FIRST COLLISION at t = {:.4} s between {} and {} (depth {:.4} m)",
                    f["time"].as_f64().unwrap_or(f64::NAN),
                    f["pair"][0].as_str().unwrap_or("?"),
                    f["pair"][1].as_str().unwrap_or("?"),
                    f["depth"].as_f64().unwrap_or(f64::NAN)
                );
            }
            None => {
                let _ = writeln!(s, "collisions: none along the motion");
            }
        }
        for (key, what) in [
            ("min_environment", "closest to the environment"),
            ("min_self", "closest to itself"),
        ] {
            if let Some(m) = c.get(key).filter(|m| !m.is_null()) {
                let _ = writeln!(
                    s,
                    "  {what}: {} - {} at {:.4} m (t = {:.3} s)",
                    m["pair"][0].as_str().unwrap_or("?"),
                    m["pair"][1].as_str().unwrap_or("?"),
                    m["distance"].as_f64().unwrap_or(f64::NAN),
                    m["time"].as_f64().unwrap_or(f64::NAN)
                );
            }
        }
        let _ = writeln!(
            s,
            "  {} pairs, {} configurations checked",
            c["pairs_tested"], c["configurations_checked"]
        );
        if let Some(u) = c["unprotected_links"].as_array().filter(|u| !u.is_empty()) {
            let _ = writeln!(
                s,
                "  WARNING: {} link(s) have no collision shape and are not checked (set collision.skeleton_radius)",
                u.len()
            );
        }
    } else {
        let _ = writeln!(s, "collisions: not checked ([collision] enabled = false)");
    }
}

/// The simulation: tracking, vibration, energy audit.
fn summary_simulation(s: &mut String, j: &Value) {
    let sim = &j["simulation"];
    if !sim.is_null() {
        let _ = writeln!(
            s,
            "\nsimulation: {} with {}, step {:e} s, {} steps, {:.3} s simulated in {:.3} s (real-time factor {:.1}){}",
            sim["integrator"].as_str().unwrap_or("?"),
            sim["controller"].as_str().unwrap_or("?"),
            sim["dt"].as_f64().unwrap_or(f64::NAN),
            sim["steps"],
            sim["sim_time_s"].as_f64().unwrap_or(f64::NAN),
            sim["wall_time_s"].as_f64().unwrap_or(f64::NAN),
            sim["real_time_factor"].as_f64().unwrap_or(f64::NAN),
            if sim["interrupted"].as_bool() == Some(true) { " INTERRUPTED" } else { "" }
        );
        let _ = writeln!(
            s,
            "  tool tracking error: max {:.3e} m, after the motion {:.3e} m",
            sim["max_tool_error_m"].as_f64().unwrap_or(f64::NAN),
            sim["residual_tool_error_m"].as_f64().unwrap_or(f64::NAN)
        );
        if let Some(f) = sim["residual_vibration_hz"].as_f64() {
            let _ = writeln!(s, "  residual vibration at {f:.2} Hz");
        }
        if let Some(nf) = sim["natural_frequency_hz"].as_object() {
            let list: Vec<String> = nf
                .iter()
                .map(|(k, v)| format!("{k} {:.1}", v.as_f64().unwrap_or(f64::NAN)))
                .collect();
            let _ = writeln!(
                s,
                "  joint-spring natural frequencies (Hz): {}",
                list.join(", ")
            );
        }
        match sim["energy_audit"].as_object() {
            Some(e) => {
                let _ = writeln!(
                    s,
                    "  energy audit: max |E - E0 - W| = {:.3e} J ({:.2e} relative)",
                    e["max_drift_j"].as_f64().unwrap_or(f64::NAN),
                    e["max_relative_drift"].as_f64().unwrap_or(f64::NAN)
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "  energy audit: skipped (the scene dissipates or is driven from outside)"
                );
            }
        }
        let runs = &sim["effect_runs"];
        let ran: Vec<String> = runs
            .as_object()
            .map(|m| {
                m.iter()
                    .filter(|(_, v)| v.as_u64() != Some(0))
                    .map(|(k, v)| format!("{k} x{v}"))
                    .collect()
            })
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "  effect code run: {}",
            if ran.is_empty() {
                "none".to_string()
            } else {
                ran.join(", ")
            }
        );
    }
}

/// The contact scene, the verdict, warnings, files and timings.
fn summary_rest(s: &mut String, torque: &TorqueReport, j: &Value) {
    if let Some(c) = j.get("contact").filter(|c| !c.is_null()) {
        let _ = writeln!(
            s,
            "\ncontact (rapier3d): box moved {:.4} m, top speed {:.3} m/s, peak push {:.2} N, sliding push {} N vs Coulomb mu m g = {:.2} N, in contact {:.3} s from t = {}",
            c["box_displacement_m"].as_f64().unwrap_or(f64::NAN),
            c["box_max_speed"].as_f64().unwrap_or(f64::NAN),
            c["max_contact_force_n"].as_f64().unwrap_or(f64::NAN),
            c["sliding_force_n"].as_f64().map_or("-".into(), |f| format!("{f:.2}")),
            c["coulomb_force_n"].as_f64().unwrap_or(f64::NAN),
            c["contact_time_s"].as_f64().unwrap_or(f64::NAN),
            c["first_contact_s"].as_f64().map_or("-".into(), |t| format!("{t:.3} s")),
        );
    }
    let _ = writeln!(
        s,
        "\nverdict: {}",
        match (
            torque.ok,
            j["collisions"]["collision_free"].as_bool() != Some(false)
        ) {
            (true, true) => "OK: the joints can deliver the motion and nothing collides",
            (false, true) => "NOT OK: joint limits exceeded",
            (true, false) => "NOT OK: collision",
            (false, false) => "NOT OK: joint limits exceeded and collision",
        }
    );
    if let Some(w) = j["warnings"].as_array().filter(|w| !w.is_empty()) {
        let _ = writeln!(s, "warnings:");
        for x in w {
            let _ = writeln!(s, "  {}", x.as_str().unwrap_or(""));
        }
    }
    if let Some(o) = j["outputs"].as_array().filter(|o| !o.is_empty()) {
        let _ = writeln!(s, "outputs:");
        for x in o {
            let _ = writeln!(s, "  {}", x.as_str().unwrap_or(""));
        }
    }
    if let Some(t) = j["timings"].as_object() {
        let list: Vec<String> = t
            .iter()
            .map(|(k, v)| {
                format!(
                    "{} {:.1} ms",
                    k.trim_end_matches("_s"),
                    v.as_f64().unwrap_or(0.0) * 1e3
                )
            })
            .collect();
        let _ = writeln!(s, "timings: {}", list.join(", "));
    }
}
