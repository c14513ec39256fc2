//! Guards shared by the XML readers (URDF, SRDF, COLLADA meshes, `package.xml`): a
//! lexical nesting pre-scan run before `roxmltree`, whose parser recurses once per element
//! level (about 20 000 nested elements overflow a thread's stack), and a line index so
//! that locating many nodes stays linear (`roxmltree`'s `text_pos_at` scans from the start
//! of the text on every call).
//!
//! Leaf module: imports nothing from the crate.

/// Byte offset of the start tag that opens nesting level `max_depth + 1`, if any.
/// A lexical scan: comments, CDATA, processing instructions and `<!…>` declarations are
/// skipped, quoted attribute values may hold `>`. Malformed text is left to roxmltree.
pub fn too_deep(text: &str, max_depth: usize) -> Option<usize> {
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
                if depth > max_depth {
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

/// Byte offsets of line starts, so a node's line is a binary search (roxmltree's
/// `text_pos_at` scans from the start of the text: quadratic over a large file).
pub struct LineIndex(Vec<usize>);

impl LineIndex {
    /// Indexes the line starts of `text`.
    pub fn new(text: &str) -> Self {
        let mut v = vec![0];
        v.extend(
            text.bytes()
                .enumerate()
                .filter(|&(_, b)| b == b'\n')
                .map(|(i, _)| i + 1),
        );
        Self(v)
    }

    /// 1-based line of byte offset `pos`.
    pub fn line(&self, pos: usize) -> usize {
        self.0.partition_point(|&s| s <= pos)
    }
}

#[cfg(test)]
mod tests {
    use crate::core::xml_guard::*;

    #[test]
    fn depth_counts_open_elements_only() {
        let t = "<?xml version=\"1.0\"?><!-- <x><x> --><a><b/><c x='>'><d></d></c></a>";
        assert_eq!(too_deep(t, 3), None);
        assert_eq!(too_deep(t, 2), Some(t.find("<d>").unwrap()));
        let deep = "<a>".repeat(20_000);
        assert_eq!(too_deep(&deep, 32), Some(3 * 32));
        let lx = LineIndex::new("a\nb\nc");
        assert_eq!((lx.line(0), lx.line(2), lx.line(4)), (1, 2, 3));
    }
}
