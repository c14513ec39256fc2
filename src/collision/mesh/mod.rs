//! Mesh files for collision geometry, read into one indexed triangle list.
//!
//! Formats, chosen by the file extension (case-insensitive):
//! - **STL**, binary and ASCII, parsed by the `mesh-loader` crate. armsim decides which:
//!   a file is binary when its size is exactly `84 + 50 n` bytes with `n` the triangle
//!   count stored at byte 80 (so binary files whose 80-byte header starts with `solid`, as
//!   many CAD exports do, are read correctly); otherwise it must be ASCII text starting
//!   with `solid` (`solid … facet normal … outer loop … vertex x y z … endloop endfacet …
//!   endsolid`, several solids allowed). Normals are ignored. mesh-loader's own rule
//!   differs (it tries ASCII first whenever the text starts with `solid`, and takes a
//!   binary file's count from its length, ignoring the declared one), so armsim keeps its
//!   rule and hands mesh-loader only input that its rule has classified (see
//!   `read_stl_binary` and `read_stl_ascii`).
//! - **OBJ** (Wavefront), parsed by `mesh-loader`: every group, polygons triangulated as
//!   fans; points, lines and materials are not read. armsim checks the face indices first
//!   (naming the line) and counts the triangles they make against [`MAX_TRIANGLES`].
//! - **DAE** (COLLADA 1.4/1.5): armsim's own reader ([`read_dae`], with `roxmltree`), not
//!   mesh-loader's: mesh-loader 0.1.13 places each geometry once, with the transform of
//!   the last node walked that instances it (a geometry placed twice comes out once), it
//!   scales by `<unit meter>` only through the instanced visual scene's root, and it
//!   indexes positions unchecked and asserts on accessor sizes (a panic on hostile input);
//!   its per-geometry parse is not public. The subset read:
//!   - every `<geometry>/<mesh>` of `<library_geometries>`: `<source>` `<float_array>`s
//!     (with the `<accessor>` stride), `<vertices>`/`<input semantic="POSITION">`, and the
//!     primitives `<triangles>`, `<polylist>` (with `<vcount>`, polygons fanned) and
//!     `<polygons>` (one `<p>` per polygon), each with any number of interleaved inputs
//!     (the index stride is the largest `offset` + 1);
//!   - placement: the nodes of the `<visual_scene>` named by `<scene>` (else the first)
//!     are walked, composing `<matrix>`, `<translate>`, `<rotate>` and `<scale>` in order,
//!     and each `<instance_geometry>` is placed with its node's transform (a geometry
//!     instanced by several nodes is placed once per node); when the scene instantiates no
//!     geometry, every geometry is taken untransformed;
//!   - `<asset><unit meter="…">` scales the result (placed or not);
//!   - not supported: `<lines>`, `<linestrips>`, `<trifans>`, `<tristrips>` (skipped),
//!     `<instance_node>`, `<library_nodes>`, controllers/skinning, and `<up_axis>`
//!     (ignored: coordinates are used as written).
//!
//! Precision: mesh-loader reads coordinates as f32 (binary STL stores f32 anyway); an
//! ASCII STL or OBJ coordinate is the f32 nearest to the decimal written, within 6e-8 of
//! it relatively (DAE coordinates are f64). `tests/mesh_reference.rs` checks that every
//! bundled mesh gives the counts, bounding box, volume and closedness of the f64 readers.
//!
//! Vertices with identical coordinates are merged (mesh-loader gives three unshared
//! vertices per face), so that closedness (every edge shared by exactly two triangles)
//! can be tested afterwards.
//!
//! Limits: a file is refused above [`crate::core::files::MAX_MESH_BYTES`] before it is read, and
//! a mesh of more than [`MAX_TRIANGLES`] triangles (a binary STL's declared count, checked
//! before anything is allocated from it; an OBJ's faces, counted before mesh-loader
//! parses them; a DAE scene's placed total) is refused; every coordinate must be finite
//! (mesh-loader turns an out-of-range decimal into an f32 infinity, refused here).
//!
//! Errors: the readers of bytes and text ([`read_stl`], [`read_obj_bytes`], [`read_dae`])
//! return a [`MeshError`] (the format, the line where the format is text and the place is
//! known, the problem with mesh-loader's line and column where it gives them);
//! [`load_mesh`] returns it as a [`LocatedError`] naming the file.

mod dae;
mod mesh_data;
mod mesh_error;
pub use dae::read_dae;
pub use mesh_data::{MeshData, MAX_TRIANGLES};
pub use mesh_error::{MeshError, NonFiniteVertex};

