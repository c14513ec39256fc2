//! Disc cams (docs/reference_data.md §M3):
//!
//! - [`laws`]: follower motion laws and dwell–rise–dwell–return timing;
//! - [`profile`]: law cams with translating (knife, roller, flat) and oscillating
//!   (knife, roller) followers: profiles, curvature, pressure angle, base-radius and
//!   offset search;
//! - [`eccentric`]: the circular eccentric cam (translating followers, oscillating flat
//!   face).
pub mod eccentric;
pub mod laws;
pub mod profile;
