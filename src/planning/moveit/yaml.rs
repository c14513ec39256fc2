//! Span-aware access to one YAML document (saphyr's `MarkedYaml`): typed getters whose
//! errors name the file, the line of the offending node, the element path and what was
//! expected instead.

use crate::planning::plan_error::PlanningInputError;
use saphyr::{LoadableYamlNode, MarkedYaml, Scalar, YamlData};
use saphyr_parser::{Event, Parser};

/// A YAML node with its source position.
pub(crate) type Node = MarkedYaml<'static>;

/// Deepest nesting of lists and mappings accepted: dropping the tree recurses per level,
/// and MoveIt messages need fewer than 10.
const MAX_DEPTH: usize = 128;

/// The file a document came from and how many lines it has (a parse error at the very end
/// can point one line past it).
pub(crate) struct Doc<'f> {
    pub file: &'f str,
    nlines: usize,
}

impl<'f> Doc<'f> {
    /// Parses `text` (one YAML document whose root is a mapping).
    pub fn parse(text: &str, file: &'f str) -> Result<(Self, Node), PlanningInputError> {
        let doc = Doc {
            file,
            nlines: text.lines().count().max(1),
        };
        if text.trim().is_empty() {
            return Err(doc.err_at(None, "YAML", "the file is empty"));
        }
        if let Some((line, msg)) = precheck(text) {
            return Err(doc.err_at(Some(line), "YAML", msg));
        }
        let mut docs = MarkedYaml::<'static>::load_from_str(text)
            .map_err(|e| doc.err_at(Some(e.marker().line()), "YAML", e.info().to_string()))?;
        if docs.len() > 1 {
            return Err(doc.err(&docs[1], "YAML", "more than one YAML document ('---')"));
        }
        let Some(root) = docs.pop() else {
            return Err(doc.err_at(None, "YAML", "the file holds no YAML document"));
        };
        if !matches!(root.data, YamlData::Mapping(_)) {
            return Err(doc.err(
                &root,
                "YAML",
                format!("the document must be a mapping, found {}", kind(&root)),
            ));
        }
        Ok((doc, root))
    }

    /// An error at a known line (clamped to the file).
    pub fn err_at(
        &self,
        line: Option<usize>,
        element: impl Into<String>,
        msg: impl Into<String>,
    ) -> PlanningInputError {
        let line = line.map(|l| l.clamp(1, self.nlines));
        PlanningInputError::new(self.file, line, element, msg)
    }

    /// An error at `node`'s line.
    pub fn err(
        &self,
        node: &Node,
        element: impl Into<String>,
        msg: impl Into<String>,
    ) -> PlanningInputError {
        self.err_at(Some(node.span.start.line()), element, msg)
    }

