//! Denavit–Hartenberg table (TOML) → [`ModelSpec`]. The format is documented in
//! `docs/dh-format.md`.
//!
//! - Standard (distal) rows: `A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)`. Joint `i`
//!   moves about/along `z_{i-1}`, so its joint frame is DH frame `i-1` and link `i`'s frame
//!   is the joint frame times `Rz(theta) Tz(d) Tx(a) Rx(alpha)` (the joint's own `Rz(q)` or
//!   `Tz(q)` commutes with the `Rz`/`Tz` factor that carries the offset).
//! - Modified (proximal, Craig) rows: `A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)`:
//!   the whole row is the joint origin and link `i`'s frame is the joint frame.

use crate::core::spatial::{rot_x, rot_z, rpy_to_matrix, Inertia, Mat3, Se3, Vec3};
use crate::model::spec::*;
use crate::model::ModelError;
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DhFile {
    name: Option<String>,
    convention: String,
    gravity: Option<[f64; 3]>,
    base: Option<PoseToml>,
    tool: Option<PoseToml>,
    #[serde(default)]
    joint: Vec<DhRow>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PoseToml {
    xyz: Option<[f64; 3]>,
    rpy: Option<[f64; 3]>,
    rpy_deg: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DhRow {
    name: Option<String>,
    #[serde(rename = "type")]
    jtype: String,
    theta: Option<f64>,
    theta_deg: Option<f64>,
    d: Option<f64>,
    a: Option<f64>,
    alpha: Option<f64>,
    alpha_deg: Option<f64>,
    lower: Option<f64>,
    upper: Option<f64>,
    lower_deg: Option<f64>,
    upper_deg: Option<f64>,
    velocity: Option<f64>,
    effort: Option<f64>,
    continuous: Option<bool>,
    mass: Option<f64>,
    com: Option<[f64; 3]>,
    inertia: Option<[f64; 6]>,
    motor_inertia: Option<f64>,
    gear_ratio: Option<f64>,
}

/// 1-based line of the `n`-th (0-based) `[[joint]]` header, and the element name of the
/// table that encloses byte offset `pos`.
struct Layout {
    joint_lines: Vec<usize>,
    /// (line, element) for every table header, in order.
    headers: Vec<(usize, String)>,
    /// (line, key) for top-level keys before the first table.
    keys: Vec<(usize, String)>,
}

impl Layout {
    fn scan(text: &str) -> Self {
        let mut joint_lines = Vec::new();
        let mut headers = Vec::new();
        let mut keys = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let l = raw.trim();
            if headers.is_empty() {
                if let Some((k, _)) = l.split_once('=') {
                    keys.push((i + 1, k.trim().to_string()));
                }
            }
            if l.starts_with("[[joint]]") {
                joint_lines.push(i + 1);
                headers.push((i + 1, format!("joint {}", joint_lines.len())));
            } else if let Some(rest) = l.strip_prefix('[') {
                let name = rest
                    .trim_start_matches('[')
                    .split(']')
                    .next()
                    .unwrap_or("")
                    .trim();
                headers.push((i + 1, format!("[{name}]")));
            }
        }
        Self {
            joint_lines,
            headers,
            keys,
        }
    }

    /// Line of a table header (`[base]`) or of a top-level key (`convention`).
    fn line_of(&self, what: &str) -> Option<usize> {
        if what.starts_with('[') {
            return self
                .headers
                .iter()
                .find(|(_, e)| e == what)
                .map(|(l, _)| *l);
        }
        self.keys.iter().find(|(_, k)| k == what).map(|(l, _)| *l)
    }

    fn element_at_line(&self, line: usize) -> String {
        self.headers
            .iter()
            .rev()
            .find(|(l, _)| *l <= line)
            .map(|(_, e)| e.clone())
            .unwrap_or_else(|| "top level".to_string())
    }
}

/// Parses a DH table read from `file`.
pub fn parse(text: &str, file: &str) -> Result<ModelSpec, ModelError> {
    let layout = Layout::scan(text);
    let dh: DhFile = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| crate::core::diag::line_at(text, s.start));
        let element = line
            .map(|l| layout.element_at_line(l))
            .unwrap_or_else(|| "file".to_string());
        // toml's messages can span lines ("invalid table header\nexpected ..."): keep the
        // one-line `FILE:LINE: ELEMENT: MESSAGE` form.
        let message: Vec<&str> = e
            .message()
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        ModelError::new(file, line, element, message.join(": "))
    })?;
    build(dh, file, &layout)
}

fn finite(
    file: &str,
    line: Option<usize>,
    element: &str,
    key: &str,
    vals: &[f64],
) -> Result<(), ModelError> {
    if vals.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(ModelError::new(
            file,
            line,
            element,
            format!("'{key}': non-finite number"),
        ))
    }
}

