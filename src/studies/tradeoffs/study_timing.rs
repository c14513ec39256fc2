//! The studies' measurement helpers: per-call timing over short rounds ([`time_calls`],
//! [`time_rounds`]), their summary ([`Stats`]) and the log-log slope of a scaling
//! ([`log_slope`]).

use serde::Serialize;
use std::time::Instant;

/// Summary statistics of a sample (times in the caller's unit).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Stats {
    /// Number of values.
    pub count: usize,
    /// Median.
    pub median: f64,
    /// 99th percentile (nearest rank).
    pub p99: f64,
    /// Smallest.
    pub min: f64,
    /// Largest.
    pub max: f64,
    /// Mean.
    pub mean: f64,
}

impl Stats {
    /// Statistics of `values` (NaNs ignored; all zeros when empty).
    pub fn of(values: &[f64]) -> Stats {
        let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
        if v.is_empty() {
            return Stats::default();
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        let rank = ((0.99 * n as f64).ceil() as usize).clamp(1, n) - 1;
        Stats {
            count: n,
            median,
            p99: v[rank],
            min: v[0],
            max: v[n - 1],
            mean: v.iter().sum::<f64>() / n as f64,
        }
    }
}

/// Times `f` (called with a running call index, to cycle over prepared inputs): a round is
/// as many calls as take about `round_ns` (calibrated on a warm-up), and the result is
/// the per-call time in nanoseconds over `rounds` rounds (median and p99 across rounds).
/// `f` should not allocate. Rounds are kept short (a fraction of a scheduler slice) so
/// that on a loaded machine most of them run uninterrupted and the median is the
/// uncontended cost, while the p99 shows the interruptions.
pub fn time_calls(rounds: usize, round_ns: f64, f: impl FnMut(usize)) -> Stats {
    Stats::of(&time_rounds(rounds, round_ns, f))
}

/// [`time_calls`] returning the per-call time of every round (ns).
pub fn time_rounds(rounds: usize, round_ns: f64, mut f: impl FnMut(usize)) -> Vec<f64> {
    // Calibrate: double the batch until it takes a tenth of a round.
    let mut k = 0usize;
    let mut batch = 1usize;
    let per_call = loop {
        let t = Instant::now();
        for _ in 0..batch {
            f(k);
            k += 1;
        }
        let ns = t.elapsed().as_nanos() as f64;
        if ns >= 0.1 * round_ns || batch >= 1 << 24 {
            break ns / batch as f64;
        }
        batch *= 2;
    };
    let per_round = ((round_ns / per_call.max(1.0)).ceil() as usize).clamp(1, 1 << 26);
    // Warm-up round.
    for _ in 0..per_round {
        f(k);
        k += 1;
    }
    (0..rounds.max(1))
        .map(|_| {
            let t = Instant::now();
            for _ in 0..per_round {
                f(k);
                k += 1;
            }
            t.elapsed().as_nanos() as f64 / per_round as f64
        })
        .collect()
}

/// Least-squares slope of `log10 y` against `log10 x` over the points with positive,
/// finite coordinates (`None` with fewer than two).
pub fn log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.log10(), y.log10()))
        .collect();
    if p.len() < 2 {
        return None;
    }
    let n = p.len() as f64;
    let (mx, my) = (
        p.iter().map(|a| a.0).sum::<f64>() / n,
        p.iter().map(|a| a.1).sum::<f64>() / n,
    );
    let sxx: f64 = p.iter().map(|a| (a.0 - mx).powi(2)).sum();
    let sxy: f64 = p.iter().map(|a| (a.0 - mx) * (a.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}
