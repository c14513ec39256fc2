//! Analytic (closed-form) inverse kinematics returning **every** branch.
//!
//! Families (recognised from the model's geometry, see [`AnalyticKind`]):
//! - [`AnalyticKind::Ur`]: the UR3/5/10/e-series structure, standard DH with
//!   `α = (±π/2, 0, 0, ±π/2, ±π/2, 0)`, `a1 = a4 = a5 = a6 = 0` and three parallel axes
//!   (2, 3, 4): up to 8 solutions (shoulder × wrist × elbow), [`ur_ik`];
//! - [`AnalyticKind::WristRrr`]: 6R arms with a spherical wrist whose first three joints
//!   are R ⟂ R ∥ R (the Puma 560, with shoulder offset `d2 + d3` and forearm offset
//!   `a3`): Pieper's decoupling, up to 8 solutions, [`wrist_ik`];
//! - [`AnalyticKind::WristRrp`]: R R P arms with a spherical wrist (the Stanford arm):
//!   up to 8 mathematical solutions, of which at most 4 have a positive boom extension;
//! - [`AnalyticKind::SphericalRrp`]: the textbook spherical R-R-P arm, position only:
//!   `g1 = atan2(y, x)`, `b2 = atan2(z, √(x²+y²))`, `r = |p|` and the other branch
//!   `(g1 + π, π − b2, r)` (plus the negative-extension branches, which limits reject),
//!   [`rrp_ik`];
//! - [`AnalyticKind::Planar2r`]: planar 2R arms, position in the arm's plane, elbow up and
//!   down, [`planar_2r_ik`].
//!
//! The parameters are read from the model (see [`DhChain`]: a model keeps no DH table,
//! so the table is rebuilt from the joint axes and checked against the model's forward
//! kinematics), or given by hand ([`UrParams::ur5`], [`WristParams::puma560`],
//! [`WristParams::stanford`]). Every angle comes from `atan2` of two consistent
//! quantities; every branch of each square root is kept (Paul's method, which the
//! textbooks use, takes `arcsin`/`arccos` and loses half of them).
//!
//! **Joint limits.** Revolute solutions are moved by multiples of 2π into the joint's
//! range, choosing the representative closest to the seed (0 by default, so ±2π joints
//! get values in (−π, π]); a solution with any joint that cannot be brought inside (by
//! more than 1e-12) is dropped. [`AnalyticOptions::respect_limits`] = `false` returns all of
//! them.
//!
//! **Singularities.** Each solution carries [`Singularity`] flags, set when the solution is
//! within [`SINGULAR_TOL`] of a singular configuration: shoulder (the wrist centre on the
//! plane of axes 1 and 2, where the two shoulder roots merge; for arms without a shoulder
//! offset, on axis 1 itself), elbow (arm stretched or folded) or wrist (`sin θ5 = 0`).
//! Where the solution set is a continuum (`sin θ5 = 0` to rounding, a target on axis 1 of
//! an arm without shoulder offset, a planar 2R target at its base), the free joint takes
//! its seed value (0 by default) and the others are solved for it: the output is one
//! valid member of the family, never NaN. Coinciding roots (exactly singular) are
//! returned once.
//!
//! **Unreachable targets** give [`IkError::Unreachable`] with the reason; targets whose
//! solutions all violate the limits give [`IkError::OutsideLimits`].
//!
//! **Branch labels** (`AnalyticSolution::branch`, `/`-separated):
//! - `shoulder-right` / `shoulder-left`: viewed from above (along `+z` of DH frame 0, the
//!   axis of joint 1), the arm's plane is offset to the right / left of the line from axis
//!   1 to the wrist centre; arms without a shoulder offset say `shoulder-front` (joint 1
//!   turned towards the wrist centre) / `shoulder-back` (turned away, reaching over);
//! - `elbow-up` / `elbow-down`: the elbow lies above / below the line from the shoulder to
//!   the wrist, "above" along world `+z` (for the planar 2R: in its plane);
//! - `extension-positive` / `extension-negative` (R R P arms): the sign of the boom length
//!   from the shoulder to the wrist centre;
//! - `wrist-up` / `wrist-down`: `sin θ5 ≥ 0` / `< 0`, `θ5` the DH angle of joint 5 (equal
//!   to `q5` for the bundled UR5 and Puma).

