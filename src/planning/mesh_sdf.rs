//! Signed distance of a triangle mesh, for the sphere cover of mesh collision geometry
//! ([`crate::planning::spherize::cover_sdf`]).
//!
//! The unsigned distance is the distance to the nearest triangle (parry's BVH point
//! projection onto the [`TriMesh`]). For a **closed**, consistently oriented mesh (every
//! edge shared by two triangles in opposite directions; wound outwards, flipped if its
//! signed volume is negative) the sign comes from the angle-weighted pseudo-normals at the
//! nearest feature (Bærentzen and Aanæs, *IEEE TVCG* 11(3), 2005): a point is inside when
//! it lies behind the pseudo-normal of its nearest point, a test that is exact for closed
//! manifold meshes. An **open** mesh has no inside: the distance is unsigned, and the
//! cover only wraps its surface.

use crate::collision::mesh::MeshData;
use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

/// Why a mesh cannot give a signed distance.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshSdfError {
    /// The mesh has no triangle.
    #[error("the mesh has no triangles")]
    NoTriangles,
    /// A scale with a zero or non-finite factor.
    #[error("mesh scale must be finite and non-zero, got {0:?}")]
    Scale([f64; 3]),
    /// A scale that takes a vertex beyond the f64 range.
    #[error("mesh scale {0:?} takes its vertices beyond the floating-point range")]
    Overflow([f64; 3]),
    /// A triangle mesh parry refuses (its error, debug-printed).
    #[error("invalid triangle mesh: {0}")]
    InvalidTriMesh(String),
}

/// A triangle mesh with its bounding box, answering signed distances.
pub struct MeshSdf {
    tri: TriMesh,
    /// Whether the mesh is closed (signed distance) or open (unsigned).
    pub closed: bool,
    /// Centre of the bounding box.
    pub center: [f64; 3],
    /// Half extents of the bounding box.
    pub half: [f64; 3],
}

