//! MoveIt inputs: `PlanningScene` YAML → obstacles, `MotionPlanRequest` YAML → start and
//! goal joint values in the model's order, and the layout of MotionBenchMaker benchmark
//! folders (`sceneNNNN.yaml` / `requestNNNN.yaml` pairs, `validity.json`).
//!
//! YAML is read with saphyr, which keeps the line of every node: each error names the
//! file, the line, the element (as a path such as
//! `world.collision_objects[3] 'Cube'.primitives[0].dimensions`) and the problem.
//!
//! **Frames.** Obstacle poses are taken in the world frame, which armsim identifies with
//! the root frame of the robot model (a URDF's root link sits at the world origin):
//! `header.frame_id` may be empty, `world`, `/world`, or a frame the caller adds (e.g. the
//! model's root link name, see [`load_scene_in`]); any other frame is an error, since
//! armsim has no TF tree to resolve it.
//!
//! ```
//! use armsim::planning::moveit::parse_scene;
//! let yaml = "world:\n  collision_objects:\n    - id: table\n      primitives:\n        - {type: box, dimensions: [1.2, 0.8, 0.05]}\n      primitive_poses:\n        - {position: [0.6, 0, -0.025], orientation: [0, 0, 0, 1]}\n";
//! let obstacles = parse_scene(yaml, "scene.yaml", &[]).unwrap();
//! assert_eq!(obstacles[0].name, "table");
//! assert!((obstacles[0].pose.trans.x - 0.6).abs() < 1e-15);
//! ```

mod pose_constraints;
mod problems;
mod request;
mod scene;
mod yaml;

pub use problems::{
    load_validity, parse_validity, problem_pairs, ProblemFiles, ProblemValidity, Validity,
};
pub use request::{parse_request, Request};
pub use scene::{parse_scene, quaternion_matrix, WORLD_FRAMES};

use crate::collision::Obstacle;
use crate::model::Model;
use crate::planning::plan_error::{PlanningInputError, PlanningInputWarning};
use std::path::Path;

/// Reads a file's text, with the error naming it.
fn read(path: &Path) -> Result<(String, String), PlanningInputError> {
    let file = path.display().to_string();
    let text = crate::core::files::read_input_string(path)
        .map_err(|e| PlanningInputError::new(&file, None, "file", format!("cannot read: {e}")))?;
    Ok((text, file))
}

/// Reads a PlanningScene YAML file: one [`Obstacle`] per primitive (named after the
/// object's `id`, then `id/1`, `id/2`, … for its further primitives), in file order.
pub fn load_scene(path: impl AsRef<Path>) -> Result<Vec<Obstacle>, PlanningInputError> {
    load_scene_in(path, &[])
}

/// [`load_scene`], also accepting the frame ids `frames` as the world.
pub fn load_scene_in(
    path: impl AsRef<Path>,
    frames: &[&str],
) -> Result<Vec<Obstacle>, PlanningInputError> {
    let (text, file) = read(path.as_ref())?;
    parse_scene(&text, &file, frames)
}

/// Reads a MotionPlanRequest YAML file for `model` (see [`Request`]): the request and the
/// warnings (joints the file names that the model does not move, ignored goals).
pub fn load_request(
    path: impl AsRef<Path>,
    model: &Model,
) -> Result<(Request, Vec<PlanningInputWarning>), PlanningInputError> {
    let (text, file) = read(path.as_ref())?;
    parse_request(&text, &file, model)
}
