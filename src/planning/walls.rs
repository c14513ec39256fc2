//! Why a search may have failed: a band of one joint's values, between the start's and the
//! goal's, in which no sampled configuration is free. Every path from start to goal moves
//! that joint through the band, so where the band is truly blocked no path exists: a UR5
//! whose elbow spans ±2π cannot bring its elbow from 2 rad to 4 rad, since the forearm
//! folded onto the upper arm (elbow ±π) always collides.
//!
//! The test is sampled, not a proof: a slice of the joint's values (every [`STEP`] rad) is
//! called blocked when none of [`SAMPLES`] configurations with the other coordinates
//! uniform in their ranges is free. A failed query names the first band it finds, as a
//! likely cause.

use crate::model::Model;
use crate::planning::checker::{CheckScratch, Checker};
use crate::planning::sampler::{bounds, Rng};

/// Width of a slice of a joint's values (rad or m).
pub const STEP: f64 = 0.05;

/// Configurations tried per slice before it is called blocked.
pub const SAMPLES: usize = 100;

/// A blocked band of one coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct Wall {
    /// The coordinate.
    pub coordinate: usize,
    /// Its blocked values.
    pub from: f64,
    /// Upper end of the blocked values.
    pub to: f64,
}

/// The first blocked band of any coordinate between `start` and `goal` (see the module
/// docs), each coordinate scanned from the start's value towards the goal's.
pub fn wall_between(
    model: &Model,
    checker: &Checker,
    s: &mut CheckScratch,
    start: &[f64],
    goal: &[f64],
    seed: u64,
) -> Option<Wall> {
    let nv = model.nv;
    let mut rng = Rng::new(seed ^ 0x3a11_5eed);
    let mut q = vec![0.0f32; nv];
    for k in 0..nv {
        let (a, b) = (start[k], goal[k]);
        let slices = ((b - a).abs() / STEP).floor() as usize;
        let mut band: Option<(f64, f64)> = None;
        for i in 1..slices {
            let v = a + (b - a).signum() * STEP * i as f64;
            let blocked = (0..SAMPLES).all(|_| {
                for (j, x) in q.iter_mut().enumerate() {
                    let (lo, hi) = bounds(model, j);
                    *x = (lo + (hi - lo) * rng.next_f64()) as f32;
                }
                q[k] = v as f32;
                !checker.config_free(&q, s)
            });
            match (blocked, band) {
                (true, None) => band = Some((v, v)),
                (true, Some((from, _))) => band = Some((from, v)),
                (false, Some((from, to))) => {
                    return Some(Wall {
                        coordinate: k,
                        from: from.min(to),
                        to: from.max(to),
                    })
                }
                (false, None) => {}
            }
        }
        if let Some((from, to)) = band {
            return Some(Wall {
                coordinate: k,
                from: from.min(to),
                to: from.max(to),
            });
        }
    }
    None
}
