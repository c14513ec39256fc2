//! `kind = "gear_train"` scenario files (format in `docs/machines.md`): reads the gears,
//! carriers, meshes, inputs, torques and Willis queries with their spans, builds a
//! [`GearTrain`], and maps every [`TrainError`] back to `file:line: key: message`.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::report::Report;
use crate::machines::gearing::assembly::{planet_checks, resolve_teeth};
use crate::machines::gearing::train::{
    Element, Gear, GearTrain, Mesh, MeshKind, TrainBody, TrainError,
};
use crate::scenarios::gear_train_report::{report, Query, TrainScenario};
use crate::scenarios::gear_train_selection::{SelectionScenario, SelectionSpec};
use crate::scenarios::source::{in_range, Source};
use serde::Deserialize;
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
    speed_unit: Option<Spanned<String>>,
    module: Option<Spanned<f64>>,
    #[serde(default)]
    profile_shifted: bool,
    #[serde(default)]
    coaxial: Vec<Spanned<Vec<String>>>,
    output: Option<Spanned<String>>,
    mesh_efficiency: Option<Spanned<f64>>,
    #[serde(default)]
    gear: Vec<Spanned<GearSpec>>,
    #[serde(default)]
    carrier: Vec<Spanned<CarrierSpec>>,
    #[serde(default)]
    mesh: Vec<Spanned<MeshSpec>>,
    #[serde(default)]
    input: Vec<Spanned<InputSpec>>,
    #[serde(default)]
    torque: Vec<Spanned<TorqueSpec>>,
    #[serde(default)]
    willis: Vec<Spanned<WillisSpec>>,
    selection: Option<Spanned<SelectionSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GearSpec {
    name: String,
    teeth: Option<i64>,
    body: Option<String>,
    carrier: Option<String>,
    #[serde(default)]
    internal: bool,
    #[serde(default)]
    fixed: bool,
    module: Option<f64>,
    #[serde(default)]
    inertia: f64,
    #[serde(default)]
    mass: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CarrierSpec {
    name: String,
    #[serde(default)]
    fixed: bool,
    planets: Option<i64>,
    #[serde(default)]
    inertia: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshSpec {
    gears: [String; 2],
    kind: Option<String>,
    sign: Option<i64>,
    efficiency: Option<f64>,
    centre_distance: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InputSpec {
    member: String,
    speed: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TorqueSpec {
    member: String,
    torque: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WillisSpec {
    from: String,
    to: String,
    carrier: String,
}

/// Most gears in a train (exact arithmetic on tooth-count products).
pub const MAX_GEARS: usize = 64;

/// Runs a gear-train scenario: [`parse`], then the report (or a `[selection]` file's
/// tooth counts).
pub fn run(path: &Path, text: &str) -> Result<Report, ScenarioError> {
    if let Some(sel) = selection_file(&path.display().to_string(), text)? {
        return Ok(crate::scenarios::gear_train_selection::report(&sel, NAME));
    }
    let sc = parse(&path.display().to_string(), text)?;
    report(&sc, NAME).map_err(|e| locate_plain(&path.display().to_string(), text, &e))
}

/// A `[selection]` file (tooth counts for a required ratio), solved; `None` for a train
/// description. The train's tables are refused next to `[selection]`.
pub fn selection_file(file: &str, text: &str) -> Result<Option<SelectionScenario>, ScenarioError> {
    let cx = Source::new(file, text);
    let f: FileSpec = toml::from_str(text).map_err(|e| cx.toml(&e))?;
    let Some(sel) = &f.selection else {
        return Ok(None);
    };
    let train_keys = [
        ("gear", !f.gear.is_empty()),
        ("carrier", !f.carrier.is_empty()),
        ("mesh", !f.mesh.is_empty()),
        ("input", !f.input.is_empty()),
        ("torque", !f.torque.is_empty()),
        ("willis", !f.willis.is_empty()),
        ("coaxial", !f.coaxial.is_empty()),
        ("output", f.output.is_some()),
        ("module", f.module.is_some()),
        ("mesh_efficiency", f.mesh_efficiency.is_some()),
        ("speed_unit", f.speed_unit.is_some()),
    ];
    if let Some((key, _)) = train_keys.iter().find(|(_, present)| *present) {
        let msg = format!(
            "a [selection] file chooses tooth counts and describes no train: remove `{key}`"
        );
        // Tables ([[gear]], …) are found by their header, plain keys by their line.
        let by_header = cx.section(key, msg.clone());
        return Err(if by_header.line.is_some() {
            by_header
        } else {
            cx.top(key, msg)
        });
    }
    let name = f.name.clone().unwrap_or_else(|| {
        Path::new(file)
            .file_stem()
            .map_or(NAME.into(), |s| s.to_string_lossy().into_owned())
    });
    crate::scenarios::gear_train_selection::read(&cx, name, sel.span(), sel.get_ref()).map(Some)
}

/// A gear-train file as an arm joint's transmission
/// ([`crate::scenarios::gear_train_report::Transmission`]): the file must name its `output` and
/// have one degree of freedom.
pub fn transmission_from_file(
    path: &Path,
) -> Result<crate::scenarios::gear_train_report::Transmission, ScenarioError> {
    let file = path.display().to_string();
    let text = crate::core::files::read_input_string(path)
        .map_err(|e| ScenarioError::new(&file, None, "file", format!("cannot read: {e}")))?;
    let kind = toml::from_str::<toml::Table>(&text)
        .ok()
        .and_then(|t| t.get("kind").and_then(|k| k.as_str().map(str::to_string)));
    if kind.as_deref() != Some(NAME) {
        return Err(ScenarioError::new(
            &file,
            None,
            "kind",
            "a joint's transmission must be a kind = \"gear_train\" file",
        ));
    }
    let sc = parse(&file, &text)?;
    let Some(o) = sc.output else {
        return Err(ScenarioError::new(
            &file,
            None,
            "output",
            "a joint's gear train must name its output member (the joint side)",
        ));
    };
    if sc.speeds.inputs.len() != 1 {
        return Err(ScenarioError::new(
            &file,
            None,
            "input",
            "a joint's gear train needs one input (the motor): one degree of freedom",
        ));
    }
    crate::scenarios::gear_train_report::transmission_of(&sc, o)
        .map_err(|e| locate_plain(&file, &text, &e))
}

/// An error found while reporting (no spans at hand): at the top of the file.
fn locate_plain(file: &str, _text: &str, e: &TrainError) -> ScenarioError {
    ScenarioError::new(file, None, e.field, e.message.clone())
}

/// The `[[input]]` speeds and the `[[torque]]` loads, each on a member of the train (a
/// member gets one input; inputs and fixed members take no given torque).
#[allow(clippy::type_complexity)]
fn inputs_and_torques(
    cx: &Source,
    f: &FileSpec,
    train: &GearTrain,
) -> Result<(Vec<(usize, f64)>, Vec<(usize, f64)>), ScenarioError> {
    let member = |name: &str, span, key: String| {
        train.body(name).ok_or_else(|| {
            cx.field(
                span,
                "member",
                key,
                format!("'{name}' is not a body or carrier of the train"),
            )
        })
    };
    let mut inputs = Vec::new();
    for (i, s) in f.input.iter().enumerate() {
        let b = member(&s.get_ref().member, s.span(), format!("input[{i}].member"))?;
        let v = s.get_ref().speed;
        if !v.is_finite() || inputs.iter().any(|&(c, _)| c == b) {
            return Err(cx.field(
                s.span(),
                "speed",
                format!("input[{i}].speed"),
                "must be a finite speed, one per member",
            ));
        }
        inputs.push((b, v));
    }
    let mut torques = Vec::new();
    for (i, s) in f.torque.iter().enumerate() {
        let b = member(&s.get_ref().member, s.span(), format!("torque[{i}].member"))?;
        if inputs.iter().any(|&(c, _)| c == b) || train.bodies[b].fixed {
            return Err(cx.field(
                s.span(),
                "member",
                format!("torque[{i}].member"),
                "an input or fixed member's torque is solved, not given: load another member",
            ));
        }
        if !s.get_ref().torque.is_finite() {
            return Err(cx.field(
                s.span(),
                "torque",
                format!("torque[{i}].torque"),
                "not a finite number",
            ));
        }
        torques.push((b, s.get_ref().torque));
    }
    Ok((inputs, torques))
}

/// The `[[willis]]` queries: from, to and a carrier of the train.
fn willis_queries(
    cx: &Source,
    f: &FileSpec,
    train: &GearTrain,
) -> Result<Vec<Query>, ScenarioError> {
    let mut willis = Vec::new();
    for (i, s) in f.willis.iter().enumerate() {
        let w = s.get_ref();
        let mut ids = [0; 3];
        for (k, (name, field)) in [(&w.from, "from"), (&w.to, "to"), (&w.carrier, "carrier")]
            .into_iter()
            .enumerate()
        {
            ids[k] = train.body(name).ok_or_else(|| {
                cx.field(
                    s.span(),
                    field,
                    format!("willis[{i}].{field}"),
                    format!("'{name}' is not a body or carrier"),
                )
            })?;
        }
        if !train.bodies[ids[2]].is_carrier {
            return Err(cx.field(
                s.span(),
                "carrier",
                format!("willis[{i}].carrier"),
                format!("'{}' is not a carrier", w.carrier),
            ));
        }
        willis.push(Query { ids, index: i });
    }
    Ok(willis)
}

/// The speed unit (`rpm` by default) and the default mesh efficiency (1), with the
/// module checked when given.
fn units(cx: &Source, f: &FileSpec) -> Result<(String, f64), ScenarioError> {
    let unit = match &f.speed_unit {
        None => "rpm".to_string(),
        Some(u) if u.get_ref() == "rpm" || u.get_ref() == "rad/s" => u.get_ref().clone(),
        Some(u) => {
            return Err(cx.at(
                u.span(),
                "speed_unit",
                format!("expected \"rpm\" or \"rad/s\", got \"{}\"", u.get_ref()),
            ))
        }
    };
    if let Some(m) = &f.module {
        if !in_range(*m.get_ref(), 1e-6, 1e6) {
            return Err(cx.at(m.span(), "module", "must be a positive module (mm)"));
        }
    }
    let default_eta = match &f.mesh_efficiency {
        Some(e) if !in_range(*e.get_ref(), 1e-6, 1.0) => {
            return Err(cx.at(e.span(), "mesh_efficiency", "must be in (0, 1]"))
        }
        Some(e) => *e.get_ref(),
        None => 1.0,
    };
    Ok((unit, default_eta))
}

/// The `coaxial` groups as body indices.
fn coaxial_groups(
    cx: &Source,
    f: &FileSpec,
    train: &GearTrain,
) -> Result<Vec<Vec<usize>>, ScenarioError> {
    let mut groups = Vec::new();
    for (i, g) in f.coaxial.iter().enumerate() {
        let mut group = Vec::new();
        for n in g.get_ref() {
            let b = train.body(n).ok_or_else(|| {
                cx.at(
                    g.span(),
                    format!("coaxial[{i}]"),
                    format!("'{n}' is not a body or carrier"),
                )
            })?;
            group.push(b);
        }
        groups.push(group);
    }
    Ok(groups)
}

/// Parses and checks `text` (the contents of `file`): the structure, tooth counts,
/// coaxiality, assembly, mobility and the inputs.
pub fn parse(file: &str, text: &str) -> Result<TrainScenario, ScenarioError> {
    let cx = Source::new(file, text);
    let f: FileSpec = toml::from_str(text).map_err(|e| cx.toml(&e))?;
    let locate = |e: TrainError| -> ScenarioError {
        let (table, i, span) = match e.element {
            Element::Gear(i) => ("gear", i, f.gear.get(i).map(|s| s.span())),
            Element::Carrier(i) => ("carrier", i, f.carrier.get(i).map(|s| s.span())),
            Element::Mesh(i) => ("mesh", i, f.mesh.get(i).map(|s| s.span())),
            Element::Input(i) => ("input", i, f.input.get(i).map(|s| s.span())),
            Element::Torque(i) => ("torque", i, f.torque.get(i).map(|s| s.span())),
            Element::Train => return cx.top(e.field, e.message),
        };
        match span {
            Some(sp) => cx.field(sp, e.field, format!("{table}[{i}].{}", e.field), e.message),
            None => cx.top(e.field, e.message),
        }
    };
    let (unit, default_eta) = units(&cx, &f)?;
    if f.selection.is_some() {
        return Err(cx.top(
            "selection",
            "a [selection] file chooses tooth counts; it is not a train to run or drive",
        ));
    }
    if f.gear.is_empty() {
        return Err(cx.top("kind", "a gear train needs [[gear]] tables"));
    }
    if f.gear.len() > MAX_GEARS {
        return Err(locate(TrainError::new(
            Element::Gear(MAX_GEARS),
            "name",
            format!("{} gears: at most {MAX_GEARS}", f.gear.len()),
        )));
    }
    let train = build(&f, default_eta).map_err(&locate)?;
    let mut train = train;
    let groups = coaxial_groups(&cx, &f, &train)?;
    train.coaxial.extend(groups);
    let (derived, mut checks) = resolve_teeth(&mut train).map_err(&locate)?;
    checks.extend(planet_checks(&train).map_err(&locate)?);
    let (inputs, torques) = inputs_and_torques(&cx, &f, &train)?;
    let willis = willis_queries(&cx, &f, &train)?;
    let output = match &f.output {
        None => None,
        Some(o) => Some(train.body(o.get_ref()).ok_or_else(|| {
            cx.at(
                o.span(),
                "output",
                format!("'{}' is not a body or carrier of the train", o.get_ref()),
            )
        })?),
    };
    let kin = crate::machines::gearing::willis::kinematics(
        &train,
        &inputs.iter().map(|x| x.0).collect::<Vec<_>>(),
    )
    .map_err(&locate)?;
    let speeds =
        crate::machines::gearing::willis::speeds(&train, &kin, &inputs).map_err(&locate)?;
    if let Some(o) = output {
        if speeds.values[o] == 0.0 || kin.dof() != 1 {
            return Err(cx.top(
                "output",
                "the output must turn, in a train of one degree of freedom",
            ));
        }
    }
    for q in &willis {
        if crate::machines::gearing::willis::relative_ratio(&train, q.ids[0], q.ids[1], q.ids[2])
            .map_err(&locate)?
            .is_none()
        {
            return Err(cx.field(
                f.willis[q.index].span(),
                "to",
                format!("willis[{}].to", q.index),
                "with the carrier held, these members are not tied by gears",
            ));
        }
    }
    Ok(TrainScenario {
        name: f.name.clone().unwrap_or_else(|| {
            Path::new(file)
                .file_stem()
                .map_or(NAME.into(), |s| s.to_string_lossy().into_owned())
        }),
        unit,
        train,
        derived,
        checks,
        kin,
        speeds,
        inputs,
        torques,
        output,
        willis,
    })
}

/// The `[[gear]]` tables: the gears and the bodies they sit on (gears naming one body
/// share it).
fn gears_and_bodies(f: &FileSpec) -> Result<(Vec<Gear>, Vec<TrainBody>), TrainError> {
    let mut bodies: Vec<TrainBody> = Vec::new();
    let mut gears = Vec::new();
    for (i, s) in f.gear.iter().enumerate() {
        let g = s.get_ref();
        let err = |field, msg: String| TrainError::new(Element::Gear(i), field, msg);
        if f.gear[..i].iter().any(|h| h.get_ref().name == g.name) {
            return Err(err("name", format!("a second gear named '{}'", g.name)));
        }
        let teeth = match g.teeth {
            None => None,
            Some(z) if (1..=100_000).contains(&z) => Some(z as u32),
            Some(z) => {
                return Err(err(
                    "teeth",
                    format!("must be a whole number 1 … 100000, got {z}"),
                ))
            }
        };
        let module = g.module.or(f.module.as_ref().map(|m| *m.get_ref()));
        if let Some(m) = g.module {
            if !in_range(m, 1e-6, 1e6) {
                return Err(err(
                    "module",
                    format!("must be a positive module (mm), got {m}"),
                ));
            }
        }
        if !in_range(g.inertia, 0.0, 1e12) || !in_range(g.mass, 0.0, 1e12) {
            return Err(err(
                if in_range(g.inertia, 0.0, 1e12) {
                    "mass"
                } else {
                    "inertia"
                },
                "must be a finite number ≥ 0".into(),
            ));
        }
        let body_name = g.body.clone().unwrap_or_else(|| g.name.clone());
        let b = match bodies.iter().position(|b| b.name == body_name) {
            Some(b) => {
                if bodies[b].fixed != g.fixed {
                    return Err(err(
                        "fixed",
                        format!("gears on body '{body_name}' disagree on `fixed`"),
                    ));
                }
                b
            }
            None => {
                bodies.push(TrainBody {
                    name: body_name,
                    carrier: None,
                    fixed: g.fixed,
                    is_carrier: false,
                    planets: 1,
                    inertia: 0.0,
                    element: Element::Gear(i),
                });
                bodies.len() - 1
            }
        };
        gears.push(Gear {
            name: g.name.clone(),
            teeth,
            internal: g.internal,
            module,
            body: b,
            inertia: g.inertia,
            mass: g.mass,
        });
    }
    Ok((gears, bodies))
}

/// Adds `[[carrier]]` `i`: a new body, or, when gears name it as their `body`, the body
/// those gears sit on (a gear rigid with its carrier).
fn add_carrier(
    f: &FileSpec,
    i: usize,
    c: &CarrierSpec,
    gears: &[Gear],
    bodies: &mut Vec<TrainBody>,
) -> Result<(), TrainError> {
    let err = |field, msg: String| TrainError::new(Element::Carrier(i), field, msg);
    let planets = match c.planets {
        None => 1,
        Some(n) if (1..=64).contains(&n) => n as u32,
        Some(n) => return Err(err("planets", format!("must be 1 … 64, got {n}"))),
    };
    if !in_range(c.inertia, 0.0, 1e12) {
        return Err(err("inertia", "must be a finite number ≥ 0".into()));
    }
    let Some(b) = bodies.iter().position(|b| b.name == c.name) else {
        bodies.push(TrainBody {
            name: c.name.clone(),
            carrier: None,
            fixed: c.fixed,
            is_carrier: true,
            planets,
            inertia: c.inertia,
            element: Element::Carrier(i),
        });
        return Ok(());
    };
    // Gears rigid with the carrier state it with `body = "<carrier>"`; a gear merely named
    // like the carrier (its body defaulted to its name) is a clash.
    let explicit = (0..gears.len())
        .filter(|&g| gears[g].body == b)
        .all(|g| f.gear[g].get_ref().body.as_deref() == Some(c.name.as_str()));
    if bodies[b].is_carrier || !explicit {
        return Err(err(
            "name",
            format!(
                "'{}' already names a {}: a gear rigid with this carrier says `body = \"{}\"`; otherwise rename one of them",
                c.name,
                if bodies[b].is_carrier { "carrier" } else { "gear" },
                c.name
            ),
        ));
    }
    let body = &mut bodies[b];
    body.fixed |= c.fixed;
    body.is_carrier = true;
    body.planets = planets;
    body.inertia = c.inertia;
    body.element = Element::Carrier(i);
    Ok(())
}

/// The train from the gear, carrier and mesh tables.
fn build(f: &FileSpec, default_eta: f64) -> Result<GearTrain, TrainError> {
    let (gears, mut bodies) = gears_and_bodies(f)?;
    for (i, s) in f.carrier.iter().enumerate() {
        add_carrier(f, i, s.get_ref(), &gears, &mut bodies)?;
    }
    // Planet axes.
    for (i, s) in f.gear.iter().enumerate() {
        let Some(cn) = &s.get_ref().carrier else {
            continue;
        };
        let err = |msg: String| TrainError::new(Element::Gear(i), "carrier", msg);
        let c = (0..bodies.len())
            .find(|&c| bodies[c].is_carrier && &bodies[c].name == cn)
            .ok_or_else(|| err(format!("'{cn}' is not a [[carrier]]")))?;
        let b = gears[i].body;
        if b == c {
            return Err(err(format!(
                "the gear turns with carrier '{cn}' (`body = \"{cn}\"`): it cannot also ride on it"
            )));
        }

        if bodies[b].carrier.is_some_and(|d| d != c) {
            return Err(err(format!(
                "gears on body '{}' name different carriers",
                bodies[b].name
            )));
        }
        if bodies[b].fixed {
            return Err(err("a planet cannot be fixed".into()));
        }
        bodies[b].carrier = Some(c);
    }
    for (i, s) in f.gear.iter().enumerate() {
        if s.get_ref().carrier.is_none() && bodies[gears[i].body].carrier.is_some() {
            return Err(TrainError::new(
                Element::Gear(i),
                "carrier",
                format!(
                    "other gears on body '{}' ride on a carrier: give this one the same `carrier`",
                    bodies[gears[i].body].name
                ),
            ));
        }
    }
    if let Some(c) = bodies
        .iter()
        .position(|b| b.is_carrier && b.carrier.is_some())
    {
        return Err(TrainError::new(
            bodies[c].element,
            "name",
            format!(
                "carrier '{}' rides on carrier '{}' (a gear rigid with it names a `carrier`): nested carriers are not supported",
                bodies[c].name,
                bodies[bodies[c].carrier.unwrap_or(c)].name
            ),
        ));
    }
    let meshes = build_meshes(f, &gears, default_eta)?;
    let t = GearTrain {
        gears,
        bodies,
        meshes,
        coaxial: Vec::new(),
        profile_shifted: f.profile_shifted,
    };
    for e in 0..t.meshes.len() {
        t.mesh_frame(e)?;
    }
    Ok(t)
}

fn build_meshes(f: &FileSpec, gears: &[Gear], default_eta: f64) -> Result<Vec<Mesh>, TrainError> {
    let mut meshes = Vec::new();
    for (i, s) in f.mesh.iter().enumerate() {
        let m = s.get_ref();
        let err = |field, msg: String| TrainError::new(Element::Mesh(i), field, msg);
        let mut ids = [0; 2];
        for (k, n) in m.gears.iter().enumerate() {
            ids[k] = gears
                .iter()
                .position(|g| &g.name == n)
                .ok_or_else(|| err("gears", format!("'{n}' is not a [[gear]]")))?;
        }
        let kind = match m.kind.as_deref() {
            None | Some("spur") => MeshKind::Spur,
            Some("bevel") => MeshKind::Bevel,
            Some("worm") => MeshKind::Worm,
            Some("crossed") => MeshKind::Crossed,
            Some(k) => {
                return Err(err(
                    "kind",
                    format!("unknown mesh kind '{k}' (expected spur, bevel, worm or crossed)"),
                ))
            }
        };
        let sign = match m.sign {
            None => None,
            Some(s @ (1 | -1)) => Some(s as i8),
            Some(s) => return Err(err("sign", format!("must be 1 or -1, got {s}"))),
        };
        let efficiency = m.efficiency.unwrap_or(default_eta);
        if !in_range(efficiency, 1e-6, 1.0) {
            return Err(err(
                "efficiency",
                format!("must be in (0, 1], got {efficiency}"),
            ));
        }
        if let Some(a) = m.centre_distance {
            if !in_range(a, 1e-9, 1e9) {
                return Err(err(
                    "centre_distance",
                    format!("must be a positive distance (mm), got {a}"),
                ));
            }
        }
        let (ma, mb) = (gears[ids[0]].module, gears[ids[1]].module);
        if kind == MeshKind::Spur {
            if let (Some(a), Some(b)) = (ma, mb) {
                if (a - b).abs() > 1e-12 * a.abs() {
                    return Err(err(
                        "gears",
                        format!("the gears' modules differ ({a} and {b} mm): they cannot mesh"),
                    ));
                }
            }
        }
        meshes.push(Mesh {
            gears: ids,
            kind,
            sign,
            efficiency,
            centre_distance: m.centre_distance,
        });
    }
    Ok(meshes)
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "gear_train";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| match selection_file(file, text)? {
        Some(_) => Ok(()),
        None => parse(file, text).map(drop),
    },
    run: |path, text, _opts| run(path, text),
};
