//! `kind = "gear_pair"` scenario files (format in `docs/machines.md`): one or more
//! `[[pair]]` tables — external, internal or rack pairs (spur or helical), crossed
//! helical, worm and bevel pairs, cycloidal, pin and Roots pairs — each computed by [`crate::machines::gearing::pair`] or
//! [`crate::machines::gearing::crossed_axes`] and reported with its checks and tooth profiles.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::report::Report;
use crate::machines::gearing::pair::{validate, PairKind, PairSpec};
use crate::scenarios::gear_pair_profiles::{read, ProfileKeys, PROFILE_TYPES};
use crate::scenarios::gear_pair_query::{Defaults, QueryTable};
use crate::scenarios::gear_pair_report::{report, PairCase, PairScenario, SpatialCase};
use crate::scenarios::source::{in_range, Source};
use serde::Deserialize;
use std::fmt::Write;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    module: Option<f64>,
    pressure_angle_deg: Option<f64>,
    addendum: Option<f64>,
    clearance: Option<f64>,
    #[serde(default)]
    pair: Vec<Spanned<PairTable>>,
    #[serde(default)]
    query: Vec<Spanned<QueryTable>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct PairTable {
    label: Option<String>,
    #[serde(rename = "type")]
    kind: Option<String>,
    module: Option<f64>,
    teeth: Option<Vec<i64>>,
    pressure_angle_deg: Option<f64>,
    addendum: Option<f64>,
    clearance: Option<f64>,
    shift: Option<toml::Value>,
    helix_angle_deg: Option<f64>,
    #[serde(default)]
    find_helix_angle: bool,
    face_width: Option<f64>,
    centre_distance: Option<f64>,
    rack_withdrawal: Option<f64>,
    helix_angles_deg: Option<[f64; 2]>,
    speed: Option<f64>,
    diameter_factor: Option<f64>,
    speed_rpm: Option<f64>,
    friction: Option<f64>,
    shaft_angle_deg: Option<f64>,
    profile_points: Option<i64>,
    ratio: Option<f64>,
    at_radii: Option<Vec<Vec<f64>>>,
    rolling_radii: Option<Vec<f64>>,
    pin_radius: Option<f64>,
    tip_radius: Option<f64>,
    lobes: Option<i64>,
}

/// Runs a gear-pair scenario.
pub fn run(path: &Path, text: &str, out_dir: Option<&Path>) -> Result<Report, ScenarioError> {
    let file = path.display().to_string();
    let sc = parse(&file, text)?;
    let mut r = report(&sc, NAME);
    let panels = crate::io::plots::machine_plots::pair_panels(&r.json);
    if let Some(p) = crate::scenarios::kit::write_plot(
        out_dir,
        &format!("{}_gears", sc.name),
        &sc.name,
        &panels,
        2,
    )
    .map_err(|m| ScenarioError::new(&file, None, "plot", m))?
    {
        let _ = writeln!(r.text, "plot: {}", p.display());
    }
    Ok(r)
}

/// Parses and checks `text` (the contents of `file`).
pub fn parse(file: &str, text: &str) -> Result<PairScenario, ScenarioError> {
    let cx = Source::new(file, text);
    let f: FileSpec = toml::from_str(text).map_err(|e| cx.toml(&e))?;
    if f.pair.is_empty() && f.query.is_empty() {
        return Err(cx.top(
            "kind",
            "a gear_pair file needs at least one [[pair]] or [[query]] table",
        ));
    }
    if f.query.len() > 100 {
        return Err(cx.at(f.query[100].span(), "query", "at most 100 queries"));
    }
    if f.pair.len() > 100 {
        return Err(cx.at(f.pair[100].span(), "pair", "at most 100 pairs"));
    }
    let mut cases = Vec::new();
    for (i, s) in f.pair.iter().enumerate() {
        cases.push(case(&cx, &f, i, s)?);
    }
    let defaults = Defaults {
        pressure_angle_deg: f.pressure_angle_deg,
        addendum: f.addendum,
        clearance: f.clearance,
    };
    let mut queries = Vec::new();
    for (i, s) in f.query.iter().enumerate() {
        queries.push(crate::scenarios::gear_pair_query::read(
            &cx, i, s, defaults,
        )?);
    }
    Ok(PairScenario {
        name: f.name.clone().unwrap_or_else(|| {
            Path::new(file)
                .file_stem()
                .map_or(NAME.into(), |s| s.to_string_lossy().into_owned())
        }),
        cases,
        queries,
    })
}

