//! Every call from the bindings into `armsim::dynamics`, in one place (the dynamics take
//! gravity from `model.gravity`; a change of those signatures touches only this file).
//! A result that is not finite (inputs that overflow, e.g. `v = 1e200`) is an error
//! naming the quantity, the joint and the largest inputs, never a NaN returned.

use armsim::dynamics;
use armsim::nalgebra::DMatrix;
use armsim::{Data, Model};

/// `Ok(out)` when every value is finite, else an error naming `what`, the joint and the
/// largest magnitude of each input.
fn finite<'a>(
    m: &Model,
    what: &str,
    out: &'a [f64],
    inputs: &[(&str, &[f64])],
) -> Result<&'a [f64], String> {
    let Some(k) = out.iter().position(|x| !x.is_finite()) else {
        return Ok(out);
    };
    let names = m.dof_names();
    let at = match names.get(k) {
        Some(n) if out.len() == names.len() => format!(" of joint '{n}'"),
        _ => format!(" (entry {k})"),
    };
    Err(overflow(&format!("{what}{at}"), out[k], inputs))
}

/// "`place` is not finite (`value`): the inputs overflow ... (largest |q| ..., ...)".
fn overflow(place: &str, value: f64, inputs: &[(&str, &[f64])]) -> String {
    let largest: Vec<String> = inputs
        .iter()
        .map(|(n, x)| {
            let big = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            format!("|{n}| {}", armsim::core::diag::fmt_num(big))
        })
        .collect();
    format!(
        "{place} is not finite ({value}): the inputs overflow floating-point arithmetic \
         (largest {})",
        largest.join(", ")
    )
}

/// Inverse dynamics `τ = M(q) a + C(q, v) v + g(q)`.
pub fn rnea<'a>(
    m: &Model,
    d: &'a mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Result<&'a [f64], String> {
    let tau = dynamics::rnea(m, d, q, v, a);
    finite(m, "tau", tau, &[("q", q), ("v", v), ("a", a)])
}

/// Generalised gravity `g(q)`.
pub fn gravity<'a>(m: &Model, d: &'a mut Data, q: &[f64]) -> Result<&'a [f64], String> {
    let g = dynamics::gravity_torque(m, d, q);
    finite(m, "the gravity torque", g, &[("q", q)])
}

/// Nonlinear effects `h(q, v) = C(q, v) v + g(q)`.
pub fn nonlinear_effects<'a>(
    m: &Model,
    d: &'a mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<&'a [f64], String> {
    let h = dynamics::bias(m, d, q, v);
    finite(m, "the nonlinear effects", h, &[("q", q), ("v", v)])
}

/// Forward dynamics `q̈` (ABA; CRBA + Cholesky with mimic joints).
pub fn aba<'a>(
    m: &Model,
    d: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'a [f64], String> {
    if m.has_mimic {
        armsim::model::data::dense_fits(m).map_err(|e| e.to_string())?;
    }
    dynamics::forward_dynamics(m, d, q, v, tau).map_err(|e| e.to_string())
}

/// The joint-space mass matrix (full, symmetric); refused above the dense algorithms'
/// size ([`armsim::model::data::MAX_DENSE_DOF`]).
pub fn crba<'a>(m: &Model, d: &'a mut Data, q: &[f64]) -> Result<&'a DMatrix<f64>, String> {
    armsim::model::data::dense_fits(m).map_err(|e| e.to_string())?;
    Ok(dynamics::crba(m, d, q))
}

/// `Err` naming `what`, its first non-finite entry (row, column) and their joints, with
/// the largest inputs, as [`finite`] does for vectors.
fn finite_matrix(
    m: &Model,
    what: &str,
    out: &DMatrix<f64>,
    inputs: &[(&str, &[f64])],
) -> Result<(), String> {
    let n = out.nrows();
    let Some(k) = out.as_slice().iter().position(|x| !x.is_finite()) else {
        return Ok(());
    };
    let (r, c) = (k % n, k / n);
    let names = m.dof_names();
    let place = format!("{what}[{r}, {c}] (joints '{}', '{}')", names[r], names[c]);
    Err(overflow(&place, out[(r, c)], inputs))
}

/// `(∂τ/∂q, ∂τ/∂v, M)` at `(q, v, a)` (Carpentier & Mansard's RNEA derivatives).
pub fn rnea_derivatives<'a>(
    m: &Model,
    d: &'a mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Result<dynamics::RneaPartials<'a>, String> {
    armsim::model::derivative_data::derivatives_fit(m).map_err(|e| e.to_string())?;
    let p = dynamics::rnea_derivatives(m, d, q, v, a);
    let inputs = [("q", q), ("v", v), ("a", a)];
    finite_matrix(m, "dtau_dq", p.dtau_dq, &inputs)?;
    finite_matrix(m, "dtau_dv", p.dtau_dv, &inputs)?;
    finite_matrix(m, "M", p.mass, &inputs)?;
    Ok(p)
}

/// `(∂q̈/∂q, ∂q̈/∂v, M⁻¹)` at `(q, v, tau)` (the ABA derivatives).
pub fn aba_derivatives<'a>(
    m: &Model,
    d: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<dynamics::AbaPartials<'a>, String> {
    armsim::model::derivative_data::derivatives_fit(m).map_err(|e| e.to_string())?;
    let p = dynamics::aba_derivatives(m, d, q, v, tau).map_err(|e| e.to_string())?;
    let inputs = [("q", q), ("v", v), ("tau", tau)];
    finite_matrix(m, "ddq_dq", p.ddq_dq, &inputs)?;
    finite_matrix(m, "ddq_dv", p.ddq_dv, &inputs)?;
    Ok(p)
}

/// `M(q)⁻¹`.
pub fn compute_minverse<'a>(
    m: &Model,
    d: &'a mut Data,
    q: &[f64],
) -> Result<&'a DMatrix<f64>, String> {
    armsim::model::derivative_data::derivatives_fit(m).map_err(|e| e.to_string())?;
    dynamics::compute_minverse(m, d, q).map_err(|e| e.to_string())
}