use crate::core::diag::LocatedError;

use std::collections::HashMap;
use std::path::Path;

/// Reads a mesh file (STL, OBJ or DAE, by extension). Errors name the file, the line
/// where known, the format and the problem (the caller adds the link and URI).
pub fn load_mesh(path: &Path) -> Result<MeshData, LocatedError> {
    let file = path.display().to_string();
    read_mesh_file(path).map_err(|e| e.in_file(&file))
}

/// [`load_mesh`] before the file is named in the error.
fn read_mesh_file(path: &Path) -> Result<MeshData, MeshError> {
    let cannot_read = |e: std::io::Error| MeshError::new("", None, format!("cannot read: {e}"));
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let mesh = match ext.as_str() {
        "stl" => {
            let bytes =
                crate::core::files::read_input_max(path, crate::core::files::MAX_MESH_BYTES)
                    .map_err(cannot_read)?;
            read_stl(&bytes)?
        }
        "obj" => read_obj(path)?,
        "dae" => {
            let text =
                crate::core::files::read_input_string_max(path, crate::core::files::MAX_MESH_BYTES)
                    .map_err(cannot_read)?;
            read_dae(&text)?
        }
        _ => {
            return Err(MeshError::new(
                "",
                None,
                format!("unsupported mesh format '.{ext}': expected .stl, .obj or .dae"),
            ))
        }
    };
    if mesh.triangles.is_empty() && mesh.dropped > 0 {
        return Err(MeshError::new(
            "",
            None,
            format!(
                "all {} triangles of the mesh have zero area (a repeated corner)",
                mesh.dropped
            ),
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(MeshError::new("", None, "the mesh has no triangles"));
    }
    Ok(mesh)
}

/// Parses STL bytes, binary or ASCII (see the module docs for the detection rule).
pub fn read_stl(bytes: &[u8]) -> Result<MeshData, MeshError> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if n.checked_mul(50).and_then(|b| b.checked_add(84)) == Some(bytes.len()) {
            if n > MAX_TRIANGLES {
                return Err(MeshError::new(
                    "",
                    None,
                    format!(
                        "binary STL of {n} triangles: more than the mesh limit of {MAX_TRIANGLES}"
                    ),
                ));
            }
            return read_stl_binary(bytes, n);
        }
    }
    if std::str::from_utf8(bytes).is_err() {
        return Err(MeshError::new(
            "",
            None,
            "not a binary STL (the size is not 84 + 50 × the triangle count) and not ASCII text",
        ));
    }
    read_stl_ascii(bytes)
}

/// A binary STL of `n` declared triangles (`n` already checked against its length and
/// [`MAX_TRIANGLES`]), parsed by `mesh-loader`. mesh-loader tries ASCII first when the
/// header starts with `solid` (as many CAD exports' do) and takes the triangle count from
/// the length: such a header is blanked in a copy, so that armsim's detection rule decides.
fn read_stl_binary(bytes: &[u8], n: usize) -> Result<MeshData, MeshError> {
    const BINARY: &str = "binary STL";
    let blanked;
    let bytes = if starts_with_solid(bytes) {
        let mut b = bytes.to_vec();
        b[..80].fill(0);
        blanked = b;
        &blanked[..]
    } else {
        bytes
    };
    let scene = mesh_loader::stl::from_slice(bytes)
        .map_err(|e| MeshError::new(BINARY, None, e.to_string()))?;
    let got: usize = scene.meshes.iter().map(|m| m.faces.len()).sum();
    if got != n {
        return Err(MeshError::new(
            BINARY,
            None,
            format!("{got} triangles read where {n} are declared"),
        ));
    }
    weld(&scene.meshes, MAX_TRIANGLES, BINARY)
}

/// Whether `bytes` start with `solid` after spaces and line breaks (where `mesh-loader`
/// takes a file for ASCII STL).
fn starts_with_solid(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    bytes[start..].starts_with(b"solid")
}

