//! Validation of an arm scenario: from the parsed [`ArmFile`] to a [`Scene`] whose every
//! part is checked (model loaded, joints named, limits consistent with each other and with
//! the model, effects built, poses in the robot's base frame). Every error names the
//! file, the line and the key.

use super::schema::*;
use crate::collision::resolve::{resolve_spec_meshes, PackagePaths};
use crate::collision::{CollisionOptions, ObstacleSpec};
use crate::diag::LocatedError as ScenarioError;
use crate::dynamics::{Effects, Elasticity, Friction, Payload, Rotor};
use crate::model::{Model, ModelSpec, Shape};
use crate::sim::{Controller, Integrator};
use crate::spatial::{Inertia, Mat3, Se3, Vec3};
use crate::trajectory::JointLimits;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The effects a scenario may name, in report order.
pub const EFFECT_NAMES: [&str; 6] = [
    "gravity",
    "friction",
    "rotor_inertia",
    "joint_elasticity",
    "payload",
    "contact",
];

/// How the joint motion is timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Timing {
    Trapezoidal,
    Quintic,
    MinimumJerk,
    TimeOptimal,
}

impl Timing {
    /// Name as written in files.
    pub fn as_str(&self) -> &'static str {
        match self {
            Timing::Trapezoidal => "trapezoidal",
            Timing::Quintic => "quintic",
            Timing::MinimumJerk => "minimum_jerk",
            Timing::TimeOptimal => "time_optimal",
        }
    }
}

/// One step of the task, with poses in the robot's base frame.
#[derive(Clone, Debug)]
pub enum Step {
    /// Joint-space move to these values.
    Joint(Vec<f64>),
    /// Joint-space move to the IK solution of this tool pose.
    Pose(Se3),
    /// Straight tool line to this pose.
    Line(Se3),
    /// Stay still (s).
    Dwell(f64),
    /// Planned, collision-free move to joint values (`Ok`) or a tool pose through IK.
    Plan(Result<Vec<f64>, Se3>),
    /// The tool grasps the part: from here its mass and shape travel with it.
    Attach,
    /// The tool releases the part.
    Detach,
}

/// A step with where it was written (for error messages).
#[derive(Clone, Debug)]
pub struct TaskStep {
    pub step: Step,
    pub key: String,
    pub line: Option<usize>,
}

/// The contact scene (poses in scene axes).
#[derive(Clone, Debug)]
pub struct ContactScene {
    pub table_size: [f64; 3],
    pub table_xyz: [f64; 3],
    pub table_friction: f64,
    pub box_size: [f64; 3],
    pub box_xyz: [f64; 3],
    pub box_mass: f64,
    pub box_friction: f64,
    pub pusher_link: usize,
    pub pusher_radius: f64,
    pub pusher_offset: [f64; 3],
    pub dt: f64,
}

/// Simulation settings.
#[derive(Clone, Debug)]
pub struct SimSettings {
    pub controller: Controller,
    pub integrator: Integrator,
    pub dt: f64,
    pub duration: Option<f64>,
    pub settle: f64,
    pub record_rate: f64,
}

/// Output settings.
#[derive(Clone, Debug)]
pub struct Outputs {
    pub dir: Option<PathBuf>,
    pub torque_plot: Option<crate::trajectory::PlotFormat>,
    pub report: bool,
    pub trajectory_csv: bool,
    pub simulation_csv: bool,
    pub mcap: bool,
}

/// A validated scenario.
pub struct Scene {
    pub file: String,
    pub name: String,
    pub description: Option<String>,
    pub model_path: PathBuf,
    pub model: Model,
    /// The model as read, its resolvable mesh URIs replaced by absolute paths.
    pub spec: ModelSpec,
    /// Where `package://` URIs were searched (command line, `model.package_path`, then
    /// the environment).
    pub package_paths: PackagePaths,
    pub model_warnings: Vec<String>,
    /// Scene → robot base.
    pub base: Se3,
    pub tool: usize,
    /// The named effects, in [`EFFECT_NAMES`] order.
    pub effect_names: Vec<&'static str>,
    /// The effects for dynamics (payload: the last mass of a sweep).
    pub effects: Effects,
    /// Payload masses of a sweep (one entry without a sweep); empty without payload.
    pub payload_masses: Vec<f64>,
    pub payload_inertia: Option<(usize, Inertia)>,
    pub contact: Option<ContactScene>,
    pub q0: Vec<f64>,
    /// Planning limits (velocity scaled).
    pub limits: JointLimits,
    /// Position limits used by planning and checks.
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// Limits the torque check judges against (model velocity, effort possibly overridden).
    pub check_velocity: Vec<f64>,
    pub check_effort: Vec<f64>,
    pub obstacles: Vec<ObstacleSpec>,
    pub collision: Option<CollisionOptions>,
    pub self_collision: bool,
    pub collision_max_step: f64,
    pub steps: Vec<TaskStep>,
    pub task_kind: String,
    /// IK and lines ignore the tool orientation.
    pub position_only: bool,
    pub timing: Timing,
    pub topp_segments: usize,
    pub line_samples: usize,
    pub tool_speed: f64,
    pub tool_acceleration: f64,
    pub check_dt: f64,
    pub simulation: Option<SimSettings>,
    pub outputs: Outputs,
    pub warnings: Vec<String>,
    /// Planner settings (when the task plans).
    pub planner: Option<super::planned::PlannerSettings>,
    /// The grasped part's shape, on the tool between attach and detach.
    pub part: Option<super::planned::Part>,
    /// `collision.disabled_pairs` and the skeleton's touching pairs, for the planner.
    pub planner_disabled: Vec<[String; 2]>,
}

/// Error context: the file and its text (the crate's one error builder).
pub type Ctx<'a> = crate::diag::Source<'a>;

use crate::diag::finite_positive as finite_pos;

/// Reads a per-joint value: a number for all, a list in joint order, or a table by joint
/// name over `default`.
pub fn per_joint(
    cx: &Ctx,
    v: &PerJoint,
    key: &str,
    names: &[String],
    default: &[f64],
) -> Result<Vec<f64>, ScenarioError> {
    let n = names.len();
    let num = |x: &toml::Value| -> Option<f64> {
        match x {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        }
    };
    let out = match v.get_ref() {
        toml::Value::Array(a) => {
            if a.len() != n {
                return Err(cx.at(
                    v.span(),
                    key,
                    format!("{} values for {n} joints ({})", a.len(), names.join(", ")),
                ));
            }
            a.iter()
                .enumerate()
                .map(|(k, x)| {
                    num(x).ok_or_else(|| {
                        cx.at(
                            v.span(),
                            key,
                            format!("value {k} (joint {}) is not a number", names[k]),
                        )
                    })
                })
                .collect::<Result<Vec<_>, _>>()?
        }
        toml::Value::Table(t) => {
            let mut out = default.to_vec();
            for (name, x) in t {
                let k = names.iter().position(|j| j == name).ok_or_else(|| {
                    let hint = closest(name, names)
                        .map(|c| format!(" (did you mean '{c}'?)"))
                        .unwrap_or_default();
                    cx.at(
                        v.span(),
                        &format!("{key}.{name}"),
                        format!(
                            "unknown joint '{name}'{hint}; the joints are: {}",
                            names.join(", ")
                        ),
                    )
                })?;
                out[k] = num(x).ok_or_else(|| {
                    cx.at(v.span(), &format!("{key}.{name}"), "expected a number")
                })?;
            }
            out
        }
        x => match num(x) {
            Some(f) => vec![f; n],
            None => {
                return Err(cx.at(
                    v.span(),
                    key,
                    format!(
                        "expected a number, a list of {n} numbers or a table by joint name, got {}",
                        x.type_str()
                    ),
                ))
            }
        },
    };
    if let Some(k) = out.iter().position(|x| !x.is_finite()) {
        return Err(cx.at(
            v.span(),
            key,
            format!("joint {}: the value is not finite", names[k]),
        ));
    }
    Ok(out)
}

