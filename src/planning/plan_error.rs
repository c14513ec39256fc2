//! Errors and warnings of the planning inputs (MoveIt scenes and requests, SRDF, benchmark
//! lists): the model loader's located error, so every message reads
//! `FILE:LINE: ELEMENT: MESSAGE` the same way (elements such as
//! `world.collision_objects[2] 'table'.primitives[0].dimensions`); and
//! [`PlanSetupError`], why a planner could not be built for a robot or given a scene.

/// A problem found while reading a planning input file.
pub type PlanningInputError = crate::model::ModelError;

/// A problem that does not stop reading (an SRDF pair naming an unknown link, a request
/// naming a joint the model does not move); same fields as an error.
pub type PlanningInputWarning = PlanningInputError;

/// Why a planner could not be built for a robot, or given a scene's obstacles.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlanSetupError {
    /// The model has no collision geometry the planner can use; `unusable` says why each
    /// geometry was left out.
    #[error(
        "model '{model}' has no collision geometry the planner can use{}",
        unusable_list(unusable)
    )]
    NoGeometry {
        /// The model's name.
        model: String,
        /// One entry per geometry that could not be used, with the reason.
        unusable: Vec<String>,
    },
    /// Collision meshes that are there but cannot be used (see
    /// [`crate::planning::spheres::SphereModel::broken`]).
    #[error("model '{model}': a collision mesh cannot be used: {}", problems.join("; "))]
    BrokenMesh {
        /// The model's name.
        model: String,
        /// One entry per mesh, with the reason.
        problems: Vec<String>,
    },
    /// The stop flag was raised while the allowed-collision matrix was sampled.
    #[error("interrupted while computing the allowed-collision matrix")]
    Interrupted,
    /// The allowed-collision matrix's sampling is over its work budget (refused before it
    /// starts; [`crate::planning::acm::AcmError::OverBudget`]).
    #[error(
        "model '{model}': {problem}: lower `armsim srdf --samples` (or pass its --force) and \
         give the SRDF it writes with --srdf"
    )]
    AcmOverBudget {
        /// The model's name.
        model: String,
        /// The budget, the pairs and the samples.
        problem: crate::planning::acm::AcmError,
    },
    /// An obstacle the planner cannot represent.
    #[error("obstacle '{name}': {problem}")]
    Obstacle {
        /// The obstacle's name.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
}

fn unusable_list(unusable: &[String]) -> String {
    if unusable.is_empty() {
        String::new()
    } else {
        format!(": {}", unusable.join("; "))
    }
}