mod branches;
mod dh_family;
mod ik_error;
mod position_ik;
mod ur;
mod wrist;

pub use crate::kinematics::ik::analytic::branches::{
    Branch, RawSolution, Singularity, FREE_TOL, PLANE_TOL, REACH_TOL, SINGULAR_TOL,
};
pub use crate::kinematics::ik::analytic::dh_family::{dh_transform, DhChain, DhRow};
pub use crate::kinematics::ik::analytic::ik_error::{IkError, Unreachable};
pub use crate::kinematics::ik::analytic::position_ik::{
    planar_2r_ik, rrp_ik, Planar2rParams, RrpParams,
};
pub use ur::{ur_ik, ur_ik_with, UrParams};
pub use wrist::{wrist_ik, wrist_ik_with, WristArm, WristParams};

use crate::core::spatial::{Se3, Vec3};
use crate::kinematics::ik::analytic::branches::to_array;
use crate::model::Model;

/// One solution of [`solve`].
#[derive(Clone, Debug, PartialEq)]
pub struct AnalyticSolution {
    /// Joint values (the model's coordinates), inside the limits.
    pub q: Vec<f64>,
    /// Branch label, e.g. `shoulder-right/elbow-up/wrist-down` (see the module docs).
    pub branch: String,
    /// Whether any singularity flag is set.
    pub singular: bool,
    /// The flags.
    pub singularity: Singularity,
    /// The roots taken.
    pub roots: Branch,
}

/// Options of [`AnalyticSolver::solve`].
#[derive(Clone, Debug)]
pub struct AnalyticOptions {
    /// Values for free joints at singularities, and the reference the 2π wrapping
    /// stays closest to (zeros when `None`).
    pub seed: Option<Vec<f64>>,
    /// Drop solutions outside the joint limits (on by default).
    pub respect_limits: bool,
}

impl Default for AnalyticOptions {
    fn default() -> Self {
        Self {
            seed: None,
            respect_limits: true,
        }
    }
}

/// The supported structures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnalyticKind {
    /// UR3/5/10 and e-series.
    Ur,
    /// 6R, R ⟂ R ∥ R then a spherical wrist (Puma 560).
    WristRrr,
    /// R R P then a spherical wrist (Stanford arm).
    WristRrp,
    /// Spherical R-R-P arm, position only.
    SphericalRrp,
    /// Planar 2R, position in the plane.
    Planar2r,
}

impl AnalyticKind {
    /// Short name.
    pub fn as_str(&self) -> &'static str {
        match self {
            AnalyticKind::Ur => "ur",
            AnalyticKind::WristRrr => "wrist_rrr",
            AnalyticKind::WristRrp => "wrist_rrp",
            AnalyticKind::SphericalRrp => "spherical_rrp",
            AnalyticKind::Planar2r => "planar_2r",
        }
    }

    /// Whether the family solves for the position only (target orientation ignored).
    pub fn position_only(&self) -> bool {
        matches!(self, AnalyticKind::SphericalRrp | AnalyticKind::Planar2r)
    }
}

#[derive(Clone, Debug)]
enum Params {
    Ur(UrParams),
    Wrist(WristParams),
    Rrp(RrpParams),
    Planar(Planar2rParams),
}

/// A model recognised as one of the families, with its parameters, ready to solve.
#[derive(Clone, Debug)]
pub struct AnalyticSolver {
    kind: AnalyticKind,
    chain: DhChain,
    params: Params,
}

const ALL_KINDS: [AnalyticKind; 5] = [
    AnalyticKind::Ur,
    AnalyticKind::WristRrr,
    AnalyticKind::WristRrp,
    AnalyticKind::SphericalRrp,
    AnalyticKind::Planar2r,
];

impl AnalyticSolver {
    /// Recognises the family of the chain from the root to `link`.
    pub fn new(model: &Model, link: usize) -> Result<Self, IkError> {
        let mut why = Vec::new();
        for kind in ALL_KINDS {
            match Self::with_kind(model, link, kind) {
                Ok(s) => return Ok(s),
                Err(IkError::Unsupported(m)) => why.push(format!("{}: {m}", kind.as_str())),
                Err(e) => return Err(e),
            }
        }
        Err(IkError::Unsupported(format!(
            "'{}' matches none of the analytic families ({})",
            model.name,
            why.join("; ")
        )))
    }

