//! Sweeps over the input with branch tracking (predictor–corrector continuation; Allgower
//! & Georg, *Introduction to Numerical Continuation Methods*, 1990, ch. 2 and 8), singular
//! positions, dead centres and stationary values.
//!
//! **Tracking.** From a state `(s, q, q', q'')` on the branch, the next input `s + h` is
//! solved by Newton ([`crate::machines::linkage::position`]) from the Taylor predictor
//! `q + q' h + ½ q'' h²`. A step is accepted only if
//! 1. Newton converges;
//! 2. the corrector is small against the step, `‖q_new − q_pred‖∞ ≤ 0.1 ‖q_new − q‖∞`
//!    (+ a rounding floor): a jump to the other assembly mode moves the solution a finite
//!    distance that does not shrink with the step;
//! 3. no group's branch indicator ([`crate::machines::linkage::branch`]) changes sign, unless one
//!    end of the step is singular for that group (|indicator| < `GROUP_SINGULAR_TOL`).
//!
//! A rejected step is halved; a sign change that survives is located by regula falsi on
//! the indicator and the tracker lands on the singular position itself (a change point,
//! where the branches cross), then continues from it. It never jumps to the other mode.
//!
//! **At a singular position** the driven Jacobian `Φ_q` has lost rank: the position is
//! still solved (Newton with minimum-norm steps converges, linearly at a double root), and
//! where the branch goes on through (a change point), its velocity and acceleration are
//! the limit along the branch: with `D(ε) = ½ (q'(s − ε) + q'(s + ε))` evaluated on the
//! tracked branch at `ε`, `ε/2`, `ε/4` (`ε` = 0.01 rad), two Richardson steps leave an `O(ε⁶)`
//! error; the solves at `s ± ε` are conditioned like `1/ε`, which is why `ε` is not smaller. Where
//! the branch ends (a limit position: the input cannot move further) the right side of
//! `Φ_q q' = e_s` is inconsistent and the state is marked locked.
//!
//! **Dead centres** of a follower (a link pinned to the ground other than the driven one,
//! or a link sliding on a ground line) are the inputs where its rate `dθ/ds` or `dx/ds`
//! vanishes: there the linkage could not be driven from that follower (the Jacobian with
//! the driver moved to it is singular). They are found by a sign change of the rate
//! between samples and refined by regula falsi (Illinois) on the branch.

use crate::core::least_squares::Factorization;
use crate::machines::linkage::branch::{
    indicators, indicators_from, sign, structural_groups, StructuralGroup, GROUP_SINGULAR_TOL,
};
use crate::machines::linkage::constraints::jacobian_mat;
use crate::machines::linkage::description::{Linkage, PlanarJoint, GROUND};
use crate::machines::linkage::mobility::{conditioning, conditioning_from, Conditioning};
use crate::machines::linkage::position::{solve_position, AssemblyError, NewtonOptions};
use crate::machines::linkage::velocity::path_derivatives_with;
use nalgebra::DVector;

/// One state on the tracked branch.
#[derive(Clone, Debug)]
pub struct State {
    /// Input value `s` (rad or m).
    pub s: f64,
    /// Coordinates.
    pub q: DVector<f64>,
    /// `q' = dq/ds`.
    pub dq: DVector<f64>,
    /// `q'' = d²q/ds²`.
    pub ddq: DVector<f64>,
    /// `‖Φ(q, s)‖∞`.
    pub residual: f64,
    /// Conditioning of the driven Jacobian.
    pub conditioning: Conditioning,
    /// Branch indicator of each structural group.
    pub indicators: Vec<f64>,
    /// Whether the driven Jacobian or a group is singular here.
    pub singular: bool,
    /// Whether `q'`, `q''` are limits along the branch (singular positions).
    pub limit: bool,
    /// At a singular position where the branch does not go on: the input cannot move.
    pub locked: bool,
}

impl State {
    /// `q̇ = q' ṡ`.
    pub fn qd(&self, sd: f64) -> DVector<f64> {
        &self.dq * sd
    }

    /// `q̈ = q'' ṡ² + q' s̈`.
    pub fn qdd(&self, sd: f64, sdd: f64) -> DVector<f64> {
        &self.ddq * (sd * sd) + &self.dq * sdd
    }

