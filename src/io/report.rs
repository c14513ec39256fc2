//! What a scenario runner or study returns: the JSON document and the human summary
//! ([`Report`]), and the number formatting of human reports ([`human_num`],
//! [`human_json`]).

/// What a scenario run produced.
#[derive(Debug, Clone)]
pub struct Report {
    /// The JSON document `armsim run --json` prints.
    pub json: serde_json::Value,
    /// The human-readable summary.
    pub text: String,
}

impl Report {
    /// The first line of the human summary that shows a non-finite number (`NaN`, `inf`
    /// or `-inf` as a word), trimmed: a result that must not be printed as an answer.
    /// Words that belong to names are not numbers: the report's JSON strings (a scenario,
    /// link or obstacle named `inf` or `inf box`) are taken out of the text first, and a
    /// word next to a quote or a path separator (`'inf'`, `/tmp/NaN/`) is skipped. (So a
    /// link named just `inf` hides an `inf` printed elsewhere; every quantity is also
    /// checked where it is computed, and this guard is the last one.)
    pub fn non_finite_line(&self) -> Option<&str> {
        let mut names = Vec::new();
        named_strings(&self.json, &mut names);
        self.text.lines().map(str::trim).find(|l| {
            let mut line = (*l).to_string();
            for n in &names {
                line = line.replace(n.as_str(), " ");
            }
            has_non_finite_word(&line)
        })
    }
}

/// Whether `line` has `NaN` or `inf` as a word (letters, digits, `_` and `.` make words)
/// that is not quoted or part of a path.
fn has_non_finite_word(line: &str) -> bool {
    let word = |c: char| c.is_alphanumeric() || c == '_' || c == '.';
    let bytes: Vec<char> = line.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        if !word(bytes[i]) {
            i += 1;
            continue;
        }
        let start = i;
        while i < bytes.len() && word(bytes[i]) {
            i += 1;
        }
        let w: String = bytes[start..i].iter().collect();
        let quoted = |c: Option<&char>| matches!(c, Some('\'' | '"' | '/' | '\\' | '`'));
        if matches!(w.as_str(), "NaN" | "inf")
            && !quoted(start.checked_sub(1).and_then(|k| bytes.get(k)))
            && !quoted(bytes.get(i))
        {
            return true;
        }
    }
    false
}

/// The JSON's short strings that hold a `NaN` or `inf` word (names, labels, paths), longest
/// first so that a name inside another is taken out after it.
fn named_strings(v: &serde_json::Value, out: &mut Vec<String>) {
    fn walk(v: &serde_json::Value, out: &mut Vec<String>) {
        match v {
            serde_json::Value::String(s) if s.len() <= 200 && has_non_finite_word(s) => {
                out.push(s.clone());
            }
            serde_json::Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            serde_json::Value::Object(o) => o.iter().for_each(|(k, x)| {
                if has_non_finite_word(k) {
                    out.push(k.clone());
                }
                walk(x, out);
            }),
            _ => {}
        }
    }
    walk(v, out);
    out.sort_by_key(|s| std::cmp::Reverse(s.len()));
    out.dedup();
}

/// `x` for a human report: six significant digits, trailing zeros dropped (`89`, not
/// `89.00000000000001`), `e` notation for very large or very small magnitudes.
pub fn human_num(x: f64) -> String {
    let a = x.abs();
    if !x.is_finite() || a == 0.0 {
        return format!("{x}");
    }
    if !(1e-4..1e7).contains(&a) {
        let s = format!("{x:.5e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = m.trim_end_matches('0').trim_end_matches('.');
        return format!("{m}e{e}");
    }
    let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" {
        "0".into()
    } else {
        s
    }
}

