//! URDF → [`ModelSpec`], with `urdf-rs` reading the structure.
//!
//! `urdf-rs` reports problems without saying where, so a first pass over the XML with
//! `roxmltree` checks every element the model uses and names the file, the line and the
//! element in its errors (unknown joint types, missing names, non-finite numbers, …).
//! Unknown tags (`<transmission>`, `<gazebo>`, vendor extensions) are ignored; joints may
//! be listed in any order; mesh URIs (`package://`, relative, absolute) are kept as written.

use super::spec::*;
use super::ModelError;
use crate::spatial::{rpy_to_matrix, Inertia, Mat3, Se3, Vec3};
use std::collections::HashMap;

/// Parses URDF text read from `file` (used in messages).
pub fn parse(text: &str, file: &str) -> Result<ModelSpec, ModelError> {
    let lines = validate(text, file)?;
    let robot = urdf_rs::read_from_string(text)
        .map_err(|e| ModelError::new(file, None, "robot", format!("invalid URDF: {e}")))?;
    Ok(convert(robot, file, text, &lines))
}

/// Deepest element nesting accepted.
const MAX_DEPTH: usize = 32;

/// Nesting at which the lexical pre-scan gives up, before roxmltree (whose parser
/// recurses once per level: ~100 000 levels overflow the main thread's stack). Far above
/// [`MAX_DEPTH`], so well-formed files are judged by the exact check after parsing.
const PRESCAN_DEPTH: usize = 256;

/// Byte offset of the start tag that opens nesting level `PRESCAN_DEPTH + 1`, if any.
/// A lexical scan: comments, CDATA, processing instructions and `<!…>` declarations are
/// skipped, quoted attribute values may hold `>`. Malformed text is left to roxmltree.
fn too_deep(text: &str) -> Option<usize> {
    let b = text.as_bytes();
    let find = |from: usize, pat: &[u8]| -> usize {
        b[from.min(b.len())..]
            .windows(pat.len())
            .position(|w| w == pat)
            .map_or(b.len(), |p| from + p + pat.len())
    };
    let mut depth = 0usize;
    let mut i = 0;
    while let Some(p) = b[i..].iter().position(|&c| c == b'<') {
        let start = i + p;
        let rest = &b[start..];
        i = if rest.starts_with(b"<!--") {
            find(start + 4, b"-->")
        } else if rest.starts_with(b"<![CDATA[") {
            find(start + 9, b"]]>")
        } else if rest.starts_with(b"<?") {
            find(start + 2, b"?>")
        } else if rest.starts_with(b"<!") {
            // <!DOCTYPE …> with an optional [internal subset].
            let gt = find(start, b">");
            match b[start..gt].iter().position(|&c| c == b'[') {
                Some(_) => find(start, b"]").max(gt).min(b.len()),
                None => gt,
            }
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            find(start, b">")
        } else {
            let mut j = start + 1;
            let mut quote = None;
            while j < b.len() {
                match (quote, b[j]) {
                    (None, b'"' | b'\'') => quote = Some(b[j]),
                    (Some(q), c) if c == q => quote = None,
                    (None, b'>') => break,
                    _ => {}
                }
                j += 1;
            }
            if j < b.len() && b[j - 1] != b'/' {
                depth += 1;
                if depth > PRESCAN_DEPTH {
                    return Some(start);
                }
            }
            j + 1
        };
        if i >= b.len() {
            break;
        }
    }
    None
}

/// Source lines of links and joints by name, from the validation pass: one entry per
/// occurrence, in file order (so a duplicate is reported at its own line).
struct Lines {
    links: HashMap<String, Vec<usize>>,
    joints: HashMap<String, Vec<usize>>,
}

/// Byte offsets of line starts, so a node's line is a binary search (roxmltree's
/// `text_pos_at` scans from the start of the text: quadratic over a large file).
struct LineIndex(Vec<usize>);

impl LineIndex {
    fn new(text: &str) -> Self {
        let mut v = vec![0];
        v.extend(
            text.bytes()
                .enumerate()
                .filter(|&(_, b)| b == b'\n')
                .map(|(i, _)| i + 1),
        );
        Self(v)
    }

