//! The `[[connected_bodies]]` tables of a `kind = "friction"` file (format in
//! `docs/machines.md`): bodies on planes joined by ropes over pulleys, read and checked
//! here and solved by [`crate::machines::friction::connected_bodies`].

use crate::core::diag::LocatedError as ScenarioError;
use crate::machines::friction::connected_bodies::{Chain, ChainMotion, Moving, RopedBody};
use crate::scenarios::source::{in_range, Source};
use serde::Deserialize;
use serde_json::{json, Value};
use toml::Spanned;

/// One `[[connected_bodies]]` table.
#[derive(Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct BodiesSpec {
    label: Option<String>,
    masses: Option<Vec<f64>>,
    weights: Option<Vec<f64>>,
    #[serde(default)]
    slopes_deg: Vec<f64>,
    friction: Option<Vec<f64>>,
    static_friction: Option<Vec<f64>>,
    rotating_masses: Option<Vec<f64>>,
    forces: Option<Vec<f64>>,
    pulley_efficiency: Option<Vec<f64>>,
    gravity: Option<f64>,
    push_body: Option<usize>,
}

/// The most bodies in one chain.
const MAX_BODIES: usize = 1000;

/// Reads, checks and solves the `i`-th chain: its JSON and a line of text.
pub(crate) fn chain(
    cx: &Source,
    i: usize,
    s: &Spanned<BodiesSpec>,
) -> Result<(Value, String), ScenarioError> {
    let e = s.get_ref();
    let err = |k: &str, m: String| cx.field(s.span(), k, format!("connected_bodies[{i}].{k}"), m);
    let g = match e.gravity {
        None => 9.81,
        Some(x) if in_range(x, 1e-6, 1e3) => x,
        Some(x) => return Err(err("gravity", format!("must be in [1e-6, 1000], got {x}"))),
    };
    let masses = match (&e.masses, &e.weights) {
        (Some(m), None) => m.clone(),
        (None, Some(w)) => w.iter().map(|w| w / g).collect(),
        _ => {
            return Err(err(
                "masses",
                "give masses (kg) or weights (N), one of the two".into(),
            ))
        }
    };
    let n = masses.len();
    if !(2..=MAX_BODIES).contains(&n) {
        let k = if e.masses.is_some() {
            "masses"
        } else {
            "weights"
        };
        return Err(err(
            k,
            format!("a chain has 2 to {MAX_BODIES} bodies, got {n}"),
        ));
    }
    // Every list: its length and range.
    let list = |k: &str, v: Option<&Vec<f64>>, len: usize, lo: f64, hi: f64, default: f64| {
        let Some(v) = v else {
            return Ok(vec![default; len]);
        };
        if v.len() != len {
            return Err(err(k, format!("has {} values, expected {len}", v.len())));
        }
        match v.iter().find(|&&x| !in_range(x, lo, hi)) {
            Some(x) => Err(err(
                k,
                format!("every value must be in [{lo}, {hi}], got {x}"),
            )),
            None => Ok(v.clone()),
        }
    };
    let key = if e.masses.is_some() {
        "masses"
    } else {
        "weights"
    };
    let hi = if e.masses.is_some() { 1e9 } else { 1e9 * g };
    list(
        key,
        e.masses.as_ref().or(e.weights.as_ref()),
        n,
        0.0,
        hi,
        0.0,
    )?;
    if e.slopes_deg.is_empty() {
        return Err(err(
            "slopes_deg",
            "missing: each body's path below the horizontal moving forward (deg; 90 = falling, −30 = pulled up a 30° incline)".into(),
        ));
    }
    let slopes = list("slopes_deg", Some(&e.slopes_deg), n, -90.0, 90.0, 0.0)?;
    let friction = list("friction", e.friction.as_ref(), n, 0.0, 2.0, 0.0)?;
    let stat = match &e.static_friction {
        None => friction.clone(),
        Some(v) => list("static_friction", Some(v), n, 0.0, 2.0, 0.0)?,
    };
    if let Some(k) = (0..n).find(|&k| stat[k] < friction[k]) {
        return Err(err(
            "static_friction",
            format!(
                "body {k}: the static coefficient {} is below the kinetic one {}",
                stat[k], friction[k]
            ),
        ));
    }
    let rot = list(
        "rotating_masses",
        e.rotating_masses.as_ref(),
        n,
        0.0,
        1e9,
        0.0,
    )?;
    let forces = list("forces", e.forces.as_ref(), n, -1e12, 1e12, 0.0)?;
    let eta = list(
        "pulley_efficiency",
        e.pulley_efficiency.as_ref(),
        n - 1,
        1e-3,
        1.0,
        1.0,
    )?;
    if masses.iter().zip(&rot).all(|(m, r)| m + r <= 0.0) {
        return Err(err(key, "the bodies have no mass".into()));
    }
    let push = match e.push_body {
        None => n - 1,
        Some(p) if p < n => p,
        Some(p) => {
            return Err(err(
                "push_body",
                format!("must be a body index 0..{}, got {p}", n - 1),
            ))
        }
    };
    let c = Chain {
        bodies: (0..n)
            .map(|k| RopedBody {
                mass: masses[k],
                slope: slopes[k].to_radians(),
                friction: friction[k],
                static_friction: stat[k],
                rotating_mass: rot[k],
                force: forces[k],
            })
            .collect(),
        pulley_efficiency: eta,
        gravity: g,
    };
    let label = e
        .label
        .clone()
        .unwrap_or_else(|| format!("chain {}", i + 1));
    report(&c, label, push).map_err(|m| err("slopes_deg", m))
}

