//! The model file formats: URDF ([`urdf`], armsim's own reader with `FILE:LINE`
//! messages) and Denavit–Hartenberg tables in TOML ([`dh_table`]). Each reader bounds its
//! input before allocating and returns located errors. (SRDFs, a planning input, are read
//! by [`crate::planning::srdf`].)
pub mod dh_table;
pub mod toml_error;
pub mod urdf;
