//! Follower motions given as a table or a diagram over the turn (problem book ch. 11: "the
//! law of motion is given by the diagram …"), as piecewise cubics in the cam angle:
//!
//! - **displacement table** `(φᵢ, sᵢ)`: the periodic cubic spline through the points
//!   (`s`, `s'`, `s''` continuous; the second derivatives `Mᵢ` solve the cyclic system
//!   `hᵢ₋₁ Mᵢ₋₁ + 2 (hᵢ₋₁ + hᵢ) Mᵢ + hᵢ Mᵢ₊₁ = 6 (Δᵢ − Δᵢ₋₁)`, `Δᵢ = (sᵢ₊₁ − sᵢ)/hᵢ`);
//! - **velocity diagram** `(φᵢ, s'ᵢ)`, linear between the points: `s` is its integral,
//!   which must close over the turn (`∮ s' dφ = 0`);
//! - **acceleration diagram** `(φᵢ, s''ᵢ)`, linear between the points (a repeated `φ`
//!   is a jump): integrated twice, with `∮ s'' dφ = 0` and the starting speed
//!   `s'(0) = −(1/2π) ∮∫ s''` that closes the displacement.
//!
//! The lowest position is `s = 0`. A diagram may be given in relative units and scaled
//! to a lift ([`MotionTable::scaled_to`]).

use crate::machines::cams::laws::Displacement;
use std::f64::consts::PI;

/// What the table's values are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableKind {
    /// `s` (spline through the points).
    Displacement,
    /// `s' = ds/dφ`, linear between the points.
    Velocity,
    /// `s'' = d²s/dφ²`, linear between the points.
    Acceleration,
}

/// A follower motion as cubics `s = c₀ + c₁t + c₂t² + c₃t³`, `t = φ − φᵢ`, on the
/// segments `[φᵢ, φᵢ₊₁)` that cover `[0, 2π)`.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionTable {
    /// Segment starts (rad), increasing, the first 0; the last segment ends at 2π.
    knots: Vec<f64>,
    /// Cubic coefficients per segment.
    coeffs: Vec<[f64; 4]>,
    /// `max s − min s`.
    lift: f64,
}

/// Why a table gives no motion.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct TableError(pub String);

fn fail<T>(m: impl Into<String>) -> Result<T, TableError> {
    Err(TableError(m.into()))
}

impl MotionTable {
    /// The motion of `points` `(φ rad, value)`: angles non-decreasing within `[0, 2π]`
    /// (a velocity or acceleration diagram may repeat an angle for a jump and must span
    /// `0 … 2π`; a displacement table has distinct angles in `[0, 2π)`, or ends at `2π`
    /// with the value at 0).
    pub fn new(kind: TableKind, points: &[(f64, f64)]) -> Result<Self, TableError> {
        if points.len() < 2 {
            return fail("needs at least two points");
        }
        if points.windows(2).any(|w| w[1].0 < w[0].0) {
            return fail("the cam angles must not decrease");
        }
        let mut t = match kind {
            TableKind::Displacement => Self::spline(points)?,
            TableKind::Velocity | TableKind::Acceleration => Self::diagram(kind, points)?,
        };
        t.settle()?;
        Ok(t)
    }

    /// Periodic cubic spline through distinct points.
    fn spline(points: &[(f64, f64)]) -> Result<Self, TableError> {
        let mut pts = points.to_vec();
        if let (Some(first), Some(last)) = (pts.first(), pts.last()) {
            if (last.0 - 2.0 * PI).abs() < 1e-12 {
                if (last.1 - first.1).abs() > 1e-9 * first.1.abs().max(last.1.abs()).max(1.0) {
                    return fail(
                        "a displacement table that ends at 360° must end at its value at 0°",
                    );
                }
                pts.pop();
            }
        }
        let n = pts.len();
        if n < 3 {
            return fail("a displacement table needs at least three distinct angles");
        }
        if pts[0].0 != 0.0 || pts[n - 1].0 >= 2.0 * PI {
            return fail("a displacement table starts at 0° and stays below 360°");
        }
        if pts.windows(2).any(|w| w[1].0 - w[0].0 < 1e-9) {
            return fail("a displacement table has distinct angles");
        }
        let h: Vec<f64> = (0..n)
            .map(|i| {
                if i + 1 < n {
                    pts[i + 1].0 - pts[i].0
                } else {
                    2.0 * PI - pts[i].0
                }
            })
            .collect();
        let d: Vec<f64> = (0..n)
            .map(|i| (pts[(i + 1) % n].1 - pts[i].1) / h[i])
            .collect();
        let m = cyclic_second_derivatives(&h, &d);
        let coeffs = (0..n)
            .map(|i| {
                let (m0, m1) = (m[i], m[(i + 1) % n]);
                [
                    pts[i].1,
                    d[i] - h[i] * (2.0 * m0 + m1) / 6.0,
                    m0 / 2.0,
                    (m1 - m0) / (6.0 * h[i]),
                ]
            })
            .collect();
        Ok(Self {
            knots: pts.iter().map(|p| p.0).collect(),
            coeffs,
            lift: 0.0,
        })
    }

