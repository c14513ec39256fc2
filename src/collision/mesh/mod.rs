//! Mesh files for collision geometry, read into one indexed triangle list.
//!
//! Formats, chosen by the file extension (case-insensitive):
//! - **STL**, binary and ASCII. A file is binary when its size is exactly
//!   `84 + 50 n` bytes with `n` the triangle count stored at byte 80 (so binary files whose
//!   80-byte header starts with `solid`, as many CAD exports do, are read correctly);
//!   otherwise it must be ASCII (`solid … facet … vertex x y z … endsolid`, several solids
//!   allowed). Normals are ignored.
//! - **OBJ** (Wavefront), through `tobj`: every object and group, polygons triangulated as
//!   fans; materials are not read.
//! - **DAE** (COLLADA 1.4/1.5), a subset read with `roxmltree`:
//!   - every `<geometry>/<mesh>` of `<library_geometries>`: `<source>` `<float_array>`s
//!     (with the `<accessor>` stride), `<vertices>`/`<input semantic="POSITION">`, and the
//!     primitives `<triangles>`, `<polylist>` (with `<vcount>`, polygons fanned) and
//!     `<polygons>` (one `<p>` per polygon), each with any number of interleaved inputs
//!     (the index stride is the largest `offset` + 1);
//!   - placement: the nodes of the `<visual_scene>` named by `<scene>` (else the first)
//!     are walked, composing `<matrix>`, `<translate>`, `<rotate>` and `<scale>` in order,
//!     and each `<instance_geometry>` is placed with its node's transform; when the scene
//!     instantiates no geometry, every geometry is taken untransformed;
//!   - `<asset><unit meter="…">` scales the result;
//!   - not supported: `<lines>`, `<linestrips>`, `<trifans>`, `<tristrips>` (skipped),
//!     `<instance_node>`, `<library_nodes>`, controllers/skinning, and `<up_axis>`
//!     (ignored: coordinates are used as written).
//!
//! Vertices with identical coordinates are merged, so that closedness (every edge shared
//! by exactly two triangles) can be tested afterwards.
//!
//! Limits: a file is refused above [`crate::core::files::MAX_MESH_BYTES`] before it is read, and
//! a mesh of more than [`MAX_TRIANGLES`] triangles (a binary STL's declared count, checked
//! before anything is allocated from it, or a DAE scene's placed total) is refused; every
//! coordinate must be finite. Errors name the problem; the caller adds the file.

mod dae;
pub use dae::read_dae;

use nalgebra::Vector3;
use std::collections::HashMap;
use std::path::Path;

/// An indexed triangle mesh in f64.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Triangles read but dropped for a repeated corner (zero area).
    pub dropped: usize,
}

/// Most triangles in one mesh (after a DAE scene places its geometries): 5 million, what
/// a binary STL of [`crate::core::files::MAX_MESH_BYTES`] holds.
pub const MAX_TRIANGLES: usize = 5_000_000;

impl MeshData {
    /// Adds a triangle given by its corner positions, merging identical vertices through
    /// `index` (keyed by the bit patterns, `-0.0` folded onto `0.0`). A non-finite
    /// coordinate is an error.
    fn push_triangle(
        &mut self,
        index: &mut HashMap<[u64; 3], u32>,
        tri: [[f64; 3]; 3],
    ) -> Result<(), String> {
        if let Some(p) = tri.iter().find(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(format!(
                "vertex ({}, {}, {}) is not finite",
                p[0], p[1], p[2]
            ));
        }
        let mut ids = [0u32; 3];
        for (k, p) in tri.iter().enumerate() {
            let key = p.map(|x| (x + 0.0).to_bits());
            ids[k] = *index.entry(key).or_insert_with(|| {
                self.vertices.push(*p);
                (self.vertices.len() - 1) as u32
            });
        }
        // Triangles with a repeated corner carry no area.
        if ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2] {
            self.triangles.push(ids);
        } else {
            self.dropped += 1;
        }
        Ok(())
    }

    /// Whether every undirected edge is used by exactly two triangles, once in each
    /// direction (a closed, consistently oriented surface).
    pub fn is_closed(&self) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let mut directed: HashMap<(u32, u32), u32> =
            HashMap::with_capacity(self.triangles.len() * 3);
        for t in &self.triangles {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        directed
            .iter()
            .all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1))
    }

    /// Six times the signed volume enclosed (positive for outward-facing triangles).
    pub fn signed_volume6(&self) -> f64 {
        let v = |i: u32| Vector3::from(self.vertices[i as usize]);
        self.triangles
            .iter()
            .map(|t| v(t[0]).dot(&v(t[1]).cross(&v(t[2]))))
            .sum()
    }

    /// Reverses the winding of every triangle.
    pub fn flip(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }
}

