//! Synthesised mechanisms run through the linkage solver ([`crate::machines::linkage::sweep`]): the
//! crank-rocker's limit positions and transmission angle, the slider-crank's stroke and
//! time ratio, the slotted lever's swing, and the structural error of a function
//! generator. These are the second route behind every number [`crate::machines::synthesis`]
//! derives from the closed forms.

use crate::machines::linkage::catalog;
use crate::machines::linkage::description::{Driver, Linkage, PlanarLink, Slider, GROUND};
use crate::machines::linkage::fourbar;
use crate::machines::linkage::position::NewtonOptions;
use crate::machines::linkage::sweep::{dead_centres, sweep, Sweep, SweepOptions, TrackError};
use crate::machines::linkage::{wrap_angle, Vec2};
use crate::machines::synthesis::{time_ratio, FunctionMap};
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};

/// The time ratio and the follower's two extreme positions from a full-turn sweep.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LimitCheck {
    /// Crank angles of the two dead centres of the follower (deg, solver frame).
    pub crank_deg: [f64; 2],
    /// Follower positions there (deg for a rocker or lever, length for a slider).
    pub follower: [f64; 2],
    /// Follower travel: swing (deg) or stroke.
    pub travel: f64,
    /// Crank angle between the limits, `|Δφ − 180°|` (deg).
    pub theta_deg: f64,
    /// Time ratio from those crank angles.
    pub time_ratio: f64,
    /// Largest pressure angle over the turn (deg): `|90° − μ|` at the rocker, the rod's
    /// angle to the slide line for a slider-crank.
    pub max_pressure_angle_deg: f64,
    /// Crank angle where it occurs (deg).
    pub max_pressure_at_deg: f64,
}

/// Why a synthesised mechanism could not be checked with the linkage solver.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SynthesisCheckError {
    /// The full-turn sweep stopped before the crank came round.
    #[error("the crank does not turn fully: {0}")]
    CrankStops(TrackError),
    /// The follower does not have exactly two dead centres over a turn.
    #[error("expected two dead centres of {follower} over a turn, found {found}")]
    DeadCentres {
        /// The follower link.
        follower: String,
        /// How many were found.
        found: usize,
    },
    /// No branch of the four-bar closes at the crank angle of the limit position.
    #[error("the four-bar does not close at the limit position")]
    OpenAtLimit,
    /// No branch of the four-bar closes at the first end of the crank range.
    #[error("the four-bar does not close at the first end of the range")]
    OpenAtRangeStart,
    /// A link of the slotted lever has no guessed point (the message is the link's name).
    #[error("{0}")]
    UnplacedLink(String),
    /// The sweep could not start.
    #[error(transparent)]
    Sweep(#[from] TrackError),
    /// The sweep stopped inside the crank range.
    #[error("the four-bar does not cover the crank range: {0}")]
    RangeNotCovered(TrackError),
    /// The tracked branch does not reach a precision point's crank angle.
    #[error("the generator does not reach a precision point")]
    PrecisionPointMissed,
}

fn full_turn(assemble_at: f64) -> SweepOptions {
    SweepOptions {
        from: 0.0,
        to: TAU,
        step: 1f64.to_radians(),
        assemble_at,
        newton: NewtonOptions::default(),
    }
}

/// The two dead centres of the follower link `follower` and the derived time ratio.
fn limits(
    l: &Linkage,
    sw: &Sweep,
    follower: &str,
    angle: bool,
) -> Result<(LimitCheck, f64), SynthesisCheckError> {
    if let Some(e) = &sw.stopped {
        return Err(SynthesisCheckError::CrankStops(e.clone()));
    }
    let t = sw.tracker(l);
    let dc: Vec<_> = dead_centres(&t, &sw.samples)
        .into_iter()
        .filter(|d| d.follower == follower)
        .collect();
    // A dead centre at 0° is found again at 360°.
    let mut uniq: Vec<_> = Vec::new();
    for d in dc {
        let s = d.state.s.rem_euclid(TAU);
        if !uniq
            .iter()
            .any(|(u, _): &(f64, f64)| wrap_angle(u - s).abs() < 1e-7)
        {
            uniq.push((s, d.value));
        }
    }
    if uniq.len() != 2 {
        return Err(SynthesisCheckError::DeadCentres {
            follower: follower.to_string(),
            found: uniq.len(),
        });
    }
    let delta = (uniq[1].0 - uniq[0].0).rem_euclid(TAU);
    let theta = (delta - PI).abs();
    let (v0, v1) = (uniq[0].1, uniq[1].1);
    let travel = if angle {
        wrap_angle(v1 - v0).abs().to_degrees()
    } else {
        (v1 - v0).abs()
    };
    let conv = |v: f64| if angle { v.to_degrees() } else { v };
    Ok((
        LimitCheck {
            crank_deg: [uniq[0].0.to_degrees(), uniq[1].0.to_degrees()],
            follower: [conv(v0), conv(v1)],
            travel,
            theta_deg: theta.to_degrees(),
            time_ratio: time_ratio(theta),
            max_pressure_angle_deg: 0.0,
            max_pressure_at_deg: 0.0,
        },
        delta,
    ))
}

