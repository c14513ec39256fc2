//! Study 6, flexible-rotor discretisation: finite-element count against critical-speed
//! error and time, on two rotors whose critical speeds are known without the elements:
//!
//! - **uniform shaft** (docs/reference_data.md FX-3: steel, d = 50 mm, l = 1.5 m, pinned
//!   ends): `ω_n = n² π² sqrt(EI/(μ l⁴))`, the closed form;
//! - **stepped rotor with discs** (a 0.8 m shaft of 60 and 40 mm steps, two discs, an
//!   elastic and a rigid bearing): the exact transfer matrices of
//!   [`crate::machines::vibration::rotor_transfer`] (a second algorithm, no discretisation).
//!
//! Each row is one element count: the first three critical speeds by
//! [`crate::machines::vibration::rotor::fe_modes`], their relative errors, and the time
//! of one eigen-solve. Hermite cubic elements with the consistent mass matrix converge
//! as `h⁴`: the fitted slope of error against elements is about −4, and each higher
//! mode needs more elements for the same error.

use crate::machines::vibration::rotor::{
    fe_modes, pinned_pinned_speed, Bearing, Disc, FlexibleRotor, Segment,
};
use crate::machines::vibration::rotor_transfer::critical_speeds;
use crate::studies::tradeoffs::study_options::Options;
use crate::studies::tradeoffs::study_timing::{log_slope, time_calls, Stats};
use serde::Serialize;

/// Modes compared.
pub const MODES: usize = 3;

/// Sizes of the rotor study.
#[derive(Clone, Debug)]
pub struct RotorConfig {
    /// Element counts.
    pub elements: Vec<usize>,
    /// Timing rounds per count.
    pub rounds: usize,
    /// Target length of a round (ns).
    pub round_ns: f64,
}

impl RotorConfig {
    /// The sizes of `mode`.
    pub fn for_mode(mode: crate::studies::tradeoffs::study_options::StudyMode) -> Self {
        let (elements, rounds, round_ns) = match mode {
            crate::studies::tradeoffs::study_options::StudyMode::Tiny => {
                (vec![2, 4, 8, 16], 5, 2e5)
            }
            crate::studies::tradeoffs::study_options::StudyMode::Quick => {
                (vec![2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64], 15, 1e6)
            }
            crate::studies::tradeoffs::study_options::StudyMode::Full => (
                vec![2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128],
                41,
                2e6,
            ),
        };
        RotorConfig {
            elements,
            rounds,
            round_ns,
        }
    }
}

/// One element count on one rotor.
#[derive(Clone, Debug, Serialize)]
pub struct RotorRow {
    /// Elements asked for (the rotor's stations add a few).
    pub elements: usize,
    /// Nodes used.
    pub nodes: usize,
    /// Critical speeds by finite elements (rad/s), lowest first.
    pub omega: Vec<f64>,
    /// `|ω_FE − ω_ref|/ω_ref` per mode.
    pub relative_error: Vec<f64>,
    /// Time of one eigen-solve (ns).
    pub solve_ns: Stats,
}

/// One rotor of the study.
#[derive(Clone, Debug, Serialize)]
pub struct RotorCase {
    /// Name.
    pub name: String,
    /// Where the reference speeds come from.
    pub reference_method: String,
    /// Reference critical speeds (rad/s).
    pub reference: Vec<f64>,
    /// Rows by element count (counts giving the same mesh as the previous one are left
    /// out).
    pub rows: Vec<RotorRow>,
    /// Fitted slope of `log error` against `log elements` per mode (about −4).
    pub slope: Vec<Option<f64>>,
}

/// Result of the rotor study.
#[derive(Clone, Debug, Serialize)]
pub struct RotorStudy {
    /// The uniform shaft and the stepped rotor.
    pub cases: Vec<RotorCase>,
}

