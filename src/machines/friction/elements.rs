//! Friction elements (docs/reference_data.md §M4): closed forms for inclines, slides, screws,
//! wedges, journals, pivots and collars, rolling resistance, band brakes (simple,
//! differential, summing) and belts, with
//! efficiency, reverse efficiency and self-locking. SI units (N, m, rad) unless a name
//! says otherwise.

/// Friction angle `φ = atan f`.
pub fn friction_angle(f: f64) -> f64 {
    f.atan()
}

/// Screw raising a load `q` (square thread: `half_angle = 0`; V/trapezoid:
/// `f' = f/cos(half_angle)`), pitch `p`, mean diameter `dm`, collar torque `collar`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Screw {
    /// Lead angle `λ = atan(p/(π dm))`.
    pub lead_angle: f64,
    /// Thread friction angle `φ' = atan(f')`.
    pub friction_angle: f64,
    /// Thread torque `Q dm/2 tan(λ + φ')`.
    pub thread_torque: f64,
    /// Total torque (thread + collar).
    pub torque: f64,
    /// `η = Q p/(2π M)`.
    pub efficiency: f64,
    /// Lowering efficiency of the thread `tan(λ − φ')/tan λ` (≤ 0: self-locking).
    pub reverse_efficiency: f64,
    /// `λ ≤ φ'`.
    pub self_locking: bool,
}

/// See [`Screw`].
pub fn screw(q: f64, p: f64, dm: f64, f: f64, half_angle: f64, collar: f64) -> Screw {
    let lam = (p / (std::f64::consts::PI * dm)).atan();
    let phi = (f / half_angle.cos()).atan();
    let mt = q * dm / 2.0 * (lam + phi).tan();
    let m = mt + collar;
    Screw {
        lead_angle: lam,
        friction_angle: phi,
        thread_torque: mt,
        torque: m,
        efficiency: q * p / (2.0 * std::f64::consts::PI * m),
        reverse_efficiency: (lam - phi).tan() / lam.tan(),
        self_locking: lam <= phi,
    }
}

/// The load a screw raises with torque `m` (no collar): `Q = M/((dm/2) tan(λ + φ'))`.
pub fn screw_load(m: f64, p: f64, dm: f64, f: f64, half_angle: f64) -> f64 {
    let lam = (p / (std::f64::consts::PI * dm)).atan();
    let phi = (f / half_angle.cos()).atan();
    m / (dm / 2.0 * (lam + phi).tan())
}

/// Collar (flat annulus, radii `r1 > r2`) torque: uniform wear `f Q (R1 + R2)/2`, new
/// (uniform pressure) `(2/3) f Q (R1³ − R2³)/(R1² − R2²)`; a solid pivot is `r2 = 0`.
pub fn collar_torque(f: f64, q: f64, r1: f64, r2: f64, worn: bool) -> f64 {
    if worn {
        f * q * (r1 + r2) / 2.0
    } else {
        2.0 / 3.0 * f * q * (r1.powi(3) - r2.powi(3)) / (r1 * r1 - r2 * r2)
    }
}

/// Inclined plane of angle `a`, the load `Q` moved by a force `P` at angle `β` to the
/// upward vertical, leaning uphill (`β = 90°` a horizontal push, `β = 90° − a` along the
/// plane, `β = 0` a straight lift). Equilibrium of the load with the plane's reaction
/// turned by the friction angle `φ` from the normal:
/// up `P = Q sin(a + φ)/sin(a + β + φ)`, down (holding the load back as it slides)
/// `P = Q sin(a − φ)/sin(a + β − φ)` (negative: it must be pushed down);
/// efficiency `P₀/P` with the frictionless `P₀ = Q sin a/sin(a + β)`, reverse
/// `P_down/P₀`; self-locking when `a ≤ φ` (whatever the direction of `P`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incline {
    /// Force to push up.
    pub up: f64,
    /// Force to hold/push down (negative: must pull back).
    pub down: f64,
    /// Efficiency raising.
    pub efficiency: f64,
    /// Reverse efficiency (`None` on a level plane, where the load does not drive).
    pub reverse_efficiency: Option<f64>,
    /// `a ≤ φ`.
    pub self_locking: bool,
}

/// Why a push at angle `β` cannot move the load (see [`incline`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InclineJam {
    /// `a + β + φ ≥ 180°`: the push presses the load into the plane faster than it drives
    /// it up (the force needed is unbounded).
    Up,
    /// `sin(a + β − φ) = 0`: no finite force of that direction holds the load back.
    Down,
}

