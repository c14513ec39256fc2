//! Resolution of mesh URIs to files.
//!
//! - `package://pkg/rest`: `pkg` is looked for, in order, in every directory of
//!   `ROS_PACKAGE_PATH` (a directory named `pkg`, or containing a directory `pkg`), under
//!   `share/pkg` of every prefix of `AMENT_PREFIX_PATH` (ROS 2), then in the base directory
//!   (the model file's directory) and each of its ancestors (a directory named `pkg`, or
//!   containing one); the first candidate where `rest` exists wins.
//! - `file:///abs/path` and `file://rel/path`: the path after the scheme, relative paths
//!   taken from the base directory.
//! - Absolute paths as they are; any other path relative to the base directory.
//! - Any other scheme (`http://`, `model://`, …) is an error.

use std::path::{Path, PathBuf};

/// Why a URI did not resolve: a message naming what was searched.
#[derive(Clone, Debug, PartialEq)]
pub struct NotFound(pub String);

fn env_dirs(var: &str) -> Vec<PathBuf> {
    std::env::var_os(var)
        .map(|v| {
            std::env::split_paths(&v)
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        })
        .unwrap_or_default()
}

/// Resolves `uri` against `base` (the directory relative paths start from; `None`: the
/// current directory). Returns an existing file, or what was searched.
pub fn resolve_uri(uri: &str, base: Option<&Path>) -> Result<PathBuf, NotFound> {
    let base_dir: PathBuf = match base {
        Some(b) if !b.as_os_str().is_empty() => b.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if let Some(rest) = uri.strip_prefix("package://") {
        let (pkg, rel) = rest.split_once('/').unwrap_or((rest, ""));
        if pkg.is_empty() || rel.is_empty() {
            return Err(NotFound(
                "malformed package URI (expected package://<package>/<path>)".to_string(),
            ));
        }
        let mut roots: Vec<PathBuf> = Vec::new();
        for d in env_dirs("ROS_PACKAGE_PATH") {
            if d.file_name().is_some_and(|n| n == pkg) {
                roots.push(d.clone());
            }
            roots.push(d.join(pkg));
        }
        for d in env_dirs("AMENT_PREFIX_PATH") {
            roots.push(d.join("share").join(pkg));
        }
        let abs_base = std::fs::canonicalize(&base_dir).unwrap_or(base_dir.clone());
        for a in abs_base.ancestors() {
            if a.file_name().is_some_and(|n| n == pkg) {
                roots.push(a.to_path_buf());
            }
            roots.push(a.join(pkg));
        }
        for r in &roots {
            let f = r.join(rel);
            if f.is_file() {
                return Ok(f);
            }
        }
        let found_pkg: Vec<String> = roots
            .iter()
            .filter(|r| r.is_dir())
            .map(|r| r.display().to_string())
            .collect();
        let rpp = std::env::var("ROS_PACKAGE_PATH").unwrap_or_default();
        return Err(NotFound(if found_pkg.is_empty() {
            format!(
                "package '{pkg}' not found (searched ROS_PACKAGE_PATH = '{rpp}', \
                 AMENT_PREFIX_PATH, and {} and its ancestors)",
                abs_base.display()
            )
        } else {
            format!(
                "'{rel}' not found in package '{pkg}' (package directories: {})",
                found_pkg.join(", ")
            )
        }));
    }
    let path = if let Some(rest) = uri.strip_prefix("file://") {
        PathBuf::from(rest)
    } else if let Some((scheme, _)) = uri.split_once("://") {
        return Err(NotFound(format!("unsupported URI scheme '{scheme}://'")));
    } else {
        PathBuf::from(uri)
    };
    let path = if path.is_absolute() {
        path
    } else {
        base_dir.join(path)
    };
    if path.is_file() {
        Ok(path)
    } else {
        Err(NotFound(format!("no file at {}", path.display())))
    }
}
