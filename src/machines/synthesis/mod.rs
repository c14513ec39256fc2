//! Four-bar and slider-crank synthesis (docs/reference_data.md §M5; problem book ch. 7):
//! limit-position and time-ratio synthesis of the crank-rocker, the offset slider-crank
//! and the crank–slotted-lever quick return, and Freudenstein's three-point function
//! generation. The results are checked by running them through the linkage solver
//! ([`crate::machines::synthesis::verify`]).
//!
//! - **Time ratio** `K = (180° + θ)/(180° − θ)`, `θ` the crank angle between the two limit
//!   positions (crank and coupler collinear).
//! - **Crank-rocker from its limit positions** (rocker `DC` at `C'` and `C''`, crank pivot
//!   `A`): `|AC'| = b + a`, `|AC''| = b − a`. Given `K` instead of `A`, `A` lies on a
//!   circle through `C'`, `C''` on which the chord subtends `θ`; with the frame length
//!   `|AD|` it is one of up to four points (every branch is returned).
//! - **Offset slider-crank** (crank `r`, rod `l`, offset `e`, stroke `H`):
//!   `H² = (l + r)² + (l − r)² − 2 (l² − r²) cos θ`, `e = (l² − r²) sin θ / H`; given
//!   `λ = r/l` this is explicit in `l`; given `e`, with `u = l + r`, `v = l − r`:
//!   `u v = e H / sin θ`, `u² + v² = H² + 2 u v cos θ`.
//! - **Crank-rocker from one limit position**, the crank pivot and `K`: the other limit
//!   `C₂` is where the ray from `A` at `±θ` to `AC₁` meets the rocker's circle.
//! - **Crank and slotted lever** (frame `d`, crank `r`, lever `L`): the lever swings
//!   `ψ = θ`, `r = d sin(ψ/2)` (or `d = r / sin(ψ/2)` when the crank is given),
//!   `L = H / (2 sin(ψ/2))`; with the ratio of the greatest speeds `K_v = (d + r)/(d − r)`
//!   instead of `K`.
//! - **Two-position synthesis**: [`two_position`].
//! - **Freudenstein** (`A = (0, 0)`, `D = (d, 0)`, crank angle `φ` at `A`, rocker angle
//!   `ψ` at `D`): `K1 cos ψ − K2 cos φ + K3 = cos(φ − ψ)`, `K1 = d/a`, `K2 = d/c`,
//!   `K3 = (a² − b² + c² + d²)/(2 a c)`: three precision points give a linear 3 × 3 system;
//!   Chebyshev spacing `x_j = (x₀ + x₁)/2 − (x₁ − x₀)/2 cos((2j − 1)π/6)`.

pub mod two_position;
pub mod verify;
use crate::machines::linkage::{cross, Vec2};
use nalgebra::{Matrix3, Vector3};
use std::f64::consts::PI;

/// Why a synthesis has no solution.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct SynthesisError(pub String);

fn fail<T>(msg: impl Into<String>) -> Result<T, SynthesisError> {
    Err(SynthesisError(msg.into()))
}

/// `θ` (rad) of a time ratio `K ≥ 1`.
pub fn theta_of_time_ratio(k: f64) -> f64 {
    PI * (k - 1.0) / (k + 1.0)
}

/// The time ratio of a crank-angle difference `θ` (rad) between the limit positions.
pub fn time_ratio(theta: f64) -> f64 {
    (PI + theta) / (PI - theta)
}

