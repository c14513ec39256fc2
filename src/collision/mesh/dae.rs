//! COLLADA (`.dae`) meshes: the subset described in the parent module's docs, read with
//! `roxmltree`, with every number taken from the file range-checked before it is used:
//!
//! - the nesting is pre-scanned ([`MAX_DEPTH`]) before `roxmltree` recurses into it;
//! - an `<input offset>` must lie inside its primitive's `<p>`, a `<vcount>` must not
//!   declare more indices than `<p>` holds, an `<accessor stride>` must fit its
//!   `<float_array>`, and every index must name an existing position;
//! - coordinates and node transforms must be finite, and placed vertices must stay finite;
//! - the scene may place at most [`MAX_INSTANCES`] geometries and
//!   [`crate::collision::mesh::MAX_TRIANGLES`] triangles in all, counted before any is placed (a
//!   small file placing one large geometry many times would otherwise expand without bound).
//!
//! Errors ([`MeshError`]) name the element and its line; the caller adds the file. An
//! `<instance_geometry>` whose URL names no geometry of the file (a missing id, another
//! file's, no URL) is skipped with a warning naming its line and URL
//! ([`MeshData::warnings`]).
//!
//! Why this reader and not `mesh-loader`'s (which reads STL and OBJ for armsim, issue 27),
//! as of mesh-loader 0.1.13 (`src/collada/instance.rs`, `iter.rs`):
//! - placements: it builds one mesh per `<geometry>`, its transform looked up in a map
//!   keyed by the geometry URL that every `<instance_geometry>` overwrites, so a geometry
//!   instanced by two nodes comes out once, at the last node's place
//!   (`tests/mesh_reference.rs`, `a_geometry_instanced_twice_gives_both_copies_in_place`,
//!   is the case: mesh-loader gives 12 triangles at z ∈ [2.75, 3.25], this reader 24);
//! - `<unit meter>` is folded into the transform of the visual scene's root only, so a
//!   geometry no node instances is not scaled;
//! - hostile input: positions are indexed without a bounds check and accessor sizes are
//!   `assert!`ed (panics), transforms are f32, and nesting is not pre-scanned (roxmltree
//!   recurses once per level);
//! - its geometry parse without placement is not public, so it cannot be used for the
//!   geometry alone under armsim's placement.

use crate::collision::mesh::mesh_data::{MeshData, MAX_TRIANGLES};
use crate::collision::mesh::mesh_error::MeshError;
use crate::core::xml_guard::LineIndex;
use nalgebra::{Matrix4, Vector3, Vector4};
use std::collections::HashMap;

/// Deepest element nesting accepted (COLLADA node hierarchies of robot exports need
/// a few dozen levels).
pub const MAX_DEPTH: usize = 256;

/// Most `<instance_geometry>` placements the visual scene may make.
pub const MAX_INSTANCES: usize = 100_000;

type Node<'a, 'i> = roxmltree::Node<'a, 'i>;

/// Local tag name (COLLADA files carry a default namespace).
fn is(n: &Node, name: &str) -> bool {
    n.is_element() && n.tag_name().name() == name
}

fn child<'a, 'i>(n: &Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    n.children().find(|c| is(c, name))
}

/// The format's name in errors.
const DAE: &str = "DAE";

/// An element errors are about: its description with its line (`what (line N)`), and the
/// line.
struct At {
    what: String,
    line: usize,
}

impl At {
    /// `what (line N)` on line `line`.
    fn new(what: impl std::fmt::Display, line: usize) -> At {
        At {
            what: format!("{what} (line {line})"),
            line,
        }
    }

    /// The error `what (line N): msg`.
    fn err(&self, msg: impl std::fmt::Display) -> MeshError {
        MeshError::new(DAE, Some(self.line), format!("{}: {msg}", self.what))
    }
}