    /// The Taylor prediction at input `s`.
    pub fn predict(&self, s: f64) -> DVector<f64> {
        let h = s - self.s;
        &self.q + &self.dq * h + &self.ddq * (0.5 * h * h)
    }
}

/// Why tracking stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TrackError {
    /// The first position does not close.
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    /// No step, however small, continues the branch past `at` toward `target`: a limit
    /// position of the linkage (the input cannot go on).
    #[error("the branch cannot be continued past input {at} (toward {target}): {reason}")]
    Stuck {
        /// Last input reached.
        at: f64,
        /// Where it was going.
        target: f64,
        /// What failed last.
        reason: String,
    },
}

impl TrackError {
    /// The message for an angle input, with the inputs in degrees (`Display` gives the
    /// input as the tracker holds it: radians for an angle).
    pub fn in_degrees(&self) -> String {
        match self {
            TrackError::Stuck { at, target, reason } => format!(
                "the branch cannot be continued past input {}° (toward {}°): {reason}",
                crate::core::diag::fmt_num(at.to_degrees()),
                crate::core::diag::fmt_num(target.to_degrees())
            ),
            e => e.to_string(),
        }
    }
}

enum Reject {
    NoConvergence(String),
    Jump,
    /// StructuralGroup `g` changed sign; its indicator at the rejected point.
    Flip(usize, f64),
}

/// Branch tracker.
#[derive(Clone, Debug)]
pub struct Tracker<'a> {
    /// The linkage.
    pub linkage: &'a Linkage,
    /// Its structural groups (fixed at assembly).
    pub groups: Vec<StructuralGroup>,
    /// Newton options.
    pub newton: NewtonOptions,
    /// Largest step (input units).
    pub max_step: f64,
    /// Half-width `ε` of the symmetric limit at singular positions (input units).
    pub eps: f64,
    /// Singular positions passed so far.
    pub singular_positions: Vec<f64>,
    cur: State,
    last_regular: Option<State>,
}

/// `ε` and the largest step default to these times the input scale (1 rad, or the
/// linkage's length scale for a slide driver).
const EPS_REL: f64 = 1e-2;
const MAX_STEP_REL: f64 = 2.0_f64.to_radians();

impl<'a> Tracker<'a> {
    /// A tracker continuing from `state` (a state of a previous sweep of `l`).
    pub fn resume(
        l: &'a Linkage,
        groups: Vec<StructuralGroup>,
        state: State,
        newton: NewtonOptions,
    ) -> Self {
        let unit = match l.driver {
            crate::machines::linkage::Driver::Angle { .. } => 1.0,
            crate::machines::linkage::Driver::Slide { .. } => l.length_scale(),
        };
        Self {
            linkage: l,
            groups,
            newton,
            max_step: MAX_STEP_REL * unit,
            eps: EPS_REL * unit,
            singular_positions: Vec::new(),
            last_regular: (!state.singular).then(|| state.clone()),
            cur: state,
        }
    }

    /// Assembles `l` at input `s0` by Newton from `guess` (which picks the assembly mode).
    pub fn assemble(
        l: &'a Linkage,
        guess: &DVector<f64>,
        s0: f64,
        newton: NewtonOptions,
    ) -> Result<Self, TrackError> {
        let sol = solve_position(l, guess, s0, &newton)?;
        let groups = structural_groups(l, &sol.q);
        let placeholder = State {
            s: s0,
            q: sol.q.clone(),
            dq: DVector::zeros(l.ncoords()),
            ddq: DVector::zeros(l.ncoords()),
            residual: sol.residual,
            conditioning: conditioning(l, &sol.q),
            indicators: Vec::new(),
            singular: true,
            limit: false,
            locked: false,
        };
        let mut t = Self::resume(l, groups, placeholder, newton);
        t.cur = t.evaluate(sol.q, s0, sol.residual, None);
        if t.cur.singular {
            t.singular_positions.push(s0);
        } else {
            t.last_regular = Some(t.cur.clone());
        }
        Ok(t)
    }

    /// The current state.
    pub fn state(&self) -> &State {
        &self.cur
    }

