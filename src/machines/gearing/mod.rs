//! Gears (docs/reference_data.md §M1 and §M2). One concern per file:
//!
//! - [`train`]: the gear-train description (gears, bodies, carriers, meshes), mesh
//!   frames, mobility and classification;
//! - [`assembly`]: coaxiality, missing tooth counts, equal-spacing assembly and neighbour
//!   conditions;
//! - [`willis`]: exact speeds by Willis' method (null space of the mesh equations);
//! - [`torques`]: torques from equilibrium with mesh efficiencies (relative power flow);
//! - [`rational`]: exact rational numbers for the ratios;
//! - [`involute`]: `inv`, its inverse, thickness at a radius, flank points;
//! - [`pair`]: involute spur/helical pairs (external, internal, rack);
//! - [`crossed_axes`]: crossed helical, worm and bevel pairs;
//! - [`tooth_count_queries`]: the tooth count at which two circles of a gear coincide;
//! - [`tooth_selection`]: standard tooth counts for a required train ratio;
//! - [`cycloids`]: epicycloids and hypocycloids (points, radii, arch areas);
//! - [`cycloidal`]: cycloidal spur pairs (epicycloid faces, hypocycloid flanks);
//! - [`pin_gear`]: pin (lantern) gearing, the gear's flank as the pins' envelope;
//! - [`roots`]: Roots blower rotors and their displacement;
//! - [`pair_design`]: the textbook's pair design for a centre distance (balanced
//!   sliding).
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
pub mod cycloidal;
pub mod cycloids;
pub mod involute;
pub mod pair;
pub mod pair_design;
pub mod pin_gear;
pub mod rational;
pub mod roots;
pub mod tooth_count_queries;
pub mod tooth_selection;
pub mod torques;
pub mod train;
pub mod willis;
