//! Time-domain integration of `J φ̈ + B φ̇ + K φ = M(t)` (docs/reference_data.md §S3) with the
//! classical fourth-order Runge–Kutta method on the state `(φ, φ̇)`:
//! `k₁ = f(t, y)`, `k₂ = f(t + h/2, y + h k₁/2)`, `k₃ = f(t + h/2, y + h k₂/2)`,
//! `k₄ = f(t + h, y + h k₃)`, `y ← y + h (k₁ + 2k₂ + 2k₃ + k₄)/6`,
//! with `φ̈ = J⁻¹ (M − B φ̇ − K φ)` evaluated in O(n) from the tridiagonal structure.
//! [`Rk4::step`] allocates nothing: every buffer is made once in [`Rk4::new`].
//!
//! [`steady_state_by_integration`] integrates a harmonic forcing from rest until the
//! transients have died out and takes the Fourier coefficients of the last period,
//! `S = (2/N) Σ φ(t_j) sin νt_j`, `C = (2/N) Σ φ(t_j) cos νt_j` (exact for trigonometric
//! polynomials on the uniform periodic grid), to compare with the harmonic solution of
//! [`crate::machines::vibration::torsional::forced`]. The rigid-body offset a free chain keeps
//! after the transient is a constant and drops out of both sums.

use crate::machines::vibration::torsional::forced::HarmonicResponse;
use crate::machines::vibration::torsional::torsional_chain::TorsionalChain;

/// A sum of harmonics `M(t) = Σ (M_s sin νt + M_c cos νt)`.
#[derive(Clone, Debug, PartialEq)]
pub struct HarmonicForcing {
    /// `(ν, M_s, M_c)` per harmonic.
    pub terms: Vec<(f64, Vec<f64>, Vec<f64>)>,
}

impl HarmonicForcing {
    /// `out = M(t)`, no allocation.
    #[inline]
    pub fn eval(&self, t: f64, out: &mut [f64]) {
        out.fill(0.0);
        for (nu, ms, mc) in &self.terms {
            let (s, c) = (nu * t).sin_cos();
            for k in 0..out.len() {
                out[k] += ms[k] * s + mc[k] * c;
            }
        }
    }
}

/// RK4 integrator for one chain, with its work buffers.
#[derive(Clone, Debug)]
pub struct Rk4<'a> {
    chain: &'a TorsionalChain,
    inv_j: Vec<f64>,
    kx: [Vec<f64>; 4],
    kv: [Vec<f64>; 4],
    xt: Vec<f64>,
    vt: Vec<f64>,
    m: Vec<f64>,
    tmp: Vec<f64>,
}

impl<'a> Rk4<'a> {
    /// Buffers for `chain`.
    pub fn new(chain: &'a TorsionalChain) -> Self {
        let n = chain.len();
        let z = || vec![0.0; n];
        Self {
            chain,
            inv_j: chain.inertia.iter().map(|j| 1.0 / j).collect(),
            kx: [z(), z(), z(), z()],
            kv: [z(), z(), z(), z()],
            xt: z(),
            vt: z(),
            m: z(),
            tmp: z(),
        }
    }

    /// `out = J⁻¹ (M − B v − K x)` with `M` already in `self.m`.
    #[inline]
    fn accel(
        chain: &TorsionalChain,
        inv_j: &[f64],
        m: &[f64],
        tmp: &mut [f64],
        x: &[f64],
        v: &[f64],
        out: &mut [f64],
    ) {
        chain.apply_stiffness(x, out);
        chain.apply_damping(v, tmp);
        for k in 0..out.len() {
            out[k] = (m[k] - out[k] - tmp[k]) * inv_j[k];
        }
    }

    /// Accelerations `φ̈` at `(t, x, v)` into `out`.
    pub fn acceleration<F: FnMut(f64, &mut [f64])>(
        &mut self,
        t: f64,
        x: &[f64],
        v: &[f64],
        force: &mut F,
        out: &mut [f64],
    ) {
        force(t, &mut self.m);
        Self::accel(self.chain, &self.inv_j, &self.m, &mut self.tmp, x, v, out);
    }

