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

mod dh_family;
mod position_ik;
mod ur;
mod wrist;

pub use crate::kinematics::ik::analytic::dh_family::{dh_transform, DhChain, DhRow};
pub use crate::kinematics::ik::analytic::position_ik::{
    planar_2r_ik, rrp_ik, Planar2rParams, RrpParams,
};
pub use ur::{ur_ik, ur_ik_with, UrParams};
pub use wrist::{wrist_ik, wrist_ik_with, WristArm, WristParams};

use crate::core::spatial::{Se3, Vec3};
use crate::model::Model;
use std::f64::consts::TAU;

/// A solution is flagged singular when the relevant sine (elbow, wrist) or the wrist
/// centre's distance in metres from the shoulder-singular plane is below this.
pub const SINGULAR_TOL: f64 = 1e-7;
/// Below this (a sine, or metres) the solution set is treated as a continuum and the free
/// joint takes its seed value; the pose error this costs is below 1e-13.
pub const FREE_TOL: f64 = 1e-14;
/// Tolerance (in the cosine, or metres) within which a just-unreachable target is
/// clamped onto the boundary of the workspace instead of being rejected.
pub const REACH_TOL: f64 = 1e-12;
/// Distance (m) within which a planar arm's target counts as being in its plane.
pub const PLANE_TOL: f64 = 1e-9;
/// A joint value may exceed its limit by this much (then it is clamped).
const LIMIT_TOL: f64 = 1e-12;

/// Why the analytic solver gives no solution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkError {
    /// The model (or the chosen link) is not one of the supported families.
    #[error("analytic IK does not support this model: {0}")]
    Unsupported(String),
    /// The target is outside the workspace (no solution, limits aside).
    #[error("unreachable target: {0}")]
    Unreachable(String),
    /// Solutions exist, but none within the joint limits.
    #[error("no solution inside the joint limits ({candidates} solutions outside them)")]
    OutsideLimits {
        /// How many solutions the limits rejected.
        candidates: usize,
    },
    /// A non-finite target or a malformed seed.
    #[error("invalid input: {0}")]
    InvalidInput(String),
}

/// The reason the fixed-size solvers give for an unreachable target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unreachable(pub &'static str);

/// Which singular configurations a solution is at or near (within [`SINGULAR_TOL`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Singularity {
    /// Wrist centre on the plane of axes 1 and 2 (shoulder roots merge), or on axis 1.
    pub shoulder: bool,
    /// Arm stretched or folded (elbow roots merge), or an R R P boom of zero length.
    pub elbow: bool,
    /// `sin θ5 = 0`: axes 4 and 6 aligned.
    pub wrist: bool,
}

impl Singularity {
    /// Any of the three.
    pub fn any(&self) -> bool {
        self.shoulder || self.elbow || self.wrist
    }
}

/// Which root of each square root a solution took (`false` = the first).
///
/// `shoulder`: first = `cos(θ1 − φ) ≥ 0` (φ the azimuth of the wrist centre); `elbow`:
/// first = the positive sine of the elbow angle (R R P arms: positive boom length);
/// `wrist`: first = `sin θ5 ≥ 0`. [`AnalyticSolution::branch`] turns these into
/// geometric labels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Branch {
    /// Second shoulder root.
    pub shoulder: bool,
    /// Second elbow (or boom-sign) root.
    pub elbow: bool,
    /// Second wrist root.
    pub wrist: bool,
}

/// A solution of a fixed-size solver: joint values (chain order), branch and flags.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawSolution<const N: usize> {
    /// Joint values, wrapped into the limits.
    pub q: [f64; N],
    /// The roots taken.
    pub branch: Branch,
    /// Singularity flags.
    pub singularity: Singularity,
}

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

fn to_array<const N: usize>(v: &[f64]) -> [f64; N] {
    let mut a = [0.0; N];
    a.copy_from_slice(v);
    a
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

/// Joint value for DH variable `v` of `row`, moved into `[lo, hi]` (revolute: by multiples
/// of 2π, closest to `reference`), or `None` when it cannot be. Without limits revolute
/// values are only wrapped towards `reference`.
#[inline]
pub(crate) fn fit_joint(
    row: &DhRow,
    v: f64,
    lo: f64,
    hi: f64,
    reference: f64,
    respect: bool,
) -> Option<f64> {
    let q = row.joint(v);
    if !row.revolute {
        if !respect {
            return Some(q);
        }
        return (q >= lo - LIMIT_TOL && q <= hi + LIMIT_TOL).then(|| q.clamp(lo, hi));
    }
    let k = ((reference - q) * (1.0 / TAU)).round();
    if !respect {
        return Some(q + k * TAU);
    }
    let near = q + k * TAU;
    if near >= lo && near <= hi {
        return Some(near);
    }
    let kmin = ((lo - LIMIT_TOL - q) / TAU).ceil();
    let kmax = ((hi + LIMIT_TOL - q) / TAU).floor();
    if kmin > kmax {
        return None;
    }
    Some((q + k.clamp(kmin, kmax) * TAU).clamp(lo, hi))
}

/// Collects the solutions of a fixed-size solver: converts DH variables to joint values,
/// applies the limits and counts the candidates.
pub(crate) struct Sink<'a, const N: usize> {
    pub rows: &'a [DhRow; N],
    pub lower: &'a [f64; N],
    pub upper: &'a [f64; N],
    pub reference: [f64; N],
    pub respect: bool,
    pub out: &'a mut Vec<RawSolution<N>>,
    pub candidates: usize,
}

