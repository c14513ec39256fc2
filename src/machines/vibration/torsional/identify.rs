//! Damping identification from measured shaft-torque amplitudes (docs/reference_data.md §S3):
//! a nonlinear least-squares fit of the forced-response model, Levenberg–Marquardt with
//! an analytic Jacobian.
//!
//! **Parameters.** Each unknown `θ_j` is one coefficient shared by a set of dampers
//! (a pattern): `B(θ) = B_0 + Σ_j θ_j B_j`, where `B_0` is the known damping and `B_j`
//! the damping matrix of pattern `j` with unit coefficients (absolute dampers on listed
//! disks, relative dampers across listed shafts, each with a weight).
//!
//! **Model.** For a measurement (order `k`, speed `w`, shaft `s`) the phasor response
//! `X = D⁻¹ F`, `D = K − ν²J + iνB(θ)`, `F = M_c − i M_s` (the complex form of the block
//! system in [`crate::machines::vibration::torsional::forced`]), torque amplitude `T = c_s |X_{s+1}
//! − X_s|`. Derivatives: `∂X/∂θ_j = −D⁻¹ (iν B_j X)`, `∂T/∂θ_j = c_s Re(conj(Z) ∂Z)/|Z|`, `Z =
//! X_{s+1} − X_s`.
//!
//! **Fit.** Residuals `r_i = ln T_i(θ) − ln T_i^meas` (a measurement error proportional
//! to the amplitude). Levenberg–Marquardt: `(JᵀJ + μ diag JᵀJ) δ = −Jᵀ r`, accept when the
//! sum of squares drops (`μ /= 3`), else `μ *= 4`; steps that would make a coefficient
//! negative are rejected. Stop when every `|δ_j| ≤ 1e-10 |θ_j|` or the sum of squares
//! stalls. **Uncertainty**: `Cov θ = σ̂² (JᵀJ)⁻¹` at the solution, `σ̂² = RSS/(m − p)`,
//! standard errors the square roots of its diagonal (the usual linearised estimate).

use crate::machines::vibration::torsional::forced::{Excitation, RAD_S_PER_RPM};
use crate::machines::vibration::torsional::torsional_chain::{ChainError, TorsionalChain};
use nalgebra::{Complex, DMatrix, DVector};

type C64 = Complex<f64>;

/// One unknown damping coefficient and the dampers it scales.
#[derive(Clone, Debug, PartialEq)]
pub struct DampingParameter {
    /// Name for reports.
    pub name: String,
    /// `(disk, weight)`: absolute dampers `weight × θ`.
    pub absolute: Vec<(usize, f64)>,
    /// `(shaft, weight)`: relative dampers `weight × θ`.
    pub relative: Vec<(usize, f64)>,
}

/// A measured shaft-torque amplitude.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    /// Harmonic order (must be one of the excitation's orders).
    pub order: f64,
    /// Shaft speed (rpm).
    pub speed_rpm: f64,
    /// Shaft index.
    pub shaft: usize,
    /// Torque amplitude (N m), > 0.
    pub torque: f64,
}

/// The fit result.
#[derive(Clone, Debug, PartialEq)]
pub struct DampingEstimate {
    /// Estimated coefficients.
    pub values: Vec<f64>,
    /// Standard errors `sqrt(diag Cov)`.
    pub std_errors: Vec<f64>,
    /// `σ̂² (JᵀJ)⁻¹`.
    pub covariance: DMatrix<f64>,
    /// Residual standard deviation `σ̂` (relative, since the residuals are log ratios).
    pub sigma: f64,
    /// Final sum of squares.
    pub rss: f64,
    /// LM iterations taken.
    pub iterations: usize,
}

/// A problem that cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IdentifyError {
    /// A bad input.
    #[error("{0}")]
    Input(#[from] ChainError),
    /// Fewer measurements than parameters + 1.
    #[error("{measurements} measurements for {parameters} parameters: need more")]
    TooFewMeasurements {
        /// Measurements given.
        measurements: usize,
        /// Parameters to fit.
        parameters: usize,
    },
    /// The normal equations are singular (parameters not identifiable from these data).
    #[error("the parameters cannot be separated with these measurements (singular JᵀJ)")]
    Singular,
}