    /// Uses the given family, failing with the structural mismatch when it does not fit.
    pub fn with_kind(model: &Model, link: usize, kind: AnalyticKind) -> Result<Self, IkError> {
        let chain = DhChain::from_model(model, link, !kind.position_only())?;
        let params = match kind {
            AnalyticKind::Ur => Params::Ur(UrParams::from_chain(&chain)?),
            AnalyticKind::WristRrr | AnalyticKind::WristRrp => {
                let p = WristParams::from_chain(&chain)?;
                let want = if kind == AnalyticKind::WristRrr {
                    WristArm::Rrr
                } else {
                    WristArm::Rrp
                };
                if p.arm != want {
                    return Err(IkError::Unsupported(format!(
                        "the arm is {:?}, not {want:?}",
                        p.arm
                    )));
                }
                Params::Wrist(p)
            }
            AnalyticKind::SphericalRrp => Params::Rrp(RrpParams::from_chain(&chain)?),
            AnalyticKind::Planar2r => Params::Planar(Planar2rParams::from_chain(&chain)?),
        };
        Ok(Self {
            kind,
            chain,
            params,
        })
    }

    /// The recognised family.
    pub fn kind(&self) -> AnalyticKind {
        self.kind
    }

    /// The DH table read from the model.
    pub fn chain(&self) -> &DhChain {
        &self.chain
    }

    /// The UR parameters, for [`ur_ik`].
    pub fn ur_params(&self) -> Option<&UrParams> {
        match &self.params {
            Params::Ur(p) => Some(p),
            _ => None,
        }
    }

    /// The spherical-wrist parameters, for [`wrist_ik`].
    pub fn wrist_params(&self) -> Option<&WristParams> {
        match &self.params {
            Params::Wrist(p) => Some(p),
            _ => None,
        }
    }

    /// All solutions for the target placement of the link (world frame). Position-only
    /// families use `target.trans` alone.
    pub fn solve(
        &self,
        target: &Se3,
        opts: &AnalyticOptions,
    ) -> Result<Vec<AnalyticSolution>, IkError> {
        let n = self.chain.len();
        if !target
            .trans
            .iter()
            .chain(target.rot.iter())
            .all(|v| v.is_finite())
        {
            return Err(IkError::InvalidInput("the target is not finite".into()));
        }
        if let Some(x) = target
            .trans
            .iter()
            .find(|x| x.abs() > super::MAX_TARGET_DISTANCE)
        {
            return Err(IkError::Unreachable(format!(
                "a coordinate of the target is {} m, beyond the {} m any arm reaches",
                crate::core::diag::fmt_num(*x),
                crate::core::diag::fmt_num(super::MAX_TARGET_DISTANCE)
            )));
        }
        let seed = match &opts.seed {
            Some(s) if s.len() != n => {
                return Err(IkError::InvalidInput(format!(
                    "the seed has {} values, the chain has {n} joints",
                    s.len()
                )))
            }
            Some(s) if !s.iter().all(|v| v.is_finite()) => {
                return Err(IkError::InvalidInput("the seed is not finite".into()))
            }
            Some(s) => s.clone(),
            None => vec![0.0; n],
        };
        let respect = opts.respect_limits;
        let raw: Vec<(Vec<f64>, Branch, Singularity)>;
        let candidates = match &self.params {
            Params::Ur(p) => {
                let mut out = Vec::with_capacity(8);
                let c = ur_ik_with(p, target, Some(&to_array(&seed)), respect, &mut out);
                raw = unpack(&out);
                c
            }
            Params::Wrist(p) => {
                let mut out = Vec::with_capacity(8);
                let c = wrist_ik_with(p, target, Some(&to_array(&seed)), respect, &mut out);
                raw = unpack(&out);
                c
            }
            Params::Rrp(p) => {
                let mut out = Vec::with_capacity(4);
                let c = rrp_ik(p, &target.trans, Some(&to_array(&seed)), respect, &mut out);
                raw = unpack(&out);
                c
            }
            Params::Planar(p) => {
                let mut out = Vec::with_capacity(2);
                let c = planar_2r_ik(p, &target.trans, Some(&to_array(&seed)), respect, &mut out);
                raw = unpack(&out);
                c
            }
        }
        .map_err(|u| IkError::Unreachable(u.0.to_string()))?;
        if raw.is_empty() {
            return Err(IkError::OutsideLimits { candidates });
        }
        Ok(raw
            .into_iter()
            .map(|(q, roots, singularity)| AnalyticSolution {
                branch: self.label(&q, roots),
                q,
                singular: singularity.any(),
                singularity,
                roots,
            })
            .collect())
    }