impl<'a, const N: usize> Sink<'a, N> {
    /// A sink for the solutions of one target: `seed` (default zeros) is the reference
    /// for free joints and wrapping; `respect` keeps only solutions inside the limits.
    pub(crate) fn new(
        rows: &'a [DhRow; N],
        lower: &'a [f64; N],
        upper: &'a [f64; N],
        seed: Option<&[f64; N]>,
        respect: bool,
        out: &'a mut Vec<RawSolution<N>>,
    ) -> Self {
        Sink {
            rows,
            lower,
            upper,
            reference: seed.copied().unwrap_or([0.0; N]),
            respect,
            out,
            candidates: 0,
        }
    }

    /// DH variable of joint `k` at its reference value (for free joints).
    #[inline]
    pub fn free(&self, k: usize) -> f64 {
        self.rows[k].variable(self.reference[k])
    }

    #[inline]
    pub fn push(&mut self, v: [f64; N], branch: Branch, singularity: Singularity) {
        self.candidates += 1;
        let mut q = [0.0; N];
        for k in 0..N {
            match fit_joint(
                &self.rows[k],
                v[k],
                self.lower[k],
                self.upper[k],
                self.reference[k],
                self.respect,
            ) {
                Some(x) => q[k] = x,
                None => return,
            }
        }
        self.out.push(RawSolution {
            q,
            branch,
            singularity,
        });
    }
}

/// The roots of `sin θ · wx − cos θ · wy = dd` (the shoulder equation: the wrist centre's
/// component along `z1` is the shoulder offset): `θ = φ + atan2(dd, ±√(R² − dd²))`, with
/// their sines and cosines. `free` is used when the equation is degenerate (`R = dd = 0`
/// within the tolerances); past this point `R > 0`, so nothing divides by zero.
pub(crate) struct ShoulderRoots {
    pub theta: [f64; 2],
    pub sin: [f64; 2],
    pub cos: [f64; 2],
    pub n: usize,
    pub singular: bool,
}

#[inline]
pub(crate) fn shoulder_roots(
    wx: f64,
    wy: f64,
    dd: f64,
    free: f64,
) -> Result<ShoulderRoots, Unreachable> {
    let r = wx.hypot(wy);
    if r < FREE_TOL && dd.abs() <= REACH_TOL {
        let (s, c) = free.sin_cos();
        return Ok(ShoulderRoots {
            theta: [free; 2],
            sin: [s; 2],
            cos: [c; 2],
            n: 1,
            singular: true,
        });
    }
    let ad = dd.abs();
    if r < ad - REACH_TOL {
        return Err(Unreachable(
            "the wrist centre is closer to axis 1 than the shoulder offset",
        ));
    }
    let c = ((r - ad).max(0.0) * (r + ad)).sqrt();
    // cos/sin(φ + β) with (cos φ, sin φ) = (wx, wy)/R, (cos β, sin β) = (±c, dd)/|(c, dd)|.
    let k = 1.0 / (r * c.hypot(dd));
    let mut out = ShoulderRoots {
        theta: [0.0; 2],
        sin: [0.0; 2],
        cos: [0.0; 2],
        n: if c == 0.0 { 1 } else { 2 },
        singular: c < SINGULAR_TOL,
    };
    for (i, cb) in [c, -c].into_iter().enumerate() {
        let s1 = (wy * cb + wx * dd) * k;
        let c1 = (wx * cb - wy * dd) * k;
        out.theta[i] = s1.atan2(c1);
        out.sin[i] = s1;
        out.cos[i] = c1;
    }
    Ok(out)
}

/// `±1` from the sign of `sin α` for a twist of ±π/2.
#[inline]
pub(crate) fn twist_sign(alpha: f64) -> f64 {
    if alpha > 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Whether `alpha` is ±π/2 (as snapped by the extraction or typed by hand).
pub(crate) fn is_quarter(alpha: f64) -> bool {
    (alpha.abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-12
}

/// Rows, lower and upper limits as fixed-size arrays.
pub(crate) type FixedChain<const N: usize> = ([DhRow; N], [f64; N], [f64; N]);

/// Rows and limits of a chain as fixed-size arrays, for the parameter structs.
pub(crate) fn fixed<const N: usize>(chain: &DhChain) -> Result<FixedChain<N>, IkError> {
    if chain.len() != N {
        return Err(IkError::Unsupported(format!(
            "{} joints, this family has {N}",
            chain.len()
        )));
    }
    let rows: [DhRow; N] = std::array::from_fn(|k| chain.rows[k]);
    Ok((rows, to_array(&chain.lower), to_array(&chain.upper)))
}