/// Whitespace-separated finite numbers.
fn floats(text: Option<&str>, at: &At) -> Result<Vec<f64>, MeshError> {
    text.unwrap_or("")
        .split_ascii_whitespace()
        .map(|s| match s.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(_) => Err(at.err(format!("'{s}' is not a finite number"))),
            Err(_) => Err(at.err(format!("'{s}' is not a number"))),
        })
        .collect()
}

fn ints(text: Option<&str>, at: &At) -> Result<Vec<usize>, MeshError> {
    text.unwrap_or("")
        .split_ascii_whitespace()
        .map(|s| {
            s.parse::<usize>()
                .map_err(|_| at.err(format!("'{s}' is not an index")))
        })
        .collect()
}

/// `#id` → `id`.
fn url_id(url: &str) -> &str {
    url.strip_prefix('#').unwrap_or(url)
}

/// Positions and triangles (position indices) of one COLLADA geometry.
type Geom = (Vec<[f64; 3]>, Vec<[usize; 3]>);

/// A `<triangles>` list of `len` indices holds whole triangles of `stride` inputs each.
fn whole_triangles(len: usize, stride: usize, at: &At) -> Result<(), MeshError> {
    if len.is_multiple_of(3 * stride) {
        return Ok(());
    }
    Err(at.err(format!(
        "its <p> holds {len} indices, not a whole number of triangles of 3 vertices × \
         {stride} inputs"
    )))
}

/// The values and stride of position source `src`, whose stride must count x, y, z.
fn position_source<'s>(
    sources: &'s Sources,
    src: &str,
    at: &At,
) -> Result<(&'s [f64], usize), MeshError> {
    let Some((vals, vstride)) = sources.get(src) else {
        return Err(at.err(format!("position source '{src}' not found")));
    };
    if *vstride < 3 {
        return Err(at.err(format!(
            "position source '{src}': its <accessor stride> is not a count of at least 3 \
             values (x, y, z) per vertex"
        )));
    }
    Ok((vals, *vstride))
}

/// Float sources of a `<mesh>`: id → (values, stride).
type Sources<'a> = HashMap<&'a str, (Vec<f64>, usize)>;

