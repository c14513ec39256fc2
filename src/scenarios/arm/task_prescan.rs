//! The task lists' length, counted in the scenario text before it is parsed as TOML: a
//! `[task]` `waypoints`, `poses` or `steps` array longer than
//! [`MAX_TASK_STEPS`](crate::scenarios::arm::scene::MAX_TASK_STEPS) is refused at its
//! first entry over the limit, without reading the rest of the file (a file of 10⁶
//! waypoints took seconds to parse, over 30 s on a loaded machine, before the count was
//! checked on the parsed table).
//!
//! The scan is lexical and skips what it does not follow: comments, basic and literal
//! strings (single- and multi-line), inline tables and nested arrays are stepped over; a
//! list written as an inline table (`task = { waypoints = […] }`) is not counted here (the
//! count on the parsed table still refuses it). Anything malformed ends the scan, so the
//! TOML parser reports it. Tests: `tests/hostile_work.rs` (the scan on its own, on every
//! bundled scenario, and a 10⁶-waypoint file through `armsim run`).

use crate::core::diag::LocatedError;
use crate::scenarios::arm::scene::MAX_TASK_STEPS;

/// The keys counted, as `TABLE.KEY` after quotes and blanks are removed.
const COUNTED: [&str; 3] = ["task.waypoints", "task.poses", "task.steps"];

/// A byte cursor over the scenario text, with its line.
struct Scan<'t> {
    b: &'t [u8],
    i: usize,
    line: usize,
}

impl Scan<'_> {
    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    fn bump(&mut self) {
        if self.peek() == Some(b'\n') {
            self.line += 1;
        }
        self.i += 1;
    }

    fn starts(&self, s: &[u8]) -> bool {
        self.b[self.i..].starts_with(s)
    }

    /// Blanks and comments (and newlines when `newlines`).
    fn skip_blank(&mut self, newlines: bool) {
        while let Some(c) = self.peek() {
            match c {
                b' ' | b'\t' | b'\r' => self.bump(),
                b'\n' if newlines => self.bump(),
                b'#' => {
                    while self.peek().is_some_and(|c| c != b'\n') {
                        self.bump();
                    }
                }
                _ => break,
            }
        }
    }

    /// A string starting at the cursor (`"`, `'`, `"""` or `'''`); `None` if unterminated.
    fn skip_string(&mut self) -> Option<()> {
        let q = self.peek()?;
        let multi = self.starts(if q == b'"' { b"\"\"\"" } else { b"'''" });
        let n = if multi { 3 } else { 1 };
        for _ in 0..n {
            self.bump();
        }
        loop {
            let c = self.peek()?;
            if c == b'\\' && q == b'"' {
                self.bump();
                self.bump();
            } else if c == q && (!multi || self.starts(&[q; 3])) {
                for _ in 0..n {
                    self.bump();
                }
                // A multi-line string may end with up to two more quotes.
                while multi && self.peek() == Some(q) {
                    self.bump();
                }
                return Some(());
            } else if c == b'\n' && !multi {
                return None;
            } else {
                self.bump();
            }
        }
    }

    /// An array or inline table opened at the cursor, to its closing bracket. In an array,
    /// `each` is called with the line of every entry at its top level; it stops the scan
    /// by returning an error.
    fn skip_nested(
        &mut self,
        each: &mut dyn FnMut(usize) -> Result<(), LocatedError>,
    ) -> Result<Option<()>, LocatedError> {
        let mut depth = 0usize;
        let mut expecting = true;
        loop {
            self.skip_blank(true);
            let Some(c) = self.peek() else {
                return Ok(None);
            };
            if depth == 1 && expecting && !matches!(c, b']' | b'}' | b',') {
                each(self.line)?;
                expecting = false;
            }
            match c {
                b'"' | b'\'' => {
                    if self.skip_string().is_none() {
                        return Ok(None);
                    }
                    continue;
                }
                b'[' | b'{' => depth += 1,
                b']' | b'}' => {
                    depth -= 1;
                    if depth == 0 {
                        self.bump();
                        return Ok(Some(()));
                    }
                }
                b',' if depth == 1 => expecting = true,
                _ => {}
            }
            self.bump();
        }
    }
}

/// A key or table name without quotes and blanks (`"task" . waypoints` → `task.waypoints`).
fn normalize(raw: &[u8]) -> String {
    String::from_utf8_lossy(raw)
        .chars()
        .filter(|c| !matches!(c, ' ' | '\t' | '"' | '\''))
        .collect()
}

/// Refuses a `[task]` list longer than [`MAX_TASK_STEPS`] (see the module docs), naming
/// the file, the line of the first entry over the limit and the key.
pub fn check(file: &str, text: &str) -> Result<(), LocatedError> {
    let mut s = Scan {
        b: text.as_bytes(),
        i: 0,
        line: 1,
    };
    let mut table = String::new();
    loop {
        s.skip_blank(true);
        let Some(c) = s.peek() else { return Ok(()) };
        if c == b'[' {
            // A table header: `[name]` or `[[name]]`, to the end of its line.
            let start = s.i;
            while s.peek().is_some_and(|c| c != b'\n' && c != b'#') {
                s.bump();
            }
            table = normalize(&s.b[start..s.i])
                .trim_matches(['[', ']'])
                .to_string();
            continue;
        }
        // A key, to its `=` on the same line.
        let start = s.i;
        while s.peek().is_some_and(|c| c != b'=' && c != b'\n') {
            if matches!(s.peek(), Some(b'"' | b'\'')) && s.skip_string().is_none() {
                return Ok(());
            }
            if s.peek().is_some_and(|c| c != b'=' && c != b'\n') {
                s.bump();
            }
        }
        if s.peek() != Some(b'=') {
            return Ok(()); // not TOML: the parser says why
        }
        let key = normalize(&s.b[start..s.i]);
        let full = if table.is_empty() {
            key
        } else {
            format!("{table}.{key}")
        };
        s.bump();
        s.skip_blank(false);
        match s.peek() {
            Some(b'[' | b'{') => {
                let counted = COUNTED.contains(&full.as_str()) && s.peek() == Some(b'[');
                let mut n = 0usize;
                let mut each = |line: usize| {
                    n += 1;
                    if counted && n > MAX_TASK_STEPS {
                        return Err(LocatedError::new(
                            file,
                            Some(line),
                            full.clone(),
                            format!(
                                "entry {n}: more than the {MAX_TASK_STEPS} entries one task \
                                 accepts (refused before the rest of the file is read)"
                            ),
                        ));
                    }
                    Ok(())
                };
                if s.skip_nested(&mut each)?.is_none() {
                    return Ok(());
                }
            }
            Some(b'"' | b'\'') if s.skip_string().is_none() => return Ok(()),
            _ => {}
        }
        // The rest of the line: a scalar, then perhaps a comment (left to `skip_blank`:
        // its text may hold an unpaired quote).
        while s.peek().is_some_and(|c| c != b'\n' && c != b'#') {
            if matches!(s.peek(), Some(b'"' | b'\'')) && s.skip_string().is_none() {
                return Ok(());
            }
            if s.peek().is_some_and(|c| c != b'\n' && c != b'#') {
                s.bump();
            }
        }
    }
}
