//! Friction and efficiency (TEXTBOOK_SYSTEMS_2 §4), `kind = "friction"`:
//!
//! - [`elements`]: closed forms for inclines, slides, screws, wedges, journals, collars,
//!   rolling, band brakes and belts; efficiency, reverse efficiency, self-locking;
//! - [`scenario`]: the scenario files and their output.

pub mod elements;
pub mod friction_circle;
