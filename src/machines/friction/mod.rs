//! Friction and efficiency (docs/reference_data.md §M4):
//!
//! - [`elements`]: closed forms for inclines, slides, screws, wedges, journals, collars,
//!   rolling, band brakes and belts; efficiency, reverse efficiency, self-locking;
//! - [`friction_circle`]: friction in a linkage's joints by friction circles.

pub mod elements;
pub mod friction_circle;
