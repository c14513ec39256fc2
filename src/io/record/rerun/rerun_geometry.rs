//! The robot's visual geometry in Rerun: primitives (boxes, cylinders, capsules,
//! spheres) and meshes read with [`crate::collision::mesh`], with per-vertex normals; a
//! visual mesh that cannot be read is replaced by the link's primitive collision shapes
//! and reported once per reason. Returns each drawn link's bounding box.

use crate::collision::mesh::{load_mesh, MeshData};
use crate::collision::resolve::resolve_uri;
use crate::core::spatial::{Se3, Vec3};
use crate::io::record::rerun::rerun_entities::{child, f32x3, link_entity, quat_xyzw, sdk};
use crate::io::record::rerun::rerun_sink::{RerunError, RerunReport};
use crate::io::record::rerun::rerun_tree::Tree;
use crate::model::{Geometry, ModelSpec, Shape};
use rerun::{archetypes, components::FillMode, EntityPath, RecordingStream};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Link-frame bounding box `[min, max]` of what was drawn on a link.
pub(super) type Aabb = ([f64; 3], [f64; 3]);

/// Grows box `b` by point `p`.
pub(super) fn grow(b: &mut Option<Aabb>, p: &Vec3) {
    let (lo, hi) = b.get_or_insert(([p.x, p.y, p.z], [p.x, p.y, p.z]));
    for k in 0..3 {
        lo[k] = lo[k].min(p[k]);
        hi[k] = hi[k].max(p[k]);
    }
}

/// Grows `b` by the corners of primitive `g`'s bounding box, placed by its origin.
fn grow_by_primitive(b: &mut Option<Aabb>, g: &Geometry) {
    if let Some(c) = primitive_corners(&g.shape) {
        for x in [c[0], c[3]] {
            for y in [c[1], c[4]] {
                for z in [c[2], c[5]] {
                    grow(b, &g.origin.act_point(&Vec3::new(x, y, z)));
                }
            }
        }
    }
}

/// Corners of the shape's local bounding box (meshes excluded).
fn primitive_corners(shape: &Shape) -> Option<[f64; 6]> {
    Some(match shape {
        Shape::Box { size } => [
            -size[0] / 2.0,
            -size[1] / 2.0,
            -size[2] / 2.0,
            size[0] / 2.0,
            size[1] / 2.0,
            size[2] / 2.0,
        ],
        Shape::Cylinder { radius, length } => [
            -radius,
            -radius,
            -length / 2.0,
            *radius,
            *radius,
            length / 2.0,
        ],
        Shape::Capsule { radius, length } => [
            -radius,
            -radius,
            -length / 2.0 - radius,
            *radius,
            *radius,
            length / 2.0 + radius,
        ],
        Shape::Sphere { radius } => [-radius, -radius, -radius, *radius, *radius, *radius],
        Shape::Mesh { .. } => return None,
    })
}

fn color_of(g: &Geometry) -> rerun::Color {
    match g.rgba {
        Some(c) if c.iter().all(|v| v.is_finite()) => {
            let u = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
            rerun::Color::from_unmultiplied_rgba(u(c[0]), u(c[1]), u(c[2]), u(c[3]))
        }
        _ => rerun::Color::from_rgb(175, 180, 190),
    }
}

/// Logs one primitive; `false` when the shape is a mesh or has non-positive sizes.
pub(crate) fn log_primitive(
    stream: &RecordingStream,
    ent: EntityPath,
    g: &Geometry,
    color: rerun::Color,
) -> Result<bool, RerunError> {
    let c = f32x3(&g.origin.trans);
    let q = rerun::Quaternion::from_xyzw(quat_xyzw(&g.origin.rot));
    let pos = |x: f64| x.is_finite() && x > 0.0;
    match &g.shape {
        Shape::Box { size } if size.iter().all(|&s| pos(s)) => stream.log_static(
            ent,
            &archetypes::Boxes3D::from_centers_and_sizes(
                [c],
                [[size[0] as f32, size[1] as f32, size[2] as f32]],
            )
            .with_quaternions([q])
            .with_colors([color])
            .with_fill_mode(FillMode::Solid),
        ),
        Shape::Cylinder { radius, length } if pos(*radius) && pos(*length) => stream.log_static(
            ent,
            &archetypes::Cylinders3D::from_lengths_and_radii([*length as f32], [*radius as f32])
                .with_centers([c])
                .with_quaternions([q])
                .with_colors([color])
                .with_fill_mode(FillMode::Solid),
        ),
        Shape::Capsule { radius, length } if pos(*radius) && pos(*length) => {
            // Rerun's capsule starts at the origin along +z; ours is centred.
            let base = g.origin.act_point(&Vec3::new(0.0, 0.0, -length / 2.0));
            stream.log_static(
                ent,
                &archetypes::Capsules3D::from_lengths_and_radii([*length as f32], [*radius as f32])
                    .with_translations([f32x3(&base)])
                    .with_quaternions([q])
                    .with_colors([color])
                    .with_fill_mode(FillMode::Solid),
            )
        }
        Shape::Sphere { radius } if pos(*radius) => stream.log_static(
            ent,
            &archetypes::Ellipsoids3D::from_centers_and_radii([c], [*radius as f32])
                .with_colors([color])
                .with_fill_mode(FillMode::Solid),
        ),
        _ => return Ok(false),
    }
    .map_err(sdk)?;
    Ok(true)
}