/// A push at angle `beta` (to the upward vertical, see [`Incline`]) on an incline of
/// angle `a` with friction coefficient `f` (a slide's equivalent one for a groove).
pub fn incline(q: f64, a: f64, f: f64, beta: f64) -> Result<Incline, InclineJam> {
    let phi = friction_angle(f);
    let up_den = (a + beta + phi).sin();
    if up_den <= 1e-12 {
        return Err(InclineJam::Up);
    }
    let down_den = (a + beta - phi).sin();
    if down_den.abs() <= 1e-12 {
        return Err(InclineJam::Down);
    }
    let up = q * (a + phi).sin() / up_den;
    let down = q * (a - phi).sin() / down_den;
    // Over the frictionless force `Q sin a/sin(a + β)` (per unit load, so that it holds
    // for Q = 0; `a + β < 180°` follows from the test on `up_den`).
    let ideal = (a > 0.0).then(|| a.sin() / (a + beta).sin());
    Ok(Incline {
        up,
        down,
        efficiency: ideal.map_or(0.0, |p0| p0 * up_den / (a + phi).sin()),
        reverse_efficiency: ideal.map(|p0| (a - phi).sin() / down_den / p0),
        self_locking: a <= phi,
    })
}

/// Wedge (angle `a`, friction angles `φ1`, `φ2` on its faces): drive-in
/// `Q[tan φ1 + tan(a + φ2)]`, pull-out `Q[tan φ1 + tan(φ2 − a)]`, self-locking if
/// `a ≤ φ1 + φ2`.
pub fn wedge(q: f64, a: f64, f1: f64, f2: f64) -> (f64, f64, bool) {
    let (p1, p2) = (friction_angle(f1), friction_angle(f2));
    (
        q * (p1.tan() + (a + p2).tan()),
        q * (p1.tan() + (p2 - a).tan()),
        a <= p1 + p2,
    )
}

/// Equivalent friction coefficient of a slide: flat `f`, V-groove `f/cos β`, worn
/// cylinder `π f/2`, new cylinder `4 f/π`.
pub fn slide_coefficient(f: f64, kind: &str, beta: f64) -> Option<f64> {
    Some(match kind {
        "flat" => f,
        "v_groove" => f / beta.cos(),
        "worn_cylinder" => std::f64::consts::PI * f / 2.0,
        "new_cylinder" => 4.0 * f / std::f64::consts::PI,
        _ => return None,
    })
}

/// Rolling: a load `Q` on wheels of diameter `d1` on axles `d2` (journal friction `f`,
/// rolling resistance arm `k`): `P = Q (f d2 + 2k)/d1`; on free rollers between two
/// surfaces (`k1`, `k2`): `P = (k1 + k2) Q/d`. The wheels' own weight: see
/// [`rolling_with_wheels`].
pub fn rolling_on_axles(q: f64, d1: f64, d2: f64, f: f64, k: f64) -> f64 {
    rolling_with_wheels(q, 0.0, d1, d2, f, k).force
}

/// The pull of a cart on wheels split into its two resistances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WheelPull {
    /// Rolling resistance at the rail `(Q + G_w) k/R` (N).
    pub rolling: f64,
    /// Journal friction brought to the rim `Q f r/R` (N).
    pub journal: f64,
    /// `P = [(Q + G_w) k + Q f r]/R` (N).
    pub force: f64,
}

/// A load `Q` carried through the axles' journals on wheels (radius `R = d1/2`, axle
/// `r = d2/2`) whose own weight (with what turns with them) is `G_w`: the rail carries
/// `Q + G_w`, the journals only `Q`, so `P = [(Q + G_w) k + Q f r]/R`.
pub fn rolling_with_wheels(q: f64, gw: f64, d1: f64, d2: f64, f: f64, k: f64) -> WheelPull {
    let rolling = (q + gw) * 2.0 * k / d1;
    let journal = q * f * d2 / d1;
    WheelPull {
        rolling,
        journal,
        force: rolling + journal,
    }
}

/// Free rollers of diameter `d` between surfaces with arms `k1`, `k2`.
pub fn free_rollers(q: f64, d: f64, k1: f64, k2: f64) -> f64 {
    (k1 + k2) * q / d
}

/// What fixes a band brake's tensions: the moment `G l` of the lever load about the
/// lever pivot, or the braking force `F = S1 − S2` at the drum rim.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BrakeGiven {
    /// `G l` (N m).
    LeverMoment(f64),
    /// `F` (N).
    BrakingForce(f64),
}