/// `base` damping plus `Σ θ_j` patterns.
pub fn chain_with(
    base: &TorsionalChain,
    params: &[DampingParameter],
    theta: &[f64],
) -> TorsionalChain {
    let mut c = base.clone();
    for (p, &t) in params.iter().zip(theta) {
        for &(k, w) in &p.absolute {
            c.absolute_damping[k] += w * t;
        }
        for &(k, w) in &p.relative {
            c.relative_damping[k] += w * t;
        }
    }
    c
}

fn check(
    base: &TorsionalChain,
    exc: &Excitation,
    params: &[DampingParameter],
    data: &[Measurement],
) -> Result<(), ChainError> {
    let n = base.len();
    exc.validate(n)?;
    for p in params {
        if p.absolute.iter().any(|&(k, _)| k >= n) || p.relative.iter().any(|&(k, _)| k + 1 >= n) {
            return Err(ChainError::new(
                "parameters",
                None,
                format!(
                    "parameter '{}' names a disk or shaft the chain lacks",
                    p.name
                ),
            ));
        }
    }
    for (i, m) in data.iter().enumerate() {
        if !exc.orders.contains(&m.order) {
            return Err(ChainError::new(
                "measurements",
                Some(i),
                format!("order {} is not in the excitation table", m.order),
            ));
        }
        if m.shaft + 1 >= n {
            return Err(ChainError::new("measurements", Some(i), "no such shaft"));
        }
        if !(m.torque.is_finite() && m.torque > 0.0) {
            return Err(ChainError::new(
                "measurements",
                Some(i),
                "torque amplitude must be positive",
            ));
        }
        if !(m.speed_rpm.is_finite() && m.speed_rpm > 0.0) {
            return Err(ChainError::new(
                "measurements",
                Some(i),
                "speed must be positive",
            ));
        }
    }
    Ok(())
}

/// `B_j x` for the pattern of `p`, without forming the matrix.
fn pattern_apply(p: &DampingParameter, x: &DVector<C64>) -> DVector<C64> {
    let mut out = DVector::zeros(x.len());
    for &(k, w) in &p.absolute {
        out[k] += x[k] * w;
    }
    for &(k, w) in &p.relative {
        let t = (x[k] - x[k + 1]) * w;
        out[k] += t;
        out[k + 1] -= t;
    }
    out
}

/// The response `X` at one (order, speed) and its derivatives `∂X/∂θ_j`.
struct Solved {
    order: f64,
    speed_rpm: f64,
    x: DVector<C64>,
    dx: Vec<DVector<C64>>,
}

/// Model torque amplitudes at `theta` and their derivatives `∂T_i/∂θ_j`. Consecutive
/// measurements at the same order and speed share one factorisation.
pub fn predict(
    base: &TorsionalChain,
    exc: &Excitation,
    params: &[DampingParameter],
    theta: &[f64],
    data: &[Measurement],
) -> (Vec<f64>, DMatrix<f64>) {
    let chain = chain_with(base, params, theta);
    let n = chain.len();
    let k = chain.stiffness_matrix();
    let b = chain.damping_matrix();
    let mut t = Vec::with_capacity(data.len());
    let mut jac = DMatrix::zeros(data.len(), params.len());
    let mut cached: Option<Solved> = None;
    for (i, m) in data.iter().enumerate() {
        let hit = matches!(&cached, Some(c) if c.order == m.order && c.speed_rpm == m.speed_rpm);
        if !hit {
            let oi = exc.orders.iter().position(|&o| o == m.order).unwrap_or(0);
            let nu = m.order * m.speed_rpm * RAD_S_PER_RPM;
            let d = DMatrix::from_fn(n, n, |r, c| {
                let mut v = C64::new(k[(r, c)], nu * b[(r, c)]);
                if r == c {
                    v.re -= nu * nu * chain.inertia[r];
                }
                v
            });
            let (ms, mc) = exc.torque_vectors(n, oi);
            let f = DVector::from_fn(n, |r, _| C64::new(mc[r], -ms[r]));
            let lu = d.lu();
            let x = lu
                .solve(&f)
                .unwrap_or_else(|| DVector::from_element(n, C64::new(f64::NAN, 0.0)));
            let dx = params
                .iter()
                .map(|p| {
                    let rhs = pattern_apply(p, &x) * C64::new(0.0, -nu);
                    lu.solve(&rhs).unwrap_or_else(|| DVector::zeros(n))
                })
                .collect();
            cached = Some(Solved {
                order: m.order,
                speed_rpm: m.speed_rpm,
                x,
                dx,
            });
        }
        let Some(Solved { x, dx, .. }) = &cached else {
            unreachable!()
        };
        let s = m.shaft;
        let z = x[s + 1] - x[s];
        let c = chain.stiffness[s];
        t.push(c * z.norm());
        for (j, dxj) in dx.iter().enumerate() {
            let dz = dxj[s + 1] - dxj[s];
            jac[(i, j)] = c * (z.conj() * dz).re / z.norm();
        }
    }
    (t, jac)
}

