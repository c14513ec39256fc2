//! The exact closest approaches of a certified motion ([`crate::collision::certify`]): the smallest
//! exact distance over the samples, environment and self apart, and the certified lower
//! bound of the clearance along the curve, by branch and bound over (sample, pair).
//!
//! Every entry starts at its best known lower bound: the bounding-volume gap, or what the
//! march of the certificate found there. The entry with the smallest bound is refined
//! (convex hulls, then the exact shapes) until the smallest remaining bound is no smaller
//! than the best exact distance. A refined entry raises its neighbours' bounds by temporal
//! coherence (`d(j) ≥ d(k) − Σ ρ · (path length between the samples)`), and exact queries
//! are bounded by the best distance so far (seeded with the smallest exact distance the
//! march measured): above it only the proof that it is above is needed. With each entry
//! lowered by the motion of its two half-intervals, the same search gives the certified
//! clearance bound along the whole curve.

use crate::collision::bounds::{Certifier, Level};
use crate::collision::certify::{ClearanceBound, Known, SampleMin, Work};
use crate::collision::collision_scene::{CollisionModel, PairDistance};
use crate::collision::shape::{distance_and_points, Placed};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

impl Certifier {
    /// The best known lower bound of every (sample, pair), sample-major, starting from the
    /// bounding-volume gaps.
    pub(super) fn ball_bounds(&self, cm: &CollisionModel, w: &mut Work) -> Vec<Known> {
        let np = self.pairs.len();
        let mut out = Vec::with_capacity(w.n * np);
        for k in 0..w.n {
            for (p, &[i, j]) in self.pairs.iter().enumerate() {
                let (pa, pb) = (*w.pose(k, i), *w.pose(k, j));
                let (value, _, _) = self.lower_bound(
                    cm,
                    p,
                    &pa,
                    &pb,
                    f64::INFINITY,
                    Level::Ball,
                    &mut w.hints[p],
                    &mut w.scratch,
                    &mut w.ev,
                );
                out.push(Known {
                    value,
                    level: Level::Ball,
                    exact: false,
                });
            }
        }
        out
    }

    /// The exact minimum over the samples and the certified clearance bound, of the self
    /// pairs (`selfs`) or the environment pairs.
    pub(super) fn minima(
        &self,
        cm: &CollisionModel,
        w: &mut Work,
        known: &mut [Known],
        selfs: bool,
    ) -> (Option<SampleMin>, Option<ClearanceBound>) {
        let range = if selfs {
            0..self.n_self
        } else {
            self.n_self..self.pairs.len()
        };
        if range.is_empty() {
            return (None, None);
        }
        let Some((k, p, _)) = self.search(cm, w, known, range.clone(), false) else {
            return (None, None);
        };
        let sample_min = self.witness(cm, w, k, p);
        let last = 2 * (w.n - 1);
        let clearance = self.search(cm, w, known, range, true).map(|(k, p, d)| {
            let hk = 2 * k;
            let [a, b] = self.pairs[p].map(|o| cm.objects[o as usize].owner);
            ClearanceBound {
                distance: d,
                from: w.half_time(hk.saturating_sub(1)),
                to: w.half_time((hk + 1).min(last)),
                a,
                b,
            }
        });
        (Some(sample_min), clearance)
    }

    /// The motion of pair `p` over the two half-intervals around sample `k` (the larger).
    fn around(&self, w: &Work, k: usize, p: usize) -> f64 {
        let (hk, last) = (2 * k, 2 * (w.n - 1));
        let l = if hk > 0 {
            w.span(self, p, hk - 1, hk)
        } else {
            0.0
        };
        let r = if hk < last {
            w.span(self, p, hk, hk + 1)
        } else {
            0.0
        };
        l.max(r)
    }