/// Reads a mesh file (STL, OBJ or DAE, by extension). Errors are plain messages naming
/// the problem (the caller adds the file, link and URI).
pub fn load_mesh(path: &Path) -> Result<MeshData, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let mesh = match ext.as_str() {
        "stl" => {
            let bytes =
                crate::core::files::read_input_max(path, crate::core::files::MAX_MESH_BYTES)
                    .map_err(|e| format!("cannot read: {e}"))?;
            read_stl(&bytes)?
        }
        "obj" => read_obj(path)?,
        "dae" => {
            let text =
                crate::core::files::read_input_string_max(path, crate::core::files::MAX_MESH_BYTES)
                    .map_err(|e| format!("cannot read: {e}"))?;
            read_dae(&text)?
        }
        _ => {
            return Err(format!(
                "unsupported mesh format '.{ext}': expected .stl, .obj or .dae"
            ))
        }
    };
    if mesh.triangles.is_empty() && mesh.dropped > 0 {
        return Err(format!(
            "all {} triangles of the mesh have zero area (a repeated corner)",
            mesh.dropped
        ));
    }
    if mesh.triangles.is_empty() {
        return Err("the mesh has no triangles".to_string());
    }
    Ok(mesh)
}

/// Parses STL bytes, binary or ASCII (see the module docs for the detection rule).
pub fn read_stl(bytes: &[u8]) -> Result<MeshData, String> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if n.checked_mul(50).and_then(|b| b.checked_add(84)) == Some(bytes.len()) {
            if n > MAX_TRIANGLES {
                return Err(format!(
                    "binary STL of {n} triangles: more than the mesh limit of {MAX_TRIANGLES}"
                ));
            }
            return read_stl_binary(&bytes[84..], n);
        }
    }
    let text = std::str::from_utf8(bytes).map_err(|_| {
        "not a binary STL (the size is not 84 + 50 × the triangle count) and not ASCII text"
            .to_string()
    })?;
    read_stl_ascii(text)
}

/// The `n` records of a binary STL body (`n` already checked against its length and
/// [`MAX_TRIANGLES`]).
fn read_stl_binary(body: &[u8], n: usize) -> Result<MeshData, String> {
    let mut mesh = MeshData::default();
    let mut index = HashMap::with_capacity(n);
    let f = |b: &[u8], k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]) as f64;
    for (k, rec) in body.chunks_exact(50).take(n).enumerate() {
        // 12 bytes of normal, then three vertices.
        let v = |j: usize| {
            let o = 12 + 12 * j;
            [f(rec, o), f(rec, o + 4), f(rec, o + 8)]
        };
        mesh.push_triangle(&mut index, [v(0), v(1), v(2)])
            .map_err(|e| format!("binary STL: triangle {}: {e}", k + 1))?;
    }
    Ok(mesh)
}

fn read_stl_ascii(text: &str) -> Result<MeshData, String> {
    let mut tokens = text.split_ascii_whitespace();
    match tokens.next() {
        Some(t) if t.eq_ignore_ascii_case("solid") => {}
        _ => {
            return Err(
                "not a binary STL (the size is not 84 + 50 × the triangle count) and not an \
                 ASCII STL (it does not start with 'solid')"
                    .to_string(),
            )
        }
    }
    let mut mesh = MeshData::default();
    let mut index = HashMap::new();
    let mut corners: Vec<[f64; 3]> = Vec::with_capacity(4);
    let mut nvert = 0usize;
    while let Some(t) = tokens.next() {
        if t.eq_ignore_ascii_case("vertex") {
            let mut p = [0.0; 3];
            for c in &mut p {
                let s = tokens
                    .next()
                    .ok_or_else(|| format!("ASCII STL: vertex {} is cut short", nvert + 1))?;
                *c = s.parse::<f64>().map_err(|_| {
                    format!("ASCII STL: vertex {}: '{s}' is not a number", nvert + 1)
                })?;
            }
            nvert += 1;
            corners.push(p);
        } else if t.eq_ignore_ascii_case("endloop") {
            if corners.len() != 3 {
                return Err(format!(
                    "ASCII STL: a facet loop has {} vertices, expected 3",
                    corners.len()
                ));
            }
            if mesh.triangles.len() >= MAX_TRIANGLES {
                return Err(format!(
                    "ASCII STL: more than the mesh limit of {MAX_TRIANGLES} triangles"
                ));
            }
            mesh.push_triangle(&mut index, [corners[0], corners[1], corners[2]])
                .map_err(|e| format!("ASCII STL: vertex {nvert}: {e}"))?;
            corners.clear();
        }
    }
    if !corners.is_empty() {
        return Err("ASCII STL: the last facet loop is not closed ('endloop')".to_string());
    }
    if nvert == 0 {
        return Err("ASCII STL: no 'vertex' found".to_string());
    }
    Ok(mesh)
}