    /// Derivatives, conditioning and indicators at a solved position; at a singular one,
    /// the limit along the branch from `prev` (a regular state on it).
    fn evaluate(&self, q: DVector<f64>, s: f64, residual: f64, prev: Option<&State>) -> State {
        let l = self.linkage;
        let jac = jacobian_mat(l, &q);
        let factor = Factorization::new(&jac);
        let cond = conditioning_from(&factor.singular_values, l.ncoords());
        let ind = indicators_from(&self.groups, &jac);
        let singular = cond.singular || ind.iter().any(|x| x.abs() < GROUP_SINGULAR_TOL);
        let (v, a) = path_derivatives_with(l, &q, &jac, &factor, prev.map(|p| (&p.dq, &p.ddq)));
        let scale = l.length_scale().max(1.0);
        let consistent = v.residual <= 1e-8 * scale && a.residual <= 1e-6 * scale;
        let mut st = State {
            s,
            q,
            dq: v.x,
            ddq: a.x,
            residual,
            conditioning: cond,
            indicators: ind,
            singular,
            limit: false,
            locked: singular && !consistent,
        };
        if singular {
            if let Some(p) = prev {
                match self.limit_derivatives(p, &st) {
                    Some((q, dq, ddq)) => {
                        // Newton converges only linearly to a double root, where a residual
                        // of 1e-18 still leaves an error of 1e-9: the limit along the branch
                        // (O(ε⁶)) is the better position, if it closes the loop.
                        let r =
                            crate::machines::linkage::constraints::residual_vec(l, &q, s).amax();
                        if r <= self.newton.accept * l.length_scale().max(1.0) {
                            st.q = q;
                            st.residual = r;
                        }
                        st.dq = dq;
                        st.ddq = ddq;
                        st.limit = true;
                        st.locked = false;
                    }
                    None => st.locked = true,
                }
            }
        }
        st
    }

    /// Solves at `s` from the prediction of `from`; returns the regular state there.
    fn regular_near(&self, from: &State, s: f64) -> Option<State> {
        let sol = solve_position(self.linkage, &from.predict(s), s, &self.newton).ok()?;
        let st = self.evaluate(sol.q, s, sol.residual, None);
        (!st.singular).then_some(st)
    }

    /// Symmetric Richardson limit of `(q, q', q'')` at singular state `st`, approached
    /// from the regular state `prev` on the same branch.
    #[allow(clippy::type_complexity)]
    fn limit_derivatives(
        &self,
        prev: &State,
        st: &State,
    ) -> Option<(DVector<f64>, DVector<f64>, DVector<f64>)> {
        let dir = if st.s >= prev.s { 1.0 } else { -1.0 };
        let mut d = Vec::new();
        for e in [self.eps, 0.5 * self.eps, 0.25 * self.eps] {
            let before = self.regular_near(prev, st.s - dir * e)?;
            let after = self.regular_near(&before, st.s + dir * e)?;
            // Both must be on one smooth curve through st: the midpoint is st.q to O(e²).
            let mid = (&before.q + &after.q) * 0.5;
            let curv = (&after.dq - &before.dq).amax() * e + 1e-9;
            if (&mid - &st.q).amax() > 10.0 * curv {
                return None;
            }
            d.push([
                mid,
                (&before.dq + &after.dq) * 0.5,
                (&before.ddq + &after.ddq) * 0.5,
            ]);
        }
        // Richardson: D(e) = D + c₂ e² + c₄ e⁴ + …
        let r1 = |a: &DVector<f64>, b: &DVector<f64>| (b * 4.0 - a) / 3.0;
        let r2 = |a: &DVector<f64>, b: &DVector<f64>| (b * 16.0 - a) / 15.0;
        let lim = |k: usize| r2(&r1(&d[0][k], &d[1][k]), &r1(&d[1][k], &d[2][k]));
        Some((lim(0), lim(1), lim(2)))
    }

