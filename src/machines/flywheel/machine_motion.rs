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

/// A position-dependent reduced inertia `J(φ)` over one period of the machine shaft: a
/// table of `(φ, J, dJ/dφ)`, cubic Hermite between the rows, periodic with `period`.
#[derive(Clone, Debug, PartialEq)]
pub struct InertiaTable {
    phi: Vec<f64>,
    j: Vec<f64>,
    dj: Vec<f64>,
    period: f64,
}

impl InertiaTable {
    /// Rows `(φ, J)` with increasing `φ` inside one `period`, cubic Hermite between them
    /// with the slopes of the neighbouring rows (periodic: the last row's neighbour is the
    /// first a period on), so `J` and `J'` are continuous and the integrator meets no kink.
    pub fn smooth(phi: Vec<f64>, j: Vec<f64>, period: f64) -> Self {
        let n = phi.len();
        let at = |k: isize| {
            let m = k.rem_euclid(n as isize) as usize;
            let turns = k.div_euclid(n as isize) as f64;
            (phi[m] + turns * period, j[m])
        };
        let dj = (0..n as isize)
            .map(|k| {
                let ((x0, y0), (x1, y1)) = (at(k - 1), at(k + 1));
                if n == 1 {
                    0.0
                } else {
                    (y1 - y0) / (x1 - x0)
                }
            })
            .collect();
        Self::hermite(phi, j, dj, period)
    }

    /// Rows `(φ, J, dJ/dφ)`, cubic Hermite between them.
    pub fn hermite(phi: Vec<f64>, j: Vec<f64>, dj: Vec<f64>, period: f64) -> Self {
        Self { phi, j, dj, period }
    }

    /// `(J(φ), dJ/dφ)`.
    pub fn eval(&self, phi: f64) -> (f64, f64) {
        let n = self.phi.len();
        if n == 1 {
            return (self.j[0], 0.0);
        }
        let x = self.phi[0] + (phi - self.phi[0]).rem_euclid(self.period);
        let k = self.phi.partition_point(|&p| p <= x).saturating_sub(1);
        let (k1, x1) = if k + 1 < n {
            (k + 1, self.phi[k + 1])
        } else {
            (0, self.phi[0] + self.period)
        };
        let h = x1 - self.phi[k];
        let t = (x - self.phi[k]) / h;
        let (j0, j1) = (self.j[k], self.j[k1]);
        let (m0, m1) = (self.dj[k] * h, self.dj[k1] * h);
        let (t2, t3) = (t * t, t * t * t);
        let val = (2.0 * t3 - 3.0 * t2 + 1.0) * j0
            + (t3 - 2.0 * t2 + t) * m0
            + (-2.0 * t3 + 3.0 * t2) * j1
            + (t3 - t2) * m1;
        let der = ((6.0 * t2 - 6.0 * t) * j0
            + (3.0 * t2 - 4.0 * t + 1.0) * m0
            + (-6.0 * t2 + 6.0 * t) * j1
            + (3.0 * t2 - 2.0 * t) * m1)
            / h;
        (val, der)
    }

    /// Smallest and largest tabulated `J`.
    pub fn range(&self) -> (f64, f64) {
        let lo = self.j.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = self.j.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    }
}

/// A motor driving a machine through a gear of ratio `u = ω_motor/ω` (problem book ch. 4),
/// everything reduced to the machine shaft:
///
/// ```text
/// J(φ) = J_motor u² + J_0 + J_table(φ),     M(ω) = u M_motor(u ω) − M_load(ω),
/// J(φ) ω̇ + ½ J'(φ) ω² = M(ω)               (Lagrange's equation of the reduced model).
/// ```
///
/// Its kinetic energy `½ J(φ) ω²` changes by the work `∫ M dφ` ([`GearedMotion::work`]).
#[derive(Clone, Debug)]
pub struct GearedMachine<'a> {
    /// `u = ω_motor / ω_machine`.
    pub ratio: f64,
    /// The motor rotor's inertia (on the motor shaft).
    pub motor_inertia: f64,
    /// The machine's constant reduced inertia (on its shaft).
    pub inertia: f64,
    /// The machine's position-dependent reduced inertia, added to `inertia`.
    pub table: Option<&'a InertiaTable>,
    /// The motor characteristic `M_motor(ω_motor)`.
    pub drive: &'a Characteristic,
    /// The load on the machine shaft `M_load(ω)`.
    pub load: &'a Characteristic,
}

impl GearedMachine<'_> {
    /// `(J(φ), J'(φ))` on the machine shaft.
    pub fn reduced_inertia(&self, phi: f64) -> (f64, f64) {
        let (jt, djt) = self.table.map_or((0.0, 0.0), |t| t.eval(phi));
        let u = self.ratio;
        (self.motor_inertia * u * u + self.inertia + jt, djt)
    }

    /// `M(ω) = u M_motor(u ω) − M_load(ω)` on the machine shaft.
    pub fn torque(&self, omega: f64) -> f64 {
        self.ratio * self.drive.eval(self.ratio * omega) - self.load.eval(omega)
    }
}

/// A time history of a [`GearedMachine`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GearedMotion {
    /// Times (s).
    pub t: Vec<f64>,
    /// Machine speeds (rad/s).
    pub omega: Vec<f64>,
    /// Machine angles (rad).
    pub phi: Vec<f64>,
    /// Work of `M` from the start, `∫ M(ω) ω dt` (J).
    pub work: Vec<f64>,
}

/// Integrates a [`GearedMachine`] from `(φ₀, ω₀)` to `t_end` by RK4 in steps of (at
/// most) `dt`, the state `(φ, ω, W)`.
pub fn integrate_geared(
    m: &GearedMachine,
    (phi0, omega0): (f64, f64),
    t_end: f64,
    dt: f64,
) -> GearedMotion {
    let n = (t_end / dt).ceil().max(1.0) as usize;
    let h = t_end / n as f64;
    let f = |y: [f64; 3]| {
        let (j, dj) = m.reduced_inertia(y[0]);
        let torque = m.torque(y[1]);
        [y[1], (torque - 0.5 * dj * y[1] * y[1]) / j, torque * y[1]]
    };
    let add =
        |y: [f64; 3], k: [f64; 3], s: f64| [y[0] + s * k[0], y[1] + s * k[1], y[2] + s * k[2]];
    let mut out = GearedMotion {
        t: vec![0.0],
        omega: vec![omega0],
        phi: vec![phi0],
        work: vec![0.0],
    };
    let mut y = [phi0, omega0, 0.0];
    for k in 1..=n {
        let k1 = f(y);
        let k2 = f(add(y, k1, 0.5 * h));
        let k3 = f(add(y, k2, 0.5 * h));
        let k4 = f(add(y, k3, h));
        for i in 0..3 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        out.t.push(k as f64 * h);
        out.phi.push(y[0]);
        out.omega.push(y[1]);
        out.work.push(y[2]);
    }
    out
}