/// A crank-rocker found from its limit positions. The frame of the synthesis has the
/// rocker pivot `D` at the origin.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct CrankRocker {
    /// Crank `AB`.
    pub crank: f64,
    /// Coupler `BC`.
    pub coupler: f64,
    /// Rocker `DC`.
    pub rocker: f64,
    /// Frame `AD`.
    pub frame: f64,
    /// Crank pivot `A` (the rocker pivot `D` is the origin).
    pub pivot: [f64; 2],
    /// Direction of `A → D` from the x axis (deg): the linkage solver's frame is turned
    /// by it.
    pub frame_angle_deg: f64,
    /// Rocker angles at the extended (`C'`) and folded (`C''`) limits (deg, at `D`).
    pub limit_angles_deg: [f64; 2],
    /// `|AC'| = b + a`.
    pub extended: f64,
    /// `|AC''| = b − a`.
    pub folded: f64,
    /// Crank angle between the limits (deg).
    pub theta_deg: f64,
    /// Time ratio.
    pub time_ratio: f64,
    /// Pressure angle at the rocker (90° − transmission angle, deg) at `C'` and `C''`.
    pub pressure_at_limits_deg: [f64; 2],
}

fn polar(len: f64, ang: f64) -> Vec2 {
    Vec2::new(len * ang.cos(), len * ang.sin())
}

/// Angle between two vectors in `[0, π]`.
fn angle_between(u: &Vec2, w: &Vec2) -> f64 {
    cross(u, w).abs().atan2(u.dot(w))
}

/// The crank-rocker with rocker `c` whose limit positions are at rocker angles
/// `limits` (rad, at `D` = origin) for the crank pivot `pivot`.
pub fn crank_rocker_from_pivot(
    c: f64,
    limits: [f64; 2],
    pivot: Vec2,
) -> Result<CrankRocker, SynthesisError> {
    let (c1, c2) = (polar(c, limits[0]), polar(c, limits[1]));
    let (r1, r2) = ((c1 - pivot).norm(), (c2 - pivot).norm());
    let d = pivot.norm();
    if d <= 1e-12 * c {
        return fail("the crank pivot coincides with the rocker pivot");
    }
    if (r1 - r2).abs() <= 1e-12 * c {
        return fail("the crank pivot is equidistant from both limit positions: no crank (a = 0)");
    }
    // The extended limit is the farther one.
    let (ext, fold, ce, cf, le, lf) = if r1 > r2 {
        (r1, r2, c1, c2, limits[0], limits[1])
    } else {
        (r2, r1, c2, c1, limits[1], limits[0])
    };
    let theta = angle_between(&(ce - pivot), &(cf - pivot));
    let pressure = |cp: Vec2| {
        let mu = angle_between(&(cp - pivot), &cp);
        (PI / 2.0 - mu).abs().to_degrees()
    };
    let to_d = -pivot;
    Ok(CrankRocker {
        crank: (ext - fold) / 2.0,
        coupler: (ext + fold) / 2.0,
        rocker: c,
        frame: d,
        pivot: [pivot.x, pivot.y],
        frame_angle_deg: to_d.y.atan2(to_d.x).to_degrees(),
        limit_angles_deg: [le.to_degrees(), lf.to_degrees()],
        extended: ext,
        folded: fold,
        theta_deg: theta.to_degrees(),
        time_ratio: time_ratio(theta),
        pressure_at_limits_deg: [pressure(ce), pressure(cf)],
    })
}

/// Every crank-rocker with rocker `c`, limit rocker angles `limits` (rad), time ratio
/// `k ≥ 1` and frame `d`: the crank pivots on the two circles where the chord `C'C''`
/// subtends `θ`, at distance `d` from `D`.
pub fn crank_rockers_from_time_ratio(
    c: f64,
    limits: [f64; 2],
    k: f64,
    d: f64,
) -> Result<Vec<CrankRocker>, SynthesisError> {
    let theta = theta_of_time_ratio(k);
    if !(theta > 1e-9 && theta < PI) {
        return fail(format!("time ratio {k} gives no quick return (need K > 1)"));
    }
    let (c1, c2) = (polar(c, limits[0]), polar(c, limits[1]));
    let chord = c2 - c1;
    let len = chord.norm();
    if len <= 1e-12 * c {
        return fail("the two limit positions coincide");
    }
    let mid = (c1 + c2) / 2.0;
    let n = Vec2::new(-chord.y, chord.x) / len;
    let radius = len / (2.0 * theta.sin());
    let off = len / (2.0 * theta.tan());
    let mut out: Vec<CrankRocker> = Vec::new();
    for side in [1.0, -1.0] {
        let centre = mid + n * (off * side);
        for p in circle_intersections(centre, radius, Vec2::zeros(), d) {
            // Only the arc on which the chord subtends θ (not π − θ).
            let seen = angle_between(&(c1 - p), &(c2 - p));
            if (seen - theta).abs() > 1e-7 {
                continue;
            }
            if let Ok(s) = crank_rocker_from_pivot(c, limits, p) {
                if !out
                    .iter()
                    .any(|o| (Vec2::new(o.pivot[0], o.pivot[1]) - p).norm() <= 1e-9 * c.max(d))
                {
                    out.push(s);
                }
            }
        }
    }
    if out.is_empty() {
        return fail(format!(
            "no crank pivot at distance {d} from the rocker pivot sees the limit positions under θ = {:.4}°",
            theta.to_degrees()
        ));
    }
    Ok(out)
}

