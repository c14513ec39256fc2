//! The workspace picture in Rerun (`armsim workspace --rerun`): a cut-away view of the
//! reachable set, so that a person sees its shape, how mobile the arm is where, and the
//! robot inside it.
//!
//! | entity                                  | what                                                 |
//! |-----------------------------------------|------------------------------------------------------|
//! | `world/workspace/boundary/back`         | the boundary surface outside the cut-away (static)   |
//! | `world/workspace/boundary/front`        | the cut-away quarter of it, hidden (switch it on)    |
//! | `world/workspace/section`               | the voxel layers through the base axis bounding it   |
//! | `world/workspace/points`                | the kept samples, hidden                             |
//! | `world/workspace/legend`, `…/labels`    | the colour bar and its values                        |
//! | `world/workspace/labels`                | what the surface and the section are                 |
//! | `world/robot/…`                         | the robot with its meshes at a representative pose   |
//! | `reports/workspace`                     | the figures of the run and the colour scale          |
//!
//! Geometry from [`crate::workspace::picture_geometry`]; colours: mean translational manipulability
//! per voxel on the viridis map ([`colormap`]), 0 to the largest voxel mean. The camera
//! looks into the cut-away quarter from above, at the whole workspace, with the robot
//! standing in that quarter. A planar workspace has no boundary surface: its points are
//! shown.

use crate::core::spatial::Vec3;
use crate::io::record::rerun::rerun_blueprint::{send_workspace, Eye};
use crate::io::record::rerun::rerun_entities::{path, sdk};
use crate::io::record::rerun::rerun_geometry::vertex_normals;
use crate::io::record::rerun::rerun_recording::log_with;
use crate::io::record::rerun::rerun_sink::colormap;
use crate::io::record::rerun::rerun_sink::{RerunError, RerunReport, RerunSink};
use crate::io::record::rerun::rerun_stream::{check_sink, finish, open};
use crate::io::record::{Header, Recording};
use crate::model::data::Data;
use crate::model::Model;
use crate::workspace::picture_geometry::{
    base_axis, representative_pose, Cutaway, Occupancy, ScalarMesh,
};
use crate::workspace::WorkspaceResult;
use rerun::{archetypes, RecordingStream};
use std::path::Path;

/// Above this many holes per occupied cell ([`Occupancy::hole_fraction`]) the occupancy
/// is drawn on a coarser grid.
pub const SPECKLE: f64 = 0.02;

/// Entity of the kept samples (hidden in the blueprint).
pub const POINTS: &str = "/world/workspace/points";
/// Entity of the cut-away half of the boundary (hidden in the blueprint).
pub const FRONT: &str = "/world/workspace/boundary/front";

