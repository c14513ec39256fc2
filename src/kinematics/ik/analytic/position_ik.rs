//! Position-only closed forms: the spherical R-R-P arm and the planar 2R arm.
//!
//! Spherical R-R-P (`α1 = σ1 π/2`, `a2 = 0`, `α2 = σ2 π/2`, prismatic joint 3 along
//! `z2` with `a3 = 0`): the tool point is `O2 + d3 z2`, so with the shoulder offset `d2`
//! along `z1` the shoulder equation gives `θ1 = φ + atan2(σ1 d2, ±√(R² − d2²))`, and in
//! frame 1 `(X, Y) = d3 (σ2 s2, −σ2 c2)`: `d3 = ±√(X² + Y²)`. For the textbook arm
//! (`d2 = 0`, DH frame 0 at the shoulder centre) these are `g1 = atan2(y, x)`,
//! `b2 = atan2(z, √(x² + y²))`, `r = |p|` and `(g1 + π, π − b2, r)`, plus the two
//! negative-extension solutions.
//!
//! Planar 2R (`α1 = 0`): in DH frame 0 the tip is
//! `(a1 c1 + a2 c12, a1 s1 + a2 s12, d1 + d2)`: `cos θ2 = (x² + y² − a1² − a2²) / (2 a1 a2)`,
//! `θ2 = atan2(±√(1 − cos² θ2), cos θ2)`, `θ1 = atan2(y, x) − atan2(a2 s2, a1 + a2 c2)`.

use crate::core::spatial::{Se3, Vec3};
use crate::kinematics::ik::analytic::branches::{
    fixed, is_quarter, shoulder_roots, twist_sign, Branch, RawSolution, Singularity, Sink,
    FREE_TOL, PLANE_TOL, REACH_TOL, SINGULAR_TOL,
};
use crate::kinematics::ik::analytic::dh_family::{DhChain, DhRow};
use crate::kinematics::ik::analytic::ik_error::{IkError, Unreachable};
use crate::model::Model;

/// Parameters of a spherical R-R-P arm.
#[derive(Clone, Debug, PartialEq)]
pub struct RrpParams {
    /// DH rows 1..3.
    pub rows: [DhRow; 3],
    /// World → DH frame 0.
    pub base: Se3,
    /// Lower joint limits.
    pub lower: [f64; 3],
    /// Upper joint limits.
    pub upper: [f64; 3],
    base_inv: Se3,
}

impl RrpParams {
    /// From rows, base and limits.
    pub fn new(rows: [DhRow; 3], base: Se3, lower: [f64; 3], upper: [f64; 3]) -> Self {
        Self {
            rows,
            base,
            lower,
            upper,
            base_inv: base.inverse(),
        }
    }

    /// Checks the structure of a DH table (the target link must be at frame 3's origin).
    pub fn from_chain(chain: &DhChain) -> Result<Self, IkError> {
        let (rows, lower, upper) = fixed::<3>(chain)?;
        let bad = |m: &str| {
            Err(IkError::Unsupported(format!(
                "not a spherical R-R-P arm: {m}"
            )))
        };
        let [r1, r2, r3] = &rows;
        if !(r1.revolute && r2.revolute && !r3.revolute) {
            return bad("the joints are not R, R, P");
        }
        if !is_quarter(r1.alpha) || !is_quarter(r2.alpha) || r2.a != 0.0 {
            return bad("axes 1, 2 and the boom are not mutually perpendicular and meeting");
        }
        if r3.a != 0.0 || chain.tool.trans.norm() > 1e-12 {
            return bad("the target link is not on the boom's axis");
        }
        Ok(Self::new(rows, chain.base, lower, upper))
    }

    /// Reads the parameters from the chain from the root to `link` of a model.
    pub fn from_model(model: &Model, link: usize) -> Result<Self, IkError> {
        Self::from_chain(&DhChain::from_model(model, link, false)?)
    }
}

/// All solutions inside the limits placing frame 3's origin at the world point `target`,
/// into `out` (cleared first). Returns the number found before the limits were applied.
pub fn rrp_ik(
    params: &RrpParams,
    target: &Vec3,
    seed: Option<&[f64; 3]>,
    respect_limits: bool,
    out: &mut Vec<RawSolution<3>>,
) -> Result<usize, Unreachable> {
    out.clear();
    let p = params.base_inv.act_point(target);
    let [r1, r2, _] = &params.rows;
    let mut sink = Sink::new(
        &params.rows,
        &params.lower,
        &params.upper,
        seed,
        respect_limits,
        out,
    );
    let s_1 = twist_sign(r1.alpha);
    let s_2 = twist_sign(r2.alpha);
    let shoulder = shoulder_roots(p.x, p.y, s_1 * r2.d, sink.free(0))?;
    for ia in 0..shoulder.n {
        let th1 = shoulder.theta[ia];
        let (s1, c1) = th1.sin_cos();
        let x = c1 * p.x + s1 * p.y - r1.a;
        let y = s_1 * (p.z - r1.d);
        let rho = x.hypot(y);
        let singularity = Singularity {
            shoulder: shoulder.singular,
            elbow: rho < SINGULAR_TOL,
            wrist: false,
        };
        if rho < FREE_TOL {
            sink.push(
                [th1, sink.free(1), 0.0],
                Branch {
                    shoulder: ia == 1,
                    ..Branch::default()
                },
                singularity,
            );
            continue;
        }
        for ie in 0..2 {
            let sg = if ie == 0 { 1.0 } else { -1.0 };
            let th2 = (s_2 * x * sg).atan2(-s_2 * y * sg);
            sink.push(
                [th1, th2, sg * rho],
                Branch {
                    shoulder: ia == 1,
                    elbow: ie == 1,
                    wrist: false,
                },
                singularity,
            );
        }
    }
    Ok(sink.candidates)
}

