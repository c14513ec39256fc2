//! How the trade-offs report prints a measured number in scientific notation ([`sci`]),
//! shared by the Markdown writer and the studies' own report files.

/// `1.2e-5` (or `0` / `–`).
pub fn sci(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else if x.is_infinite() {
        "∞".into()
    } else if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.1e}")
    }
}
