//! 6-DOF arms with a spherical wrist (Pieper): the Puma 560 (R R R) and the Stanford arm
//! (R R P).
//!
//! Axes 4, 5, 6 meet at the wrist centre `w = p − d6 z6` (`a4 = a5 = d5 = a6 = 0`), whose
//! position depends on joints 1–3 only. With `θi` the DH variables and
//! `z1 = σ1 (sin θ1, −cos θ1, 0)` (`α1 = σ1 π/2`), everything after joint 1 sits at the
//! constant offset `D` along `z1` (`D = d2 + d3` for R R R, `d2` for R R P), so
//! `θ1 = φ + atan2(σ1 D, ±√(R² − D²))` as for the UR. In frame 1 the wrist centre is
//! `(X, Y) = (c1 wx + s1 wy − a1, σ1 (wz − d1))`, and
//! - R R R (`α2 = 0`, `α3 = σ3 π/2`): `X = a2 c2 + a3 c23 + σ3 d4 s23`,
//!   `Y = a2 s2 + a3 s23 − σ3 d4 c23`, a planar 2R with the second link
//!   `L = √(a3² + d4²)` at angle `ψ = atan2(−σ3 d4, a3)`: `β = θ3 + ψ = ±acos(..)`;
//! - R R P (`a2 = a3 = 0`, `α2 = σ2 π/2`, `α3 = 0`): `(X, Y) = ρ (σ2 s2, −σ2 c2)` with
//!   `ρ = d3 + d4 = ±√(X² + Y²)`.
//!
//! The wrist: `M = ³R₆ = Rz(θ4) Rx(α4) Rz(θ5) Rx(α5) Rz(θ6)` (`α6 = 0`) has third column
//! `σ5 s5 (c4, s4, ·)`, `m22 = −σ4 σ5 c5` and third row `σ4 s5 (c6, −s6, ·)`:
//! `θ5 = atan2(±|(m02, m12)|, −σ4 σ5 m22)`, `θ6 = atan2(−σ4 m21 / s5, σ4 m20 / s5)`, and
//! `θ4` from `Rz(θ4) = M (⁴R₆(θ5, θ6))ᵀ Rx(α4)ᵀ`, so that near `s5 = 0` `θ4` absorbs the
//! error of `θ6` and the orientation stays exact.

use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::kinematics::ik::analytic::branches::{
    fixed, is_quarter, shoulder_roots, twist_sign, Branch, RawSolution, Singularity, Sink,
    FREE_TOL, REACH_TOL, SINGULAR_TOL,
};
use crate::kinematics::ik::analytic::dh_family::{dh_transform, dh_transform_sc, exact_sin_cos};
use crate::kinematics::ik::analytic::dh_family::{DhChain, DhRow};
use crate::kinematics::ik::analytic::ik_error::{IkError, Unreachable};
use crate::model::Model;
use std::f64::consts::{FRAC_PI_2, PI};

/// The arm before the wrist.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WristArm {
    /// R ⟂ R ∥ R (Puma 560).
    Rrr,
    /// R ⟂ R ⟂ P (Stanford arm).
    Rrp,
}

/// Parameters of a spherical-wrist arm (see [`WristArm`]).
#[derive(Clone, Debug, PartialEq)]
pub struct WristParams {
    /// The arm type.
    pub arm: WristArm,
    /// DH rows 1..6.
    pub rows: [DhRow; 6],
    /// World → DH frame 0.
    pub base: Se3,
    /// DH frame 6 → target link.
    pub tool: Se3,
    /// Lower joint limits.
    pub lower: [f64; 6],
    /// Upper joint limits.
    pub upper: [f64; 6],
    base_inv: Se3,
    tool_inv: Se3,
}

fn rrow(d: f64, a: f64, alpha: f64) -> DhRow {
    DhRow {
        theta: 0.0,
        d,
        a,
        alpha,
        revolute: true,
    }
}

