//! The linkage part of a mechanism report: mobility, branches, dead centres and
//! followers, the sweep and its extremes, report points, kinetostatics.

use crate::machines::linkage::continuation::sweep_through;
use crate::machines::linkage::fourbar;
use crate::machines::linkage::mobility::mobility;
use crate::machines::linkage::sweep::{
    self, dead_centres, follower_value, followers, State, Sweep, Tracker,
};
use crate::machines::linkage::Vec2;
use crate::scenarios::linkage::linkage_scenario::{KinetostaticsScenario, MechanismScenario};
use crate::scenarios::linkage::report::centres_report::{centres_at, structure_json};
use crate::scenarios::linkage::report::change_points::change_points_json;
use crate::scenarios::linkage::report::counterweight_report::counterweight;
use crate::scenarios::linkage::report::guide_report;
use crate::scenarios::linkage::report::sweep_rows::{
    deg360, extremes_json, named_points, point_world, state_at, v2, ReportCtx, Row,
};
use serde_json::{json, Map, Value};
use std::f64::consts::TAU;
use std::fmt::Write;

/// The mobility (Grübler and the Jacobian's rank), the four-bar's Grashof class and
/// closed-form transmission extremes when named, and the driver.
fn mobility_json(
    m: &MechanismScenario,
    st: &State,
    json: &mut Map<String, Value>,
    text: &mut String,
) {
    let l = &m.linkage;
    let mob = mobility(&m.linkage, &m.assembly);
    json.insert(
        "mobility".into(),
        serde_json::to_value(&mob).unwrap_or(Value::Null),
    );
    let _ = writeln!(
        text,
        "mobility: Grübler 3(n-1) - 2j1 - j2 = 3·{} - 2·{} - {} = {}; rank of the joint Jacobian {} of {} equations → mobility {}, {} redundant",
        mob.links - 1,
        mob.full_joints,
        mob.half_joints,
        mob.grubler,
        mob.rank,
        mob.equations,
        mob.mobility,
        mob.redundant
    );
    if let Some(fb) = &m.four_bar {
        let p: Vec<Vec2> = fb.iter().map(|n| point_world(l, st, n)).collect();
        let (g, a, b, c) = (
            (p[3] - p[0]).norm(),
            (p[1] - p[0]).norm(),
            (p[2] - p[1]).norm(),
            (p[2] - p[3]).norm(),
        );
        let cls = fourbar::classify(g, a, b, c);
        let (mu0, mu180) = fourbar::transmission_extremes(g, a, b, c);
        json.insert(
            "four_bar".into(),
            json!({
                "points": fb,
                "lengths": {"ground": g, "input": a, "coupler": b, "output": c},
                "grashof": cls,
                "transmission_angle_closed_form_deg": {"at_input_0": mu0.map(f64::to_degrees), "at_input_180": mu180.map(f64::to_degrees)},
            }),
        );
        let _ = writeln!(
            text,
            "four-bar {}: ground {g:.4}, input {a:.4}, coupler {b:.4}, output {c:.4} m: s+l = {:.4} {} p+q = {:.4}: {:?}, {}",
            fb.join("-"),
            cls.s_plus_l,
            match cls.class {
                fourbar::GrashofClass::Grashof => "<",
                fourbar::GrashofClass::NonGrashof => ">",
                fourbar::GrashofClass::ChangePoint => "=",
            },
            cls.p_plus_q,
            cls.class,
            cls.kind
        );
    }
    json.insert(
        "driver".into(),
        json!({
            "link": l.links[l.driven_link()].name,
            "type": if m.angle_input { "angle" } else { "slide" },
            "speed": m.speed,
            "acceleration": m.acceleration,
        }),
    );
}

