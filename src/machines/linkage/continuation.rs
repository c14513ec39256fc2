//! Sweeps that continue through change points on the smooth (analytic) motion.
//!
//! At a change point two assembly branches cross (the antiparallelogram and the
//! parallelogram of a folding four-bar meet where all four links lie on one line). The
//! tracker of [`crate::machines::linkage::sweep`] keeps the sign of each group's
//! indicator, so past such a point the only solutions with that sign are on the other
//! branch, and its sweep stops there. Here the sweep goes on along the curve that passes
//! smoothly through the point: from a regular state at `s* − h` (`s*` where it stopped),
//! the Taylor prediction `q(s* + h) ≈ q + q' (2h) + ½ q'' (2h)²` is within `O(h³)` of the
//! smooth continuation, while the other branch lies `O(h)` away; Newton from it, checked
//! to move less than a tenth of the way from `s* − h`, lands on the continuation, and the
//! tracker resumes there with the groups' signs it finds. A real limit position (the
//! input cannot pass) has no solution past it, so the sweep still stops there.

use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::position::solve_position;
use crate::machines::linkage::sweep::{sweep, Sweep, SweepOptions, TrackError, Tracker};
use nalgebra::DVector;

/// At most this many change points are passed in one sweep.
const MAX_PASSES: usize = 64;

/// [`sweep`], continued through the change points where it stops; returns the sweep (its
/// `stopped` only where no continuation exists) and the inputs passed that way.
pub fn sweep_through(
    l: &Linkage,
    guess: &DVector<f64>,
    opts: &SweepOptions,
) -> Result<(Sweep, Vec<f64>), TrackError> {
    let mut sw = sweep(l, guess, opts)?;
    let mut passed = Vec::new();
    let span = opts.to - opts.from;
    let dir = span.signum();
    let n = (span.abs() / opts.step.abs()).round().max(1.0) as usize;
    let grid = |k: usize| {
        if k == n {
            opts.to
        } else {
            opts.from + span * (k as f64) / (n as f64)
        }
    };
    for _ in 0..MAX_PASSES {
        let Some(TrackError::Stuck { at, .. }) = sw.stopped.clone() else {
            break;
        };
        let h = 0.25 * (span.abs() / n as f64).min(2.0_f64.to_radians());
        let Some(mut t) = restart_after(l, &sw, at, dir * h, opts) else {
            break;
        };
        passed.push(at);
        sw.singular_positions.push(at);
        sw.stopped = None;
        let first = (0..=n).find(|&k| (grid(k) - at) * dir > h).unwrap_or(n + 1);
        for k in first..=n {
            match t.advance(grid(k)) {
                Ok(st) => sw.samples.push(st),
                Err(e) => {
                    sw.stopped = Some(e);
                    break;
                }
            }
        }
        sw.singular_positions
            .extend(t.singular_positions.iter().copied());
    }
    Ok((sw, passed))
}

/// A tracker at `s* + h` on the smooth continuation through `s* = at`, or `None`.
fn restart_after<'a>(
    l: &'a Linkage,
    sw: &Sweep,
    at: f64,
    h: f64,
    opts: &SweepOptions,
) -> Option<Tracker<'a>> {
    let last = sw.samples.last()?;
    let tracker = sw.tracker(l);
    let before = tracker.state_near(last, at - h)?;
    if before.singular {
        return None;
    }
    let guess = before.predict(at + h);
    let sol = solve_position(l, &guess, at + h, &opts.newton).ok()?;
    let moved = (&sol.q - &before.q).amax();
    if (&sol.q - &guess).amax() > 0.1 * moved {
        return None;
    }
    let groups = crate::machines::linkage::branch::structural_groups(l, &sol.q);
    let probe = Tracker::resume(l, groups.clone(), before.clone(), opts.newton);
    let after = probe.state_near(&before, at + h)?;
    if after.singular || (&after.q - &sol.q).amax() > 0.1 * moved {
        return None;
    }
    Some(Tracker::resume(l, groups, after, opts.newton))
}

/// A singular position the sweep passed where two assembly branches cross: the sign of
/// a group's indicator differs between the last regular sample before it and the first
/// after it (on the smooth motion through a change point the branch indicator changes
/// sign, since the group's block of `Φ_q` is singular there).
#[derive(Clone, Debug, PartialEq)]
pub struct BranchCrossing {
    /// Input there (rad or m).
    pub at: f64,
    /// Index in the sweep's samples of the last regular sample before it.
    pub before: usize,
    /// Index of the first regular sample after it.
    pub after: usize,
    /// Each group's sign before and after (±1).
    pub signs: (Vec<i8>, Vec<i8>),
    /// Whether the tracker stopped there and [`sweep_through`] restarted it on the smooth
    /// continuation (else the tracker passed it itself, leaving the point along the
    /// limits of `q'`, `q''`, which is the same smooth motion).
    pub restarted: bool,
}

/// The branch crossings among `sw.singular_positions` (`passed`: the inputs
/// [`sweep_through`] restarted at). With `periodic` (a complete full turn of a crank) the
/// samples wrap around: the first sample follows the last, and a crossing at the end is
/// the one at the start.
pub fn branch_crossings(sw: &Sweep, passed: &[f64], periodic: bool) -> Vec<BranchCrossing> {
    use crate::machines::linkage::branch::sign;
    let dir = (sw.options.to - sw.options.from).signum();
    let near = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()));
    let signs =
        |k: usize| -> Vec<i8> { sw.samples[k].indicators.iter().map(|x| sign(*x)).collect() };
    let regular: Vec<usize> = (0..sw.samples.len())
        .filter(|&k| !sw.samples[k].singular)
        .collect();
    let mut out: Vec<BranchCrossing> = Vec::new();
    for &at in &sw.singular_positions {
        if periodic && near(at, sw.options.to) {
            let start = sw.options.from;
            if sw.singular_positions.iter().any(|&x| near(x, start)) {
                continue;
            }
        }
        if out.iter().any(|c| near(c.at, at)) {
            continue;
        }
        let before = regular
            .iter()
            .rev()
            .find(|&&k| (sw.samples[k].s - at) * dir < 0.0)
            .or(periodic.then(|| regular.last()).flatten());
        let after = regular
            .iter()
            .find(|&&k| (sw.samples[k].s - at) * dir > 0.0)
            .or(periodic.then(|| regular.first()).flatten());
        let (Some(&b), Some(&a)) = (before, after) else {
            continue;
        };
        let (sb, sa) = (signs(b), signs(a));
        let restarted = passed.iter().any(|&p| near(p, at));
        // The tracker's landing point and the restart there lie between the same two
        // samples: one crossing, at the restart.
        if let Some(c) = out.iter_mut().find(|c| (c.before, c.after) == (b, a)) {
            if restarted {
                c.at = at;
                c.restarted = true;
            }
            continue;
        }
        if sb
            .iter()
            .zip(&sa)
            .any(|(x, y)| *x != 0 && *y != 0 && x != y)
        {
            out.push(BranchCrossing {
                at,
                before: b,
                after: a,
                signs: (sb, sa),
                restarted,
            });
        }
    }
    out.sort_by(|x, y| (x.at * dir).total_cmp(&(y.at * dir)));
    out
}