/// Which limit position of the rocker is given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RockerLimit {
    /// `C'`, crank and coupler extended: `|AC'| = b + a`.
    Extended,
    /// `C''`, crank and coupler folded: `|AC''| = b − a`.
    Folded,
}

/// Every crank-rocker with rocker `c` that has a limit position at rocker angle `limit`
/// (rad, at `D` = origin), crank pivot `pivot` and time ratio `k > 1`. The other limit
/// `C₂` is on the rocker's circle and on a ray from `A` at `±θ` to `AC₁`, farther from
/// `A` when the given limit is the folded one, nearer when it is the extended one.
/// `which = None` tries both.
pub fn crank_rockers_from_one_limit(
    c: f64,
    limit: f64,
    which: Option<RockerLimit>,
    k: f64,
    pivot: Vec2,
) -> Result<Vec<CrankRocker>, SynthesisError> {
    let theta = theta_of_time_ratio(k);
    if !(theta > 1e-9 && theta < PI) {
        return fail(format!("time ratio {k} gives no quick return (need K > 1)"));
    }
    let c1 = polar(c, limit);
    let ac1 = c1 - pivot;
    let r1 = ac1.norm();
    if r1 <= 1e-12 * c {
        return fail("the given limit position of the rocker lies on the crank pivot");
    }
    let kinds = match which {
        Some(w) => vec![w],
        None => vec![RockerLimit::Extended, RockerLimit::Folded],
    };
    let mut out: Vec<CrankRocker> = Vec::new();
    for kind in kinds {
        for side in [1.0, -1.0] {
            let u = crate::machines::linkage::rotate(side * theta, &(ac1 / r1));
            // |A + t u| = c: t² + 2 t (A·u) + |A|² − c² = 0.
            let (p, q) = (pivot.dot(&u), pivot.norm_squared() - c * c);
            let disc = p * p - q;
            if disc < 0.0 {
                continue;
            }
            for t in [-p - disc.sqrt(), -p + disc.sqrt()] {
                let fits = match kind {
                    RockerLimit::Extended => t > 1e-9 * r1 && t < r1 * (1.0 - 1e-9),
                    RockerLimit::Folded => t > r1 * (1.0 + 1e-9),
                };
                if !fits {
                    continue;
                }
                let c2 = pivot + u * t;
                let other = c2.y.atan2(c2.x);
                if let Ok(s) = crank_rocker_from_pivot(c, [limit, other], pivot) {
                    if !out.iter().any(|o| {
                        (o.crank - s.crank).abs() <= 1e-9 * c
                            && (o.limit_angles_deg[0] - s.limit_angles_deg[0]).abs() <= 1e-9
                            && (o.limit_angles_deg[1] - s.limit_angles_deg[1]).abs() <= 1e-9
                    }) {
                        out.push(s);
                    }
                }
            }
        }
    }
    if out.is_empty() {
        return fail(format!(
            "no second limit position on the rocker's circle is seen from the crank pivot at θ = {:.4}° from the given one",
            theta.to_degrees()
        ));
    }
    Ok(out)
}