    fn try_step(&self, s: f64) -> Result<State, Reject> {
        let l = self.linkage;
        let pred = self.cur.predict(s);
        let sol = solve_position(l, &pred, s, &self.newton)
            .map_err(|e| Reject::NoConvergence(e.to_string()))?;
        let floor = 1e-9 * l.length_scale().max(1.0);
        let moved = (&sol.q - &self.cur.q).amax();
        if (&sol.q - &pred).amax() > 0.1 * moved + floor {
            return Err(Reject::Jump);
        }
        let ind = indicators(l, &self.groups, &sol.q);
        for (g, (&a, &b)) in self.cur.indicators.iter().zip(&ind).enumerate() {
            let (sa, sb) = (sign(a), sign(b));
            if sa != 0 && sb != 0 && sa != sb {
                return Err(Reject::Flip(g, b));
            }
        }
        let prev = if self.cur.singular {
            self.last_regular.as_ref()
        } else {
            Some(&self.cur)
        };
        Ok(self.evaluate(sol.q, s, sol.residual, prev))
    }

    fn accept(&mut self, st: State) {
        if st.singular {
            let near = self
                .singular_positions
                .last()
                .is_some_and(|&x| (x - st.s).abs() < 10.0 * self.eps);
            if !near {
                self.singular_positions.push(st.s);
            }
        } else {
            self.last_regular = Some(st.clone());
        }
        self.cur = st;
    }

    /// Tracks the branch to input `target` and returns the state there.
    pub fn advance(&mut self, target: f64) -> Result<State, TrackError> {
        let min_step = 1e-12 * self.max_step.max(1.0);
        while self.cur.s != target {
            if self.cur.locked {
                return Err(TrackError::Stuck {
                    at: self.cur.s,
                    target,
                    reason: "the linkage is locked here (limit position)".into(),
                });
            }
            let remaining = target - self.cur.s;
            let mut h = remaining.clamp(-self.max_step, self.max_step);
            loop {
                let s_try = if (h - remaining).abs() <= 1e-15 * remaining.abs() {
                    target
                } else {
                    self.cur.s + h
                };
                if s_try == self.cur.s {
                    // |s| so large that the step is below its floating-point resolution:
                    // no step can make progress.
                    return Err(TrackError::Stuck {
                        at: self.cur.s,
                        target,
                        reason: "the input is too large for the tracking step (below its floating-point resolution)".into(),
                    });
                }
                match self.try_step(s_try) {
                    Ok(st) => {
                        self.accept(st);
                        break;
                    }
                    Err(Reject::Flip(g, b)) => {
                        // Regula falsi on the flipping indicator: land on its zero.
                        let a = self.cur.indicators[g];
                        let frac = if (a - b).abs() > 0.0 {
                            a / (a - b)
                        } else {
                            0.5
                        };
                        let frac = frac.clamp(0.05, 0.95);
                        h *= frac;
                    }
                    Err(Reject::Jump) => h *= 0.5,
                    Err(Reject::NoConvergence(why)) => {
                        h *= 0.5;
                        if h.abs() < min_step {
                            return Err(TrackError::Stuck {
                                at: self.cur.s,
                                target,
                                reason: why,
                            });
                        }
                        continue;
                    }
                }
                if h.abs() < min_step {
                    return Err(TrackError::Stuck {
                        at: self.cur.s,
                        target,
                        reason: "the only solutions nearby are on another branch".into(),
                    });
                }
            }
        }
        Ok(self.cur.clone())
    }

    /// The state at `s` near `from` on the branch (for refining roots between samples).
    pub fn state_near(&self, from: &State, s: f64) -> Option<State> {
        let sol = solve_position(self.linkage, &from.predict(s), s, &self.newton).ok()?;
        let prev = (!from.singular).then_some(from);
        Some(self.evaluate(sol.q, s, sol.residual, prev))
    }
}

/// Options for [`sweep`].
#[derive(Clone, Copy, Debug)]
pub struct SweepOptions {
    /// First input.
    pub from: f64,
    /// Last input.
    pub to: f64,
    /// Step (positive; its sign follows `to − from`).
    pub step: f64,
    /// Input at which the guess applies (the tracker assembles there, then goes to `from`).
    pub assemble_at: f64,
    /// Newton options.
    pub newton: NewtonOptions,
}

/// A follower: a link pinned to the ground (not the driven one), or a link sliding on a
/// ground line.
#[derive(Clone, Debug, PartialEq)]
pub enum Follower {
    /// Angle of this link.
    Rocker(usize),
    /// Position along the line of this slider joint.
    Slide(usize),
}