/// `vals` finite and within [`crate::model::model_limits::MAX_LENGTH`] (lengths and coordinates, m).
fn length(
    file: &str,
    line: Option<usize>,
    element: &str,
    key: &str,
    vals: &[f64],
) -> Result<(), ModelError> {
    finite(file, line, element, key, vals)?;
    match vals
        .iter()
        .find(|v| v.abs() > crate::model::model_limits::MAX_LENGTH)
    {
        Some(v) => Err(ModelError::new(
            file,
            line,
            element,
            format!(
                "'{key}': {} m is beyond the {} m accepted for a length or coordinate",
                crate::core::diag::fmt_num(*v),
                crate::core::diag::fmt_num(crate::model::model_limits::MAX_LENGTH)
            ),
        )),
        None => Ok(()),
    }
}

fn one_of(
    file: &str,
    line: Option<usize>,
    element: &str,
    (k1, v1): (&str, Option<f64>),
    (k2, v2): (&str, Option<f64>),
) -> Result<Option<f64>, ModelError> {
    match (v1, v2) {
        (Some(_), Some(_)) => Err(ModelError::new(
            file,
            line,
            element,
            format!("give either '{k1}' or '{k2}', not both"),
        )),
        (Some(x), None) => {
            finite(file, line, element, k1, &[x])?;
            Ok(Some(x))
        }
        (None, Some(x)) => {
            finite(file, line, element, k2, &[x])?;
            Ok(Some(x.to_radians()))
        }
        (None, None) => Ok(None),
    }
}

fn pose(
    file: &str,
    layout: &Layout,
    element: &str,
    p: &Option<PoseToml>,
) -> Result<Se3, ModelError> {
    let Some(p) = p else {
        return Ok(Se3::identity());
    };
    let line = layout.line_of(element);
    let xyz = p.xyz.unwrap_or([0.0; 3]);
    length(file, line, element, "xyz", &xyz)?;
    let rpy = match (p.rpy, p.rpy_deg) {
        (Some(_), Some(_)) => {
            return Err(ModelError::new(
                file,
                line,
                element,
                "give either 'rpy' or 'rpy_deg', not both",
            ))
        }
        (Some(r), None) => r,
        (None, Some(r)) => r.map(f64::to_radians),
        (None, None) => [0.0; 3],
    };
    finite(file, line, element, "rpy", &rpy)?;
    Ok(Se3::new(rpy_to_matrix(rpy), Vec3::from(xyz)))
}

fn tz(d: f64) -> Se3 {
    Se3::from_translation(Vec3::new(0.0, 0.0, d))
}

fn tx(a: f64) -> Se3 {
    Se3::from_translation(Vec3::new(a, 0.0, 0.0))
}

fn build(dh: DhFile, file: &str, layout: &Layout) -> Result<ModelSpec, ModelError> {
    let modified = match dh.convention.as_str() {
        "standard" => false,
        "modified" => true,
        other => {
            return Err(ModelError::new(
                file,
                layout.line_of("convention"),
                "convention",
                format!("unknown convention '{other}' (expected \"standard\" or \"modified\")"),
            ))
        }
    };
    if dh.joint.is_empty() {
        return Err(ModelError::new(
            file,
            None,
            "joint",
            "the table has no [[joint]] rows",
        ));
    }
    let base = pose(file, layout, "[base]", &dh.base)?;
    let tool = pose(file, layout, "[tool]", &dh.tool)?;
    if let Some(g) = dh.gravity {
        finite(file, layout.line_of("gravity"), "gravity", "gravity", &g)?;
    }
    let mut links = vec![LinkSpec::new("base_link")];
    let mut joints = Vec::with_capacity(dh.joint.len() + 1);
    for (i, row) in dh.joint.iter().enumerate() {
        let (joint, link) = dh_row(file, layout, i, row, modified)?;
        joints.push(joint);
        links.push(link);
    }
    let n = dh.joint.len();
    let mut tj = JointSpec::new("tool_joint", JointType::Fixed, format!("link{n}"), "tool");
    tj.origin = tool;
    joints.push(tj);
    links.push(LinkSpec::new("tool"));
    Ok(ModelSpec {
        gravity: dh.gravity.map(Vec3::from),
        warnings: Vec::new(),
        name: dh.name.unwrap_or_else(|| "dh_robot".to_string()),
        source: file.to_string(),
        root_offset: base,
        links,
        joints,
        urdf_text: None,
    })
}