/// The FX-3 shaft, pinned at both ends.
pub fn uniform_shaft() -> FlexibleRotor {
    FlexibleRotor {
        segments: vec![Segment::circular(1.5, 0.05, 0.0, 2.1e11, 7850.0)],
        discs: Vec::new(),
        bearings: vec![
            Bearing {
                at: 0.0,
                stiffness: None,
            },
            Bearing {
                at: 1.5,
                stiffness: None,
            },
        ],
    }
}

/// A stepped shaft with two discs on an elastic and a rigid bearing.
pub fn stepped_rotor() -> FlexibleRotor {
    let s = |l: f64, d: f64| Segment::circular(l, d, 0.0, 2.1e11, 7850.0);
    let disc = |at: f64, mass: f64| Disc {
        at,
        mass,
        unbalance: 0.0,
        phase: 0.0,
    };
    FlexibleRotor {
        segments: vec![s(0.3, 0.06), s(0.3, 0.04), s(0.2, 0.06)],
        discs: vec![disc(0.25, 12.0), disc(0.55, 6.0)],
        bearings: vec![
            Bearing {
                at: 0.0,
                stiffness: Some(5e7),
            },
            Bearing {
                at: 0.8,
                stiffness: None,
            },
        ],
    }
}

fn case(
    opts: &Options,
    cfg: &RotorConfig,
    name: &str,
    rotor: &FlexibleRotor,
    method: &str,
    reference: Vec<f64>,
) -> Result<RotorCase, String> {
    let mut rows = Vec::new();
    for &n in &cfg.elements {
        opts.say(format!("rotor: {name}, {n} elements"));
        let modes = fe_modes(rotor, n, MODES)
            .ok_or_else(|| format!("{name}: no modes with {n} elements"))?;
        if rows
            .last()
            .is_some_and(|r: &RotorRow| r.nodes == modes[0].x.len())
        {
            continue; // the rotor's stations already give this mesh
        }
        let omega: Vec<f64> = modes.iter().map(|m| m.omega).collect();
        let relative_error = omega
            .iter()
            .zip(&reference)
            .map(|(w, r)| (w - r).abs() / r)
            .collect();
        let solve_ns = time_calls(cfg.rounds, cfg.round_ns, |_| {
            std::hint::black_box(fe_modes(rotor, n, MODES));
        });
        rows.push(RotorRow {
            elements: n,
            nodes: modes[0].x.len(),
            omega,
            relative_error,
            solve_ns,
        });
    }
    // The slope over the counts whose error is above the round-off floor.
    let slope = (0..MODES)
        .map(|k| {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .map(|r: &RotorRow| (r.nodes as f64 - 1.0, r.relative_error[k]))
                .filter(|p| p.1 > 1e-11)
                .collect();
            log_slope(&pts)
        })
        .collect();
    Ok(RotorCase {
        name: name.into(),
        reference_method: method.into(),
        reference,
        rows,
        slope,
    })
}

/// Runs the study.
pub fn run(opts: &Options, cfg: &RotorConfig) -> Result<RotorStudy, String> {
    let u = uniform_shaft();
    let (ei, mu) = (u.segments[0].ei, u.segments[0].mu);
    let closed = (1..=MODES)
        .map(|n| pinned_pinned_speed(n, ei, mu, 1.5))
        .collect();
    let s = stepped_rotor();
    // Bracket the third mode from a fine mesh, then the exact determinant's roots.
    let guess = fe_modes(&s, 200, MODES).ok_or("stepped rotor: no modes")?;
    let exact = critical_speeds(&s, guess[MODES - 1].omega * 1.2, 6000);
    if exact.len() < MODES {
        return Err(format!(
            "stepped rotor: the transfer matrices found {} critical speeds",
            exact.len()
        ));
    }
    Ok(RotorStudy {
        cases: vec![
            case(
                opts,
                cfg,
                "uniform shaft (FX-3)",
                &u,
                "closed form n² π² sqrt(EI/(μ l⁴))",
                closed,
            )?,
            case(
                opts,
                cfg,
                "stepped rotor, two discs",
                &s,
                "transfer matrices (exact)",
                exact[..MODES].to_vec(),
            )?,
        ],
    })
}
