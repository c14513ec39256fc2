//! Vibration of machines: torsional drivetrain chains ([`torsional`]), flexible rotors
//! ([`rotor`], with exact transfer matrices in [`rotor_transfer`]) and vibration
//! isolation on a one-degree-of-freedom mount ([`isolator`]). Algorithms only: the
//! scenario files and reports of these kinds live in [`crate::scenarios`].
pub mod isolator;
pub mod rotor;
pub mod rotor_transfer;
pub mod torsional;