impl WristParams {
    /// The Puma 560 of `robots/puma560.toml` (Corke's table with the 0.67183 m pedestal;
    /// Corke's `qlim` limits), base and tool identity.
    pub fn puma560() -> Self {
        let deg = |a: [f64; 6]| a.map(f64::to_radians);
        Self::from_parts(
            WristArm::Rrr,
            [
                rrow(0.67183, 0.0, FRAC_PI_2),
                rrow(0.0, 0.4318, 0.0),
                rrow(0.15005, 0.0203, -FRAC_PI_2),
                rrow(0.4318, 0.0, FRAC_PI_2),
                rrow(0.0, 0.0, -FRAC_PI_2),
                rrow(0.0, 0.0, 0.0),
            ],
            Se3::identity(),
            Se3::identity(),
            deg([-160.0, -45.0, -225.0, -110.0, -100.0, -266.0]),
            deg([160.0, 225.0, 45.0, 170.0, 100.0, 266.0]),
        )
    }

    /// The Stanford arm of `robots/stanford.toml` (Corke's MATLAB `mdl_stanford`, boom
    /// stroke 0.3048..1.27 m), base and tool identity.
    pub fn stanford() -> Self {
        let r = |a: f64| a.to_radians();
        Self::from_parts(
            WristArm::Rrp,
            [
                rrow(0.412, 0.0, -FRAC_PI_2),
                rrow(0.154, 0.0, FRAC_PI_2),
                DhRow {
                    theta: -FRAC_PI_2,
                    d: 0.0,
                    a: 0.0,
                    alpha: 0.0,
                    revolute: false,
                },
                rrow(0.0, 0.0, -FRAC_PI_2),
                rrow(0.0, 0.0, FRAC_PI_2),
                rrow(0.263, 0.0, 0.0),
            ],
            Se3::identity(),
            Se3::identity(),
            [r(-170.0), r(-170.0), 0.3048, r(-170.0), r(-90.0), r(-170.0)],
            [r(170.0), r(170.0), 1.27, r(170.0), r(90.0), r(170.0)],
        )
    }

    /// The same arm with other joint limits.
    pub fn with_limits(self, lower: [f64; 6], upper: [f64; 6]) -> Self {
        Self::from_parts(self.arm, self.rows, self.base, self.tool, lower, upper)
    }

    /// The same arm with another world → DH frame 0 transform.
    pub fn with_base(self, base: Se3) -> Self {
        Self::from_parts(self.arm, self.rows, base, self.tool, self.lower, self.upper)
    }

    /// The same arm with another DH frame 6 → target transform.
    pub fn with_tool(self, tool: Se3) -> Self {
        Self::from_parts(self.arm, self.rows, self.base, tool, self.lower, self.upper)
    }

    fn from_parts(
        arm: WristArm,
        rows: [DhRow; 6],
        base: Se3,
        tool: Se3,
        lower: [f64; 6],
        upper: [f64; 6],
    ) -> Self {
        Self {
            arm,
            rows,
            base,
            tool,
            lower,
            upper,
            base_inv: base.inverse(),
            tool_inv: tool.inverse(),
        }
    }

    /// Checks the structure of a DH table.
    pub fn from_chain(chain: &DhChain) -> Result<Self, IkError> {
        let (rows, lower, upper) = fixed::<6>(chain)?;
        let bad = |m: &str| {
            Err(IkError::Unsupported(format!(
                "not a spherical-wrist arm of a supported type: {m}"
            )))
        };
        let [r1, r2, r3, r4, r5, r6] = &rows;
        if !(r1.revolute && r2.revolute && r4.revolute && r5.revolute && r6.revolute) {
            return bad("only joint 3 may be prismatic");
        }
        if r4.a != 0.0 || r5.a != 0.0 || r5.d != 0.0 || r6.a != 0.0 || r6.alpha != 0.0 {
            return bad("axes 4, 5 and 6 do not meet in one point");
        }
        if !is_quarter(r4.alpha) || !is_quarter(r5.alpha) {
            return bad("the wrist axes are not perpendicular");
        }
        if !is_quarter(r1.alpha) {
            return bad("axes 1 and 2 are not perpendicular");
        }
        let arm = if r3.revolute {
            if r2.alpha != 0.0 || !is_quarter(r3.alpha) || r2.a == 0.0 || r3.a.hypot(r4.d) == 0.0 {
                return bad("R R R arm without axis 2 ∥ axis 3 ⟂ axis 4");
            }
            WristArm::Rrr
        } else {
            if r2.a != 0.0 || !is_quarter(r2.alpha) || r3.a != 0.0 || r3.alpha != 0.0 {
                return bad("R R P arm whose boom does not cross axis 2 at right angles");
            }
            WristArm::Rrp
        };
        Ok(Self::from_parts(
            arm, rows, chain.base, chain.tool, lower, upper,
        ))
    }