/// A band brake: the band wraps the drum with `e = e^{fβ}` (Euler: tight side
/// `S1 = S2 e`); its slack end sits on the lever at arm `b` (`slack_arm`) from the pivot,
/// its tight end at arm `a` (`tight_arm`) on the other side (a differential brake; `a = 0`
/// is the simple brake, the tight end at the pivot; `a < 0` puts it on the slack end's
/// side, a summing brake). Lever equilibrium about the pivot: `G l = S2 b − S1 a`, so
/// `S2 = G l/(b − a e)`, braking force `F = S2 (e − 1)`. Self-locking (no lever load
/// needed) when `b − a e ≤ 0`, i.e. `e ≥ b/a`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandBrake {
    /// Slack-side tension `S2`.
    pub s2: f64,
    /// Tight-side tension `S1 = S2 e`.
    pub s1: f64,
    /// Braking force at the rim `F = S1 − S2`.
    pub force: f64,
    /// Lever moment `G l = S2 b − S1 a` (≤ 0 when self-locking).
    pub lever_moment: f64,
    /// `b − a e ≤ 0`: the band pulls the lever on by itself.
    pub self_locking: bool,
    /// `b − a e` (N m per N of slack tension): how far from locking.
    pub locking_margin: f64,
    /// `d ln F/d ln f` at a fixed lever moment: `fβ [e/(e − 1) + a e/(b − a e)]` (1 %
    /// more friction gives about this many % more braking force; large near locking).
    pub friction_sensitivity: f64,
}

/// See [`BandBrake`]. `None` when the lever moment is given but the brake self-locks
/// (the lever moment then does not fix the tensions).
pub fn band_brake(e: f64, tight_arm: f64, slack_arm: f64, given: BrakeGiven) -> Option<BandBrake> {
    let margin = slack_arm - tight_arm * e;
    let locking = margin <= 0.0;
    let s2 = match given {
        BrakeGiven::LeverMoment(_) if locking => return None,
        BrakeGiven::LeverMoment(m) => m / margin,
        BrakeGiven::BrakingForce(f) => f / (e - 1.0),
    };
    Some(BandBrake {
        s2,
        s1: s2 * e,
        force: s2 * (e - 1.0),
        lever_moment: s2 * margin,
        self_locking: locking,
        locking_margin: margin,
        friction_sensitivity: e.ln() * (e / (e - 1.0) + tight_arm * e / margin),
    })
}

/// A shoe (block) brake: a lever pivoted at `O` presses a shoe on a drum of radius `R`.
/// The lever load's moment about `O` is `G l`; the shoe's normal force `N` acts at arm `b`
/// from `O`, its friction force `f' N` along the drum's tangent at arm `e` from `O`,
/// signed: `e > 0` when the drum's friction on the shoe turns the lever the way the lever
/// load does (the brake applies itself: self-energising), `e < 0` when it opposes it.
/// Lever equilibrium `N b = G l + f' N e`, so `N = G l/(b − f' e)`, braking force
/// `F = f' N`, torque `F R`; self-locking when `b − f' e ≤ 0`. A long shoe of contact
/// angle `θ` (pressure ∝ cos of the angle from the shoe's middle) acts with
/// `f' = 4 f sin(θ/2)/(θ + sin θ)`, which tends to `f` as `θ → 0`.
pub fn shoe_coefficient(f: f64, contact: f64) -> f64 {
    if contact <= 0.0 {
        f
    } else {
        4.0 * f * (contact / 2.0).sin() / (contact + contact.sin())
    }
}

/// The normal force of a shoe brake (see [`shoe_coefficient`]) for a lever moment `g_l`,
/// shoe arm `b`, friction arm `e` and coefficient `f`; `None` when the brake self-locks
/// (`b − f e ≤ 0`: no lever load fixes the force).
pub fn shoe_normal_force(g_l: f64, b: f64, e: f64, f: f64) -> Option<f64> {
    let margin = b - f * e;
    (margin > 0.0).then(|| g_l / margin)
}

/// Belt transmitting power `w` at speed `v` with `e = e^{fα}`: useful pull `P = W/v`,
/// `S1 = P e/(e − 1)`, `S2 = P/(e − 1)`, initial tension `(S1 + S2)/2`, shaft load
/// `S1 + S2` (parallel strands).
pub fn belt(w: f64, v: f64, e: f64) -> [f64; 5] {
    let p = w / v;
    let s1 = p * e / (e - 1.0);
    let s2 = p / (e - 1.0);
    [p, s1, s2, (s1 + s2) / 2.0, s1 + s2]
}

/// Series `Π η_i` and parallel `Σ N_i η_i / Σ N_i` efficiency.
pub fn series(etas: &[f64]) -> f64 {
    etas.iter().product()
}

/// See [`series`].
pub fn parallel(powers: &[f64], etas: &[f64]) -> f64 {
    let n: f64 = powers.iter().sum();
    powers.iter().zip(etas).map(|(p, e)| p * e).sum::<f64>() / n
}