    /// Value of `key` in mapping `node`, if present and not null.
    pub fn get<'n>(&self, node: &'n Node, key: &str) -> Option<&'n Node> {
        node.data
            .as_mapping_get(key)
            .filter(|v| !matches!(v.data, YamlData::Value(Scalar::Null)))
    }

    /// Value of `key` in mapping `node` (whose path is `element`), which must be there.
    pub fn req<'n>(
        &self,
        node: &'n Node,
        element: &str,
        key: &str,
    ) -> Result<&'n Node, PlanningInputError> {
        self.get(node, key)
            .ok_or_else(|| self.err(node, element, format!("missing key '{key}'")))
    }

    /// `node` as a mapping.
    pub fn map<'n>(&self, node: &'n Node, element: &str) -> Result<&'n Node, PlanningInputError> {
        match node.data {
            YamlData::Mapping(_) => Ok(node),
            _ => Err(self.expected(node, element, "a mapping")),
        }
    }

    /// `node` as a list.
    pub fn seq<'n>(&self, node: &'n Node, element: &str) -> Result<&'n [Node], PlanningInputError> {
        match &node.data {
            YamlData::Sequence(s) => Ok(s),
            _ => Err(self.expected(node, element, "a list")),
        }
    }

    /// Optional list under `key` (absent or null: empty).
    pub fn opt_seq<'n>(
        &self,
        node: &'n Node,
        element: &str,
        key: &str,
    ) -> Result<&'n [Node], PlanningInputError> {
        match self.get(node, key) {
            None => Ok(&[]),
            Some(v) => self.seq(v, &format!("{element}.{key}")),
        }
    }

    /// `node` as a finite number (integer or float).
    pub fn num(&self, node: &Node, element: &str) -> Result<f64, PlanningInputError> {
        let x = match node.data {
            YamlData::Value(Scalar::Integer(i)) => i as f64,
            YamlData::Value(Scalar::FloatingPoint(f)) => f.into_inner(),
            _ => return Err(self.expected(node, element, "a number")),
        };
        if !x.is_finite() {
            return Err(self.err(node, element, format!("non-finite number {x}")));
        }
        Ok(x)
    }

    /// `node` as a string (a plain scalar that reads as a number or a boolean is not one).
    pub fn str<'n>(&self, node: &'n Node, element: &str) -> Result<&'n str, PlanningInputError> {
        match &node.data {
            YamlData::Value(Scalar::String(s)) => Ok(s),
            _ => Err(self.expected(node, element, "a string")),
        }
    }

    /// `node` as exactly `N` numbers.
    pub fn nums<const N: usize>(
        &self,
        node: &Node,
        element: &str,
    ) -> Result<[f64; N], PlanningInputError> {
        let s = self.seq(node, element)?;
        if s.len() != N {
            return Err(self.err(
                node,
                element,
                format!("expected {N} numbers, found {}", s.len()),
            ));
        }
        let mut out = [0.0; N];
        for (i, v) in s.iter().enumerate() {
            out[i] = self.num(v, &format!("{element}[{i}]"))?;
        }
        Ok(out)
    }

    fn expected(&self, node: &Node, element: &str, what: &str) -> PlanningInputError {
        self.err(
            node,
            element,
            format!("expected {what}, found {}", kind(node)),
        )
    }
}

/// What a node is, for messages.
pub(crate) fn kind(node: &Node) -> String {
    match &node.data {
        YamlData::Mapping(_) => "a mapping".into(),
        YamlData::Sequence(_) => "a list".into(),
        YamlData::Value(Scalar::Null) => "nothing (null)".into(),
        YamlData::Value(Scalar::Boolean(b)) => format!("the boolean {b}"),
        YamlData::Value(Scalar::Integer(i)) => format!("the number {i}"),
        YamlData::Value(Scalar::FloatingPoint(f)) => format!("the number {f}"),
        YamlData::Value(Scalar::String(s)) => format!("the string '{s}'"),
        YamlData::Tagged(t, _) => format!("a node tagged '{t}'"),
        YamlData::Alias(_) => "an alias".into(),
        YamlData::Representation(s, ..) => format!("'{s}'"),
        YamlData::BadValue => "an invalid value".into(),
    }
}

/// A pass over the parser's events before building the tree: the line and the problem of
/// the first collection nested deeper than [`MAX_DEPTH`], of the first alias (`*name`: the
/// loader copies the anchored tree at each alias, so a few lines of nested aliases would
/// fill the memory; MoveIt messages never use them), or of the first syntax error.
fn precheck(text: &str) -> Option<(usize, String)> {
    let mut depth = 0usize;
    for ev in Parser::new_from_str(text) {
        let (ev, span) = match ev {
            Ok(e) => e,
            Err(e) => return Some((e.marker().line(), e.info().to_string())),
        };
        match ev {
            Event::SequenceStart(..) | Event::MappingStart(..) => {
                depth += 1;
                if depth > MAX_DEPTH {
                    let msg = format!("lists or mappings nested deeper than {MAX_DEPTH} levels");
                    return Some((span.start.line(), msg));
                }
            }
            Event::SequenceEnd | Event::MappingEnd => depth = depth.saturating_sub(1),
            Event::Alias(_) => {
                let msg = "YAML aliases ('*name') are not supported".to_string();
                return Some((span.start.line(), msg));
            }
            Event::StreamEnd => break,
            _ => {}
        }
    }
    None
}