    /// A velocity or acceleration diagram, integrated.
    fn diagram(kind: TableKind, points: &[(f64, f64)]) -> Result<Self, TableError> {
        let (first, last) = (points[0].0, points[points.len() - 1].0);
        if first != 0.0 || (last - 2.0 * PI).abs() > 1e-9 {
            return fail("a diagram spans the whole turn, 0° to 360°");
        }
        let mut knots = Vec::new();
        let mut lin = Vec::new(); // (value at start, slope) per segment
        for w in points.windows(2) {
            let h = w[1].0 - w[0].0;
            if h <= 1e-12 {
                continue; // a jump
            }
            knots.push(w[0].0);
            lin.push((w[0].1, (w[1].1 - w[0].1) / h, h));
        }
        let integral: f64 = lin.iter().map(|(v, k, h)| v * h + k * h * h / 2.0).sum();
        let scale = lin
            .iter()
            .map(|(v, k, h)| v.abs().max((v + k * h).abs()))
            .fold(0.0, f64::max);
        if scale == 0.0 {
            return fail("the diagram is zero throughout: no motion");
        }
        let what = if kind == TableKind::Velocity {
            "velocity"
        } else {
            "acceleration"
        };
        if integral.abs() > 1e-9 * scale * 2.0 * PI {
            return fail(format!(
                "the {what} diagram does not close: its integral over the turn is {integral:.6e}, not 0 (the follower would not come back)"
            ));
        }
        let mut coeffs = Vec::with_capacity(lin.len());
        let (mut s, mut v) = (0.0, 0.0);
        for &(a, k, h) in &lin {
            let c = match kind {
                TableKind::Velocity => [s, a, k / 2.0, 0.0],
                _ => [s, v, a / 2.0, k / 6.0],
            };
            s = c[0] + h * (c[1] + h * (c[2] + h * c[3]));
            v = c[1] + h * (2.0 * c[2] + 3.0 * h * c[3]);
            coeffs.push(c);
        }
        if kind == TableKind::Acceleration {
            // s(2π) with s'(0) = 0 is `s`; a starting speed v₀ adds v₀ φ everywhere.
            let v0 = -s / (2.0 * PI);
            for (c, x) in coeffs.iter_mut().zip(&knots) {
                c[0] += v0 * x;
                c[1] += v0;
            }
        }
        Ok(Self {
            knots,
            coeffs,
            lift: 0.0,
        })
    }

    /// Shifts `s` so the lowest position is 0 and records the lift.
    fn settle(&mut self) -> Result<(), TableError> {
        let n = 7200;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..n {
            let s = self.eval(2.0 * PI * k as f64 / n as f64)[0];
            lo = lo.min(s);
            hi = hi.max(s);
        }
        for c in &mut self.coeffs {
            c[0] -= lo;
        }
        self.lift = hi - lo;
        if !(self.lift.is_finite() && self.lift > 0.0) {
            return fail("the table gives no lift");
        }
        Ok(())
    }

    /// The same motion scaled so that its lift is `h`.
    pub fn scaled_to(mut self, h: f64) -> Self {
        let k = h / self.lift;
        for c in &mut self.coeffs {
            c.iter_mut().for_each(|x| *x *= k);
        }
        self.lift = h;
        self
    }

    fn segment(&self, p: f64) -> usize {
        self.knots.partition_point(|&k| k <= p).saturating_sub(1)
    }
}

