//! The scene around the robot in a Rerun recording: the obstacles of a
//! [`SceneExtras`], drawn as static geometry under `world/obstacles/<name>` (boxes,
//! cylinders, capsules, spheres, and meshes read with [`crate::collision::mesh`]), and the
//! world bounding box of what was drawn, for framing the 3-D view.

use crate::collision::mesh::load_mesh;
use crate::collision::resolve::resolve_uri;
use crate::core::spatial::Vec3;
use crate::io::record::rerun::rerun_entities::path;
use crate::io::record::rerun::rerun_geometry::placed_vertices;
use crate::io::record::rerun::rerun_geometry::{log_primitive, vertex_normals};
use crate::io::record::rerun::rerun_sink::{RerunError, SceneExtras};
use crate::model::Shape;
use rerun::{archetypes, RecordingStream};

/// Colour of obstacles (a light wood brown).
const OBSTACLE: [u8; 3] = [196, 144, 96];

/// World axis-aligned box `(lo, hi)`.
pub type Bounds = ([f64; 3], [f64; 3]);

pub(super) use crate::io::record::rerun::rerun_geometry::grow;

/// Logs the obstacles of `extras`, except those named in `drawn` (already drawn, with
/// their labels, from the recording's obstacle markers: drawing them twice would make
/// two coincident surfaces flicker); returns the world bounds of all of them. A mesh
/// obstacle that cannot be found or read is skipped with a warning.
pub fn log_obstacles(
    stream: &RecordingStream,
    extras: &SceneExtras,
    drawn: &[&str],
    warnings: &mut Vec<String>,
) -> Result<Option<Bounds>, RerunError> {
    let mut bounds = None;
    let color = rerun::Color::from_rgb(OBSTACLE[0], OBSTACLE[1], OBSTACLE[2]);
    for (name, g) in &extras.obstacles {
        let ent = path(&["world", "obstacles", name]);
        let skip = drawn.contains(&name.as_str());
        if let Shape::Mesh { uri, scale } = &g.shape {
            let loaded = resolve_uri(uri, extras.obstacle_dir.as_deref())
                .map_err(|e| e.0)
                .and_then(|p| load_mesh(&p).map_err(|e| e.to_string()));
            let m = match loaded {
                Ok(m) => m,
                Err(e) => {
                    warnings.push(format!("obstacle '{name}': mesh '{uri}' not drawn: {e}"));
                    continue;
                }
            };
            let pts = placed_vertices(&m, &g.origin, scale, &mut bounds);
            if skip {
                continue;
            }
            let normals = vertex_normals(&pts, &m.triangles);
            stream
                .log_static(
                    ent,
                    &archetypes::Mesh3D::new(pts)
                        .with_triangle_indices(m.triangles.clone())
                        .with_vertex_normals(normals)
                        .with_albedo_factor(color.to_array()),
                )
                .map_err(|e| RerunError::Sdk(e.to_string()))?;
        } else if skip || log_primitive(stream, ent, g, color)? {
            for c in corners(&g.shape) {
                grow(&mut bounds, &g.origin.act_point(&c));
            }
        }
    }
    Ok(bounds)
}

/// Corners of a primitive's local bounding box (none for meshes).
fn corners(shape: &Shape) -> Vec<Vec3> {
    let h = match shape {
        Shape::Box { size } => Vec3::new(size[0], size[1], size[2]) / 2.0,
        Shape::Cylinder { radius, length } => Vec3::new(*radius, *radius, length / 2.0),
        Shape::Capsule { radius, length } => Vec3::new(*radius, *radius, length / 2.0 + radius),
        Shape::Sphere { radius } => Vec3::repeat(*radius),
        Shape::Mesh { .. } => return Vec::new(),
    };
    let mut out = Vec::with_capacity(8);
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                out.push(Vec3::new(sx * h.x, sy * h.y, sz * h.z));
            }
        }
    }
    out
}