/// Errors at `pair[i]`, located at its table.
struct At<'c> {
    cx: &'c Source<'c>,
    span: std::ops::Range<usize>,
    i: usize,
}

impl At<'_> {
    fn err(&self, field: &str, msg: String) -> ScenarioError {
        self.cx.field(
            self.span.clone(),
            field,
            format!("pair[{}].{field}", self.i),
            msg,
        )
    }
}

/// What every pair type shares: the module, pressure angle (degrees and radians),
/// addendum and clearance factors (each with the file's default), and profile points.
struct Common {
    module: f64,
    alpha_deg: f64,
    alpha: f64,
    ha: f64,
    c: f64,
    points: usize,
}

/// Refuses a planar pair whose tip circles do not overlap on the line of action (no
/// positive transverse contact ratio), naming the key that set the distance.
fn tips_reach(
    at: &At,
    p: &PairTable,
    spec: &crate::machines::gearing::pair::PairSpec,
) -> Result<(), ScenarioError> {
    let eps = crate::machines::gearing::pair::pair(spec).eps_alpha;
    if eps.is_nan() || eps <= 0.0 {
        let field = if p.rack_withdrawal.is_some() {
            "rack_withdrawal"
        } else if p.centre_distance.is_some() {
            "centre_distance"
        } else {
            "shift"
        };
        return Err(at.err(
            field,
            format!(
                "the tips do not reach each other: the transverse contact ratio would be \
                 {} (the tip circles do not overlap on the line of action); bring the \
                 gears closer or shift them less",
                crate::io::report::human_num(eps)
            ),
        ));
    }
    Ok(())
}

