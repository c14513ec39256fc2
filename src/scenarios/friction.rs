//! `kind = "friction"` scenario files (format in `docs/machines.md`): a list of
//! `[[element]]` tables (screw, slide, rolling, wedge, incline, journal, collar, belt,
//! band brake), and `[[connected_bodies]]` tables (bodies on planes joined by ropes,
//! read by [`crate::scenarios::friction_bodies`]),
//! each computed by [`crate::machines::friction::elements`]; torques of the elements add up, and a
//! shaft speed turns the total into a friction power.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::report::Report;
use crate::machines::friction::elements as el;
use crate::scenarios::source::{in_range, Source};
use serde::Deserialize;
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    speed_rpm: Option<f64>,
    #[serde(default)]
    element: Vec<Spanned<Element>>,
    #[serde(default)]
    connected_bodies: Vec<Spanned<crate::scenarios::friction_bodies::BodiesSpec>>,
}

#[derive(Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
struct Element {
    label: Option<String>,
    #[serde(rename = "type")]
    kind: String,
    load: Option<f64>,
    friction: Option<f64>,
    friction_faces: Option<[f64; 2]>,
    pitch: Option<f64>,
    diameters: Option<[f64; 2]>,
    thread_angle_deg: Option<f64>,
    collar_friction: Option<f64>,
    collar_diameters: Option<[f64; 2]>,
    #[serde(default)]
    new: bool,
    handle_force: Option<f64>,
    handle_length: Option<f64>,
    slide: Option<String>,
    groove_angle_deg: Option<f64>,
    wheel_diameter: Option<f64>,
    axle_diameter: Option<f64>,
    rolling_arms: Option<[f64; 2]>,
    angle_deg: Option<f64>,
    diameter: Option<f64>,
    fit_factor: Option<f64>,
    count: Option<f64>,
    power: Option<f64>,
    speed: Option<f64>,
    euler_factor: Option<f64>,
    wrap_deg: Option<f64>,
    lever_load: Option<f64>,
    lever_arm: Option<f64>,
    braking_torque: Option<f64>,
    slack_arm: Option<f64>,
    tight_arm: Option<f64>,
    drum_diameter: Option<f64>,
    load_drum_diameter: Option<f64>,
    push_angle_deg: Option<f64>,
    shoe_arm: Option<f64>,
    friction_arm: Option<f64>,
    contact_deg: Option<f64>,
    shoes: Option<f64>,
    wheel_weight: Option<f64>,
    wheels: Option<f64>,
}

/// Runs a friction scenario.
pub fn run(path: &Path, text: &str) -> Result<Report, ScenarioError> {
    let file = path.display().to_string();
    compute(&file, text)
}

/// Parses and checks (the computation is closed-form, so this is the run itself).
pub fn parse(file: &str, text: &str) -> Result<(), ScenarioError> {
    compute(file, text).map(drop)
}

fn compute(file: &str, text: &str) -> Result<Report, ScenarioError> {
    let cx = Source::new(file, text);
    let f: FileSpec = toml::from_str(text).map_err(|e| cx.toml(&e))?;
    if f.element.is_empty() && f.connected_bodies.is_empty() {
        return Err(cx.top(
            "kind",
            "a friction file needs at least one [[element]] or [[connected_bodies]] table",
        ));
    }
    if let Some(n) = f.speed_rpm {
        if !in_range(n, 0.0, 1e7) {
            return Err(cx.top("speed_rpm", "must be a speed ≥ 0"));
        }
    }
    let name = f.name.clone().unwrap_or_else(|| {
        Path::new(file)
            .file_stem()
            .map_or(NAME.into(), |s| s.to_string_lossy().into_owned())
    });
    let mut text_out = format!("Friction '{name}'\n");
    let mut out = Vec::new();
    let mut total = 0.0;
    for (i, s) in f.element.iter().enumerate() {
        let (v, torque) = element(&cx, i, s)?;
        let mut fields = v.clone();
        if let Some(o) = fields.as_object_mut() {
            o.remove("label");
            o.remove("type");
        }
        let _ = writeln!(
            text_out,
            "[{}] {}: {}",
            v["label"].as_str().unwrap_or(""),
            v["type"].as_str().unwrap_or(""),
            crate::io::report::human_json(&fields)
        );
        total += torque;
        out.push(v);
    }
    let mut chains = Vec::new();
    for (i, s) in f.connected_bodies.iter().enumerate() {
        let (v, line) = crate::scenarios::friction_bodies::chain(&cx, i, s)?;
        let _ = writeln!(
            text_out,
            "[{}] connected bodies: {line}",
            v["label"].as_str().unwrap_or("")
        );
        chains.push(v);
    }
    let mut json =
        json!({ "scenario": name, "kind": NAME, "elements": out, "total_torque_Nm": total });
    if !chains.is_empty() {
        json["connected_bodies"] = Value::Array(chains);
    }
    if let Some(n) = f.speed_rpm {
        json["speed_rpm"] = json!(n);
        json["friction_power_W"] = json!(total * n * PI / 30.0);
        let _ = writeln!(
            text_out,
            "Total friction torque {total:.4} N m, power {:.4} W at {n} rpm",
            total * n * PI / 30.0
        );
    } else {
        let _ = writeln!(text_out, "Total friction torque {total:.4} N m");
    }
    Ok(Report {
        json,
        text: text_out,
    })
}

