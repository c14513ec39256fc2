//! The non-involute `[[pair]]` types of `kind = "gear_pair"` files (format in
//! `docs/machines.md`): `cycloidal` ([`crate::machines::gearing::cycloidal`]), `pin`
//! ([`crate::machines::gearing::pin_gear`]) and `roots`
//! ([`crate::machines::gearing::roots`]): their keys, checks, JSON and text lines.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::report::human_num;
use crate::machines::gearing::cycloidal::{check, cycloidal_flank, cycloidal_pair, CycloidalSpec};
use crate::machines::gearing::pin_gear::{pin_gear_flank, pin_outline, pin_pair, PinGearSpec};
use crate::machines::gearing::roots::{roots_flank, roots_pair, RootsSpec};
use serde_json::{json, Value};
use std::fmt::Write;

/// The pair types this module reads.
pub const PROFILE_TYPES: [&str; 3] = ["cycloidal", "pin", "roots"];

/// A non-involute pair, checked.
#[derive(Clone, Debug, PartialEq)]
pub enum ProfileCase {
    /// Cycloidal teeth.
    Cycloidal(CycloidalSpec),
    /// Pin gearing.
    Pin(PinGearSpec),
    /// Roots rotors.
    Roots(RootsSpec),
}

/// The keys these types read, as written (`None` where absent); the module, addendum and
/// clearance already carry the file's defaults.
#[derive(Clone, Debug, Default)]
pub struct ProfileKeys {
    /// `type`.
    pub kind: String,
    /// `module` (here or at the top).
    pub module: Option<f64>,
    /// `teeth`.
    pub teeth: Option<Vec<i64>>,
    /// `addendum` (here or at the top).
    pub addendum: Option<f64>,
    /// `clearance` (here or at the top).
    pub clearance: Option<f64>,
    /// `rolling_radii`.
    pub rolling_radii: Option<Vec<f64>>,
    /// `pin_radius`.
    pub pin_radius: Option<f64>,
    /// `tip_radius`.
    pub tip_radius: Option<f64>,
    /// `lobes`.
    pub lobes: Option<i64>,
    /// `centre_distance`.
    pub centre_distance: Option<f64>,
    /// `face_width`.
    pub face_width: Option<f64>,
    /// `speed_rpm`.
    pub speed_rpm: Option<f64>,
}

type Err<'e> = &'e dyn Fn(&str, String) -> ScenarioError;

fn module(k: &ProfileKeys, err: Err) -> Result<f64, ScenarioError> {
    let m = k
        .module
        .ok_or_else(|| err("module", "a module is needed (here or at the top)".into()))?;
    if !(m > 1e-6 && m <= 1e6) {
        return Err(err(
            "module",
            format!("must be a positive module (mm), got {m}"),
        ));
    }
    Ok(m)
}

fn two_teeth(k: &ProfileKeys, err: Err, what: &str) -> Result<[u32; 2], ScenarioError> {
    match k.teeth.as_deref() {
        Some([a, b]) if (1..=100_000).contains(a) && (1..=100_000).contains(b) => {
            Ok([*a as u32, *b as u32])
        }
        _ => Err(err(
            "teeth",
            format!("expected {what}, whole numbers 1 … 100000"),
        )),
    }
}

