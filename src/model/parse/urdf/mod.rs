//! URDF → [`ModelSpec`]: reads the XML with `roxmltree` and follows urdfdom (the parser
//! behind ROS and Pinocchio) in what it accepts, so that every file the ecosystem loads,
//! armsim loads.
//!
//! - What carries meaning is loaded; what is odd or ignored gives a warning naming the
//!   file, the line, the element and the problem (see docs/urdf.md for each case):
//!   geometry without a shape or of an unknown type, a mesh `scale` of the wrong count, a
//!   repeated child tag (the first is used, as urdfdom does), an XML declaration not at the
//!   start, undeclared namespace prefixes, a malformed `<inertial>` or `<material>`.
//! - What makes the computation meaningless is an error with the same location: unknown
//!   joint types, missing names, malformed joint origins, axes and limits, non-finite
//!   numbers.
//! - Unknown tags (`<transmission>`, `<gazebo>`, vendor extensions) are ignored anywhere;
//!   joints may be listed in any order; mesh URIs are kept as written.
//!
//! Links, materials and geometry are read in [`links`], joints in [`joints`] (where
//! floating and planar joints become chains of one-axis joints); [`interop`] takes and gives
//! `urdf_rs::Robot`s through the same rules.

mod interop;
mod joints;
mod links;
use crate::core::spatial::{rpy_to_matrix, Se3, Vec3};
use crate::core::xml_guard::LineIndex;
use crate::model::spec::*;
use crate::model::{ModelError, ModelWarning};

type Node<'a, 'i> = roxmltree::Node<'a, 'i>;

/// Parses URDF text read from `file` (used in messages). Warnings travel in
/// [`ModelSpec::warnings`].
pub fn parse(text: &str, file: &str) -> Result<ModelSpec, ModelError> {
    let lx = LineIndex::new(text);
    if let Some(pos) = too_deep(text) {
        return Err(ModelError::new(
            file,
            Some(lx.line(pos)),
            "XML",
            format!("elements nested deeper than {MAX_DEPTH} levels"),
        ));
    }
    let mut rd = Reader {
        file,
        lx,
        ns: None,
        warnings: Vec::new(),
    };
    let prepared = rd.without_late_declarations(text);
    let first = roxmltree::Document::parse_with_options(&prepared, parsing_options());
    let declared;
    let doc = match first {
        Err(roxmltree::Error::UnknownNamespace(..)) => {
            declared = rd.declare_prefixes(prepared.clone());
            // The declarations keep the lines but move the bytes.
            rd.lx = LineIndex::new(&declared);
            roxmltree::Document::parse_with_options(&declared, parsing_options())
                .map_err(|e| xml_error(&declared, file, e))?
        }
        other => other.map_err(|e| xml_error(&prepared, file, e))?,
    };
    // Later passes walk the tree recursively: refuse absurd nesting (a URDF needs ~6).
    if let Some(deep) = doc
        .descendants()
        .find(|n| n.ancestors().nth(MAX_DEPTH).is_some())
    {
        return Err(rd.err(
            deep,
            "XML",
            format!("elements nested deeper than {MAX_DEPTH} levels"),
        ));
    }
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(rd.err(
            root,
            &format!("<{}>", root.tag_name().name()),
            "the root element must be <robot>",
        ));
    }
    read_robot(&mut rd, root, text)
}

/// The `<robot>` element: materials first (links may use them before they are defined),
/// then links and joints in file order.
fn read_robot(
    rd: &mut Reader<'_>,
    root: Node<'_, '_>,
    text: &str,
) -> Result<ModelSpec, ModelError> {
    let name = match root.attribute("name") {
        Some(n) => n.to_string(),
        None => {
            let stem = std::path::Path::new(rd.file)
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("robot")
                .to_string();
            rd.warn(
                root,
                "<robot>",
                format!("missing 'name' attribute: named '{stem}' after the file"),
            );
            stem
        }
    };
    let mut materials = links::Materials::default();
    rd.ns = root.tag_name().namespace().map(str::to_string);
    let material_nodes: Vec<_> = root.children().filter(|&n| rd.is(n, "material")).collect();
    for node in material_nodes {
        links::read_top_material(rd, node, &mut materials);
    }
    let mut spec_links = Vec::new();
    let mut spec_joints = Vec::new();
    let elements: Vec<_> = root
        .children()
        .filter(|&n| rd.is(n, "link") || rd.is(n, "joint"))
        .collect();
    for node in elements {
        match node.tag_name().name() {
            "link" => {
                if let Some(l) = links::read_link(rd, node, &mut materials)? {
                    spec_links.push(l);
                }
            }
            "joint" => {
                let (js, extra) = joints::read_joint(rd, node)?;
                spec_joints.extend(js);
                spec_links.extend(extra);
            }
            _ => {}
        }
    }
    Ok(ModelSpec {
        name,
        source: rd.file.to_string(),
        root_offset: Se3::identity(),
        links: spec_links,
        joints: spec_joints,
        urdf_text: Some(text.to_string()),
        gravity: None,
        warnings: std::mem::take(&mut rd.warnings),
    })
}

