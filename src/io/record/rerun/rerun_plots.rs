//! The recording's data besides the motion, in Rerun: joint position and torque plots
//! with their effort limits, workspace clouds, collision boxes and log rows, and the
//! markdown reports.

use crate::io::record::rerun::rerun_entities::{child, link_entity, path, sdk, send_timed};
use crate::io::record::rerun::rerun_geometry::Aabb;
use crate::io::record::rerun::rerun_sink::{colormap, TIMELINE};
use crate::io::record::rerun::rerun_sink::{RerunError, RerunReport};
use crate::io::record::rerun::rerun_tree::Tree;
use crate::io::record::{CollisionEvent, Frame, Recording};
use rerun::{archetypes, components::FillMode, EntityPath, RecordingStream};
use std::collections::{BTreeMap, HashMap};

/// Text log rows at time `t` (temporal, so that every row is kept).
pub(super) fn log_texts(
    stream: &RecordingStream,
    ent: &str,
    t: f64,
    texts: &[String],
    level: &str,
) -> Result<(), RerunError> {
    if texts.is_empty() {
        return Ok(());
    }
    let cols = archetypes::TextLog::update_fields()
        .with_many_text(texts.iter().cloned())
        .with_many_level(std::iter::repeat_n(level, texts.len()))
        .columns_of_unit_batches()
        .map_err(sdk)?;
    send_timed(stream, ent, vec![t; texts.len()], cols)
}

pub(super) fn log_joint_plots(
    stream: &RecordingStream,
    rec: &Recording,
    frames: &[&Frame],
) -> Result<(), RerunError> {
    if frames.is_empty() {
        return Ok(());
    }
    let series = |field: fn(&Frame) -> &Vec<f64>, k: usize| -> (Vec<f64>, Vec<f64>) {
        frames
            .iter()
            .filter_map(|f| field(f).get(k).map(|&v| (f.t, v)))
            .unzip()
    };
    let send = |ent: EntityPath, t: Vec<f64>, v: Vec<f64>| -> Result<(), RerunError> {
        if t.is_empty() {
            return Ok(());
        }
        let cols = archetypes::Scalars::new(v)
            .columns_of_unit_batches()
            .map_err(sdk)?;
        send_timed(stream, ent, t, cols)
    };
    let (t0, t1) = (frames[0].t, frames[frames.len() - 1].t);
    let style = |ent: &EntityPath, name: String, rgb: [u8; 3]| {
        stream
            .log_static(
                ent.clone(),
                &archetypes::SeriesLines::new()
                    .with_names([name])
                    .with_colors([rerun::Color::from_rgb(rgb[0], rgb[1], rgb[2])]),
            )
            .map_err(sdk)
    };
    for (k, joint) in rec.header.joint_names.iter().enumerate() {
        let (t, v) = series(|f| &f.tau, k);
        if !t.is_empty() {
            let ent = path(&["plots", "torque", joint]);
            style(&ent, format!("τ {joint}"), [40, 120, 220])?;
            send(ent.clone(), t, v)?;
            if let Some(&Some(lim)) = rec.header.effort_limits.get(k) {
                if lim.is_finite() {
                    let ts = if t1 > t0 { vec![t0, t1] } else { vec![t0] };
                    for (part, sign) in [("upper_limit", 1.0), ("lower_limit", -1.0)] {
                        let e = child(&ent, part);
                        let name = if sign > 0.0 { "+limit" } else { "-limit" };
                        style(&e, name.to_string(), [220, 40, 40])?;
                        send(e, ts.clone(), vec![sign * lim; ts.len()])?;
                    }
                }
            }
        }
        let (t, v) = series(|f| &f.q, k);
        if !t.is_empty() {
            let ent = path(&["plots", "q", joint]);
            style(&ent, joint.clone(), [60, 160, 90])?;
            send(ent, t, v)?;
        }
    }
    Ok(())
}

/// Logs the clouds; returns one line per coloured cloud (its value range).
pub(super) fn log_clouds(
    stream: &RecordingStream,
    rec: &Recording,
    tree: &Tree,
    report: &mut RerunReport,
    warnings: &mut Vec<String>,
) -> Result<Vec<String>, RerunError> {
    let mut info = Vec::new();
    for (i, c) in rec.clouds.iter().enumerate() {
        let name = format!("cloud_{i}");
        let ent = match tree.index.get(&c.frame) {
            Some(_) => child(&link_entity(&c.frame), &name),
            None => path(&["world", "workspace", &name]),
        };
        let pts: Vec<[f32; 3]> = c.points.clone();
        let finite: Vec<f32> = c.values.iter().copied().filter(|v| v.is_finite()).collect();
        let lo = finite.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = finite.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let mut arch = archetypes::Points3D::new(pts).with_radii([0.004f32]);
        if c.values.len() == c.points.len() && !finite.is_empty() {
            let span = if hi > lo { hi - lo } else { 1.0 };
            let colors: Vec<rerun::Color> = c
                .values
                .iter()
                .map(|v| {
                    let [r, g, b] = colormap((v - lo) / span);
                    rerun::Color::from_rgb(r, g, b)
                })
                .collect();
            arch = arch.with_colors(colors);
            info.push(format!(
                "{ent}: {} points, value {lo:.6} (dark violet) … {hi:.6} (yellow)",
                c.points.len()
            ));
        } else if !c.values.is_empty() {
            warnings.push(format!(
                "{ent}: {} values for {} points (or none finite); drawn uncoloured",
                c.values.len(),
                c.points.len()
            ));
        }
        if c.t.is_finite() && !rec.frames.is_empty() {
            stream.set_duration_secs(TIMELINE, c.t);
            stream.log(ent, &arch).map_err(sdk)?;
            stream.reset_time();
        } else {
            stream.log_static(ent, &arch).map_err(sdk)?;
        }
        report.points += c.points.len();
    }
    Ok(info)
}

