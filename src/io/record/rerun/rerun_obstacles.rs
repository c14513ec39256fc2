//! Rerun output of a recording's obstacles
//! ([`crate::io::record::obstacle_markers::ObstacleMarker`]): each shape as a static entity
//! `world/obstacles/<name>/shape_<k>` in world coordinates — `CUBE` as `Boxes3D`, `SPHERE` as
//! `Ellipsoids3D` (half sizes = scale / 2), `CYLINDER` as `Cylinders3D` (radius = the larger of
//! scale x, y over 2, length = scale z), meshes as `Mesh3D` (the file loaded with
//! [`crate::collision::mesh`], scale baked in) — labelled with the obstacle's name on its first
//! shape. A marker's pose is in its frame: `world` (or an empty frame id) as is, another frame at
//! that frame's first pose in the recording (obstacles are static).

use crate::collision::mesh::load_mesh;
use crate::collision::resolve::resolve_uri;
use crate::core::spatial::{Se3, Vec3};
use crate::io::record::obstacle_markers::{MarkerShape, ObstacleMarker};
use crate::io::record::rerun::rerun_entities::path;
use crate::io::record::rerun::rerun_sink::{RerunError, RerunReport};
use crate::io::record::tf::to_se3;
use nalgebra::{Rotation3, UnitQuaternion};
use rerun::{archetypes, components::FillMode, RecordingStream};
use std::path::Path;

fn sdk(e: impl std::fmt::Display) -> RerunError {
    RerunError::Sdk(e.to_string())
}

fn f32x3(v: &Vec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

fn quaternion(pose: &Se3) -> rerun::Quaternion {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(pose.rot));
    rerun::Quaternion::from_xyzw([q.i as f32, q.j as f32, q.k as f32, q.w as f32])
}

fn color(m: &ObstacleMarker) -> rerun::Color {
    let u = |v: f32| {
        if v.is_finite() {
            (v.clamp(0.0, 1.0) * 255.0).round() as u8
        } else {
            255
        }
    };
    let [r, g, b, a] = m.color;
    rerun::Color::from_unmultiplied_rgba(u(r), u(g), u(b), u(a))
}

/// Logs `markers`; `frame_pose` gives the world pose of a frame named in a marker's pose
/// (`None`: unknown, the marker is skipped with a warning). Mesh URIs are resolved against
/// `mesh_base`. Returns the number of shapes drawn.
pub(super) fn log_obstacles(
    stream: &RecordingStream,
    markers: &[ObstacleMarker],
    frame_pose: &dyn Fn(&str) -> Option<Se3>,
    mesh_base: Option<&Path>,
    report: &mut RerunReport,
    warnings: &mut Vec<String>,
) -> Result<(), RerunError> {
    let mut labelled: Vec<&str> = Vec::new();
    for (k, m) in markers.iter().enumerate() {
        let frame = m.pose.parent.as_str();
        let base = if frame.is_empty() || frame == "world" {
            Some(Se3::identity())
        } else {
            frame_pose(frame)
        };
        let Some(base) = base else {
            warnings.push(format!(
                "obstacle '{}' not drawn: its frame '{frame}' is not in the recording",
                m.name
            ));
            continue;
        };
        let ok = m.scale.iter().all(|s| s.is_finite() && *s > 0.0)
            && m.pose
                .translation
                .iter()
                .chain(&m.pose.rotation)
                .all(|v| v.is_finite());
        if !ok {
            warnings.push(format!(
                "obstacle '{}' not drawn: non-finite or non-positive size or pose",
                m.name
            ));
            continue;
        }
        let pose = base.mul(&to_se3(&m.pose));
        let ent = path(&["world", "obstacles", &m.name, &format!("shape_{k}")]);
        let label = (!labelled.contains(&m.name.as_str())).then(|| m.name.clone());
        if log_shape(stream, ent, m, &pose, label.clone(), mesh_base, warnings)? {
            report.obstacles += 1;
            if label.is_some() {
                labelled.push(&m.name);
            }
        }
    }
    Ok(())
}

