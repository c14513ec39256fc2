//! What a scenario runner returns: the JSON document and the human summary. A leaf
//! module, so the runners ([`crate::arm`], [`crate::mechanism`], [`crate::drivetrain`])
//! do not import the dispatcher ([`crate::scenario`]) that calls them.

/// What a scenario run produced.
#[derive(Debug, Clone)]
pub struct Report {
    /// The JSON document `armsim run --json` prints.
    pub json: serde_json::Value,
    /// The human-readable summary.
    pub text: String,
}

/// `x` for a message: Rust's shortest form for ordinary magnitudes (`0.25`, `1500`),
/// `e` notation for very large or very small ones (`1e308`, not 309 digits; `1e-300`),
/// and `NaN`, `inf`, `-inf` as such.
pub fn fmt_num(x: f64) -> String {
    let a = x.abs();
    if !x.is_finite() || a == 0.0 || (1e-4..1e7).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::fmt_num;

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