/// A `<mesh>`'s float sources and its `<vertices>` (id → the id of their POSITION
/// source).
fn dae_sources<'a>(
    mesh: &Node<'a, '_>,
    gid: &str,
    lx: &LineIndex,
) -> Result<(Sources<'a>, HashMap<&'a str, &'a str>), MeshError> {
    let mut sources: Sources = HashMap::new();
    for s in mesh.children().filter(|c| is(c, "source")) {
        let id = s.attribute("id").unwrap_or("");
        let Some(fa) = child(&s, "float_array") else {
            continue;
        };
        let at = At::new(
            format!("geometry '{gid}' source '{id}'"),
            lx.line(fa.range().start),
        );
        let vals = floats(fa.text(), &at)?;
        // 0 for a stride that does not parse: refused where the source is read as
        // positions (a normal or texture source may hold 2 values per vertex).
        let stride = child(&s, "technique_common")
            .and_then(|t| child(&t, "accessor"))
            .and_then(|a| a.attribute("stride"))
            .map_or(3, |v| v.trim().parse::<usize>().unwrap_or(0));
        if !vals.is_empty() && stride > vals.len() {
            return Err(at.err(format!(
                "<accessor stride=\"{stride}\"> is larger than the {} values \
                 of its <float_array>",
                vals.len()
            )));
        }
        sources.insert(id, (vals, stride));
    }
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

/// The index stride of a primitive (largest `<input offset>` + 1) and the offset of its
/// VERTEX input, each offset checked to lie within the `p_len` indices of its `<p>`.
fn input_offsets(prim: &Node, at: &At, p_len: usize) -> Result<(usize, usize), MeshError> {
    let mut stride = 1;
    let mut voff = None;
    for i in prim.children().filter(|c| is(c, "input")) {
        let off = match i.attribute("offset") {
            None => 0,
            Some(o) => o
                .trim()
                .parse::<usize>()
                .map_err(|_| at.err(format!("<input offset=\"{o}\">: not an index")))?,
        };
        if off >= p_len.max(1) {
            return Err(at.err(format!(
                "<input offset=\"{off}\"> is beyond the {p_len} indices of its <p>"
            )));
        }
        stride = stride.max(off + 1);
        if voff.is_none() && matches!(i.attribute("semantic"), Some("VERTEX" | "POSITION")) {
            voff = Some(off);
        }
    }
    let voff = voff.ok_or_else(|| at.err("no VERTEX input"))?;
    Ok((stride, voff))
}

/// Reads one `<mesh>` into positions and triangles (position indices).
fn dae_geometry(mesh: &Node, gid: &str, lx: &LineIndex) -> Result<Geom, MeshError> {
    let (sources, vertices_pos) = dae_sources(mesh, gid, lx)?;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut base_of: HashMap<&str, usize> = HashMap::new();
    let mut tris: Vec<[usize; 3]> = Vec::new();
    for prim in mesh.children().filter(|c| c.is_element()) {
        let kind = prim.tag_name().name();
        if !matches!(kind, "triangles" | "polylist" | "polygons") {
            continue;
        }
        let at = At::new(
            format!("geometry '{gid}' <{kind}>"),
            lx.line(prim.range().start),
        );
        let ps: Vec<Vec<usize>> = prim
            .children()
            .filter(|c| is(c, "p"))
            .map(|p| ints(p.text(), &at))
            .collect::<Result<_, _>>()?;
        let p_len = ps.iter().map(Vec::len).max().unwrap_or(0);
        if p_len == 0 {
            continue; // No indices: nothing to read (and no offset to check).
        }
        let (stride, voff) = input_offsets(&prim, &at, p_len)?;
        let vin = prim
            .children()
            .find(|i| {
                is(i, "input") && matches!(i.attribute("semantic"), Some("VERTEX" | "POSITION"))
            })
            .ok_or_else(|| at.err("no VERTEX input"))?;
        let src = url_id(vin.attribute("source").unwrap_or(""));
        let src = vertices_pos.get(src).copied().unwrap_or(src);
        let (vals, vstride) = position_source(&sources, src, &at)?;
        // Each position source is appended once.
        let base = *base_of.entry(src).or_insert_with(|| {
            let b = positions.len();
            positions.extend(vals.chunks_exact(vstride).map(|c| [c[0], c[1], c[2]]));
            b
        });
        let npos = vals.len() / vstride;
        // `k < p.len() / stride` throughout, so `k * stride + voff < p.len()`.
        let vertex = |p: &[usize], k: usize| -> Result<usize, MeshError> {
            let i = *p
                .get(k * stride + voff)
                .ok_or_else(|| at.err("<p> is cut short"))?;
            if i >= npos {
                return Err(at.err(format!(
                    "position index {i} out of range (the source has {npos})"
                )));
            }
            Ok(base + i)
        };
        let mut fan = |p: &[usize], first: usize, n: usize| -> Result<(), MeshError> {
            if tris.len() + n.saturating_sub(2) > MAX_TRIANGLES {
                return Err(at.err(format!(
                    "more than {MAX_TRIANGLES} triangles (the mesh limit)"
                )));
            }
            for k in 1..n.saturating_sub(1) {
                tris.push([
                    vertex(p, first)?,
                    vertex(p, first + k)?,
                    vertex(p, first + k + 1)?,
                ]);
            }
            Ok(())
        };
        let empty = Vec::new();
        let p = ps.first().unwrap_or(&empty);
        match kind {
            "triangles" => {
                whole_triangles(p.len(), stride, &at)?;
                for t in 0..p.len() / (3 * stride) {
                    fan(p, 3 * t, 3)?;
                }
            }
            "polylist" => {
                let vcount = ints(child(&prim, "vcount").and_then(|p| p.text()), &at)?;
                let held = p.len() / stride;
                let mut first = 0usize;
                for n in vcount {
                    if n > held - first {
                        return Err(at.err(format!(
                            "<vcount> declares more vertices than the {held} \
                             its <p> holds"
                        )));
                    }
                    fan(p, first, n)?;
                    first += n;
                }
            }
            _ => {
                for p in &ps {
                    fan(p, 0, p.len() / stride)?;
                }
            }
        }
    }
    Ok((positions, tris))
}

/// Composes the transform elements of a `<node>` in document order; every number must
/// be finite.
fn node_transform(node: &Node, lx: &LineIndex) -> Result<Matrix4<f64>, MeshError> {
    let mut m = Matrix4::identity();
    for c in node.children().filter(|c| c.is_element()) {
        let at = At::new(
            format_args!(
                "node '{}' <{}>",
                node.attribute("id").unwrap_or(""),
                c.tag_name().name()
            ),
            lx.line(c.range().start),
        );
        let want = match c.tag_name().name() {
            "matrix" => 16,
            "translate" | "scale" => 3,
            "rotate" => 4,
            _ => continue,
        };
        let v = floats(c.text(), &at)?;
        if v.len() != want {
            return Err(at.err(format!("expected {want} numbers")));
        }
        let t = match c.tag_name().name() {
            "matrix" => Matrix4::from_row_slice(&v),
            "translate" => Matrix4::new_translation(&Vector3::new(v[0], v[1], v[2])),
            "scale" => Matrix4::new_nonuniform_scaling(&Vector3::new(v[0], v[1], v[2])),
            _ => {
                let axis = Vector3::new(v[0], v[1], v[2]);
                if axis.norm() == 0.0 {
                    Matrix4::identity()
                } else {
                    let r = crate::core::spatial::axis_angle(&axis.normalize(), v[3].to_radians());
                    r.to_homogeneous()
                }
            }
        };
        m *= t;
        if m.iter().any(|x: &f64| !x.is_finite()) {
            return Err(at.err("the node's transform overflows the floating-point range"));
        }
    }
    Ok(m)
}

/// A geometry placed by a node: its index, the transform, and the node's id and line.
struct Instance {
    geom: usize,
    m: Matrix4<f64>,
    node: String,
    /// The line of the `<instance_geometry>` (none when no node places the geometry).
    line: Option<usize>,
}

/// Most `<instance_geometry>` elements whose URL resolves to nothing are named one by one
/// in the warnings; the rest are counted in one more.
const MAX_URL_WARNINGS: usize = 8;

/// The `<instance_geometry>` elements skipped because their URL names no geometry of the
/// file: warnings (with the line and the URL) for the first [`MAX_URL_WARNINGS`], then a
/// count.
#[derive(Default)]
struct Unresolved {
    warnings: Vec<MeshError>,
    more: usize,
}

impl Unresolved {
    /// Notes the skipped `<instance_geometry>` `c`.
    fn note(&mut self, c: &Node, lx: &LineIndex) {
        if self.warnings.len() >= MAX_URL_WARNINGS {
            self.more += 1;
            return;
        }
        let line = lx.line(c.range().start);
        let why = match c.attribute("url") {
            None => "has no url attribute".to_string(),
            Some(url) => match url.split_once('#') {
                Some((file, _)) if !file.is_empty() => format!(
                    "names a geometry in another file ('{file}'), which this reader does not \
                     follow"
                ),
                _ => "names no <geometry> with a <mesh> in this file's <library_geometries>"
                    .to_string(),
            },
        };
        let what = match c.attribute("url") {
            Some(url) => format!("<instance_geometry url=\"{url}\">"),
            None => "<instance_geometry>".to_string(),
        };
        self.warnings
            .push(At::new(what, line).err(format!("{why}: skipped")));
    }

    /// The warnings, with the count of those not named.
    fn into_warnings(mut self) -> Vec<MeshError> {
        if self.more > 0 {
            self.warnings.push(MeshError::new(
                DAE,
                None,
                format!(
                    "{} more <instance_geometry> elements name no geometry of this file: skipped",
                    self.more
                ),
            ));
        }
        self.warnings
    }
}

/// The geometries the `<visual_scene>` places (the one `<scene>` names, else the first),
/// counted against [`MAX_INSTANCES`] and [`MAX_TRIANGLES`] before any is placed.
fn scene_instances(
    root: &Node,
    geoms: &[(&str, Geom)],
    lx: &LineIndex,
    unresolved: &mut Unresolved,
) -> Result<Vec<Instance>, MeshError> {
    let mut instances = Vec::new();
    let Some(lib) = child(root, "library_visual_scenes") else {
        return Ok(instances);
    };
    let by_id: HashMap<&str, usize> = geoms.iter().enumerate().map(|(k, g)| (g.0, k)).collect();
    let wanted = child(root, "scene")
        .and_then(|s| child(&s, "instance_visual_scene"))
        .and_then(|i| i.attribute("url"))
        .map(url_id);
    let scenes: Vec<Node> = lib.children().filter(|c| is(c, "visual_scene")).collect();
    let Some(scene) = wanted
        .and_then(|w| scenes.iter().find(|s| s.attribute("id") == Some(w)))
        .or(scenes.first())
    else {
        return Ok(instances);
    };
    let mut stack: Vec<(Node, Matrix4<f64>)> = scene
        .children()
        .filter(|c| is(c, "node"))
        .map(|n| (n, Matrix4::identity()))
        .collect();
    let mut total = 0usize;
    while let Some((node, parent)) = stack.pop() {
        let m = parent * node_transform(&node, lx)?;
        for c in node.children().filter(|c| c.is_element()) {
            if is(&c, "node") {
                stack.push((c, m));
            } else if is(&c, "instance_geometry") {
                let id = url_id(c.attribute("url").unwrap_or(""));
                let Some(&k) = by_id.get(id) else {
                    unresolved.note(&c, lx);
                    continue;
                };
                total += geoms[k].1 .1.len();
                let line = lx.line(c.range().start);
                if instances.len() >= MAX_INSTANCES || total > MAX_TRIANGLES {
                    return Err(
                        At::new(format_args!("<instance_geometry url=\"#{id}\">"), line).err(
                            format!(
                                "the scene places more than {} (the mesh limit is {MAX_INSTANCES} \
                             placements and {MAX_TRIANGLES} triangles)",
                                if instances.len() >= MAX_INSTANCES {
                                    format!("{MAX_INSTANCES} geometries")
                                } else {
                                    format!("{MAX_TRIANGLES} triangles")
                                }
                            ),
                        ),
                    );
                }
                let node = format!(
                    "node '{}' (line {line})",
                    node.attribute("id").unwrap_or("")
                );
                instances.push(Instance {
                    geom: k,
                    m,
                    node,
                    line: Some(line),
                });
            }
        }
    }
    Ok(instances)
}

/// Parses COLLADA text (see the module docs for the subset and the checks).
pub fn read_dae(text: &str) -> Result<MeshData, MeshError> {
    let lx = LineIndex::new(text);
    if let Some(pos) = crate::core::xml_guard::too_deep(text, MAX_DEPTH) {
        let line = lx.line(pos);
        return Err(MeshError::new(
            DAE,
            Some(line),
            format!("line {line}: elements nested deeper than {MAX_DEPTH} levels"),
        ));
    }
    let doc = roxmltree::Document::parse(text)
        .map_err(|e| MeshError::new(DAE, None, format!("not valid XML: {e}")))?;
    let root = doc.root_element();
    // `<unit meter>`: a positive finite scale (exporters write 1, 0.001, 0.0254…); a
    // missing element means metres, a bad value is refused rather than read as 1.
    let unit = match child(&root, "asset")
        .and_then(|a| child(&a, "unit"))
        .and_then(|u| u.attribute_node("meter").map(|a| (u, a.value())))
    {
        None => 1.0,
        Some((u, v)) => match v.trim().parse::<f64>() {
            Ok(m) if m.is_finite() && m > 0.0 && m <= 1e6 => m,
            _ => {
                let line = lx.line(u.range().start);
                return Err(MeshError::new(
                    DAE,
                    Some(line),
                    format!(
                        "line {line}: <unit meter=\"{v}\">: expected a positive length in metres"
                    ),
                ));
            }
        },
    };
    let mut geoms: Vec<(&str, Geom)> = Vec::new();
    if let Some(lib) = child(&root, "library_geometries") {
        for g in lib.children().filter(|c| is(c, "geometry")) {
            let gid = g.attribute("id").unwrap_or("");
            if let Some(m) = child(&g, "mesh") {
                geoms.push((gid, dae_geometry(&m, gid, &lx)?));
            }
        }
    }
    if geoms.is_empty() {
        return Err(MeshError::new(
            DAE,
            None,
            "no <geometry> with a <mesh> in <library_geometries>",
        ));
    }
    let mut unresolved = Unresolved::default();
    let mut instances = scene_instances(&root, &geoms, &lx, &mut unresolved)?;
    if instances.is_empty() {
        let total: usize = geoms.iter().map(|g| g.1 .1.len()).sum();
        if total > MAX_TRIANGLES {
            return Err(MeshError::new(
                DAE,
                None,
                format!(
                    "the geometries hold {total} triangles, more than the mesh limit of \
                     {MAX_TRIANGLES}"
                ),
            ));
        }
        instances = (0..geoms.len())
            .map(|k| Instance {
                geom: k,
                m: Matrix4::identity(),
                node: "no node".into(),
                line: None,
            })
            .collect();
    }
    let mut mesh = place(&geoms, &instances, unit)?;
    mesh.warnings = unresolved.into_warnings();
    Ok(mesh)
}

/// The placed triangles of every instance, in metres. A flattening (singular) placement
/// is kept (its triangles may all lose their area): when nothing is left, the error
/// names the node.
fn place(geoms: &[(&str, Geom)], instances: &[Instance], unit: f64) -> Result<MeshData, MeshError> {
    let mut mesh = MeshData::default();
    let mut index = HashMap::new();
    let mut flat: Option<&Instance> = None;
    for inst in instances {
        let (gid, (pos, tris)) = &geoms[inst.geom];
        let m = &inst.m;
        // A mirroring node transform reverses the winding.
        let det = m.fixed_view::<3, 3>(0, 0).determinant();
        if det == 0.0 && !tris.is_empty() {
            flat.get_or_insert(inst);
        }
        let place = |i: usize| {
            let p = m * Vector4::new(pos[i][0], pos[i][1], pos[i][2], 1.0);
            [p.x * unit, p.y * unit, p.z * unit]
        };
        for t in tris {
            let (a, b, c) = (place(t[0]), place(t[1]), place(t[2]));
            mesh.push_triangle(&mut index, if det < 0.0 { [a, c, b] } else { [a, b, c] })
                .map_err(|e| {
                    MeshError::new(
                        DAE,
                        inst.line,
                        format!("geometry '{gid}' placed by {}: {e}", inst.node),
                    )
                })?;
        }
    }
    if mesh.triangles.is_empty() && mesh.dropped > 0 {
        return Err(match flat {
            Some(inst) => MeshError::new(
                DAE,
                inst.line,
                format!(
                    "all {} placed triangles have zero area: {} has a singular transform \
                     (a zero scale?)",
                    mesh.dropped, inst.node
                ),
            ),
            None => MeshError::new(
                DAE,
                None,
                format!(
                    "all {} triangles have zero area (coincident corners)",
                    mesh.dropped
                ),
            ),
        });
    }
    Ok(mesh)
}
