//! Plots of the machine kinds a person would rather look at than read: a cam's pitch and
//! working profiles with its follower's `s, v, a, jerk` and pressure angle over the turn,
//! and each gear of a gear pair drawn whole from its computed tooth profile. Panels are
//! built from the kind's report JSON (the numbers the JSON states are the ones drawn)
//! and written atomically as `<out>/<name>_cam.png` / `<name>_gears.png` by
//! [`crate::scenarios::kit::write_plot`] when `armsim run --out DIR` is given.

use crate::io::plots::panels::{Panel, Series, PALETTE};
use serde_json::Value;

fn nums(v: &Value) -> Vec<f64> {
    v.as_array()
        .map(|a| a.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect())
        .unwrap_or_default()
}

fn pts(v: &Value) -> Vec<(f64, f64)> {
    v.as_array()
        .map(|a| {
            a.iter()
                .filter_map(|p| Some((p.get(0)?.as_f64()?, p.get(1)?.as_f64()?)))
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect()
        })
        .unwrap_or_default()
}

fn series(label: &str, points: Vec<(f64, f64)>, k: usize) -> Series {
    Series {
        label: label.into(),
        points,
        color: PALETTE[k % PALETTE.len()],
        dashed: false,
    }
}

fn over_turn(phi: &[f64], ys: &[f64]) -> Vec<(f64, f64)> {
    phi.iter()
        .zip(ys)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| (*x, *y))
        .collect()
}

/// A cam report's panels: the profiles (law cams), then `s`, `v`, `a`, jerk and the
/// pressure angle against the cam angle (what the report sampled).
pub fn cam_panels(j: &Value) -> Vec<Panel> {
    let smp = &j["samples"];
    let phi = nums(&smp["phi_deg"]);
    let mut out = Vec::new();
    let pitch = pts(&j["profile"]["pitch"]);
    if !pitch.is_empty() {
        out.push(Panel {
            title: "profile (cam frame)".into(),
            x_desc: "x".into(),
            y_desc: "y".into(),
            series: vec![
                series("pitch curve", pitch, 0),
                series("working profile", pts(&j["profile"]["working"]), 1),
            ],
            equal_aspect: true,
            ..Default::default()
        });
    }
    // An oscillating follower's s is its swing (rad); otherwise a length in the file's unit.
    let u = if j["follower_motion"] == "oscillating" {
        "rad"
    } else {
        "mm"
    };
    for (k, (key, title, unit)) in [
        ("s", "displacement s", u.to_string()),
        ("face_angle_deg", "face angle", "deg".into()),
        ("v", "velocity v", format!("{u}/s")),
        ("a", "acceleration a", format!("{u}/s²")),
        ("jerk", "jerk", format!("{u}/s³")),
        ("pressure_angle_deg", "pressure angle", "deg".into()),
    ]
    .iter()
    .enumerate()
    {
        let ys = nums(&smp[*key]);
        if ys.is_empty() {
            continue;
        }
        out.push(Panel {
            title: (*title).into(),
            x_desc: "cam angle φ (deg)".into(),
            y_desc: unit.clone(),
            series: vec![series(key, over_turn(&phi, &ys), k + 2)],
            ..Default::default()
        });
    }
    out
}

/// The whole outline of a gear from one tooth as the report lists it (the left flank
/// from tip to root, then the right flank from root to tip; the tooth on the +y axis):
/// each tooth is drawn root → tip → tip land → root, and the teeth follow clockwise.
fn gear_outline(tooth: &[(f64, f64)], z: usize) -> Vec<(f64, f64)> {
    let half = tooth.len() / 2;
    let one: Vec<(f64, f64)> = tooth[..half]
        .iter()
        .rev()
        .chain(tooth[half..].iter().rev())
        .copied()
        .collect();
    let mut out = Vec::with_capacity(tooth.len() * z + 1);
    for k in 0..z {
        let (s, c) = (-std::f64::consts::TAU * k as f64 / z as f64).sin_cos();
        out.extend(one.iter().map(|&(x, y)| (c * x - s * y, s * x + c * y)));
    }
    if let Some(&p) = out.first() {
        out.push(p);
    }
    out
}

/// The legend of a gear's outline by the pair's `type`.
fn outline_name(pair: &Value, gear: usize) -> &'static str {
    match (pair["type"].as_str().unwrap_or(""), gear) {
        ("cycloidal", _) => "cycloidal teeth",
        ("pin", 0) => "pins",
        ("pin", _) => "teeth (envelope of the pins)",
        ("roots", _) => "lobes",
        _ => "involute teeth",
    }
}

/// A gear-pair report's panels: each planar pair's gears (at most 8 panels), whole, with
/// their pitch circles.
pub fn pair_panels(j: &Value) -> Vec<Panel> {
    let mut out = Vec::new();
    for pair in j["pairs"].as_array().into_iter().flatten() {
        let label = pair["label"].as_str().unwrap_or("pair");
        for (i, g) in pair["gears"].as_array().into_iter().flatten().enumerate() {
            let tooth = pts(&g["tooth_profile"]);
            let z = g["teeth"].as_u64().unwrap_or(0) as usize;
            if tooth.is_empty() || z == 0 || z > 1000 || out.len() >= 8 {
                continue;
            }
            let r = g["pitch_radius"].as_f64().unwrap_or(0.0);
            let circle = (0..=180)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / 180.0;
                    (r * t.cos(), r * t.sin())
                })
                .collect();
            out.push(Panel {
                title: format!("{label}: gear {} (z = {z})", i + 1),
                x_desc: "x (mm)".into(),
                y_desc: "y (mm)".into(),
                series: vec![
                    series(outline_name(pair, i), gear_outline(&tooth, z), 0),
                    Series {
                        dashed: true,
                        ..series("pitch circle", circle, 1)
                    },
                ],
                equal_aspect: true,
                ..Default::default()
            });
        }
    }
    out
}