    /// The geometric branch label of a solution (see the module docs).
    fn label(&self, q: &[f64], roots: Branch) -> String {
        let o = self.chain.origins(q);
        let rows = &self.chain.rows;
        let mut parts: Vec<&'static str> = Vec::with_capacity(3);
        // Shoulder: wrist centre w and the axis-1/axis-2 geometry in DH frame 0.
        let wrist_centre = match self.kind {
            AnalyticKind::Ur => Some(o[5]),
            AnalyticKind::WristRrr | AnalyticKind::WristRrp => Some(o[4]),
            AnalyticKind::SphericalRrp => Some(o[3]),
            AnalyticKind::Planar2r => None,
        };
        if let Some(w) = wrist_centre {
            let a1 = rows[0].transform(q[0]);
            let z1 = a1.rot.column(2).into_owned();
            let offset = w.dot(&z1);
            let h = Vec3::new(w.x, w.y, 0.0);
            let side = h.cross(&(z1 * offset)).z;
            parts.push(if offset.abs() > SINGULAR_TOL && side.abs() > 1e-15 {
                if side < 0.0 {
                    "shoulder-right"
                } else {
                    "shoulder-left"
                }
            } else if roots.shoulder {
                "shoulder-back"
            } else {
                "shoulder-front"
            });
        }
        // Elbow: shoulder S, elbow E, wrist W, projected on the arm's plane (normal to
        // axis 2); "up" along world z.
        let elbow_points = match self.kind {
            AnalyticKind::Ur => Some((o[1], o[2], o[3])),
            AnalyticKind::WristRrr => Some((o[1], o[2], o[4])),
            AnalyticKind::Planar2r => Some((o[0], o[1], o[2])),
            _ => None,
        };
        if let Some((s, e, w)) = elbow_points {
            let normal = rows[0].transform(q[0]).rot.column(2).into_owned();
            let flat = |v: Vec3| v - normal * v.dot(&normal);
            let r = self.chain.base.rot;
            let (e, w) = (r * flat(e - s), r * flat(w - s));
            let up = match w.try_normalize(1e-12) {
                Some(wn) => (e - wn * e.dot(&wn)).z,
                None => 0.0,
            };
            let is_up = if up.abs() > 1e-12 {
                up > 0.0
            } else {
                !roots.elbow
            };
            parts.push(if is_up { "elbow-up" } else { "elbow-down" });
        } else if matches!(
            self.kind,
            AnalyticKind::WristRrp | AnalyticKind::SphericalRrp
        ) {
            parts.push(if roots.elbow {
                "extension-negative"
            } else {
                "extension-positive"
            });
        }
        if matches!(
            self.kind,
            AnalyticKind::Ur | AnalyticKind::WristRrr | AnalyticKind::WristRrp
        ) {
            parts.push(if roots.wrist {
                "wrist-down"
            } else {
                "wrist-up"
            });
        }
        parts.join("/")
    }
}

fn unpack<const N: usize>(out: &[RawSolution<N>]) -> Vec<(Vec<f64>, Branch, Singularity)> {
    out.iter()
        .map(|s| (s.q.to_vec(), s.branch, s.singularity))
        .collect()
}

/// All solutions for the placement `target` (world frame) of `link`, with default options.
///
/// Recognises the family from the model (see [`AnalyticSolver::new`]); building the
/// solver once and calling [`AnalyticSolver::solve`] avoids re-reading the model.
pub fn solve(model: &Model, link: usize, target: &Se3) -> Result<Vec<AnalyticSolution>, IkError> {
    AnalyticSolver::new(model, link)?.solve(target, &AnalyticOptions::default())
}

/// [`solve`] with options.
pub fn solve_with(
    model: &Model,
    link: usize,
    target: &Se3,
    opts: &AnalyticOptions,
) -> Result<Vec<AnalyticSolution>, IkError> {
    AnalyticSolver::new(model, link)?.solve(target, opts)
}
