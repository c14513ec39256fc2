//! Load errors and warnings: every message names the file, the element and the problem,
//! and the line where the loader knows it. Both are the crate's one located error,
//! [`crate::core::diag::LocatedError`] (its `key` is the element, e.g. `joint 'j3'`).

/// An error found while loading a model file.
pub type ModelError = crate::core::diag::LocatedError;

/// A problem that does not stop loading (e.g. an inertia breaking the triangle
/// inequality, as real files such as iCub's do). `--strict` turns warnings into errors.
pub type ModelWarning = ModelError;