fn case(
    cx: &Source,
    f: &FileSpec,
    i: usize,
    s: &Spanned<PairTable>,
) -> Result<PairCase, ScenarioError> {
    let p = s.get_ref();
    let at = At {
        cx,
        span: s.span(),
        i,
    };
    let kind = p.kind.clone().unwrap_or_else(|| "external".into());
    let label = p.label.clone().unwrap_or_else(|| format!("pair {}", i + 1));
    let need = |key: &str, v: bool| -> Result<(), ScenarioError> {
        if v {
            Ok(())
        } else {
            Err(at.err(key, format!("is not used by pairs of type '{kind}'")))
        }
    };
    if PROFILE_TYPES.contains(&kind.as_str()) {
        return profile_case(&at, f, p, label, kind.clone());
    }
    need("rolling_radii", p.rolling_radii.is_none())?;
    need("pin_radius", p.pin_radius.is_none())?;
    need("tip_radius", p.tip_radius.is_none())?;
    need("lobes", p.lobes.is_none())?;
    let common = common(&at, f, p)?;
    need("ratio", p.ratio.is_none() || kind == "design")?;
    if kind == "design" {
        need("teeth", p.teeth.is_none())?;
        let spatial = design_case(&at, p, &common)?;
        return Ok(PairCase {
            label,
            kind,
            spec: None,
            spatial: Some(spatial),
            points: common.points,
            at_radii: Vec::new(),
            profile: None,
        });
    }
    let teeth = tooth_counts(&at, p, &kind)?;
    let planar = matches!(kind.as_str(), "external" | "internal" | "rack");
    let crossed = kind == "crossed" || kind == "crossed_rack";
    need("helix_angles_deg", p.helix_angles_deg.is_none() || crossed)?;
    need(
        "diameter_factor",
        p.diameter_factor.is_none() || kind == "worm",
    )?;
    need("speed_rpm", p.speed_rpm.is_none() || kind == "worm")?;
    need("friction", p.friction.is_none() || kind == "worm")?;
    need("speed", p.speed.is_none() || crossed)?;
    need(
        "shaft_angle_deg",
        p.shaft_angle_deg.is_none() || kind == "bevel",
    )?;
    need(
        "rack_withdrawal",
        p.rack_withdrawal.is_none() || kind == "rack",
    )?;
    need("shift", p.shift.is_none() || planar)?;
    need("helix_angle_deg", p.helix_angle_deg.is_none() || planar)?;
    need("find_helix_angle", !p.find_helix_angle || planar)?;
    need("at_radii", p.at_radii.is_none() || planar)?;
    for (k, v) in [
        ("speed", p.speed),
        ("speed_rpm", p.speed_rpm),
        ("rack_withdrawal", p.rack_withdrawal),
    ] {
        if v.is_some_and(|x| !x.is_finite()) {
            return Err(at.err(k, "not a finite number".into()));
        }
    }
    if planar {
        let spec = planar_spec(&at, p, &kind, &teeth, &common)?;
        tips_reach(&at, p, &spec)?;
        let at_radii = at_radii(&at, p, &spec)?;
        return Ok(PairCase {
            label,
            kind,
            spec: Some(spec),
            spatial: None,
            points: common.points,
            at_radii,
            profile: None,
        });
    }
    let spatial = spatial_case(&at, p, &kind, &teeth, &common)?;
    if !in_range(common.alpha_deg, 1.0, 45.0) {
        return Err(at.err("pressure_angle_deg", "must be between 1° and 45°".into()));
    }
    Ok(PairCase {
        label,
        kind,
        spec: None,
        spatial: Some(spatial),
        points: common.points,
        at_radii: Vec::new(),
        profile: None,
    })
}

/// `at_radii = [[r, …], [r, …]]` (mm), one list per gear of the pair (the pinion only for
/// a rack): each radius on the involute, from the base circle to ten times the tip radius.
fn at_radii(
    at: &At,
    p: &PairTable,
    spec: &crate::machines::gearing::pair::PairSpec,
) -> Result<Vec<Vec<f64>>, ScenarioError> {
    let Some(lists) = &p.at_radii else {
        return Ok(Vec::new());
    };
    let gears = crate::machines::gearing::pair::pair(spec).gears;
    if lists.len() > gears.len() {
        return Err(at.err(
            "at_radii",
            format!(
                "{} lists for a pair of {} gear(s): give one list of radii per gear",
                lists.len(),
                gears.len()
            ),
        ));
    }
    for (k, (list, g)) in lists.iter().zip(&gears).enumerate() {
        if list.len() > 100 {
            return Err(at.err("at_radii", format!("gear {}: at most 100 radii", k + 1)));
        }
        let hi = 10.0 * g.ra.max(g.r);
        if let Some(r) = list.iter().find(|r| !(**r >= g.rb && **r <= hi)) {
            return Err(at.err(
                "at_radii",
                format!(
                    "gear {}: radius {} mm is outside {:.4} … {:.4} mm (the involute starts \
                     on the base circle r_b = {:.4} mm)",
                    k + 1,
                    crate::io::report::human_num(*r),
                    g.rb,
                    hi,
                    g.rb
                ),
            ));
        }
    }
    Ok(lists.clone())
}

/// The module (here or at the top), the pressure angle, addendum and clearance factors
/// (defaults 20°, 1, 0.25) and the profile points (default 12).
fn common(at: &At, f: &FileSpec, p: &PairTable) -> Result<Common, ScenarioError> {
    let module = p
        .module
        .or(f.module)
        .ok_or_else(|| at.err("module", "a module is needed (here or at the top)".into()))?;
    if !in_range(module, 1e-6, 1e6) {
        return Err(at.err(
            "module",
            format!("must be a positive module (mm), got {module}"),
        ));
    }
    let alpha_deg = p
        .pressure_angle_deg
        .or(f.pressure_angle_deg)
        .unwrap_or(20.0);
    let points = profile_points(at, p)?;
    Ok(Common {
        module,
        alpha_deg,
        alpha: alpha_deg.to_radians(),
        ha: p.addendum.or(f.addendum).unwrap_or(1.0),
        c: p.clearance.or(f.clearance).unwrap_or(0.25),
        points,
    })
}

