//! The edge checks: the coarse pass in rake order, the refinement of intervals whose
//! inflated check failed, and the per-edge speed bounds (see the parent module's docs).

use crate::planning::checker::checker_state::{
    group_bit, CheckScratch, Checker, EdgeMode, Piece, SpeedTables, PAIRS_BIT,
};
use crate::planning::lanes::{Mask, ALL, L, N};
use crate::planning::simd::Simd;

impl Checker {
    #[inline(always)]
    pub(super) fn edge_free_impl<S: Simd>(
        &self,
        tok: S,
        a: &[f32],
        b: &[f32],
        mode: EdgeMode,
        s: &mut CheckScratch,
    ) -> bool {
        let continuous = mode == EdgeMode::Continuous;
        let nv = self.nv();
        let mut dist2 = 0.0f32;
        for k in 0..nv {
            dist2 += (b[k] - a[k]) * (b[k] - a[k]);
        }
        if continuous {
            self.edge_speeds(a, b, s);
        }
        s.moving = continuous;
        let res = if continuous {
            self.opts.resolution
        } else {
            self.opts.search_resolution
        };
        let n = ((dist2.sqrt() * res).ceil() as usize).max(1);
        // Continuous: fill the coarse batches' lanes. The same batches then cover narrower
        // intervals, with less inflation and fewer to refine (UR5: 46 → 43 a query).
        let n = if continuous { n.div_ceil(N) * N } else { n };
        let h0 = if continuous { 0.5 / n as f32 } else { 0.0 };
        let m = n.div_ceil(N);
        let mut qs = std::mem::take(&mut s.q);
        s.stack.clear();
        if continuous {
            s.need.fill(ALL);
            s.need_pairs = ALL;
        }
        let mut ok = true;
        // Discrete: the lanes the points leave idle in the last batches check more points.
        let (idle, mut extra) = (m * N - n, 0);
        let leaving = mode == EdgeMode::DiscreteLeavingEnd;
        // Coarse pass in rake order; an exact hit ends it, inflated-only hits wait. Every
        // lane checks a point (continuous: `n` fills the batches).
        for i in 0..m {
            let mut t = [0.0f32; N];
            for (l, tl) in t.iter_mut().enumerate() {
                let k = l * m + i;
                // Continuous: interval centres; discrete: the points k/n, k = 1..n (the end
                // included, the start being a node already checked), then the extra points.
                *tl = if k < n {
                    (k as f32 + if continuous { 0.5 } else { 1.0 }) / n as f32
                } else {
                    extra += 1;
                    extra_point(extra - 1, idle, n, leaving)
                };
            }
            let (exact, inflated) = self.lerp_lanes_hit(tok, a, b, &t, &[h0; N], &mut qs, s);
            if exact != 0 {
                ok = false;
                break;
            }
            for (l, &tl) in t.iter().enumerate() {
                if inflated & (1 << l) != 0 {
                    let items = self.failed_items(l, s);
                    s.stack.push(Piece {
                        t: tl,
                        h: h0,
                        items,
                    });
                }
            }
        }
        ok = ok && self.refine(tok, a, b, &mut qs, s);
        std::mem::swap(&mut s.q, &mut qs);
        s.moving = false;
        ok
    }

    /// Works through the stack of intervals whose inflated check failed but whose centre is
    /// free: their pieces are checked with a piece's inflation, eight at a time (halves of
    /// four intervals, quarters of two, eighths of one), each piece only against what
    /// failed on its interval ([`Piece::items`]). False on a real (exact) hit.
    #[inline(always)]
    pub(super) fn refine<S: Simd>(
        &self,
        tok: S,
        a: &[f32],
        b: &[f32],
        qs: &mut [L],
        s: &mut CheckScratch,
    ) -> bool {
        while !s.stack.is_empty() {
            let mut t = [0.0f32; N];
            let mut h = [0.0f32; N];
            let mut lanes = 0;
            s.need.fill(0);
            s.need_pairs = 0;
            // Pieces per interval: as many as fill the lanes (one interval: eight pieces
            // with an eighth of the inflation, not two and six idle lanes).
            let k = match s.stack.len() {
                1 => N,
                2 => N / 2,
                _ => 2,
            };
            while lanes + k <= N && !s.stack.is_empty() {
                let p = s.stack.pop().unwrap_or_default();
                let hh = p.h / k as f32;
                if hh < 1e-7 {
                    // Subdivided to nothing without an exact hit: refuse, conservatively.
                    return false;
                }
                let lanes_k: Mask = ((1 << k) - 1) << lanes;
                self.set_need(p.items, lanes_k, s);
                for j in 0..k {
                    t[lanes + j] = p.t - p.h + (2 * j + 1) as f32 * hh;
                    h[lanes + j] = hh;
                }
                lanes += k;
            }
            // Idle lanes repeat the first piece and check nothing (no need set).
            for l in lanes..N {
                t[l] = t[0];
                h[l] = h[0];
            }
            let (exact, inflated) = self.lerp_lanes_hit(tok, a, b, &t, &h, qs, s);
            if exact != 0 {
                return false;
            }
            for l in 0..lanes {
                if inflated & (1 << l) != 0 {
                    let items = self.failed_items(l, s);
                    s.stack.push(Piece {
                        t: t[l],
                        h: h[l],
                        items,
                    });
                }
            }
        }
        true
    }