/// The assembly branches: each group's starting sign and whether it stays constant.
fn branches_json(sw: &Sweep, json: &mut Map<String, Value>, text: &mut String) {
    let signs0: Vec<i8> = sw.samples[0]
        .indicators
        .iter()
        .map(|x| crate::machines::linkage::branch::sign(*x))
        .collect();
    let mut constant = true;
    let mut groups = Vec::new();
    for (gi, g) in sw.groups.iter().enumerate() {
        let signs: Vec<i8> = sw
            .samples
            .iter()
            .map(|s| crate::machines::linkage::branch::sign(s.indicators[gi]))
            .collect();
        let nonzero: Vec<i8> = signs.iter().copied().filter(|&x| x != 0).collect();
        let same = nonzero.windows(2).all(|w| w[0] == w[1]);
        constant &= same;
        let min_abs = sw
            .samples
            .iter()
            .map(|s| s.indicators[gi].abs())
            .fold(f64::INFINITY, f64::min);
        groups.push(json!({
            "group": g.name,
            "start_sign": signs0[gi],
            "constant": same,
            "min_abs_indicator": min_abs,
        }));
    }
    json.insert(
        "branches".into(),
        json!({"groups": groups, "constant": constant}),
    );
    let _ = writeln!(
        text,
        "branches: {} — sign {}",
        sw.groups
            .iter()
            .map(|g| g.name.clone())
            .collect::<Vec<_>>()
            .join(", "),
        if constant {
            "constant over the sweep (no jump)".to_string()
        } else {
            "changes at singular positions (the tracker crossed them on the same branch)"
                .to_string()
        }
    );
}

/// A follower's dead centres, its stroke or swing, and over a full turn the time ratio.
fn follower_json(f: &sweep::Follower, mine: &[&sweep::DeadCentre], full_turn: bool) -> Value {
    let vals: Vec<f64> = mine.iter().map(|d| d.value).collect();
    let travel = vals.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
        - vals.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let mut o = Map::new();
    o.insert(
        "kind".into(),
        json!(if matches!(f, sweep::Follower::Rocker(_)) {
            "rocker"
        } else {
            "slide"
        }),
    );
    o.insert("dead_centres".into(), json!(mine.len()));
    if mine.len() >= 2 {
        o.insert(
            if matches!(f, sweep::Follower::Rocker(_)) {
                "swing_deg"
            } else {
                "stroke"
            }
            .into(),
            json!(if matches!(f, sweep::Follower::Rocker(_)) {
                travel.to_degrees()
            } else {
                travel
            }),
        );
    }
    if full_turn && mine.len() == 2 {
        let d1 = (mine[1].state.s - mine[0].state.s).abs();
        let d2 = TAU - d1;
        o.insert("time_ratio".into(), json!(d1.max(d2) / d1.min(d2)));
    }
    Value::Object(o)
}

/// The text of one report point (input `s`): points' positions, velocities and
/// accelerations, the links' angles and rates, the transmission angle, singularity.
fn point_text(ctx: &ReportCtx, r: &Row, s: f64, text: &mut String) {
    let l = ctx.l;
    let _ = writeln!(text, "\nat input {:.4}{}:", ctx.input(s), ctx.unit());
    let _ = writeln!(
        text,
        "  {:<8} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12}",
        "point", "x", "y", "vx", "vy", "ax", "ay"
    );
    for (n, b, p) in &ctx.points {
        let (pp, vv, aa) = (
            l.point_position(&r.st.q, *b, p),
            l.point_velocity(&r.st.q, &r.qd, *b, p),
            l.point_acceleration(&r.st.q, &r.qd, &r.qdd, *b, p),
        );
        let _ = writeln!(
            text,
            "  {n:<8} {:>12.6} {:>12.6} {:>12.6} {:>12.6} {:>12.6} {:>12.6}",
            pp.x, pp.y, vv.x, vv.y, aa.x, aa.y
        );
    }
    let _ = writeln!(
        text,
        "  {:<8} {:>12} {:>12} {:>12}",
        "link", "angle °", "omega", "alpha"
    );
    for (i, k) in l.links.iter().enumerate() {
        let _ = writeln!(
            text,
            "  {:<8} {:>12.4} {:>12.6} {:>12.6}",
            k.name,
            deg360(r.st.q[3 * i + 2]),
            r.qd[3 * i + 2],
            r.qdd[3 * i + 2]
        );
    }
    if let Some(mu) = ctx.transmission(&r.st) {
        let _ = writeln!(text, "  transmission angle {mu:.3}°");
    }
    if r.st.singular {
        let _ = writeln!(
            text,
            "  singular position (condition {:.3e}){}",
            r.st.conditioning.condition,
            if r.st.locked {
                ": locked"
            } else {
                ": velocities are the limits along the branch"
            }
        );
    }
}

