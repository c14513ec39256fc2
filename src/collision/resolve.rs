//! Resolution of mesh URIs to files, the way ROS users expect.
//!
//! - `package://pkg/rest`: `pkg` is looked for, in this order (the first candidate where
//!   `rest` is a file wins):
//!   1. the explicit package paths ([`PackagePaths::explicit`]: `--package-path DIR`, the
//!      scenario key `model.package_path`), each either a directory containing `pkg/` or
//!      the package directory itself;
//!   2. every directory of `ROS_PACKAGE_PATH` (ROS 1), the same two ways;
//!   3. `<prefix>/share/pkg` for every prefix of `AMENT_PREFIX_PATH` (ROS 2);
//!   4. the base directory (the model file's directory) and each of its ancestors: a
//!      directory named `pkg`, or one containing `pkg/`.
//!
//!   A directory "is the package" when it is named `pkg` or its `package.xml` says
//!   `<name>pkg</name>` (a package cloned under another name).
//! - `file:///abs/path` and `file://rel/path`: the path after the scheme, relative paths
//!   taken from the base directory.
//! - Absolute paths as they are; any other path relative to the base directory.
//! - Any other scheme (`http://`, `model://`, …) is an error.
//!
//! The environment is read once into a [`PackagePaths`] through a lookup function, so
//! tests pass their own variables instead of changing the process environment.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// Why a URI did not resolve: a message naming what was searched.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct NotFound(pub String);

/// Where `package://` URIs are looked for, before the model file's own folder tree.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PackagePaths {
    /// Explicit directories (command line, scenario file), searched first.
    pub explicit: Vec<PathBuf>,
    /// `ROS_PACKAGE_PATH`.
    pub ros_package_path: Vec<PathBuf>,
    /// `AMENT_PREFIX_PATH`.
    pub ament_prefix_path: Vec<PathBuf>,
}

fn split(v: Option<OsString>) -> Vec<PathBuf> {
    v.map(|v| {
        std::env::split_paths(&v)
            .filter(|p| !p.as_os_str().is_empty())
            .collect()
    })
    .unwrap_or_default()
}

impl PackagePaths {
    /// `explicit` plus the process's `ROS_PACKAGE_PATH` and `AMENT_PREFIX_PATH`.
    pub fn from_env(explicit: Vec<PathBuf>) -> Self {
        Self::with_env(explicit, |k| std::env::var_os(k))
    }

    /// `explicit` plus the variables as `lookup` gives them (for tests).
    pub fn with_env(explicit: Vec<PathBuf>, lookup: impl Fn(&str) -> Option<OsString>) -> Self {
        PackagePaths {
            explicit,
            ros_package_path: split(lookup("ROS_PACKAGE_PATH")),
            ament_prefix_path: split(lookup("AMENT_PREFIX_PATH")),
        }
    }

    /// Candidate package directories for `pkg`, in search order (they may not exist).
    fn roots(&self, pkg: &str, base: &Path) -> Vec<PathBuf> {
        let mut roots = Vec::new();
        for d in self.explicit.iter().chain(&self.ros_package_path) {
            if is_package(d, pkg) {
                roots.push(d.clone());
            }
            roots.push(d.join(pkg));
        }
        for d in &self.ament_prefix_path {
            roots.push(d.join("share").join(pkg));
        }
        let abs_base = std::fs::canonicalize(base).unwrap_or(base.to_path_buf());
        for a in abs_base.ancestors() {
            if a.file_name().is_some_and(|n| n == pkg) {
                roots.push(a.to_path_buf());
            }
            roots.push(a.join(pkg));
        }
        roots
    }

    fn describe(&self, base: &Path) -> String {
        let show = |v: &[PathBuf]| {
            v.iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(":")
        };
        format!(
            "searched package paths '{}', ROS_PACKAGE_PATH '{}', AMENT_PREFIX_PATH '{}', \
             and {} and its ancestors",
            show(&self.explicit),
            show(&self.ros_package_path),
            show(&self.ament_prefix_path),
            std::fs::canonicalize(base)
                .unwrap_or(base.to_path_buf())
                .display()
        )
    }
}

