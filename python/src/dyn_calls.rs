//! Every call from the bindings into `armsim::dynamics`, in one place (the dynamics take
//! gravity from `model.gravity`; a change of those signatures touches only this file), the
//! energies, the Coriolis matrix and the centre of mass included.
//! A result that is not finite (inputs that overflow, e.g. `v = 1e200`) is an error
//! naming the quantity, the joint and the largest inputs, never a NaN returned.

use armsim::dynamics;
use armsim::nalgebra::DMatrix;
use armsim::{Data, Model, Vec3};

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

/// `Err` naming `what` unless the scalar `x` is finite (with the largest inputs).
fn finite_scalar(what: &str, x: f64, inputs: &[(&str, &[f64])]) -> Result<f64, String> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(overflow(what, x, inputs))
    }
}

/// `Err` naming `what` and its first non-finite entry unless every value of `out` is
/// finite (kinematic results such as a frame velocity, `out` not per coordinate).
pub fn finite_values(what: &str, out: &[f64], inputs: &[(&str, &[f64])]) -> Result<(), String> {
    match out.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(k) => Err(overflow(&format!("{what}[{k}]"), out[k], inputs)),
    }
}

/// [`finite_values`] for a matrix (any shape), naming the entry `[row, column]`.
pub fn finite_dmatrix(
    what: &str,
    out: &DMatrix<f64>,
    inputs: &[(&str, &[f64])],
) -> Result<(), String> {
    let n = out.nrows();
    match out.as_slice().iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(k) => Err(overflow(
            &format!("{what}[{}, {}]", k % n, k / n),
            out[k],
            inputs,
        )),
    }
}

/// Kinetic energy `½ vᵀ M(q) v`.
pub fn kinetic_energy(m: &Model, d: &mut Data, q: &[f64], v: &[f64]) -> Result<f64, String> {
    let t = dynamics::kinetic_energy(m, d, q, v);
    finite_scalar("the kinetic energy", t, &[("q", q), ("v", v)])
}

/// Potential energy `−Σ m_i gᵀ c_i` in the model's gravity.
pub fn potential_energy(m: &Model, d: &mut Data, q: &[f64]) -> Result<f64, String> {
    let u = dynamics::potential_energy(m, d, q, &m.gravity);
    finite_scalar("the potential energy", u, &[("q", q)])
}

/// The most coordinates [`coriolis_matrix`] accepts: its reference algorithm keeps
/// `∂M/∂q` (nv³ values, 64 MB at this size) and takes O(nv⁴).
pub const MAX_CORIOLIS_DOF: usize = 200;

/// The Christoffel Coriolis matrix `C(q, v)` (`Ṁ − 2C` skew-symmetric).
pub fn coriolis_matrix(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<DMatrix<f64>, String> {
    if m.nv > MAX_CORIOLIS_DOF {
        return Err(format!(
            "compute_coriolis_matrix: '{}' has {} coordinates; the Coriolis matrix is computed \
             from ∂M/∂q (nv³ values, O(nv⁴) time) for at most {MAX_CORIOLIS_DOF}",
            m.name, m.nv
        ));
    }
    let c = dynamics::coriolis_matrix(m, d, q, v);
    finite_matrix(m, "C", &c, &[("q", q), ("v", v)])?;
    Ok(c)
}

/// "'model' has no mass": the centre of mass does not exist.
fn massless(m: &Model) -> String {
    format!(
        "'{}' has no mass (every body's mass is 0): its centre of mass does not exist",
        m.name
    )
}

/// The world centre of mass.
pub fn center_of_mass(m: &Model, d: &mut Data, q: &[f64]) -> Result<Vec3, String> {
    let c = dynamics::center_of_mass(m, d, q).ok_or_else(|| massless(m))?;
    finite_values("the centre of mass", c.as_slice(), &[("q", q)])?;
    Ok(c)
}

/// The 3 × nv Jacobian of the centre of mass.
pub fn jacobian_center_of_mass(m: &Model, d: &mut Data, q: &[f64]) -> Result<DMatrix<f64>, String> {
    let mut j = DMatrix::zeros(3, m.nv);
    dynamics::jacobian_center_of_mass(m, d, q, &mut j).ok_or_else(|| massless(m))?;
    finite_dmatrix("the CoM Jacobian", &j, &[("q", q)])?;
    Ok(j)
}

/// Inverse dynamics with the model's gravity plus `effects` (wrenches, payload).
pub fn inverse_dynamics<'a>(
    m: &Model,
    d: &'a mut Data,
    effects: &dynamics::Effects,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Result<&'a [f64], String> {
    let tau = dynamics::inverse_dynamics(m, d, effects, q, v, a);
    finite(m, "tau", tau, &[("q", q), ("v", v), ("a", a)])
}

/// Forward dynamics with the model's gravity plus `effects` (wrenches, payload).
pub fn forward_dynamics<'a>(
    m: &Model,
    d: &'a mut Data,
    effects: &dynamics::Effects,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'a [f64], String> {
    if m.has_mimic {
        armsim::model::data::dense_fits(m).map_err(|e| e.to_string())?;
    }
    dynamics::forward_dynamics_with(m, d, effects, q, v, tau).map_err(|e| e.to_string())
}
