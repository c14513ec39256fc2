//! Benchmark folders: `sceneNNNN.yaml` / `requestNNNN.yaml` pairs in a folder, and the
//! `validity.json` that says which problems have a collision-free start and goal.

use crate::planning::plan_error::PlanningInputError;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One problem of a benchmark folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ProblemFiles {
    /// The problem id: the `NNNN` of the file names (digits, as written).
    pub id: String,
    /// `sceneNNNN.yaml`.
    pub scene: PathBuf,
    /// `requestNNNN.yaml`.
    pub request: PathBuf,
}

/// The problems of folder `dir`, paired by id and sorted by it (numerically). Other files
/// are ignored; a scene without its request (or the reverse) is an error, and so is a
/// folder without any pair.
pub fn problem_pairs(dir: impl AsRef<Path>) -> Result<Vec<ProblemFiles>, PlanningInputError> {
    let dir = dir.as_ref();
    let file = dir.display().to_string();
    let err = |msg: String| PlanningInputError::new(&file, None, "folder", msg);
    let entries = std::fs::read_dir(dir).map_err(|e| err(format!("cannot list: {e}")))?;
    let mut scenes: BTreeMap<(u64, String), PathBuf> = BTreeMap::new();
    let mut requests: BTreeMap<(u64, String), PathBuf> = BTreeMap::new();
    for e in entries {
        let e = e.map_err(|e| err(format!("cannot list: {e}")))?;
        let name = e.file_name().to_string_lossy().into_owned();
        for (prefix, map) in [("scene", &mut scenes), ("request", &mut requests)] {
            if let Some(id) = problem_id(&name, prefix) {
                let key = (id.parse::<u64>().unwrap_or(u64::MAX), id.to_string());
                map.insert(key, e.path());
            }
        }
    }
    for (a, b, what) in [
        (&scenes, &requests, "request"),
        (&requests, &scenes, "scene"),
    ] {
        if let Some(((_, id), path)) = a.iter().find(|(k, _)| !b.contains_key(k)) {
            return Err(err(format!(
                "{} has no {what}{id}.yaml beside it",
                path.display()
            )));
        }
    }
    if scenes.is_empty() {
        return Err(err(
            "no sceneNNNN.yaml / requestNNNN.yaml pairs in this folder".to_string(),
        ));
    }
    Ok(scenes
        .into_iter()
        .zip(requests)
        .map(|(((_, id), scene), (_, request))| ProblemFiles { id, scene, request })
        .collect())
}

/// `NNNN` of `{prefix}NNNN.yaml` (one or more ASCII digits).
fn problem_id<'n>(name: &'n str, prefix: &str) -> Option<&'n str> {
    let id = name.strip_prefix(prefix)?.strip_suffix(".yaml")?;
    (!id.is_empty() && id.bytes().all(|b| b.is_ascii_digit())).then_some(id)
}

/// `validity.json` of a benchmark robot folder.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Validity {
    /// Robot name.
    pub robot: String,
    /// The planned joints, in order.
    pub joints: Vec<String>,
    /// Per scene folder, its problems in order.
    pub problems: BTreeMap<String, Vec<ProblemValidity>>,
}

/// Whether one problem's start and goal are collision-free.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProblemValidity {
    /// Problem id (`NNNN`).
    pub problem: String,
    /// Start and goal both collision-free.
    pub valid: bool,
}

impl Validity {
    /// Whether problem `id` of scene `scene` is valid, if listed.
    pub fn is_valid(&self, scene: &str, id: &str) -> Option<bool> {
        self.problems
            .get(scene)?
            .iter()
            .find(|p| p.problem == id)
            .map(|p| p.valid)
    }
}

/// Reads a `validity.json`.
pub fn load_validity(path: impl AsRef<Path>) -> Result<Validity, PlanningInputError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let text = crate::core::files::read_input_string(path)
        .map_err(|e| PlanningInputError::new(&file, None, "file", format!("cannot read: {e}")))?;
    parse_validity(&text, &file)
}

/// Parses `validity.json` text read from `file` (used in messages).
pub fn parse_validity(text: &str, file: &str) -> Result<Validity, PlanningInputError> {
    serde_json::from_str(text)
        .map_err(|e| PlanningInputError::new(file, Some(e.line().max(1)), "JSON", e.to_string()))
}
