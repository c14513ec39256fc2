//! What the fixed-size analytic solvers share: the tolerances, the roots taken
//! ([`Branch`]) and singularity flags of a solution, the [`Sink`] that fits DH variables
//! into the joint limits, and the shoulder-root and twist helpers.

use crate::kinematics::ik::analytic::dh_family::{DhChain, DhRow};
use crate::kinematics::ik::analytic::ik_error::{IkError, Unreachable};
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
/// `wrist`: first = `sin θ5 ≥ 0`.
/// [`AnalyticSolution::branch`](super::AnalyticSolution::branch) turns these into geometric
/// labels.
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

/// `v` as a fixed-size array (zeros past its end).
pub(crate) fn to_array<const N: usize>(v: &[f64]) -> [f64; N] {
    let mut a = [0.0; N];
    a.copy_from_slice(v);
    a
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