/// The kinetostatics text at input `s`: the driving effort both ways, inertia forces,
/// joint forces and the shaking force.
fn kinetostatics_text(ctx: &ReportCtx, r: &Row, s: f64, text: &mut String) {
    let (m, l) = (ctx.m, ctx.l);
    let (ks, vp) = r.kin.as_ref().expect("loads given");
    let _ = writeln!(
        text,
        "\nkinetostatics at input {:.4}{}:",
        ctx.input(s),
        ctx.unit()
    );
    let what = if m.angle_input {
        "torque (N m)"
    } else {
        "force (N)"
    };
    let _ = writeln!(
        text,
        "  driving {what} by {}: {:.9}",
        if r.st.singular {
            "virtual power at a singular position"
        } else {
            "joint forces (Lagrange multipliers)"
        },
        ks.driving
    );
    if r.st.singular {
        let _ = writeln!(
            text,
            "  singular position: the joint forces are not determined here (they grow without bound toward it); the driving {what} above is the virtual-power one (limit along the branch)"
        );
        return;
    }
    if let Some(v) = vp {
        let _ = writeln!(
            text,
            "  driving {what} by virtual power:                     {:.9}  (difference {:.2e})",
            v,
            v - ks.driving
        );
    }
    for (i, (f, c)) in ks.inertia.iter().enumerate() {
        if f.norm() > 0.0 || *c != 0.0 {
            let _ = writeln!(
                text,
                "  inertia force on {}: {:.4} N ({:.4}, {:.4}), couple {:.6} N m",
                l.links[i].name,
                f.norm(),
                f.x,
                f.y,
                c
            );
        }
    }
    for f in &ks.joint_forces {
        let _ = writeln!(
            text,
            "  joint {} on {} by {}: {:.4} N ({:.4}, {:.4}){}",
            f.name,
            l.body_name(f.on),
            l.body_name(f.by),
            f.force.norm(),
            f.force.x,
            f.force.y,
            if f.couple != 0.0 {
                format!(", couple {:.6} N m", f.couple)
            } else {
                String::new()
            }
        );
    }
    let _ = writeln!(
        text,
        "  shaking force on the frame: ({:.4}, {:.4}) N",
        ks.shaking_force.x, ks.shaking_force.y
    );
}

