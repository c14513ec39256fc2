//! The parsed and validated linkage scenario ([`LinkageScenario`] and its parts): what
//! [`super::parse`] builds and [`super::report`] analyses.

use crate::machines::balancing::RotorMass;
use crate::machines::flywheel::machine_motion::Characteristic;
use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::kinetostatics::Loads;
use crate::machines::linkage::sweep::SweepOptions;
use nalgebra::DVector;

/// The `kind` value of these scenario files.
pub const NAME: &str = "linkage";

/// Kinetostatics settings.
#[derive(Clone, Debug)]
pub struct KinetostaticsScenario {
    /// Loads (gravity included).
    pub loads: Loads,
    /// Joint friction (friction circles) in every joint.
    pub friction: Option<PinFriction>,
    /// Inputs (rad or m) at which the text report lists the joint forces.
    pub report_at: Vec<f64>,
}

/// Friction in a linkage's joints: one coefficient, a pin radius per joint.
#[derive(Clone, Debug, PartialEq)]
pub struct PinFriction {
    /// Coefficient `f` of every joint (pins and sliders).
    pub coefficient: f64,
    /// `pin_radius`: the radius of the pins not named in `pin_radii` (m).
    pub default_radius: f64,
    /// Pin radius of each joint, in [`Linkage::joints`] order (m; unused for sliders).
    pub radii: Vec<f64>,
    /// The joints given their own radius, by name.
    pub named: Vec<(String, f64)>,
}

/// Counterweight settings (slider-crank).
#[derive(Clone, Debug)]
pub struct CounterweightScenario {
    /// Crank link.
    pub crank: usize,
    /// Connecting rod.
    pub rod: usize,
    /// Slider link.
    pub slider: usize,
    /// Fraction of the reciprocating mass balanced.
    pub fraction: f64,
    /// Counterweight radius (m).
    pub radius: f64,
    /// Distance of a second counterweight on the rod beyond the crank pin (m): full
    /// static balancing (then `fraction` is 0 and unused).
    pub rod_radius: Option<f64>,
}

/// Flywheel settings.
#[derive(Clone, Debug)]
pub struct FlywheelScenario {
    /// Coefficient of speed fluctuation `δ`.
    pub delta: f64,
    /// Mean speed (rad/s).
    pub speed: f64,
    /// Constant load torque; `None`: the cycle mean of the driving torque.
    pub load: Option<f64>,
    /// A driving torque table `(φ rad, M)`; `None`: the linkage's kinetostatic torque.
    pub table: Option<Vec<(f64, f64)>>,
}

/// The linkage part of a scenario.
#[derive(Clone, Debug)]
pub struct MechanismScenario {
    /// The linkage.
    pub linkage: Linkage,
    /// Assembled coordinates at `sweep.assemble_at` (the guess closed by Newton).
    pub assembly: DVector<f64>,
    /// Sweep settings.
    pub sweep: SweepOptions,
    /// Whether the input is an angle (else a slide, in m).
    pub angle_input: bool,
    /// Input rate `ṡ`.
    pub speed: f64,
    /// Input acceleration `s̈`.
    pub acceleration: f64,
    /// Inputs the text report tabulates.
    pub report_at: Vec<f64>,
    /// Four-bar loop points `[O, A, B, C]` (Grashof, transmission angle at `B`).
    pub four_bar: Option<[String; 4]>,
    /// Points whose paths are reported.
    pub coupler_curves: Vec<String>,
    /// Kinetostatics, if asked for.
    pub kinetostatics: Option<KinetostaticsScenario>,
    /// Counterweight, if asked for.
    pub counterweight: Option<CounterweightScenario>,
    /// Inputs (rad or m) at which every relative instant centre is reported, if asked for.
    pub instant_centres: Option<Vec<f64>>,
    /// Prismatic guides bearing at two points (`[[sliders]] contacts`).
    pub guides: Vec<crate::machines::friction::two_point_guide::TwoPointGuide>,
}

/// Rotor balancing settings.
#[derive(Clone, Debug)]
pub struct RotorScenario {
    /// The masses.
    pub masses: Vec<RotorMass>,
    /// Correction planes `(position, radius)` (one or two).
    pub planes: Vec<(f64, f64)>,
    /// Speed (rad/s) and bearing positions `z_A`, `z_B` (m), for the bearing loads.
    pub bearings: Option<(f64, [f64; 2])>,
}

/// Machine-motion settings.
#[derive(Clone, Debug)]
pub struct MachineScenario {
    /// The machine's constant reduced inertia `J_0` (on its shaft).
    pub inertia: f64,
    /// Gear ratio `u = ω_motor / ω_machine` (1: the motor on the machine shaft).
    pub ratio: f64,
    /// The motor rotor's inertia (on the motor shaft).
    pub motor_inertia: f64,
    /// A position-dependent reduced inertia table `(φ rad, J)` over a turn, added to `J_0`.
    pub inertia_table: Option<Vec<(f64, f64)>>,
    /// Whether the linkage's own `J_red(φ)` (its sweep over a full turn) is added to `J_0`.
    pub inertia_from_linkage: bool,
    /// Motor characteristic `M_motor(ω_motor)`.
    pub drive: Characteristic,
    /// Constant load torque.
    pub load: f64,
    /// Starting speed.
    pub omega0: f64,
    /// End time.
    pub t_end: f64,
    /// Step.
    pub dt: f64,
}

/// A parsed and validated linkage scenario.
#[derive(Clone, Debug)]
pub struct LinkageScenario {
    /// The file.
    pub file: String,
    /// Name.
    pub name: String,
    /// Description.
    pub description: Option<String>,
    /// The linkage, if any.
    pub mechanism: Option<MechanismScenario>,
    /// Flywheel sizing, if asked for.
    pub flywheel: Option<FlywheelScenario>,
    /// Rotor balancing, if any.
    pub rotor: Option<RotorScenario>,
    /// Machine motion, if any.
    pub machine: Option<MachineScenario>,
}
