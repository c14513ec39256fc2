//! The model file formats: URDF ([`urdf`], armsim's own reader with `FILE:LINE`
//! messages, and its bridge to the ecosystem's `urdf_rs` types), Denavit–Hartenberg
//! tables in TOML ([`dh_table`]) and MoveIt SRDFs ([`srdf`]: the disabled collision
//! pairs). Each reader bounds its input before allocating and returns located errors.
pub mod dh_table;
pub mod srdf;
pub mod urdf;
