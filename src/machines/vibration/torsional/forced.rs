//! Forced steady state per harmonic order, speed sweeps and the critical-speed table
//! (docs/reference_data.md §S3).
//!
//! **Excitation.** Cylinder `j` (a disk of the chain) fires at crank angle `α_j`; the
//! order-`k` harmonic of its torque at shaft speed `w` is
//! `M_j(t) = A_k cos(k (w t − α_j)) = M_s,j sin νt + M_c,j cos νt`, `ν = k w`, with
//! `M_s,j = A_k sin kα_j`, `M_c,j = A_k cos kα_j`. (Half orders of four-stroke engines
//! work the same way with `α` in 0…720°.)
//!
//! **Steady state.** With `φ = S sin νt + C cos νt`, `J φ̈ + B φ̇ + K φ = M` splits into
//! the real 2n system
//! `[[K − ν²J, −νB], [νB, K − ν²J]] [S; C] = [M_s; M_c]`,
//! solved by LU. Amplitudes `|φ_k| = sqrt(S_k² + C_k²)`, shaft torque amplitudes
//! `c_k |φ_{k+1} − φ_k|`. (In phasors `φ = Re(X e^{iνt})`, `X = C − iS`, this is
//! `(K − ν²J + iνB) X = M_c − i M_s`, the form [`crate::machines::vibration::torsional::identify`]
//! differentiates.)
//!
//! **Critical speeds.** Mode `r` (frequency `f_r` in cycles/min) is excited by order `k`
//! at `n = f_r / k` rpm. How strongly depends on the phase sum
//! `Σ_cyl x_cyl e^{i k α_cyl}` of the (undamped) shape over the cylinders: the modal
//! work of order `k`. Its magnitude is reported, and relative to `Σ |x_cyl|` (1 when all
//! cylinders act in phase on this mode: a "major" order; for a two-stroke six with
//! firing angles 0, 120, 240, 180, 300, 60° every `kα` is a multiple of 360° for k = 6,
//! 12, …).

use crate::machines::vibration::torsional::modes::Mode;
use crate::machines::vibration::torsional::torsional_chain::{ChainError, TorsionalChain};
use nalgebra::{Complex, DMatrix, DVector};

/// rad/s per rpm.
pub const RAD_S_PER_RPM: f64 = std::f64::consts::PI / 30.0;

/// Engine excitation: cylinders, firing angles and one amplitude per harmonic order.
#[derive(Clone, Debug, PartialEq)]
pub struct Excitation {
    /// Disk index of each cylinder.
    pub cylinders: Vec<usize>,
    /// Firing angle of each cylinder (degrees of crank angle).
    pub firing_angles_deg: Vec<f64>,
    /// Harmonic orders `k` (per revolution).
    pub orders: Vec<f64>,
    /// Amplitude `A_k` (N m) of each order, per cylinder.
    pub amplitudes: Vec<f64>,
}

