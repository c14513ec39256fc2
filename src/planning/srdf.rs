//! MoveIt SRDF: the link pairs whose collisions are never checked
//! (`<disable_collisions link1= link2= reason=>`), and the planning groups (`<group>` with
//! its chains, joints, links and subgroups).
//!
//! As MoveIt's srdfdom does, a pair naming a link the model does not have is skipped with
//! a warning (naming the file, the line and the element). `<enable_collisions>` removes a
//! pair again; `<disable_default_collisions>` is ignored with a warning (every pair is then
//! checked, which is conservative). Other elements (group states, end effectors, virtual
//! and passive joints) are not read. A malformed element (a pair or a group without its
//! attributes) is an error.
//!
//! Limits (refused with the file, the line and the limit): elements nested deeper than
//! [`MAX_DEPTH`] levels, and more than [`MAX_PAIRS`] `<disable_collisions>` plus
//! `<enable_collisions>` elements. Filtering the pairs is linear (hash sets).
//!
//! ```
//! use armsim::planning::srdf::parse_srdf;
//! let srdf = parse_srdf(
//!     r#"<robot name="r"><disable_collisions link1="a" link2="b" reason="Adjacent"/></robot>"#,
//!     "r.srdf",
//! )
//! .unwrap();
//! assert_eq!((srdf.disabled[0].link1.as_str(), srdf.disabled[0].link2.as_str()), ("a", "b"));
//! ```

use crate::model::Model;
use crate::planning::plan_error::{PlanningInputError, PlanningInputWarning};
use std::collections::HashSet;
use std::path::Path;

/// Deepest element nesting accepted (an SRDF needs 3).
pub const MAX_DEPTH: usize = 32;

/// Most `<disable_collisions>` plus `<enable_collisions>` elements accepted: every pair
/// of a 1 400-link model.
pub const MAX_PAIRS: usize = 1_000_000;

/// Two link names.
pub type NamePair = (String, String);

/// A `<disable_collisions>` or `<enable_collisions>` pair.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LinkPair {
    /// First link.
    pub link1: String,
    /// Second link.
    pub link2: String,
    /// `reason` (Adjacent, Never, Default, …), if given.
    pub reason: Option<String>,
    /// 1-based source line.
    pub line: usize,
}

/// A `<group>`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SrdfGroup {
    /// SrdfGroup name.
    pub name: String,
    /// `<chain base_link tip_link>` entries.
    pub chains: Vec<(String, String)>,
    /// `<joint name>` entries.
    pub joints: Vec<String>,
    /// `<link name>` entries.
    pub links: Vec<String>,
    /// `<group name>` entries (subgroups).
    pub subgroups: Vec<String>,
    /// 1-based source line.
    pub line: usize,
}

/// What armsim reads of an SRDF.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Srdf {
    /// The file it came from (for messages).
    pub file: String,
    /// `<robot name>`.
    pub robot: String,
    /// `<disable_collisions>` pairs, in file order.
    pub disabled: Vec<LinkPair>,
    /// `<enable_collisions>` pairs, in file order.
    pub enabled: Vec<LinkPair>,
    /// Lines of `<disable_default_collisions>` elements (not applied).
    pub disable_default_lines: Vec<usize>,
    /// Planning groups, in file order.
    pub groups: Vec<SrdfGroup>,
}

/// Reads an SRDF file.
pub fn load_srdf(path: impl AsRef<Path>) -> Result<Srdf, PlanningInputError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let text = crate::core::files::read_input_string(path)
        .map_err(|e| PlanningInputError::new(&file, None, "file", format!("cannot read: {e}")))?;
    parse_srdf(&text, &file)
}

/// Reads an SRDF file and returns its disabled pairs whose links `model` has (see
/// [`Srdf::disabled_pairs`]), with the warnings.
pub fn load_disabled_pairs(
    path: impl AsRef<Path>,
    model: &Model,
) -> Result<(Vec<NamePair>, Vec<PlanningInputWarning>), PlanningInputError> {
    Ok(load_srdf(path)?.disabled_pairs(model))
}

