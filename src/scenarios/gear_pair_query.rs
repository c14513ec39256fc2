//! The `[[query]]` tables of a `kind = "gear_pair"` file (format in `docs/machines.md`):
//! "which tooth count gives X" ([`crate::machines::gearing::tooth_count_queries`]), read
//! with located errors and reported as JSON.

use crate::core::diag::LocatedError as ScenarioError;
use crate::machines::gearing::tooth_count_queries::{
    boundary_teeth, ToothCountAnswer, ToothCountQuery, ToothData,
};
use crate::scenarios::source::{in_range, Source};
use serde::Deserialize;
use serde_json::{json, Value};
use toml::Spanned;

/// One `[[query]]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QueryTable {
    label: Option<String>,
    find: String,
    pressure_angle_deg: Option<f64>,
    helix_angle_deg: Option<f64>,
    addendum: Option<f64>,
    clearance: Option<f64>,
    shift: Option<f64>,
}

/// The file-level defaults a query falls back on (`pressure_angle_deg`, `addendum`,
/// `clearance`).
#[derive(Clone, Copy, Debug)]
pub struct Defaults {
    /// Degrees.
    pub pressure_angle_deg: Option<f64>,
    /// `h_a*`.
    pub addendum: Option<f64>,
    /// `c*`.
    pub clearance: Option<f64>,
}

/// A read and answered query.
#[derive(Clone, Debug, PartialEq)]
pub struct QueryCase {
    /// Label (default `query[i]`).
    pub label: String,
    /// What is asked.
    pub query: ToothCountQuery,
    /// The data.
    pub data: ToothData,
    /// The answer.
    pub answer: ToothCountAnswer,
}

/// Reads and answers `query[i]`.
pub fn read(
    cx: &Source,
    i: usize,
    s: &Spanned<QueryTable>,
    d: Defaults,
) -> Result<QueryCase, ScenarioError> {
    let q = s.get_ref();
    let err =
        |field: &str, msg: String| cx.field(s.span(), field, format!("query[{i}].{field}"), msg);
    let query = ToothCountQuery::from_name(&q.find).ok_or_else(|| {
        err(
            "find",
            format!(
                "unknown query '{}' (expected root_equals_base, internal_tip_equals_base or no_undercut)",
                q.find
            ),
        )
    })?;
    if query != ToothCountQuery::RootEqualsBase && q.clearance.is_some() {
        return Err(err(
            "clearance",
            format!("is not used by `find = \"{}\"`", q.find),
        ));
    }
    if query == ToothCountQuery::InternalTipEqualsBase && q.shift.is_some() {
        return Err(err(
            "shift",
            format!("is not used by `find = \"{}\"`", q.find),
        ));
    }
    let alpha = q
        .pressure_angle_deg
        .or(d.pressure_angle_deg)
        .unwrap_or(20.0);
    if !in_range(alpha, 1.0, 45.0) {
        return Err(err(
            "pressure_angle_deg",
            format!("must be 1 … 45°, got {alpha}"),
        ));
    }
    let beta = q.helix_angle_deg.unwrap_or(0.0);
    if !in_range(beta, 0.0, 60.0) {
        return Err(err(
            "helix_angle_deg",
            format!("must be 0 … 60°, got {beta}"),
        ));
    }
    let ha = q.addendum.or(d.addendum).unwrap_or(1.0);
    let c = q.clearance.or(d.clearance).unwrap_or(0.25);
    if !in_range(ha, 0.1, 3.0) {
        return Err(err("addendum", format!("must be 0.1 … 3, got {ha}")));
    }
    if !in_range(c, 0.0, 1.0) {
        return Err(err("clearance", format!("must be 0 … 1, got {c}")));
    }
    let shift = q.shift.unwrap_or(0.0);
    if !in_range(shift, -3.0, 3.0) {
        return Err(err("shift", format!("must be −3 … 3, got {shift}")));
    }
    let data = ToothData {
        pressure_angle: alpha.to_radians(),
        helix_angle: beta.to_radians(),
        addendum: ha,
        clearance: c,
        shift,
    };
    let answer = boundary_teeth(query, &data).ok_or_else(|| {
        err(
            "shift",
            format!("with shift {shift} the boundary is not a positive tooth count"),
        )
    })?;
    Ok(QueryCase {
        label: q.label.clone().unwrap_or_else(|| format!("query[{i}]")),
        query,
        data,
        answer,
    })
}

/// The JSON entry of a query.
pub fn query_json(c: &QueryCase) -> Value {
    json!({
        "label": c.label,
        "find": c.query.name(),
        "pressure_angle_deg": c.data.pressure_angle.to_degrees(),
        "helix_angle_deg": c.data.helix_angle.to_degrees(),
        "addendum": c.data.addendum,
        "clearance": c.data.clearance,
        "shift": c.data.shift,
        "teeth_exact": c.answer.exact,
        "largest_below": c.answer.largest_below,
        "teeth": c.answer.answer,
        "meaning": c.query.meaning(),
    })
}

/// The text line of a query.
pub fn query_line(c: &QueryCase) -> String {
    format!(
        "{}: {} at z = {:.4}: z = {} ({})",
        c.label,
        c.query.name(),
        c.answer.exact,
        c.answer.answer,
        c.query.meaning()
    )
}