/// An ASCII STL (not of binary length), parsed by `mesh-loader` (`solid … facet normal …
/// outer loop … vertex x y z … endloop endfacet … endsolid`, several solids allowed).
/// mesh-loader falls back to binary when its ASCII parse fails early and the length would
/// fit 50-byte records; armsim's rule says this file is not binary, so it is given with
/// three bytes of whitespace appended when the fallback could apply (no 50-byte fit then).
fn read_stl_ascii(bytes: &[u8]) -> Result<MeshData, MeshError> {
    const ASCII: &str = "ASCII STL";
    if !starts_with_solid(bytes) {
        return Err(MeshError::new(
            "",
            None,
            "not a binary STL (the size is not 84 + 50 × the triangle count) and not an \
             ASCII STL (it does not start with 'solid')",
        ));
    }
    let padded;
    let fits_binary = bytes.len() >= 84 && (bytes.len() - 84) % 50 <= 2;
    let bytes = if fits_binary {
        let mut b = Vec::with_capacity(bytes.len() + 3);
        b.extend_from_slice(bytes);
        b.extend_from_slice(b"\n \n");
        padded = b;
        &padded[..]
    } else {
        bytes
    };
    let scene = mesh_loader::stl::from_slice(bytes).map_err(|e| {
        let e = e.to_string();
        if e.contains("failed to determine STL storage representation") {
            MeshError::new(
                ASCII,
                None,
                "unreadable after 'solid' (an ASCII name and a line end, then \
                 'facet normal x y z', expected)",
            )
        } else {
            located(ASCII, &e)
        }
    })?;
    weld(&scene.meshes, MAX_TRIANGLES, ASCII)
}

/// A `mesh-loader` message `MESSAGE (LINE:COLUMN)` of `format` as `line LINE, column
/// COLUMN: MESSAGE` on line `LINE` (other messages unchanged, with no line).
fn located(format: &'static str, e: &str) -> MeshError {
    let place = e
        .strip_suffix(')')
        .and_then(|s| s.rsplit_once(" ("))
        .and_then(|(msg, at)| Some((msg, at.split_once(':')?)))
        .filter(|(_, (l, c))| l.parse::<usize>().is_ok() && c.parse::<usize>().is_ok());
    match place {
        Some((msg, (l, c))) => MeshError::new(
            format,
            l.parse().ok(),
            format!("line {l}, column {c}: {msg}"),
        ),
        None => MeshError::new(format, None, e),
    }
}

/// Merges `mesh-loader` meshes into one [`MeshData`], welding identical positions
/// (mesh-loader gives three unshared f32 vertices per face). More than `max` triangles in
/// all is an error, and so is a face index out of range (not expected from mesh-loader);
/// errors are of `format`.
fn weld(
    meshes: &[mesh_loader::Mesh],
    max: usize,
    format: &'static str,
) -> Result<MeshData, MeshError> {
    let total: usize = meshes.iter().map(|m| m.faces.len()).sum();
    if total > max {
        return Err(MeshError::new(
            format,
            None,
            format!("{total} triangles: more than the mesh limit of {max}"),
        ));
    }
    let mut mesh = MeshData::default();
    let mut index = HashMap::with_capacity(total / 2);
    let mut k = 0usize;
    for m in meshes {
        for f in &m.faces {
            k += 1;
            let p = |i: u32| {
                m.vertices
                    .get(i as usize)
                    .map(|v| v.map(f64::from))
                    .ok_or_else(|| {
                        MeshError::new(
                            format,
                            None,
                            format!("triangle {k}: vertex index {i} out of range"),
                        )
                    })
            };
            let tri = [p(f[0])?, p(f[1])?, p(f[2])?];
            mesh.push_triangle(&mut index, tri)
                .map_err(|e| MeshError::new(format, None, format!("triangle {k}: {e}")))?;
        }
    }
    Ok(mesh)
}

/// The OBJ format's name in errors.
const OBJ: &str = "OBJ";

fn read_obj(path: &Path) -> Result<MeshData, MeshError> {
    let bytes = crate::core::files::read_input_max(path, crate::core::files::MAX_MESH_BYTES)
        .map_err(|e| MeshError::new("", None, format!("cannot read: {e}")))?;
    read_obj_bytes(&bytes)
}

/// Parses Wavefront OBJ bytes with `mesh-loader` (every group; polygons fanned; points,
/// lines and materials are not read). The faces are checked first by armsim
/// ([`check_obj_indices`]): indices in range, with the line named, and at most
/// [`MAX_TRIANGLES`] triangles before mesh-loader allocates them.
pub fn read_obj_bytes(bytes: &[u8]) -> Result<MeshData, MeshError> {
    // mesh-loader decodes UTF-16 (with a byte-order mark) before parsing, which the
    // pre-scan would not see through: refused, as tobj did.
    if bytes.starts_with(&[0xFE, 0xFF]) || bytes.starts_with(&[0xFF, 0xFE]) {
        return Err(MeshError::new(
            OBJ,
            None,
            "UTF-16 text is not read (save the file as UTF-8)",
        ));
    }
    // Lossy: the lines that are UTF-8 keep their text (mesh-loader reads bytes); a UTF-8
    // byte-order mark is skipped, as mesh-loader does.
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let tris = check_obj_indices(&String::from_utf8_lossy(text))?;
    if tris > MAX_TRIANGLES {
        return Err(MeshError::new(
            OBJ,
            None,
            format!("the faces make {tris} triangles, more than the mesh limit of {MAX_TRIANGLES}"),
        ));
    }
    // Materials are not needed: every `mtllib` is answered with "not loaded" (and with
    // no path given, mesh-loader asks for none).
    let scene = mesh_loader::obj::from_slice(bytes, None, |_| {
        Err::<Vec<u8>, _>(std::io::Error::other("materials are not read"))
    })
    .map_err(|e| located(OBJ, &e.to_string()))?;
    weld(&scene.meshes, MAX_TRIANGLES, OBJ)
}

