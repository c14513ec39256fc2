//! What a trade-offs run is asked for: the size of the studies ([`StudyMode`]) and the
//! [`Options`] of [`super::run`] (mode, progress lines, seed).

use serde::Serialize;

/// How big the studies are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StudyMode {
    /// Seconds: the smoke run the tests use (numbers are real but coarse).
    Tiny,
    /// Under 3 minutes on a 2-core machine.
    Quick,
    /// Under 20 minutes on a 2-core machine.
    Full,
}

impl StudyMode {
    /// Name used in the report.
    pub fn as_str(&self) -> &'static str {
        match self {
            StudyMode::Tiny => "tiny",
            StudyMode::Quick => "quick",
            StudyMode::Full => "full",
        }
    }
}

/// Options of [`super::run`].
#[derive(Clone, Debug)]
pub struct Options {
    /// Study sizes.
    pub mode: StudyMode,
    /// Progress lines on standard error.
    pub progress: bool,
    /// Seed of every random choice (targets, states, sample streams).
    pub seed: u64,
}

impl Options {
    /// `mode` with progress off and the default seed.
    pub fn new(mode: StudyMode) -> Self {
        Self {
            mode,
            progress: false,
            seed: 0x7ade_0ff5,
        }
    }

    /// Prints a progress line to standard error when asked to.
    pub fn say(&self, msg: impl AsRef<str>) {
        if self.progress {
            eprintln!("tradeoffs: {}", msg.as_ref());
        }
    }
}