/// Parameters of a planar 2R arm.
#[derive(Clone, Debug, PartialEq)]
pub struct Planar2rParams {
    /// DH rows 1..2.
    pub rows: [DhRow; 2],
    /// World → DH frame 0.
    pub base: Se3,
    /// Lower joint limits.
    pub lower: [f64; 2],
    /// Upper joint limits.
    pub upper: [f64; 2],
    base_inv: Se3,
}

impl Planar2rParams {
    /// From rows, base and limits.
    pub fn new(rows: [DhRow; 2], base: Se3, lower: [f64; 2], upper: [f64; 2]) -> Self {
        Self {
            rows,
            base,
            lower,
            upper,
            base_inv: base.inverse(),
        }
    }

    /// Checks the structure of a DH table (the target link must be at frame 2's origin).
    pub fn from_chain(chain: &DhChain) -> Result<Self, IkError> {
        let (rows, lower, upper) = fixed::<2>(chain)?;
        let bad = |m: &str| Err(IkError::Unsupported(format!("not a planar 2R arm: {m}")));
        let [r1, r2] = &rows;
        if !(r1.revolute && r2.revolute) {
            return bad("a joint is prismatic");
        }
        if r1.alpha != 0.0 {
            return bad("the two axes are not parallel (same direction)");
        }
        if r1.a == 0.0 || r2.a == 0.0 {
            return bad("a zero link length");
        }
        if chain.tool.trans.norm() > 1e-12 {
            return bad("the target link is not at the tip frame");
        }
        Ok(Self::new(rows, chain.base, lower, upper))
    }

    /// Reads the parameters from the chain from the root to `link` of a model.
    pub fn from_model(model: &Model, link: usize) -> Result<Self, IkError> {
        Self::from_chain(&DhChain::from_model(model, link, false)?)
    }
}

/// Elbow-up and elbow-down solutions placing the tip at the world point `target` (which
/// must lie in the arm's plane, within [`PLANE_TOL`]), into `out` (cleared first).
pub fn planar_2r_ik(
    params: &Planar2rParams,
    target: &Vec3,
    seed: Option<&[f64; 2]>,
    respect_limits: bool,
    out: &mut Vec<RawSolution<2>>,
) -> Result<usize, Unreachable> {
    out.clear();
    let p = params.base_inv.act_point(target);
    let [r1, r2] = &params.rows;
    if (p.z - r1.d - r2.d).abs() > PLANE_TOL {
        return Err(Unreachable("the target is not in the arm's plane"));
    }
    let mut sink = Sink::new(
        &params.rows,
        &params.lower,
        &params.upper,
        seed,
        respect_limits,
        out,
    );
    let (a1, a2) = (r1.a, r2.a);
    let r = p.x.hypot(p.y);
    let c2 = (r * r - a1 * a1 - a2 * a2) / (2.0 * a1 * a2);
    if c2.abs() > 1.0 + REACH_TOL {
        return Err(Unreachable(
            "the target is out of reach (farther than |a1| + |a2| or closer than ||a1| − |a2||)",
        ));
    }
    let c2 = c2.clamp(-1.0, 1.0);
    let s2abs = ((1.0 - c2) * (1.0 + c2)).sqrt();
    let free = r < FREE_TOL;
    let singularity = Singularity {
        shoulder: r < SINGULAR_TOL,
        elbow: s2abs < SINGULAR_TOL,
        wrist: false,
    };
    let phi = p.y.atan2(p.x);
    for ie in 0..(if s2abs == 0.0 { 1 } else { 2 }) {
        let s2 = if ie == 0 { s2abs } else { -s2abs };
        let th2 = s2.atan2(c2);
        let th1 = if free {
            sink.free(0)
        } else {
            phi - (a2 * s2).atan2(a1 + a2 * c2)
        };
        sink.push(
            [th1, th2],
            Branch {
                elbow: ie == 1,
                ..Branch::default()
            },
            singularity,
        );
    }
    Ok(sink.candidates)
}