impl Excitation {
    /// Checks the sizes against a chain of `n` disks.
    pub fn validate(&self, n: usize) -> Result<(), ChainError> {
        if self.firing_angles_deg.len() != self.cylinders.len() {
            return Err(ChainError::new(
                "firing_angles_deg",
                None,
                format!(
                    "{} firing angles for {} cylinders",
                    self.firing_angles_deg.len(),
                    self.cylinders.len()
                ),
            ));
        }
        if let Some(i) = self.cylinders.iter().position(|&c| c >= n) {
            return Err(ChainError::new("cylinders", Some(i), "no such disk"));
        }
        if self.amplitudes.len() != self.orders.len() {
            return Err(ChainError::new(
                "amplitude",
                None,
                format!(
                    "{} amplitudes for {} orders",
                    self.amplitudes.len(),
                    self.orders.len()
                ),
            ));
        }
        for (i, k) in self.orders.iter().enumerate() {
            if !(k.is_finite() && *k > 0.0) {
                return Err(ChainError::new(
                    "orders",
                    Some(i),
                    "orders must be positive numbers",
                ));
            }
        }
        for (field, v) in [
            ("firing_angles_deg", &self.firing_angles_deg),
            ("amplitude", &self.amplitudes),
        ] {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(ChainError::new(field, Some(i), "not a finite number"));
            }
        }
        Ok(())
    }

    /// `(M_s, M_c)` of order `k` with amplitude `a`, on a chain of `n` disks.
    pub fn torque_vectors_for(&self, n: usize, k: f64, a: f64) -> (Vec<f64>, Vec<f64>) {
        let (mut ms, mut mc) = (vec![0.0; n], vec![0.0; n]);
        for (&c, &alpha) in self.cylinders.iter().zip(&self.firing_angles_deg) {
            let (s, co) = (k * alpha.to_radians()).sin_cos();
            ms[c] += a * s;
            mc[c] += a * co;
        }
        (ms, mc)
    }

    /// `(M_s, M_c)` of order number `i` of the table.
    pub fn torque_vectors(&self, n: usize, i: usize) -> (Vec<f64>, Vec<f64>) {
        self.torque_vectors_for(n, self.orders[i], self.amplitudes[i])
    }

    /// The phase sum `Σ_cyl x_cyl e^{i k α_cyl}` of order `k` for shape `x`.
    pub fn phase_sum(&self, k: f64, shape: &[f64]) -> Complex<f64> {
        self.cylinders
            .iter()
            .zip(&self.firing_angles_deg)
            .map(|(&c, &alpha)| Complex::from_polar(shape[c], k * alpha.to_radians()))
            .sum()
    }
}

/// Steady-state response to one harmonic: `φ = S sin νt + C cos νt`.
#[derive(Clone, Debug, PartialEq)]
pub struct HarmonicResponse {
    /// Excitation frequency `ν` (rad/s).
    pub omega: f64,
    /// `S` (rad).
    pub sin: Vec<f64>,
    /// `C` (rad).
    pub cos: Vec<f64>,
}

impl HarmonicResponse {
    /// Disk amplitudes `sqrt(S² + C²)` (rad).
    pub fn amplitudes(&self) -> Vec<f64> {
        self.sin
            .iter()
            .zip(&self.cos)
            .map(|(s, c)| s.hypot(*c))
            .collect()
    }

    /// Shaft torque amplitudes `c_k |φ_{k+1} − φ_k|` (N m).
    pub fn shaft_torques(&self, chain: &TorsionalChain) -> Vec<f64> {
        (0..chain.len().saturating_sub(1))
            .map(|k| {
                let ds = self.sin[k + 1] - self.sin[k];
                let dc = self.cos[k + 1] - self.cos[k];
                chain.stiffness[k] * ds.hypot(dc)
            })
            .collect()
    }
}

/// Solves the real 2n block system (module docs) at excitation frequency `nu` (rad/s).
/// `None` when it is singular (an undamped chain exactly at resonance).
pub fn harmonic_response(
    chain: &TorsionalChain,
    nu: f64,
    m_sin: &[f64],
    m_cos: &[f64],
) -> Option<HarmonicResponse> {
    let n = chain.len();
    let k = chain.stiffness_matrix();
    let b = chain.damping_matrix();
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    for i in 0..n {
        for j in 0..n {
            let d = k[(i, j)]
                - if i == j {
                    nu * nu * chain.inertia[i]
                } else {
                    0.0
                };
            a[(i, j)] = d;
            a[(n + i, n + j)] = d;
            a[(i, n + j)] = -nu * b[(i, j)];
            a[(n + i, j)] = nu * b[(i, j)];
        }
    }
    let rhs = DVector::from_iterator(2 * n, m_sin.iter().chain(m_cos).copied());
    let x = a.lu().solve(&rhs)?;
    if !x.iter().all(|v| v.is_finite()) {
        return None;
    }
    Some(HarmonicResponse {
        omega: nu,
        sin: x.rows(0, n).iter().copied().collect(),
        cos: x.rows(n, n).iter().copied().collect(),
    })
}