/// Logs the workspace picture of `ws` (sampled on `model`, read from `model.source`)
/// to `sink`.
pub fn log_workspace_scene(
    model: &Model,
    ws: &WorkspaceResult,
    sink: &RerunSink,
) -> Result<RerunReport, RerunError> {
    check_sink(sink)?;
    let source = Path::new(&model.source);
    let mut warnings = Vec::new();
    let spec = match Model::read_spec(source) {
        Ok(s) => Some(s),
        Err(e) => {
            warnings.push(format!("robot geometry not drawn: {e}"));
            None
        }
    };
    let (occ, coarsened) = drawable_occupancy(ws, &mut warnings);
    let (base, axis) = base_axis(model, &ws.tool).unwrap_or((Vec3::zeros(), Vec3::z()));
    let cut = Cutaway::new(base, &axis);
    let pose = representative_pose(model, ws, &cut);
    let q = pose.clone().unwrap_or_else(|| model.neutral());
    let title = format!("{} workspace", model.name);
    let rec = robot_recording(model, ws, spec.as_ref(), &q, &title);
    let (stream, storage) = open(sink, &title)?;
    let (mut report, _) = log_with(&stream, &rec, spec.as_ref(), None, warnings)?;

    let scale = colour_scale(occ.as_ref(), ws);
    let color = |v: f32| {
        let [r, g, b] = colormap(if scale > 0.0 { v / scale } else { f32::NAN });
        rerun::Color::from_rgb(r, g, b)
    };
    log_points(&stream, ws, &color)?;
    report.points = ws.points.len();
    let mut lo = ws.bbox[0];
    let mut hi = ws.bbox[1];
    let mut hidden = vec![POINTS];
    let mut lines = Vec::new();
    if let Some(occ) = &occ {
        let (front, back) = occ.boundary_mesh().cut(&cut);
        log_mesh(&stream, "world/workspace/boundary/back", &back, 255, &color)?;
        log_mesh(&stream, FRONT, &front, 255, &color)?;
        hidden.push(FRONT);
        let section = occ.cutaway_section(&cut);
        log_mesh(&stream, "world/workspace/section", &section, 255, &color)?;
        let [u, v] = cut.across.map(|k| ["x", "y", "z"][k]);
        lines.push(format!(
            "- **boundary**: the surface of the reachable set ({} occupied voxels of {} m{}, \
             surface nets); the quarter {u} < {:.3} m, {v} < {:.3} m is cut away \
             (`{FRONT}`, hidden: switch it on in the blueprint panel)",
            occ.count(),
            occ.h,
            if coarsened > 0 {
                format!(
                    ", the run's {} m voxels merged by {}: too few samples per voxel for a \
                     surface",
                    ws.voxel,
                    1 << coarsened
                )
            } else {
                String::new()
            },
            cut.base[cut.across[0]],
            cut.base[cut.across[1]],
        ));
        lines.push(format!(
            "- **section**: the occupied voxels of the layers through the base axis that \
             bound the cut ({} voxels)",
            section.triangles.len() / 2
        ));
        let (llo, lhi) = log_legend(&stream, ws, &cut, scale, &color)?;
        for k in 0..3 {
            lo[k] = lo[k].min(llo[k]);
            hi[k] = hi[k].max(lhi[k]);
        }
    } else {
        hidden.clear();
    }
    lines.push(format!(
        "- **colour**: mean translational manipulability w = σ₁σ₂σ₃ of the tool point's \
         Jacobian over the samples in each voxel, viridis from 0 (dark violet) to {scale:.4} \
         m³/rad³ (yellow)"
    ));
    lines.push(match &pose {
        Some(_) => "- **robot**: at a representative pose, the most mobile kept sample whose \
                    tool and links lie in the cut-away quarter"
            .to_string(),
        None => "- **robot**: at its neutral pose".to_string(),
    });
    lines.push(format!(
        "- **points**: the {} kept samples (`{POINTS}`, hidden)",
        ws.points.len()
    ));
    log_doc(&stream, model, ws, &lines)?;
    let dir = camera_direction(&cut);
    let eye = Eye::framing_from(lo, hi, dir, 0.7);
    let view = format!(
        "{}: reachable boundary and section through the base, coloured by manipulability",
        title
    );
    let skeleton: &[&str] = if report.visuals > 0 {
        &["/world/robot/skeleton"]
    } else {
        &[]
    };
    send_workspace(&stream, &view, skeleton, &hidden, eye)?;
    report.bytes = finish(&stream, storage, sink)?;
    Ok(report)
}

/// The occupancy grid to draw, coarsened (at most four times, counted) while too few
/// samples per voxel make a speckle of a surface; `None` (with a warning) when there is
/// none to draw.
fn drawable_occupancy(
    ws: &WorkspaceResult,
    warnings: &mut Vec<String>,
) -> (Option<Occupancy>, u32) {
    let mut occ = Occupancy::from_workspace(ws);
    // Too few samples for the voxel make a speckle of a surface: draw the grid coarsened
    // until it is solid (at most four times).
    let mut coarsened = 0;
    while let Some(o) = occ
        .as_ref()
        .filter(|o| coarsened < 4 && o.hole_fraction() > SPECKLE)
    {
        occ = Some(o.coarsened());
        coarsened += 1;
    }
    if occ.is_none() {
        warnings.push(if ws.planar {
            "planar workspace: drawn as its sample points".to_string()
        } else {
            "occupancy grid too large to draw: only the sample points are shown".to_string()
        });
    }
    (occ, coarsened)
}

