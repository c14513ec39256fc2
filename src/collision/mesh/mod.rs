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

use nalgebra::{Matrix4, Vector3, Vector4};
use std::collections::HashMap;
use std::path::Path;

/// An indexed triangle mesh in f64.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
}

impl MeshData {
    /// Adds a triangle given by its corner positions, merging identical vertices through
    /// `index` (keyed by the bit patterns, `-0.0` folded onto `0.0`).
    fn push_triangle(&mut self, index: &mut HashMap<[u64; 3], u32>, tri: [[f64; 3]; 3]) {
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
        }
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
            let bytes = crate::io::read_input(path).map_err(|e| format!("cannot read: {e}"))?;
            read_stl(&bytes)?
        }
        "obj" => read_obj(path)?,
        "dae" => {
            let text =
                crate::io::read_input_string(path).map_err(|e| format!("cannot read: {e}"))?;
            read_dae(&text)?
        }
        _ => {
            return Err(format!(
                "unsupported mesh format '.{ext}': expected .stl, .obj or .dae"
            ))
        }
    };
    if mesh.triangles.is_empty() {
        return Err("the mesh has no triangles".to_string());
    }
    if mesh.vertices.iter().flatten().any(|x| !x.is_finite()) {
        return Err("the mesh has a non-finite vertex coordinate".to_string());
    }
    Ok(mesh)
}

/// Parses STL bytes, binary or ASCII (see the module docs for the detection rule).
pub fn read_stl(bytes: &[u8]) -> Result<MeshData, String> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if n.checked_mul(50).and_then(|b| b.checked_add(84)) == Some(bytes.len()) {
            return Ok(read_stl_binary(&bytes[84..], n));
        }
    }
    let text = std::str::from_utf8(bytes).map_err(|_| {
        "not a binary STL (the size is not 84 + 50 × the triangle count) and not ASCII text"
            .to_string()
    })?;
    read_stl_ascii(text)
}

fn read_stl_binary(body: &[u8], n: usize) -> MeshData {
    let mut mesh = MeshData::default();
    let mut index = HashMap::with_capacity(n);
    let f = |b: &[u8], k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]) as f64;
    for rec in body.chunks_exact(50).take(n) {
        // 12 bytes of normal, then three vertices.
        let v = |j: usize| {
            let o = 12 + 12 * j;
            [f(rec, o), f(rec, o + 4), f(rec, o + 8)]
        };
        mesh.push_triangle(&mut index, [v(0), v(1), v(2)]);
    }
    mesh
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
            mesh.push_triangle(&mut index, [corners[0], corners[1], corners[2]]);
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

// `..Default::default()` fills the fields behind tobj features another crate may enable.
#[allow(clippy::needless_update)]
fn read_obj(path: &Path) -> Result<MeshData, String> {
    let bytes = crate::io::read_input(path).map_err(|e| format!("cannot read: {e}"))?;
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
        for t in m.mesh.indices.chunks_exact(3) {
            mesh.push_triangle(&mut index, [p(t[0])?, p(t[1])?, p(t[2])?]);
        }
    }
    Ok(mesh)
}

/// Local tag name (COLLADA files carry a default namespace).
fn is(n: &roxmltree::Node, name: &str) -> bool {
    n.is_element() && n.tag_name().name() == name
}

fn child<'a, 'i>(n: &roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    n.children().find(|c| is(c, name))
}

fn floats(text: Option<&str>, what: &str) -> Result<Vec<f64>, String> {
    text.unwrap_or("")
        .split_ascii_whitespace()
        .map(|s| {
            s.parse::<f64>()
                .map_err(|_| format!("DAE: {what}: '{s}' is not a number"))
        })
        .collect()
}

fn ints(text: Option<&str>, what: &str) -> Result<Vec<usize>, String> {
    text.unwrap_or("")
        .split_ascii_whitespace()
        .map(|s| {
            s.parse::<usize>()
                .map_err(|_| format!("DAE: {what}: '{s}' is not an index"))
        })
        .collect()
}

/// `#id` → `id`.
fn url_id(url: &str) -> &str {
    url.strip_prefix('#').unwrap_or(url)
}

/// Positions and triangles (position indices) of one COLLADA geometry.
type Geom = (Vec<[f64; 3]>, Vec<[usize; 3]>);

/// A `<mesh>`'s float sources (id → values and stride) and its `<vertices>` (id → the
/// id of their POSITION source).
#[allow(clippy::type_complexity)]
fn dae_sources<'a>(
    mesh: &roxmltree::Node<'a, '_>,
    gid: &str,
) -> Result<
    (
        HashMap<&'a str, (Vec<f64>, usize)>,
        HashMap<&'a str, &'a str>,
    ),
    String,