/// Reads a `cycloidal`, `pin` or `roots` pair; `err` locates an error at the pair's key.
pub fn read(k: &ProfileKeys, err: Err) -> Result<ProfileCase, ScenarioError> {
    let refuse = |key: &str, present: bool| -> Result<(), ScenarioError> {
        if present {
            Err(err(
                key,
                format!("is not used by pairs of type '{}'", k.kind),
            ))
        } else {
            Ok(())
        }
    };
    refuse(
        "rolling_radii",
        k.rolling_radii.is_some() && k.kind != "cycloidal",
    )?;
    refuse("pin_radius", k.pin_radius.is_some() && k.kind != "pin")?;
    refuse("tip_radius", k.tip_radius.is_some() && k.kind != "pin")?;
    refuse("lobes", k.lobes.is_some() && k.kind != "roots")?;
    refuse(
        "centre_distance",
        k.centre_distance.is_some() && k.kind != "roots",
    )?;
    refuse("face_width", k.face_width.is_some() && k.kind != "roots")?;
    refuse("speed_rpm", k.speed_rpm.is_some() && k.kind != "roots")?;
    let checked = |r: Result<(), (&'static str, String)>| r.map_err(|(key, m)| err(key, m));
    match k.kind.as_str() {
        "cycloidal" => {
            let module = module(k, err)?;
            let teeth = two_teeth(k, err, "teeth = [z1, z2]")?;
            let rolling = match k.rolling_radii.as_deref() {
                None => teeth.map(|z| module * z as f64 / 4.0),
                Some([a, b]) if a.is_finite() && b.is_finite() => [*a, *b],
                Some(_) => {
                    return Err(err(
                        "rolling_radii",
                        "expected [ρ1, ρ2] in mm (ρ1 rolls inside gear 1)".into(),
                    ))
                }
            };
            let spec = CycloidalSpec {
                module,
                teeth,
                rolling,
                addendum: k.addendum.unwrap_or(1.0),
                clearance: k.clearance.unwrap_or(0.25),
            };
            checked(check(&spec))?;
            Ok(ProfileCase::Cycloidal(spec))
        }
        "pin" => {
            let module = module(k, err)?;
            let teeth = two_teeth(k, err, "teeth = [pins z1, gear teeth z2]")?;
            let pin_radius = k
                .pin_radius
                .ok_or_else(|| err("pin_radius", "missing: the pins' radius r_c (mm)".into()))?;
            if k.tip_radius.is_some_and(|x| !x.is_finite()) {
                return Err(err("tip_radius", "not a finite number".into()));
            }
            let spec = PinGearSpec {
                module,
                teeth,
                pin_radius,
                tip_radius: k.tip_radius,
            };
            checked(crate::machines::gearing::pin_gear::check(&spec))?;
            Ok(ProfileCase::Pin(spec))
        }
        _ => {
            refuse("teeth", k.teeth.is_some())?;
            let lobes = k
                .lobes
                .ok_or_else(|| err("lobes", "missing: lobes per rotor".into()))?;
            let centre_distance = k.centre_distance.ok_or_else(|| {
                err(
                    "centre_distance",
                    "missing: the rotors' centre distance A (mm)".into(),
                )
            })?;
            let spec = RootsSpec {
                lobes: lobes.clamp(0, 1000) as u32,
                centre_distance,
                length: k.face_width,
                speed_rpm: k.speed_rpm,
            };
            checked(crate::machines::gearing::roots::check(&spec))?;
            Ok(ProfileCase::Roots(spec))
        }
    }
}

/// A symmetric tooth in the involute pairs' layout: the left flank (mirrored) from tip
/// to root, then the right flank from root to tip.
pub fn tooth(right: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = right.iter().rev().map(|p| [-p[0], p[1]]).collect();
    out.extend_from_slice(right);
    out
}

fn deg(x: f64) -> f64 {
    x.to_degrees()
}

fn opt(x: Option<f64>) -> Value {
    x.map_or(Value::Null, |v| json!(v))
}

/// The JSON of one pair (keys in `docs/machines.md`) and its text lines.
pub fn profile_json(label: &str, c: &ProfileCase, points: usize, text: &mut String) -> Value {
    match c {
        ProfileCase::Cycloidal(s) => cycloidal_json(label, s, points, text),
        ProfileCase::Pin(s) => pin_json(label, s, points, text),
        ProfileCase::Roots(s) => roots_json(label, s, points, text),
    }
}

fn cycloidal_json(label: &str, s: &CycloidalSpec, points: usize, text: &mut String) -> Value {
    let g = cycloidal_pair(s);
    let _ = writeln!(
        text,
        "  {label}: cycloidal z = {}/{}, m = {}, ρ = {}/{} mm: A = {}, arcs of action {} + {} \
         mm, ε = {}, largest pressure angles {}°/{}°, flanks {}/{}",
        s.teeth[0],
        s.teeth[1],
        human_num(s.module),
        human_num(s.rolling[0]),
        human_num(s.rolling[1]),
        human_num(g.centre_distance),
        human_num(g.arcs[0]),
        human_num(g.arcs[1]),
        human_num(g.contact_ratio),
        human_num(deg(g.max_pressure_angles[0])),
        human_num(deg(g.max_pressure_angles[1])),
        g.gears[0].flank.name(),
        g.gears[1].flank.name()
    );
    let gears: Vec<Value> = g
        .gears
        .iter()
        .map(|gk| {
            json!({
                "teeth": gk.teeth,
                "pitch_radius": gk.r,
                "tip_radius": gk.ra,
                "root_radius": gk.rf,
                "rolling_radius_flank": gk.rho_flank,
                "rolling_radius_face": gk.rho_face,
                "flank": gk.flank.name(),
                "thickness_pitch": gk.s,
                "thickness_tip": gk.s_tip,
                "lowest_contact_radius": gk.lowest_contact,
                "face_limit": gk.face_limit,
                "tooth_profile": tooth(&cycloidal_flank(gk, points)),
            })
        })
        .collect();
    json!({
        "label": label,
        "type": "cycloidal",
        "module": s.module,
        "teeth": s.teeth,
        "addendum": s.addendum,
        "clearance": s.clearance,
        "rolling_radii": s.rolling,
        "centre_distance": g.centre_distance,
        "pitch": g.pitch,
        "rolling_angles_deg": g.rolling_angles.map(deg),
        "arcs_of_action": g.arcs,
        "contact_ratio": g.contact_ratio,
        "max_pressure_angles_deg": g.max_pressure_angles.map(deg),
        "gears": gears,
    })
}

fn pin_json(label: &str, s: &PinGearSpec, points: usize, text: &mut String) -> Value {
    let g = pin_pair(s);
    let _ = writeln!(
        text,
        "  {label}: pin gearing z = {} pins/{} teeth, m = {}, r_c = {} mm: A = {}, pointed tip \
         {} mm (tip {}), working flank from {} mm, ε = {}, pressure angle {}° … {}°",
        s.teeth[0],
        s.teeth[1],
        human_num(s.module),
        human_num(s.pin_radius),
        human_num(g.centre_distance),
        human_num(g.pointed_tip_radius),
        human_num(g.tip_radius),
        human_num(g.working_start_radius),
        human_num(g.contact_ratio),
        human_num(deg(g.pressure_angles[0])),
        human_num(deg(g.pressure_angles[1]))
    );
    json!({
        "label": label,
        "type": "pin",
        "module": s.module,
        "teeth": s.teeth,
        "pin_radius": s.pin_radius,
        "pitch": g.pitch,
        "centre_distance": g.centre_distance,
        "contact_angles_deg": g.contact_angles.map(deg),
        "contact_ratio": g.contact_ratio,
        "pressure_angles_deg": g.pressure_angles.map(deg),
        "gears": [
            {
                "teeth": s.teeth[0],
                "pitch_radius": g.r[0],
                "pin_radius": s.pin_radius,
                "tooth_profile": tooth(&pin_outline(&g, s.pin_radius, points)),
            },
            {
                "teeth": s.teeth[1],
                "pitch_radius": g.r[1],
                "root_radius": g.root_radius,
                "tip_radius": g.tip_radius,
                "pointed_tip_radius": g.pointed_tip_radius,
                "thickness_pitch": g.thickness_pitch,
                "thickness_tip": g.thickness_tip,
                "working_start_radius": g.working_start_radius,
                "tooth_profile": tooth(&pin_gear_flank(s, &g, points)),
            }
        ],
    })
}

fn roots_json(label: &str, s: &RootsSpec, points: usize, text: &mut String) -> Value {
    let g = roots_pair(s);
    let _ = writeln!(
        text,
        "  {label}: Roots rotors, {} lobes, A = {} mm: R = {}, r = {}, tip {}, root {} mm, \
         rotor area {} mm², pocket {} mm²{}{}",
        s.lobes,
        human_num(s.centre_distance),
        human_num(g.pitch_radius),
        human_num(g.rolling_radius),
        human_num(g.tip_radius),
        human_num(g.root_radius),
        human_num(g.rotor_area),
        human_num(g.pocket_area),
        g.displacement.map_or(String::new(), |v| format!(
            ", displacement {} l/rev",
            human_num(v * 1e-6)
        )),
        g.flow_m3_per_min
            .map_or(String::new(), |q| format!(", flow {} m³/min", human_num(q)))
    );
    let rotor = json!({
        "teeth": s.lobes,
        "pitch_radius": g.pitch_radius,
        "tip_radius": g.tip_radius,
        "root_radius": g.root_radius,
        "tooth_profile": tooth(&roots_flank(&g, points)),
    });
    json!({
        "label": label,
        "type": "roots",
        "lobes": s.lobes,
        "centre_distance": s.centre_distance,
        "pitch_radius": g.pitch_radius,
        "rolling_radius": g.rolling_radius,
        "tip_radius": g.tip_radius,
        "root_radius": g.root_radius,
        "rotor_area": g.rotor_area,
        "bore_area": g.bore_area,
        "pocket_area": g.pocket_area,
        "fill_ratio": g.fill_ratio,
        "length": opt(s.length),
        "displacement": opt(g.displacement),
        "displacement_litres": opt(g.displacement.map(|v| v * 1e-6)),
        "speed_rpm": opt(s.speed_rpm),
        "flow_m3_per_min": opt(g.flow_m3_per_min),
        "gears": [rotor.clone(), rotor],
    })
}