/// The name in `names` closest to `name` (edit distance ≤ 3), for "did you mean".
fn closest<'a>(name: &str, names: &'a [String]) -> Option<&'a str> {
    fn dist(a: &str, b: &str) -> usize {
        let b: Vec<char> = b.chars().collect();
        let mut prev: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.chars().enumerate() {
            let mut cur = vec![i + 1; b.len() + 1];
            for (j, cb) in b.iter().enumerate() {
                cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                    .min(prev[j + 1] + 1)
                    .min(cur[j] + 1);
            }
            prev = cur;
        }
        prev[b.len()]
    }
    names
        .iter()
        .map(|n| (dist(name, n), n))
        .filter(|(d, _)| *d <= 3)
        .min_by_key(|(d, _)| *d)
        .map(|(_, n)| n.as_str())
}

fn positive_all(
    cx: &Ctx,
    v: &PerJoint,
    key: &str,
    names: &[String],
    vals: &[f64],
    allow_zero: bool,
) -> Result<(), ScenarioError> {
    for (k, x) in vals.iter().enumerate() {
        if *x < 0.0 || (!allow_zero && *x == 0.0) {
            return Err(cx.at(
                v.span(),
                key,
                format!(
                    "joint {}: must be {} (got {x})",
                    names[k],
                    if allow_zero { ">= 0" } else { "> 0" }
                ),
            ));
        }
    }
    Ok(())
}

fn pose_of(p: &PoseSec) -> Se3 {
    Se3::from_xyz_rpy(p.xyz, p.rpy)
}

fn finite_pose(p: &PoseSec) -> bool {
    p.xyz.iter().chain(p.rpy.iter()).all(|x| x.is_finite())
}

/// Adds capsules along the bones of links whose collision meshes cannot be found (or that
/// have no collision geometry): one from the link origin to each child joint origin.
fn add_skeleton(spec: &mut ModelSpec, radius: f64, base_dir: Option<&Path>) -> Vec<String> {
    let mut added = Vec::new();
    let missing = |s: &Shape| match s {
        Shape::Mesh { uri, .. } => crate::collision::resolve::resolve_uri(uri, base_dir)
            .ok()
            .is_none_or(|p| !p.exists()),
        _ => false,
    };
    let bones: Vec<(String, Vec3)> = spec
        .joints
        .iter()
        .map(|j| (j.parent.clone(), j.origin.trans))
        .collect();
    for link in &mut spec.links {
        let all_missing = link.collisions.iter().all(|g| missing(&g.shape));
        if !all_missing {
            continue;
        }
        link.collisions.clear();
        for (parent, d) in &bones {
            let len = d.norm();
            if parent != &link.name || len < 1e-3 {
                continue;
            }
            let rot = crate::spatial::rotation_z_to(&(d / len));
            link.collisions.push(crate::model::Geometry {
                origin: Se3::new(rot, d * 0.5),
                shape: Shape::Capsule {
                    radius,
                    length: len,
                },
                rgba: None,
            });
        }
        if !link.collisions.is_empty() {
            added.push(link.name.clone());
        }
    }
    added
}

/// Pairs of skeleton links whose capsules overlap by construction: a link `C` and an
/// ancestor `P` whose bone ends within `2r` of `C`'s origin along the chain (short or
/// zero-length bones in between, e.g. a shoulder whose two joints share an origin, or a
/// short wrist link). They touch in every configuration, so they are not tested.
fn skeleton_contacts(spec: &ModelSpec, skeleton: &[String], radius: f64) -> Vec<[String; 2]> {
    let parent_bone = |child: &str| {
        spec.joints
            .iter()
            .find(|j| j.child == child)
            .map(|j| (j.parent.clone(), j.origin.trans.norm()))
    };
    let mut out = Vec::new();
    for c in skeleton {
        // `acc` bounds the distance from C's origin to x's origin (the end of p's bone).
        let (mut x, mut acc) = (c.clone(), 0.0);
        let mut guard = 0;
        while let Some((p, len)) = parent_bone(&x) {
            guard += 1;
            if guard > spec.joints.len() || acc >= 2.0 * radius {
                break;
            }
            if &x != c && skeleton.contains(&p) {
                out.push([p.clone(), c.clone()]);
            }
            acc += len;
            x = p;
        }
    }
    out
}

/// A loaded model: its path, spec (mesh URIs resolved, with skeleton capsules), model,
/// warnings, notes, the skeleton pairs that touch by construction, and the package paths.
type Loaded = (
    PathBuf,
    ModelSpec,
    Model,
    Vec<String>,
    Vec<String>,
    Vec<[String; 2]>,
    PackagePaths,
);

/// The package search paths: `cli` first, then `model.package_path` (relative to the
/// scenario's directory `dir`), then the environment.
fn package_paths(
    cx: &Ctx,
    dir: &Path,
    sec: &ModelSec,
    cli: &[PathBuf],
) -> Result<PackagePaths, ScenarioError> {
    let mut explicit = cli.to_vec();
    for p in &sec.package_path {
        let d = dir.join(p.get_ref());
        if !d.is_dir() {
            return Err(cx.at(
                p.span(),
                "model.package_path",
                format!(
                    "'{}' is not a directory (looked for {})",
                    p.get_ref(),
                    d.display()
                ),
            ));
        }
        explicit.push(d);
    }
    Ok(PackagePaths::from_env(explicit))
}

/// Loads the model named by `[model]`; `cli` are the command line's package paths.
fn load_model(
    cx: &Ctx,
    dir: &Path,
    sec: &Spanned<ModelSec>,
    skeleton: Option<f64>,
    cli: &[PathBuf],
) -> Result<Loaded, ScenarioError> {
    let m = sec.get_ref();
    let rel = m.file.get_ref();
    let path = dir.join(rel);
    let fail = |msg: String| cx.at(m.file.span(), "model.file", msg);
    if !path.exists() {
        return Err(fail(format!(
            "model file '{rel}' not found (looked for {})",
            path.display()
        )));
    }
    let mut spec = Model::read_spec(&path).map_err(|e| fail(format!("cannot load: {e}")))?;
    let pkgs = package_paths(cx, dir, m, cli)?;
    let unresolved = resolve_spec_meshes(&mut spec, path.parent(), &pkgs);
    let mut notes = Vec::new();
    let mut touching = Vec::new();
    if let Some(r) = skeleton {
        let added = add_skeleton(&mut spec, r, path.parent());
        touching = skeleton_contacts(&spec, &added, r);
        if !added.is_empty() {
            notes.push(format!(
                "collision: links without usable collision geometry get capsules of radius {r} m along their bones: {}",
                added.join(", ")
            ));
        }
    }
    // Unresolved collision meshes are reported by the collision model, unless the
    // skeleton took them out of the spec.
    for u in &unresolved {
        if u.kind == "visual" || skeleton.is_some() {
            notes.push(format!(
                "{}: link '{}': {} mesh '{}' not found: {}",
                path.display(),
                u.link,
                u.kind,
                u.uri,
                u.reason
            ));
        }
    }
    let (model, warnings) =
        Model::build(spec.clone()).map_err(|e| fail(format!("cannot load: {e}")))?;
    if model.nv == 0 {
        return Err(fail("the model has no movable joint".into()));
    }
    let w = warnings.iter().map(|w| w.to_string()).collect();
    Ok((path, spec, model, w, notes, touching, pkgs))
}