pub(super) fn log_collisions(
    stream: &RecordingStream,
    events: &[CollisionEvent],
    tree: &Tree,
    times: &[f64],
    boxes: &HashMap<usize, Aabb>,
) -> Result<(), RerunError> {
    // Event times per link, sorted.
    let mut per_link: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
    for e in events.iter().filter(|e| e.t.is_finite()) {
        stream.set_duration_secs(TIMELINE, e.t);
        stream
            .log(
                "log/collisions",
                &archetypes::TextLog::new(format!("collision: {} ↔ {}", e.body_a, e.body_b))
                    .with_level(rerun::TextLogLevel::WARN),
            )
            .map_err(sdk)?;
        for b in [&e.body_a, &e.body_b] {
            if let Some(&i) = tree.index.get(b) {
                per_link.entry(i).or_default().push(e.t);
            }
        }
    }
    for (i, mut ts) in per_link {
        ts.sort_by(f64::total_cmp);
        ts.dedup();
        let ent = child(&link_entity(&tree.names[i]), "collision");
        let (lo, hi) = boxes.get(&i).copied().unwrap_or(([-0.03; 3], [0.03; 3]));
        let pad = 0.01;
        let marker = archetypes::Boxes3D::from_mins_and_sizes(
            [[
                (lo[0] - pad) as f32,
                (lo[1] - pad) as f32,
                (lo[2] - pad) as f32,
            ]],
            [[
                (hi[0] - lo[0] + 2.0 * pad) as f32,
                (hi[1] - lo[1] + 2.0 * pad) as f32,
                (hi[2] - lo[2] + 2.0 * pad) as f32,
            ]],
        )
        .with_colors([rerun::Color::from_rgb(255, 0, 0)])
        .with_radii([0.004f32])
        .with_fill_mode(FillMode::MajorWireframe);
        for (k, &t) in ts.iter().enumerate() {
            stream.set_duration_secs(TIMELINE, t);
            stream.log(ent.clone(), &marker).map_err(sdk)?;
            // Clear at the next frame time that is not itself a collision time.
            let next_event = ts.get(k + 1).copied().unwrap_or(f64::INFINITY);
            if let Some(&tc) = times.iter().find(|&&x| x > t) {
                if tc < next_event {
                    stream.set_duration_secs(TIMELINE, tc);
                    stream
                        .log(ent.clone(), &archetypes::Boxes3D::clear_fields())
                        .map_err(sdk)?;
                }
            }
        }
    }
    stream.reset_time();
    Ok(())
}

pub(super) fn log_reports(stream: &RecordingStream, rec: &Recording) -> Result<(), RerunError> {
    let h = &rec.header;
    let mut md = format!(
        "# {}\n\n",
        if h.name.is_empty() {
            "recording"
        } else {
            &h.name
        }
    );
    md.push_str(&format!(
        "{} frames, {} joints, {} clouds, {} collision events\n\n",
        rec.frames.len(),
        h.joint_names.len(),
        rec.clouds.len(),
        rec.collisions.len()
    ));
    for (k, v) in &h.metadata {
        md.push_str(&format!("- **{k}**: {v}\n"));
    }
    stream
        .log_static(
            "reports/header",
            &archetypes::TextDocument::from_markdown(md),
        )
        .map_err(sdk)?;
    if !rec.torque_check.is_empty() {
        let opt = |x: Option<f64>, p: usize| x.map_or("–".to_string(), |v| format!("{v:.p$}"));
        let mut md = String::from(
            "| joint | peak τ | rms τ | peak speed | peak power | limit | margin % | ok | first violation (s) |\n\
             |---|---|---|---|---|---|---|---|---|\n",
        );
        for r in &rec.torque_check {
            md.push_str(&format!(
                "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {} | {} |\n",
                r.joint,
                r.peak_torque,
                r.rms_torque,
                r.peak_speed,
                r.peak_power,
                opt(r.limit, 3),
                opt(r.margin, 1),
                if r.ok { "yes" } else { "**NO**" },
                opt(r.first_violation, 4)
            ));
        }
        stream
            .log_static(
                "reports/torque_check",
                &archetypes::TextDocument::from_markdown(md),
            )
            .map_err(sdk)?;
    }
    Ok(())
}