/// A required number checked against its range: `need(key, value, lo, hi)`.
type Need<'a> = dyn Fn(&str, Option<f64>, f64, f64) -> Result<f64, ScenarioError> + 'a;

/// A screw element: thread (and collar) torque, efficiencies and self-locking for a load,
/// or the load a handle force lifts.
fn screw(
    e: &Element,
    label: &str,
    need: &Need,
    err: &dyn Fn(&str, String) -> ScenarioError,
) -> Result<Value, ScenarioError> {
    let p = need("pitch", e.pitch, 1e-9, 1e3)?;
    let [d_out, d_in] = e.diameters.ok_or_else(|| {
        err(
            "diameters",
            "missing: [outer, root] thread diameters (m)".into(),
        )
    })?;
    if !(in_range(d_in, 1e-9, 1e3) && d_out > d_in) {
        return Err(err(
            "diameters",
            format!("expected [outer, root] with outer > root > 0, got [{d_out}, {d_in}]"),
        ));
    }
    let dm = (d_out + d_in) / 2.0;
    let fr = need("friction", e.friction, 0.0, 2.0)?;
    let half = e
        .thread_angle_deg
        .map_or(Ok(0.0), |a| need("thread_angle_deg", Some(a), 0.0, 120.0))?
        .to_radians()
        / 2.0;
    if let (Some(force), None) = (e.handle_force, e.load) {
        let l = need("handle_length", e.handle_length, 1e-9, 1e3)?;
        let force = need("handle_force", Some(force), 1e-9, 1e12)?;
        let q = el::screw_load(force * l, p, dm, fr, half);
        let sc = el::screw(q, p, dm, fr, half, 0.0);
        Ok(
            json!({"label": label, "type": "screw", "load_N": q, "lead_angle_deg": sc.lead_angle.to_degrees(),
            "friction_angle_deg": sc.friction_angle.to_degrees(), "torque_Nm": sc.torque, "efficiency": sc.efficiency,
            "reverse_efficiency": sc.reverse_efficiency, "self_locking": sc.self_locking}),
        )
    } else {
        let q = need("load", e.load, 0.0, 1e12)?;
        let collar = match (e.collar_friction, e.collar_diameters) {
            (Some(f1), Some([a, b])) if a > b && b >= 0.0 => el::collar_torque(
                need("collar_friction", Some(f1), 0.0, 2.0)?,
                q,
                a / 2.0,
                b / 2.0,
                !e.new,
            ),
            (None, None) => 0.0,
            _ => {
                return Err(err(
                    "collar_diameters",
                    "give collar_friction and collar_diameters = [outer, inner] together".into(),
                ))
            }
        };
        let sc = el::screw(q, p, dm, fr, half, collar);
        let mut v = json!({"label": label, "type": "screw", "load_N": q, "lead_angle_deg": sc.lead_angle.to_degrees(),
            "friction_angle_deg": sc.friction_angle.to_degrees(), "thread_torque_Nm": sc.thread_torque,
            "collar_torque_Nm": collar, "torque_Nm": sc.torque, "efficiency": sc.efficiency,
            "reverse_efficiency": sc.reverse_efficiency, "self_locking": sc.self_locking});
        if let Some(fh) = e.handle_force {
            v["handle_length_m"] = json!(sc.torque / need("handle_force", Some(fh), 1e-9, 1e12)?);
        }
        Ok(v)
    }
}