/// The JSON of one way of moving, and whether every rope stays taut.
fn moving_json(m: &Moving) -> (Value, bool) {
    let taut = m.tensions.iter().flatten().all(|&t| t >= -1e-9);
    (
        json!({"acceleration_mps2": m.acceleration, "tensions_N": m.tensions, "ropes_taut": taut}),
        taut,
    )
}

/// The chain's report: the motion from rest, the forces that start it and keep it
/// moving uniformly, and each way of moving. `Err` when the motion from rest would slacken
/// a rope.
fn report(c: &Chain, label: String, push: usize) -> Result<(Value, String), String> {
    let motion = c.motion_from_rest();
    let (fwd, bwd) = (c.moving(1.0), c.moving(-1.0));
    let (fj, ft) = moving_json(&fwd);
    let (bj, bt) = moving_json(&bwd);
    let mut v = json!({"label": label, "type": "connected_bodies",
        "normal_N": c.normals(), "driving_N": c.driving(),
        "motion": match motion { ChainMotion::Forward => "forward", ChainMotion::Backward => "backward", ChainMotion::Rest => "rest" },
        "push_body": push,
        "start_forward_N": c.force_to_move(push, 1.0, true),
        "start_backward_N": c.force_to_move(push, -1.0, true),
        "uniform_forward_N": c.force_to_move(push, 1.0, false),
        "uniform_backward_N": c.force_to_move(push, -1.0, false),
        "forward": fj, "backward": bj});
    let now = match motion {
        ChainMotion::Forward if !ft => return Err("moving forward a rope goes slack (negative tension): the bodies do not move as one chain; check the slopes' signs".into()),
        ChainMotion::Backward if !bt => return Err("moving backward a rope goes slack (negative tension): the bodies do not move as one chain; check the slopes' signs".into()),
        ChainMotion::Forward => Some(&fwd),
        ChainMotion::Backward => Some(&bwd),
        ChainMotion::Rest => None,
    };
    let text = match now {
        Some(m) => {
            v["acceleration_mps2"] = json!(m.acceleration);
            v["tensions_N"] = json!(m.tensions);
            v["resistance_N"] = json!(m.resistances);
            let t: Vec<String> = m
                .tensions
                .iter()
                .map(|[b, f]| format!("{b:.3}/{f:.3}"))
                .collect();
            format!(
                "moves {}: a = {:.6} m/s², rope tensions (back/front end) {} N",
                v["motion"].as_str().unwrap_or(""),
                m.acceleration,
                t.join(", ")
            )
        }
        None => {
            v["acceleration_mps2"] = json!(0.0);
            format!(
                "at rest: to start it forward {:.4} N, backward {:.4} N at body {push}",
                c.force_to_move(push, 1.0, true),
                c.force_to_move(push, -1.0, true)
            )
        }
    };
    Ok((v, text))
}