/// A one-frame recording of the robot at `q` (frames only when its geometry was read),
/// with the workspace's provenance in the header.
fn robot_recording(
    model: &Model,
    ws: &WorkspaceResult,
    spec: Option<&crate::model::ModelSpec>,
    q: &[f64],
    title: &str,
) -> Recording {
    let source = Path::new(&model.source);
    let (mut header, robot_tf) = match spec {
        Some(s) => {
            let (h, tf) = Header::for_model(title.to_string(), source, model, s);
            (h, Some(tf))
        }
        None => (
            Header {
                name: title.to_string(),
                ..Default::default()
            },
            None,
        ),
    };
    header.metadata = vec![
        ("robot".into(), model.name.clone()),
        ("model_source".into(), model.source.clone()),
        ("workspace_tool".into(), ws.tool.clone()),
    ];
    let frames = match &robot_tf {
        Some(tf) => vec![tf.frame_at(model, &mut Data::new(model), 0.0, q, &[], &[])],
        None => Vec::new(),
    };
    Recording {
        header,
        frames,
        ..Default::default()
    }
}

/// The top of the colour scale: the grid's largest voxel value, else the largest finite
/// sample manipulability.
fn colour_scale(occ: Option<&Occupancy>, ws: &WorkspaceResult) -> f32 {
    occ.map_or_else(
        || {
            ws.points
                .iter()
                .map(|p| p.manipulability as f32)
                .filter(|v| v.is_finite())
                .fold(0.0, f32::max)
        },
        Occupancy::max_value,
    )
}

/// Into the removed quarter, from above.
fn camera_direction(cut: &Cutaway) -> [f64; 3] {
    let mut d = [0.0; 3];
    for k in cut.across {
        d[k] = -1.0;
    }
    d[2] += 0.9;
    d
}

/// The unit vector to the right of the image for a camera looking along `-dir`.
fn right_of(dir: [f64; 3]) -> Vec3 {
    let d = Vec3::from(dir);
    let r = -d.cross(&Vec3::z());
    r / r.norm().max(1e-12)
}

fn log_points(
    stream: &RecordingStream,
    ws: &WorkspaceResult,
    color: &dyn Fn(f32) -> rerun::Color,
) -> Result<(), RerunError> {
    if ws.points.is_empty() {
        return Ok(());
    }
    let pts: Vec<[f32; 3]> = ws.points.iter().map(|s| s.p.map(|x| x as f32)).collect();
    let colors: Vec<rerun::Color> = ws
        .points
        .iter()
        .map(|s| color(s.manipulability as f32))
        .collect();
    stream
        .log_static(
            POINTS,
            &archetypes::Points3D::new(pts)
                .with_radii([0.004f32])
                .with_colors(colors),
        )
        .map_err(sdk)
}

/// Logs `mesh` with per-vertex colours and opacity `alpha`.
fn log_mesh(
    stream: &RecordingStream,
    ent: &str,
    mesh: &ScalarMesh,
    alpha: u8,
    color: &dyn Fn(f32) -> rerun::Color,
) -> Result<(), RerunError> {
    if mesh.triangles.is_empty() {
        return Ok(());
    }
    let tris = mesh.triangles.clone();
    let normals = vertex_normals(&mesh.vertices, &tris);
    let colors: Vec<rerun::Color> = mesh.values.iter().map(|&v| color(v)).collect();
    stream
        .log_static(
            ent,
            &archetypes::Mesh3D::new(mesh.vertices.clone())
                .with_triangle_indices(tris)
                .with_vertex_normals(normals)
                .with_vertex_colors(colors)
                .with_albedo_factor([255, 255, 255, alpha]),
        )
        .map_err(sdk)
}