> {
    // Sources: id → (values, stride).
    let mut sources: HashMap<&str, (Vec<f64>, usize)> = HashMap::new();
    for s in mesh.children().filter(|c| is(c, "source")) {
        let id = s.attribute("id").unwrap_or("");
        let Some(fa) = child(&s, "float_array") else {
            continue;
        };
        let vals = floats(fa.text(), &format!("geometry '{gid}' source '{id}'"))?;
        let stride = child(&s, "technique_common")
            .and_then(|t| child(&t, "accessor"))
            .and_then(|a| a.attribute("stride"))
            .and_then(|s| s.parse::<usize>().ok())
            .unwrap_or(3)
            .max(3);
        sources.insert(id, (vals, stride));
    }
    // <vertices id> → POSITION source id.
    let mut vertices_pos: HashMap<&str, &str> = HashMap::new();
    for v in mesh.children().filter(|c| is(c, "vertices")) {
        if let Some(inp) = v
            .children()
            .find(|c| is(c, "input") && c.attribute("semantic") == Some("POSITION"))
        {
            vertices_pos.insert(
                v.attribute("id").unwrap_or(""),
                url_id(inp.attribute("source").unwrap_or("")),
            );
        }
    }
    Ok((sources, vertices_pos))
}

/// Reads one `<mesh>` into positions and triangles (position indices).
fn dae_geometry(mesh: &roxmltree::Node, gid: &str) -> Result<Geom, String> {
    let (sources, vertices_pos) = dae_sources(mesh, gid)?;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut base_of: HashMap<&str, usize> = HashMap::new();
    let mut tris: Vec<[usize; 3]> = Vec::new();
    for prim in mesh.children().filter(|c| c.is_element()) {
        let kind = prim.tag_name().name();
        if !matches!(kind, "triangles" | "polylist" | "polygons") {
            continue;
        }
        let inputs: Vec<roxmltree::Node> = prim.children().filter(|c| is(c, "input")).collect();
        let stride = inputs
            .iter()
            .filter_map(|i| i.attribute("offset").and_then(|o| o.parse::<usize>().ok()))
            .max()
            .unwrap_or(0)
            + 1;
        let Some(vin) = inputs
            .iter()
            .find(|i| matches!(i.attribute("semantic"), Some("VERTEX") | Some("POSITION")))
        else {
            return Err(format!(
                "DAE: geometry '{gid}': <{kind}> has no VERTEX input"
            ));
        };
        let voff: usize = vin
            .attribute("offset")
            .and_then(|o| o.parse().ok())
            .unwrap_or(0);
        let src = url_id(vin.attribute("source").unwrap_or(""));
        let src = vertices_pos.get(src).copied().unwrap_or(src);
        let Some((vals, vstride)) = sources.get(src) else {
            return Err(format!(
                "DAE: geometry '{gid}': position source '{src}' not found"
            ));
        };
        // Each position source is appended once.
        let base = *base_of.entry(src).or_insert_with(|| {
            let b = positions.len();
            positions.extend(vals.chunks_exact(*vstride).map(|c| [c[0], c[1], c[2]]));
            b
        });
        let npos = vals.len() / vstride;
        let what = format!("geometry '{gid}' <{kind}>");
        let vertex = |p: &[usize], k: usize| -> Result<usize, String> {
            let i = *p
                .get(k * stride + voff)
                .ok_or_else(|| format!("DAE: {what}: <p> is cut short"))?;
            if i >= npos {
                return Err(format!("DAE: {what}: position index {i} out of range"));
            }
            Ok(base + i)
        };
        let mut fan = |p: &[usize], first: usize, n: usize| -> Result<(), String> {
            for k in 1..n.saturating_sub(1) {
                tris.push([
                    vertex(p, first)?,
                    vertex(p, first + k)?,
                    vertex(p, first + k + 1)?,
                ]);
            }
            Ok(())
        };
        match kind {
            "triangles" => {
                let p = ints(child(&prim, "p").and_then(|p| p.text()), &what)?;
                for t in 0..p.len() / (3 * stride) {
                    fan(&p, 3 * t, 3)?;
                }
            }
            "polylist" => {
                let p = ints(child(&prim, "p").and_then(|p| p.text()), &what)?;
                let vcount = ints(child(&prim, "vcount").and_then(|p| p.text()), &what)?;
                let mut first = 0;
                for n in vcount {
                    fan(&p, first, n)?;
                    first += n;
                }
            }
            _ => {
                for pe in prim.children().filter(|c| is(c, "p")) {
                    let p = ints(pe.text(), &what)?;
                    fan(&p, 0, p.len() / stride)?;
                }
            }
        }
    }
    Ok((positions, tris))
}