    /// Branch and bound for the smallest `d(k, p)` (or, with `around`, `d(k, p)` less the
    /// motion around sample `k`) over the samples and the pairs of `range`. `known` holds
    /// the best lower bound of each entry and is refined in place; a refined entry also
    /// raises its neighbours' bounds by temporal coherence (`d(j) ≥ d(k) − span(k, j)`).
    fn search(
        &self,
        cm: &CollisionModel,
        w: &mut Work,
        known: &mut [Known],
        range: std::ops::Range<usize>,
        around: bool,
    ) -> Option<(usize, usize, f64)> {
        let off = |w: &Work, k: usize, p: usize| {
            if around {
                self.around(w, k, p)
            } else {
                0.0
            }
        };
        let np = self.pairs.len();
        let wr: &Work = w;
        let mut heap: BinaryHeap<Entry> = (0..wr.n)
            .flat_map(|k| range.clone().map(move |p| (k, p)))
            .map(|(k, p)| Entry {
                key: known[k * np + p].value - off(wr, k, p),
                k,
                p,
            })
            .collect();
        // Seeded with the smallest exact distance known (from the march or a previous
        // search), so that every exact query below is bounded by it.
        let mut best: Option<(usize, usize, f64)> = None;
        for k in 0..wr.n {
            for p in range.clone() {
                let kn = known[k * np + p];
                let v = kn.value - off(wr, k, p);
                if kn.exact && best.is_none_or(|b| v < b.2) {
                    best = Some((k, p, v));
                }
            }
        }
        while let Some(e) = heap.pop() {
            if best.is_some_and(|b| e.key >= b.2) {
                break;
            }
            let o = off(w, e.k, e.p);
            let kn = known[e.k * np + e.p];
            if kn.value - o > e.key {
                // Raised by a neighbour since it was queued.
                heap.push(Entry {
                    key: kn.value - o,
                    ..e
                });
                continue;
            }
            if kn.exact {
                if best.is_none_or(|b| kn.value - o < b.2) {
                    best = Some((e.k, e.p, kn.value - o));
                }
                continue;
            }
            let [i, j] = self.pairs[e.p];
            let (pa, pb) = (*w.pose(e.k, i), *w.pose(e.k, j));
            let level = if kn.level == Level::Ball {
                Level::Hull
            } else {
                Level::Exact
            };
            // Above the best so far, only the proof that it is above matters.
            let need = best.map_or(f64::INFINITY, |b| b.2 + o);
            let (h, s) = (&mut w.hints[e.p], &mut w.scratch);
            let (d, level, exact) =
                self.lower_bound(cm, e.p, &pa, &pb, need, level, h, s, &mut w.ev);
            let d = if exact { d } else { d.max(kn.value) };
            // An exact distance bounds every later query at once, not when it is popped.
            if exact && best.is_none_or(|b| d - o < b.2) {
                best = Some((e.k, e.p, d - o));
            }
            known[e.k * np + e.p] = Known {
                value: d,
                level,
                exact,
            };
            self.propagate(w, known, e.k, e.p, d);
            heap.push(Entry { key: d - o, ..e });
        }
        best
    }

    /// Raises the bounds of pair `p` at the samples around `k` to `d − span` while that
    /// is higher.
    fn propagate(&self, w: &Work, known: &mut [Known], k: usize, p: usize, d: f64) {
        let np = self.pairs.len();
        for dir in [-1isize, 1] {
            let mut j = k as isize + dir;
            while j >= 0 && (j as usize) < w.n {
                let ju = j as usize;
                let (a, b) = if ju < k { (ju, k) } else { (k, ju) };
                let v = d - w.span(self, p, 2 * a, 2 * b);
                let slot = &mut known[ju * np + p];
                if slot.exact || v <= slot.value {
                    break;
                }
                slot.value = v;
                j += dir;
            }
        }
    }

    /// The pair distance with witness points of pair `p` at sample `k`.
    pub(super) fn witness(
        &self,
        cm: &CollisionModel,
        w: &mut Work,
        k: usize,
        p: usize,
    ) -> SampleMin {
        let [i, j] = self.pairs[p];
        let (pa, pb) = (*w.pose(k, i), *w.pose(k, j));
        let (oa, ob) = (&cm.objects[i as usize], &cm.objects[j as usize]);
        let (ba, bb) = (oa.shape.aabb(&pa), ob.shape.aabb(&pb));
        let a = Placed {
            shape: &oa.shape,
            pose: &pa,
            aabb: &ba,
        };
        let b = Placed {
            shape: &ob.shape,
            pose: &pb,
            aabb: &bb,
        };
        let (d, x, y) = distance_and_points(a, b, &mut w.scratch);
        SampleMin {
            time: w.motion.times[k],
            pair: PairDistance {
                a: oa.owner,
                b: ob.owner,
                distance: d,
                point_a: x.into(),
                point_b: y.into(),
            },
            q: w.qs[k * w.nv..(k + 1) * w.nv].to_vec(),
        }
    }
}

/// A branch-and-bound entry: smallest key first.
struct Entry {
    key: f64,
    k: usize,
    p: usize,
}

impl PartialEq for Entry {
    fn eq(&self, o: &Self) -> bool {
        self.key.total_cmp(&o.key) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        o.key.total_cmp(&self.key)
    }
}