/// Intersections of two circles (none, one or two points).
pub fn circle_intersections(c1: Vec2, r1: f64, c2: Vec2, r2: f64) -> Vec<Vec2> {
    let d = c2 - c1;
    let dist = d.norm();
    if dist == 0.0 {
        return Vec::new();
    }
    let x = (r1 * r1 - r2 * r2 + dist * dist) / (2.0 * dist);
    let h2 = r1 * r1 - x * x;
    let scale = r1.max(r2).powi(2);
    if h2 < -1e-12 * scale {
        return Vec::new();
    }
    let u = d / dist;
    let base = c1 + u * x;
    if h2 <= 1e-12 * scale {
        return vec![base];
    }
    let h = h2.sqrt();
    let n = Vec2::new(-u.y, u.x);
    vec![base + n * h, base - n * h]
}

/// An offset slider-crank from stroke and time ratio.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SliderCrankDesign {
    /// Crank `r`.
    pub crank: f64,
    /// Rod `l`.
    pub rod: f64,
    /// Offset `e` of the slide line from the crank pivot.
    pub offset: f64,
    /// Stroke `H`.
    pub stroke: f64,
    /// Crank angle between the dead centres (deg).
    pub theta_deg: f64,
    /// Time ratio.
    pub time_ratio: f64,
    /// Largest pressure angle `asin((r + e)/l)` (deg).
    pub max_pressure_angle_deg: f64,
}

fn slider_design(r: f64, l: f64, e: f64, h: f64, theta: f64) -> SliderCrankDesign {
    SliderCrankDesign {
        crank: r,
        rod: l,
        offset: e,
        stroke: h,
        theta_deg: theta.to_degrees(),
        time_ratio: time_ratio(theta),
        max_pressure_angle_deg: ((r + e) / l).clamp(-1.0, 1.0).asin().to_degrees(),
    }
}

/// The slider-crank of stroke `h`, time ratio `k` and crank-to-rod ratio `lambda`.
pub fn slider_crank_from_ratio(
    h: f64,
    k: f64,
    lambda: f64,
) -> Result<SliderCrankDesign, SynthesisError> {
    let theta = theta_of_time_ratio(k);
    if !(0.0..PI).contains(&theta) {
        return fail(format!("time ratio {k} must be at least 1"));
    }
    if !(lambda > 0.0 && lambda < 1.0) {
        return fail(format!("crank-to-rod ratio {lambda} must lie in (0, 1)"));
    }
    let den = (1.0 + lambda).powi(2) + (1.0 - lambda).powi(2)
        - 2.0 * (1.0 - lambda * lambda) * theta.cos();
    let l = h / den.sqrt();
    let r = lambda * l;
    let e = (l * l - r * r) * theta.sin() / h;
    if r + e >= l {
        return fail(format!(
            "r + e = {:.6} reaches the rod length {l:.6}: the crank cannot turn",
            r + e
        ));
    }
    Ok(slider_design(r, l, e, h, theta))
}

/// The slider-crank of stroke `h`, time ratio `k` and offset `e`.
pub fn slider_crank_from_offset(
    h: f64,
    k: f64,
    e: f64,
) -> Result<SliderCrankDesign, SynthesisError> {
    let theta = theta_of_time_ratio(k);
    if !(theta > 0.0 && theta < PI) {
        return fail("with a given offset the time ratio must exceed 1");
    }
    let p = e * h / theta.sin();
    let s = h * h + 2.0 * p * theta.cos();
    if s - 2.0 * p < 0.0 {
        return fail("no real solution for this stroke, time ratio and offset");
    }
    let (sp, sm) = ((s + 2.0 * p).sqrt(), (s - 2.0 * p).sqrt());
    let (u, v) = ((sp + sm) / 2.0, (sp - sm) / 2.0);
    let (l, r) = ((u + v) / 2.0, (u - v) / 2.0);
    if r <= 0.0 || r + e >= l {
        return fail("the solution has no turning crank (r ≤ 0 or r + e ≥ l)");
    }
    Ok(slider_design(r, l, e, h, theta))
}