/// One element: its JSON and its friction torque (N m, 0 when it has none).
fn element(cx: &Source, i: usize, s: &Spanned<Element>) -> Result<(Value, f64), ScenarioError> {
    let e = s.get_ref();
    let err = |k: &str, m: String| cx.field(s.span(), k, format!("element[{i}].{k}"), m);
    let need = |k: &str, v: Option<f64>, lo: f64, hi: f64| -> Result<f64, ScenarioError> {
        match v {
            Some(x) if in_range(x, lo, hi) => Ok(x),
            Some(x) => Err(err(k, format!("must be in [{lo}, {hi}], got {x}"))),
            None => Err(err(k, format!("missing (a '{}' element needs it)", e.kind))),
        }
    };
    keys_apply(e, &err)?;
    let label = e
        .label
        .clone()
        .unwrap_or_else(|| format!("{} {}", e.kind, i + 1));
    let (v, torque) = match e.kind.as_str() {
        "screw" => (screw(e, &label, &need, &err)?, 0.0),
        "slide" => {
            let q = need("load", e.load, 0.0, 1e12)?;
            let (kind, fe) = slide(e, &need, &err)?;
            (json!({"label": label, "type": "slide", "slide": kind, "equivalent_friction": fe, "force_N": fe * q}), 0.0)
        }
        "rolling" => (rolling(e, label, &need, &err)?, 0.0),
        "wedge" => {
            let q = need("load", e.load, 0.0, 1e12)?;
            let a = need("angle_deg", e.angle_deg, 0.0, 89.0)?.to_radians();
            let [f1, f2] = e.friction_faces.ok_or_else(|| err("friction_faces", "missing: [f1, f2]".into()))?;
            let (f1, f2) = (need("friction_faces", Some(f1), 0.0, 2.0)?, need("friction_faces", Some(f2), 0.0, 2.0)?);
            let (drive, pull, lock) = el::wedge(q, a, f1, f2);
            (json!({"label": label, "type": "wedge", "drive_in_N": drive, "pull_out_N": pull, "self_locking": lock}), 0.0)
        }
        "incline" => (incline(e, label, &need, &err)?, 0.0),
        "journal" => {
            let q = need("load", e.load, 0.0, 1e12)?;
            let r = need("diameter", e.diameter, 1e-9, 1e3)? / 2.0;
            let lam = e.fit_factor.map_or(Ok(1.0), |x| need("fit_factor", Some(x), 0.5, 2.0))?;
            let n = e.count.map_or(Ok(1.0), |x| need("count", Some(x), 1.0, 1e6))?;
            let m = lam * need("friction", e.friction, 0.0, 2.0)? * q * r;
            (json!({"label": label, "type": "journal", "friction_circle_m": m / q.max(1e-300), "torque_Nm": m, "count": n, "total_torque_Nm": m * n}), m * n)
        }
        "collar" => {
            let q = need("load", e.load, 0.0, 1e12)?;
            let [a, b] = e.diameters.ok_or_else(|| err("diameters", "missing: [outer, inner] (inner 0 for a solid pivot)".into()))?;
            if !(a > b && b >= 0.0 && a.is_finite()) {
                return Err(err("diameters", "expected [outer, inner] with outer > inner ≥ 0".into()));
            }
            let m = el::collar_torque(need("friction", e.friction, 0.0, 2.0)?, q, a / 2.0, b / 2.0, !e.new);
            (json!({"label": label, "type": "collar", "torque_Nm": m}), m)
        }
        "belt" => {
            let w = need("power", e.power, 0.0, 1e12)?;
            let v = need("speed", e.speed, 1e-9, 1e6)?;
            let ef = euler_factor(e, &need, &err)?;
            let [p, s1, s2, s0, load] = el::belt(w, v, ef);
            (json!({"label": label, "type": "belt", "euler_factor": ef, "pull_N": p, "tight_N": s1, "slack_N": s2, "initial_tension_N": s0, "shaft_load_N": load}), 0.0)
        }
        "band_brake" => (band_brake(e, label, &need, &err)?, 0.0),
        "shoe_brake" => (shoe_brake(e, label, &need, &err)?, 0.0),
        other => return Err(err("type", format!("unknown element type '{other}' (screw, slide, rolling, wedge, incline, journal, collar, belt, band_brake, shoe_brake)"))),
    };
    // A result that is not finite (serialised as null) comes from the inputs: refuse it.
    if let Some((k, _)) = v
        .as_object()
        .and_then(|o| o.iter().find(|(_, x)| x.is_null()))
    {
        return Err(cx.at(
            s.span(),
            format!("element[{i}]"),
            format!("the result {k} is not finite: check the element's values"),
        ));
    }
    if !torque.is_finite() {
        return Err(cx.at(
            s.span(),
            format!("element[{i}]"),
            "the friction torque is not finite: check the element's values",
        ));
    }
    Ok((v, torque))
}

