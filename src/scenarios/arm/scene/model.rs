//! The `[model]` section of an arm scenario: the scenario's name, the model file (with
//! `package://` paths and the skeleton capsules for links without collision geometry),
//! the base pose and the tool link.

use crate::collision::resolve::{resolve_spec_meshes, PackagePaths};
use crate::core::diag::LocatedError as ScenarioError;
use crate::core::spatial::{Se3, Vec3};
use crate::model::{Model, ModelSpec, Shape};
use crate::scenarios::arm::scene::section_reader::{closest, get_f};
use crate::scenarios::arm::schema::*;
use crate::scenarios::source::Source;
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The scenario's name: `name`, else the file stem (it names the output files).
pub(super) fn scene_name(
    cx: &Source,
    path: &Path,
    file: &ArmFile,
) -> Result<String, ScenarioError> {
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
    Ok(name)
}

/// The model section read: the model and where it came from, its base pose and tool.
pub(super) struct ModelSection {
    pub model_path: PathBuf,
    pub spec: ModelSpec,
    pub model: Model,
    pub model_warnings: Vec<String>,
    /// Skeleton pairs that touch by construction.
    pub touching: Vec<[String; 2]>,
    pub package_paths: PackagePaths,
    pub base: Se3,
    pub tool: usize,
}

/// Loads the model (skeleton radius from `[collision]`), checks the base pose and finds
/// the tool link; loader notes go to `warnings`.
pub(super) fn load(
    cx: &Source,
    file: &ArmFile,
    dir: &Path,
    package_path: &[PathBuf],
    warnings: &mut Vec<String>,
) -> Result<ModelSection, ScenarioError> {
    // Collision settings (the skeleton changes the model spec).
    let csec = file.collision.as_ref().map(|c| c.get_ref());
    let skeleton = match csec.and_then(|c| c.skeleton_radius.as_ref()) {
        None => None,
        Some(r) => Some(get_f(
            cx,
            &Some(r.clone()),
            "collision.skeleton_radius",
            0.0,
        )?),
    };
    let (model_path, spec, model, model_warnings, notes, touching, package_paths) =
        load_model(cx, dir, &file.model, skeleton, package_path)?;
    // Planning, torques and simulation all use the mass matrix.
    crate::model::data::dense_fits(&model).map_err(|e| {
        cx.at(
            file.model.get_ref().file.span(),
            "model.file",
            e.to_string(),
        )
    })?;
    warnings.extend(notes);
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
    let tool = match &msec.tool {
        Some(t) => link_by_name(cx, &model, t, "model.tool")?,
        None => model.tool_link(),
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
    Ok(ModelSection {
        model_path,
        spec,
        model,
        model_warnings,
        touching,
        package_paths,
        base,
        tool,
    })
}

/// The link called `s` (with a "did you mean" hint when there is none).
pub(super) fn link_by_name(
    cx: &Source,
    model: &Model,
    s: &Spanned<String>,
    key: &str,
) -> Result<usize, ScenarioError> {
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
            let rot = crate::core::spatial::rotation_z_to(&(d / len));
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
    cx: &Source,
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
    cx: &Source,
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