/// A crank and slotted-lever quick return.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ShaperDesign {
    /// Frame: crank pivot to lever pivot.
    pub frame: f64,
    /// Crank.
    pub crank: f64,
    /// Lever (pivot to the rod pin).
    pub lever: f64,
    /// Lever swing (deg) = crank angle between the limits.
    pub swing_deg: f64,
    /// Stroke.
    pub stroke: f64,
    /// Time ratio.
    pub time_ratio: f64,
    /// Ratio of the greatest speeds `(d + r)/(d − r)`.
    pub velocity_ratio: f64,
    /// Sagitta of the lever tip's arc `L (1 − cos(ψ/2))`.
    pub sagitta: f64,
    /// With a rod: its largest angle to the ram line at mid-sagitta (deg).
    pub max_rod_angle_deg: Option<f64>,
}

/// What fixes the size of a shaper beside its stroke.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShaperSize {
    /// The frame `d` (crank pivot to lever pivot): `r = d sin(ψ/2)`.
    Frame(f64),
    /// The crank `r`: `d = r / sin(ψ/2)`.
    Crank(f64),
}

/// The shaper of stroke `h` and the frame or crank `size` with time ratio `k` (or, when
/// `by_velocity`, ratio of the greatest speeds `k`); `rod` the link to the ram, if any.
pub fn shaper(
    h: f64,
    size: ShaperSize,
    k: f64,
    by_velocity: bool,
    rod: Option<f64>,
) -> Result<ShaperDesign, SynthesisError> {
    if k <= 1.0 {
        return fail(format!("ratio {k} must exceed 1"));
    }
    let half = if by_velocity {
        ((k - 1.0) / (k + 1.0)).asin()
    } else {
        theta_of_time_ratio(k) / 2.0
    };
    let (d, r) = match size {
        ShaperSize::Frame(d) => (d, d * half.sin()),
        ShaperSize::Crank(r) => (r / half.sin(), r),
    };
    let lever = h / (2.0 * half.sin());
    let sagitta = lever * (1.0 - half.cos());
    let rod_angle = match rod {
        Some(len) if sagitta / 2.0 >= len => {
            return fail(format!(
                "rod {len} is shorter than half the sagitta {:.6}",
                sagitta / 2.0
            ))
        }
        Some(len) => Some((sagitta / 2.0 / len).asin().to_degrees()),
        None => None,
    };
    Ok(ShaperDesign {
        frame: d,
        crank: r,
        lever,
        swing_deg: (2.0 * half).to_degrees(),
        stroke: h,
        time_ratio: time_ratio(2.0 * half),
        velocity_ratio: (d + r) / (d - r),
        sagitta,
        max_rod_angle_deg: rod_angle,
    })
}

/// Freudenstein's coefficients through three `(φ, ψ)` precision points (rad).
pub fn freudenstein_coefficients(points: &[(f64, f64); 3]) -> Result<[f64; 3], SynthesisError> {
    let mut m = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for (i, &(phi, psi)) in points.iter().enumerate() {
        m[(i, 0)] = psi.cos();
        m[(i, 1)] = -phi.cos();
        m[(i, 2)] = 1.0;
        rhs[i] = (phi - psi).cos();
    }
    let lu = m.lu();
    match lu.solve(&rhs) {
        Some(k) if k.iter().all(|x| x.is_finite()) && lu.determinant().abs() > 1e-12 => {
            Ok([k[0], k[1], k[2]])
        }
        _ => fail("the precision points give a singular Freudenstein system (repeated or dependent points)"),
    }
}