impl MeshSdf {
    /// The mesh scaled by `scale` (per axis; a mirror flips the winding back).
    pub fn new(mesh: &MeshData, scale: [f64; 3]) -> Result<MeshSdf, MeshSdfError> {
        if mesh.triangles.is_empty() {
            return Err(MeshSdfError::NoTriangles);
        }
        if !scale.iter().all(|s| s.is_finite() && *s != 0.0) {
            return Err(MeshSdfError::Scale(scale));
        }
        let mut m = mesh.clone();
        for v in &mut m.vertices {
            for k in 0..3 {
                v[k] *= scale[k];
            }
        }
        if m.vertices.iter().flatten().any(|x| !x.is_finite()) {
            return Err(MeshSdfError::Overflow(scale));
        }
        let closed = m.is_closed();
        let mut flags = TriMeshFlags::empty();
        if closed {
            if m.signed_volume6() < 0.0 {
                m.flip();
            }
            flags |= TriMeshFlags::ORIENTED;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for v in &m.vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        let vertices: Vec<Vector> = m
            .vertices
            .iter()
            .map(|p| Vector::new(p[0], p[1], p[2]))
            .collect();
        let tri = TriMesh::with_flags(vertices, m.triangles, flags)
            .map_err(|e| MeshSdfError::InvalidTriMesh(format!("{e:?}")))?;
        Ok(MeshSdf {
            tri,
            closed,
            center: [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k])),
            half: [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k])),
        })
    }

    /// Signed distance from `p` to the surface (negative inside a closed mesh).
    pub fn sdf(&self, p: [f64; 3]) -> f64 {
        let x = Vector::new(p[0], p[1], p[2]);
        // One BVH query: the projection, and for an oriented (closed) mesh the inside
        // test by the pseudo-normal at the nearest feature (what `contains_local_point`
        // computes with a second query).
        let (proj, _) = self.tri.project_local_point_and_get_location(x, false);
        let d = (proj.point - x).length();
        if self.closed && proj.is_inside {
            -d
        } else {
            d
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::planning::mesh_sdf::*;
    use crate::planning::spherize::{cover_sdf, Primitive};

    /// A box `±h` as 12 outward triangles.
    fn box_mesh(h: [f64; 3]) -> MeshData {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 1 { h[k] } else { -h[k] }))
            .collect();
        // Faces as quads of corner indices (bit k set = +h on axis k), wound outwards.
        let quads = [
            [0, 2, 3, 1], // z−
            [4, 5, 7, 6], // z+
            [0, 1, 5, 4], // y−
            [2, 6, 7, 3], // y+
            [0, 4, 6, 2], // x−
            [1, 3, 7, 5], // x+
        ];
        let mut triangles = Vec::new();
        for q in quads {
            triangles.push([q[0], q[1], q[2]]);
            triangles.push([q[0], q[2], q[3]]);
        }
        MeshData {
            vertices: v,
            triangles,
            dropped: 0,
            ..Default::default()
        }
    }

    fn rnd(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    #[test]
    fn a_scale_that_overflows_the_vertices_is_refused() {
        // 20 m × 1e308 overflows to infinity.
        let m = box_mesh([20.0, 0.1, 0.2]);
        let e = MeshSdf::new(&m, [1e308, 1.0, 1.0])
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("floating-point range"), "{e}");
    }

    #[test]
    fn box_mesh_signed_distance_equals_the_box_closed_form() {
        let h = [0.05, 0.1, 0.2];
        let m = box_mesh(h);
        assert!(m.is_closed() && m.signed_volume6() > 0.0);
        // Inverted winding is flipped back; a mirror scale too.
        let mut inv = m.clone();
        inv.flip();
        let exact = Primitive::Box(h);
        let mut st = 0x9e37_79b9_7f4a_7c15u64;
        for sdf in [
            MeshSdf::new(&m, [1.0; 3]).unwrap(),
            MeshSdf::new(&inv, [1.0; 3]).unwrap(),
            MeshSdf::new(&m, [-1.0, 1.0, 1.0]).unwrap(),
        ] {
            assert!(sdf.closed);
            for _ in 0..5000 {
                let p = [rnd(&mut st) * 0.3, rnd(&mut st) * 0.3, rnd(&mut st) * 0.3];
                let (a, b) = (sdf.sdf(p), exact.sdf(p));
                assert!((a - b).abs() < 1e-12, "{p:?}: mesh {a}, box {b}");
            }
        }
    }

    #[test]
    fn closed_mesh_cover_contains_the_mesh_and_overshoots_at_most_delta() {
        // A box mesh scaled anisotropically, checked against the box's closed form:
        // every sampled point inside is in a sphere; no sphere's surface point is more
        // than delta outside.
        let h = [0.04, 0.15, 0.06];
        let scale = [1.0, 2.0, 0.5];
        let sdf = MeshSdf::new(&box_mesh(h), scale).unwrap();
        let exact = Primitive::Box([h[0], h[1] * 2.0, h[2] * 0.5]);
        let delta = 0.01;
        let t = std::time::Instant::now();
        let (spheres, used) = cover_sdf(&|p| sdf.sdf(p), sdf.center, sdf.half, delta);
        assert_eq!(used, delta);
        assert!(t.elapsed().as_secs_f64() < 1.0, "{:?}", t.elapsed());
        let mut st = 0x2545_f491_4f6c_dd1du64;
        let ext = [h[0], h[1] * 2.0, h[2] * 0.5];
        let mut inside = 0;
        for _ in 0..20000 {
            let p = [0, 1, 2].map(|k| rnd(&mut st) * ext[k]);
            if exact.sdf(p) <= 0.0 {
                inside += 1;
                assert!(
                    spheres.iter().any(|(c, r)| {
                        ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2))
                            .sqrt()
                            <= *r + 1e-12
                    }),
                    "{p:?} not covered"
                );
            }
        }
        assert!(inside > 19000);
        for (c, r) in &spheres {
            for _ in 0..200 {
                let d = [rnd(&mut st), rnd(&mut st), rnd(&mut st)];
                let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-9);
                let p = [0, 1, 2].map(|k| c[k] + r * d[k] / n);
                assert!(exact.sdf(p) <= delta + 1e-12, "overshoot at {p:?}");
            }
        }
    }

    #[test]
    fn open_mesh_is_unsigned_and_bundled_cube_files_are_closed() {
        let mut m = box_mesh([0.1; 3]);
        m.triangles.truncate(10); // the x+ face removed
        let sdf = MeshSdf::new(&m, [1.0; 3]).unwrap();
        assert!(!sdf.closed);
        assert!((sdf.sdf([0.0; 3]) - 0.1).abs() < 1e-12, "unsigned inside");
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes");
        for f in ["cube_binary.stl", "cube.obj"] {
            let data = crate::collision::mesh::load_mesh(&dir.join(f)).unwrap();
            let sdf = MeshSdf::new(&data, [1.0; 3]).unwrap();
            assert!(sdf.closed, "{f}");
            assert!(sdf.sdf(sdf.center) < 0.0, "{f}: centre inside");
        }
    }
}
