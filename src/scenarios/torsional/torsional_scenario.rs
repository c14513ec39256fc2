//! The parsed torsional scenario ([`TorsionalScenario`], with its [`Identification`]):
//! what [`super::parse`] builds and [`super::report`] computes on.

use crate::machines::vibration::torsional::forced::Excitation;
use crate::machines::vibration::torsional::identify::{DampingParameter, Measurement};
use crate::machines::vibration::torsional::torsional_chain::TorsionalChain;

/// A parsed and validated torsional scenario: what [`super::report`] computes on.
#[derive(Clone, Debug)]
pub struct TorsionalScenario {
    pub(super) file: String,
    pub(super) name: String,
    pub(super) chain: TorsionalChain,
    pub(super) rated: Option<f64>,
    pub(super) exc: Option<Excitation>,
    pub(super) speeds: Option<Vec<f64>>,
    /// Order index, speed (rpm), periods, steps per period.
    pub(super) time_check: Option<(usize, f64, usize, usize)>,
    pub(super) ident: Option<Identification>,
}

/// The damping identification asked for: the chain without the fitted dampers, the
/// parameters, the measurements, the initial and the nominal values.
#[derive(Clone, Debug)]
pub(super) struct Identification {
    pub(super) base: TorsionalChain,
    pub(super) params: Vec<DampingParameter>,
    pub(super) data: Vec<Measurement>,
    pub(super) initial: Vec<f64>,
    pub(super) nominal: Vec<f64>,
    /// Line of `[identification]`, for a fit that fails.
    pub(super) line: usize,
}
