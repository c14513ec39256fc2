//! Flywheel design beyond [`crate::machines::flywheel::size`] (docs/reference_data.md §M6;
//! problem book ch. 4): turning-moment diagrams given as periodic tables, the speed band, the
//! machine's own inertia, moving the flywheel to another shaft, rim sizing, a time-domain
//! check, a work stroke against a speed-dependent motor, and the deceleration limit of an
//! overload.
//!
//! - **Cycle sizing**: `E(φ) = ∫ (M_d − M_c) dφ` over one period, `ΔE = max E − min E`,
//!   `J_total = ΔE / (ω_m² δ)`, `J_fw = J_total − J_machine`, with
//!   `δ = (ω_max − ω_min)/ω_m`, `ω_m = (ω_max + ω_min)/2`. The torques are piecewise
//!   linear in `φ`; the grid holds every table corner and every zero of `M_d − M_c`, so
//!   the trapezoidal rule ([`crate::machines::flywheel::energy_curve`]) is exact.
//! - **Another shaft** turning at `ω'`: `J' = J (ω/ω')²`. **Rim**: `m = 4 J / D²`,
//!   rim speed `v = ω_max D/2`, thin-ring hoop stress `σ = ρ v²`. `GD² = 4 g J`.
//! - **Time check**: `J_total ω̇ = M_d(φ) − M_c(φ)` by RK4 in time over several periods
//!   from the speed the energy curve gives at `φ = 0`.
//! - **Work stroke** (angle form): a motor `M_d(ω)` against a constant `M_c` over an angle
//!   `Φ` takes the speed from `ω_max` to `ω_min` when
//!   `J = Φ / ∫_{ω_max}^{ω_min} ω dω / (M_d(ω) − M_c)` (Gauss–Legendre); for a linear
//!   motor `M_d − M_c = A − B ω` the integral is
//!   `[−ω/B − (A/B²) ln|A − B ω|]`.
//! - **Overload**: the deceleration stays within `ε_max` when
//!   `J_total ≥ |M_d − M_c| / ε_max`.

use crate::machines::flywheel::energy_curve;
use crate::machines::flywheel::machine_motion::{self, Characteristic};
use serde::Serialize;

/// Standard gravity for `GD²` (m/s²).
pub const G: f64 = 9.81;

/// A periodic torque over the angle of one period.
#[derive(Clone, Debug, PartialEq)]
pub enum Torque {
    /// Constant (N m).
    Constant(f64),
    /// `(φ, M)` corners (rad, N m), increasing `φ` inside `[0, period]`; linear between
    /// them and periodic (the last corner joins the first one of the next period).
    Table(Vec<(f64, f64)>),
}

impl Torque {
    /// `M(φ)` for `φ` in `[0, period]`.
    pub fn eval(&self, phi: f64, period: f64) -> f64 {
        match self {
            Torque::Constant(m) => *m,
            Torque::Table(t) => {
                let x = phi.rem_euclid(period);
                let x = if phi == period { period } else { x };
                let n = t.len();
                // Before the first corner or after the last: wrap through the period.
                let (p0, p1) = match t.iter().position(|(a, _)| *a > x) {
                    Some(0) => ((t[n - 1].0 - period, t[n - 1].1), t[0]),
                    Some(k) => (t[k - 1], t[k]),
                    None => (t[n - 1], (t[0].0 + period, t[0].1)),
                };
                if p1.0 == p0.0 {
                    p1.1
                } else {
                    p0.1 + (p1.1 - p0.1) * (x - p0.0) / (p1.0 - p0.0)
                }
            }
        }
    }

    fn corners(&self) -> Vec<f64> {
        match self {
            Torque::Constant(_) => Vec::new(),
            Torque::Table(t) => t.iter().map(|p| p.0).collect(),
        }
    }
}

/// Result of [`size_cycle`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CycleSizing {
    /// Period (deg).
    pub period_deg: f64,
    /// Mean speed `ω_m` (rad/s).
    pub mean_speed: f64,
    /// `δ`.
    pub speed_fluctuation: f64,
    /// `[ω_min, ω_max]` (rad/s).
    pub speed_band: [f64; 2],
    /// Cycle means of the driving and resisting torques (N m).
    pub mean_drive: f64,
    /// See `mean_drive`.
    pub mean_load: f64,
    /// `∫ (M_d − M_c) dφ` over the period (J): zero in a steady state.
    pub cycle_work: f64,
    /// `ΔE` (J).
    pub energy_fluctuation: f64,
    /// Angles of the largest and smallest energy (deg).
    pub max_energy_at_deg: f64,
    /// See `max_energy_at_deg`.
    pub min_energy_at_deg: f64,
    /// `ΔE / (ω_m² δ)` (kg m²).
    pub required_inertia: f64,
    /// The machine's own reduced inertia (kg m²).
    pub machine_inertia: f64,
    /// `required − machine` (kg m²).
    pub flywheel_inertia: f64,
    /// `GD² = 4 g J_fw` (N m²).
    pub gd2: f64,
    /// The energy curve `(φ deg, E J)`.
    #[serde(skip)]
    pub energy: Vec<(f64, f64)>,
}

