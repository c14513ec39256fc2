//! Informed sampling (Gammell, Srinivasa & Barfoot, IROS 2014): once a path of length `c`
//! joins `start` and `goal`, only configurations `x` with `‖x − start‖ + ‖goal − x‖ < c`
//! can lie on a shorter one. They fill the prolate hyperspheroid (PHS) with foci `start`
//! and `goal`, transverse diameter `c` and conjugate diameters `√(c² − c_min²)`, where
//! `c_min = ‖goal − start‖`.
//!
//! A uniform sample of the PHS is `x = centre + L·u`, `u` uniform in the unit n-ball and
//! `L = R·diag(c/2, r, …, r)·Rᵀ` with `r = √(c² − c_min²)/2` and `R` any rotation taking
//! the first axis to the transverse axis `a`. Because the ball is rotation-invariant,
//! `L = r·I + (c/2 − r)·a·aᵀ` gives the same distribution without forming `R`.
//!
//! Samples outside the joint box are rejected. When the PHS is larger than the joint box
//! (early, with a long first path) the box is sampled instead and samples outside the PHS
//! are rejected, as Gammell et al. do: each way, the kept samples are uniform over the
//! intersection. After [`MAX_TRIES`] rejections the last draw is clamped to the box, so a
//! sample is always returned in bounded time.

use crate::planning::sampler::Rng;

/// Draws before a sample is clamped into the box.
pub const MAX_TRIES: usize = 64;

/// A sampler of the configurations that could shorten a path between two foci.
#[derive(Clone, Debug, Default)]
pub struct InformedSampler {
    start: Vec<f32>,
    goal: Vec<f32>,
    centre: Vec<f32>,
    /// Unit transverse axis (`start → goal`); zero when the foci coincide.
    axis: Vec<f32>,
    lo: Vec<f32>,
    hi: Vec<f32>,
    c_min: f32,
    /// Half the transverse diameter and half a conjugate diameter.
    half_transverse: f32,
    half_conjugate: f32,
    /// Sample the box and reject by the PHS (true) or the PHS and reject by the box.
    box_first: bool,
}

impl InformedSampler {
    /// A sampler between `start` and `goal` within the joint box `[lo, hi]`; it samples
    /// the whole box until [`InformedSampler::set_cost_bound`] is called.
    pub fn new(start: &[f32], goal: &[f32], lo: &[f32], hi: &[f32]) -> InformedSampler {
        let mut s = InformedSampler::default();
        s.reset(start, goal, lo, hi);
        s
    }

    /// Re-aims the sampler at new foci and box (allocates only when they grow).
    pub fn reset(&mut self, start: &[f32], goal: &[f32], lo: &[f32], hi: &[f32]) {
        let c_min = dist(start, goal);
        let set = |v: &mut Vec<f32>, it: &mut dyn Iterator<Item = f32>| {
            v.clear();
            v.extend(it);
        };
        set(&mut self.start, &mut start.iter().copied());
        set(&mut self.goal, &mut goal.iter().copied());
        set(&mut self.lo, &mut lo.iter().copied());
        set(&mut self.hi, &mut hi.iter().copied());
        let mid = start.iter().zip(goal).map(|(s, g)| 0.5 * (s + g));
        set(&mut self.centre, &mut mid.into_iter());
        let unit = start
            .iter()
            .zip(goal)
            .map(|(s, g)| if c_min > 1e-6 { (g - s) / c_min } else { 0.0 });
        set(&mut self.axis, &mut unit.into_iter());
        self.c_min = c_min;
        self.half_transverse = f32::INFINITY;
        self.half_conjugate = f32::INFINITY;
        self.box_first = true;
    }

    /// The length of the straight line between the foci: no path is shorter.
    pub fn min_cost(&self) -> f32 {
        self.c_min
    }

    /// Restricts the samples to configurations that could lie on a path shorter than `c`.
    pub fn set_cost_bound(&mut self, c: f32) {
        let c = c.max(self.c_min);
        self.half_transverse = 0.5 * c;
        self.half_conjugate = 0.5 * (c * c - self.c_min * self.c_min).max(0.0).sqrt();
        self.box_first = self.log_phs_measure() >= self.log_box_measure();
    }

    /// `‖x − start‖ + ‖goal − x‖`: the shortest path through `x`.
    pub fn heuristic(&self, x: &[f32]) -> f32 {
        dist(&self.start, x) + dist(x, &self.goal)
    }

    /// Writes one sample into `out` (`n` values; the rest of a padded buffer is left).
    pub fn sample(&self, rng: &mut Rng, out: &mut [f32]) {
        let n = self.start.len();
        let bound = 2.0 * self.half_transverse;
        for _ in 0..MAX_TRIES {
            if self.box_first {
                for ((o, lo), hi) in out[..n].iter_mut().zip(&self.lo).zip(&self.hi) {
                    *o = lo + (hi - lo) * rng.next_f64() as f32;
                }
                if self.heuristic(&out[..n]) < bound {
                    return;
                }
            } else {
                self.in_phs(rng, &mut out[..n]);
                if self.in_box(&out[..n]) {
                    return;
                }
            }
        }
        for ((o, &lo), &hi) in out[..n].iter_mut().zip(&self.lo).zip(&self.hi) {
            *o = o.clamp(lo, hi);
        }
    }