/// The keys each element type reads (besides `label` and `type`).
const KEYS: &[(&str, &[&str])] = &[
    (
        "screw",
        &[
            "load",
            "friction",
            "pitch",
            "diameters",
            "thread_angle_deg",
            "collar_friction",
            "collar_diameters",
            "new",
            "handle_force",
            "handle_length",
        ],
    ),
    ("slide", &["load", "friction", "slide", "groove_angle_deg"]),
    (
        "rolling",
        &[
            "load",
            "friction",
            "rolling_arms",
            "wheel_diameter",
            "axle_diameter",
            "wheel_weight",
            "wheels",
        ],
    ),
    ("wedge", &["load", "angle_deg", "friction_faces"]),
    (
        "incline",
        &[
            "load",
            "angle_deg",
            "friction",
            "slide",
            "groove_angle_deg",
            "push_angle_deg",
        ],
    ),
    (
        "journal",
        &["load", "friction", "diameter", "fit_factor", "count"],
    ),
    ("collar", &["load", "friction", "diameters", "new"]),
    (
        "belt",
        &["power", "speed", "euler_factor", "friction", "wrap_deg"],
    ),
    (
        "band_brake",
        &[
            "euler_factor",
            "friction",
            "wrap_deg",
            "drum_diameter",
            "slack_arm",
            "tight_arm",
            "lever_load",
            "lever_arm",
            "braking_torque",
            "load_drum_diameter",
        ],
    ),
    (
        "shoe_brake",
        &[
            "friction",
            "drum_diameter",
            "shoe_arm",
            "friction_arm",
            "contact_deg",
            "shoes",
            "lever_load",
            "lever_arm",
            "braking_torque",
            "load_drum_diameter",
        ],
    ),
];

/// The keys written in `e` (besides `label` and `type`).
fn written(e: &Element) -> Vec<&'static str> {
    let f = [
        ("load", e.load.is_some()),
        ("friction", e.friction.is_some()),
        ("friction_faces", e.friction_faces.is_some()),
        ("pitch", e.pitch.is_some()),
        ("diameters", e.diameters.is_some()),
        ("thread_angle_deg", e.thread_angle_deg.is_some()),
        ("collar_friction", e.collar_friction.is_some()),
        ("collar_diameters", e.collar_diameters.is_some()),
        ("new", e.new),
        ("handle_force", e.handle_force.is_some()),
        ("handle_length", e.handle_length.is_some()),
        ("slide", e.slide.is_some()),
        ("groove_angle_deg", e.groove_angle_deg.is_some()),
        ("wheel_diameter", e.wheel_diameter.is_some()),
        ("axle_diameter", e.axle_diameter.is_some()),
        ("rolling_arms", e.rolling_arms.is_some()),
        ("angle_deg", e.angle_deg.is_some()),
        ("diameter", e.diameter.is_some()),
        ("fit_factor", e.fit_factor.is_some()),
        ("count", e.count.is_some()),
        ("power", e.power.is_some()),
        ("speed", e.speed.is_some()),
        ("euler_factor", e.euler_factor.is_some()),
        ("wrap_deg", e.wrap_deg.is_some()),
        ("lever_load", e.lever_load.is_some()),
        ("lever_arm", e.lever_arm.is_some()),
        ("braking_torque", e.braking_torque.is_some()),
        ("slack_arm", e.slack_arm.is_some()),
        ("tight_arm", e.tight_arm.is_some()),
        ("drum_diameter", e.drum_diameter.is_some()),
        ("load_drum_diameter", e.load_drum_diameter.is_some()),
        ("push_angle_deg", e.push_angle_deg.is_some()),
        ("shoe_arm", e.shoe_arm.is_some()),
        ("friction_arm", e.friction_arm.is_some()),
        ("contact_deg", e.contact_deg.is_some()),
        ("shoes", e.shoes.is_some()),
        ("wheel_weight", e.wheel_weight.is_some()),
        ("wheels", e.wheels.is_some()),
    ];
    f.iter().filter(|(_, w)| *w).map(|(k, _)| *k).collect()
}

