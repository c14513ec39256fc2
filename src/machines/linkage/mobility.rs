//! Mobility and singular positions.
//!
//! - Grübler–Kutzbach count for planar linkages: `F = 3 (n − 1) − 2 j₁ − j₂`, with `n`
//!   links including the ground, `j₁` full joints (pins, prismatic sliders) and `j₂` half
//!   joints (a pin in a slot, a cam contact: `p₄`).
//! - The count assumes independent constraints. The rank `r` of the joint Jacobian
//!   `Φ^K_q` (without the driver) gives the true (instantaneous) mobility
//!   `F_r = 3 (n − 1) − r` and the number of redundant equations `m − r` (Haug 1989, §3.2;
//!   the parallelogram coupled by a third parallel crank counts `F = 0` but moves with
//!   `F_r = 1`).
//! - With the driver, the driven Jacobian `Φ_q` (square for a proper single-input
//!   linkage) is singular where the input does not determine the motion: change points,
//!   and dead centres of the driven link (Haug 1989, §4.5). The ratio `σ_min / σ_max`
//!   of its singular values measures the distance; below [`SINGULAR_TOL`] the position
//!   counts as singular. The position itself remains solvable there.

use crate::core::least_squares::{singular_values, RANK_TOL};
use crate::machines::linkage::constraints::jacobian_mat;
use crate::machines::linkage::description::{Linkage, PlanarJoint};
use nalgebra::DVector;

/// `σ_min / σ_max` below which the driven Jacobian counts as singular.
pub const SINGULAR_TOL: f64 = 1e-6;

/// Grübler's count and the rank check.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Mobility {
    /// Links, the ground included.
    pub links: usize,
    /// Full joints (pins, prismatic sliders).
    pub full_joints: usize,
    /// Half joints (pins in slots).
    pub half_joints: usize,
    /// Cam contacts among the half joints (`p₄` of `W = 3n − 2p₅ − p₄`).
    pub higher_pairs: usize,
    /// `3 (n − 1) − 2 j₁ − j₂`.
    pub grubler: i64,
    /// PlanarJoint constraint equations.
    pub equations: usize,
    /// Rank of the joint Jacobian at the position checked.
    pub rank: usize,
    /// `3 (n − 1) − rank`: the mobility the constraints really leave.
    pub mobility: i64,
    /// `equations − rank`: redundant equations.
    pub redundant: usize,
}

/// Grübler's count for `l`, and the rank of its joint Jacobian at `q`.
pub fn mobility(l: &Linkage, q: &DVector<f64>) -> Mobility {
    let mut full = 0;
    let mut half = 0;
    let mut higher = 0;
    for j in &l.joints {
        match j {
            PlanarJoint::Revolute { .. } => full += 1,
            PlanarJoint::Slider(s) if s.prismatic.is_some() => full += 1,
            PlanarJoint::Slider(_) => half += 1,
            PlanarJoint::Contact(_) => {
                half += 1;
                higher += 1;
            }
        }
    }
    let n = l.links.len() + 1;
    let m = l.kinematic_rows();
    let jac = jacobian_mat(l, q);
    let kin = jac.rows(0, m).into_owned();
    let rank = crate::core::least_squares::rank(&kin);
    let dof = l.ncoords() as i64;
    Mobility {
        links: n,
        full_joints: full,
        half_joints: half,
        higher_pairs: higher,
        grubler: dof - 2 * full as i64 - half as i64,
        equations: m,
        rank,
        mobility: dof - rank as i64,
        redundant: m - rank,
    }
}

/// How far the driven Jacobian is from singular.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Conditioning {
    /// Largest singular value.
    pub sigma_max: f64,
    /// The `n`-th singular value (`n` coordinates); zero if there are fewer rows.
    pub sigma_min: f64,
    /// `σ_max / σ_min` (infinite when singular to rounding).
    pub condition: f64,
    /// Numerical rank.
    pub rank: usize,
    /// `σ_min < SINGULAR_TOL σ_max`.
    pub singular: bool,
}

/// Conditioning of the driven Jacobian `Φ_q` at `q`.
pub fn conditioning(l: &Linkage, q: &DVector<f64>) -> Conditioning {
    conditioning_from(&singular_values(&jacobian_mat(l, q)), l.ncoords())
}

/// Conditioning from the singular values (largest first) of a Jacobian with `n` columns.
pub fn conditioning_from(s: &[f64], n: usize) -> Conditioning {
    let smax = s.first().copied().unwrap_or(0.0);
    let smin = if s.len() >= n { s[n - 1] } else { 0.0 };
    let rank = s.iter().filter(|&&x| x > smax * RANK_TOL).count();
    Conditioning {
        sigma_max: smax,
        sigma_min: smin,
        condition: if smin > 0.0 {
            smax / smin
        } else {
            f64::INFINITY
        },
        rank,
        singular: smin < SINGULAR_TOL * smax,
    }
}
