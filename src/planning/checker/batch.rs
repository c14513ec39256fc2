//! One batch of eight configurations: link bounds and spheres against the obstacles, then
//! the self pairs, with the inflation of a continuous check (see the parent module's docs).

use crate::model::WORLD;
use crate::planning::checker::checker_state::{CheckScratch, Checker, CLEARANCE_RAMP};
use crate::planning::checker::motion::{point_speed, sub};
use crate::planning::lanes::{LanePose, Mask, ALL, L, P3};
use crate::planning::simd::{Simd, W};
use crate::planning::spheres::LinkSpheres;

impl Checker {
    /// Collision masks `(exact, inflated)` of eight configurations `q` (one `L` per
    /// coordinate): `exact` with the spheres as they are, `inflated` with sphere `i` grown by
    /// `max(speed_i · h − tol, 0)` per lane. Returns at the first exact hit (the masks are
    /// then partial). Without `MOVING` (configurations, discrete edges) nothing is inflated
    /// and the inflation is not even computed: `inflated == exact`.
    ///
    /// Every body is placed first (base to tip), then the link groups meet the obstacles
    /// from the tip back to the base, as VAMP orders them: the hand and the distal links are
    /// the likeliest to hit, so a colliding batch ends early. Self pairs come last.
    #[inline(always)]
    pub(crate) fn lanes_hit<S: Simd, const MOVING: bool>(
        &self,
        tok: S,
        q: &[L],
        h: L,
        s: &mut CheckScratch,
    ) -> (Mask, Mask) {
        let sm = &self.spheres;
        let h = tok.load(&h);
        let (mut exact, mut inflated): (Mask, Mask) = (0, 0);
        let pad = if s.keep_clearance {
            self.clearance(tok, q, s)
        } else {
            tok.splat(0.0)
        };
        for bi in 0..self.bodies.len() {
            let pose = self.body_pose(tok, bi, q, &s.poses);
            pose.store_into(&mut s.poses[bi]);
            if MOVING {
                let (w, v) = self.body_twist(tok, bi, s);
                s.twist[bi] = [w.store(), v.store()];
            }
        }
        // Groups are ordered by body: a body's pose is loaded once for all its groups.
        let mut loaded: Option<(usize, LanePose<S>)> = None;
        for g in (0..sm.links.len()).rev() {
            let ls = &sm.links[g];
            s.placed[g] = false;
            let pose = match loaded {
                Some((b, p)) if b == ls.body => p,
                _ => {
                    let p = self.stored_pose(tok, ls.body, s);
                    loaded = Some((ls.body, p));
                    p
                }
            };
            let cluster = self.clusters.of[g];
            if let Some(c) = cluster {
                if g + 1 == self.clusters.list[c].groups.end {
                    self.cluster_near::<S, MOVING>(tok, c, &pose, pad, h, s);
                }
            }
            let bc = pose.act(tok, &ls.bound.center);
            s.bounds[g] = bc.store();
            let mut br = tok.splat(ls.bound.radius) + pad;
            // Moving, only the lanes whose interval failed this group before check it
            // (the bound's place and inflation are still needed by the self pairs).
            let need = if MOVING { s.need[g] } else { ALL };
            if MOVING {
                let bi_g = self.bound_inflation(tok, g, &bc, h, s);
                s.bound_infl[g] = S::store(bi_g);
                br = br + bi_g;
                s.group_fail[g] = 0;
                if need == 0 {
                    continue;
                }
            }
            s.group_checks += 1;
            for &o in &self.reachable[g] {
                if cluster.is_some() && !s.near[o] {
                    continue;
                }
                let ob = &self.env.obstacles[o];
                if ob.near(tok, &bc, br) & need == 0 || ob.overlaps(tok, &bc, br) & need == 0 {
                    continue;
                }
                self.place_spheres::<S, MOVING>(tok, g, &pose, h, s);
                for i in ls.first..ls.end {
                    let r = tok.splat(sm.spheres[i].radius) + pad;
                    let c = P3::load(tok, &s.centers[i]);
                    if MOVING {
                        let m = ob.overlaps(tok, &c, r + tok.load(&s.infl[i])) & need;
                        if m != 0 {
                            exact |= ob.overlaps(tok, &c, r) & need;
                            // Failed inflated: try the rate of the distance.
                            let vel = self.point_velocity(tok, ls.body, &c, s);
                            let k = tok.splat(1.5 * s.l1 * s.speed[i]);
                            let rt = r - tok.splat(self.opts.tolerance);
                            let fail = m & ob.rate_overlaps(tok, &c, &vel, rt, h, k);
                            inflated |= fail;
                            s.group_fail[g] |= fail;
                        }
                    } else {
                        exact |= ob.overlaps(tok, &c, r);
                    }
                }
                if exact != 0 {
                    return (exact, if MOVING { inflated } else { exact });
                }
            }
        }
        let need = if MOVING { s.need_pairs } else { ALL };
        s.pairs_fail = 0;
        if need == 0 {
            return (exact, if MOVING { inflated } else { exact });
        }
        s.group_checks += 1;
        'runs: for run in &self.clusters.runs {
            if let Some(c) = run.cluster {
                if !self.group_meets_cluster::<S, MOVING>(tok, run.group, c, s) {
                    continue;
                }
            }
            for p in run.pairs.clone() {
                let (e, i) = self.pair_hit::<S, MOVING>(tok, p, h, s);
                exact |= e & need;
                inflated |= i & need;
                s.pairs_fail |= i & need;
                if exact != 0 {
                    break 'runs;
                }
            }
        }
        (exact, if MOVING { inflated } else { exact })
    }

    /// Places cluster `c`'s sphere (body pose `pose`) and marks in `s.near` the obstacles
    /// it may touch, inflated as the batch demands.
    #[inline(always)]
    fn cluster_near<S: Simd, const MOVING: bool>(
        &self,
        tok: S,
        c: usize,
        pose: &LanePose<S>,
        pad: W<S>,
        h: W<S>,
        s: &mut CheckScratch,
    ) {
        let cl = &self.clusters.list[c];
        let body = self.spheres.links[cl.groups.start].body;
        let cc = pose.act(tok, &cl.bound.center);
        s.cluster_bounds[c] = cc.store();
        let mut r = tok.splat(cl.bound.radius) + pad;
        if MOVING {
            let e = self.ball_inflation(tok, body, &cc, cl.bound.radius, s.cluster_speed[c], h, s);
            s.cluster_infl[c] = S::store(e);
            r = r + e;
        }
        for &o in &cl.reachable {
            let ob = &self.env.obstacles[o];
            s.near[o] = ob.near(tok, &cc, r) != 0 && ob.overlaps(tok, &cc, r) != 0;
        }
    }

    /// Whether group `g`'s bound may touch cluster `c`'s sphere (both inflated when moving).
    #[inline(always)]
    fn group_meets_cluster<S: Simd, const MOVING: bool>(
        &self,
        tok: S,
        g: usize,
        c: usize,
        s: &CheckScratch,
    ) -> bool {
        let ca = P3::load(tok, &s.bounds[g]);
        let cb = P3::load(tok, &s.cluster_bounds[c]);
        let mut rr =
            tok.splat(self.spheres.links[g].bound.radius + self.clusters.list[c].bound.radius);
        if MOVING {
            rr = rr + tok.load(&s.bound_infl[g]) + tok.load(&s.cluster_infl[c]);
        }
        ca.dist2(&cb).lt(rr * rr) != 0
    }

    /// The clearance demanded of each lane: the full [`CheckOptions::clearance`] farther
    /// than [`CLEARANCE_RAMP`] from both ends of the path, less in proportion nearer.
    #[inline(always)]
    pub(super) fn clearance<S: Simd>(&self, tok: S, q: &[L], s: &CheckScratch) -> W<S> {
        let nv = self.nv();
        let full = tok.splat(self.opts.clearance);
        if s.ends.len() != 2 * nv {
            return full;
        }
        let (mut ds, mut dg) = (tok.splat(0.0), tok.splat(0.0));
        for (k, qk) in q.iter().enumerate().take(nv) {
            let x = tok.load(qk);
            let a = x - tok.splat(s.ends[k]);
            let b = x - tok.splat(s.ends[nv + k]);
            ds = a.mul_add(a, ds);
            dg = b.mul_add(b, dg);
        }
        let near = ds.min(dg).sqrt() * tok.splat(1.0 / CLEARANCE_RAMP);
        full * near.min(tok.splat(1.0))
    }

    /// Computes the world centres of group `g`'s spheres (once per batch).
    #[inline(always)]
    pub(super) fn place_spheres<S: Simd, const MOVING: bool>(
        &self,
        tok: S,
        g: usize,
        pose: &LanePose<S>,
        h: W<S>,
        s: &mut CheckScratch,
    ) {
        if s.placed[g] {
            return;
        }
        let ls = &self.spheres.links[g];
        if !MOVING {
            for i in ls.first..ls.end {
                s.centers[i] = pose.act(tok, &self.spheres.spheres[i].center).store();
            }
            s.placed[g] = true;
            return;
        }
        // No closures here: they would not inherit the caller's target features.
        let tw = if ls.body != WORLD {
            let t = &s.twist[ls.body];
            Some((P3::load(tok, &t[0]), P3::load(tok, &t[1])))
        } else {
            None
        };
        for i in ls.first..ls.end {
            let c = pose.act(tok, &self.spheres.spheres[i].center);
            s.centers[i] = c.store();
            let speed = match &tw {
                Some((w, v)) => Some(point_speed(w, v, &pose.t, &c)),
                None => None,
            };
            s.infl[i] = S::store(self.inflation(tok, s.speed[i], speed, h, s.l1));
        }
        s.placed[g] = true;
    }

    /// The inflation `max(speed · h − tol, 0)` of a point whose speed bound over the edge is
    /// `v` (per unit of the edge parameter) and whose speed at the check point is `now`:
    /// within `h` of it the speed is at most `now + ½ M h` with `M = 3 ‖Δ‖₁ v` (see the
    /// module docs), and never more than `v`.
    #[inline(always)]
    pub(super) fn inflation<S: Simd>(
        &self,
        tok: S,
        v: f32,
        now: Option<W<S>>,
        h: W<S>,
        l1: f32,
    ) -> W<S> {
        let bound = tok.splat(v);
        let speed = match now {
            Some(now) => bound.min(now + tok.splat(1.5 * l1 * v) * h),
            None => bound,
        };
        (speed * h - tok.splat(self.opts.tolerance)).max(tok.splat(0.0))
    }

    /// Inflation of group `g`'s bounding sphere centred at `bc`: its points move at most at
    /// `|v_bc| + |ω| R`.
    #[inline(always)]
    pub(super) fn bound_inflation<S: Simd>(
        &self,
        tok: S,
        g: usize,
        bc: &P3<S>,
        h: W<S>,
        s: &CheckScratch,
    ) -> W<S> {
        let ls = &self.spheres.links[g];
        self.ball_inflation(tok, ls.body, bc, ls.bound.radius, s.link_speed[g], h, s)
    }

    /// Inflation of a ball of radius `radius` centred at `bc` on `body`, whose points move
    /// at most at `cap` over the edge: at the check point they move at most at
    /// `|v_bc| + |ω| R`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn ball_inflation<S: Simd>(
        &self,
        tok: S,
        body: usize,
        bc: &P3<S>,
        radius: f32,
        cap: f32,
        h: W<S>,
        s: &CheckScratch,
    ) -> W<S> {
        // No closures here: they would not inherit the caller's target features.
        let now = if body != WORLD {
            let t = &s.twist[body];
            let (w, v) = (P3::load(tok, &t[0]), P3::load(tok, &t[1]));
            let o = P3::load(tok, &s.poses[body].t);
            Some(point_speed(&w, &v, &o, bc) + W::norm2(w.x, w.y, w.z).sqrt() * tok.splat(radius))
        } else {
            None
        };
        self.inflation(tok, cap, now, h, s.l1)
    }

    /// Masks `(exact, inflated)` where the link groups of self pair `p` overlap (bounding
    /// spheres first). Moving, a sphere pair is inflated by the smaller of its spheres'
    /// inflations summed and the pair's relative bound `v_rel h − tol`
    /// ([`crate::planning::spheres::pair_rho`]): both cover the interval.
    #[inline(always)]
    pub(super) fn pair_hit<S: Simd, const MOVING: bool>(
        &self,
        tok: S,
        p: usize,
        h: W<S>,
        s: &mut CheckScratch,
    ) -> (Mask, Mask) {
        let (ga, gb) = self.self_pairs[p];
        let sm = &self.spheres;
        let (la, lb) = (&sm.links[ga], &sm.links[gb]);
        let ca = P3::load(tok, &s.bounds[ga]);
        let cb = P3::load(tok, &s.bounds[gb]);
        let mut rr = tok.splat(la.bound.radius + lb.bound.radius);
        let relative = if MOVING {
            let rel = tok.splat(s.pair_speed[p]) * h - tok.splat(self.opts.tolerance);
            rel.max(tok.splat(0.0))
        } else {
            tok.splat(0.0)
        };
        if MOVING {
            rr = rr + (tok.load(&s.bound_infl[ga]) + tok.load(&s.bound_infl[gb])).min(relative);
        }
        if ca.dist2(&cb).lt(rr * rr) == 0 {
            return (0, 0);
        }
        for (g, body) in [(ga, la.body), (gb, lb.body)] {
            if !s.placed[g] {
                let pose = self.stored_pose(tok, body, s);
                self.place_spheres::<S, MOVING>(tok, g, &pose, h, s);
            }
        }
        if !MOVING {
            return (self.pair_spheres_hit(tok, la, lb, ca, cb, s), 0);
        }
        let (mut exact, mut inflated) = (0, 0);
        // Each sphere of the group with more spheres against the other group's bound first.
        let (la, lb, cb, gb) = if la.end - la.first >= lb.end - lb.first {
            (la, lb, cb, gb)
        } else {
            (lb, la, ca, ga)
        };
        let rb = tok.splat(lb.bound.radius);
        let eb = tok.load(&s.bound_infl[gb]);
        for i in la.first..la.end {
            let ri = tok.splat(sm.spheres[i].radius);
            let ei = tok.load(&s.infl[i]);
            let ci = P3::load(tok, &s.centers[i]);
            let reach = ri + rb + (ei + eb).min(relative);
            if ci.dist2(&cb).lt(reach * reach) == 0 {
                continue;
            }
            for j in lb.first..lb.end {
                let cj = P3::load(tok, &s.centers[j]);
                let r = ri + tok.splat(sm.spheres[j].radius);
                let d2 = ci.dist2(&cj);
                let rinf = r + (ei + tok.load(&s.infl[j])).min(relative);
                let m = d2.lt(rinf * rinf);
                if m != 0 {
                    exact |= d2.lt(r * r);
                    inflated |= m & self.distance_rate_hit(tok, p, (i, j), (&ci, &cj), d2, h, s);
                }
            }
        }
        (exact, inflated)
    }

    /// The lanes where spheres `i` and `j` of self pair `p` (centres `ci`, `cj`, squared
    /// distance `d2`) may come closer than their radii less the tolerance within `h` of the
    /// check point, by the rate of their distance `d`: `|d'| = |x·w|/d` at the check point
    /// (`x = c_i − c_j`, `w` their relative velocity from the bodies' twists) and
    /// `|d''| ≤ |x''| + |x'|²/d ≤ 3‖Δ‖₁ (v_i + v_j) + V²/(r − tol)`, with `V` the pair's
    /// relative speed bound (in the common ancestor's frame, where `d` is the same) and
    /// `d ≥ r − tol` until a first contact. So `d` stays above `r − tol` where
    /// `d ≥ r − tol + |d'| h + ½ |d''| h²`, tested multiplied by `d`. Spheres moving side
    /// by side (a tangential motion) pass with a second-order inflation.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn distance_rate_hit<S: Simd>(
        &self,
        tok: S,
        p: usize,
        (i, j): (usize, usize),
        (ci, cj): (&P3<S>, &P3<S>),
        d2: W<S>,
        h: W<S>,
        s: &CheckScratch,
    ) -> Mask {
        let sm = &self.spheres;
        let (gi, gj) = self.self_pairs[p];
        let (bi, bj) = if (sm.links[gi].first..sm.links[gi].end).contains(&i) {
            (sm.links[gi].body, sm.links[gj].body)
        } else {
            (sm.links[gj].body, sm.links[gi].body)
        };
        let r = sm.spheres[i].radius + sm.spheres[j].radius - self.opts.tolerance;
        if r <= 0.0 {
            return Mask::MAX;
        }
        let v = s.pair_speed[p];
        let k = 1.5 * s.l1 * (s.speed[i] + s.speed[j]) + 0.5 * v * v / r;
        let vi = self.point_velocity(tok, bi, ci, s);
        let vj = self.point_velocity(tok, bj, cj, s);
        let x = sub(ci, cj);
        let w = sub(&vi, &vj);
        let xw = (x.x * w.x + x.y * w.y + x.z * w.z).abs();
        let reach = tok.splat(r) + tok.splat(k) * h * h;
        d2.lt(reach * d2.sqrt() + xw * h)
    }

    /// Mask of the lanes where a sphere of `la` touches one of `lb` (no inflation): each
    /// sphere of the group with more spheres against the other group's bound first.
    #[inline(always)]
    pub(super) fn pair_spheres_hit<S: Simd>(
        &self,
        tok: S,
        la: &LinkSpheres,
        lb: &LinkSpheres,
        ca: P3<S>,
        cb: P3<S>,
        s: &CheckScratch,
    ) -> Mask {
        let sm = &self.spheres;
        let (la, lb, cb) = if la.end - la.first >= lb.end - lb.first {
            (la, lb, cb)
        } else {
            (lb, la, ca)
        };
        let rb = tok.splat(lb.bound.radius);
        let mut hit = 0;
        for i in la.first..la.end {
            let ri = tok.splat(sm.spheres[i].radius);
            let ci = P3::load(tok, &s.centers[i]);
            let reach = ri + rb;
            if ci.dist2(&cb).lt(reach * reach) == 0 {
                continue;
            }
            for j in lb.first..lb.end {
                let r = ri + tok.splat(sm.spheres[j].radius);
                hit |= ci.dist2(&P3::load(tok, &s.centers[j])).lt(r * r);
            }
        }
        hit
    }
}