    fn line(&self, pos: usize) -> usize {
        self.0.partition_point(|&s| s <= pos)
    }
}

fn line_of(lx: &LineIndex, node: roxmltree::Node<'_, '_>) -> usize {
    lx.line(node.range().start)
}

/// Checks the elements armsim uses; returns where each link and joint is.
fn validate(text: &str, file: &str) -> Result<Lines, ModelError> {
    if let Some(pos) = too_deep(text) {
        return Err(ModelError::new(
            file,
            Some(LineIndex::new(text).line(pos)),
            "XML",
            format!("elements nested deeper than {MAX_DEPTH} levels"),
        ));
    }
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, opts)
        .map_err(|e| xml_error(text, file, e))?;
    // urdf-rs walks the document recursively: refuse absurd nesting (a URDF needs ~6).
    let lx = LineIndex::new(text);
    if let Some(deep) = doc
        .descendants()
        .find(|n| n.ancestors().nth(MAX_DEPTH).is_some())
    {
        return Err(ModelError::new(
            file,
            Some(line_of(&lx, deep)),
            "XML",
            format!("elements nested deeper than {MAX_DEPTH} levels"),
        ));
    }
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(ModelError::new(
            file,
            Some(line_of(&lx, root)),
            format!("<{}>", root.tag_name().name()),
            "the root element must be <robot>",
        ));
    }
    let mut lines = Lines {
        links: HashMap::new(),
        joints: HashMap::new(),
    };
    for node in root.children().filter(|n| n.is_element()) {
        let line = line_of(&lx, node);
        let tag = node.tag_name().name();
        if tag == "material" {
            let element = match node.attribute("name") {
                Some(name) => format!("material '{name}'"),
                None => "<material>".to_string(),
            };
            let ctx = Ctx {
                file,
                lx: &lx,
                element: &element,
            };
            validate_material(&ctx, node)?;
            continue;
        }
        if tag != "link" && tag != "joint" {
            continue;
        }
        let Some(name) = node.attribute("name") else {
            return Err(ModelError::new(
                file,
                Some(line),
                format!("<{tag}>"),
                "missing 'name' attribute",
            ));
        };
        let element = format!("{tag} '{name}'");
        let ctx = Ctx {
            file,
            lx: &lx,
            element: &element,
        };
        if tag == "link" {
            lines.links.entry(name.to_string()).or_default().push(line);
            validate_link(&ctx, node)?;
        } else {
            lines.joints.entry(name.to_string()).or_default().push(line);
            validate_joint(&ctx, node)?;
        }
    }
    Ok(lines)
}

struct Ctx<'a> {
    file: &'a str,
    lx: &'a LineIndex,
    element: &'a str,
}

impl Ctx<'_> {
    fn err(&self, node: roxmltree::Node<'_, '_>, msg: impl Into<String>) -> ModelError {
        ModelError::new(self.file, Some(line_of(self.lx, node)), self.element, msg)
    }

    /// Checks that attribute `attr` of `node`, if present, holds `n` finite numbers.
    fn numbers(
        &self,
        node: roxmltree::Node<'_, '_>,
        attr: &str,
        n: usize,
        required: bool,
    ) -> Result<(), ModelError> {
        let tag = node.tag_name().name();
        let Some(v) = node.attribute(attr) else {
            if required {
                return Err(self.err(node, format!("<{tag}>: missing '{attr}' attribute")));
            }
            return Ok(());
        };
        let parts: Vec<&str> = v.split_whitespace().collect();
        if parts.len() != n {
            return Err(self.err(
                node,
                format!(
                    "<{tag} {attr}=\"{v}\">: expected {n} number(s), found {}",
                    parts.len()
                ),
            ));
        }
        for p in parts {
            match p.parse::<f64>() {
                Ok(x) if x.is_finite() => {}
                Ok(_) => {
                    return Err(self.err(
                        node,
                        format!("<{tag} {attr}=\"{v}\">: non-finite number '{p}'"),
                    ))
                }
                Err(_) => {
                    return Err(self.err(
                        node,
                        format!("<{tag} {attr}=\"{v}\">: '{p}' is not a number"),
                    ))
                }
            }
        }
        Ok(())
    }

    fn origin(&self, parent: roxmltree::Node<'_, '_>) -> Result<(), ModelError> {
        for o in children(parent, "origin") {
            self.numbers(o, "xyz", 3, false)?;
            self.numbers(o, "rpy", 3, false)?;
        }
        Ok(())
    }
}