/// The sweep's summary lines: samples and residual, where it stopped, singular positions,
/// dead centres, followers' stroke, swing and time ratio, the transmission angle range.
fn sweep_text(
    ctx: &ReportCtx,
    sw: &Sweep,
    (sing, dcs): (&[f64], &[sweep::DeadCentre]),
    followers_json: &Map<String, Value>,
    json: &Map<String, Value>,
    text: &mut String,
) {
    let m = ctx.m;
    let _ = writeln!(
        text,
        "sweep: {} samples from {:.4}{u} to {:.4}{u}{}; max loop residual {:.2e}",
        sw.samples.len(),
        ctx.input(m.sweep.from),
        ctx.input(sw.samples.last().map(|s| s.s).unwrap_or(m.sweep.from)),
        if sw.stopped.is_some() {
            " (stopped early: the branch ends)"
        } else {
            ""
        },
        sw.samples.iter().map(|s| s.residual).fold(0.0, f64::max),
        u = ctx.unit()
    );
    if let Some(e) = &sw.stopped {
        let _ = writeln!(text, "  {e}");
    }
    if !sing.is_empty() {
        let _ = writeln!(
            text,
            "singular positions (driven Jacobian loses rank; solved there, motion continued on the branch): {}",
            sing.iter().map(|s| format!("{s:.4}{}", ctx.unit())).collect::<Vec<_>>().join(", ")
        );
    }
    for d in dcs {
        let _ = writeln!(
            text,
            "dead centre of {} at input {:.4}{}",
            d.follower,
            ctx.input(d.state.s),
            ctx.unit()
        );
    }
    for (n, o) in followers_json {
        if let Some(s) = o.get("stroke") {
            let _ = writeln!(text, "{n}: stroke {:.6} m", s.as_f64().unwrap_or(f64::NAN));
        }
        if let Some(s) = o.get("swing_deg") {
            let _ = writeln!(text, "{n}: swing {:.4}°", s.as_f64().unwrap_or(f64::NAN));
        }
        if let Some(t) = o.get("time_ratio") {
            let _ = writeln!(
                text,
                "{n}: time ratio (forward/return crank angles) {:.4}",
                t.as_f64().unwrap_or(f64::NAN)
            );
        }
    }
    if let Some(ext) = json
        .get("extremes")
        .and_then(|e| e.get("transmission_angle_deg"))
    {
        let _ = writeln!(
            text,
            "transmission angle: {:.3}° to {:.3}°",
            ext["min"].as_f64().unwrap_or(f64::NAN),
            ext["max"].as_f64().unwrap_or(f64::NAN)
        );
    }
}

/// The kinetostatics at the points asked for, the agreement of the two driving-effort
/// methods over the sweep, and the counterweight; returns the driving effort over a full
/// turn (for the flywheel).
fn kinetostatics_section(
    ctx: &ReportCtx,
    k: &KinetostaticsScenario,
    (tracker, samples, rows): (&Tracker, &[State], &[Row]),
    full_turn: bool,
    json: &mut Map<String, Value>,
    text: &mut String,
) -> Option<Vec<(f64, f64)>> {
    let m = ctx.m;
    let mut kat = Vec::new();
    for &s in &k.report_at {
        let Some(st) = state_at(tracker, samples, s) else {
            continue;
        };
        let r = ctx.row(&st, Some(&k.loads));
        kinetostatics_text(ctx, &r, s, text);
        let mut entry = ctx.kinetostatics_json(&r);
        if let (false, false, Some((ks, _))) = (m.guides.is_empty(), r.st.singular, &r.kin) {
            entry["guide_contacts"] =
                guide_report::guides_json(ctx.l, &r.st.q, ks, &m.guides, text);
        }
        kat.push(entry);
    }
    let max_diff = rows
        .iter()
        .filter_map(|r| {
            r.kin
                .as_ref()
                .and_then(|(k, v)| v.map(|v| (v - k.driving).abs()))
        })
        .fold(0.0, f64::max);
    let mut kj = json!({"at": kat, "max_virtual_power_difference": max_diff});
    if let Some(fc) = &k.friction {
        let samples: Vec<crate::scenarios::linkage::friction_report::FrictionSample> = rows
            .iter()
            .map(|r| (r.st.s, &r.st.q, &r.qd, &r.qdd))
            .collect();
        kj["friction"] = crate::scenarios::linkage::friction_report::report(
            ctx.l,
            &samples,
            &k.loads,
            m.speed,
            fc,
            &k.report_at,
            (full_turn, m.angle_input),
            &m.guides,
            text,
        );
    }
    json.insert("kinetostatics".into(), kj);
    let _ = writeln!(text, "  largest difference between the two driving-effort methods over the sweep: {max_diff:.2e}");
    if let Some(cw) = &m.counterweight {
        counterweight(m, ctx, cw, rows, json, text);
    }
    full_turn.then(|| {
        rows.iter()
            .filter_map(|r| r.kin.as_ref().map(|(k, _)| (r.st.s, k.driving)))
            .collect()
    })
}