fn point(l: &Linkage, q: &nalgebra::DVector<f64>, name: &str) -> Vec2 {
    let (b, p) = l.find_point(name).expect("catalog point");
    l.point_position(q, b, &p)
}

/// A crank-rocker in the solver's frame (`A = (0, 0)`, `D = (g, 0)`), assembled at crank
/// angle `phi0` on the branch whose `C` is nearest `near`.
pub fn check_four_bar(
    (g, a, b, c): (f64, f64, f64, f64),
    phi0: f64,
    near: Vec2,
) -> Result<LimitCheck, SynthesisCheckError> {
    let l = catalog::four_bar(g, a, b, c);
    let guess = [1.0, -1.0]
        .iter()
        .filter_map(|&m| {
            let (_, pc) = fourbar::position(g, a, b, c, phi0, m)?;
            Some(((pc - near).norm(), m))
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .and_then(|(_, m)| catalog::four_bar_guess(&l, (g, a, b, c), phi0, m))
        .ok_or(SynthesisCheckError::OpenAtLimit)?;
    let sw = sweep(&l, &guess, &full_turn(phi0))?;
    let (mut chk, _) = limits(&l, &sw, "DC", true)?;
    let d = Vec2::new(g, 0.0);
    for st in &sw.samples {
        let (pb, pc) = (point(&l, &st.q, "B"), point(&l, &st.q, "C"));
        let mu = fourbar::transmission_angle(&pb, &pc, &d);
        let pa = (PI / 2.0 - mu).abs().to_degrees();
        if pa > chk.max_pressure_angle_deg {
            chk.max_pressure_angle_deg = pa;
            chk.max_pressure_at_deg = st.s.to_degrees();
        }
    }
    Ok(chk)
}

/// A slider-crank (catalog frame: crank pivot at the origin, slide line `y = e`).
pub fn check_slider_crank(r: f64, l: f64, e: f64) -> Result<LimitCheck, SynthesisCheckError> {
    let lk = catalog::slider_crank(r, l, e);
    let s0 = 45f64.to_radians();
    let guess = catalog::slider_crank_guess(&lk, r, l, e, s0, 1.0);
    let sw = sweep(&lk, &guess, &full_turn(s0))?;
    let (mut chk, _) = limits(&lk, &sw, "slider", false)?;
    for st in &sw.samples {
        let rod = st.q[3 + 2];
        let pa = rod.sin().abs().asin().to_degrees();
        if pa > chk.max_pressure_angle_deg {
            chk.max_pressure_angle_deg = pa;
            chk.max_pressure_at_deg = st.s.to_degrees();
        }
    }
    Ok(chk)
}

/// A crank (pivot `(0, d)`, length `r`) whose pin slides in a lever pivoted at the origin
/// (length `lever`): the lever's swing and the time ratio.
pub fn check_slotted_lever(d: f64, r: f64, lever: f64) -> Result<LimitCheck, SynthesisCheckError> {
    let l = Linkage::with_shared_pins(
        "crank and slotted lever",
        vec![
            ("O2".into(), Vec2::new(0.0, d)),
            ("O4".into(), Vec2::zeros()),
        ],
        vec![
            PlanarLink::binary("crank", "O2", "A", r),
            PlanarLink::binary("lever", "O4", "B", lever),
        ],
        vec![Slider {
            name: "A".into(),
            link: 0,
            p: Vec2::new(r, 0.0),
            guide: 1,
            through: Vec2::zeros(),
            dir: Vec2::new(1.0, 0.0),
            prismatic: None,
        }],
        Driver::Angle {
            link: 0,
            relative_to: GROUND,
        },
    );
    let pa = Vec2::new(r, d);
    let pts: HashMap<String, Vec2> = [
        ("A".to_string(), pa),
        ("B".to_string(), pa * (lever / pa.norm())),
    ]
    .into_iter()
    .collect();
    let guess = l
        .coordinates_from_points(&pts, &[])
        .map_err(|e| SynthesisCheckError::UnplacedLink(e.link))?;
    let sw = sweep(&l, &guess, &full_turn(0.0))?;
    Ok(limits(&l, &sw, "lever", true)?.0)
}

/// A four-bar of frame `d` tracked over a crank range in Freudenstein's frame (signed
/// `a`, `c` allowed: a negative length turns its link by π).
pub struct RockerTrack {
    linkage: Linkage,
    sweep: Sweep,
    phi_off: f64,
    psi_off: f64,
}

impl RockerTrack {
    /// Tracks `(a, b, c, d)` from crank angle `phi[0]` to `phi[1]` (rad) in `samples`
    /// steps, on the branch whose rocker angle at `phi[0]` is nearest `psi0`.
    pub fn new(
        (a, b, c, d): (f64, f64, f64, f64),
        phi: [f64; 2],
        psi0: f64,
        samples: usize,
    ) -> Result<Self, SynthesisCheckError> {
        let phi_off = if a < 0.0 { PI } else { 0.0 };
        let psi_off = if c < 0.0 { PI } else { 0.0 };
        let (aa, cc) = (a.abs(), c.abs());
        let l = catalog::four_bar(d, aa, b, cc);
        let phi0 = phi[0] + phi_off;
        let pl = psi0 + psi_off;
        let near = Vec2::new(d + cc * pl.cos(), cc * pl.sin());
        let guess = [1.0, -1.0]
            .iter()
            .filter_map(|&m| {
                let (_, pc) = fourbar::position(d, aa, b, cc, phi0, m)?;
                Some(((pc - near).norm(), m))
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .and_then(|(_, m)| catalog::four_bar_guess(&l, (d, aa, b, cc), phi0, m))
            .ok_or(SynthesisCheckError::OpenAtRangeStart)?;
        let span = phi[1] - phi[0];
        let opts = SweepOptions {
            from: phi0,
            to: phi0 + span,
            step: span.abs() / samples.max(1) as f64,
            assemble_at: phi0,
            newton: NewtonOptions::default(),
        };
        let sw = sweep(&l, &guess, &opts)?;
        if let Some(e) = &sw.stopped {
            return Err(SynthesisCheckError::RangeNotCovered(e.clone()));
        }
        Ok(Self {
            linkage: l,
            sweep: sw,
            phi_off,
            psi_off,
        })
    }

    /// `(φ, ψ)` at the samples (rad).
    pub fn samples(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.sweep
            .samples
            .iter()
            .map(|st| (st.s - self.phi_off, st.q[3 * 2 + 2] - self.psi_off))
    }

    /// `ψ` at crank angle `phi` (rad), solved on the tracked branch.
    pub fn psi_at(&self, phi: f64) -> Option<f64> {
        let s = phi + self.phi_off;
        let from = self
            .sweep
            .samples
            .iter()
            .min_by(|p, q| (p.s - s).abs().total_cmp(&(q.s - s).abs()))?;
        let st = self.sweep.tracker(&self.linkage).state_near(from, s)?;
        Some(st.q[3 * 2 + 2] - self.psi_off)
    }
}

/// The structural error of a Freudenstein function generator.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StructuralError {
    /// Largest `|ψ_generated − ψ_ideal|` over the range (deg).
    pub max_angle_error_deg: f64,
    /// Largest `|y_generated − f(x)|`.
    pub max_function_error: f64,
    /// `x` where the largest angle error occurs.
    pub at_x: f64,
    /// `|ψ error|` at each precision point (deg): zero up to the solver's tolerance.
    pub at_precision_points_deg: Vec<f64>,
    /// `(x, ψ error in deg)` over the range.
    pub curve: Vec<[f64; 2]>,
}

/// Runs the generator over the crank range of `map` and compares the rocker angle with
/// the ideal one.
pub fn structural_error(
    dims: (f64, f64, f64, f64),
    map: &FunctionMap,
    precision_x: &[f64],
    samples: usize,
) -> Result<StructuralError, SynthesisCheckError> {
    let track = RockerTrack::new(dims, map.phi, map.psi[0], samples)?;
    let mut out = StructuralError {
        max_angle_error_deg: 0.0,
        max_function_error: 0.0,
        at_x: map.x[0],
        at_precision_points_deg: Vec::new(),
        curve: Vec::new(),
    };
    for (phi, psi) in track.samples() {
        let x = map.x_of(phi);
        let ideal = map.psi_of(x);
        let e = wrap_angle(psi - ideal);
        out.curve.push([x, e.to_degrees()]);
        if e.abs().to_degrees() > out.max_angle_error_deg {
            out.max_angle_error_deg = e.abs().to_degrees();
            out.at_x = x;
        }
        let fe = (map.y_of(ideal + e) - map.f.eval(x)).abs();
        out.max_function_error = out.max_function_error.max(fe);
    }
    for &x in precision_x {
        let psi = track
            .psi_at(map.phi_of(x))
            .ok_or(SynthesisCheckError::PrecisionPointMissed)?;
        out.at_precision_points_deg
            .push(wrap_angle(psi - map.psi_of(x)).abs().to_degrees());
    }
    Ok(out)
}