/// Response to order number `i` of `exc` at shaft speed `speed_rpm`.
pub fn order_response(
    chain: &TorsionalChain,
    exc: &Excitation,
    i: usize,
    speed_rpm: f64,
) -> Option<HarmonicResponse> {
    let (ms, mc) = exc.torque_vectors(chain.len(), i);
    harmonic_response(chain, exc.orders[i] * speed_rpm * RAD_S_PER_RPM, &ms, &mc)
}

/// One order over a speed range.
#[derive(Clone, Debug, PartialEq)]
pub struct OrderSweep {
    /// The order `k`.
    pub order: f64,
    /// Its amplitude per cylinder (N m).
    pub amplitude: f64,
    /// Shaft speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Disk amplitudes (rad), `[disk][speed]`.
    pub mass_amplitude: Vec<Vec<f64>>,
    /// Shaft torque amplitudes (N m), `[shaft][speed]`.
    pub shaft_torque: Vec<Vec<f64>>,
}

impl OrderSweep {
    /// The largest shaft torque: `(speed index, shaft, torque)`; `None` without shafts.
    pub fn peak(&self) -> Option<(usize, usize, f64)> {
        let mut best: Option<(usize, usize, f64)> = None;
        for (s, row) in self.shaft_torque.iter().enumerate() {
            for (i, &t) in row.iter().enumerate() {
                if best.is_none_or(|b| t > b.2) && !t.is_nan() {
                    best = Some((i, s, t));
                }
            }
        }
        best
    }
}

/// Every order of `exc` at every speed (NaN where the system is singular).
pub fn sweep(chain: &TorsionalChain, exc: &Excitation, speeds_rpm: &[f64]) -> Vec<OrderSweep> {
    let n = chain.len();
    (0..exc.orders.len())
        .map(|i| {
            let mut mass_amplitude = vec![Vec::with_capacity(speeds_rpm.len()); n];
            let mut shaft_torque = vec![Vec::with_capacity(speeds_rpm.len()); n - 1];
            for &rpm in speeds_rpm {
                let r = order_response(chain, exc, i, rpm);
                let amp = r.as_ref().map(|r| r.amplitudes());
                let tq = r.as_ref().map(|r| r.shaft_torques(chain));
                for k in 0..n {
                    mass_amplitude[k].push(amp.as_ref().map_or(f64::NAN, |a| a[k]));
                }
                for k in 0..n - 1 {
                    shaft_torque[k].push(tq.as_ref().map_or(f64::NAN, |t| t[k]));
                }
            }
            OrderSweep {
                order: exc.orders[i],
                amplitude: exc.amplitudes[i],
                speeds_rpm: speeds_rpm.to_vec(),
                mass_amplitude,
                shaft_torque,
            }
        })
        .collect()
}

/// One line of the critical-speed table.
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalSpeed {
    /// Harmonic order `k`.
    pub order: f64,
    /// Index of the mode in the mode list (0 is the rigid-body mode).
    pub mode: usize,
    /// Its natural frequency (cycles/min).
    pub frequency_cpm: f64,
    /// Critical shaft speed `f / k` (rpm).
    pub speed_rpm: f64,
    /// `|Σ_cyl x_cyl e^{i k α_cyl}|` (shape normalised to max |x| = 1).
    pub phase_sum: f64,
    /// `phase_sum / Σ_cyl |x_cyl|` in [0, 1].
    pub relative: f64,
}

/// The critical-speed table: every order of `exc` against every elastic mode, sorted by
/// order, then mode.
pub fn critical_speeds(modes: &[Mode], exc: &Excitation) -> Vec<CriticalSpeed> {
    let mut out = Vec::new();
    for &k in &exc.orders {
        for (r, m) in modes.iter().enumerate() {
            if m.is_rigid_body() {
                continue;
            }
            let ps = exc.phase_sum(k, &m.shape).norm();
            let total: f64 = exc.cylinders.iter().map(|&c| m.shape[c].abs()).sum();
            out.push(CriticalSpeed {
                order: k,
                mode: r,
                frequency_cpm: m.frequency_cpm(),
                speed_rpm: m.frequency_cpm() / k,
                phase_sum: ps,
                relative: if total > 0.0 { ps / total } else { 0.0 },
            });
        }
    }
    out
}
