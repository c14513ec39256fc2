//! Closed-chain planar mechanisms: loop closure with branch tracking, velocities and
//! accelerations through the constraint Jacobian, mobility, and kinetostatics.
//!
//! The planar formulation is the body-coordinate one of Haug, *Computer-Aided Kinematics
//! and Dynamics of Mechanical Systems* (1989), ch. 3 and 6, and Nikravesh, *Computer-Aided
//! Analysis of Mechanical Systems* (1988), ch. 3–6: every moving link `i` has coordinates
//! `(x_i, y_i, θ_i)` of its centre of mass and angle, and the joints and the driver give
//! constraint equations `Φ(q, s) = 0` with `s` the input (crank angle or slider position).
//!
//! One algorithm per file (the minimum-norm solve they share is
//! [`crate::core::least_squares`]):
//! - [`description`]: the description (ground points, links with named points and inertia,
//!   pins, sliders, the driver);
//! - [`constraints`]: `Φ`, its Jacobian `Φ_q`, `−Φ_t` and the acceleration right side `γ`;
//! - [`higher_pair`], [`contact_rows`]: cam contacts of circles and lines (one row each);
//! - [`position`]: Newton's method on `Φ(q, s) = 0`;
//! - [`velocity`]: `Φ_q q̇ = −Φ_t`, `Φ_q q̈ = γ` by a minimum-norm solve;
//! - [`mobility`]: Grübler's count checked by the rank of `Φ_q`, singular positions;
//! - [`branch`]: the structural groups of the linkage and their assembly-mode signs;
//! - [`sweep`]: continuation over the input with branch tracking, dead centres, extremes;
//! - [`continuation`]: sweeps continued through change points on the smooth motion;
//! - [`fourbar`]: Grashof classification, transmission angle, closed-form four-bar;
//! - [`kinetostatics`]: joint forces and driving effort from `M q̈ − Φ_qᵀ λ = Q`;
//! - [`virtual_power`]: the driving effort from `Σ F·v + M ω = 0`;
//! - [`reduced`]: the reduced moment of inertia `J_red(φ)` and reduced moment `M_red(φ)`;
//! - [`assur`]: the structure (initial mechanism, Assur groups, class);
//! - [`catalog`]: standard linkages (slider-crank, four-bar, Scotch yoke) built in code.
//!
//! Synthesis, centrodes, balancing, flywheels and friction circles are siblings in
//! [`crate::machines`]; loop closure on the spatial tree is
//! [`crate::kinematics::spatial_loop`].

pub mod assur;
pub mod branch;
pub mod catalog;
pub mod constraints;
pub mod contact_rows;
pub mod continuation;
pub mod description;
pub mod fourbar;
pub mod higher_pair;
pub mod kinetostatics;
pub mod mobility;
pub mod planar;
pub mod position;
pub mod reduced;
pub mod sweep;
pub mod velocity;
pub mod virtual_power;
pub use crate::core::least_squares::MinNormSolve;
pub use crate::machines::linkage::description::{
    Driver, Linkage, LinkageError, NoGuessedPoint, PlanarJoint, PlanarLink, Slider, GROUND,
};

pub use crate::machines::linkage::planar::{cross, perp, rotate, wrap_angle, Vec2};