    /// Reads the parameters from the chain from the root to `link` of a model.
    pub fn from_model(model: &Model, link: usize) -> Result<Self, IkError> {
        Self::from_chain(&DhChain::from_model(model, link, true)?)
    }

    /// World placement of the target link at `q`.
    pub fn fk(&self, q: &[f64; 6]) -> Se3 {
        crate::kinematics::ik::analytic::dh_family::table_fk(&self.base, &self.rows, &self.tool, q)
    }
}

/// All solutions inside the limits for the world placement `target`, into `out`
/// (cleared first). Returns the number found before the limits were applied. Does not
/// allocate when `out` has room for 8.
pub fn wrist_ik(
    params: &WristParams,
    target: &Se3,
    out: &mut Vec<RawSolution<6>>,
) -> Result<usize, Unreachable> {
    wrist_ik_with(params, target, None, true, out)
}

/// [`wrist_ik`] with a seed and the limits optional (see
/// [`crate::kinematics::ik::analytic::ur_ik_with`]).
// One closed-form derivation read top to bottom (shoulder, wrist, elbow roots) on the IK
// hot path: the branches share a dozen intermediate sines, cosines and transforms, which
// helper functions would have to pass back and forth.
#[allow(clippy::too_many_lines)]
pub fn wrist_ik_with(
    params: &WristParams,
    target: &Se3,
    seed: Option<&[f64; 6]>,
    respect_limits: bool,
    out: &mut Vec<RawSolution<6>>,
) -> Result<usize, Unreachable> {
    out.clear();
    let t = params.base_inv.mul(target).mul(&params.tool_inv);
    let rows = &params.rows;
    let [r1, r2, r3, r4, r5, r6] = rows;
    let mut sink = Sink::new(
        rows,
        &params.lower,
        &params.upper,
        seed,
        respect_limits,
        out,
    );
    let s_1 = twist_sign(r1.alpha);
    let s_4 = twist_sign(r4.alpha);
    let s_5 = twist_sign(r5.alpha);
    let z6 = Vec3::new(t.rot[(0, 2)], t.rot[(1, 2)], t.rot[(2, 2)]);
    let w = t.trans - z6 * r6.d;
    let offset = match params.arm {
        WristArm::Rrr => r2.d + r3.d,
        WristArm::Rrp => r2.d,
    };
    let shoulder = shoulder_roots(w.x, w.y, s_1 * offset, sink.free(0))?;
    let rot = |s: f64, c: f64, alpha: f64| {
        let (sa, ca) = exact_sin_cos(alpha);
        dh_transform_sc(s, c, 0.0, 0.0, sa, ca).rot
    };
    // Rz(θ3) Rx(α3) of a prismatic joint 3 is constant.
    let r23_fixed = dh_transform(r3.theta, 0.0, 0.0, r3.alpha).rot;
    let mut arm_ok = false;
    for ia in 0..shoulder.n {
        let th1 = shoulder.theta[ia];
        let (s1, c1) = (shoulder.sin[ia], shoulder.cos[ia]);
        let x = c1 * w.x + s1 * w.y - r1.a;
        let y = s_1 * (w.z - r1.d);
        let r01 = rot(s1, c1, r1.alpha);
        // Up to two (θ2, θ3 or d3, ⁰R₃) per shoulder root.
        let mut arms = [(0.0, 0.0, Mat3::zeros()); 2];
        let n_arm;
        let elbow_singular;
        match params.arm {
            WristArm::Rrr => {
                let s_3 = twist_sign(r3.alpha);
                let (a2, a3, d4) = (r2.a, r3.a, r4.d);
                let l = a3.hypot(d4);
                // (cos ψ, sin ψ) of the forearm's direction in frame 3.
                let (cp, sp) = (a3 / l, -s_3 * d4 / l);
                let cb = (x * x + y * y - a2 * a2 - l * l) / (2.0 * a2 * l);
                if cb.abs() > 1.0 + REACH_TOL {
                    continue;
                }
                let cb = cb.clamp(-1.0, 1.0);
                let sbabs = ((1.0 - cb) * (1.0 + cb)).sqrt();
                n_arm = if sbabs == 0.0 { 1 } else { 2 };
                for (ie, slot) in arms.iter_mut().enumerate().take(n_arm) {
                    let sb = if ie == 0 { sbabs } else { -sbabs };
                    // θ2 = atan2(y, x) − atan2(L sβ, a2 + L cβ); θ3 = β − ψ.
                    let (k1, k2) = (a2 + l * cb, l * sb);
                    let (u, v) = (y * k1 - x * k2, x * k1 + y * k2);
                    let th2 = u.atan2(v);
                    let n = u.hypot(v);
                    let (s2, c2) = if n > 0.0 { (u / n, v / n) } else { (0.0, 1.0) };
                    let (s3, c3) = (sb * cp - cb * sp, cb * cp + sb * sp);
                    let th3 = s3.atan2(c3);
                    let (s23, c23) = (s2 * c3 + c2 * s3, c2 * c3 - s2 * s3);
                    *slot = (th2, th3, r01 * rot(s23, c23, r3.alpha));
                }
                elbow_singular = sbabs < SINGULAR_TOL;
            }
            WristArm::Rrp => {
                let s_2 = twist_sign(r2.alpha);
                let rho = x.hypot(y);
                if rho < FREE_TOL {
                    n_arm = 1;
                    let th2 = sink.free(1);
                    let (s2, c2) = th2.sin_cos();
                    arms[0] = (th2, -r4.d, r01 * rot(s2, c2, r2.alpha) * r23_fixed);
                } else {
                    n_arm = 2;
                    for (ie, slot) in arms.iter_mut().enumerate() {
                        let sg = if ie == 0 { 1.0 } else { -1.0 };
                        let (s2, c2) = (s_2 * x * sg / rho, -s_2 * y * sg / rho);
                        let r03 = r01 * rot(s2, c2, r2.alpha) * r23_fixed;
                        *slot = (s2.atan2(c2), sg * rho - r4.d, r03);
                    }
                }
                elbow_singular = rho < SINGULAR_TOL;
            }
        }
        arm_ok = true;
        for (ie, &(th2, v3, r03)) in arms.iter().enumerate().take(n_arm) {
            let m = r03.transpose() * t.rot;
            let c5 = (-s_4 * s_5 * m[(2, 2)]).clamp(-1.0, 1.0);
            let s5abs = m[(0, 2)].hypot(m[(1, 2)]);
            let wrist_free = s5abs < FREE_TOL;
            // The second wrist root is (−θ5, θ6 + π).
            let th5abs = s5abs.atan2(c5);
            let mut th6_first = 0.0;
            for iw in 0..(if wrist_free { 1 } else { 2 }) {
                let ws = if iw == 0 { 1.0 } else { -1.0 };
                let s5 = ws * s5abs;
                let th5 = ws * th5abs;
                let (th6, s6, c6) = if wrist_free {
                    let th6 = sink.free(5);
                    let (s6, c6) = th6.sin_cos();
                    (th6, s6, c6)
                } else {
                    let k = ws / s5abs;
                    let (s6, c6) = (-s_4 * m[(2, 1)] * k, s_4 * m[(2, 0)] * k);
                    th6_first = if iw == 0 {
                        s6.atan2(c6)
                    } else {
                        th6_first + PI
                    };
                    (th6_first, s6, c6)
                };
                // Rz(θ4) = M ⁴R₆ᵀ Rx(α4)ᵀ: its first column is M (row 0 of ⁴R₆)ᵀ.
                let r46 = rot(s5, c5, r5.alpha) * rot(s6, c6, r6.alpha);
                let (e0, e1, e2) = (r46[(0, 0)], r46[(0, 1)], r46[(0, 2)]);
                let k0 = m[(0, 0)] * e0 + m[(0, 1)] * e1 + m[(0, 2)] * e2;
                let k1 = m[(1, 0)] * e0 + m[(1, 1)] * e1 + m[(1, 2)] * e2;
                let th4 = k1.atan2(k0);
                sink.push(
                    [th1, th2, v3, th4, th5, th6],
                    Branch {
                        shoulder: ia == 1,
                        elbow: ie == 1,
                        wrist: iw == 1,
                    },
                    Singularity {
                        shoulder: shoulder.singular,
                        elbow: elbow_singular,
                        wrist: s5abs < SINGULAR_TOL,
                    },
                );
            }
        }
    }
    if !arm_ok {
        return Err(Unreachable(
            "the wrist centre is out of the arm's reach (no elbow angle closes the triangle)",
        ));
    }
    Ok(sink.candidates)
}
