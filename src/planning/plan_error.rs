//! Errors and warnings of the planning inputs (MoveIt scenes and requests, SRDF, benchmark
//! lists): the model loader's located error, so every message reads
//! `FILE:LINE: ELEMENT: MESSAGE` the same way (elements such as
//! `world.collision_objects[2] 'table'.primitives[0].dimensions`).

/// A problem found while reading a planning input file.
pub type PlanningInputError = crate::model::ModelError;

/// A problem that does not stop reading (an SRDF pair naming an unknown link, a request
/// naming a joint the model does not move); same fields as an error.
pub type PlanningInputWarning = PlanningInputError;