/// The integration grid: `points` uniform steps, the table corners, and the zeros of
/// `drive − load` between them.
fn grid(drive: &Torque, load: &Torque, period: f64, points: usize) -> Vec<f64> {
    let mut g: Vec<f64> = (0..=points)
        .map(|k| period * k as f64 / points as f64)
        .chain(drive.corners())
        .chain(load.corners())
        .filter(|x| (0.0..=period).contains(x))
        .collect();
    g.sort_by(f64::total_cmp);
    g.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * period);
    let net = |x: f64| drive.eval(x, period) - load.eval(x, period);
    let mut out = Vec::with_capacity(g.len() * 2);
    for w in g.windows(2) {
        out.push(w[0]);
        let (f0, f1) = (net(w[0]), net(w[1]));
        if f0 * f1 < 0.0 {
            out.push(w[0] + (w[1] - w[0]) * f0 / (f0 - f1));
        }
    }
    out.extend(g.last());
    out
}

/// Sizes the flywheel for one period of `drive` against `load`, mean speed `omega` and
/// coefficient `delta`, with the machine's own inertia `machine`.
pub fn size_cycle(
    drive: &Torque,
    load: &Torque,
    period: f64,
    points: usize,
    (omega, delta): (f64, f64),
    machine: f64,
) -> CycleSizing {
    let phi = grid(drive, load, period, points.max(1));
    let net: Vec<f64> = phi
        .iter()
        .map(|&x| drive.eval(x, period) - load.eval(x, period))
        .collect();
    let md: Vec<f64> = phi.iter().map(|&x| drive.eval(x, period)).collect();
    let e = energy_curve(&phi, &net);
    let work_d = energy_curve(&phi, &md).last().copied().unwrap_or(0.0);
    let cycle_work = e.last().copied().unwrap_or(0.0);
    let (mut imax, mut imin) = (0, 0);
    for k in 0..e.len() {
        if e[k] > e[imax] {
            imax = k;
        }
        if e[k] < e[imin] {
            imin = k;
        }
    }
    let de = e[imax] - e[imin];
    let req = de / (omega * omega * delta);
    CycleSizing {
        period_deg: period.to_degrees(),
        mean_speed: omega,
        speed_fluctuation: delta,
        speed_band: [omega * (1.0 - delta / 2.0), omega * (1.0 + delta / 2.0)],
        mean_drive: work_d / period,
        mean_load: (work_d - cycle_work) / period,
        cycle_work,
        energy_fluctuation: de,
        max_energy_at_deg: phi[imax].to_degrees(),
        min_energy_at_deg: phi[imin].to_degrees(),
        required_inertia: req,
        machine_inertia: machine,
        flywheel_inertia: req - machine,
        gd2: 4.0 * G * (req - machine),
        energy: phi
            .iter()
            .zip(&e)
            .map(|(p, v)| (p.to_degrees(), *v))
            .collect(),
    }
}

/// `J' = J (ω/ω')²`: an inertia on a shaft at `omega` moved to one at `omega_to`.
pub fn transfer_inertia(j: f64, omega: f64, omega_to: f64) -> f64 {
    j * (omega / omega_to).powi(2)
}

/// A thin rim of diameter `d`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Rim {
    /// Diameter (m).
    pub diameter: f64,
    /// `m = 4 J / D²` (kg).
    pub mass: f64,
    /// Rim speed at the top of the band (m/s).
    pub rim_speed: f64,
    /// Hoop stress `ρ v²` (Pa).
    pub hoop_stress: f64,
}

/// The thin rim of diameter `d` and density `rho` holding inertia `j` at top speed
/// `omega_max`.
pub fn rim(j: f64, d: f64, rho: f64, omega_max: f64) -> Rim {
    let v = omega_max * d / 2.0;
    Rim {
        diameter: d,
        mass: 4.0 * j / (d * d),
        rim_speed: v,
        hoop_stress: rho * v * v,
    }
}

