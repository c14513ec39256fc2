//! Disc cams (docs/reference_data.md §M3):
//!
//! - [`laws`]: follower motion laws and dwell–rise–dwell–return timing;
//! - [`motion_table`]: motions given as a displacement table or a velocity or
//!   acceleration diagram;
//! - [`profile`]: law cams with translating (knife, roller, flat) and oscillating
//!   (knife, roller) followers, a flat face at any inclination: profiles, curvature,
//!   pressure angle, base-radius and
//!   offset search;
//! - [`given_profile`]: a cam given by its profile (arcs, segments, polygons) and the
//!   follower motion it produces;
//! - [`eccentric`]: the circular eccentric cam (translating followers, oscillating flat
//!   face).
pub mod eccentric;
pub mod given_profile;
pub mod laws;
pub mod motion_table;
pub mod profile;