fn children<'a, 'i>(
    node: roxmltree::Node<'a, 'i>,
    tag: &'static str,
) -> impl Iterator<Item = roxmltree::Node<'a, 'i>> {
    node.children()
        .filter(move |n| n.is_element() && n.tag_name().name() == tag)
}

fn validate_link(ctx: &Ctx<'_>, node: roxmltree::Node<'_, '_>) -> Result<(), ModelError> {
    for inertial in children(node, "inertial") {
        ctx.origin(inertial)?;
        let mass: Vec<_> = children(inertial, "mass").collect();
        match mass.first() {
            None => return Err(ctx.err(inertial, "<inertial>: missing <mass>")),
            Some(&m) => ctx.numbers(m, "value", 1, true)?,
        }
        let inertia: Vec<_> = children(inertial, "inertia").collect();
        match inertia.first() {
            None => return Err(ctx.err(inertial, "<inertial>: missing <inertia>")),
            Some(&i) => {
                for a in ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"] {
                    ctx.numbers(i, a, 1, true)?;
                }
            }
        }
    }
    for tag in ["visual", "collision"] {
        for g in children(node, tag) {
            ctx.origin(g)?;
            if children(g, "geometry").next().is_none() {
                return Err(ctx.err(g, format!("<{tag}>: missing <geometry>")));
            }
            if tag == "visual" {
                for m in children(g, "material") {
                    validate_material(ctx, m)?;
                }
            }
            for geom in children(g, "geometry") {
                if geom.children().filter(|n| n.is_element()).count() != 1 {
                    return Err(ctx.err(
                        geom,
                        "<geometry>: expected exactly one shape (<box>, <cylinder>, <sphere>, <capsule> or <mesh>)",
                    ));
                }
                for shape in geom.children().filter(|n| n.is_element()) {
                    match shape.tag_name().name() {
                        "box" => ctx.numbers(shape, "size", 3, true)?,
                        "sphere" => ctx.numbers(shape, "radius", 1, true)?,
                        "cylinder" | "capsule" => {
                            ctx.numbers(shape, "radius", 1, true)?;
                            ctx.numbers(shape, "length", 1, true)?;
                        }
                        "mesh" => {
                            if shape.attribute("filename").is_none() {
                                return Err(ctx.err(shape, "<mesh>: missing 'filename' attribute"));
                            }
                            ctx.numbers(shape, "scale", 3, false)?;
                        }
                        other => return Err(ctx.err(shape, format!("unknown geometry <{other}>"))),
                    }
                }
            }
        }
    }
    Ok(())
}

/// A `<material>` (top level or in a `<visual>`): a name, and an optional
/// `<color rgba="r g b a">`.
fn validate_material(ctx: &Ctx<'_>, node: roxmltree::Node<'_, '_>) -> Result<(), ModelError> {
    if node.attribute("name").is_none() {
        return Err(ctx.err(node, "<material>: missing 'name' attribute"));
    }
    for c in children(node, "color") {
        ctx.numbers(c, "rgba", 4, true)?;
    }
    Ok(())
}

