//! UR3/5/10 (and e-series) closed form: all 8 solutions.
//!
//! Standard DH with `α = (σ1 π/2, 0, 0, σ4 π/2, σ5 π/2, 0)`, `a1 = a4 = a5 = a6 = 0`,
//! `d2 = d3 = 0` (the UR tables have σ = (+, +, −)). With `T = ⁰T₆` the flange target
//! and `θi` the DH angles:
//!
//! 1. `p5 = p − d6 z6` (origin of frame 5). Axes 2, 3, 4 are parallel to
//!    `z1 = σ1 (sin θ1, −cos θ1, 0)`, and everything after joint 1 except the offset `d4`
//!    moves in planes normal to it, so `p5 · z1 = d4`:
//!    `θ1 = φ + atan2(σ1 d4, ±√(R² − d4²))`, `R, φ` the polar coordinates of `p5`.
//! 2. `z1` in flange coordinates, `v = Rᵀ z1 = σ4 (s5 c6, −s5 s6, −σ5 c5)`:
//!    `θ5 = atan2(±|(v_x, v_y)|, −σ4 σ5 v_z)`, `θ6 = atan2(−σ4 v_y / s5, σ4 v_x / s5)`.
//! 3. `¹T₄ = A1⁻¹ T (A5 A6)⁻¹ = Rz(θ2 + θ3 + θ4) Rx(α4)` translated by
//!    `(a2 c2 + a3 c23, a2 s2 + a3 s23, d4)`: the planar 2R elbow for `θ2, θ3`
//!    (`cos θ3 = (x² + y² − a2² − a3²) / (2 a2 a3)`, both signs of the sine), and
//!    `θ4 = atan2(r10, r00) − θ2 − θ3`.
//!
//! (The same steps as K. P. Hawkins, "Analytic inverse kinematics for the Universal
//! Robots UR-5/UR-10 arms", 2013, with every sign kept symbolic.) Step 3 recomputes the
//! wrist rotation from the chosen `θ5, θ6`, so near the wrist singularity, where `θ6` is
//! ill-conditioned, `θ4` absorbs its error and the pose stays exact.

use crate::core::spatial::{rot_z, Se3, Vec3};
use crate::kinematics::ik::analytic::branches::{
    fixed, is_quarter, shoulder_roots, twist_sign, Branch, RawSolution, Singularity, Sink,
    FREE_TOL, REACH_TOL, SINGULAR_TOL,
};
use crate::kinematics::ik::analytic::dh_family::{dh_transform_sc, exact_sin_cos};
use crate::kinematics::ik::analytic::dh_family::{DhChain, DhRow};
use crate::kinematics::ik::analytic::ik_error::{IkError, Unreachable};
use crate::model::Model;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Parameters of a UR-type arm: its DH rows (offsets included), the world → DH frame 0
/// `base`, the DH frame 6 → target link `tool`, and the joint limits.
#[derive(Clone, Debug, PartialEq)]
pub struct UrParams {
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
    plain: bool,
}

impl UrParams {
    /// A UR arm from its DH lengths (UR's own table convention: `α = (π/2, 0, 0, π/2,
    /// −π/2, 0)`, no angle offsets), base and tool identity, limits ±2π.
    pub fn new(d1: f64, a2: f64, a3: f64, d4: f64, d5: f64, d6: f64) -> Self {
        let row = |d: f64, a: f64, alpha: f64| DhRow {
            theta: 0.0,
            d,
            a,
            alpha,
            revolute: true,
        };
        Self::from_parts(
            [
                row(d1, 0.0, FRAC_PI_2),
                row(0.0, a2, 0.0),
                row(0.0, a3, 0.0),
                row(d4, 0.0, FRAC_PI_2),
                row(d5, 0.0, -FRAC_PI_2),
                row(d6, 0.0, 0.0),
            ],
            Se3::identity(),
            Se3::identity(),
            [-TAU; 6],
            [TAU; 6],
        )
    }