/// Refuses a key the element's type does not read (as a misspelt key is refused), and
/// `groove_angle_deg` on a slide that is not a V groove.
fn keys_apply(e: &Element, err: &Err) -> Result<(), ScenarioError> {
    let Some((_, keys)) = KEYS.iter().find(|(t, _)| *t == e.kind) else {
        return Ok(()); // the unknown type is reported with its list
    };
    if let Some(k) = written(e).into_iter().find(|k| !keys.contains(k)) {
        return Err(err(
            k,
            format!(
                "does not apply to an element of type '{}' (it reads {})",
                e.kind,
                keys.join(", ")
            ),
        ));
    }
    if e.groove_angle_deg.is_some() && e.slide.as_deref() != Some("v_groove") {
        return Err(err(
            "groove_angle_deg",
            "applies only to slide = \"v_groove\"".into(),
        ));
    }
    Ok(())
}

type Err<'a> = dyn Fn(&str, String) -> ScenarioError + 'a;

/// `e^{fα}`: `euler_factor`, or `friction` and `wrap_deg`.
fn euler_factor(e: &Element, need: &Need, err: &Err) -> Result<f64, ScenarioError> {
    match (e.euler_factor, e.friction, e.wrap_deg) {
        (Some(x), None, None) => need("euler_factor", Some(x), 1.0 + 1e-9, 1e6),
        (None, Some(fr), Some(wr)) => Ok((need("friction", Some(fr), 1e-9, 2.0)?
            * need("wrap_deg", Some(wr), 1e-3, 3600.0)?.to_radians())
        .exp()),
        _ => Err(err(
            "euler_factor",
            "give euler_factor = e^(f α), or friction and wrap_deg".into(),
        )),
    }
}

/// A band brake (FR-4): lever load and arm (or the braking torque wanted), the band's
/// arms on the lever, the drum, optionally the drum of the load held.
fn band_brake(e: &Element, label: String, need: &Need, err: &Err) -> Result<Value, ScenarioError> {
    let ef = euler_factor(e, need, err)?;
    let r = need("drum_diameter", e.drum_diameter, 1e-9, 1e3)? / 2.0;
    let b = need("slack_arm", e.slack_arm, 1e-9, 1e3)?;
    let a = e
        .tight_arm
        .map_or(Ok(0.0), |x| need("tight_arm", Some(x), -1e3, 1e3))?;
    let given = match (e.lever_load, e.braking_torque) {
        (Some(g), None) => el::BrakeGiven::LeverMoment(
            need("lever_load", Some(g), 0.0, 1e12)? * need("lever_arm", e.lever_arm, 1e-9, 1e3)?,
        ),
        (None, Some(m)) => {
            el::BrakeGiven::BrakingForce(need("braking_torque", Some(m), 0.0, 1e12)? / r)
        }
        _ => {
            return Err(err(
                "lever_load",
                "give lever_load (with lever_arm) or braking_torque, one of the two".into(),
            ))
        }
    };
    let mut v = json!({"label": label, "type": "band_brake", "euler_factor": ef,
        "brake": if a == 0.0 { "simple" } else if a > 0.0 { "differential" } else { "summing" },
        "locking_margin_m": b - a * ef, "self_locking": b - a * ef <= 0.0});
    let Some(bb) = el::band_brake(ef, a, b, given) else {
        // Self-locking with a lever load given: the tensions are set by the drum.
        return Ok(v);
    };
    v["slack_N"] = json!(bb.s2);
    v["tight_N"] = json!(bb.s1);
    v["braking_force_N"] = json!(bb.force);
    v["braking_torque_Nm"] = json!(bb.force * r);
    v["lever_moment_Nm"] = json!(bb.lever_moment);
    v["friction_sensitivity"] = json!(bb.friction_sensitivity);
    if let Some(l) = e.lever_arm {
        v["lever_load_N"] = json!(bb.lever_moment / need("lever_arm", Some(l), 1e-9, 1e3)?);
    }
    if let Some(d) = e.load_drum_diameter {
        v["load_held_N"] =
            json!(bb.force * r / (need("load_drum_diameter", Some(d), 1e-9, 1e3)? / 2.0));
    }
    Ok(v)
}