fn get_f(
    cx: &Ctx,
    v: &Option<Spanned<f64>>,
    key: &str,
    default: f64,
) -> Result<f64, ScenarioError> {
    match v {
        None => Ok(default),
        Some(s) if finite_pos(*s.get_ref()) => Ok(*s.get_ref()),
        Some(s) => Err(cx.at(
            s.span(),
            key,
            format!("must be finite and positive (got {})", s.get_ref()),
        )),
    }
}

/// Validates `file` (read from `path`) into a [`Scene`].
pub fn build(path: &Path, text: &str, file: &ArmFile) -> Result<Scene, ScenarioError> {
    build_with(path, text, file, &[])
}

/// [`build`] with package paths from the command line, searched before the file's
/// `model.package_path` and the environment.
pub fn build_with(
    path: &Path,
    text: &str,
    file: &ArmFile,
    package_path: &[PathBuf],
) -> Result<Scene, ScenarioError> {
    let fname = path.display().to_string();
    let cx = Ctx { file: &fname, text };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut warnings = Vec::new();
    let name = match &file.name {
        Some(n) if n.get_ref().trim().is_empty() => {
            return Err(cx.at(n.span(), "name", "the name is empty"))
        }
        Some(n) if n.get_ref().contains(['/', '\\']) => {
            return Err(cx.at(n.span(), "name", "the name is used for file names: no '/'"))
        }
        Some(n) => n.get_ref().clone(),
        None => path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scenario")
            .to_string(),
    };

    // Effects named.
    let mut named: Vec<&'static str> = Vec::new();
    for e in file.effects.get_ref() {
        let Some(k) = EFFECT_NAMES.iter().position(|n| n == e.get_ref()) else {
            return Err(cx.at(
                e.span(),
                "effects",
                format!(
                    "unknown effect '{}' (known: {})",
                    e.get_ref(),
                    EFFECT_NAMES.join(", ")
                ),
            ));
        };
        if named.contains(&EFFECT_NAMES[k]) {
            return Err(cx.at(
                e.span(),
                "effects",
                format!("effect '{}' listed twice", e.get_ref()),
            ));
        }
        named.push(EFFECT_NAMES[k]);
    }
    named.sort_by_key(|n| EFFECT_NAMES.iter().position(|m| m == n));
    let has = |e: &str| named.contains(&e);
    // Parameter tables for effects left out: ignored, with a warning.
    for (sec, present) in [
        ("gravity", file.gravity.is_some()),
        ("friction", file.friction.is_some()),
        ("rotor_inertia", file.rotor_inertia.is_some()),
        ("joint_elasticity", file.joint_elasticity.is_some()),
        ("payload", file.payload.is_some()),
        ("contact", file.contact.is_some()),
    ] {
        if present && !has(sec) {
            warnings.push(format!(
                "[{sec}] is given but '{sec}' is not in effects: it is not simulated"
            ));
        }
    }
    if has("contact") && file.contact.is_none() {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'contact' needs a [contact] table (table, box, pusher)",
        ));
    }
    if has("contact") && !has("gravity") {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'contact' needs 'gravity' (the box rests on the table under its weight)",
        ));
    }
    if has("joint_elasticity") && file.joint_elasticity.is_none() {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'joint_elasticity' needs a [joint_elasticity] table with the stiffness",
        ));
    }
    if has("payload") && file.payload.is_none() {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'payload' needs a [payload] table with the mass",
        ));
    }

    // Collision settings (the skeleton changes the model spec).
    let csec = file.collision.as_ref().map(|c| c.get_ref());
    let skeleton = match csec.and_then(|c| c.skeleton_radius.as_ref()) {
        None => None,
        Some(r) => Some(get_f(
            &cx,
            &Some(r.clone()),
            "collision.skeleton_radius",
            0.0,
        )?),
    };
    let (model_path, spec, model, model_warnings, notes, touching, package_paths) =
        load_model(&cx, dir, &file.model, skeleton, package_path)?;
    warnings.extend(notes);
    let names = model.dof_names();
    let n = model.nv;
    let msec = file.model.get_ref();
    if !msec
        .base_xyz
        .iter()
        .chain(msec.base_rpy.iter())
        .all(|x| x.is_finite())
    {
        return Err(cx.at(
            file.model.span(),
            "model.base_xyz",
            "base pose is not finite",
        ));
    }
    let base = Se3::from_xyz_rpy(msec.base_xyz, msec.base_rpy);
    let base_inv = base.inverse();
    let link_by_name = |s: &Spanned<String>, key: &str| -> Result<usize, ScenarioError> {
        model.link_id(s.get_ref()).ok_or_else(|| {
            let links: Vec<String> = model.links.iter().map(|l| l.name.clone()).collect();
            let hint = closest(s.get_ref(), &links)
                .map(|c| format!(" (did you mean '{c}'?)"))
                .unwrap_or_default();
            cx.at(
                s.span(),
                key,
                format!("unknown link '{}'{hint}", s.get_ref()),
            )
        })
    };
    let tool = match &msec.tool {
        Some(t) => link_by_name(t, "model.tool")?,
        None => model.links.len() - 1,
    };
    if model.links[tool].body == crate::model::WORLD {
        let key_line = msec
            .tool
            .as_ref()
            .map(|t| t.span())
            .unwrap_or(file.model.span());
        return Err(cx.at(
            key_line,
            "model.tool",
            format!(
                "the tool link '{}' is fixed to the world",
                model.links[tool].name
            ),
        ));
    }

    // Effects.
    let mut effects = Effects::default();
    if has("gravity") {
        let g = match file
            .gravity
            .as_ref()
            .and_then(|g| g.get_ref().vector.as_ref())
        {
            Some(v) if v.get_ref().iter().all(|x| x.is_finite()) => *v.get_ref(),
            Some(v) => return Err(cx.at(v.span(), "gravity.vector", "not finite")),
            None => [0.0, 0.0, -9.81],
        };
        effects.gravity = Some(base.rot.transpose() * Vec3::new(g[0], g[1], g[2]));
    }
    if has("friction") {
        let mut f = Friction::from_model(&model);
        if let Some(sec) = &file.friction {
            let s = sec.get_ref();
            for (v, key, dst) in [
                (&s.viscous, "friction.viscous", &mut f.viscous),
                (&s.coulomb, "friction.coulomb", &mut f.coulomb),
                (&s.stiction, "friction.stiction", &mut f.stiction),
                (
                    &s.stribeck_velocity,
                    "friction.stribeck_velocity",
                    &mut f.stribeck_velocity,
                ),
            ] {
                if let Some(v) = v {
                    let vals = per_joint(&cx, v, key, &names, dst)?;
                    positive_all(
                        &cx,
                        v,
                        key,
                        &names,
                        &vals,
                        key != "friction.stribeck_velocity",
                    )?;
                    *dst = vals;
                }
            }
            // Stiction defaults to the Coulomb level when only that is given.
            if s.coulomb.is_some() && s.stiction.is_none() {
                f.stiction = f.coulomb.clone();
            }
            if let Some(v) = &s.stiction {
                let low = (0..n).find(|&k| f.stiction[k] < f.coulomb[k]);
                if let Some(k) = low {
                    return Err(cx.at(
                        v.span(),
                        "friction.stiction",
                        format!(
                            "joint {}: stiction {} is below the Coulomb level {}",
                            names[k], f.stiction[k], f.coulomb[k]
                        ),
                    ));
                }
            }
            f.smoothing = get_f(&cx, &s.smoothing, "friction.smoothing", f.smoothing)?;
        }
        effects.friction = Some(f);
    }
    if has("rotor_inertia") {
        let mut r = Rotor::from_model(&model, 1.0);
        if let Some(sec) = &file.rotor_inertia {
            let s = sec.get_ref();
            for (v, key, dst, zero_ok) in [
                (&s.inertia, "rotor_inertia.inertia", &mut r.inertia, true),
                (
                    &s.gear_ratio,
                    "rotor_inertia.gear_ratio",
                    &mut r.gear_ratio,
                    false,
                ),
                (
                    &s.efficiency,
                    "rotor_inertia.efficiency",
                    &mut r.efficiency,
                    false,
                ),
            ] {
                if let Some(v) = v {
                    let vals = per_joint(&cx, v, key, &names, dst)?;
                    positive_all(&cx, v, key, &names, &vals, zero_ok)?;
                    if key.ends_with("efficiency") {
                        if let Some(k) = vals.iter().position(|e| *e > 1.0) {
                            return Err(cx.at(
                                v.span(),
                                key,
                                format!("joint {}: efficiency {} is above 1", names[k], vals[k]),
                            ));
                        }
                    }
                    *dst = vals;
                }
            }
        }
        if r.inertia.iter().all(|x| *x == 0.0) {
            let span = file
                .rotor_inertia
                .as_ref()
                .map(|s| s.span())
                .unwrap_or(file.effects.span());
            return Err(cx.at(
                span,
                "rotor_inertia.inertia",
                "effect 'rotor_inertia' is named but every rotor inertia is 0 (the model gives none): set rotor_inertia.inertia",
            ));
        }
        effects.rotor = Some(r);
    }
    if has("joint_elasticity") {
        let sec = file.joint_elasticity.as_ref().expect("checked above");
        let s = sec.get_ref();
        let zeros = vec![0.0; n];
        let stiffness = per_joint(
            &cx,
            &s.stiffness,
            "joint_elasticity.stiffness",
            &names,
            &zeros,
        )?;
        positive_all(
            &cx,
            &s.stiffness,
            "joint_elasticity.stiffness",
            &names,
            &stiffness,
            false,
        )?;
        let damping = match &s.damping {
            Some(v) => {
                let d = per_joint(&cx, v, "joint_elasticity.damping", &names, &zeros)?;
                positive_all(&cx, v, "joint_elasticity.damping", &names, &d, true)?;
                d
            }
            None => zeros.clone(),
        };
        let from_rotor: Vec<f64> = match &effects.rotor {
            Some(r) => (0..n).map(|k| r.armature(k)).collect(),
            None => (0..n)
                .map(|k| {
                    let j = model.dof_joint(k);
                    j.motor_inertia * j.gear_ratio * j.gear_ratio
                })
                .collect(),
        };
        let motor_inertia = match &s.motor_inertia {
            Some(v) => {
                let b = per_joint(
                    &cx,
                    v,
                    "joint_elasticity.motor_inertia",
                    &names,
                    &from_rotor,
                )?;
                positive_all(&cx, v, "joint_elasticity.motor_inertia", &names, &b, false)?;
                b
            }
            None => {
                if let Some(k) = from_rotor.iter().position(|b| *b <= 0.0) {
                    return Err(cx.at(
                        sec.span(),
                        "joint_elasticity.motor_inertia",
                        format!(
                            "joint {}: no motor inertia in the model; set joint_elasticity.motor_inertia (reflected, I_m N², kg m²)",
                            names[k]
                        ),
                    ));
                }
                from_rotor
            }
        };
        effects.elasticity = Some(Elasticity {
            stiffness,
            damping,
            motor_inertia,
        });
    }
    let mut payload_masses = Vec::new();
    let mut payload_inertia = None;
    if has("payload") {
        let sec = file.payload.as_ref().expect("checked above");
        let s = sec.get_ref();
        let link = match &s.link {
            Some(l) => link_by_name(l, "payload.link")?,
            None => tool,
        };
        let as_num = |x: &toml::Value| match x {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        };
        payload_masses = match s.mass.get_ref() {
            toml::Value::Array(a) if !a.is_empty() => a
                .iter()
                .map(as_num)
                .collect::<Option<Vec<f64>>>()
                .ok_or_else(|| cx.at(s.mass.span(), "payload.mass", "expected numbers"))?,
            x => vec![as_num(x).ok_or_else(|| {
                cx.at(
                    s.mass.span(),
                    "payload.mass",
                    "expected a mass (kg) or a non-empty list of masses for a sweep",
                )
            })?],
        };
        if let Some(m) = payload_masses
            .iter()
            .find(|m| !(m.is_finite() && **m >= 0.0))
        {
            return Err(cx.at(
                s.mass.span(),
                "payload.mass",
                format!("masses must be finite and >= 0 (got {m})"),
            ));
        }
        if !s.com.iter().all(|x| x.is_finite()) {
            return Err(cx.at(sec.span(), "payload.com", "not finite"));
        }
        let inertia_com = match &s.inertia {
            None => Mat3::zeros(),
            Some(v) => {
                let i = v.get_ref();
                let m = match i.len() {
                    3 => Mat3::from_diagonal(&Vec3::new(i[0], i[1], i[2])),
                    6 => Mat3::new(i[0], i[3], i[4], i[3], i[1], i[5], i[4], i[5], i[2]),
                    k => {
                        return Err(cx.at(
                            v.span(),
                            "payload.inertia",
                            format!("expected 3 or 6 values, got {k}"),
                        ))
                    }
                };
                let eig = m.symmetric_eigenvalues();
                if !i.iter().all(|x| x.is_finite()) || eig.iter().any(|e| *e < -1e-12) {
                    return Err(cx.at(
                        v.span(),
                        "payload.inertia",
                        "the inertia is not symmetric positive semi-definite",
                    ));
                }
                m
            }
        };
        let com = Vec3::new(s.com[0], s.com[1], s.com[2]);
        let mass = *payload_masses.last().expect("non-empty");
        let inertia = Inertia::new(mass, com, inertia_com);
        let p = Payload::new(&model, link, inertia)
            .map_err(|e| cx.at(sec.span(), "payload.link", e))?;
        payload_inertia = Some((link, inertia));
        effects.payload = Some(p);
    }
    effects
        .validate(&model)
        .map_err(|e| cx.at(file.effects.span(), "effects", e))?;

    // Limits.
    let lsec = file.limits.as_ref().map(|l| l.get_ref());
    let mut lower = model.lower.clone();
    let mut upper = model.upper.clone();
    if let Some(l) = lsec {
        for (v, key, dst, model_lim, is_lower) in [
            (&l.lower, "limits.lower", &mut lower, &model.lower, true),
            (&l.upper, "limits.upper", &mut upper, &model.upper, false),
        ] {
            if let Some(v) = v {
                let vals = per_joint(&cx, v, key, &names, model_lim)?;
                for k in 0..n {
                    let outside = if is_lower {
                        vals[k] < model_lim[k]
                    } else {
                        vals[k] > model_lim[k]
                    };
                    if outside {
                        return Err(cx.at(
                            v.span(),
                            key,
                            format!(
                                "joint {}: {} is outside the model's range [{}, {}]",
                                names[k], vals[k], model.lower[k], model.upper[k]
                            ),
                        ));
                    }
                }
                *dst = vals;
            }
        }
    }
    for k in 0..n {
        if lower[k] >= upper[k] {
            let span = lsec
                .and_then(|l| l.lower.as_ref().or(l.upper.as_ref()))
                .map(|v| v.span())
                .unwrap_or(0..0);
            return Err(cx.at(
                span,
                "limits.lower",
                format!(
                    "joint {}: lower limit {} is not below the upper limit {}",
                    names[k], lower[k], upper[k]
                ),
            ));
        }
    }
    let scale = match lsec.and_then(|l| l.velocity_scale.as_ref()) {
        None => 1.0,
        Some(s) if *s.get_ref() > 0.0 && *s.get_ref() <= 1.0 => *s.get_ref(),
        Some(s) => {
            return Err(cx.at(
                s.span(),
                "limits.velocity_scale",
                format!("must be in (0, 1] (got {})", s.get_ref()),
            ))
        }
    };
    let mut velocity = model.velocity_limit.clone();
    if let Some(v) = lsec.and_then(|l| l.velocity.as_ref()) {
        let vals = per_joint(&cx, v, "limits.velocity", &names, &velocity)?;
        positive_all(&cx, v, "limits.velocity", &names, &vals, false)?;
        for k in 0..n {
            if vals[k] > model.velocity_limit[k] {
                return Err(cx.at(
                    v.span(),
                    "limits.velocity",
                    format!(
                        "joint {}: {} exceeds the model's velocity limit {}",
                        names[k], vals[k], model.velocity_limit[k]
                    ),
                ));
            }
        }
        velocity = vals;
    }
    if let Some(k) = velocity.iter().position(|v| !v.is_finite()) {
        let span = file
            .limits
            .as_ref()
            .map(|l| l.span())
            .unwrap_or(file.model.span());
        return Err(cx.at(
            span,
            "limits.velocity",
            format!(
                "joint {}: the model gives no velocity limit; set limits.velocity",
                names[k]
            ),
        ));
    }
    let check_velocity = velocity.clone();
    for v in &mut velocity {
        *v *= scale;
    }
    let default_acc: Vec<f64> = velocity.iter().map(|v| 4.0 * v).collect();
    let acceleration = match lsec.and_then(|l| l.acceleration.as_ref()) {
        Some(v) => {
            let vals = per_joint(&cx, v, "limits.acceleration", &names, &default_acc)?;
            positive_all(&cx, v, "limits.acceleration", &names, &vals, false)?;
            vals
        }
        None => default_acc,
    };
    let mut effort = model.effort_limit.clone();
    if let Some(v) = lsec.and_then(|l| l.effort.as_ref()) {
        let vals = per_joint(&cx, v, "limits.effort", &names, &effort)?;
        positive_all(&cx, v, "limits.effort", &names, &vals, false)?;
        for k in 0..n {
            if vals[k] > model.effort_limit[k] {
                return Err(cx.at(
                    v.span(),
                    "limits.effort",
                    format!(
                        "joint {}: {} exceeds the model's effort limit {}",
                        names[k], vals[k], model.effort_limit[k]
                    ),
                ));
            }
        }
        effort = vals;
    }
    let limits = JointLimits {
        velocity,
        acceleration,
        effort: effort.clone(),
    };

    // Initial configuration.
    let deg = |x: f64, k: usize, degrees: bool| {
        if degrees && model.dof_joint(k).jtype != crate::model::JointType::Prismatic {
            x.to_radians()
        } else {
            x
        }
    };
    let neutral: Vec<f64> = (0..n).map(|k| 0.0f64.clamp(lower[k], upper[k])).collect();
    let q0 = match &file.initial {
        Some(init) => {
            let s = init.get_ref();
            let raw_default: Vec<f64> = neutral
                .iter()
                .enumerate()
                .map(|(k, x)| {
                    if s.degrees && deg(1.0, k, true) != 1.0 {
                        x.to_degrees()
                    } else {
                        *x
                    }
                })
                .collect();
            let vals = per_joint(&cx, &s.q, "initial.q", &names, &raw_default)?;
            let q: Vec<f64> = vals
                .iter()
                .enumerate()
                .map(|(k, x)| deg(*x, k, s.degrees))
                .collect();
            check_in_limits(&cx, &s.q, "initial.q", &names, &q, &lower, &upper)?;
            q
        }
        None => neutral.clone(),
    };

    // Obstacles (scene → base frame).
    let mut obstacles = Vec::new();
    for (i, o) in file.obstacles.iter().enumerate() {
        let spec = o.get_ref();
        let key = format!("obstacles[{i}] ({})", spec.name);
        spec.to_obstacle()
            .map_err(|e| cx.at(o.span(), &key, e.to_string()))?;
        if model.link_id(&spec.name).is_some() {
            return Err(cx.at(o.span(), &key, "an obstacle may not share a link's name"));
        }
        if obstacles.iter().any(|p: &ObstacleSpec| p.name == spec.name) {
            return Err(cx.at(o.span(), &key, "duplicate obstacle name"));
        }
        let world = Se3::from_xyz_rpy(spec.xyz, spec.rpy);
        let local = base_inv.mul(&world);
        let mut s = spec.clone();
        s.xyz = [local.trans.x, local.trans.y, local.trans.z];
        s.rpy = crate::spatial::matrix_to_rpy(&local.rot);
        obstacles.push(s);
    }
    // The planner leaves these pairs out whether or not the motion is checked.
    let mut planner_disabled = touching.clone();
    if let Some(c) = csec {
        planner_disabled.extend(c.disabled_pairs.iter().map(|p| p.get_ref().clone()));
    }
    let collision_enabled = csec.is_none_or(|c| c.enabled);
    let self_collision = csec.is_none_or(|c| c.self_collision);
    let collision = if collision_enabled {
        let mut opts = CollisionOptions {
            obstacle_dir: Some(dir.to_path_buf()),
            disabled_pairs: touching,
            ..Default::default()
        };
        if let Some(c) = csec {
            if !(c.margin.is_finite() && c.margin >= 0.0) {
                let sp = file.collision.as_ref().expect("some").span();
                return Err(cx.at(sp, "collision.margin", "must be finite and >= 0"));
            }
            opts.margin = c.margin;
            opts.convex_hulls = c.convex_hulls;
            for p in &c.disabled_pairs {
                for nm in p.get_ref() {
                    if model.link_id(nm).is_none() && !obstacles.iter().any(|o| &o.name == nm) {
                        return Err(cx.at(
                            p.span(),
                            "collision.disabled_pairs",
                            format!("'{nm}' is neither a link nor an obstacle"),
                        ));
                    }
                }
                opts.disabled_pairs.push(p.get_ref().clone());
            }
        }
        Some(opts)
    } else {
        None
    };
    let collision_max_step = get_f(
        &cx,
        &csec.and_then(|c| c.max_step.clone()),
        "collision.max_step",
        0.02,
    )?;

    // Contact scene.
    let contact = if has("contact") {
        let sec = file.contact.as_ref().expect("checked above");
        let c = sec.get_ref();
        let t = c.table.get_ref();
        let b = c.object.get_ref();
        let ok3 = |v: &[f64; 3], pos: bool| v.iter().all(|x| x.is_finite() && (!pos || *x > 0.0));
        let table_ok =
            ok3(&t.size, true) && ok3(&t.xyz, false) && t.friction >= 0.0 && t.friction.is_finite();
        if !table_ok {
            return Err(cx.at(
                c.table.span(),
                "contact.table",
                "size must be positive, xyz finite, friction >= 0",
            ));
        }
        let box_ok = ok3(&b.size, true)
            && ok3(&b.xyz, false)
            && finite_pos(b.mass)
            && b.friction >= 0.0
            && b.friction.is_finite();
        if !box_ok {
            return Err(cx.at(
                c.object.span(),
                "contact.box",
                "size and mass must be positive, xyz finite, friction >= 0",
            ));
        }
        let pusher_link = match &c.pusher_link {
            Some(l) => link_by_name(l, "contact.pusher_link")?,
            None => tool,
        };
        Some(ContactScene {
            table_size: t.size,
            table_xyz: t.xyz,
            table_friction: t.friction,
            box_size: b.size,
            box_xyz: b.xyz,
            box_mass: b.mass,
            box_friction: b.friction,
            pusher_link,
            pusher_radius: get_f(&cx, &c.pusher_radius, "contact.pusher_radius", 0.03)?,
            pusher_offset: c.pusher_offset,
            dt: get_f(&cx, &c.dt, "contact.dt", 0.0)?,
        })
    } else {
        None
    };

    // Task.
    let tsec = file.task.get_ref();
    let tdeg = tsec.degrees;
    let joint_row = |v: &PerJoint, key: &str| -> Result<Vec<f64>, ScenarioError> {
        let raw = per_joint(&cx, v, key, &names, &q0)?;
        let q: Vec<f64> = raw
            .iter()
            .enumerate()
            .map(|(k, x)| deg(*x, k, tdeg))
            .collect();
        check_in_limits(&cx, v, key, &names, &q, &lower, &upper)?;
        Ok(q)
    };
    let to_base = |p: &PoseSec| base_inv.mul(&pose_of(p));
    let kind = tsec.kind.get_ref().as_str();
    let need = |what: &str| {
        cx.at(
            file.task.span(),
            &format!("task.{what}"),
            format!("task type '{kind}' needs task.{what}"),
        )
    };
    let mut steps = Vec::new();
    let push = |steps: &mut Vec<TaskStep>, step: Step, key: String, span: Range<usize>| {
        steps.push(TaskStep {
            step,
            key,
            line: Some(cx.line(&span)),
        })
    };
    let check_pose = |p: &PoseSec, key: &str, span: Range<usize>| -> Result<(), ScenarioError> {
        if finite_pose(p) {
            Ok(())
        } else {
            Err(cx.at(span, key, "pose is not finite"))
        }
    };
    match kind {
        "joint_waypoints" => {
            let w = tsec.waypoints.as_ref().ok_or_else(|| need("waypoints"))?;
            if w.get_ref().is_empty() {
                return Err(cx.at(w.span(), "task.waypoints", "no waypoints"));
            }
            for (i, row) in w.get_ref().iter().enumerate() {
                let key = format!("task.waypoints[{i}]");
                let q = joint_row(row, &key)?;
                push(&mut steps, Step::Joint(q), key, row.span());
            }
        }
        "cartesian_waypoints" => {
            let w = tsec.poses.as_ref().ok_or_else(|| need("poses"))?;
            if w.get_ref().is_empty() {
                return Err(cx.at(w.span(), "task.poses", "no poses"));
            }
            for (i, p) in w.get_ref().iter().enumerate() {
                let key = format!("task.poses[{i}]");
                check_pose(p, &key, w.span())?;
                push(&mut steps, Step::Pose(to_base(p)), key, w.span());
            }
        }
        "line" => {
            let g = tsec.goal.as_ref().ok_or_else(|| need("goal"))?;
            check_pose(g.get_ref(), "task.goal", g.span())?;
            push(&mut steps, Step::Line(to_base(g.get_ref())), "task.goal".into(), g.span());
        }
        "pick_and_place" => {
            let pick = tsec.pick.as_ref().ok_or_else(|| need("pick"))?;
            let place = tsec.place.as_ref().ok_or_else(|| need("place"))?;
            check_pose(pick.get_ref(), "task.pick", pick.span())?;
            check_pose(place.get_ref(), "task.place", place.span())?;
            let a = match &tsec.approach {
                None => 0.1,
                Some(s) if s.get_ref().is_finite() && *s.get_ref() >= 0.0 => *s.get_ref(),
                Some(s) => return Err(cx.at(s.span(), "task.approach", "must be finite and >= 0")),
            };
            let dwell = match &tsec.dwell {
                None => 0.3,
                Some(s) if s.get_ref().is_finite() && *s.get_ref() >= 0.0 => *s.get_ref(),
                Some(s) => return Err(cx.at(s.span(), "task.dwell", "must be finite and >= 0")),
            };
            let above = |p: &PoseSec| {
                let mut p = *p;
                p.xyz[2] += a;
                p
            };
            let planned = uses_planner(&cx, tsec)?;
            for (label, p) in [("pick", pick), ("place", place)] {
                let key = format!("task.{label}");
                let approach = to_base(&above(p.get_ref()));
                let step = if planned { Step::Plan(Err(approach)) } else { Step::Pose(approach) };
                push(&mut steps, step, format!("{key} (approach)"), p.span());
                push(&mut steps, Step::Line(to_base(p.get_ref())), key.clone(), p.span());
                if dwell > 0.0 {
                    push(&mut steps, Step::Dwell(dwell), key.clone(), p.span());
                }
                let grip = if label == "pick" { Step::Attach } else { Step::Detach };
                push(&mut steps, grip, key.clone(), p.span());
                push(&mut steps, Step::Line(to_base(&above(p.get_ref()))), format!("{key} (retreat)"), p.span());
            }
            let back = if planned { Step::Plan(Ok(q0.clone())) } else { Step::Joint(q0.clone()) };
            push(&mut steps, back, "initial.q (return)".into(), pick.span());
        }
        "plan" => {
            let target = match (&tsec.goal, &tsec.goal_q) {
                (Some(g), None) => {
                    check_pose(g.get_ref(), "task.goal", g.span())?;
                    Err(to_base(g.get_ref()))
                }
                (None, Some(j)) => Ok(joint_row(j, "task.goal_q")?),
                _ => {
                    return Err(cx.at(
                        file.task.span(),
                        "task.goal",
                        "task type 'plan' needs exactly one of task.goal (a tool pose) and task.goal_q (joint values)",
                    ))
                }
            };
            push(&mut steps, Step::Plan(target), "task.goal".into(), file.task.span());
        }
        "sequence" => {
            let list = tsec.steps.as_ref().ok_or_else(|| need("steps"))?;
            if list.get_ref().is_empty() {
                return Err(cx.at(list.span(), "task.steps", "no steps"));
            }
            for (i, s) in list.get_ref().iter().enumerate() {
                let key = format!("task.steps[{i}]");
                let st = s.get_ref();
                let count = [st.joint.is_some(), st.pose.is_some(), st.line.is_some(), st.dwell.is_some()]
                    .iter()
                    .filter(|b| **b)
                    .count();
                if count != 1 {
                    return Err(cx.at(
                        s.span(),
                        &key,
                        "each step has exactly one of joint, pose, line, dwell",
                    ));
                }
                let step = if let Some(j) = &st.joint {
                    Step::Joint(joint_row(j, &format!("{key}.joint"))?)
                } else if let Some(p) = &st.pose {
                    check_pose(p, &key, s.span())?;
                    Step::Pose(to_base(p))
                } else if let Some(p) = &st.line {
                    check_pose(p, &key, s.span())?;
                    Step::Line(to_base(p))
                } else {
                    let d = st.dwell.expect("counted");
                    if !(d.is_finite() && d > 0.0) {
                        return Err(cx.at(s.span(), &format!("{key}.dwell"), "must be positive"));
                    }
                    Step::Dwell(d)
                };
                push(&mut steps, step, key, s.span());
            }
        }
        other => {
            return Err(cx.at(
                file.task.get_ref().kind.span(),
                "task.type",
                format!(
                    "unknown task type '{other}' (expected joint_waypoints, cartesian_waypoints, line, pick_and_place, plan or sequence)"
                ),
            ))
        }
    }

    // Trajectory.
    let trs = file.trajectory.as_ref().map(|t| t.get_ref());
    let timing = match trs.and_then(|t| t.kind.as_ref()) {
        None => Timing::Quintic,
        Some(k) => match k.get_ref().as_str() {
            "trapezoidal" => Timing::Trapezoidal,
            "quintic" => Timing::Quintic,
            "minimum_jerk" => Timing::MinimumJerk,
            "time_optimal" => Timing::TimeOptimal,
            other => {
                return Err(cx.at(
                    k.span(),
                    "trajectory.type",
                    format!("unknown trajectory type '{other}' (expected trapezoidal, quintic, minimum_jerk or time_optimal)"),
                ))
            }
        },
    };
    let usize_in = |v: &Option<Spanned<usize>>, key: &str, d: usize, lo: usize, hi: usize| match v {
        None => Ok(d),
        Some(s) if (lo..=hi).contains(s.get_ref()) => Ok(*s.get_ref()),
        Some(s) => Err(cx.at(s.span(), key, format!("must be between {lo} and {hi}"))),
    };
    let topp_segments = usize_in(
        &trs.and_then(|t| t.segments.clone()),
        "trajectory.segments",
        200,
        10,
        20_000,
    )?;
    let line_samples = usize_in(
        &trs.and_then(|t| t.line_samples.clone()),
        "trajectory.line_samples",
        41,
        4,
        10_000,
    )?;
    let tool_speed = get_f(
        &cx,
        &trs.and_then(|t| t.tool_speed.clone()),
        "trajectory.tool_speed",
        0.25,
    )?;
    let tool_acceleration = get_f(
        &cx,
        &trs.and_then(|t| t.tool_acceleration.clone()),
        "trajectory.tool_acceleration",
        1.0,
    )?;
    let check_dt = get_f(
        &cx,
        &trs.and_then(|t| t.check_dt.clone()),
        "trajectory.check_dt",
        1e-3,
    )?;

    // Simulation.
    let ssec = file.simulation.as_ref().map(|s| s.get_ref());
    let simulation = if ssec.is_none_or(|s| s.enabled) {
        let elastic = effects.elasticity.is_some();
        let integrator = match ssec.and_then(|s| s.integrator.as_ref()) {
            None if elastic => Integrator::Implicit,
            None => Integrator::Rk4,
            Some(i) => match i.get_ref().as_str() {
                "semi_implicit_euler" => Integrator::SemiImplicitEuler,
                "rk4" => Integrator::Rk4,
                "implicit" => Integrator::Implicit,
                other => {
                    return Err(cx.at(
                        i.span(),
                        "simulation.integrator",
                        format!("unknown integrator '{other}' (expected semi_implicit_euler, rk4 or implicit)"),
                    ))
                }
            },
        };
        let ctrl_name = ssec
            .and_then(|s| s.controller.as_ref())
            .map(|c| (c.get_ref().as_str(), c.span()))
            .unwrap_or(("computed_torque", 0..0));
        let gains = |v: Option<&PerJoint>, key: &str, d: f64| -> Result<Vec<f64>, ScenarioError> {
            match v {
                None => Ok(vec![d; n]),
                Some(v) => {
                    let g = per_joint(&cx, v, key, &names, &vec![d; n])?;
                    positive_all(&cx, v, key, &names, &g, true)?;
                    Ok(g)
                }
            }
        };
        let (kp, kd) = (
            ssec.and_then(|s| s.kp.as_ref()),
            ssec.and_then(|s| s.kd.as_ref()),
        );
        let controller = match ctrl_name.0 {
            "computed_torque" => Controller::ComputedTorque {
                kp: gains(kp, "simulation.kp", 400.0)?,
                kd: gains(kd, "simulation.kd", 40.0)?,
            },
            "pd_gravity" => Controller::PdGravity {
                kp: gains(kp, "simulation.kp", 800.0)?,
                kd: gains(kd, "simulation.kd", 40.0)?,
            },
            "none" => Controller::None,
            other => {
                return Err(cx.at(
                    ctrl_name.1,
                    "simulation.controller",
                    format!(
                    "unknown controller '{other}' (expected computed_torque, pd_gravity or none)"
                ),
                ))
            }
        };
        let dt = get_f(&cx, &ssec.and_then(|s| s.dt.clone()), "simulation.dt", 1e-3)?;
        if dt > 0.1 {
            let sp = ssec
                .and_then(|s| s.dt.as_ref())
                .map(|d| d.span())
                .unwrap_or(0..0);
            return Err(cx.at(
                sp,
                "simulation.dt",
                format!("step {dt} s is too large (at most 0.1 s)"),
            ));
        }
        let duration = match ssec.and_then(|s| s.duration.as_ref()) {
            None => None,
            Some(d) => Some(get_f(&cx, &Some(d.clone()), "simulation.duration", 0.0)?),
        };
        let settle = match ssec.and_then(|s| s.settle.as_ref()) {
            None => 0.5,
            Some(s) if s.get_ref().is_finite() && *s.get_ref() >= 0.0 => *s.get_ref(),
            Some(s) => return Err(cx.at(s.span(), "simulation.settle", "must be finite and >= 0")),
        };
        if let (Some(d), Some(dur)) = (ssec.and_then(|s| s.duration.as_ref()), duration) {
            if dur / dt > 5e7 {
                return Err(cx.at(
                    d.span(),
                    "simulation.duration",
                    "more than 5e7 steps: shorten it or raise the step",
                ));
            }
        }
        let record_rate = get_f(
            &cx,
            &ssec.and_then(|s| s.record_rate.clone()),
            "simulation.record_rate",
            100.0,
        )?;
        Some(SimSettings {
            controller,
            integrator,
            dt,
            duration,
            settle,
            record_rate,
        })
    } else {
        None
    };
    if contact.is_some() && simulation.is_none() {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'contact' needs the simulation (simulation.enabled = false contradicts it)",
        ));
    }

    // Outputs.
    let osec = file.outputs.as_ref().map(|o| o.get_ref());
    let torque_plot = match osec.and_then(|o| o.torque_plot.as_ref()) {
        None => Some(crate::trajectory::PlotFormat::Png),
        Some(p) => match p.get_ref().as_str() {
            "png" => Some(crate::trajectory::PlotFormat::Png),
            "svg" => Some(crate::trajectory::PlotFormat::Svg),
            "none" => None,
            other => {
                return Err(cx.at(
                    p.span(),
                    "outputs.torque_plot",
                    format!("expected png, svg or none (got '{other}')"),
                ))
            }
        },
    };
    let plans = steps.iter().any(|s| matches!(s.step, Step::Plan(_)));
    let planner = planner_settings(&cx, file, dir, &model, plans, &mut warnings)?;
    let part = match &tsec.part {
        None => None,
        Some(p) => {
            let v = p.get_ref();
            if kind != "pick_and_place" {
                return Err(cx.at(
                    p.span(),
                    "task.part",
                    "only a pick_and_place task grasps a part",
                ));
            }
            if !(v.size.iter().all(|x| finite_pos(*x)) && v.xyz.iter().all(|x| x.is_finite())) {
                return Err(cx.at(
                    p.span(),
                    "task.part",
                    "size must be positive and xyz finite",
                ));
            }
            Some(super::planned::Part {
                size: v.size,
                xyz: v.xyz,
            })
        }
    };
    let outputs = Outputs {
        dir: osec.and_then(|o| o.dir.clone()).map(PathBuf::from),
        torque_plot,
        report: osec.and_then(|o| o.report).unwrap_or(true),
        trajectory_csv: osec.and_then(|o| o.trajectory_csv).unwrap_or(false),
        simulation_csv: osec.and_then(|o| o.simulation_csv).unwrap_or(false),
        mcap: osec.and_then(|o| o.mcap).unwrap_or(true),
    };

    Ok(Scene {
        file: fname.clone(),
        name,
        description: file.description.clone(),
        model_path,
        package_paths,
        model,
        spec,
        model_warnings,
        base,
        tool,
        effect_names: named,
        effects,
        payload_masses,
        payload_inertia,
        contact,
        q0,
        limits,
        lower,
        upper,
        check_velocity,
        check_effort: effort,
        obstacles,
        collision,
        self_collision,
        collision_max_step,
        steps,
        task_kind: kind.to_string(),
        position_only: tsec.position_only.unwrap_or(n < 6),
        timing,
        topp_segments,
        line_samples,
        tool_speed,
        tool_acceleration,
        check_dt,
        simulation,
        outputs,
        warnings,
        planner,
        part,
        planner_disabled,
    })
}

