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
mod urdf_reader;
use crate::core::spatial::Se3;
use crate::core::xml_guard::LineIndex;
use crate::model::model_error::ModelError;
use crate::model::spec::*;
use urdf_reader::{parsing_options, Node, Reader};

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