/// A rolling element: wheels on axles (with the wheels' own weight `wheels` ×
/// `wheel_weight`, which loads the rail but not the journals) or free rollers.
fn rolling(e: &Element, label: String, need: &Need, err: &Err) -> Result<Value, ScenarioError> {
    let q = need("load", e.load, 0.0, 1e12)?;
    let [k1, k2] = e.rolling_arms.ok_or_else(|| {
        err(
            "rolling_arms",
            "missing: [k1, k2] rolling-resistance arms (m)".into(),
        )
    })?;
    let (k1, k2) = (
        need("rolling_arms", Some(k1), 0.0, 1.0)?,
        need("rolling_arms", Some(k2), 0.0, 1.0)?,
    );
    let d1 = need("wheel_diameter", e.wheel_diameter, 1e-9, 1e3)?;
    let Some(d2) = e.axle_diameter else {
        if e.wheel_weight.is_some() || e.wheels.is_some() {
            let k = if e.wheels.is_some() {
                "wheels"
            } else {
                "wheel_weight"
            };
            return Err(err(
                k,
                "applies to wheels on axles (give axle_diameter)".into(),
            ));
        }
        let p = el::free_rollers(q, d1, k1, k2);
        return Ok(json!({"label": label, "type": "rolling", "force_N": p}));
    };
    let d2 = need("axle_diameter", Some(d2), 1e-9, d1)?;
    let f = need("friction", e.friction, 0.0, 2.0)?;
    let n = e
        .wheels
        .map_or(Ok(1.0), |x| need("wheels", Some(x), 1.0, 1e6))?;
    if n.fract() != 0.0 {
        return Err(err("wheels", format!("must be a whole number, got {n}")));
    }
    let gw = n * e
        .wheel_weight
        .map_or(Ok(0.0), |x| need("wheel_weight", Some(x), 0.0, 1e12))?;
    let w = el::rolling_with_wheels(q, gw, d1, d2, f, k1);
    Ok(
        json!({"label": label, "type": "rolling", "force_N": w.force,
        "rolling_N": w.rolling, "journal_N": w.journal, "wheels_weight_N": gw}),
    )
}

/// A slide's kind and equivalent coefficient (`slide`, `groove_angle_deg`, `friction`),
/// for slide and incline elements.
fn slide(e: &Element, need: &Need, err: &Err) -> Result<(String, f64), ScenarioError> {
    let fr = need("friction", e.friction, 0.0, 2.0)?;
    let kind = e.slide.clone().unwrap_or_else(|| "flat".into());
    let beta = match (kind.as_str(), e.groove_angle_deg) {
        ("v_groove", g) => g
            .map_or(Ok(0.0), |x| need("groove_angle_deg", Some(x), 0.0, 89.0))?
            .to_radians(),
        _ => 0.0,
    };
    let fe = el::slide_coefficient(fr, &kind, beta).ok_or_else(|| {
        err(
            "slide",
            format!("unknown slide '{kind}' (flat, v_groove, worn_cylinder, new_cylinder)"),
        )
    })?;
    Ok((kind, fe))
}

/// An incline (FR: 164, 168): the load pushed up and held back by a force at
/// `push_angle_deg` to the vertical (90, horizontal, by default), on a flat plane or a
/// groove (`slide`).
fn incline(e: &Element, label: String, need: &Need, err: &Err) -> Result<Value, ScenarioError> {
    let q = need("load", e.load, 0.0, 1e12)?;
    let a = need("angle_deg", e.angle_deg, 0.0, 89.0)?.to_radians();
    let beta = e
        .push_angle_deg
        .map_or(Ok(90.0), |x| need("push_angle_deg", Some(x), 0.0, 180.0))?;
    let (kind, fe) = slide(e, need, err)?;
    let inc = el::incline(q, a, fe, beta.to_radians()).map_err(|jam| {
        let (what, sum) = match jam {
            el::InclineJam::Up => ("push the load up", "a + β + φ ≥ 180°"),
            el::InclineJam::Down => ("hold the load back", "sin(a + β − φ) = 0"),
        };
        err(
            "push_angle_deg",
            format!(
                "no force at {beta}° to the vertical can {what} ({sum}, with the friction \
                 angle φ = {:.4}°): the push presses the load into the plane",
                fe.atan().to_degrees()
            ),
        )
    })?;
    let mut v = json!({"label": label, "type": "incline", "slide": kind, "equivalent_friction": fe,
        "push_angle_deg": beta, "push_up_N": inc.up, "push_down_N": inc.down,
        "efficiency": inc.efficiency, "self_locking": inc.self_locking});
    if let Some(r) = inc.reverse_efficiency {
        v["reverse_efficiency"] = json!(r);
    }
    Ok(v)
}

