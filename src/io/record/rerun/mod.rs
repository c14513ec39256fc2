//! Rerun output of a recording: one file per part of the picture (robot geometry, link
//! motion, plots, obstacles, the transform tree, the workspace cut-away, the viewer
//! blueprint) behind [`rerun_out`]; without the `rerun` feature, `rerun_off.rs` stands in
//! for it with the same API.
#[cfg(feature = "rerun")]
mod rerun_blueprint;
#[cfg(feature = "rerun")]
mod rerun_entities;
#[cfg(feature = "rerun")]
mod rerun_geometry;
#[cfg(feature = "rerun")]
mod rerun_motion;
#[cfg(feature = "rerun")]
mod rerun_obstacles;
/// Rerun output in a build without the `rerun` feature: the same API, every log call
/// refused with [`rerun_sink::RerunError::NotBuilt`].
#[cfg(not(feature = "rerun"))]
#[path = "rerun_off.rs"]
pub mod rerun_out;
#[cfg(feature = "rerun")]
pub mod rerun_out;
#[cfg(feature = "rerun")]
mod rerun_plots;
#[cfg(feature = "rerun")]
mod rerun_recording;
#[cfg(feature = "rerun")]
mod rerun_scene;
pub mod rerun_sink;
#[cfg(feature = "rerun")]
mod rerun_stream;
#[cfg(feature = "rerun")]
mod rerun_tree;
#[cfg(feature = "rerun")]
mod rerun_workspace;