/// The time-domain check of a sized flywheel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TimeCheck {
    /// Periods integrated.
    pub periods: usize,
    /// RK4 steps per period.
    pub steps_per_period: usize,
    /// Smallest and largest speed over the last period (rad/s).
    pub speed_band: [f64; 2],
    /// `(max − min)/mean` over the last period.
    pub speed_fluctuation: f64,
    /// `(t, ω)` over all periods.
    #[serde(skip)]
    pub history: Vec<(f64, f64)>,
}

/// Integrates `J φ̈ = M_d(φ) − M_c(φ)` in time by RK4 for `periods` periods from `φ = 0`
/// at speed `omega0`, with a time step of `1/steps` of the mean period.
pub fn time_check(
    drive: &Torque,
    load: &Torque,
    period: f64,
    j: f64,
    omega0: f64,
    (periods, steps): (usize, usize),
) -> TimeCheck {
    let f = |phi: f64| {
        (drive.eval(phi.rem_euclid(period), period) - load.eval(phi.rem_euclid(period), period)) / j
    };
    let h = period / omega0 / steps as f64;
    let (mut t, mut phi, mut w) = (0.0, 0.0, omega0);
    let mut history = vec![(0.0, w)];
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let end = period * periods as f64;
    let mut guard = 0usize;
    while phi < end && guard < 100 * steps * periods {
        guard += 1;
        // State (φ, ω): φ̇ = ω, ω̇ = f(φ).
        let (k1p, k1w) = (w, f(phi));
        let (k2p, k2w) = (w + 0.5 * h * k1w, f(phi + 0.5 * h * k1p));
        let (k3p, k3w) = (w + 0.5 * h * k2w, f(phi + 0.5 * h * k2p));
        let (k4p, k4w) = (w + h * k3w, f(phi + h * k3p));
        phi += h / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
        w += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
        t += h;
        history.push((t, w));
        if phi >= end - period {
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    TimeCheck {
        periods,
        steps_per_period: steps,
        speed_band: [lo, hi],
        speed_fluctuation: (hi - lo) / ((hi + lo) / 2.0),
        history,
    }
}

/// A work stroke against a speed-dependent motor.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stroke {
    /// `∫_{ω_from}^{ω_to} ω dω / (M_d(ω) − M_c)` (rad per kg m²) for a stroke given by its
    /// angle; `∫ dω / (M_d(ω) − M_c)` (s per kg m²) for one given by its duration.
    pub integral: f64,
    /// The same for a linear motor, in closed form (`None` otherwise).
    pub integral_closed_form: Option<f64>,
    /// `J = Φ / integral` (or `T / integral`) (kg m²).
    pub required_inertia: f64,
    /// `J − J_machine`.
    pub flywheel_inertia: f64,
    /// `GD² = 4 g J_fw` (N m²).
    pub gd2: f64,
    /// Speed at the stroke's end by RK4 in time with `J` (rad/s).
    pub time_check_speed: f64,
    /// Duration of the stroke in that run (s).
    pub time_check_duration: f64,
    /// Angle the stroke sweeps in that run (rad).
    pub time_check_angle: f64,
}

/// 16-point Gauss–Legendre nodes and weights on `[−1, 1]` (half of them; symmetric).
const GL16: [(f64, f64); 8] = [
    (0.095_012_509_837_637_44, 0.189_450_610_455_068_5),
    (0.281_603_550_779_258_9, 0.182_603_415_044_923_6),
    (0.458_016_777_657_227_4, 0.169_156_519_395_002_5),
    (0.617_876_244_402_643_7, 0.149_595_988_816_576_7),
    (0.755_404_408_355_003, 0.124_628_971_255_533_9),
    (0.865_631_202_387_831_7, 0.095_158_511_682_492_78),
    (0.944_575_023_073_232_6, 0.062_253_523_938_647_89),
    (0.989_400_934_991_649_9, 0.027_152_459_411_754_09),
];

/// `∫_a^b f` by composite 16-point Gauss–Legendre on `pieces` intervals.
pub fn gauss_legendre(f: &dyn Fn(f64) -> f64, a: f64, b: f64, pieces: usize) -> f64 {
    let h = (b - a) / pieces as f64;
    let mut s = 0.0;
    for k in 0..pieces {
        let mid = a + h * (k as f64 + 0.5);
        for &(x, w) in &GL16 {
            s += w * (f(mid + 0.5 * h * x) + f(mid - 0.5 * h * x));
        }
    }
    s * h / 2.0
}

/// How long a work stroke is: its angle (rad) or its duration (s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StrokeSpan {
    /// The stroke turns the shaft through this angle (rad): `J = Φ / ∫ ω dω/(M_d − M_c)`.
    Angle(f64),
    /// The stroke lasts this long (s): `J = T / ∫ dω/(M_d − M_c)`.
    Duration(f64),
}