    /// The UR5 of `robots/ur5_dh.toml` (CB-series nominal table): `d1 = 0.089159`,
    /// `a2 = −0.425`, `a3 = −0.39225`, `d4 = 0.10915`, `d5 = 0.09465`, `d6 = 0.0823`,
    /// base `Rz(π)` (world = `base_link`), tool identity (= URDF `tool0`), limits ±2π.
    pub fn ur5() -> Self {
        Self::new(0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823)
            .with_base(Se3::from_rotation(rot_z(PI)))
    }

    /// The same arm with another world → DH frame 0 transform.
    pub fn with_base(self, base: Se3) -> Self {
        Self::from_parts(self.rows, base, self.tool, self.lower, self.upper)
    }

    /// The same arm with another DH frame 6 → target transform.
    pub fn with_tool(self, tool: Se3) -> Self {
        Self::from_parts(self.rows, self.base, tool, self.lower, self.upper)
    }

    /// The same arm with other joint limits.
    pub fn with_limits(self, lower: [f64; 6], upper: [f64; 6]) -> Self {
        Self::from_parts(self.rows, self.base, self.tool, lower, upper)
    }

    fn from_parts(
        rows: [DhRow; 6],
        base: Se3,
        tool: Se3,
        lower: [f64; 6],
        upper: [f64; 6],
    ) -> Self {
        Self {
            rows,
            base,
            tool,
            lower,
            upper,
            base_inv: base.inverse(),
            tool_inv: tool.inverse(),
            plain: base == Se3::identity() && tool == Se3::identity(),
        }
    }

    /// Checks the UR structure of a DH table.
    pub fn from_chain(chain: &DhChain) -> Result<Self, IkError> {
        let (rows, lower, upper) = fixed::<6>(chain)?;
        let bad = |m: &str| Err(IkError::Unsupported(format!("not a UR-type arm: {m}")));
        if !rows.iter().all(|r| r.revolute) {
            return bad("a joint is prismatic");
        }
        let [r1, r2, r3, r4, r5, r6] = &rows;
        if r1.a != 0.0 || !is_quarter(r1.alpha) {
            return bad("axes 1 and 2 are not perpendicular and intersecting");
        }
        if r2.alpha != 0.0 || r3.alpha != 0.0 || r2.d != 0.0 || r3.d != 0.0 {
            return bad("axes 2, 3 and 4 are not parallel (same direction)");
        }
        if r2.a == 0.0 || r3.a == 0.0 {
            return bad("zero upper-arm or forearm length");
        }
        if r4.a != 0.0 || !is_quarter(r4.alpha) || r5.a != 0.0 || !is_quarter(r5.alpha) {
            return bad("axes 4, 5 and 6 are not pairwise perpendicular and intersecting");
        }
        if r6.a != 0.0 || r6.alpha != 0.0 {
            return bad("the flange frame is not on axis 6");
        }
        Ok(Self::from_parts(rows, chain.base, chain.tool, lower, upper))
    }

    /// Reads the parameters from the chain from the root to `link` of a model.
    pub fn from_model(model: &Model, link: usize) -> Result<Self, IkError> {
        Self::from_chain(&DhChain::from_model(model, link, true)?)
    }

    /// World placement of the target link at `q` (the table's own forward kinematics).
    pub fn fk(&self, q: &[f64; 6]) -> Se3 {
        crate::kinematics::ik::analytic::dh_family::table_fk(&self.base, &self.rows, &self.tool, q)
    }
}

/// All solutions inside the limits for the world placement `target` of the target link,
/// appended to `out` (cleared first); free joints at singularities are 0, and angles are
/// wrapped towards 0. Returns the number of solutions found before the limits were
/// applied. Does not allocate when `out` has room for 8.
pub fn ur_ik(
    params: &UrParams,
    target: &Se3,
    out: &mut Vec<RawSolution<6>>,
) -> Result<usize, Unreachable> {
    ur_ik_with(params, target, None, true, out)
}