/// Checks every face and line index of an OBJ before `mesh-loader` parses it, and counts
/// the triangles its faces make. mesh-loader bounds-checks indices too, but names the end
/// of the file as the place; this names the line. A negative (relative) index must stay
/// within the elements of its kind read so far, a positive one within those of the whole
/// file, and 0 is no index. Lines are split at `\n` and at a lone `\r` (mesh-loader ends a
/// line at either), so no face escapes the count.
fn check_obj_indices(text: &str) -> Result<usize, MeshError> {
    let kinds = ["vertex", "texture coordinate", "normal"];
    let lines = || {
        text.split('\n')
            .enumerate()
            .flat_map(|(n, l)| l.split('\r').map(move |l| (n + 1, l)))
    };
    let mut total = [0usize; 3];
    for (_, l) in lines() {
        match l.split_whitespace().next() {
            Some("v") => total[0] += 1,
            Some("vt") => total[1] += 1,
            Some("vn") => total[2] += 1,
            _ => {}
        }
    }
    let mut seen = [0usize; 3];
    let mut triangles = 0usize;
    for (n, l) in lines() {
        let mut words = l.split_whitespace();
        match words.next() {
            Some("v") => seen[0] += 1,
            Some("vt") => seen[1] += 1,
            Some("vn") => seen[2] += 1,
            Some(w @ ("f" | "l")) => {
                let mut corners = 0usize;
                for w in words {
                    corners += 1;
                    check_obj_corner(w, n, &seen, &total, &kinds)?;
                }
                if w == "f" {
                    triangles += corners.saturating_sub(2);
                }
            }
            _ => {}
        }
    }
    Ok(triangles)
}

/// One `v/vt/vn` corner of a face or line on line `n` (see [`check_obj_indices`]).
fn check_obj_corner(
    w: &str,
    n: usize,
    seen: &[usize; 3],
    total: &[usize; 3],
    kinds: &[&str; 3],
) -> Result<(), MeshError> {
    for (k, part) in w.split('/').take(3).enumerate() {
        let Ok(x) = part.parse::<isize>() else {
            continue; // empty (v//vn) or malformed: mesh-loader decides
        };
        let (bad, limit) = if x < 0 {
            (x.unsigned_abs() > seen[k], seen[k])
        } else {
            (x == 0 || x as usize > total[k], total[k])
        };
        if bad {
            return Err(MeshError::new(
                OBJ,
                Some(n),
                format!(
                    "line {n}: index {x} of a {} is out of range ({limit} {})",
                    kinds[k],
                    if x < 0 {
                        "before it"
                    } else {
                        "in the file, from 1"
                    }
                ),
            ));
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
        let e = read_stl(t.as_bytes()).unwrap_err().to_string();
        assert_eq!(e, "ASCII STL: line 7, column 1: expected endloop");
        let t = "solid x\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 x\n";
        let e = read_stl(t.as_bytes()).unwrap_err().to_string();
        assert!(e.starts_with("ASCII STL: line 5, column "), "{e}");
        assert!(e.ends_with(": error while parsing a float"), "{e}");
        // mesh-loader reads 1e39 as an f32 infinity: refused by armsim's finite check.
        let t = "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e39 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n";
        let e = read_stl(t.as_bytes()).unwrap_err().to_string();
        assert_eq!(e, "ASCII STL: triangle 1: vertex (inf, 0, 0) is not finite");
    }

    #[test]
    fn tetrahedron_is_closed_and_flip_changes_volume_sign() {
        let mut m = MeshData {
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            dropped: 0,
            ..Default::default()
        };
        assert!(m.is_closed());
        assert!((m.signed_volume6() - 1.0).abs() < 1e-15);
        m.flip();
        assert!((m.signed_volume6() + 1.0).abs() < 1e-15);
        m.triangles.pop();
        assert!(!m.is_closed());
    }
}