fn parsing_options() -> roxmltree::ParsingOptions {
    roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    }
}

/// Deepest element nesting accepted.
const MAX_DEPTH: usize = 32;

/// Nesting at which the lexical pre-scan gives up, before roxmltree (whose parser
/// recurses once per level: ~100 000 levels overflow the main thread's stack). Far above
/// [`MAX_DEPTH`], so well-formed files are judged by the exact check after parsing.
const PRESCAN_DEPTH: usize = 256;

/// Byte offset of the start tag that opens nesting level `PRESCAN_DEPTH + 1`, if any.
fn too_deep(text: &str) -> Option<usize> {
    crate::core::xml_guard::too_deep(text, PRESCAN_DEPTH)
}

/// A number-reading or element problem, with the line of the node it is about.
struct Bad {
    line: usize,
    msg: String,
}

/// The reading context: file, line index and the warnings so far.
struct Reader<'f> {
    file: &'f str,
    lx: LineIndex,
    /// The namespace of `<robot>` (usually none): elements in another one (`xacro:`,
    /// vendor prefixes) are extensions, as they are to urdfdom.
    ns: Option<String>,
    warnings: Vec<ModelWarning>,
}

impl Reader<'_> {
    /// Whether `node` is the URDF element `<tag>`.
    fn is(&self, node: Node<'_, '_>, tag: &str) -> bool {
        node.is_element()
            && node.tag_name().name() == tag
            && node.tag_name().namespace() == self.ns.as_deref()
    }

    fn line(&self, node: Node<'_, '_>) -> usize {
        self.lx.line(node.range().start)
    }

    fn bad(&self, node: Node<'_, '_>, msg: impl Into<String>) -> Bad {
        Bad {
            line: self.line(node),
            msg: msg.into(),
        }
    }

    fn err(&self, node: Node<'_, '_>, element: &str, msg: impl Into<String>) -> ModelError {
        ModelError::new(self.file, Some(self.line(node)), element, msg)
    }

    /// The error of `bad` in `element`.
    fn fail(&self, bad: Bad, element: &str) -> ModelError {
        ModelError::new(self.file, Some(bad.line), element, bad.msg)
    }

    fn warn(&mut self, node: Node<'_, '_>, element: &str, msg: impl Into<String>) {
        let w = self.err(node, element, msg);
        self.warnings.push(w);
    }

    /// Warns about `bad` in `element`, saying what was done about it.
    fn warn_bad(&mut self, bad: Bad, element: &str, consequence: &str) {
        let w = ModelError::new(
            self.file,
            Some(bad.line),
            element,
            format!("{}: {consequence}", bad.msg),
        );
        self.warnings.push(w);
    }

    /// The first `<tag>` child of `node`; further ones are ignored with a warning (urdfdom
    /// reads the first).
    fn first<'a, 'i>(
        &mut self,
        node: Node<'a, 'i>,
        tag: &str,
        element: &str,
    ) -> Option<Node<'a, 'i>> {
        let mut all = node.children().filter(|&n| self.is(n, tag));
        let first = all.next()?;
        if let Some(second) = all.next() {
            let line = self.line(first);
            self.warn(
                second,
                element,
                format!("<{tag}> given more than once: the first (line {line}) is used, the others are ignored"),
            );
        }
        Some(first)
    }

    /// Attribute `attr` of `node` as `n` finite numbers, if present.
    fn numbers(&self, node: Node<'_, '_>, attr: &str, n: usize) -> Result<Option<Vec<f64>>, Bad> {
        let tag = node.tag_name().name();
        let Some(v) = node.attribute(attr) else {
            return Ok(None);
        };
        let parts: Vec<&str> = v.split_whitespace().collect();
        if parts.len() != n {
            return Err(self.bad(
                node,
                format!(
                    "<{tag} {attr}=\"{v}\">: expected {n} number(s), found {}",
                    parts.len()
                ),
            ));
        }
        parts
            .iter()
            .map(|p| match p.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                Ok(_) => Err(self.bad(
                    node,
                    format!("<{tag} {attr}=\"{v}\">: non-finite number '{p}'"),
                )),
                Err(_) => Err(self.bad(
                    node,
                    format!("<{tag} {attr}=\"{v}\">: '{p}' is not a number"),
                )),
            })
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    }

    /// Attribute `attr` as `n` numbers; missing is an error.
    fn required(&self, node: Node<'_, '_>, attr: &str, n: usize) -> Result<Vec<f64>, Bad> {
        self.numbers(node, attr, n)?.ok_or_else(|| {
            self.bad(
                node,
                format!("<{}>: missing '{attr}' attribute", node.tag_name().name()),
            )
        })
    }

    fn scalar(&self, node: Node<'_, '_>, attr: &str) -> Result<Option<f64>, Bad> {
        Ok(self.numbers(node, attr, 1)?.map(|v| v[0]))
    }

    fn vec3(&self, node: Node<'_, '_>, attr: &str) -> Result<Option<Vec3>, Bad> {
        Ok(self
            .numbers(node, attr, 3)?
            .map(|v| Vec3::new(v[0], v[1], v[2])))
    }

    /// The pose of the first `<origin>` of `parent` (identity without one).
    fn origin(&mut self, parent: Node<'_, '_>, element: &str) -> Result<Se3, Bad> {
        let Some(o) = self.first(parent, "origin", element) else {
            return Ok(Se3::identity());
        };
        let xyz = self.vec3(o, "xyz")?.unwrap_or_else(Vec3::zeros);
        let rpy = self.vec3(o, "rpy")?.unwrap_or_else(Vec3::zeros);
        Ok(Se3::new(rpy_to_matrix([rpy.x, rpy.y, rpy.z]), xyz))
    }

    /// `text` with every XML declaration after the first byte blanked out (urdfdom's
    /// tinyxml2 accepts them after white space; XML only at the start), with a warning
    /// each. Byte offsets and lines are kept.
    fn without_late_declarations(&mut self, text: &str) -> String {
        let start = if text.starts_with('\u{feff}') { 3 } else { 0 };
        let mut out = text.as_bytes().to_vec();
        let mut done = 0;
        for (at, _) in text.match_indices("<?xml") {
            let after = text.as_bytes().get(at + 5).copied().unwrap_or(b'?');
            if at == start || at < done || !(after.is_ascii_whitespace() || after == b'?') {
                continue;
            }
            let end = text[at..].find("?>").map_or(text.len(), |e| at + e + 2);
            done = end;
            for b in &mut out[at..end] {
                if *b != b'\n' {
                    *b = b' ';
                }
            }
            let line = self.lx.line(at);
            self.warnings.push(ModelError::new(
                self.file,
                Some(line),
                "XML",
                "XML declaration <?xml …?> not at the start of the file: ignored",
            ));
        }
        // Whole characters were blanked (the range starts and ends at ASCII bytes).
        String::from_utf8(out).unwrap_or_else(|_| text.to_string())
    }

    /// Declares namespace prefixes used without a declaration (`xacro:` left in generated
    /// files; urdfdom ignores namespaces) on the root element, with a warning each.
    fn declare_prefixes(&mut self, mut text: String) -> String {
        for _ in 0..16 {
            let (prefix, pos) =
                match roxmltree::Document::parse_with_options(&text, parsing_options()) {
                    Err(roxmltree::Error::UnknownNamespace(p, pos)) => (p, pos),
                    _ => break,
                };
            let Some(at) = root_name_end(&text) else {
                break;
            };
            text.insert_str(
                at,
                &format!(" xmlns:{prefix}=\"urn:armsim:undeclared:{prefix}\""),
            );
            self.warnings.push(ModelError::new(
                self.file,
                Some(pos.row as usize),
                "XML",
                format!("namespace prefix '{prefix}' is not declared: its elements are ignored (as extensions)"),
            ));
        }
        text
    }
}

/// Byte offset just after the root element's name (`<robot|`), skipping comments,
/// declarations and processing instructions.
fn root_name_end(text: &str) -> Option<usize> {
    let b = text.as_bytes();
    let mut i = 0;
    while let Some(p) = text[i..].find('<') {
        let at = i + p;
        let rest = &text[at..];
        if rest.starts_with("<!--") {
            i = at + rest.find("-->")? + 3;
        } else if rest.starts_with("<?") {
            i = at + rest.find("?>")? + 2;
        } else if rest.starts_with("<!") {
            i = at + rest.find('>')? + 1;
        } else {
            let mut j = at + 1;
            while j < b.len() && !b[j].is_ascii_whitespace() && b[j] != b'>' && b[j] != b'/' {
                j += 1;
            }
            return Some(j);
        }
    }
    None
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