    /// A uniform sample of the PHS: `centre + r·u + (c/2 − r)(a·u)·a`.
    fn in_phs(&self, rng: &mut Rng, out: &mut [f32]) {
        let n = out.len();
        let mut norm2 = 0.0f64;
        for pair in out.chunks_mut(2) {
            let g = gaussian_pair(rng);
            for (o, g) in pair.iter_mut().zip(g) {
                *o = g as f32;
                norm2 += g * g;
            }
        }
        // Uniform in the ball: a uniform direction times radius U^(1/n).
        let radius = rng.next_f64().powf(1.0 / n as f64) / norm2.sqrt().max(1e-300);
        let mut along = 0.0f32;
        for (o, a) in out.iter_mut().zip(&self.axis) {
            *o *= radius as f32;
            along += *o * a;
        }
        let stretch = (self.half_transverse - self.half_conjugate) * along;
        for ((o, a), c) in out.iter_mut().zip(&self.axis).zip(&self.centre) {
            *o = c + self.half_conjugate * *o + stretch * a;
        }
    }

    fn in_box(&self, x: &[f32]) -> bool {
        x.iter()
            .zip(self.lo.iter().zip(&self.hi))
            .all(|(v, (l, h))| *v >= *l && *v <= *h)
    }

    /// ln of the PHS volume: `ln(ζ_n) + ln(c/2) + (n − 1)·ln(r)`.
    fn log_phs_measure(&self) -> f64 {
        let n = self.start.len() as f64;
        let ln_unit_ball = 0.5 * n * std::f64::consts::PI.ln() - ln_gamma(0.5 * n + 1.0);
        ln_unit_ball
            + f64::from(self.half_transverse).ln()
            + (n - 1.0) * f64::from(self.half_conjugate.max(1e-30)).ln()
    }

    fn log_box_measure(&self) -> f64 {
        self.lo
            .iter()
            .zip(&self.hi)
            .map(|(l, h)| f64::from((h - l).max(1e-30)).ln())
            .sum()
    }
}

/// Euclidean distance of two configurations.
pub fn dist(a: &[f32], b: &[f32]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f32>()
        .sqrt()
}

/// Two independent standard normal draws (Marsaglia's polar method: a point uniform in the
/// unit disc, by rejection from the square, scaled by `√(−2 ln s / s)`; one logarithm and no
/// trigonometry per pair, where Box–Muller spent a logarithm and a cosine per draw).
fn gaussian_pair(rng: &mut Rng) -> [f64; 2] {
    loop {
        let u = 2.0 * rng.next_f64() - 1.0;
        let v = 2.0 * rng.next_f64() - 1.0;
        let s = u * u + v * v;
        if s > 0.0 && s < 1.0 {
            let f = (-2.0 * s.ln() / s).sqrt();
            return [u * f, v * f];
        }
    }
}

/// `ln Γ(x)` for `x = k/2`, `k ≥ 2` (the unit-ball volume's denominator).
fn ln_gamma(x: f64) -> f64 {
    // Γ(x + 1) = x Γ(x), down to Γ(1) = 1 or Γ(1/2) = √π.
    let mut acc = 0.0;
    let mut y = x;
    while y > 1.0 + 1e-9 {
        y -= 1.0;
        acc += y.ln();
    }
    if (y - 0.5).abs() < 1e-9 {
        acc + 0.5 * std::f64::consts::PI.ln()
    } else {
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_pairs_have_the_moments_of_two_independent_standard_normals() {
        let mut rng = Rng::new(3);
        let n = 200_000;
        let (mut m1, mut m2, mut m4, mut cross) = ([0.0f64; 2], [0.0f64; 2], [0.0f64; 2], 0.0);
        for _ in 0..n {
            let g = gaussian_pair(&mut rng);
            for k in 0..2 {
                m1[k] += g[k];
                m2[k] += g[k] * g[k];
                m4[k] += g[k].powi(4);
            }
            cross += g[0] * g[1];
        }
        let n = n as f64;
        for k in 0..2 {
            // Standard errors at n = 2·10⁵: mean 0.0022, variance 0.0032, E[g⁴] 0.022.
            assert!((m1[k] / n).abs() < 0.01, "mean {}", m1[k] / n);
            assert!((m2[k] / n - 1.0).abs() < 0.015, "variance {}", m2[k] / n);
            assert!((m4[k] / n - 3.0).abs() < 0.1, "fourth moment {}", m4[k] / n);
        }
        assert!((cross / n).abs() < 0.01, "correlation {}", cross / n);
    }

    #[test]
    fn ln_gamma_matches_known_values() {
        // Γ(3) = 2, Γ(5/2) = 3√π/4, Γ(4) = 6.
        assert!((ln_gamma(3.0) - 2f64.ln()).abs() < 1e-12);
        let g52 = 0.75 * std::f64::consts::PI.sqrt();
        assert!((ln_gamma(2.5) - g52.ln()).abs() < 1e-12);
        assert!((ln_gamma(4.0) - 6f64.ln()).abs() < 1e-12);
    }
}
