//! The machines of the theory-of-machines texts, as algorithms (no file formats, no
//! pictures; their scenario kinds live in [`crate::scenarios`]):
//!
//! - [`linkage`]: closed-chain planar mechanisms (loop closure, velocities, mobility,
//!   branches, sweeps, kinetostatics);
//! - [`synthesis`]: four-bar and slider-crank synthesis, checked by the linkage solver;
//! - [`instant_centres`]: instant centres and centrodes; [`centrode_fit`]: a centrode's
//!   fitted line or circle;
//! - [`balancing`]: rotor correction masses, slider-crank counterweights, modal balancing
//!   of flexible rotors;
//! - [`flywheel`]: flywheel sizing and design, machine motion reduced to the input shaft;
//! - [`friction`]: friction elements and efficiency, friction circles in joints;
//! - [`gearing`]: gear trains (Willis' method, torques, assembly) and involute, crossed
//!   helical, worm and bevel pair geometry, with exact rational ratios;
//! - [`cams`]: disc cams (follower laws, profiles, curvature, pressure angle);
//! - [`vibration`]: torsional chains, flexible rotors and vibration isolation.

pub mod balancing;
pub mod cams;
pub mod centrode_fit;
pub mod flywheel;
pub mod friction;
pub mod gearing;
pub mod instant_centres;
pub mod linkage;
pub mod synthesis;
pub mod vibration;