/// A dead centre of a follower.
#[derive(Clone, Debug)]
pub struct DeadCentre {
    /// Follower name (the link).
    pub follower: String,
    /// The state there.
    pub state: State,
    /// The follower's position there (rad or m).
    pub value: f64,
}

/// A tracked sweep.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The options it ran with.
    pub options: SweepOptions,
    /// Samples from `from` to `to` (fewer if the branch ended).
    pub samples: Vec<State>,
    /// The structural groups whose indicators the states carry.
    pub groups: Vec<StructuralGroup>,
    /// Singular positions passed (inputs).
    pub singular_positions: Vec<f64>,
    /// Why the sweep stopped early, if it did.
    pub stopped: Option<TrackError>,
}

/// Tracks `l` from the `guess` over `opts`.
pub fn sweep(l: &Linkage, guess: &DVector<f64>, opts: &SweepOptions) -> Result<Sweep, TrackError> {
    let mut t = Tracker::assemble(l, guess, opts.assemble_at, opts.newton)?;
    let first = t.advance(opts.from)?;
    t.singular_positions.clear();
    if first.singular {
        t.singular_positions.push(first.s);
    }
    let span = opts.to - opts.from;
    let n = (span.abs() / opts.step.abs()).round().max(1.0) as usize;
    let mut samples = vec![first];
    let mut stopped = None;
    for k in 1..=n {
        let s = if k == n {
            opts.to
        } else {
            opts.from + span * (k as f64) / (n as f64)
        };
        match t.advance(s) {
            Ok(st) => samples.push(st),
            Err(e) => {
                stopped = Some(e);
                break;
            }
        }
    }
    Ok(Sweep {
        options: *opts,
        samples,
        groups: t.groups.clone(),
        singular_positions: t.singular_positions.clone(),
        stopped,
    })
}

impl Sweep {
    /// A tracker on the swept branch, at the first sample (for refining between samples).
    pub fn tracker<'a>(&self, l: &'a Linkage) -> Tracker<'a> {
        Tracker::resume(
            l,
            self.groups.clone(),
            self.samples[0].clone(),
            self.options.newton,
        )
    }
}

/// The followers of `l` with their names.
pub fn followers(l: &Linkage) -> Vec<(String, Follower)> {
    let driven = l.driven_link();
    let mut v = Vec::new();
    for j in &l.joints {
        match j {
            PlanarJoint::Revolute { a, b, .. } => {
                let k = if *a == GROUND {
                    *b
                } else if *b == GROUND {
                    *a
                } else {
                    continue;
                };
                if k != driven && !v.iter().any(|(_, f)| *f == Follower::Rocker(k)) {
                    v.push((l.links[k].name.clone(), Follower::Rocker(k)));
                }
            }
            PlanarJoint::Slider(s) => {
                if s.guide == GROUND && s.link != driven {
                    let k = l.joints.iter().position(|x| x == j).expect("own joint");
                    v.push((l.links[s.link].name.clone(), Follower::Slide(k)));
                }
            }
            PlanarJoint::Contact(_) => {}
        }
    }
    v
}

/// A follower's position and its rate per unit input at a state.
pub fn follower_value(l: &Linkage, f: &Follower, st: &State) -> (f64, f64) {
    match f {
        Follower::Rocker(k) => (st.q[3 * k + 2], st.dq[3 * k + 2]),
        Follower::Slide(j) => {
            let PlanarJoint::Slider(s) = &l.joints[*j] else {
                unreachable!("slide follower on a slider joint")
            };
            let p = l.point_position(&st.q, s.link, &s.p);
            let v = l.point_velocity(&st.q, &st.dq, s.link, &s.p);
            (s.dir.dot(&(p - s.through)), s.dir.dot(&v))
        }
    }
}