impl Srdf {
    /// The `<disable_collisions>` pairs minus the `<enable_collisions>` ones (either order),
    /// keeping only pairs whose two links `model` has; a warning for each pair dropped for
    /// an unknown link and for each `<disable_default_collisions>`.
    pub fn disabled_pairs(&self, model: &Model) -> (Vec<NamePair>, Vec<PlanningInputWarning>) {
        let mut warnings = Vec::new();
        for &line in &self.disable_default_lines {
            warnings.push(PlanningInputError::new(
                &self.file,
                Some(line),
                "<disable_default_collisions>",
                "not supported: ignored (the link's pairs stay checked)",
            ));
        }
        // Unordered pairs: (smaller, larger) name.
        fn key(p: &LinkPair) -> (&str, &str) {
            let (a, b) = (p.link1.as_str(), p.link2.as_str());
            if a <= b {
                (a, b)
            } else {
                (b, a)
            }
        }
        let enabled: HashSet<(&str, &str)> = self.enabled.iter().map(key).collect();
        let mut pairs = Vec::with_capacity(self.disabled.len());
        for p in &self.disabled {
            let unknown: Vec<&str> = [&p.link1, &p.link2]
                .into_iter()
                .filter(|l| model.link_id(l).is_none())
                .map(String::as_str)
                .collect();
            if !unknown.is_empty() {
                warnings.push(PlanningInputError::new(
                    &self.file,
                    Some(p.line),
                    format!(
                        "<disable_collisions link1=\"{}\" link2=\"{}\">",
                        p.link1, p.link2
                    ),
                    format!(
                        "link '{}' is not in model '{}': pair ignored",
                        unknown.join("', '"),
                        model.name
                    ),
                ));
                continue;
            }
            if enabled.contains(&key(p)) {
                continue;
            }
            pairs.push((p.link1.clone(), p.link2.clone()));
        }
        (pairs, warnings)
    }
}

/// Parses SRDF text read from `file` (used in messages).
pub fn parse_srdf(text: &str, file: &str) -> Result<Srdf, PlanningInputError> {
    let lx = crate::core::xml_guard::LineIndex::new(text);
    if let Some(pos) = crate::core::xml_guard::too_deep(text, MAX_DEPTH) {
        return Err(PlanningInputError::new(
            file,
            Some(lx.line(pos)),
            "XML",
            format!("elements nested deeper than {MAX_DEPTH} levels"),
        ));
    }
    let doc = roxmltree::Document::parse(text)
        .map_err(|e| crate::model::parse::urdf::xml_error(text, file, e))?;
    let line = |n: roxmltree::Node<'_, '_>| lx.line(n.range().start);
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(PlanningInputError::new(
            file,
            Some(line(root)),
            format!("<{}>", root.tag_name().name()),
            "the root element must be <robot>",
        ));
    }
    let attr = |n: roxmltree::Node<'_, '_>, a: &str| -> Result<String, PlanningInputError> {
        match n.attribute(a) {
            Some(v) if !v.is_empty() => Ok(v.to_string()),
            found => Err(PlanningInputError::new(
                file,
                Some(line(n)),
                format!("<{}>", n.tag_name().name()),
                format!(
                    "{} '{a}' attribute",
                    if found.is_some() { "empty" } else { "missing" }
                ),
            )),
        }
    };
    let mut srdf = Srdf {
        file: file.to_string(),
        robot: root.attribute("name").unwrap_or_default().to_string(),
        disabled: Vec::new(),
        enabled: Vec::new(),
        disable_default_lines: Vec::new(),
        groups: Vec::new(),
    };
    for n in root.children().filter(|n| n.is_element()) {
        match n.tag_name().name() {
            tag @ ("disable_collisions" | "enable_collisions") => {
                let pair = LinkPair {
                    link1: attr(n, "link1")?,
                    link2: attr(n, "link2")?,
                    reason: n.attribute("reason").map(str::to_string),
                    line: line(n),
                };
                if srdf.disabled.len() + srdf.enabled.len() >= MAX_PAIRS {
                    return Err(PlanningInputError::new(
                        file,
                        Some(pair.line),
                        format!("<{tag}>"),
                        format!(
                            "more than {MAX_PAIRS} <disable_collisions> and <enable_collisions> \
                             elements: refused (the limit of this reader)"
                        ),
                    ));
                }
                if tag == "disable_collisions" {
                    srdf.disabled.push(pair);
                } else {
                    srdf.enabled.push(pair);
                }
            }
            "disable_default_collisions" => srdf.disable_default_lines.push(line(n)),
            "group" => {
                let mut g = SrdfGroup {
                    name: attr(n, "name")?,
                    line: line(n),
                    ..SrdfGroup::default()
                };
                for c in n.children().filter(|c| c.is_element()) {
                    match c.tag_name().name() {
                        "chain" => g.chains.push((attr(c, "base_link")?, attr(c, "tip_link")?)),
                        "joint" => g.joints.push(attr(c, "name")?),
                        "link" => g.links.push(attr(c, "name")?),
                        "group" => g.subgroups.push(attr(c, "name")?),
                        _ => {}
                    }
                }
                srdf.groups.push(g);
            }
            _ => {}
        }
    }
    Ok(srdf)
}
