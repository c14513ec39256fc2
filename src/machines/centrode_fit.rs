//! A centrode as a fitted curve: least-squares line and circle through its points, so a
//! centrode that is a circle (the Cardan pair of an isosceles slider-crank, the Scotch
//! yoke) or a line is reported by its centre and radius (or a point and direction) beside
//! the point list, with the largest residual saying how well it fits.
//!
//! - **Line** (total least squares): through the mean `m` of the points along the
//!   eigenvector of the largest eigenvalue of the scatter matrix `Σ (p − m)(p − m)ᵀ`;
//!   residual: the distance of each point from it.
//! - **Circle**: Kåsa's algebraic fit, `min Σ (x² + y² + D x + E y + F)²` (linear least
//!   squares, on points shifted to their mean), then Gauss–Newton on the geometric
//!   residuals `|p − c| − R`; residual: `||p − c| − R|`.
//! - **Kind**: `point` when all points lie within `tol` of their mean, `line` when the
//!   line fits within `tol`, `circle` when the circle does, else `curve`.

use crate::machines::linkage::Vec2;
use nalgebra::{Matrix3, Vector3};

/// A fitted circle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CircleFit {
    /// Centre.
    pub centre: Vec2,
    /// Radius.
    pub radius: f64,
    /// Largest `||p − c| − R|`.
    pub max_residual: f64,
}

/// A fitted line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    /// A point of it (the mean of the points).
    pub point: Vec2,
    /// Unit direction.
    pub direction: Vec2,
    /// Largest distance of a point from it.
    pub max_residual: f64,
}

/// What a point set is, within a tolerance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveKind {
    /// All points coincide.
    Point,
    /// A straight line.
    Line,
    /// A circle.
    Circle,
    /// None of these.
    Curve,
}

impl CurveKind {
    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            CurveKind::Point => "point",
            CurveKind::Line => "line",
            CurveKind::Circle => "circle",
            CurveKind::Curve => "curve",
        }
    }
}

/// Both fits and the kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveFit {
    /// The kind within the tolerance.
    pub kind: CurveKind,
    /// The mean of the points.
    pub mean: Vec2,
    /// Largest distance of a point from the mean.
    pub spread: f64,
    /// The line fit (`None` with fewer than two distinct points).
    pub line: Option<LineFit>,
    /// The circle fit (`None` with fewer than three points or collinear ones).
    pub circle: Option<CircleFit>,
}

fn mean(pts: &[Vec2]) -> Vec2 {
    pts.iter().fold(Vec2::zeros(), |a, p| a + p) / pts.len() as f64
}

/// The total-least-squares line through `pts`.
pub fn fit_line(pts: &[Vec2]) -> Option<LineFit> {
    if pts.len() < 2 {
        return None;
    }
    let m = mean(pts);
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in pts {
        let d = p - m;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    if sxx + syy == 0.0 {
        return None;
    }
    // Principal direction of [[sxx, sxy], [sxy, syy]].
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let dir = Vec2::new(angle.cos(), angle.sin());
    let max_residual = pts
        .iter()
        .map(|p| crate::machines::linkage::cross(&dir, &(p - m)).abs())
        .fold(0.0, f64::max);
    Some(LineFit {
        point: m,
        direction: dir,
        max_residual,
    })
}

/// The least-squares circle through `pts` (Kåsa, then Gauss–Newton).
pub fn fit_circle(pts: &[Vec2]) -> Option<CircleFit> {
    if pts.len() < 3 {
        return None;
    }
    let m = mean(pts);
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for p in pts {
        let d = p - m;
        let row = Vector3::new(d.x, d.y, 1.0);
        let rhs = -(d.x * d.x + d.y * d.y);
        a += row * row.transpose();
        b += row * rhs;
    }
    let sol = a.lu().solve(&b)?;
    let c0 = Vec2::new(-0.5 * sol[0], -0.5 * sol[1]);
    let r2 = c0.norm_squared() - sol[2];
    if !(r2 > 0.0 && r2.is_finite()) {
        return None;
    }
    let (mut c, mut r) = (c0, r2.sqrt());
    for _ in 0..20 {
        let mut jtj = Matrix3::zeros();
        let mut jtr = Vector3::zeros();
        for p in pts {
            let d = (p - m) - c;
            let n = d.norm();
            if n == 0.0 {
                continue;
            }
            let row = Vector3::new(-d.x / n, -d.y / n, -1.0);
            let res = n - r;
            jtj += row * row.transpose();
            jtr += row * res;
        }
        let Some(step) = jtj.lu().solve(&(-jtr)) else {
            break;
        };
        c += Vec2::new(step[0], step[1]);
        r += step[2];
        if step.norm() <= 1e-15 * r.max(1e-300) {
            break;
        }
    }
    let centre = c + m;
    let max_residual = pts
        .iter()
        .map(|p| ((p - centre).norm() - r).abs())
        .fold(0.0, f64::max);
    (r.is_finite() && r > 0.0).then_some(CircleFit {
        centre,
        radius: r,
        max_residual,
    })
}

/// Fits both and names the kind within `tol` (length).
pub fn classify(pts: &[Vec2], tol: f64) -> Option<CurveFit> {
    if pts.is_empty() {
        return None;
    }
    let m = mean(pts);
    let spread = pts.iter().map(|p| (p - m).norm()).fold(0.0, f64::max);
    let line = fit_line(pts);
    let circle = fit_circle(pts);
    let kind = if spread <= tol {
        CurveKind::Point
    } else if line.is_some_and(|l| l.max_residual <= tol) {
        CurveKind::Line
    } else if circle.is_some_and(|c| c.max_residual <= tol) {
        CurveKind::Circle
    } else {
        CurveKind::Curve
    };
    Some(CurveFit {
        kind,
        mean: m,
        spread,
        line,
        circle,
    })
}