fn read_obj(path: &Path) -> Result<MeshData, String> {
    let bytes = crate::core::files::read_input_max(path, crate::core::files::MAX_MESH_BYTES)
        .map_err(|e| format!("cannot read: {e}"))?;
    read_obj_bytes(&bytes)
}

/// Parses Wavefront OBJ bytes (materials are not read).
// `..Default::default()` fills the fields behind tobj features another crate may enable.
#[allow(clippy::needless_update)]
pub fn read_obj_bytes(bytes: &[u8]) -> Result<MeshData, String> {
    // Lossy: tobj reads the lines before the first one that is not UTF-8 (then fails),
    // and those lines are the same in the lossy text.
    check_obj_indices(&String::from_utf8_lossy(bytes))?;
    let mut reader = std::io::Cursor::new(bytes);
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // Materials are not needed: every `mtllib` is answered with "not loaded".
    let (models, _materials) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| format!("OBJ: {e}"))?;
    let mut mesh = MeshData::default();
    let mut index = HashMap::new();
    for m in &models {
        let pos = &m.mesh.positions;
        let p = |i: u32| -> Result<[f64; 3], String> {
            let i = i as usize;
            pos.get(3 * i..3 * i + 3)
                .map(|s| [s[0], s[1], s[2]])
                .ok_or_else(|| format!("OBJ: object '{}': vertex index out of range", m.name))
        };
        if mesh.triangles.len() + m.mesh.indices.len() / 3 > MAX_TRIANGLES {
            return Err(format!(
                "OBJ: more than the mesh limit of {MAX_TRIANGLES} triangles"
            ));
        }
        for t in m.mesh.indices.chunks_exact(3) {
            mesh.push_triangle(&mut index, [p(t[0])?, p(t[1])?, p(t[2])?])
                .map_err(|e| format!("OBJ: object '{}': {e}", m.name))?;
        }
    }
    Ok(mesh)
}

/// Checks every face and line index of an OBJ before `tobj` sees it: tobj 4.0.5 turns a
/// relative index reaching before the first element (`f 1/-11` after one `vt`) into a
/// huge one and overflows (`vt * 2 + 1`) or indexes out of bounds, a panic. A negative
/// index must stay within the elements of its kind read so far, a positive one within
/// those of the whole file.
fn check_obj_indices(text: &str) -> Result<(), String> {
    let kinds = ["vertex", "texture coordinate", "normal"];
    let mut total = [0usize; 3];
    for l in text.lines() {
        match l.split_whitespace().next() {
            Some("v") => total[0] += 1,
            Some("vt") => total[1] += 1,
            Some("vn") => total[2] += 1,
            _ => {}
        }
    }
    let mut seen = [0usize; 3];
    for (n, l) in text.lines().enumerate() {
        let mut words = l.split_whitespace();
        match words.next() {
            Some("v") => seen[0] += 1,
            Some("vt") => seen[1] += 1,
            Some("vn") => seen[2] += 1,
            Some("f" | "l") => {
                for w in words {
                    for (k, part) in w.split('/').take(3).enumerate() {
                        let Ok(x) = part.parse::<isize>() else {
                            continue; // empty (v//vn) or malformed: tobj decides
                        };
                        let (bad, limit) = if x < 0 {
                            (x.unsigned_abs() > seen[k], seen[k])
                        } else {
                            (x as usize > total[k], total[k])
                        };
                        if bad {
                            return Err(format!(
                                "OBJ: line {}: index {x} of a {} is out of range ({limit} {})",
                                n + 1,
                                kinds[k],
                                if x < 0 { "before it" } else { "in the file" }
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::collision::mesh::*;

    #[test]
    fn binary_stl_with_solid_header_is_binary() {
        let mut b = vec![0u8; 80];
        b[..6].copy_from_slice(b"solid ");
        b.extend_from_slice(&1u32.to_le_bytes());
        let mut rec = vec![0u8; 12];
        for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for x in v {
                rec.extend_from_slice(&x.to_le_bytes());
            }
        }
        rec.extend_from_slice(&[0, 0]);
        b.extend_from_slice(&rec);
        let m = read_stl(&b).unwrap();
        assert_eq!(m.vertices.len(), 3);
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        assert_eq!(m.vertices[1], [1.0, 0.0, 0.0]);
    }

    #[test]
    fn ascii_stl_rejects_a_four_vertex_loop() {
        let t = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 0\nendloop\nendfacet\nendsolid\n";
        assert!(read_stl(t.as_bytes()).unwrap_err().contains("4 vertices"));
    }

    #[test]
    fn tetrahedron_is_closed_and_flip_changes_volume_sign() {
        let mut m = MeshData {
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            dropped: 0,
        };
        assert!(m.is_closed());
        assert!((m.signed_volume6() - 1.0).abs() < 1e-15);
        m.flip();
        assert!((m.signed_volume6() + 1.0).abs() < 1e-15);
        m.triangles.pop();
        assert!(!m.is_closed());
    }
}