/// The named coupler points' paths over the sweep.
fn coupler_curves(m: &MechanismScenario, samples: &[State]) -> Value {
    let mut cc = Map::new();
    for n in &m.coupler_curves {
        let pts: Vec<Value> = samples
            .iter()
            .map(|s| v2(&point_world(&m.linkage, s, n)))
            .collect();
        cc.insert(n.clone(), Value::Array(pts));
    }
    Value::Object(cc)
}

/// The dead centres (input and follower position) and each follower's summary, into
/// `json`; returns the followers' summaries.
fn dead_centre_json(
    ctx: &ReportCtx,
    fol: &[(String, sweep::Follower)],
    dcs: &[sweep::DeadCentre],
    full_turn: bool,
    json: &mut Map<String, Value>,
) -> Map<String, Value> {
    let mut dc_json = Vec::new();
    let mut followers_json = Map::new();
    for (name, f) in fol {
        let mine: Vec<&sweep::DeadCentre> = dcs.iter().filter(|d| &d.follower == name).collect();
        followers_json.insert(name.clone(), follower_json(f, &mine, full_turn));
    }
    for d in dcs {
        dc_json.push(json!({
            "follower": d.follower,
            ctx.input_key(): ctx.input(d.state.s),
            "position": if fol.iter().any(|(n, f)| n == &d.follower && matches!(f, sweep::Follower::Rocker(_))) { d.value.to_degrees() } else { d.value },
        }));
    }
    json.insert("dead_centres".into(), Value::Array(dc_json));
    json.insert("followers".into(), Value::Object(followers_json.clone()));
    followers_json
}