/// `profile_points` (default 12).
fn profile_points(at: &At, p: &PairTable) -> Result<usize, ScenarioError> {
    match p.profile_points {
        None => Ok(12),
        Some(n) if (2..=1000).contains(&n) => Ok(n as usize),
        Some(n) => Err(at.err("profile_points", format!("expected 2 … 1000, got {n}"))),
    }
}

/// A `cycloidal`, `pin` or `roots` pair ([`crate::scenarios::gear_pair_profiles`]): the
/// involute-only keys are refused here, the rest read there.
fn profile_case(
    at: &At,
    f: &FileSpec,
    p: &PairTable,
    label: String,
    kind: String,
) -> Result<PairCase, ScenarioError> {
    let involute_only = [
        ("shift", p.shift.is_some()),
        ("helix_angle_deg", p.helix_angle_deg.is_some()),
        ("find_helix_angle", p.find_helix_angle),
        ("at_radii", p.at_radii.is_some()),
        ("rack_withdrawal", p.rack_withdrawal.is_some()),
        ("helix_angles_deg", p.helix_angles_deg.is_some()),
        ("diameter_factor", p.diameter_factor.is_some()),
        ("friction", p.friction.is_some()),
        ("speed", p.speed.is_some()),
        ("shaft_angle_deg", p.shaft_angle_deg.is_some()),
        ("ratio", p.ratio.is_some()),
        ("pressure_angle_deg", p.pressure_angle_deg.is_some()),
        ("module", p.module.is_some() && kind == "roots"),
        ("addendum", p.addendum.is_some() && kind != "cycloidal"),
        ("clearance", p.clearance.is_some() && kind != "cycloidal"),
    ];
    if let Some((key, _)) = involute_only.iter().find(|(_, present)| *present) {
        return Err(at.err(key, format!("is not used by pairs of type '{kind}'")));
    }
    let keys = ProfileKeys {
        kind: kind.clone(),
        module: p.module.or(f.module),
        teeth: p.teeth.clone(),
        addendum: p.addendum.or(f.addendum),
        clearance: p.clearance.or(f.clearance),
        rolling_radii: p.rolling_radii.clone(),
        pin_radius: p.pin_radius,
        tip_radius: p.tip_radius,
        lobes: p.lobes,
        centre_distance: p.centre_distance,
        face_width: p.face_width,
        speed_rpm: p.speed_rpm,
    };
    let profile = read(&keys, &|k, m| at.err(k, m))?;
    Ok(PairCase {
        label,
        kind,
        spec: None,
        spatial: None,
        points: profile_points(at, p)?,
        at_radii: Vec::new(),
        profile: Some(profile),
    })
}

/// A `design` pair: tooth counts chosen for a centre distance and a speed ratio.
fn design_case(at: &At, p: &PairTable, cm: &Common) -> Result<SpatialCase, ScenarioError> {
    let Common {
        module,
        alpha_deg,
        alpha,
        ha,
        c,
        ..
    } = *cm;
    let a = p.centre_distance.ok_or_else(|| {
        at.err(
            "centre_distance",
            "missing: the design starts from the centre distance".into(),
        )
    })?;
    let i = p
        .ratio
        .ok_or_else(|| at.err("ratio", "missing: the speed ratio z2/z1 ≥ 1".into()))?;
    if !in_range(i, 1.0, 100.0) {
        return Err(at.err("ratio", format!("must be in [1, 100], got {i}")));
    }
    if !in_range(a, 3.0 * module, 1e7) {
        return Err(at.err(
            "centre_distance",
            "must be a positive distance of at least 3 modules (mm)".into(),
        ));
    }
    if !in_range(alpha_deg, 5.0, 45.0) {
        return Err(at.err("pressure_angle_deg", "must be between 5° and 45°".into()));
    }
    if crate::machines::gearing::pair_design::design(a, module, alpha, i, ha, c).is_none() {
        return Err(at.err(
            "centre_distance",
            "no pair fits: the standard centre distance of the tooth counts exceeds A".into(),
        ));
    }
    Ok(SpatialCase::Design {
        a,
        m: module,
        alpha,
        i,
        ha,
        c,
    })
}

