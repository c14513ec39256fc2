//! Machine motion: the equation of motion of a machine reduced to its input shaft,
//! `J ω̇ = M_d(ω) − M_load(ω)` (Norton §11.11; the problem book's "motion of a machine"),
//! integrated from a given start by the classical fourth-order Runge–Kutta method, with
//! the angle `φ̇ = ω` carried along.
//!
//! For a linear motor characteristic `M_d = a − b ω` and a constant load `L` the solution
//! is closed form: `ω(t) = ω_s + (ω₀ − ω_s) e^{−b t / J}`, `ω_s = (a − L) / b`; from rest
//! with `J = 0.1`, `M_d = 100 − ω`, `L = 5` this is `ω(t) = 95 (1 − e^{−10 t})`.

use serde::Serialize;

/// A polynomial torque characteristic `M(ω) = Σ c_k ω^k`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Characteristic(pub Vec<f64>);

impl Characteristic {
    /// `M(ω)` by Horner's rule.
    pub fn eval(&self, omega: f64) -> f64 {
        self.0.iter().rev().fold(0.0, |acc, c| acc * omega + c)
    }
}

/// A time history.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MachineMotion {
    /// Times (s).
    pub t: Vec<f64>,
    /// Speeds (rad/s).
    pub omega: Vec<f64>,
    /// Angles (rad).
    pub phi: Vec<f64>,
}

/// Integrates `J ω̇ = M_d(ω) − M_load(ω)` from `omega0` at `t = 0` to `t_end` in steps
/// of (at most) `dt` by RK4.
pub fn integrate(
    inertia: f64,
    drive: &Characteristic,
    load: &Characteristic,
    omega0: f64,
    t_end: f64,
    dt: f64,
) -> MachineMotion {
    let n = (t_end / dt).ceil().max(1.0) as usize;
    let h = t_end / n as f64;
    let f = |w: f64| (drive.eval(w) - load.eval(w)) / inertia;
    let mut out = MachineMotion {
        t: Vec::with_capacity(n + 1),
        omega: Vec::with_capacity(n + 1),
        phi: Vec::with_capacity(n + 1),
    };
    let (mut w, mut phi) = (omega0, 0.0);
    out.t.push(0.0);
    out.omega.push(w);
    out.phi.push(phi);
    for k in 1..=n {
        let k1 = f(w);
        let k2 = f(w + 0.5 * h * k1);
        let k3 = f(w + 0.5 * h * k2);
        let k4 = f(w + h * k3);
        // φ̇ = ω: its RK4 stages are the stage speeds.
        phi += h / 6.0 * (w + 2.0 * (w + 0.5 * h * k1) + 2.0 * (w + 0.5 * h * k2) + (w + h * k3));
        w += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        out.t.push(k as f64 * h);
        out.omega.push(w);
        out.phi.push(phi);
    }
    out
}

/// Closed form for `M_d = a − b ω`, constant load: `ω(t)`.
pub fn linear_speed(inertia: f64, a: f64, b: f64, load: f64, omega0: f64, t: f64) -> f64 {
    let ws = (a - load) / b;
    ws + (omega0 - ws) * (-b * t / inertia).exp()
}

/// Closed form for `M_d = a − b ω`, constant load: `φ(t)` from `φ(0) = 0`.
pub fn linear_angle(inertia: f64, a: f64, b: f64, load: f64, omega0: f64, t: f64) -> f64 {
    let ws = (a - load) / b;
    let tau = inertia / b;
    ws * t + (omega0 - ws) * tau * (1.0 - (-t / tau).exp())
}