/// Logs one marker at its world `pose`; `false` when a mesh could not be loaded.
fn log_shape(
    stream: &RecordingStream,
    ent: rerun::EntityPath,
    m: &ObstacleMarker,
    pose: &Se3,
    label: Option<String>,
    mesh_base: Option<&Path>,
    warnings: &mut Vec<String>,
) -> Result<bool, RerunError> {
    let c = f32x3(&pose.trans);
    let q = quaternion(pose);
    let s = m.scale.map(|x| x as f32);
    let labels: Vec<String> = label.into_iter().collect();
    match &m.shape {
        MarkerShape::Cube => stream.log_static(
            ent,
            &archetypes::Boxes3D::from_centers_and_sizes([c], [s])
                .with_quaternions([q])
                .with_colors([color(m)])
                .with_fill_mode(FillMode::Solid)
                .with_labels(labels),
        ),
        MarkerShape::Sphere => stream.log_static(
            ent,
            &archetypes::Ellipsoids3D::from_centers_and_half_sizes(
                [c],
                [[s[0] / 2.0, s[1] / 2.0, s[2] / 2.0]],
            )
            .with_quaternions([q])
            .with_colors([color(m)])
            .with_fill_mode(FillMode::Solid)
            .with_labels(labels),
        ),
        MarkerShape::Cylinder => stream.log_static(
            ent,
            &archetypes::Cylinders3D::from_lengths_and_radii([s[2]], [s[0].max(s[1]) / 2.0])
                .with_centers([c])
                .with_quaternions([q])
                .with_colors([color(m)])
                .with_fill_mode(FillMode::Solid)
                .with_labels(labels),
        ),
        MarkerShape::Mesh { uri } => {
            let mesh = resolve_uri(uri, mesh_base)
                .map_err(|e| e.0)
                .and_then(|p| load_mesh(&p).map_err(|e| e.to_string()));
            let mesh = match mesh {
                Ok(mesh) if !mesh.triangles.is_empty() => mesh,
                Ok(_) | Err(_) => {
                    let why = mesh.err().unwrap_or_else(|| "no triangles".into());
                    warnings.push(format!("obstacle '{}' mesh not drawn: {why}", m.name));
                    return Ok(false);
                }
            };
            let limit = crate::collision::MAX_COORD;
            let far = |v: &[f64; 3]| {
                (0..3).any(|k| {
                    let x = (v[k] * m.scale[k]).abs();
                    x.is_nan() || x > limit
                })
            };
            if mesh.vertices.iter().any(far) {
                warnings.push(format!(
                    "obstacle '{}' mesh not drawn: scale {:?} takes a vertex beyond the {limit:e} m accepted",
                    m.name, m.scale
                ));
                return Ok(false);
            }
            let pts: Vec<[f32; 3]> = mesh
                .vertices
                .iter()
                .map(|v| {
                    let local = Vec3::new(v[0] * m.scale[0], v[1] * m.scale[1], v[2] * m.scale[2]);
                    f32x3(&pose.act_point(&local))
                })
                .collect();
            let flip = m.scale[0] * m.scale[1] * m.scale[2] < 0.0;
            let tris: Vec<[u32; 3]> = mesh
                .triangles
                .iter()
                .map(|t| if flip { [t[0], t[2], t[1]] } else { *t })
                .collect();
            stream
                .log_static(
                    ent.clone(),
                    &archetypes::Mesh3D::new(pts)
                        .with_triangle_indices(tris)
                        .with_albedo_factor(color(m).to_array()),
                )
                .map_err(sdk)?;
            if !labels.is_empty() {
                stream
                    .log_static(
                        ent.join(&path(&["label"])),
                        &archetypes::Points3D::new([c]).with_labels(labels),
                    )
                    .map_err(sdk)?;
            }
            return Ok(true);
        }
    }
    .map_err(sdk)?;
    Ok(true)
}
