//! Gear trains (TEXTBOOK_SYSTEMS_2 §1). One concern per file:
//!
//! - [`train`]: the description (gears, bodies, carriers, meshes), mesh frames, mobility
//!   and classification;
//! - [`assembly`]: coaxiality, missing tooth counts, equal-spacing assembly and neighbour
//!   conditions;
//! - [`willis`]: exact speeds by Willis' method (null space of the mesh equations);
//! - [`torques`]: torques from equilibrium with mesh efficiencies (relative power flow);
//! - [`train_scenario`] and [`train_report`]: `kind = "gear_train"` files and output;
//! - [`involute`]: `inv`, its inverse, thickness at a radius, flank points;
//! - [`pair`]: involute spur/helical pairs (external, internal, rack);
//! - [`spatial`]: crossed helical, worm and bevel pairs;
//! - [`design`]: the textbook's pair design for a centre distance (balanced sliding);
//! - [`pair_scenario`] and [`pair_report`]: `kind = "gear_pair"` files and output.
//!
//! ```
//! use armsim::machines::gearing::rational::Ratio;
//! // GT-4's high-ratio differential: i_1C = 2/(−69/68 + 68/67) exactly.
//! let s = Ratio::new(-69, 68).unwrap().plus(Ratio::new(68, 67).unwrap()).unwrap();
//! let i = Ratio::int(2).over(s).unwrap().unwrap();
//! assert_eq!(i, Ratio::int(9112));
//! ```
pub mod assembly;
pub mod crossed_axes;
pub mod involute;
pub mod pair;
pub mod pair_design;
pub mod rational;
pub mod torques;
pub mod train;
pub mod willis;