/// The tooth counts: whole numbers 1 … 100000, one for a rack pinion, two otherwise.
fn tooth_counts(at: &At, p: &PairTable, kind: &str) -> Result<Vec<u32>, ScenarioError> {
    let teeth: Vec<u32> = match &p.teeth {
        Some(t) if t.iter().all(|z| (1..=100_000).contains(z)) => {
            t.iter().map(|&z| z as u32).collect()
        }
        Some(_) => {
            return Err(at.err(
                "teeth",
                "tooth counts must be whole numbers 1 … 100000".into(),
            ))
        }
        None => return Err(at.err("teeth", "missing: teeth = [z1, z2]".into())),
    };
    let n_teeth = if kind == "rack" || kind == "crossed_rack" {
        1
    } else {
        2
    };
    if teeth.len() != n_teeth {
        return Err(at.err(
            "teeth",
            format!(
                "a '{kind}' pair takes {n_teeth} tooth count{}",
                if n_teeth == 1 { "" } else { "s" }
            ),
        ));
    }
    Ok(teeth)
}

/// An external, internal or rack pair: profile shifts (given, or the least that avoids
/// undercut), the helix angle (given, or found from the centre distance).
fn planar_spec(
    at: &At,
    p: &PairTable,
    kind: &str,
    teeth: &[u32],
    cm: &Common,
) -> Result<PairSpec, ScenarioError> {
    let Common {
        module,
        alpha,
        ha,
        c,
        ..
    } = *cm;
    let pk = match kind {
        "internal" => PairKind::Internal,
        "rack" => PairKind::Rack,
        _ => PairKind::External,
    };
    let z2 = if pk == PairKind::Rack { 0 } else { teeth[1] };
    let shift = match &p.shift {
        None => [0.0, 0.0],
        Some(toml::Value::String(s)) if s == "no_undercut" => {
            let zmin = crate::machines::gearing::pair::z_min_book(
                ha,
                alpha,
                p.helix_angle_deg.unwrap_or(0.0).to_radians(),
            );
            [
                (zmin - teeth[0] as f64) / zmin,
                if pk == PairKind::External {
                    (zmin - z2 as f64) / zmin
                } else {
                    0.0
                },
            ]
        }
        Some(toml::Value::Array(a)) if a.len() == 2 || (pk == PairKind::Rack && a.len() == 1) => {
            let mut x = [0.0; 2];
            for (k, v) in a.iter().enumerate() {
                x[k] = v
                    .as_float()
                    .or(v.as_integer().map(|n| n as f64))
                    .ok_or_else(|| at.err("shift", "expected numbers".into()))?;
            }
            x
        }
        Some(_) => {
            return Err(at.err(
                "shift",
                "expected [x1, x2] ([x] for a rack) or \"no_undercut\"".into(),
            ))
        }
    };
    let mut helix = p.helix_angle_deg.unwrap_or(0.0).to_radians();
    if p.find_helix_angle {
        let a = p
            .centre_distance
            .ok_or_else(|| at.err("find_helix_angle", "needs a centre_distance".into()))?;
        if pk != PairKind::External || p.helix_angle_deg.is_some() {
            return Err(at.err(
                "find_helix_angle",
                "only for an external pair without helix_angle_deg".into(),
            ));
        }
        let cosb = module * (teeth[0] + teeth[1]) as f64 / (2.0 * a);
        if !(cosb > 0.0 && cosb <= 1.0) {
            return Err(at.err(
                "centre_distance",
                format!("no helix angle fits: cos β = m (z1 + z2)/(2A) = {cosb:.4} > 1"),
            ));
        }
        helix = cosb.acos();
    }
    let mut x = shift;
    if pk == PairKind::Rack {
        x[1] = p.rack_withdrawal.unwrap_or(0.0) / module;
    }
    let spec = PairSpec {
        kind: pk,
        module,
        teeth: [teeth[0], z2],
        pressure_angle: alpha,
        addendum: ha,
        clearance: c,
        shift: x,
        helix,
        face_width: p.face_width,
        centre_distance: if p.find_helix_angle {
            None
        } else {
            p.centre_distance
        },
    };
    validate(&spec).map_err(|(k, m)| at.err(k, m))?;
    Ok(spec)
}