/// [`ur_ik`] with a seed (free joints at singularities take its values, wrapping stays
/// closest to it) and the limits optional.
// One closed-form derivation read top to bottom (shoulder, wrist, elbow roots) on the IK
// hot path: the branches share a dozen intermediate sines, cosines and transforms, which
// helper functions would have to pass back and forth.
#[allow(clippy::too_many_lines)]
pub fn ur_ik_with(
    params: &UrParams,
    target: &Se3,
    seed: Option<&[f64; 6]>,
    respect_limits: bool,
    out: &mut Vec<RawSolution<6>>,
) -> Result<usize, Unreachable> {
    out.clear();
    let t = if params.plain {
        *target
    } else {
        params.base_inv.mul(target).mul(&params.tool_inv)
    };
    let [r1, r2, r3, r4, r5, r6] = &params.rows;
    let mut sink = Sink::new(
        &params.rows,
        &params.lower,
        &params.upper,
        seed,
        respect_limits,
        out,
    );
    let s_1 = twist_sign(r1.alpha);
    let s_4 = twist_sign(r4.alpha);
    let s_5 = twist_sign(r5.alpha);
    let (sa1, ca1) = exact_sin_cos(r1.alpha);
    let (sa5, ca5) = exact_sin_cos(r5.alpha);
    let (a2, a3, d4) = (r2.a, r3.a, r4.d);
    let rt = t.rot.transpose();
    let z6 = Vec3::new(t.rot[(0, 2)], t.rot[(1, 2)], t.rot[(2, 2)]);
    let p5 = t.trans - z6 * r6.d;
    let shoulder = shoulder_roots(p5.x, p5.y, s_1 * d4, sink.free(0))?;
    let mut elbow_ok = false;
    for ia in 0..shoulder.n {
        let th1 = shoulder.theta[ia];
        let (s1, c1) = (shoulder.sin[ia], shoulder.cos[ia]);
        let v = rt * Vec3::new(s_1 * s1, -s_1 * c1, 0.0);
        let c5 = (-s_4 * s_5 * v.z).clamp(-1.0, 1.0);
        let s5abs = v.x.hypot(v.y);
        let wrist_free = s5abs < FREE_TOL;
        // ¹T₆ = A1⁻¹ T.
        let t16 = dh_transform_sc(s1, c1, r1.d, 0.0, sa1, ca1).inv_mul(&t);
        // The second wrist root is (−θ5, θ6 + π).
        let th5abs = s5abs.atan2(c5);
        let mut th6_first = 0.0;
        for iw in 0..(if wrist_free { 1 } else { 2 }) {
            let ws = if iw == 0 { 1.0 } else { -1.0 };
            let s5 = ws * s5abs;
            let th5 = ws * th5abs;
            let a5 = dh_transform_sc(s5, c5, r5.d, 0.0, sa5, ca5);
            // ¹T₄ and the elbow cosine for θ6 (given by its sine and cosine).
            let elbow = |s6: f64, c6: f64| {
                let t46 = a5.mul(&dh_transform_sc(s6, c6, r6.d, 0.0, 0.0, 1.0));
                let t14 = t16.mul(&t46.inverse());
                let (x, y) = (t14.trans.x, t14.trans.y);
                (t14, (x * x + y * y - a2 * a2 - a3 * a3) / (2.0 * a2 * a3))
            };
            let (mut th6, (mut t14, mut c3));
            if wrist_free {
                th6 = sink.free(5);
                let (s6, c6) = th6.sin_cos();
                (t14, c3) = elbow(s6, c6);
                if c3.abs() > 1.0 + REACH_TOL {
                    // Axis 6 is parallel to axes 2-4: θ6 moves the wrist-1 point on a
                    // circle of radius d5; take the member the elbow can reach.
                    if let Some(alt) = singular_theta6(&t16, r6.d, r5.d, s_5, th6, a2, a3) {
                        th6 = alt;
                        let (s6, c6) = th6.sin_cos();
                        (t14, c3) = elbow(s6, c6);
                    }
                }
            } else {
                let k = ws / s5abs;
                let (s6, c6) = (-s_4 * v.y * k, s_4 * v.x * k);
                th6 = if iw == 0 {
                    s6.atan2(c6)
                } else {
                    th6_first + PI
                };
                th6_first = th6;
                (t14, c3) = elbow(s6, c6);
            }
            if c3.abs() > 1.0 + REACH_TOL {
                continue;
            }
            elbow_ok = true;
            let th234 = t14.rot[(1, 0)].atan2(t14.rot[(0, 0)]);
            let (x, y) = (t14.trans.x, t14.trans.y);
            let c3 = c3.clamp(-1.0, 1.0);
            let s3abs = ((1.0 - c3) * (1.0 + c3)).sqrt();
            let singularity = Singularity {
                shoulder: shoulder.singular,
                elbow: s3abs < SINGULAR_TOL,
                wrist: s5abs < SINGULAR_TOL,
            };
            let th3abs = s3abs.atan2(c3);
            for ie in 0..(if s3abs == 0.0 { 1 } else { 2 }) {
                let (s3, th3) = if ie == 0 {
                    (s3abs, th3abs)
                } else {
                    (-s3abs, -th3abs)
                };
                // θ2 = atan2(y, x) − atan2(a3 s3, a2 + a3 c3), as one atan2.
                let (k1, k2) = (a2 + a3 * c3, a3 * s3);
                let th2 = (y * k1 - x * k2).atan2(x * k1 + y * k2);
                let th4 = th234 - th2 - th3;
                sink.push(
                    [th1, th2, th3, th4, th5, th6],
                    Branch {
                        shoulder: ia == 1,
                        elbow: ie == 1,
                        wrist: iw == 1,
                    },
                    singularity,
                );
            }
        }
    }
    if !elbow_ok {
        return Err(Unreachable(
            "the wrist is out of the arm's reach (no elbow angle closes the triangle)",
        ));
    }
    Ok(sink.candidates)
}