/// A shoe brake: one shoe on a lever, or two opposite shoes with the same lever load
/// (`shoes = 2`: one self-energising, one not), a lever load or the braking torque wanted.
fn shoe_brake(e: &Element, label: String, need: &Need, err: &Err) -> Result<Value, ScenarioError> {
    let f = need("friction", e.friction, 0.0, 2.0)?;
    let r = need("drum_diameter", e.drum_diameter, 1e-9, 1e3)? / 2.0;
    let b = need("shoe_arm", e.shoe_arm, 1e-9, 1e3)?;
    let arm = e
        .friction_arm
        .map_or(Ok(0.0), |x| need("friction_arm", Some(x), -1e3, 1e3))?;
    let contact = e
        .contact_deg
        .map_or(Ok(0.0), |x| need("contact_deg", Some(x), 0.0, 180.0))?
        .to_radians();
    let shoes = match e.shoes {
        None => 1,
        Some(n) if n == 1.0 || n == 2.0 => n as usize,
        Some(n) => return Err(err("shoes", format!("must be 1 or 2, got {n}"))),
    };
    let fe = el::shoe_coefficient(f, contact);
    // Normal force per unit lever moment, for each shoe (the second mirrored: arm −e).
    let unit: Vec<Option<f64>> = [arm, -arm][..shoes]
        .iter()
        .map(|&ea| el::shoe_normal_force(1.0, b, ea, fe))
        .collect();
    // The shoe the friction presses on hardest decides locking.
    let margin = b - fe * if shoes == 2 { arm.abs() } else { arm };
    let mut v = json!({"label": label, "type": "shoe_brake", "shoes": shoes,
        "equivalent_friction": fe, "locking_margin_m": margin,
        "self_energising": arm != 0.0 && (shoes == 2 || arm > 0.0),
        "self_locking": unit.iter().any(Option::is_none)});
    if unit.iter().any(Option::is_none) {
        // Self-locking: the drum pulls the shoe on; no lever load fixes the forces.
        return Ok(v);
    }
    let unit_torque: f64 = unit.iter().flatten().sum::<f64>() * fe * r;
    let lever_moment = match (e.lever_load, e.braking_torque) {
        (Some(g), None) => {
            need("lever_load", Some(g), 0.0, 1e12)? * need("lever_arm", e.lever_arm, 1e-9, 1e3)?
        }
        (None, Some(m)) => need("braking_torque", Some(m), 0.0, 1e12)? / unit_torque,
        _ => {
            return Err(err(
                "lever_load",
                "give lever_load (with lever_arm) or braking_torque, one of the two".into(),
            ))
        }
    };
    let normal: Vec<f64> = unit.iter().flatten().map(|n| n * lever_moment).collect();
    let torque = unit_torque * lever_moment;
    v["normal_N"] = json!(normal);
    v["braking_force_N"] = json!(torque / r);
    v["braking_torque_Nm"] = json!(torque);
    v["lever_moment_Nm"] = json!(lever_moment);
    if shoes == 1 {
        // The drum turning the other way: the friction arm changes sign.
        match el::shoe_normal_force(lever_moment, b, -arm, fe) {
            Some(n) => v["reverse_braking_torque_Nm"] = json!(fe * n * r),
            None => v["reverse_self_locking"] = json!(true),
        }
    }
    if let Some(l) = e.lever_arm {
        v["lever_load_N"] = json!(lever_moment / need("lever_arm", Some(l), 1e-9, 1e3)?);
    }
    if let Some(d) = e.load_drum_diameter {
        v["load_held_N"] = json!(torque / (need("load_drum_diameter", Some(d), 1e-9, 1e3)? / 2.0));
    }
    Ok(v)
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "friction";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text),
    run: |path, text, _opts| run(path, text),
};
