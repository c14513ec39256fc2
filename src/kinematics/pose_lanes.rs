//! Batched frame placements: the world pose of one link for every row of a row-major
//! `(n, nv)` array of configurations, eight rows at a time in SIMD lanes
//! ([`ToolChain::poses`], the links' support chain only), written as row-major 4 × 4
//! homogeneous matrices. Rows the lane `sin_cos` cannot take (`|q| > 1e4`, or not finite)
//! and the last `n mod 8` rows go through the scalar [`forward_kinematics`] +
//! [`frame_placement`]; a link fixed to the world gets its constant placement.

use crate::core::simd_lanes::{lanes_in_range, LaneBuf, Lanes, LANES};
use crate::core::spatial::Se3;
use crate::kinematics::fk_lanes::ToolChain;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::Model;

/// Values per row of the output: a 4 × 4 matrix.
pub const POSE_VALUES: usize = 16;

/// The buffers of [`PoseLanes::frame_poses`] for one link of one model: its chain, the
/// configurations transposed to lanes, and a scalar [`Data`] for the fallback rows.
/// Allocated once; a call allocates nothing.
pub struct PoseLanes {
    link: usize,
    chain: Option<ToolChain>,
    q: LaneBuf,
    out: [Lanes; 12],
    scalar: Data,
}

impl PoseLanes {
    /// Buffers for link `link` of `model` (an index into `model.links`).
    pub fn new(model: &Model, link: usize) -> PoseLanes {
        PoseLanes {
            link,
            chain: ToolChain::for_pose(model, link),
            q: LaneBuf::zeros(model.nv),
            out: [[0.0; LANES]; 12],
            scalar: Data::new(model),
        }
    }

    /// The chain's instruction set limited to `max` (every one gives the same bits).
    pub fn limit_isa(&mut self, max: crate::core::simd_lanes::Isa) {
        if let Some(c) = &mut self.chain {
            c.limit_isa(max);
        }
    }

    /// The link's world pose for every row of `q` (row-major `(n, nv)`) into `out`
    /// (row-major `(n, 4, 4)`).
    pub fn frame_poses(&mut self, model: &Model, q: &[f64], out: &mut [f64]) {
        let nv = model.nv;
        assert!(
            self.q.len() == nv && self.link < model.links.len(),
            "PoseLanes was built for another model"
        );
        let n = q.len().checked_div(nv).unwrap_or(out.len() / POSE_VALUES);
        assert!(
            q.len() == n * nv && out.len() == n * POSE_VALUES,
            "q needs nv values and out 16 values per row"
        );
        let Some(chain) = &self.chain else {
            let fixed = model.links[self.link].offset;
            for row in out.chunks_exact_mut(POSE_VALUES) {
                write_4x4(&fixed, row);
            }
            return;
        };
        let groups = if nv == 0 { 0 } else { n / LANES };
        for g in 0..groups {
            let rows = &q[g * LANES * nv..(g + 1) * LANES * nv];
            for (k, lanes) in self.q.iter_mut().enumerate() {
                for l in 0..LANES {
                    lanes[l] = rows[l * nv + k];
                }
            }
            let outs = &mut out[g * LANES * POSE_VALUES..(g + 1) * LANES * POSE_VALUES];
            if !lanes_in_range(&self.q) {
                for (l, o) in outs.chunks_exact_mut(POSE_VALUES).enumerate() {
                    scalar_row(
                        model,
                        &mut self.scalar,
                        self.link,
                        &rows[l * nv..(l + 1) * nv],
                        o,
                    );
                }
                continue;
            }
            chain.poses(&self.q, &mut self.out);
            for (l, o) in outs.chunks_exact_mut(POSE_VALUES).enumerate() {
                for r in 0..3 {
                    for c in 0..3 {
                        o[4 * r + c] = self.out[3 * r + c][l];
                    }
                    o[4 * r + 3] = self.out[9 + r][l];
                }
                o[12..].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
            }
        }
        for r in groups * LANES..n {
            let o = &mut out[r * POSE_VALUES..(r + 1) * POSE_VALUES];
            scalar_row(
                model,
                &mut self.scalar,
                self.link,
                &q[r * nv..(r + 1) * nv],
                o,
            );
        }
    }
}

/// Row `q`'s pose of `link` by the scalar FK.
fn scalar_row(model: &Model, data: &mut Data, link: usize, q: &[f64], out: &mut [f64]) {
    forward_kinematics(model, data, q);
    write_4x4(&frame_placement(model, data, link), out);
}

/// `m` as a row-major 4 × 4 homogeneous matrix.
fn write_4x4(m: &Se3, out: &mut [f64]) {
    for r in 0..3 {
        for c in 0..3 {
            out[4 * r + c] = m.rot[(r, c)];
        }
        out[4 * r + 3] = m.trans[r];
    }
    out[12..16].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
}