/// A JSON value as human text: numbers by [`human_num`], `{"value_deg", "at_deg"}` as
/// `V° at A°`, other objects as `key value, key value`, lists in brackets, null as `-`.
pub fn human_json(v: &serde_json::Value) -> String {
    use serde_json::Value;
    match v {
        Value::Null => "-".into(),
        Value::Bool(b) => if *b { "yes" } else { "no" }.into(),
        Value::Number(n) => n.as_f64().map_or_else(|| n.to_string(), human_num),
        Value::String(s) => s.clone(),
        Value::Array(a) => format!(
            "[{}]",
            a.iter().map(human_json).collect::<Vec<_>>().join(", ")
        ),
        Value::Object(o) => match (o.get("value_deg"), o.get("at_deg")) {
            (Some(x), Some(at)) if o.len() == 2 => {
                format!("{}° at {}°", human_json(x), human_json(at))
            }
            _ => o
                .iter()
                .map(|(k, x)| format!("{k} {}", human_json(x)))
                .collect::<Vec<_>>()
                .join(", "),
        },
    }
}

/// `12.3 µs`, `4.56 ms`, `789 ns` from nanoseconds.
pub fn fmt_ns(ns: f64) -> String {
    if !ns.is_finite() {
        "–".into()
    } else if ns >= 1e9 {
        format!("{:.2} s", ns * 1e-9)
    } else if ns >= 1e6 {
        format!("{:.2} ms", ns * 1e-6)
    } else if ns >= 1e3 {
        format!("{:.2} µs", ns * 1e-3)
    } else {
        format!("{ns:.0} ns")
    }
}

#[cfg(test)]
mod tests {
    use crate::core::diag::fmt_num;
    use crate::io::report::{has_non_finite_word, human_json, human_num, Report};
    use serde_json::json;

    fn report(json: serde_json::Value, text: &str) -> Report {
        Report {
            json,
            text: text.into(),
        }
    }

    #[test]
    fn non_finite_numbers_are_found_and_names_are_not() {
        let r = report(json!({}), "peak 1.5 N\n  force NaN N at 3\n");
        assert_eq!(r.non_finite_line(), Some("force NaN N at 3"));
        assert!(report(json!({}), "x = -inf").non_finite_line().is_some());
        assert!(report(json!({}), "(inf, 0)").non_finite_line().is_some());
        // A scenario, link or obstacle named `inf`, quoted or not, and paths.
        let named = json!({"scenario": "inf", "links": ["NaN"], "o": {"name": "inf box"}});
        let text = "Scenario 'inf'\n  link NaN carries 3 N\n  obstacle inf box at 1 m\n\
                    plot: /tmp/inf/NaN/x.png\n  file \"NaN\"";
        assert_eq!(report(named.clone(), text).non_finite_line(), None);
        // A longer name does not hide a number elsewhere in the text. (A bare name `inf`
        // does: the guard then rests on the checks of each quantity.)
        let named = json!({"o": {"name": "inf box"}});
        let both = "obstacle inf box at 1 m\nforce inf N";
        assert_eq!(report(named, both).non_finite_line(), Some("force inf N"));
        assert!(!has_non_finite_word("information infinite NaNs"));
    }

    #[test]
    fn human_text_rounds_and_names() {
        assert_eq!(human_num(89.00000000000001), "89");
        assert_eq!(human_num(0.123456789), "0.123457");
        assert_eq!(human_num(-1234.5), "-1234.5");
        assert_eq!(human_num(2.5e-7), "2.5e-7");
        let v = serde_json::json!({"value_deg": 0.0, "at_deg": 89.00000000000001});
        assert_eq!(human_json(&v), "0° at 89°");
        let v = serde_json::json!({"force_N": 12.0, "lock": true});
        assert_eq!(human_json(&v), "force_N 12, lock yes");
    }

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(fmt_num(0.25), "0.25");
        assert_eq!(fmt_num(1500.0), "1500");
        assert_eq!(fmt_num(1e308), "1e308");
        assert_eq!(fmt_num(-2.5e-300), "-2.5e-300");
        assert_eq!(fmt_num(f64::NAN), "NaN");
        assert_eq!(fmt_num(0.0), "0");
    }
}