fn validate_joint(ctx: &Ctx<'_>, node: roxmltree::Node<'_, '_>) -> Result<(), ModelError> {
    let Some(jtype) = node.attribute("type") else {
        return Err(ctx.err(node, "missing 'type' attribute"));
    };
    match jtype {
        "revolute" | "continuous" | "prismatic" | "fixed" => {}
        "floating" | "planar" => {
            return Err(ctx.err(
                node,
                format!(
                    "joint type '{jtype}' is not supported yet (armsim models fixed-base mechanisms; floating and planar joints are refused)"
                ),
            ))
        }
        "spherical" => {
            return Err(ctx.err(node, "joint type 'spherical' is not supported"));
        }
        other => {
            return Err(ctx.err(
                node,
                format!(
                    "unknown joint type '{other}' (expected revolute, continuous, prismatic or fixed)"
                ),
            ))
        }
    }
    for tag in ["parent", "child"] {
        let n: Vec<_> = children(node, tag).collect();
        match n.first() {
            None => return Err(ctx.err(node, format!("missing <{tag}>"))),
            Some(e) if e.attribute("link").is_none() => {
                return Err(ctx.err(*e, format!("<{tag}>: missing 'link' attribute")))
            }
            _ => {}
        }
    }
    ctx.origin(node)?;
    for a in children(node, "axis") {
        ctx.numbers(a, "xyz", 3, true)?;
    }
    let limits: Vec<_> = children(node, "limit").collect();
    if (jtype == "revolute" || jtype == "prismatic") && limits.is_empty() {
        return Err(ctx.err(node, format!("a {jtype} joint needs a <limit>")));
    }
    for l in limits {
        for a in ["lower", "upper"] {
            ctx.numbers(l, a, 1, false)?;
        }
        // The URDF spec (and urdf-rs) require both whenever a <limit> is written.
        for a in ["effort", "velocity"] {
            ctx.numbers(l, a, 1, true)?;
            if let Some(v) = l.attribute(a).and_then(|v| v.trim().parse::<f64>().ok()) {
                if v < 0.0 {
                    return Err(ctx.err(l, format!("<limit {a}=\"{v}\">: must not be negative")));
                }
            }
        }
    }
    for m in children(node, "mimic") {
        if m.attribute("joint").is_none() {
            return Err(ctx.err(m, "<mimic>: missing 'joint' attribute"));
        }
        ctx.numbers(m, "multiplier", 1, false)?;
        ctx.numbers(m, "offset", 1, false)?;
    }
    for d in children(node, "dynamics") {
        ctx.numbers(d, "damping", 1, false)?;
        ctx.numbers(d, "friction", 1, false)?;
    }
    Ok(())
}

fn pose(p: &urdf_rs::Pose) -> Se3 {
    Se3::new(rpy_to_matrix(*p.rpy), Vec3::from(*p.xyz))
}

fn geometry(g: &urdf_rs::Geometry) -> Shape {
    match g {
        urdf_rs::Geometry::Box { size } => Shape::Box { size: **size },
        urdf_rs::Geometry::Cylinder { radius, length } => Shape::Cylinder {
            radius: *radius,
            length: *length,
        },
        urdf_rs::Geometry::Capsule { radius, length } => Shape::Capsule {
            radius: *radius,
            length: *length,
        },
        urdf_rs::Geometry::Sphere { radius } => Shape::Sphere { radius: *radius },
        urdf_rs::Geometry::Mesh { filename, scale } => Shape::Mesh {
            uri: filename.clone(),
            scale: scale.as_ref().map(|s| **s).unwrap_or([1.0; 3]),
        },
    }
}