/// Row `i` of the table: the joint from link `i` (`base_link` for the first) to link
/// `i + 1`, placed by the convention's four factors, and that link's inertia.
fn dh_row(
    file: &str,
    layout: &Layout,
    i: usize,
    row: &DhRow,
    modified: bool,
) -> Result<(JointSpec, LinkSpec), ModelError> {
    let n = i + 1;
    let line = layout.joint_lines.get(i).copied();
    let element = match &row.name {
        Some(name) => format!("joint {n} ('{name}')"),
        None => format!("joint {n}"),
    };
    let el = element.as_str();
    let revolute = match row.jtype.as_str() {
        "R" | "r" => true,
        "P" | "p" => false,
        other => {
            return Err(ModelError::new(
                file,
                line,
                el,
                format!("'type': unknown joint type '{other}' (expected \"R\" or \"P\")"),
            ))
        }
    };
    let theta = one_of(
        file,
        line,
        el,
        ("theta", row.theta),
        ("theta_deg", row.theta_deg),
    )?
    .unwrap_or(0.0);
    let alpha = one_of(
        file,
        line,
        el,
        ("alpha", row.alpha),
        ("alpha_deg", row.alpha_deg),
    )?
    .unwrap_or(0.0);
    let d = row.d.unwrap_or(0.0);
    let a = row.a.unwrap_or(0.0);
    length(file, line, el, "d", &[d])?;
    length(file, line, el, "a", &[a])?;
    let (jtype, limits) = dh_limits(file, line, el, row, revolute)?;
    let parent = if i == 0 {
        "base_link".to_string()
    } else {
        format!("link{i}")
    };
    let child = format!("link{n}");
    let mut js = JointSpec::new(
        row.name.clone().unwrap_or_else(|| format!("joint{n}")),
        jtype,
        parent,
        &child,
    );
    // Offsets: theta for R (and d) or d for P (and theta) sit in the same Rz·Tz factor.
    let rz_tz = Se3::from_rotation(rot_z(theta)).mul(&tz(d));
    let rx = Se3::from_rotation(rot_x(alpha));
    if modified {
        js.origin = rx.mul(&tx(a)).mul(&rz_tz);
    } else {
        js.child_offset = rz_tz.mul(&tx(a)).mul(&rx);
    }
    js.limits = limits;
    js.motor_inertia = row.motor_inertia.unwrap_or(0.0);
    js.gear_ratio = row.gear_ratio.unwrap_or(1.0);
    js.line = line;
    let mut link = LinkSpec::new(child);
    link.line = line;
    let mass = row.mass.unwrap_or(0.0);
    let com = row.com.unwrap_or([0.0; 3]);
    let t = row.inertia.unwrap_or([0.0; 6]);
    finite(file, line, el, "mass", &[mass])?;
    length(file, line, el, "com", &com)?;
    finite(file, line, el, "inertia", &t)?;
    let tensor = Mat3::new(t[0], t[3], t[4], t[3], t[1], t[5], t[4], t[5], t[2]);
    link.inertial = Inertia::new(mass, Vec3::from(com), tensor);
    Ok((js, link))
}

/// A row's joint type and limits: position limits (radians or degrees for a revolute
/// joint, metres for a prismatic one) unless continuous, velocity and effort (unbounded
/// by default).
fn dh_limits(
    file: &str,
    line: Option<usize>,
    el: &str,
    row: &DhRow,
    revolute: bool,
) -> Result<(JointType, Limits), ModelError> {
    if !revolute && (row.lower_deg.is_some() || row.upper_deg.is_some()) {
        return Err(ModelError::new(
            file,
            line,
            el,
            "'lower_deg'/'upper_deg' apply to revolute joints only; give 'lower'/'upper' in metres",
        ));
    }
    let lower = one_of(
        file,
        line,
        el,
        ("lower", row.lower),
        ("lower_deg", row.lower_deg),
    )?;
    let upper = one_of(
        file,
        line,
        el,
        ("upper", row.upper),
        ("upper_deg", row.upper_deg),
    )?;
    let continuous = row.continuous.unwrap_or(false);
    if continuous && !revolute {
        return Err(ModelError::new(
            file,
            line,
            el,
            "'continuous': a prismatic joint cannot be continuous",
        ));
    }
    if continuous && (lower.is_some() || upper.is_some()) {
        return Err(ModelError::new(
            file,
            line,
            el,
            "'continuous': a continuous joint has no position limits",
        ));
    }
    if let (Some(l), Some(u)) = (lower, upper) {
        if l > u {
            // Name the keys and values as written (degrees when given in degrees).
            let show = |k: &str, rad: f64, deg: Option<f64>| match deg {
                Some(d) => format!("'{k}_deg' = {d}"),
                None => format!("'{k}' = {rad}"),
            };
            return Err(ModelError::new(
                file,
                line,
                el,
                format!(
                    "lower limit {} is greater than upper limit {}",
                    show("lower", l, row.lower_deg),
                    show("upper", u, row.upper_deg)
                ),
            ));
        }
    }
    let (lower, upper) = match (lower, upper, continuous) {
        (_, _, true) => (f64::NEG_INFINITY, f64::INFINITY),
        (Some(l), Some(u), false) => (l, u),
        _ => {
            return Err(ModelError::new(
                file,
                line,
                el,
                "'lower'/'upper': position limits are required (or 'continuous = true' for an unlimited revolute joint)",
            ))
        }
    };
    let velocity = row.velocity.unwrap_or(f64::INFINITY);
    let effort = row.effort.unwrap_or(f64::INFINITY);
    for (k, v) in [("velocity", velocity), ("effort", effort)] {
        if v.is_nan() || v < 0.0 {
            return Err(ModelError::new(
                file,
                line,
                el,
                format!("'{k}': must be a non-negative number"),
            ));
        }
    }
    let jtype = match (revolute, continuous) {
        (true, true) => JointType::Continuous,
        (true, false) => JointType::Revolute,
        (false, _) => JointType::Prismatic,
    };
    Ok((
        jtype,
        Limits {
            lower,
            upper,
            velocity,
            effort,
        },
    ))
}
