//! The leaves every other layer builds on: SE(3) and spatial vectors ([`spatial`]),
//! in-place dense linear algebra ([`linalg`]), fast sine and cosine ([`fastmath`]), the
//! one located error ([`diag`]), bounded input reads and atomic writes ([`files`]), the
//! XML readers' nesting pre-scan ([`xml_guard`]) and the Ctrl-C flag ([`interrupt`]).
pub mod diag;
pub mod fastmath;
pub mod files;
pub mod interrupt;
pub mod least_squares;
pub mod linalg;
pub mod simd_lanes;
pub mod spatial;
pub mod spd_inverse;
pub mod sym6;
pub mod xml_guard;
