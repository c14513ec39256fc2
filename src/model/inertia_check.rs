//! The physical sanity of each link's inertia, before the tree is compiled: finite numbers,
//! a non-negative mass, a symmetric tensor, non-negative principal moments, and the
//! triangle inequality.
//!
//! Real files carry tensors that are not positive semi-definite: by noise (TIAGo's
//! antenna links: principal moments 9.1e-8, -3.5e-8, 3.5e-8 kg m² on a 1 mg link), or
//! because the exporter got the products of inertia wrong (Romeo's body: 0.099, -0.021,
//! 0.052). urdfdom and Pinocchio load both. armsim replaces such a tensor by the nearest
//! positive semi-definite one (negative principal moments set to zero, same axes), with a
//! warning that says how far it was; the URDF reader refuses a negative moment of inertia
//! written on the diagonal (`ixx`, `iyy`, `izz`) beyond [`clamp_tolerance`], and this
//! check refuses a negative mass.

use crate::core::spatial::Mat3;
use crate::model::model_error::{ModelError, ModelWarning};
use crate::model::spec::LinkSpec;

/// Relative size of a negative principal moment that is floating-point noise: accepted
/// silently (as is one below [`NOISE_ABS`]).
const NOISE_REL: f64 = 1e-9;

/// Absolute size (kg m²) below which a negative principal moment, or a triangle-inequality
/// defect, is noise (a milligram 1 mm from its axis): iCub's tensors of 1e-20 kg m².
const NOISE_ABS: f64 = 1e-12;

/// A negative principal moment up to this fraction of the largest one is clamped (with a
/// warning).
pub const CLAMP_REL: f64 = 1e-3;

/// A negative principal moment up to this many kg m² is clamped (with a warning): below
/// the inertia of a 10 g part 1 cm from its axis, negligible in an arm's dynamics.
pub const CLAMP_ABS: f64 = 1e-6;

/// The largest negative principal moment that is clamped rather than refused, for a
/// tensor whose largest principal moment is `max_moment`.
pub fn clamp_tolerance(max_moment: f64) -> f64 {
    (CLAMP_REL * max_moment.abs()).max(CLAMP_ABS)
}

/// Checks `l`'s inertia, clamps a slightly negative tensor, and returns the warnings.
pub(super) fn check(l: &mut LinkSpec, file: &str) -> Result<Vec<ModelWarning>, ModelError> {
    let element = format!("link '{}'", l.name);
    let err = |msg: String| ModelError::new(file, l.line, &element, msg);
    let i = &mut l.inertial;
    let finite = i.mass.is_finite()
        && i.com.iter().all(|x| x.is_finite())
        && i.inertia_com.iter().all(|x| x.is_finite());
    if !finite {
        return Err(err("inertial: non-finite number".into()));
    }
    if i.mass < 0.0 {
        return Err(err(format!("inertial: negative mass {}", i.mass)));
    }
    let sym = (i.inertia_com - i.inertia_com.transpose()).norm();
    let scale = i.inertia_com.norm().max(f64::MIN_POSITIVE);
    if sym > 1e-12 * scale {
        return Err(err("inertial: inertia tensor is not symmetric".into()));
    }
    let mut warnings = Vec::new();
    let eig = i.inertia_com.symmetric_eigen();
    let ev = eig.eigenvalues;
    let (lo, hi) = (ev.min(), ev.max());
    let moments = format!("{:.6e}, {:.6e}, {:.6e}", ev[0], ev[1], ev[2]);
    let noise = (NOISE_REL * scale).max(NOISE_ABS);
    if lo < -noise {
        let tol = clamp_tolerance(hi);
        let clamped = ev.map(|e| e.max(0.0));
        i.inertia_com =
            eig.eigenvectors * Mat3::from_diagonal(&clamped) * eig.eigenvectors.transpose();
        // Exactly symmetric again (the product rounds).
        i.inertia_com = 0.5 * (i.inertia_com + i.inertia_com.transpose());
        let why = if -lo <= tol {
            format!("the negative one is within {tol:.1e} kg m² of zero (rounding)")
        } else {
            format!(
                "not positive semi-definite by {:.1e} kg m², more than rounding ({tol:.1e}): the products of inertia are inconsistent with the moments",
                -lo
            )
        };
        warnings.push(err(format!(
            "inertial: principal moments {moments}: {why}; negative moments are clamped to 0 (principal moments {:.6e}, {:.6e}, {:.6e})",
            clamped[0], clamped[1], clamped[2]
        )));
    }
    if !warnings.is_empty() {
        return Ok(warnings); // clamped: the warning already says it is not a rigid body
    }
    let (a, b, c) = (ev[0], ev[1], ev[2]);
    let tol = noise;
    if a + b < c - tol || a + c < b - tol || b + c < a - tol {
        warnings.push(err(format!(
            "inertial: principal moments {a:.6e}, {b:.6e}, {c:.6e} break the triangle inequality (not a physical rigid body)"
        )));
    }
    Ok(warnings)
}
