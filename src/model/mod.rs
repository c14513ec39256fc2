//! The immutable [`Model`] of a mechanism: a kinematic tree of links and joints, compiled
//! from a [`ModelSpec`] (URDF, DH table or generated chain) into flat arrays for the hot
//! paths.
//!
//! Compilation (see [`Model::build`]):
//! - the tree is walked depth-first (children in file order, iteratively, so deep chains
//!   cannot overflow the stack); that order is **the joint order** every command uses;
//! - every movable joint becomes a *body*; a joint about ±x, ±y or ±z keeps its URDF
//!   frame (the sign folds into the coordinate's multiplier), any other axis gets a body
//!   frame rotated so that the axis is its local z: every body then moves by `Rx/Ry/Rz(q)`
//!   or `Tx/Ty/Tz(q)`;
//! - fixed joints are folded away: their links become frames rigidly attached to a body
//!   (or to the world), still queryable by name, and their inertias are merged into the
//!   body they ride on;
//! - mimic joints (`q = multiplier * q_master + offset`) are bodies without a coordinate
//!   of their own: they read the master's coordinate.

mod body_frames;
mod build;
pub mod chain;
mod compiled;
pub mod data;
pub mod derivative_data;
pub mod model_limits;
pub use model_limits::MAX_LENGTH;
mod ids;
mod inertia_check;
mod joint_transform;
mod mimic;
mod model_error;
pub mod parse;
mod sampling;
mod spec;
mod spec_check;

pub(crate) use crate::model::joint_transform::AxisX;
pub use crate::model::model_error::{ModelError, ModelWarning};
use build::Builder;
pub use compiled::{BodyKind, Joint, Link, Model, WORLD};
pub use ids::{FrameId, JointId};
pub use inertia_check::{clamp_tolerance, CLAMP_ABS, CLAMP_REL};
pub use spec::{Geometry, JointSpec, JointType, Limits, LinkSpec, MimicSpec, ModelSpec, Shape};

use std::path::Path;

/// How to load a model file.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions {
    /// Turn warnings into errors.
    pub strict: bool,
    /// Treat mimic joints as independent coordinates.
    pub ignore_mimic: bool,
}

impl Model {
    /// Loads a model file, choosing the loader by extension (`.urdf`/`.xml` or `.toml`).
    /// Returns the model and the warnings.
    pub fn load(path: impl AsRef<Path>) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::load_with(path, &LoadOptions::default())
    }

    /// [`Model::load_with`] with only `strict` set.
    pub fn load_checked(
        path: impl AsRef<Path>,
        strict: bool,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::load_with(
            path,
            &LoadOptions {
                strict,
                ignore_mimic: false,
            },
        )
    }

    /// Reads a model file into a [`ModelSpec`] without validating the tree.
    pub fn read_spec(path: &Path) -> Result<ModelSpec, ModelError> {
        let file = path.display().to_string();
        let text = crate::core::files::read_input_string(path)
            .map_err(|e| ModelError::new(&file, None, "file", format!("cannot read: {e}")))?;
        Self::spec_from_str(&text, &file)
    }

    /// Parses model text into a [`ModelSpec`] without touching the filesystem (the
    /// string form of [`Model::read_spec`], used by the fuzz targets): `file` names the
    /// text in messages and its extension picks the loader (`.urdf`/`.xml` or `.toml`).
    pub fn spec_from_str(text: &str, file: &str) -> Result<ModelSpec, ModelError> {
        if text.trim().is_empty() {
            return Err(ModelError::new(file, None, "file", "the file is empty"));
        }
        let ext = Path::new(file)
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "urdf" | "xml" => parse::urdf::parse(text, file),
            "toml" => parse::dh_table::parse(text, file),
            _ => Err(ModelError::new(
                file,
                None,
                "file",
                "unknown model format: expected a .urdf or a .toml (DH table) file",
            )),
        }
    }

    /// Loads with options: `strict` fails on warnings; `ignore_mimic` makes every mimic
    /// joint an independent coordinate (as Pinocchio's default URDF parser does).
    pub fn load_with(
        path: impl AsRef<Path>,
        opts: &LoadOptions,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::build_with(Self::read_spec(path.as_ref())?, opts)
    }

    /// [`Model::load_with`] on text instead of a file: `file` names the text in messages
    /// and its extension picks the loader (see [`Model::spec_from_str`]).
    pub fn load_str(
        text: &str,
        file: &str,
        opts: &LoadOptions,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::build_with(Self::spec_from_str(text, file)?, opts)
    }

    fn build_with(
        mut spec: ModelSpec,
        opts: &LoadOptions,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        if opts.ignore_mimic {
            for j in &mut spec.joints {
                j.mimic = None;
            }
        }
        let (m, w) = Model::build(spec)?;
        if opts.strict {
            if let Some(first) = w.into_iter().next() {
                return Err(first);
            }
            return Ok((m, Vec::new()));
        }
        Ok((m, w))
    }

    /// Validates a spec and compiles it (see the module docs). The warnings start with
    /// the reader's ([`ModelSpec::warnings`]).
    pub fn build(mut spec: ModelSpec) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        let mut warnings = std::mem::take(&mut spec.warnings);
        for l in spec.links.iter_mut() {
            warnings.extend(inertia_check::check(l, &spec.source)?);
        }
        Builder {
            spec: &spec,
            warnings,
        }
        .build()
    }
}