/// Inputs between consecutive samples where `rate(state)` changes sign (or is zero at a
/// sample), refined by the Illinois variant of regula falsi on the tracked branch.
pub fn stationary_states(
    tracker: &Tracker,
    samples: &[State],
    rate: &dyn Fn(&State) -> f64,
) -> Vec<State> {
    let vals: Vec<f64> = samples.iter().map(rate).collect();
    let big = vals.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if big == 0.0 {
        return Vec::new();
    }
    let tiny = 1e-12 * big;
    let mut out: Vec<State> = Vec::new();
    for k in 0..samples.len() {
        if vals[k].abs() <= tiny {
            if out.last().is_none_or(|o| (o.s - samples[k].s).abs() > 1e-9) {
                out.push(samples[k].clone());
            }
            continue;
        }
        if k + 1 >= samples.len() || vals[k + 1].abs() <= tiny || vals[k] * vals[k + 1] > 0.0 {
            continue;
        }
        let (mut a, mut fa) = (samples[k].clone(), vals[k]);
        let (mut b, mut fb) = (samples[k + 1].s, vals[k + 1]);
        let mut side = 0i8;
        let mut best = a.clone();
        for _ in 0..100 {
            let s = (a.s * fb - b * fa) / (fb - fa);
            let Some(st) = tracker.state_near(&a, s) else {
                break;
            };
            let f = rate(&st);
            best = st.clone();
            if f.abs() <= 1e-15 * big || (b - a.s).abs() <= 1e-14 * (1.0 + b.abs()) {
                break;
            }
            if f * fa > 0.0 {
                a = st;
                fa = f;
                if side == 1 {
                    fb *= 0.5;
                }
                side = 1;
            } else {
                b = s;
                fb = f;
                if side == -1 {
                    fa *= 0.5;
                }
                side = -1;
            }
        }
        out.push(best);
    }
    out
}

/// Dead centres of every follower over the samples.
pub fn dead_centres(tracker: &Tracker, samples: &[State]) -> Vec<DeadCentre> {
    let l = tracker.linkage;
    let mut out = Vec::new();
    for (name, f) in followers(l) {
        for st in stationary_states(tracker, samples, &|st| follower_value(l, &f, st).1) {
            let value = follower_value(l, &f, &st).0;
            out.push(DeadCentre {
                follower: name.clone(),
                state: st,
                value,
            });
        }
    }
    out.sort_by(|a, b| a.state.s.total_cmp(&b.state.s));
    out
}

#[cfg(test)]
mod tests {
    use crate::machines::linkage::catalog;
    use crate::machines::linkage::sweep::*;

    const DIMS: (f64, f64, f64, f64) = (1.16, 0.42, 1.05, 0.74);

    fn tracker(l: &Linkage, s: f64) -> Tracker<'_> {
        let q = catalog::four_bar_guess(l, DIMS, s, 1.0).expect("closes");
        Tracker::assemble(l, &q, s, NewtonOptions::default()).expect("assembles")
    }

    fn other_branch(l: &Linkage, s: f64) -> DVector<f64> {
        let q = catalog::four_bar_guess(l, DIMS, s, -1.0).expect("closes");
        solve_position(l, &q, s, &NewtonOptions::default())
            .expect("closes")
            .q
    }

    #[test]
    fn a_step_landing_on_the_other_sign_is_rejected() {
        let l = catalog::four_bar(DIMS.0, DIMS.1, DIMS.2, DIMS.3);
        let mut t = tracker(&l, 2.6);
        assert!(t.try_step(2.62).is_ok());
        // A predictor aimed exactly at the other assembly mode: the corrector is tiny, so
        // only the sign of the group's indicator can tell.
        let target = other_branch(&l, 2.62);
        t.cur.dq = (&target - &t.cur.q) / 0.02;
        t.cur.ddq.fill(0.0);
        assert!(matches!(t.try_step(2.62), Err(Reject::Flip(0, _))));
    }

    #[test]
    fn a_step_with_a_large_correction_is_rejected() {
        let l = catalog::four_bar(DIMS.0, DIMS.1, DIMS.2, DIMS.3);
        let mut t = tracker(&l, 2.6);
        // Predict half-way between the two modes, with the sign check off (a group at a
        // singular position has no sign): Newton lands a branch-distance from the
        // prediction, which is no continuation.
        let mid = (other_branch(&l, 2.62) + &t.cur.q) * 0.5;
        t.cur.q = mid;
        t.cur.dq.fill(0.0);
        t.cur.ddq.fill(0.0);
        t.cur.indicators = vec![0.0];
        assert!(matches!(t.try_step(2.62), Err(Reject::Jump)));
    }
}