    /// One step of length `h` from `t`; `force(t, out)` writes `M(t)`.
    pub fn step<F: FnMut(f64, &mut [f64])>(
        &mut self,
        t: f64,
        h: f64,
        x: &mut [f64],
        v: &mut [f64],
        force: &mut F,
    ) {
        let n = x.len();
        let c = self.chain;
        let [k1x, k2x, k3x, k4x] = &mut self.kx;
        let [k1v, k2v, k3v, k4v] = &mut self.kv;
        // Stage 1.
        force(t, &mut self.m);
        k1x.copy_from_slice(v);
        Self::accel(c, &self.inv_j, &self.m, &mut self.tmp, x, v, k1v);
        // Stage 2.
        for k in 0..n {
            self.xt[k] = x[k] + 0.5 * h * k1x[k];
            self.vt[k] = v[k] + 0.5 * h * k1v[k];
        }
        force(t + 0.5 * h, &mut self.m);
        k2x.copy_from_slice(&self.vt);
        Self::accel(
            c,
            &self.inv_j,
            &self.m,
            &mut self.tmp,
            &self.xt,
            &self.vt,
            k2v,
        );
        // Stage 3 (same time).
        for k in 0..n {
            self.xt[k] = x[k] + 0.5 * h * k2x[k];
            self.vt[k] = v[k] + 0.5 * h * k2v[k];
        }
        k3x.copy_from_slice(&self.vt);
        Self::accel(
            c,
            &self.inv_j,
            &self.m,
            &mut self.tmp,
            &self.xt,
            &self.vt,
            k3v,
        );
        // Stage 4.
        for k in 0..n {
            self.xt[k] = x[k] + h * k3x[k];
            self.vt[k] = v[k] + h * k3v[k];
        }
        force(t + h, &mut self.m);
        k4x.copy_from_slice(&self.vt);
        Self::accel(
            c,
            &self.inv_j,
            &self.m,
            &mut self.tmp,
            &self.xt,
            &self.vt,
            k4v,
        );
        let w = h / 6.0;
        for k in 0..n {
            x[k] += w * (k1x[k] + 2.0 * k2x[k] + 2.0 * k3x[k] + k4x[k]);
            v[k] += w * (k1v[k] + 2.0 * k2v[k] + 2.0 * k3v[k] + k4v[k]);
        }
    }
}

/// Integrates `M = M_s sin νt + M_c cos νt` from rest over `periods` periods of
/// `steps_per_period` steps each, and returns the Fourier coefficients of the last
/// period (module docs).
pub fn steady_state_by_integration(
    chain: &TorsionalChain,
    nu: f64,
    m_sin: &[f64],
    m_cos: &[f64],
    periods: usize,
    steps_per_period: usize,
) -> HarmonicResponse {
    let n = chain.len();
    let forcing = HarmonicForcing {
        terms: vec![(nu, m_sin.to_vec(), m_cos.to_vec())],
    };
    let mut force = |t: f64, out: &mut [f64]| forcing.eval(t, out);
    let mut rk = Rk4::new(chain);
    let (mut x, mut v) = (vec![0.0; n], vec![0.0; n]);
    let (mut s, mut c) = (vec![0.0; n], vec![0.0; n]);
    let np = steps_per_period;
    let h = 2.0 * std::f64::consts::PI / nu / np as f64;
    let total = periods.max(1) * np;
    for step in 0..total {
        let t = step as f64 * h;
        if step >= total - np {
            // Last period: accumulate at t_j before stepping (j = 0 … N−1).
            let j = step - (total - np);
            let (sn, cs) = (2.0 * std::f64::consts::PI * j as f64 / np as f64).sin_cos();
            for k in 0..n {
                s[k] += x[k] * sn;
                c[k] += x[k] * cs;
            }
        }
        rk.step(t, h, &mut x, &mut v, &mut force);
    }
    let w = 2.0 / np as f64;
    s.iter_mut().for_each(|v| *v *= w);
    c.iter_mut().for_each(|v| *v *= w);
    HarmonicResponse {
        omega: nu,
        sin: s,
        cos: c,
    }
}