fn residuals(pred: &[f64], data: &[Measurement]) -> DVector<f64> {
    DVector::from_iterator(
        data.len(),
        pred.iter().zip(data).map(|(p, m)| p.ln() - m.torque.ln()),
    )
}

/// Fits the damping coefficients (module docs) from `initial`.
pub fn identify_damping(
    base: &TorsionalChain,
    exc: &Excitation,
    params: &[DampingParameter],
    data: &[Measurement],
    initial: &[f64],
) -> Result<DampingEstimate, IdentifyError> {
    check(base, exc, params, data)?;
    let p = params.len();
    if initial.len() != p {
        return Err(ChainError::new(
            "initial",
            None,
            format!("{} initial values for {p} parameters", initial.len()),
        )
        .into());
    }
    if data.len() <= p {
        return Err(IdentifyError::TooFewMeasurements {
            measurements: data.len(),
            parameters: p,
        });
    }
    let mut theta = initial.to_vec();
    let eval = |th: &[f64]| {
        let (t, dt) = predict(base, exc, params, th, data);
        let r = residuals(&t, data);
        // ∂ ln T / ∂θ = (∂T/∂θ) / T.
        let jac = DMatrix::from_fn(data.len(), p, |i, j| dt[(i, j)] / t[i]);
        (r, jac)
    };
    let (mut r, mut jac) = eval(&theta);
    let mut rss = r.norm_squared();
    let mut mu = 1e-3;
    let mut iterations = 0;
    for _ in 0..200 {
        iterations += 1;
        let jtj = jac.transpose() * &jac;
        let g = jac.transpose() * &r;
        let mut a = jtj.clone();
        for j in 0..p {
            a[(j, j)] += mu * jtj[(j, j)].max(1e-300);
        }
        let Some(delta) = a.lu().solve(&(-g)) else {
            return Err(IdentifyError::Singular);
        };
        let cand: Vec<f64> = theta.iter().zip(delta.iter()).map(|(t, d)| t + d).collect();
        let small = delta
            .iter()
            .zip(&theta)
            .all(|(d, t)| d.abs() <= 1e-10 * t.abs().max(1e-300));
        if cand.iter().all(|v| v.is_finite() && *v >= 0.0) {
            let (rc, jc) = eval(&cand);
            let rss_c = rc.norm_squared();
            if rss_c.is_finite() && rss_c <= rss {
                let stalled = rss - rss_c <= 1e-15 * rss;
                theta = cand;
                r = rc;
                jac = jc;
                rss = rss_c;
                mu = (mu / 3.0).max(1e-12);
                if small || stalled {
                    break;
                }
                continue;
            }
        }
        mu *= 4.0;
        if mu > 1e12 {
            break;
        }
    }
    let jtj = jac.transpose() * &jac;
    let inv = jtj.try_inverse().ok_or(IdentifyError::Singular)?;
    let dof = (data.len() - p) as f64;
    let sigma2 = rss / dof;
    let covariance = inv * sigma2;
    let std_errors = (0..p).map(|j| covariance[(j, j)].max(0.0).sqrt()).collect();
    Ok(DampingEstimate {
        values: theta,
        std_errors,
        covariance,
        sigma: sigma2.sqrt(),
        rss,
        iterations,
    })
}
