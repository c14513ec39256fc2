//! The URDF reading context shared by the readers of the robot, links and joints: the
//! [`Reader`] (file, line index, namespace, warnings so far) with its located errors and
//! warnings, number and origin readers, and the repairs made before parsing (late XML
//! declarations blanked, undeclared namespace prefixes declared); [`Bad`] carries a
//! problem with its line until the element is known.

use crate::core::spatial::{rpy_to_matrix, Se3, Vec3};
use crate::core::xml_guard::LineIndex;
use crate::model::model_error::{ModelError, ModelWarning};

/// A node of the parsed URDF.
pub(super) type Node<'a, 'i> = roxmltree::Node<'a, 'i>;

/// The options every parse of a URDF uses (a DTD is allowed).
pub(super) fn parsing_options() -> roxmltree::ParsingOptions {
    roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    }
}

/// A number-reading or element problem, with the line of the node it is about.
pub(super) struct Bad {
    pub(super) line: usize,
    pub(super) msg: String,
}

/// The reading context: file, line index and the warnings so far.
pub(super) struct Reader<'f> {
    pub(super) file: &'f str,
    pub(super) lx: LineIndex,
    /// The namespace of `<robot>` (usually none): elements in another one (`xacro:`,
    /// vendor prefixes) are extensions, as they are to urdfdom.
    pub(super) ns: Option<String>,
    pub(super) warnings: Vec<ModelWarning>,
}

impl Reader<'_> {
    /// Whether `node` is the URDF element `<tag>`.
    pub(super) fn is(&self, node: Node<'_, '_>, tag: &str) -> bool {
        node.is_element()
            && node.tag_name().name() == tag
            && node.tag_name().namespace() == self.ns.as_deref()
    }

    pub(super) fn line(&self, node: Node<'_, '_>) -> usize {
        self.lx.line(node.range().start)
    }

    pub(super) fn bad(&self, node: Node<'_, '_>, msg: impl Into<String>) -> Bad {
        Bad {
            line: self.line(node),
            msg: msg.into(),
        }
    }

    pub(super) fn err(
        &self,
        node: Node<'_, '_>,
        element: &str,
        msg: impl Into<String>,
    ) -> ModelError {
        ModelError::new(self.file, Some(self.line(node)), element, msg)
    }

    /// The error of `bad` in `element`.
    pub(super) fn fail(&self, bad: Bad, element: &str) -> ModelError {
        ModelError::new(self.file, Some(bad.line), element, bad.msg)
    }

    pub(super) fn warn(&mut self, node: Node<'_, '_>, element: &str, msg: impl Into<String>) {
        let w = self.err(node, element, msg);
        self.warnings.push(w);
    }

    /// Warns about `bad` in `element`, saying what was done about it.
    pub(super) fn warn_bad(&mut self, bad: Bad, element: &str, consequence: &str) {
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
    pub(super) fn first<'a, 'i>(
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
    pub(super) fn numbers(
        &self,
        node: Node<'_, '_>,
        attr: &str,
        n: usize,
    ) -> Result<Option<Vec<f64>>, Bad> {
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
    pub(super) fn required(
        &self,
        node: Node<'_, '_>,
        attr: &str,
        n: usize,
    ) -> Result<Vec<f64>, Bad> {
        self.numbers(node, attr, n)?.ok_or_else(|| {
            self.bad(
                node,
                format!("<{}>: missing '{attr}' attribute", node.tag_name().name()),
            )
        })
    }

    pub(super) fn scalar(&self, node: Node<'_, '_>, attr: &str) -> Result<Option<f64>, Bad> {
        Ok(self.numbers(node, attr, 1)?.map(|v| v[0]))
    }

    pub(super) fn vec3(&self, node: Node<'_, '_>, attr: &str) -> Result<Option<Vec3>, Bad> {
        Ok(self
            .numbers(node, attr, 3)?
            .map(|v| Vec3::new(v[0], v[1], v[2])))
    }

    /// The pose of the first `<origin>` of `parent` (identity without one).
    pub(super) fn origin(&mut self, parent: Node<'_, '_>, element: &str) -> Result<Se3, Bad> {
        let Some(o) = self.first(parent, "origin", element) else {
            return Ok(Se3::identity());
        };
        let xyz = self.vec3(o, "xyz")?.unwrap_or_else(Vec3::zeros);
        if let Some(v) = xyz
            .iter()
            .find(|v| v.abs() > crate::model::model_limits::MAX_LENGTH)
        {
            return Err(self.bad(
                o,
                format!(
                    "<origin xyz>: {} m is beyond the {} m accepted for a coordinate",
                    crate::core::diag::fmt_num(*v),
                    crate::core::diag::fmt_num(crate::model::model_limits::MAX_LENGTH)
                ),
            ));
        }
        let rpy = self.vec3(o, "rpy")?.unwrap_or_else(Vec3::zeros);
        Ok(Se3::new(rpy_to_matrix([rpy.x, rpy.y, rpy.z]), xyz))
    }

    /// `text` with every XML declaration after the first byte blanked out (urdfdom's
    /// tinyxml2 accepts them after white space; XML only at the start), with a warning
    /// each. Byte offsets and lines are kept.
    pub(super) fn without_late_declarations(&mut self, text: &str) -> String {
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
    pub(super) fn declare_prefixes(&mut self, mut text: String) -> String {
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