pub(super) fn mechanism(
    m: &MechanismScenario,
    json: &mut Map<String, Value>,
    text: &mut String,
) -> Option<Vec<(f64, f64)>> {
    let l = &m.linkage;
    let ctx = ReportCtx {
        m,
        l,
        points: named_points(l),
    };
    let (sw, passed): (Sweep, Vec<f64>) = match sweep_through(l, &m.assembly, &m.sweep) {
        Ok(s) => s,
        Err(e) => {
            json.insert("error".into(), json!(e.to_string()));
            let _ = writeln!(text, "sweep failed: {e}");
            return None;
        }
    };
    let tracker = sw.tracker(l);
    let loads = m.kinetostatics.as_ref().map(|k| &k.loads);
    let rows: Vec<Row> = sw.samples.iter().map(|st| ctx.row(st, loads)).collect();
    mobility_json(m, &sw.samples[0], json, text);
    branches_json(&sw, json, text);
    // Dead centres and singular positions.
    let full_turn = m.angle_input && ((m.sweep.to - m.sweep.from).abs() - TAU).abs() < 1e-9;
    // Over a full turn the last sample repeats the first: count its dead centres once.
    let dcs: Vec<sweep::DeadCentre> = dead_centres(&tracker, &sw.samples)
        .into_iter()
        .filter(|d| !full_turn || (d.state.s - m.sweep.from).abs() < TAU - 1e-9)
        .collect();
    let fol = followers(l);
    let rates: Vec<f64> = fol
        .iter()
        .map(|(_, f)| {
            sw.samples
                .iter()
                .map(|s| follower_value(l, f, s).1.abs())
                .fold(0.0, f64::max)
        })
        .collect();
    let dead_at = |st: &State| -> Vec<String> {
        fol.iter()
            .zip(&rates)
            .filter(|((_, f), &big)| follower_value(l, f, st).1.abs() <= 1e-9 * big.max(1e-300))
            .map(|((n, _), _)| n.clone())
            .collect()
    };
    let followers_json = dead_centre_json(&ctx, &fol, &dcs, full_turn, json);
    let sing: Vec<f64> = sw
        .singular_positions
        .iter()
        .map(|&s| ctx.input(s))
        .collect();
    json.insert(
        format!("singular_positions{}", &ctx.input_key()[5..]),
        json!(sing),
    );
    if let Some(e) = &sw.stopped {
        json.insert("stopped".into(), json!(e.to_string()));
    }
    // The sweep.
    let sweep_json: Vec<Value> = rows
        .iter()
        .map(|r| ctx.sample_json(r, &sw.groups, &dead_at(&r.st)))
        .collect();
    json.insert("sweep".into(), Value::Array(sweep_json));
    json.insert("extremes".into(), extremes_json(&ctx, &tracker, &rows));
    if !m.coupler_curves.is_empty() {
        json.insert("coupler_curves".into(), coupler_curves(m, &sw.samples));
    }
    sweep_text(&ctx, &sw, (&sing, &dcs), &followers_json, json, text);
    let periodic = full_turn && sw.stopped.is_none();
    change_points_json(&ctx, &sw, &passed, periodic, json, text);
    // Report points.
    let mut at = Vec::new();
    for &s in &m.report_at {
        let Some(st) = state_at(&tracker, &sw.samples, s) else {
            let _ = writeln!(
                text,
                "input {:.4}{}: not reached on this branch",
                ctx.input(s),
                ctx.unit()
            );
            continue;
        };
        let r = ctx.row(&st, loads);
        point_text(&ctx, &r, s, text);
        let dead = dead_at(&r.st);
        if !dead.is_empty() {
            let _ = writeln!(text, "  dead centre of {}", dead.join(", "));
        }
        at.push(ctx.sample_json(&r, &sw.groups, &dead));
    }
    json.insert("at".into(), Value::Array(at));
    structure_json(l, json, text);
    if let Some(at) = &m.instant_centres {
        instant_centres(&ctx, at, (&tracker, &sw.samples), json, text);
    }
    let k = m.kinetostatics.as_ref()?;
    kinetostatics_section(
        &ctx,
        k,
        (&tracker, &sw.samples, &rows),
        full_turn,
        json,
        text,
    )
}

/// `"instant_centres"`: every relative centre at the inputs asked for.
fn instant_centres(
    ctx: &ReportCtx,
    at: &[f64],
    (tracker, samples): (&Tracker, &[State]),
    json: &mut Map<String, Value>,
    text: &mut String,
) {
    let mut out = Vec::new();
    let mut worst = 0.0f64;
    for &s in at {
        let Some(st) = state_at(tracker, samples, s) else {
            continue;
        };
        let (c, e) = centres_at(ctx.l, &st, ctx.m.speed);
        worst = worst.max(e);
        let _ = writeln!(
            text,
            "instant centres at {:.4}{} (three-centres line within {e:.2e} m):",
            ctx.input(s),
            ctx.unit()
        );
        for p in &c {
            let _ = writeln!(
                text,
                "  {}: {}",
                p["label"].as_str().unwrap_or(""),
                match (&p["point"], &p["direction_at_infinity"]) {
                    (Value::Array(x), _) => format!(
                        "({:.6}, {:.6})",
                        x[0].as_f64().unwrap_or(f64::NAN),
                        x[1].as_f64().unwrap_or(f64::NAN)
                    ),
                    (_, Value::Array(d)) => format!(
                        "at infinity toward ({:.6}, {:.6})",
                        d[0].as_f64().unwrap_or(f64::NAN),
                        d[1].as_f64().unwrap_or(f64::NAN)
                    ),
                    _ => "undefined (no relative motion)".into(),
                }
            );
        }
        out.push(
            json!({ctx.input_key(): ctx.input(s), "centres": c, "three_centres_max_error": e}),
        );
    }
    json.insert(
        "instant_centres".into(),
        json!({"at": out, "three_centres_max_error": worst}),
    );
}