impl Displacement for MotionTable {
    fn eval(&self, phi: f64) -> [f64; 4] {
        let p = phi.rem_euclid(2.0 * PI);
        let i = self.segment(p);
        let c = &self.coeffs[i];
        let t = p - self.knots[i];
        [
            c[0] + t * (c[1] + t * (c[2] + t * c[3])),
            c[1] + t * (2.0 * c[2] + 3.0 * t * c[3]),
            2.0 * c[2] + 6.0 * t * c[3],
            6.0 * c[3],
        ]
    }

    fn stroke(&self) -> f64 {
        self.lift
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.knots.clone()
    }

    fn derivative_scale(&self, order: usize) -> f64 {
        let h = self
            .knots
            .windows(2)
            .map(|w| w[1] - w[0])
            .chain(self.knots.last().map(|k| 2.0 * PI - k))
            .fold(2.0 * PI, f64::min);
        self.lift / h.powi(order as i32)
    }
}

/// Second derivatives `M` of the periodic cubic spline with intervals `h` and slopes
/// `d`: the cyclic tridiagonal system solved by Sherman–Morrison.
fn cyclic_second_derivatives(h: &[f64], d: &[f64]) -> Vec<f64> {
    let n = h.len();
    let prev = |i: usize| (i + n - 1) % n;
    let diag: Vec<f64> = (0..n).map(|i| 2.0 * (h[prev(i)] + h[i])).collect();
    let rhs: Vec<f64> = (0..n).map(|i| 6.0 * (d[i] - d[prev(i)])).collect();
    // Row i: h[i−1] M[i−1] + diag[i] M[i] + h[i] M[i+1]; the corners are h[n−1].
    let (alpha, beta) = (h[n - 1], h[n - 1]);
    let gamma = -diag[0];
    let mut b = diag.clone();
    b[0] -= gamma;
    b[n - 1] -= alpha * beta / gamma;
    let lower = |i: usize| h[i - 1];
    let upper = |i: usize| h[i];
    let x = thomas(&b, &lower, &upper, &rhs);
    let mut u = vec![0.0; n];
    u[0] = gamma;
    u[n - 1] = alpha;
    let z = thomas(&b, &lower, &upper, &u);
    let f = (x[0] + beta * x[n - 1] / gamma) / (1.0 + z[0] + beta * z[n - 1] / gamma);
    x.iter().zip(&z).map(|(xi, zi)| xi - f * zi).collect()
}

/// Solves the tridiagonal system with diagonal `b`, sub-diagonal `lower(i)` (row i ≥ 1)
/// and super-diagonal `upper(i)` (row i < n − 1).
fn thomas(
    b: &[f64],
    lower: &dyn Fn(usize) -> f64,
    upper: &dyn Fn(usize) -> f64,
    r: &[f64],
) -> Vec<f64> {
    let n = b.len();
    let (mut c, mut d) = (vec![0.0; n], vec![0.0; n]);
    c[0] = if n > 1 { upper(0) / b[0] } else { 0.0 };
    d[0] = r[0] / b[0];
    for i in 1..n {
        let m = b[i] - lower(i) * c[i - 1];
        c[i] = if i + 1 < n { upper(i) / m } else { 0.0 };
        d[i] = (r[i] - lower(i) * d[i - 1]) / m;
    }
    let mut x = d;
    for i in (0..n - 1).rev() {
        x[i] -= c[i] * x[i + 1];
    }
    x
}

/// The motion of a law cam: a law with its timing or a table.
#[derive(Clone, Debug, PartialEq)]
pub enum CamMotion {
    /// Dwell–rise–dwell–return with named laws.
    Law(crate::machines::cams::laws::MotionLaw),
    /// A table or diagram.
    Table(MotionTable),
    /// What a given profile makes the follower do.
    Profile(crate::machines::cams::given_profile::ProfileMotion),
}

impl CamMotion {
    fn inner(&self) -> &dyn Displacement {
        match self {
            Self::Law(m) => m,
            Self::Table(t) => t,
            Self::Profile(p) => p,
        }
    }
}

impl Displacement for CamMotion {
    fn eval(&self, phi: f64) -> [f64; 4] {
        self.inner().eval(phi)
    }

    fn stroke(&self) -> f64 {
        self.inner().stroke()
    }

    fn breakpoints(&self) -> Vec<f64> {
        self.inner().breakpoints()
    }

    fn derivative_scale(&self, order: usize) -> f64 {
        self.inner().derivative_scale(order)
    }
}