/// The flywheel that lets the stroke (`span`: its angle or its duration) against `load`
/// take the speed from `band[1]` down to `band[0]` (or up, if the motor wins), motor
/// `drive(ω)`: `J dω/dt = M_d(ω) − M_c`, so `dφ = J ω dω/(M_d − M_c)` and
/// `dt = J dω/(M_d − M_c)`. `None` when `M_d − M_c` vanishes inside the band (the speed
/// cannot cross it).
pub fn size_stroke(
    drive: &Characteristic,
    load: f64,
    span: StrokeSpan,
    band: [f64; 2],
    machine: f64,
) -> Option<Stroke> {
    let net = |w: f64| drive.eval(w) - load;
    let (lo, hi) = (band[0].min(band[1]), band[0].max(band[1]));
    let (from, to) = if net(hi) < 0.0 { (hi, lo) } else { (lo, hi) };
    let n = 200;
    if (0..=n).any(|k| {
        let w = lo + (hi - lo) * k as f64 / n as f64;
        net(w) * net(from) <= 0.0
    }) {
        return None;
    }
    let by_angle = matches!(span, StrokeSpan::Angle(_));
    let integral = if by_angle {
        gauss_legendre(&|w| w / net(w), from, to, 64)
    } else {
        gauss_legendre(&|w| 1.0 / net(w), from, to, 64)
    };
    // A linear motor M_d − M_c = aa − bb ω in closed form.
    let closed = match drive.0.as_slice() {
        [a, b] if *b != 0.0 => {
            let (aa, bb) = (a - load, -b);
            let log = |w: f64| (aa - bb * w).abs().ln();
            let prim = |w: f64| {
                if by_angle {
                    -w / bb - aa / (bb * bb) * log(w)
                } else {
                    -log(w) / bb
                }
            };
            Some(prim(to) - prim(from))
        }
        _ => None,
    };
    let (StrokeSpan::Angle(size) | StrokeSpan::Duration(size)) = span;
    let j = size / integral;
    let (t_end, w_end, angle) = stroke_time_check(j, drive, load, from, to, span);
    Some(Stroke {
        integral,
        integral_closed_form: closed,
        required_inertia: j,
        flywheel_inertia: j - machine,
        gd2: 4.0 * G * (j - machine),
        time_check_speed: w_end,
        time_check_duration: t_end,
        time_check_angle: angle,
    })
}

/// RK4 in time with `J` from `from`: until the stroke's angle is swept, or for its
/// duration. Returns the time, the speed and the angle at the stroke's end.
fn stroke_time_check(
    j: f64,
    drive: &Characteristic,
    load: f64,
    from: f64,
    to: f64,
    span: StrokeSpan,
) -> (f64, f64, f64) {
    let t_run = match span {
        StrokeSpan::Angle(angle) => angle / (0.5 * (from + to)) * 1.5,
        StrokeSpan::Duration(t) => t,
    };
    let m = machine_motion::integrate(
        j,
        drive,
        &Characteristic(vec![load]),
        from,
        t_run,
        t_run / 20_000.0,
    );
    let last = m.phi.len() - 1;
    let StrokeSpan::Angle(angle) = span else {
        return (m.t[last], m.omega[last], m.phi[last]);
    };
    let k = m.phi.iter().position(|&p| p >= angle).unwrap_or(last);
    if k == 0 {
        return (m.t[0], m.omega[0], m.phi[0]);
    }
    let s = (angle - m.phi[k - 1]) / (m.phi[k] - m.phi[k - 1]);
    (
        m.t[k - 1] + s * (m.t[k] - m.t[k - 1]),
        m.omega[k - 1] + s * (m.omega[k] - m.omega[k - 1]),
        angle,
    )
}

/// `J_total ≥ |M_d − M_c| / ε_max`: the inertia that limits the deceleration under an
/// overload; returns `(J_total, J_total − J_machine)`.
pub fn overload_inertia(drive: f64, load: f64, max_decel: f64, machine: f64) -> (f64, f64) {
    let j = (drive - load).abs() / max_decel;
    (j, j - machine)
}