    /// The checks that failed inflated in lane `l` of the last batch, as [`Piece::items`].
    #[inline(always)]
    fn failed_items(&self, l: usize, s: &CheckScratch) -> u64 {
        let mut items = if s.pairs_fail & (1 << l) != 0 {
            PAIRS_BIT
        } else {
            0
        };
        for (g, &m) in s.group_fail.iter().enumerate() {
            if m & (1 << l) != 0 {
                items |= group_bit(g);
            }
        }
        items
    }

    /// Marks `lanes` as needing the checks of `items` ([`Piece::items`]) in the next batch.
    #[inline(always)]
    fn set_need(&self, items: u64, lanes: Mask, s: &mut CheckScratch) {
        let items = if self.selective { items } else { u64::MAX };
        if items & PAIRS_BIT != 0 {
            s.need_pairs |= lanes;
        }
        for (g, need) in s.need.iter_mut().enumerate() {
            if items & group_bit(g) != 0 {
                *need |= lanes;
            }
        }
    }

    /// Per-sphere, per-link, per-self-pair and per-cluster speed bounds
    /// `v = Σ_k |b_k − a_k| ρ_k` of the edge (from the transposed tables of
    /// [`SpeedTables`], so that the sums run eight or sixteen bounds at a time).
    #[inline(always)]
    pub(super) fn edge_speeds(&self, a: &[f32], b: &[f32], s: &mut CheckScratch) {
        for (d, (&ak, &bk)) in s.abs_delta.iter_mut().zip(a.iter().zip(b)) {
            *d = (bk - ak).abs();
        }
        let t = &self.speed_tables;
        speeds_into(&t.sphere, &s.abs_delta, &mut s.speed);
        speeds_into(&t.link, &s.abs_delta, &mut s.link_speed);
        speeds_into(&t.pair, &s.abs_delta, &mut s.pair_speed);
        speeds_into(&t.cluster, &s.abs_delta, &mut s.cluster_speed);
        s.l1 = 0.0;
        for (d, body) in s.body_delta.iter_mut().zip(&self.bodies) {
            *d = body.mult * (b[body.q_index] - a[body.q_index]);
            s.l1 += d.abs();
        }
    }

    /// Hits at `a + t (b − a)` per lane, spheres inflated for half-widths `h`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn lerp_lanes_hit<S: Simd>(
        &self,
        tok: S,
        a: &[f32],
        b: &[f32],
        t: &[f32; N],
        h: &[f32; N],
        qs: &mut [L],
        s: &mut CheckScratch,
    ) -> (Mask, Mask) {
        for (k, lane) in qs.iter_mut().enumerate() {
            let d = b[k] - a[k];
            for (x, &tl) in lane.0.iter_mut().zip(t) {
                *x = a[k] + tl * d;
            }
        }
        s.batches += 1;
        if s.moving {
            self.lanes_hit::<S, true>(tok, qs, L(*h), s)
        } else {
            self.lanes_hit::<S, false>(tok, qs, L(*h), s)
        }
    }
}

/// The `e`-th of `idle` extra points of a discrete check with `n` intervals: leaving a
/// task's end ([`EdgeMode::DiscreteLeavingEnd`]), spread over the first interval, where a
/// hand leaving a grasp sweeps past the grasped object; otherwise at the centres of
/// intervals spread over the edge.
#[inline(always)]
fn extra_point(e: usize, idle: usize, n: usize, leaving: bool) -> f32 {
    if leaving {
        (e + 1) as f32 / ((idle + 1) * n) as f32
    } else {
        ((e * n / idle) as f32 + 0.5) / n as f32
    }
}

impl SpeedTables {
    /// From row-major tables (`nv` per row): spheres, links, pairs, clusters.
    pub(super) fn new(nv: usize, rows: [&[f32]; 4]) -> SpeedTables {
        let [sphere, link, pair, cluster] = rows.map(|r| transpose(r, nv));
        SpeedTables {
            sphere,
            link,
            pair,
            cluster,
        }
    }
}

/// Coordinate-major copy of a row-major table with `nv` columns.
fn transpose(rows: &[f32], nv: usize) -> Vec<f32> {
    let n = rows.len().checked_div(nv).unwrap_or(0);
    (0..nv)
        .flat_map(|k| (0..n).map(move |i| rows[i * nv + k]))
        .collect()
}

/// `out[i] = Σ_k d_k table[k · n + i]`, summed over `k` in order (the same bits as the
/// row-by-row sums).
#[inline(always)]
fn speeds_into(table: &[f32], d: &[f32], out: &mut [f32]) {
    let n = out.len();
    out.fill(0.0);
    if n == 0 {
        return;
    }
    for (row, &dk) in table.chunks_exact(n).zip(d) {
        for (o, &r) in out.iter_mut().zip(row) {
            *o += dk * r;
        }
    }
}