/// A crossed helical, worm or bevel pair.
fn spatial_case(
    at: &At,
    p: &PairTable,
    kind: &str,
    teeth: &[u32],
    cm: &Common,
) -> Result<SpatialCase, ScenarioError> {
    let Common {
        module,
        alpha,
        ha,
        c,
        ..
    } = *cm;
    let err = |field: &str, msg: String| at.err(field, msg);
    let spatial = match kind {
        "crossed" => {
            let b = p.helix_angles_deg.ok_or_else(|| err("helix_angles_deg", "missing: [β1, β2] in degrees".into()))?;
            if b.iter().any(|x| !in_range(x.abs(), 0.0, 85.0)) {
                return Err(err("helix_angles_deg", "each must be within ±85°".into()));
            }
            SpatialCase::Crossed { mn: module, z: [teeth[0], teeth[1]], beta: [b[0].to_radians(), b[1].to_radians()], omega1: p.speed }
        }
        "crossed_rack" => {
            let b = p.helix_angles_deg.ok_or_else(|| err("helix_angles_deg", "missing: [β1 (gear), β2 (rack teeth)] in degrees".into()))?;
            if b.iter().any(|x| !in_range(x.abs(), 0.0, 85.0)) {
                return Err(err("helix_angles_deg", "each must be within ±85°".into()));
            }
            if let Some(w) = p.speed {
                if !in_range(w.abs(), 0.0, 1e6) {
                    return Err(err("speed", "must be a finite speed (rad/s)".into()));
                }
            }
            SpatialCase::CrossedRack { mn: module, z: teeth[0], beta: [b[0].to_radians(), b[1].to_radians()], omega1: p.speed }
        }
        "worm" => {
            let q = p.diameter_factor.ok_or_else(|| err("diameter_factor", "missing: q = d1/m".into()))?;
            if !in_range(q, 0.5, 1000.0) {
                return Err(err("diameter_factor", "must be in [0.5, 1000]".into()));
            }
            if let Some(fr) = p.friction {
                if !in_range(fr, 0.0, 2.0) {
                    return Err(err("friction", "must be in [0, 2]".into()));
                }
            }
            SpatialCase::Worm { m: module, starts: teeth[0], q, z2: teeth[1], alpha, n1: p.speed_rpm, f: p.friction }
        }
        "bevel" => {
            let sigma = p.shaft_angle_deg.unwrap_or(90.0);
            if !in_range(sigma, 1.0, 179.0) {
                return Err(err("shaft_angle_deg", "must be in [1°, 179°]".into()));
            }
            SpatialCase::Bevel { m: module, z: [teeth[0], teeth[1]], sigma: sigma.to_radians(), alpha, ha, c }
        }
        other => {
            return Err(err(
                "type",
                format!("unknown pair type '{other}' (expected external, internal, rack, crossed, crossed_rack, worm, bevel, design, cycloidal, pin or roots)"),
            ))
        }
    };
    Ok(spatial)
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "gear_pair";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, opts| run(path, text, opts.out_dir.as_deref()),
};
