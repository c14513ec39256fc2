//! Friction and efficiency (docs/reference_data.md §M4):
//!
//! - [`elements`]: closed forms for inclines, slides, screws, wedges, journals, collars,
//!   rolling, band brakes and belts; efficiency, reverse efficiency, self-locking;
//! - [`friction_circle`]: friction in a linkage's joints by friction circles;
//! - [`two_point_guide`]: a prismatic guide bearing at two points (two normal forces, the
//!   friction `f (|N_a| + |N_b|)`, jamming);
//! - [`connected_bodies`]: bodies on planes joined by ropes over pulleys (Newton's
//!   second law: acceleration, tensions, start and hold forces).

pub mod connected_bodies;
pub mod elements;
pub mod friction_circle;
pub mod two_point_guide;