/// The colour bar beside the workspace (to the right of the image) with its values, and
/// the labels of the surface and the section. Returns the box it occupies.
fn log_legend(
    stream: &RecordingStream,
    ws: &WorkspaceResult,
    cut: &Cutaway,
    scale: f32,
    color: &dyn Fn(f32) -> rerun::Color,
) -> Result<([f64; 3], [f64; 3]), RerunError> {
    let [lo, hi] = ws.bbox;
    let c = Vec3::new(
        0.5 * (lo[0] + hi[0]),
        0.5 * (lo[1] + hi[1]),
        0.5 * (lo[2] + hi[2]),
    );
    let right = right_of(camera_direction(cut));
    let half = (0..3)
        .map(|k| 0.5 * (hi[k] - lo[k]) * right[k].abs())
        .sum::<f64>();
    let size = (hi[2] - lo[2]).max(0.2);
    let foot = c + right * (half + 0.05 * size);
    let (z0, z1) = (lo[2] + 0.1 * size, hi[2] - 0.1 * size);
    let steps = 32;
    let dz = (z1 - z0) / steps as f64;
    let w = (0.04 * size) as f32;
    let mut centers = Vec::with_capacity(steps);
    let mut colors = Vec::with_capacity(steps);
    for k in 0..steps {
        let z = z0 + (k as f64 + 0.5) * dz;
        centers.push([foot.x as f32, foot.y as f32, z as f32]);
        colors.push(color(scale * (k as f32 + 0.5) / steps as f32));
    }
    stream
        .log_static(
            "world/workspace/legend",
            &archetypes::Boxes3D::from_centers_and_sizes(centers, vec![[w, w, dz as f32]; steps])
                .with_colors(colors)
                .with_fill_mode(rerun::components::FillMode::Solid),
        )
        .map_err(sdk)?;
    let at = |f: f64, z: f64| {
        let p = foot + right * f;
        [p.x as f32, p.y as f32, z as f32]
    };
    let side = 0.06 * size;
    let ticks = [0.0f32, 0.5, 1.0];
    let mut pos: Vec<[f32; 3]> = ticks
        .iter()
        .map(|&t| at(side, z0 + t as f64 * (z1 - z0)))
        .collect();
    let mut text: Vec<String> = ticks
        .iter()
        .map(|&t| format!("w = {:.3}", t * scale))
        .collect();
    pos.push(at(0.0, z1 + 0.06 * size));
    text.push("manipulability w (m³/rad³)".into());
    stream
        .log_static(
            "world/workspace/legend/labels",
            &archetypes::Points3D::new(pos)
                .with_radii([0.001f32])
                .with_labels(text)
                .with_show_labels(true),
        )
        .map_err(sdk)?;
    // What the surface and the section are, on each.
    let [u, v] = cut.across;
    let r = 0.5 * size;
    let mut on_section = [0.0f64; 3];
    on_section[u] = cut.base[u] - 0.5 * r;
    on_section[v] = cut.base[v];
    on_section[2] = cut.base[2] + 0.3 * r;
    let mut on_boundary = [0.0f64; 3];
    on_boundary[u] = cut.base[u] + 0.75 * r;
    on_boundary[v] = cut.base[v] - 0.15 * r;
    on_boundary[2] = cut.base[2] + 0.6 * r;
    stream
        .log_static(
            "world/workspace/labels",
            &archetypes::Points3D::new([
                on_section.map(|x| x as f32),
                on_boundary.map(|x| x as f32),
            ])
            .with_radii([0.001f32])
            .with_labels(["section through the base axis", "reachable boundary"])
            .with_show_labels(true),
        )
        .map_err(sdk)?;
    let a = foot - right * (0.5 * w as f64);
    let b = foot + right * (side + 0.3 * size);
    Ok((
        [a.x.min(b.x), a.y.min(b.y), lo[2]],
        [a.x.max(b.x), a.y.max(b.y), z1 + 0.1 * size],
    ))
}

fn log_doc(
    stream: &RecordingStream,
    model: &Model,
    ws: &WorkspaceResult,
    lines: &[String],
) -> Result<(), RerunError> {
    // The estimate as `armsim workspace` prints it (interval, or a lower bound when
    // under-sampled).
    let estimate: String = crate::workspace::summary_lines(ws)
        .iter()
        .map(|l| format!("- {l}\n"))
        .collect();
    let mut md = format!(
        "# {} workspace\n\nTool link `{}`; {} samples in {} replicates, voxel {} m; {} \
         occupied voxels, {} on the boundary.\n\n{estimate}\n## In the 3-D view\n\n",
        model.name,
        ws.tool,
        ws.samples,
        ws.replicates,
        ws.voxel,
        ws.occupied_voxels,
        ws.boundary_voxels
    );
    for l in lines {
        md.push_str(l);
        md.push('\n');
    }
    stream
        .log_static(
            path(&["reports", "workspace"]),
            &archetypes::TextDocument::from_markdown(md),
        )
        .map_err(sdk)
}
