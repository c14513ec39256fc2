//! `toml` errors as located errors: [`LocatedError::from_toml`] takes the line from the
//! error's span and the key from its message (`unknown field`, `missing field`) or from
//! the line, prefixed with the enclosing `[table]`. Shared by the DH-table reader and the
//! scenario readers.

use crate::core::diag::{line_at, LocatedError};

impl LocatedError {
    /// From a `toml` deserialisation error of `text` (line from its span; the key from
    /// the message (`unknown field`, `missing field`) or the line, prefixed with the
    /// enclosing `[table]`).
    pub fn from_toml(file: &str, text: &str, e: &toml::de::Error) -> Self {
        let line = e.span().map(|s| line_at(text, s.start));
        let line_text = line.and_then(|l| text.lines().nth(l - 1)).unwrap_or("");
        let key = toml_error_key(text, line, line_text, e.message());
        let message = e
            .message()
            .lines()
            .map(str::trim)
            .collect::<Vec<_>>()
            .join(" ");
        Self::new(file, line, key, message)
    }
}

/// The key a `toml` error message names: the quoted field of `unknown field`/`missing
/// field`, else the key assigned on the error's line, prefixed with the enclosing table.
fn toml_error_key(text: &str, line: Option<usize>, line_text: &str, msg: &str) -> String {
    let quoted = |what: &str| {
        let i = msg.find(what)? + what.len();
        let rest = msg[i..].strip_prefix('`')?;
        Some(rest[..rest.find('`')?].to_string())
    };
    let from_line = line_text
        .split('=')
        .next()
        .map(|k| k.trim().to_string())
        .filter(|k| !k.is_empty() && !k.starts_with('#') && !k.starts_with('['));
    let table = line.and_then(|l| enclosing_table(text, l));
    let on_header = line_text.trim_start().starts_with('[');
    match quoted("unknown field ")
        .or_else(|| quoted("missing field "))
        .or(from_line)
    {
        Some(k) => match &table {
            Some(t) if on_header || !k.starts_with(t.as_str()) => {
                if on_header && msg.contains("missing field") {
                    format!("{t}.{k}")
                } else if on_header {
                    t.clone()
                } else {
                    format!("{t}.{k}")
                }
            }
            _ => k,
        },
        None => table.unwrap_or_else(|| "file".into()),
    }
}

/// The `[table]` or `[[array]]` header in force at 1-based `line` (inclusive).
fn enclosing_table(text: &str, line: usize) -> Option<String> {
    text.lines()
        .take(line)
        .collect::<Vec<_>>()
        .iter()
        .rev()
        .find_map(|t| {
            let t = t.trim();
            let inner = t.strip_prefix("[[").and_then(|x| x.strip_suffix("]]"));
            let inner = inner.or_else(|| t.strip_prefix('[').and_then(|x| x.strip_suffix(']')));
            inner.map(|x| x.trim().to_string())
        })
}

#[cfg(test)]
mod tests {
    use crate::core::diag::LocatedError;

    #[test]
    fn toml_errors_name_the_table_and_the_key() {
        #[derive(serde::Deserialize, Debug)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct S {
            t: T,
        }
        #[derive(serde::Deserialize, Debug)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct T {
            a: f64,
        }
        let text = "[t]\na = 1.0\nb = 2\n";
        let e = toml::from_str::<S>(text).unwrap_err();
        let e = LocatedError::from_toml("f.toml", text, &e);
        assert_eq!((e.line, e.key.as_str()), (Some(3), "t.b"), "{e}");
        assert!(
            e.to_string().starts_with("f.toml:3: t.b: unknown field"),
            "{e}"
        );
    }
}