/// Area-weighted vertex normals.
pub(crate) fn vertex_normals(vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut n = vec![Vec3::zeros(); vertices.len()];
    let v = |i: u32| {
        let p = vertices[i as usize];
        Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
    };
    for t in triangles {
        let w = (v(t[1]) - v(t[0])).cross(&(v(t[2]) - v(t[0])));
        for &i in t {
            n[i as usize] += w;
        }
    }
    n.iter()
        .map(|x| {
            let l = x.norm();
            if l > 0.0 {
                f32x3(&(x / l))
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
}

/// The vertices of mesh `m` scaled by `scale` and placed by `origin`, in f32; grows `bb`
/// by them.
pub(super) fn placed_vertices(
    m: &MeshData,
    origin: &Se3,
    scale: &[f64; 3],
    bb: &mut Option<Aabb>,
) -> Vec<[f32; 3]> {
    m.vertices
        .iter()
        .map(|v| {
            let p = origin.act_point(&Vec3::new(
                v[0] * scale[0],
                v[1] * scale[1],
                v[2] * scale[2],
            ));
            grow(bb, &p);
            f32x3(&p)
        })
        .collect()
}

/// Logs one visual mesh (scaled and placed by its geometry's origin, the winding flipped
/// under a mirroring scale) and grows the link's bounding box by it.
fn log_mesh(
    stream: &RecordingStream,
    vent: EntityPath,
    (g, scale, color): (&Geometry, &[f64; 3], rerun::Color),
    m: &MeshData,
    bb: &mut Option<Aabb>,
) -> Result<(), RerunError> {
    let pts = placed_vertices(m, &g.origin, scale, bb);
    // A mirroring scale flips the winding.
    let flip = scale[0] * scale[1] * scale[2] < 0.0;
    let tris: Vec<[u32; 3]> = m
        .triangles
        .iter()
        .map(|t| if flip { [t[0], t[2], t[1]] } else { *t })
        .collect();
    let normals = vertex_normals(&pts, &tris);
    stream
        .log_static(
            vent,
            &archetypes::Mesh3D::new(pts)
                .with_triangle_indices(tris)
                .with_vertex_normals(normals)
                .with_albedo_factor(color.to_array()),
        )
        .map_err(sdk)?;
    Ok(())
}

/// Logs all visual geometry; returns the link-frame bounding box of each drawn link.
pub(super) fn log_geometry(
    stream: &RecordingStream,
    spec: &ModelSpec,
    tree: &Tree,
    mesh_base: Option<&Path>,
    report: &mut RerunReport,
    warnings: &mut Vec<String>,
) -> Result<HashMap<usize, Aabb>, RerunError> {
    let spec_dir = Path::new(&spec.source)
        .is_file()
        .then(|| Path::new(&spec.source).parent())
        .flatten();
    let base = mesh_base.or(spec_dir);
    // Each mesh is read once: `None` when it could not be (the reason is in `failed`).
    let mut meshes: HashMap<String, Option<MeshData>> = HashMap::new();
    let mut failed: BTreeMap<String, String> = BTreeMap::new();
    let mut boxes = HashMap::new();
    for link in &spec.links {
        let li = tree.index[&link.name];
        let ent = link_entity(&link.name);
        let mut bb: Option<Aabb> = None;
        let mut k = 0usize;
        let mut mesh_missing = false;
        for g in &link.visuals {
            let color = color_of(g);
            let vent = child(&ent, &format!("visual_{k}"));
            if let Shape::Mesh { uri, scale } = &g.shape {
                let loaded = meshes.entry(uri.clone()).or_insert_with(|| {
                    let read = resolve_uri(uri, base)
                        .map_err(|e| e.0)
                        .and_then(|p| load_mesh(&p).map_err(|e| e.to_string()));
                    read.map_err(|why| failed.insert(uri.clone(), why)).ok()
                });
                let m = match loaded {
                    Some(m) if !m.triangles.is_empty() => m,
                    Some(_) => {
                        failed.insert(uri.clone(), "no triangles".into());
                        mesh_missing = true;
                        continue;
                    }
                    None => {
                        mesh_missing = true;
                        continue;
                    }
                };
                // As the collision layer: a scale that takes a vertex out of range is refused.
                let limit = crate::collision::MAX_COORD;
                let far = |v: &[f64; 3]| {
                    (0..3).any(|k| {
                        let x = (v[k] * scale[k]).abs();
                        x.is_nan() || x > limit
                    })
                };
                if m.vertices.iter().any(far) {
                    failed.insert(
                        uri.clone(),
                        format!(
                            "mesh scale {scale:?} takes a vertex beyond the {:e} m accepted",
                            crate::collision::MAX_COORD
                        ),
                    );
                    mesh_missing = true;
                    continue;
                }
                log_mesh(stream, vent, (g, scale, color), m, &mut bb)?;
                k += 1;
                report.visuals += 1;
            } else if log_primitive(stream, vent, g, color)? {
                grow_by_primitive(&mut bb, g);
                k += 1;
                report.visuals += 1;
            }
        }
        // Missing visual meshes: draw the primitive collision shapes instead.
        if mesh_missing || link.visuals.is_empty() {
            for g in &link.collisions {
                if matches!(g.shape, Shape::Mesh { .. }) {
                    continue;
                }
                let vent = child(&ent, &format!("visual_{k}"));
                if log_primitive(stream, vent, g, rerun::Color::from_rgb(150, 160, 175))? {
                    grow_by_primitive(&mut bb, g);
                    k += 1;
                    report.visuals += 1;
                }
            }
        }
        if let Some(b) = bb {
            boxes.insert(li, b);
        }
    }
    // One warning per reason (a missing package fails every mesh in it).
    let mut by_reason: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for (uri, why) in failed {
        by_reason.entry(why).or_default().push(uri);
    }
    for (why, uris) in by_reason {
        warnings.push(match uris.as_slice() {
            [one] => format!("visual mesh '{one}' not drawn: {why}"),
            many => format!(
                "{} visual meshes not drawn ('{}', …): {why}",
                many.len(),
                many[0]
            ),
        });
    }
    Ok(boxes)
}
