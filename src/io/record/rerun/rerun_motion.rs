//! The robot's motion in Rerun: each link's world pose per frame, the skeleton from
//! parent to child origins, and the tool link's path.

use crate::core::spatial::Se3;
use crate::io::record::rerun::rerun_entities::{
    f32x3, link_entity, path, quat_xyzw, sdk, send_timed,
};
use crate::io::record::rerun::rerun_sink::{RerunError, RerunReport};
use crate::io::record::rerun::rerun_tree::Tree;
use rerun::{archetypes, RecordingStream};

pub(super) fn log_links(
    stream: &RecordingStream,
    tree: &Tree,
    times: &[f64],
    posed: &[(Vec<Se3>, Vec<Option<usize>>)],
    report: &mut RerunReport,
) -> Result<(), RerunError> {
    for (i, name) in tree.names.iter().enumerate() {
        let ent = link_entity(name);
        report.links.push(ent.to_string());
        stream
            .log_static(ent.clone(), &archetypes::TransformAxes3D::new(0.05))
            .map_err(sdk)?;
        let has_tf = tree.moving[i] || tree.statics[i].is_some();
        if !has_tf {
            continue;
        }
        if times.is_empty() {
            let m = &posed[0].0[i];
            stream
                .log_static(
                    ent,
                    &archetypes::Transform3D::from_translation_rotation(
                        f32x3(&m.trans),
                        rerun::Quaternion::from_xyzw(quat_xyzw(&m.rot)),
                    ),
                )
                .map_err(sdk)?;
            continue;
        }
        report.moving_links += 1;
        let tr: Vec<[f32; 3]> = posed.iter().map(|(w, _)| f32x3(&w[i].trans)).collect();
        let qs: Vec<rerun::Quaternion> = posed
            .iter()
            .map(|(w, _)| rerun::Quaternion::from_xyzw(quat_xyzw(&w[i].rot)))
            .collect();
        let cols = archetypes::Transform3D::update_fields()
            .with_many_translation(tr)
            .with_many_quaternion(qs)
            .columns_of_unit_batches()
            .map_err(sdk)?;
        send_timed(stream, ent, times.iter().copied(), cols)?;
    }
    Ok(())
}

pub(super) fn log_skeleton(
    stream: &RecordingStream,
    times: &[f64],
    posed: &[(Vec<Se3>, Vec<Option<usize>>)],
) -> Result<(), RerunError> {
    let strips_of = |(w, parent): &(Vec<Se3>, Vec<Option<usize>>)| -> Vec<[[f32; 3]; 2]> {
        parent
            .iter()
            .enumerate()
            .filter_map(|(c, p)| {
                let p = (*p)?;
                let (a, b) = (w[p].trans, w[c].trans);
                ((a - b).norm() > 1e-9).then(|| [f32x3(&a), f32x3(&b)])
            })
            .collect()
    };
    let ent = path(&["world", "robot", "skeleton"]);
    let style = |s: archetypes::LineStrips3D| {
        s.with_radii([0.006f32])
            .with_colors([rerun::Color::from_rgb(230, 160, 40)])
    };
    if times.is_empty() {
        let strips = strips_of(&posed[0]);
        if !strips.is_empty() {
            stream
                .log_static(ent, &style(archetypes::LineStrips3D::new(strips)))
                .map_err(sdk)?;
        }
        return Ok(());
    }
    let per: Vec<Vec<[[f32; 3]; 2]>> = posed.iter().map(strips_of).collect();
    let lengths: Vec<usize> = per.iter().map(Vec::len).collect();
    if lengths.iter().all(|&l| l == 0) {
        return Ok(());
    }
    stream
        .log_static(
            ent.clone(),
            &style(archetypes::LineStrips3D::update_fields()),
        )
        .map_err(sdk)?;
    let cols = archetypes::LineStrips3D::update_fields()
        .with_strips(per.into_iter().flatten())
        .columns(lengths)
        .map_err(sdk)?;
    send_timed(stream, ent, times.iter().copied(), cols)
}

/// The deepest link with a transform (the last in order among ties).
pub(super) fn tool_link(tree: &Tree, parent: &[Option<usize>]) -> Option<usize> {
    let n = tree.names.len();
    let depth = |mut i: usize| {
        let mut d = 0usize;
        while let Some(p) = parent[i] {
            d += 1;
            i = p;
            if d > n {
                break;
            }
        }
        d
    };
    let mut best: Option<(usize, usize)> = None;
    for i in 0..n {
        if !(tree.moving[i] || tree.statics[i].is_some()) {
            continue;
        }
        let d = depth(i);
        if best.is_none_or(|(bd, _)| d >= bd) {
            best = Some((d, i));
        }
    }
    best.map(|(_, i)| i)
}

pub(super) fn log_tool_path(
    stream: &RecordingStream,
    tree: &Tree,
    posed: &[(Vec<Se3>, Vec<Option<usize>>)],
) -> Result<Option<String>, RerunError> {
    let Some(tool) = tool_link(tree, &posed[0].1) else {
        return Ok(None);
    };
    if posed.len() >= 2 {
        let pts: Vec<[f32; 3]> = posed.iter().map(|(w, _)| f32x3(&w[tool].trans)).collect();
        stream
            .log_static(
                "world/tool_path",
                &archetypes::LineStrips3D::new([pts])
                    .with_radii([0.004f32])
                    .with_colors([rerun::Color::from_rgb(255, 120, 0)])
                    .with_labels([format!("{} path", tree.names[tool])]),
            )
            .map_err(sdk)?;
    }
    Ok(Some(tree.names[tool].clone()))
}
