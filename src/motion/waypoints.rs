//! Helpers of the piecewise trajectories: default joint names, the waypoint check, the
//! segment holding a time, and uniform time grids.

use crate::motion::trajectory_error::TrajectoryError;

/// Names `joint0`, `joint1`, … for `n` coordinates (when no model is at hand).
pub(crate) fn default_names(n: usize) -> Vec<String> {
    (0..n).map(|k| format!("joint{k}")).collect()
}

/// Checks a waypoint list: at least two, all `n` long, all finite.
pub(crate) fn validate_waypoints(waypoints: &[Vec<f64>]) -> Result<usize, TrajectoryError> {
    if waypoints.len() < 2 {
        return Err(TrajectoryError::Invalid(format!(
            "need at least two waypoints (got {})",
            waypoints.len()
        )));
    }
    let n = waypoints[0].len();
    if n == 0 {
        return Err(TrajectoryError::Invalid(
            "waypoints have no coordinates".into(),
        ));
    }
    for (i, w) in waypoints.iter().enumerate() {
        if w.len() != n {
            return Err(TrajectoryError::Invalid(format!(
                "waypoint {i} has {} values, waypoint 0 has {n}",
                w.len()
            )));
        }
        if let Some(k) = w.iter().position(|x| !x.is_finite()) {
            return Err(TrajectoryError::Invalid(format!(
                "waypoint {i}: coordinate {k} is not finite"
            )));
        }
    }
    Ok(n)
}

/// Segment of a piecewise motion with knot times `knots` (sorted, `knots[0] = 0`) holding
/// `t` (clamped), and the local time in it.
#[inline]
pub(crate) fn locate(knots: &[f64], t: f64) -> (usize, f64) {
    let nseg = knots.len() - 1;
    let t = t.clamp(0.0, knots[nseg]);
    // First knot strictly greater than t, minus one: the segment [knots[k], knots[k+1]).
    let k = knots
        .partition_point(|&x| x <= t)
        .saturating_sub(1)
        .min(nseg - 1);
    (k, t - knots[k])
}

/// A uniform time grid over `[0, duration]` with step at most `dt`: `(intervals, step)`.
/// A zero duration gives one interval of zero length.
pub(crate) fn time_grid(duration: f64, dt: f64) -> (usize, f64) {
    if duration <= 0.0 {
        return (1, 0.0);
    }
    let n = ((duration / dt).ceil() as usize).max(1);
    (n, duration / n as f64)
}
