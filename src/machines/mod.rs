//! The textbook's machines beyond arms and linkages (TEXTBOOK_SYSTEMS_2): gear trains and
//! gear geometry, cams, friction and efficiency. Each topic is a library module with its
//! scenario `kind`; they share exact arithmetic ([`rational`]) and error location
//! ([`spans`]).
//!
//! - [`gears`]: gear trains (`kind = "gear_train"`, Willis' method, torques with mesh
//!   losses, coaxiality and assembly) and gear geometry (`kind = "gear_pair"`, involute
//!   spur/helical, internal, rack, crossed helical, worm and bevel pairs);
//! - [`cam`]: disc cams (`kind = "cam"`, follower laws, profiles, curvature, pressure
//!   angle, base radius and offset by search);
//! - [`friction`]: friction elements and efficiency (`kind = "friction"`);
//! - [`plots`]: the cam and gear-pair pictures written with `armsim run --out DIR`.

pub mod balancing;
pub mod cams;
pub mod flywheel;
pub mod friction;
pub mod gearing;
pub mod instant_centres;
pub mod linkage;
pub mod synthesis;
pub mod vibration;