/// The four-bar `(a, b, c)` of frame `d` from Freudenstein's coefficients.
pub fn four_bar_from_coefficients(k: [f64; 3], d: f64) -> Result<[f64; 3], SynthesisError> {
    if k[0] == 0.0 || k[1] == 0.0 {
        return fail("K1 or K2 is zero: no finite crank or rocker");
    }
    let (a, c) = (d / k[0], d / k[1]);
    let b2 = a * a + c * c + d * d - 2.0 * a * c * k[2];
    if b2 <= 0.0 {
        return fail(format!("the coupler length squared is {b2:.3e} ≤ 0"));
    }
    // Negative a or c mean the link points the other way: lengths are magnitudes, the
    // angles shift by π (the caller's check runs the mechanism and reports the error).
    Ok([a.abs(), b2.sqrt(), c.abs()])
}

/// Chebyshev spacing of `n` precision points over `[x0, x1]`.
pub fn chebyshev_points(x0: f64, x1: f64, n: usize) -> Vec<f64> {
    (1..=n)
        .map(|j| {
            (x0 + x1) / 2.0 - (x1 - x0) / 2.0 * ((2 * j - 1) as f64 * PI / (2 * n) as f64).cos()
        })
        .collect()
}

/// A function to generate, `y = f(x)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Function {
    /// `log10 x`.
    Log10,
    /// `ln x`.
    Ln,
    /// `e^x`.
    Exp,
    /// `sin x` (x in rad).
    Sin,
    /// `cos x` (x in rad).
    Cos,
    /// `tan x` (x in rad).
    Tan,
    /// `x^p`.
    Power(f64),
}

impl Function {
    /// The names accepted in scenario files.
    pub const NAMES: &'static str = "log10, ln, exp, sin, cos, tan, power";

    /// By name (`power` takes the exponent).
    pub fn from_name(name: &str, exponent: Option<f64>) -> Option<Self> {
        Some(match name {
            "log10" => Self::Log10,
            "ln" => Self::Ln,
            "exp" => Self::Exp,
            "sin" => Self::Sin,
            "cos" => Self::Cos,
            "tan" => Self::Tan,
            "power" => Self::Power(exponent?),
            _ => return None,
        })
    }

    /// `f(x)`.
    pub fn eval(&self, x: f64) -> f64 {
        match self {
            Self::Log10 => x.log10(),
            Self::Ln => x.ln(),
            Self::Exp => x.exp(),
            Self::Sin => x.sin(),
            Self::Cos => x.cos(),
            Self::Tan => x.tan(),
            Self::Power(p) => x.powf(*p),
        }
    }
}

/// A linear map of `x ∈ [x0, x1]` to the crank angle and `y = f(x)` to the rocker
/// angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FunctionMap {
    /// The function.
    pub f: Function,
    /// `x` range.
    pub x: [f64; 2],
    /// Crank angles at `x0`, `x1` (rad).
    pub phi: [f64; 2],
    /// Rocker angles at `f(x0)`, `f(x1)` (rad).
    pub psi: [f64; 2],
}

impl FunctionMap {
    /// `x` at crank angle `phi`.
    pub fn x_of(&self, phi: f64) -> f64 {
        self.x[0] + (phi - self.phi[0]) / (self.phi[1] - self.phi[0]) * (self.x[1] - self.x[0])
    }

    /// Crank angle of `x`.
    pub fn phi_of(&self, x: f64) -> f64 {
        self.phi[0] + (x - self.x[0]) / (self.x[1] - self.x[0]) * (self.phi[1] - self.phi[0])
    }

    /// The rocker angle that represents `f(x)` exactly.
    pub fn psi_of(&self, x: f64) -> f64 {
        let (y0, y1) = (self.f.eval(self.x[0]), self.f.eval(self.x[1]));
        self.psi[0] + (self.f.eval(x) - y0) / (y1 - y0) * (self.psi[1] - self.psi[0])
    }

    /// `y` represented by rocker angle `psi`.
    pub fn y_of(&self, psi: f64) -> f64 {
        let (y0, y1) = (self.f.eval(self.x[0]), self.f.eval(self.x[1]));
        y0 + (psi - self.psi[0]) / (self.psi[1] - self.psi[0]) * (y1 - y0)
    }
}