/// At the UR wrist singularity (axis 6 ∥ axes 2-4, `sin θ5 = 0`) the wrist-1 point is
/// `O4 = p5 − d5 z4` with `z4 = σ5 (sin θ6 x6 + cos θ6 y6)` free on the circle normal to
/// `z1`. Returns the `θ6` closest to `th6_seed` that puts `O4` at the distance from axis 2
/// nearest its current one within the elbow's range `[|a2| − |a3|, |a2| + |a3|]`, or `None`
/// when no `θ6` does. `t16` is the flange in frame 1 (`z1` = its z axis).
fn singular_theta6(
    t16: &Se3,
    d6: f64,
    d5: f64,
    s_5: f64,
    th6_seed: f64,
    a2: f64,
    a3: f64,
) -> Option<f64> {
    let x6 = t16.rot.column(0).into_owned();
    let y6 = t16.rot.column(1).into_owned();
    let z6 = t16.rot.column(2).into_owned();
    let p5 = t16.trans - z6 * d6;
    let rho = p5.x.hypot(p5.y);
    let (lo, hi) = ((a2.abs() - a3.abs()).abs(), a2.abs() + a3.abs());
    let want = rho.clamp(lo, hi);
    if rho < FREE_TOL || d5 == 0.0 {
        return None;
    }
    let cg = (rho * rho + d5 * d5 - want * want) / (2.0 * rho * d5);
    if cg.abs() > 1.0 + REACH_TOL {
        return None;
    }
    let cg = cg.clamp(-1.0, 1.0);
    let sg = ((1.0 - cg) * (1.0 + cg)).sqrt();
    let (px, py) = (p5.x / rho, p5.y / rho);
    let (ss, cs) = th6_seed.sin_cos();
    let z4_seed = (x6 * ss + y6 * cs) * s_5;
    let mut best: Option<(f64, f64)> = None;
    for sgn in [1.0, -1.0] {
        // z4 = Rz(±γ) p̂ in the plane of frame 1.
        let s = sgn * sg;
        let u = Vec3::new(cg * px - s * py, s * px + cg * py, 0.0);
        let th6 = (s_5 * u.dot(&x6)).atan2(s_5 * u.dot(&y6));
        let score = u.dot(&z4_seed);
        if best.is_none_or(|(b, _)| score > b) {
            best = Some((score, th6));
        }
    }
    best.map(|(_, t)| t)
}