fn convert(robot: urdf_rs::Robot, file: &str, text: &str, lines: &Lines) -> ModelSpec {
    let mut link_seen: HashMap<&str, usize> = HashMap::new();
    let mut joint_seen: HashMap<&str, usize> = HashMap::new();
    let materials: HashMap<&str, [f64; 4]> = robot
        .materials
        .iter()
        .filter_map(|m| m.color.as_ref().map(|c| (m.name.as_str(), *c.rgba)))
        .collect();
    let links = robot
        .links
        .iter()
        .map(|l| {
            let i = &l.inertial;
            let frame = pose(&i.origin);
            let t = &i.inertia;
            let tensor = Mat3::new(
                t.ixx, t.ixy, t.ixz, t.ixy, t.iyy, t.iyz, t.ixz, t.iyz, t.izz,
            );
            let inertial = Inertia::new(i.mass.value, Vec3::zeros(), tensor).transformed(&frame);
            LinkSpec {
                name: l.name.clone(),
                inertial,
                visuals: l
                    .visual
                    .iter()
                    .map(|v| Geometry {
                        origin: pose(&v.origin),
                        shape: geometry(&v.geometry),
                        rgba: v.material.as_ref().and_then(|m| {
                            m.color
                                .as_ref()
                                .map(|c| *c.rgba)
                                .or_else(|| materials.get(m.name.as_str()).copied())
                        }),
                    })
                    .collect(),
                collisions: l
                    .collision
                    .iter()
                    .map(|c| Geometry {
                        origin: pose(&c.origin),
                        shape: geometry(&c.geometry),
                        rgba: None,
                    })
                    .collect(),
                line: occurrence_line(&lines.links, &mut link_seen, &l.name),
            }
        })
        .collect();
    let joints = robot
        .joints
        .iter()
        .map(|j| {
            let jtype = match j.joint_type {
                urdf_rs::JointType::Revolute => JointType::Revolute,
                urdf_rs::JointType::Continuous => JointType::Continuous,
                urdf_rs::JointType::Prismatic => JointType::Prismatic,
                // Other types were refused by the validation pass.
                _ => JointType::Fixed,
            };
            let lim = &j.limit;
            let limits = match jtype {
                JointType::Fixed => Limits::unlimited(),
                JointType::Continuous => Limits {
                    lower: f64::NEG_INFINITY,
                    upper: f64::INFINITY,
                    velocity: positive_or_inf(lim.velocity),
                    effort: positive_or_inf(lim.effort),
                },
                _ => Limits {
                    lower: lim.lower,
                    upper: lim.upper,
                    velocity: positive_or_inf(lim.velocity),
                    effort: positive_or_inf(lim.effort),
                },
            };
            let mut js = JointSpec::new(&j.name, jtype, &j.parent.link, &j.child.link);
            js.origin = pose(&j.origin);
            js.axis = Vec3::from(*j.axis.xyz);
            js.limits = limits;
            js.mimic = j.mimic.as_ref().map(|m| MimicSpec {
                joint: m.joint.clone(),
                multiplier: m.multiplier.unwrap_or(1.0),
                offset: m.offset.unwrap_or(0.0),
            });
            if let Some(d) = &j.dynamics {
                js.damping = d.damping;
                js.friction = d.friction;
            }
            js.line = occurrence_line(&lines.joints, &mut joint_seen, &j.name);
            js
        })
        .collect();
    ModelSpec {
        name: robot.name,
        source: file.to_string(),
        root_offset: Se3::identity(),
        links,
        joints,
        urdf_text: Some(text.to_string()),
        gravity: None,
    }
}

/// The line of the next occurrence of `name` (links and joints come in file order).
fn occurrence_line<'n>(
    lines: &HashMap<String, Vec<usize>>,
    seen: &mut HashMap<&'n str, usize>,
    name: &'n str,
) -> Option<usize> {
    let k = seen.entry(name).or_insert(0);
    let line = lines
        .get(name)
        .and_then(|v| v.get(*k).or(v.last()))
        .copied();
    *k += 1;
    line
}

/// URDF writes 0 for "not given" on velocity/effort of continuous joints; treat 0 and
/// missing as unlimited only where the file cannot have meant a zero limit.
fn positive_or_inf(v: f64) -> f64 {
    if v > 0.0 {
        v
    } else {
        f64::INFINITY
    }
}

/// The located error of an XML syntax error in `text` read from `file`. Some errors carry no
/// position (roxmltree says 1:1): an early end of the file is at its last line; the others
/// have no line.
pub(crate) fn xml_error(text: &str, file: &str, e: roxmltree::Error) -> ModelError {
    use roxmltree::Error as E;
    let line = match e {
        E::UnexpectedEndOfStream | E::UnclosedRootNode => Some(text.lines().count().max(1)),
        E::NoRootNode
        | E::DtdDetected
        | E::NodesLimitReached
        | E::AttributesLimitReached
        | E::NamespacesLimitReached => None,
        _ => Some(e.pos().row as usize),
    };
    ModelError::new(file, line, "XML", e.to_string())
}