/// Composes the transform elements of a `<node>` in document order.
fn node_transform(node: &roxmltree::Node) -> Result<Matrix4<f64>, String> {
    let mut m = Matrix4::identity();
    for c in node.children().filter(|c| c.is_element()) {
        let what = format!(
            "node '{}' <{}>",
            node.attribute("id").unwrap_or(""),
            c.tag_name().name()
        );
        let t = match c.tag_name().name() {
            "matrix" => {
                let v = floats(c.text(), &what)?;
                if v.len() != 16 {
                    return Err(format!("DAE: {what}: expected 16 numbers"));
                }
                Matrix4::from_row_slice(&v)
            }
            "translate" => {
                let v = floats(c.text(), &what)?;
                if v.len() != 3 {
                    return Err(format!("DAE: {what}: expected 3 numbers"));
                }
                Matrix4::new_translation(&Vector3::new(v[0], v[1], v[2]))
            }
            "scale" => {
                let v = floats(c.text(), &what)?;
                if v.len() != 3 {
                    return Err(format!("DAE: {what}: expected 3 numbers"));
                }
                Matrix4::new_nonuniform_scaling(&Vector3::new(v[0], v[1], v[2]))
            }
            "rotate" => {
                let v = floats(c.text(), &what)?;
                if v.len() != 4 {
                    return Err(format!("DAE: {what}: expected 4 numbers"));
                }
                let axis = Vector3::new(v[0], v[1], v[2]);
                if axis.norm() == 0.0 {
                    Matrix4::identity()
                } else {
                    let r = crate::spatial::axis_angle(&axis.normalize(), v[3].to_radians());
                    r.to_homogeneous()
                }
            }
            _ => continue,
        };
        m *= t;
    }
    Ok(m)
}

/// Parses COLLADA text (see the module docs for the subset).
pub fn read_dae(text: &str) -> Result<MeshData, String> {
    let doc = roxmltree::Document::parse(text).map_err(|e| format!("DAE: not valid XML: {e}"))?;
    let root = doc.root_element();
    let unit = child(&root, "asset")
        .and_then(|a| child(&a, "unit"))
        .and_then(|u| u.attribute("meter"))
        .and_then(|m| m.parse::<f64>().ok())
        .filter(|m| m.is_finite() && *m > 0.0)
        .unwrap_or(1.0);
    let mut geoms: Vec<(&str, Geom)> = Vec::new();
    if let Some(lib) = child(&root, "library_geometries") {
        for g in lib.children().filter(|c| is(c, "geometry")) {
            let gid = g.attribute("id").unwrap_or("");
            if let Some(m) = child(&g, "mesh") {
                geoms.push((gid, dae_geometry(&m, gid)?));
            }
        }
    }
    if geoms.is_empty() {
        return Err("DAE: no <geometry> with a <mesh> in <library_geometries>".to_string());
    }
    // Instances from the visual scene.
    let mut instances: Vec<(usize, Matrix4<f64>)> = Vec::new();
    if let Some(lib) = child(&root, "library_visual_scenes") {
        let wanted = child(&root, "scene")
            .and_then(|s| child(&s, "instance_visual_scene"))
            .and_then(|i| i.attribute("url"))
            .map(url_id);
        let scenes: Vec<roxmltree::Node> =
            lib.children().filter(|c| is(c, "visual_scene")).collect();
        let scene = wanted
            .and_then(|w| scenes.iter().find(|s| s.attribute("id") == Some(w)))
            .or(scenes.first());
        if let Some(scene) = scene {
            let mut stack: Vec<(roxmltree::Node, Matrix4<f64>)> = scene
                .children()
                .filter(|c| is(c, "node"))
                .map(|n| (n, Matrix4::identity()))
                .collect();
            while let Some((node, parent)) = stack.pop() {
                let m = parent * node_transform(&node)?;
                for c in node.children().filter(|c| c.is_element()) {
                    if is(&c, "node") {
                        stack.push((c, m));
                    } else if is(&c, "instance_geometry") {
                        let id = url_id(c.attribute("url").unwrap_or(""));
                        if let Some(k) = geoms.iter().position(|g| g.0 == id) {
                            instances.push((k, m));
                        }
                    }
                }
            }
        }
    }
    if instances.is_empty() {
        instances = (0..geoms.len()).map(|k| (k, Matrix4::identity())).collect();
    }
    let mut mesh = MeshData::default();
    let mut index = HashMap::new();
    for (k, m) in instances {
        let (_, (pos, tris)) = &geoms[k];
        // A mirroring node transform reverses the winding.
        let mirror = m.fixed_view::<3, 3>(0, 0).determinant() < 0.0;
        let place = |i: usize| {
            let p = m * Vector4::new(pos[i][0], pos[i][1], pos[i][2], 1.0);
            [p.x * unit, p.y * unit, p.z * unit]
        };
        for t in tris {
            let (a, b, c) = (place(t[0]), place(t[1]), place(t[2]));
            mesh.push_triangle(&mut index, if mirror { [a, c, b] } else { [a, b, c] });
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        };
        assert!(m.is_closed());
        assert!((m.signed_volume6() - 1.0).abs() < 1e-15);
        m.flip();
        assert!((m.signed_volume6() + 1.0).abs() < 1e-15);
        m.triangles.pop();
        assert!(!m.is_closed());
    }
}
