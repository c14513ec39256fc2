//! Shape of the tool-point cloud: its dimension (principal spreads above a tolerance)
//! and, when it is flat, its plane — for a planar mechanism the workspace is reported as
//! an area, measured on pixels in that plane.
//!
//! The plane comes from a principal-component analysis of a pilot cloud; a normal
//! within 1e-9 of a world axis is snapped to it and the in-plane axes are then the other
//! two world axes in order (x–z for an arm in the world x–z plane), so pixels line up with
//! world axes when they can. The main pass re-checks every sample's distance to the plane.

use crate::core::spatial::{Mat3, Vec3};
use crate::workspace::grid::PlaneFrame;

/// What the pilot cloud looks like.
#[derive(Clone, Debug)]
pub(crate) struct Shape {
    /// Number of principal spreads above the tolerance (0 to 3).
    pub dimension: usize,
    /// Largest distance of a pilot point from the best-fit plane.
    pub off_plane: f64,
    /// Best-fit plane.
    pub plane: PlaneFrame,
}

/// Principal-component analysis of `points`. A principal spread (standard deviation)
/// at or below `spread_tol` (m) counts as flat for [`Shape::dimension`]; eigenvalues are
/// only accurate to about `ε` times the largest, so `spread_tol` must be well above
/// `√ε` times the extent. Planarity itself is judged on the distances to the plane.
pub(crate) fn analyse(points: &[Vec3], spread_tol: f64) -> Shape {
    let n = points.len().max(1) as f64;
    let mean = points.iter().fold(Vec3::zeros(), |a, p| a + p) / n;
    let mut cov = Mat3::zeros();
    for p in points {
        let d = p - mean;
        cov += d * d.transpose();
    }
    cov /= n;
    let eig = cov.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let dimension = order
        .iter()
        .filter(|&&k| eig.eigenvalues[k].max(0.0).sqrt() > spread_tol)
        .count();
    let mut normal: Vec3 = eig.eigenvectors.column(order[0]).into_owned().normalize();
    let mut u: Vec3 = eig.eigenvectors.column(order[2]).into_owned().normalize();
    let axis = (0..3).find(|&k| normal[k].abs() >= 1.0 - 1e-9);
    let v = match axis {
        Some(k) => {
            normal = Vec3::zeros();
            normal[k] = 1.0;
            let others: Vec<usize> = (0..3).filter(|&i| i != k).collect();
            u = Vec3::zeros();
            u[others[0]] = 1.0;
            let mut v = Vec3::zeros();
            v[others[1]] = 1.0;
            v
        }
        None => normal.cross(&u).normalize(),
    };
    let off = mean.dot(&normal);
    let off_plane = points
        .iter()
        .map(|p| (p.dot(&normal) - off).abs())
        .fold(0.0, f64::max);
    Shape {
        dimension,
        off_plane,
        plane: PlaneFrame {
            o: normal * off,
            u,
            v,
            n: normal,
        },
    }
}