/// The `[planner]` settings when the task plans (the table is refused otherwise).
fn planner_settings(
    cx: &Ctx,
    file: &ArmFile,
    dir: &Path,
    model: &Model,
    plans: bool,
    warnings: &mut Vec<String>,
) -> Result<Option<super::planned::PlannerSettings>, ScenarioError> {
    let sec = file.planner.as_ref();
    if !plans {
        return match sec {
            Some(s) => Err(cx.at(
                s.span(),
                "planner",
                "the task plans nothing (use task type 'plan' or task.planner = \"rrt-connect\")",
            )),
            None => Ok(None),
        };
    }
    let p = sec.map(|s| s.get_ref());
    let ms = match p.and_then(|p| p.time_limit_ms.as_ref()) {
        None => 1000.0,
        Some(t) if finite_pos(*t.get_ref()) => *t.get_ref(),
        Some(t) => return Err(cx.at(t.span(), "planner.time_limit_ms", "must be positive")),
    };
    let max_overshoot = match p.and_then(|p| p.max_overshoot.as_ref()) {
        None => 0.01,
        Some(t) if finite_pos(*t.get_ref()) => *t.get_ref(),
        Some(t) => return Err(cx.at(t.span(), "planner.max_overshoot", "must be positive")),
    };
    let srdf = match p.and_then(|p| p.srdf.as_ref()) {
        None => None,
        Some(f) => {
            let path = dir.join(f.get_ref());
            let (pairs, w) = crate::planning::srdf::load_disabled_pairs(&path, model)
                .map_err(|e| cx.at(f.span(), "planner.srdf", e.to_string()))?;
            warnings.extend(w.iter().map(|w| format!("{w}")));
            Some((path.display().to_string(), pairs))
        }
    };
    Ok(Some(super::planned::PlannerSettings {
        seed: p.and_then(|p| p.seed).unwrap_or(0),
        time_limit: std::time::Duration::from_secs_f64(ms / 1e3),
        simplify: p.and_then(|p| p.simplify).unwrap_or(true),
        max_overshoot,
        srdf,
    }))
}

/// Whether a pick-and-place plans its transfers (`task.planner`).
fn uses_planner(cx: &Ctx, tsec: &TaskSec) -> Result<bool, ScenarioError> {
    match &tsec.planner {
        None => Ok(false),
        Some(p) => match p.get_ref().as_str() {
            "rrt-connect" => Ok(true),
            "none" => Ok(false),
            other => Err(cx.at(
                p.span(),
                "task.planner",
                format!("unknown planner '{other}' (expected rrt-connect or none)"),
            )),
        },
    }
}

fn check_in_limits(
    cx: &Ctx,
    v: &PerJoint,
    key: &str,
    names: &[String],
    q: &[f64],
    lower: &[f64],
    upper: &[f64],
) -> Result<(), ScenarioError> {
    for k in 0..q.len() {
        if q[k] < lower[k] - 1e-9 || q[k] > upper[k] + 1e-9 {
            return Err(cx.at(
                v.span(),
                key,
                format!(
                    "joint {}: {} is outside the limits [{}, {}]",
                    names[k], q[k], lower[k], upper[k]
                ),
            ));
        }
    }
    Ok(())
}