/// Whether `dir` is the package `pkg`: named so, or its `package.xml` names it.
fn is_package(dir: &Path, pkg: &str) -> bool {
    if dir.file_name().is_some_and(|n| n == pkg) {
        return true;
    }
    // Through the input guard (a FIFO named package.xml must not block), and no
    // deeper than a package manifest needs.
    crate::core::files::read_input_string(&dir.join("package.xml"))
        .ok()
        .filter(|t| crate::core::xml_guard::too_deep(t, 32).is_none())
        .and_then(|t| {
            roxmltree::Document::parse(&t).ok().map(|d| {
                d.descendants()
                    .find(|n| n.has_tag_name("name"))
                    .and_then(|n| n.text())
                    .is_some_and(|n| n.trim() == pkg)
            })
        })
        .unwrap_or(false)
}

/// Resolves `uri` against `base` with the process environment and no explicit package
/// paths. See [`resolve_with`].
pub fn resolve_uri(uri: &str, base: Option<&Path>) -> Result<PathBuf, NotFound> {
    resolve_with(uri, base, &PackagePaths::from_env(Vec::new()))
}

/// Resolves `uri` against `base` (the directory relative paths start from; `None`: the
/// current directory) and `pkgs`. Returns an existing file, or what was searched.
pub fn resolve_with(
    uri: &str,
    base: Option<&Path>,
    pkgs: &PackagePaths,
) -> Result<PathBuf, NotFound> {
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
        let roots = pkgs.roots(pkg, &base_dir);
        if let Some(f) = roots.iter().map(|r| r.join(rel)).find(|f| f.is_file()) {
            return Ok(f);
        }
        if let Some(f) = roots.iter().map(|r| r.join(rel)).find(|f| f.exists()) {
            return Err(NotFound(missing_why(&f)));
        }
        let found_pkg: Vec<String> = roots
            .iter()
            .filter(|r| r.is_dir())
            .map(|r| r.display().to_string())
            .collect();
        return Err(NotFound(if found_pkg.is_empty() {
            format!("package '{pkg}' not found ({})", pkgs.describe(&base_dir))
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
        Err(NotFound(missing_why(&path)))
    }
}

/// Why `path` is not a mesh file: absent, a directory, or not a regular file.
fn missing_why(path: &Path) -> String {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => format!("{} is a directory, not a mesh file", path.display()),
        Ok(_) => format!(
            "{} is not a regular file (a FIFO, device or socket)",
            path.display()
        ),
        Err(_) => format!("no file at {}", path.display()),
    }
}

/// The absolute `file://` URI of an existing file (symbolic links and `..` resolved).
pub fn file_uri(path: &Path) -> String {
    let abs = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    format!("file://{}", abs.display())
}

/// A mesh URI of a model that did not resolve.
#[derive(Clone, Debug, PartialEq)]
pub struct Unresolved {
    /// Link name.
    pub link: String,
    /// `"visual"` or `"collision"`.
    pub kind: &'static str,
    /// The URI as written.
    pub uri: String,
    /// What was searched.
    pub reason: String,
}

/// Replaces every mesh URI of `spec` (visual and collision) that resolves against `base`
/// and `pkgs` by the absolute path of its file, so that later readers need no search
/// paths; returns the ones that did not resolve (left as written).
pub fn resolve_spec_meshes(
    spec: &mut crate::model::ModelSpec,
    base: Option<&Path>,
    pkgs: &PackagePaths,
) -> Vec<Unresolved> {
    let mut missing = Vec::new();
    for link in &mut spec.links {
        let name = link.name.clone();
        let geoms = link
            .visuals
            .iter_mut()
            .map(|g| ("visual", g))
            .chain(link.collisions.iter_mut().map(|g| ("collision", g)));
        for (kind, g) in geoms {
            let crate::model::Shape::Mesh { uri, .. } = &mut g.shape else {
                continue;
            };
            match resolve_with(uri, base, pkgs) {
                Ok(p) => *uri = std::fs::canonicalize(&p).unwrap_or(p).display().to_string(),
                Err(e) => missing.push(Unresolved {
                    link: name.clone(),
                    kind,
                    uri: uri.clone(),
                    reason: e.0,
                }),
            }
        }
    }
    missing
}

#[cfg(test)]
mod tests {
    use crate::collision::resolve::*;
    use std::collections::HashMap;

    /// A fresh directory under the system temp dir, removed on drop.
    struct Tmp(PathBuf);
    impl Tmp {
        fn new(tag: &str) -> Tmp {
            let p = std::env::temp_dir().join(format!(
                "armsim-resolve-{tag}-{}-{:?}",
                std::process::id(),
                std::thread::current().id()
            ));
            let _ = std::fs::remove_dir_all(&p);
            std::fs::create_dir_all(&p).unwrap();
            Tmp(p)
        }
        /// Creates `rel` (and its parents) holding `text`; returns its path.
        fn file(&self, rel: &str, text: &str) -> PathBuf {
            let f = self.0.join(rel);
            std::fs::create_dir_all(f.parent().unwrap()).unwrap();
            std::fs::write(&f, text).unwrap();
            f
        }
    }
    impl Drop for Tmp {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn env(vars: &[(&str, &Path)]) -> impl Fn(&str) -> Option<OsString> {
        let m: HashMap<String, OsString> = vars
            .iter()
            .map(|(k, v)| (k.to_string(), v.as_os_str().to_owned()))
            .collect();
        move |k| m.get(k).cloned()
    }

    const URI: &str = "package://arm_description/meshes/link.stl";

    #[test]
    fn explicit_package_path_containing_or_being_the_package() {
        let t = Tmp::new("explicit");
        let f = t.file("ws/arm_description/meshes/link.stl", "a");
        let model_dir = t.0.join("elsewhere");
        std::fs::create_dir_all(&model_dir).unwrap();
        for dir in [t.0.join("ws"), t.0.join("ws/arm_description")] {
            let pkgs = PackagePaths::with_env(vec![dir], env(&[]));
            assert_eq!(resolve_with(URI, Some(&model_dir), &pkgs), Ok(f.clone()));
        }
        // Not found without it; the message names what was searched.
        let e = resolve_with(
            URI,
            Some(&model_dir),
            &PackagePaths::with_env(vec![], env(&[])),
        )
        .unwrap_err();
        assert!(
            e.0.contains("package 'arm_description' not found") && e.0.contains("ROS_PACKAGE_PATH"),
            "{}",
            e.0
        );
    }

    #[test]
    fn package_xml_names_a_package_cloned_under_another_name() {
        let t = Tmp::new("pkgxml");
        let f = t.file("clone/meshes/link.stl", "a");
        t.file(
            "clone/package.xml",
            "<?xml version=\"1.0\"?><package format=\"2\"><name>arm_description</name></package>",
        );
        let pkgs = PackagePaths::with_env(vec![t.0.join("clone")], env(&[]));
        assert_eq!(resolve_with(URI, Some(&t.0), &pkgs), Ok(f));
    }

    #[test]
    fn ros_package_path_entries_contain_or_are_packages() {
        let t = Tmp::new("rpp");
        let f1 = t.file("a/arm_description/meshes/link.stl", "1");
        let both = std::env::join_paths([t.0.join("none"), t.0.join("a")]).unwrap();
        let lookup = {
            let both = both.clone();
            move |k: &str| (k == "ROS_PACKAGE_PATH").then(|| both.clone())
        };
        let pkgs = PackagePaths::with_env(vec![], lookup);
        assert_eq!(pkgs.ros_package_path.len(), 2);
        assert_eq!(
            resolve_with(URI, Some(&t.0.join("none")), &pkgs),
            Ok(f1.clone())
        );
        let pkgs = PackagePaths::with_env(
            vec![],
            env(&[("ROS_PACKAGE_PATH", &t.0.join("a/arm_description"))]),
        );
        assert_eq!(resolve_with(URI, None, &pkgs), Ok(f1));
    }

    #[test]
    fn ament_prefix_path_uses_share() {
        let t = Tmp::new("ament");
        let f = t.file("install/share/arm_description/meshes/link.stl", "a");
        // A package directly under the prefix is not where ROS 2 installs it.
        t.file("install/arm_description/meshes/link.stl", "wrong");
        let pkgs =
            PackagePaths::with_env(vec![], env(&[("AMENT_PREFIX_PATH", &t.0.join("install"))]));
        assert_eq!(resolve_with(URI, Some(&t.0.join("x")), &pkgs), Ok(f));
    }

    #[test]
    fn model_folder_tree_is_searched_last() {
        let t = Tmp::new("tree");
        // The model lives in repo/arm_description/urdf; the package is an ancestor.
        let in_tree = t.file("repo/arm_description/meshes/link.stl", "tree");
        let urdf_dir = t.0.join("repo/arm_description/urdf");
        std::fs::create_dir_all(&urdf_dir).unwrap();
        let none = PackagePaths::with_env(vec![], env(&[]));
        assert_eq!(
            resolve_with(URI, Some(&urdf_dir), &none).map(|p| std::fs::canonicalize(p).unwrap()),
            Ok(std::fs::canonicalize(&in_tree).unwrap())
        );
        // A sibling folder holding the package is found from a model one level down.
        let sib = t.file("repo2/arm_description/meshes/link.stl", "sib");
        let urdf2 = t.0.join("repo2/robots");
        std::fs::create_dir_all(&urdf2).unwrap();
        assert_eq!(
            resolve_with(URI, Some(&urdf2), &none).map(|p| std::fs::canonicalize(p).unwrap()),
            Ok(std::fs::canonicalize(&sib).unwrap())
        );
        // Every earlier source wins over the tree: explicit, ROS_PACKAGE_PATH, AMENT.
        let ex = t.file("ex/arm_description/meshes/link.stl", "ex");
        let rp = t.file("rp/arm_description/meshes/link.stl", "rp");
        let am = t.file("am/share/arm_description/meshes/link.stl", "am");
        let all = PackagePaths::with_env(
            vec![t.0.join("ex")],
            env(&[
                ("ROS_PACKAGE_PATH", &t.0.join("rp")),
                ("AMENT_PREFIX_PATH", &t.0.join("am")),
            ]),
        );
        assert_eq!(resolve_with(URI, Some(&urdf_dir), &all), Ok(ex));
        let no_ex = PackagePaths {
            explicit: vec![],
            ..all.clone()
        };
        assert_eq!(resolve_with(URI, Some(&urdf_dir), &no_ex), Ok(rp));
        let only_am = PackagePaths {
            ros_package_path: vec![],
            ..no_ex
        };
        assert_eq!(resolve_with(URI, Some(&urdf_dir), &only_am), Ok(am));
    }

    #[test]
    fn missing_file_in_a_found_package_names_the_package_directory() {
        let t = Tmp::new("missing");
        t.file("ws/arm_description/meshes/other.stl", "a");
        let pkgs = PackagePaths::with_env(vec![t.0.join("ws")], env(&[]));
        let e = resolve_with(URI, Some(&t.0), &pkgs).unwrap_err().0;
        assert!(
            e.contains("'meshes/link.stl' not found in package 'arm_description'")
                && e.contains("ws/arm_description"),
            "{e}"
        );
        assert!(resolve_with("package://x", None, &pkgs)
            .unwrap_err()
            .0
            .contains("malformed"));
        assert!(resolve_with("http://x/y.stl", None, &pkgs)
            .unwrap_err()
            .0
            .contains("unsupported URI scheme 'http://'"));
    }

    #[test]
    fn file_uri_is_absolute_and_resolves_back() {
        let t = Tmp::new("fileuri");
        let f = t.file("m/x.stl", "a");
        let u = file_uri(&t.0.join("m/../m/x.stl"));
        assert!(u.starts_with("file:///") && !u.contains(".."), "{u}");
        assert_eq!(
            resolve_with(&u, None, &PackagePaths::default()),
            Ok(std::fs::canonicalize(&f).unwrap())
        );
    }
}
