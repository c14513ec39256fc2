//! A prismatic guide that bears on its slider at two points (a piston rod in two bushes,
//! a slider block's two ends): the guide's reaction as two normal forces, and the friction
//! `f (|N_a| + |N_b|)` they cause.
//!
//! **Statics (exact).** The prismatic joint's multipliers are a normal force `N` (along the
//! guide normal `n`, `dir × n = 1`) at the slider point `X` and a couple `C` on the slider
//! ([`crate::machines::linkage::kinetostatics`]). With `s_a`, `s_b` the positions of the
//! bearing points `A`, `B` along the guide line measured from `X`, two normal forces there
//! are the same force system when
//!
//! ```text
//! N_a + N_b = N,   s_a N_a + s_b N_b = C
//! ⇒  N_a = (C − s_b N)/(s_a − s_b),   N_b = (s_a N − C)/(s_a − s_b).
//! ```
//!
//! **Friction.** The friction force `F` acts along the guide line (through `A`, `B` and
//! `X`) against the relative sliding velocity. The kinetostatics is linear in the loads, so
//! with `F` at the guide the normal forces are `N_k(F) = α_k + β_k F` (two solutions:
//! without and with a unit friction force), and Coulomb's law for the two contacts is
//!
//! ```text
//! F = f (|α_a + β_a F| + |α_b + β_b F|).
//! ```
//!
//! `g(F) = f(|α_a + β_a F| + |α_b + β_b F|) − F` is convex and piecewise linear with
//! `g(0) ≥ 0`; its smallest root `F ≥ 0` is found segment by segment between the
//! breakpoints `F = −α_k/β_k` (the sign cases of `N_a`, `N_b`). Where `g` stays positive
//! (on the last segment `f (±β_a ± β_b) ≥ 1`: the friction grows at least as fast as the
//! force that overcomes it) no driving effort moves the slider: the guide **jams**
//! (self-locking; the drawer pushed too far off its axis, `2 f h / L ≥ 1`). Friction in
//! the other joints (friction circles, [`crate::machines::friction::friction_circle`])
//! enters as loads updated in an outer iteration, each guide solved exactly in turn.

use crate::machines::friction::friction_circle::{friction_loads, JointFriction, WithFriction};
use crate::machines::linkage::description::{Linkage, PlanarJoint, GROUND};
use crate::machines::linkage::kinetostatics::{solve, Kinetostatics, Loads, PointForce};
use crate::machines::linkage::{perp, rotate, Vec2};
use nalgebra::DVector;

/// A prismatic joint bearing at two points of its guide line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoPointGuide {
    /// Index of the slider joint in [`Linkage::joints`].
    pub joint: usize,
    /// Positions of the two bearing points along the line (m, along its direction).
    pub at: [f64; 2],
    /// `true`: measured from the slider point, moving with the sliding link (a block's
    /// ends); `false`: from the line's `through` point, fixed on the guide (bushes).
    pub on_link: bool,
}

/// The reaction of a [`TwoPointGuide`] on its sliding link as two normal forces.
#[derive(Clone, Debug, PartialEq)]
pub struct GuideReaction {
    /// The slider joint.
    pub joint: usize,
    /// The bearing points (world).
    pub points: [Vec2; 2],
    /// The guide's unit normal `n` (world); the forces are `N_a n`, `N_b n`.
    pub normal: Vec2,
    /// `N_a`, `N_b` (N, along `n`, on the sliding link).
    pub forces: [f64; 2],
}

/// The guide line's direction (world) and the slider point `X` (world).
fn line(l: &Linkage, q: &DVector<f64>, g: &TwoPointGuide) -> Option<(Vec2, Vec2, Vec2)> {
    let PlanarJoint::Slider(s) = &l.joints.get(g.joint)? else {
        return None;
    };
    let (r0, theta) = if s.guide == GROUND {
        (Vec2::zeros(), 0.0)
    } else {
        let (rg, tg) = l.pose(q, s.guide);
        (rg - rotate(tg, &l.links[s.guide].com), tg)
    };
    let dir = rotate(theta, &s.dir);
    let through = r0 + rotate(theta, &s.through);
    Some((dir, through, l.point_position(q, s.link, &s.p)))
}

/// `N_a`, `N_b` of guide `g` from the kinetostatic solution `k` (frictionless statics).
pub fn split(
    l: &Linkage,
    q: &DVector<f64>,
    k: &Kinetostatics,
    g: &TwoPointGuide,
) -> Option<GuideReaction> {
    let (dir, through, x) = line(l, q, g)?;
    let r = k.joint_forces.iter().find(|f| f.joint == g.joint)?;
    let normal = perp(&dir);
    let n = r.force.dot(&normal);
    let c = r.couple;
    let origin = if g.on_link { x } else { through };
    let points = [origin + dir * g.at[0], origin + dir * g.at[1]];
    let (sa, sb) = ((points[0] - x).dot(&dir), (points[1] - x).dot(&dir));
    let forces = [(c - sb * n) / (sa - sb), (sa * n - c) / (sa - sb)];
    Some(GuideReaction {
        joint: g.joint,
        points,
        normal,
        forces,
    })
}

/// The smallest `F ≥ 0` with `F = f (|α_a + β_a F| + |α_b + β_b F|)`, or `None` when there
/// is none (the guide jams).
pub fn friction_force(f: f64, alpha: [f64; 2], beta: [f64; 2]) -> Option<f64> {
    let g = |x: f64| f * ((alpha[0] + beta[0] * x).abs() + (alpha[1] + beta[1] * x).abs()) - x;
    let mut cuts: Vec<f64> = (0..2)
        .filter(|&k| beta[k] != 0.0)
        .map(|k| -alpha[k] / beta[k])
        .filter(|x| *x > 0.0 && x.is_finite())
        .collect();
    cuts.sort_by(f64::total_cmp);
    let mut lo = 0.0;
    let mut g_lo = g(lo);
    if g_lo <= 0.0 {
        return Some(0.0);
    }
    for hi in cuts.into_iter().chain(std::iter::once(f64::INFINITY)) {
        // g is linear on [lo, hi]: its slope from a point inside.
        let probe = if hi.is_finite() {
            0.5 * (lo + hi)
        } else {
            lo + 1.0 + lo.abs()
        };
        let slope = (g(probe) - g_lo) / (probe - lo);
        if slope < 0.0 {
            let root = lo - g_lo / slope;
            if root <= hi {
                return Some(root);
            }
        }
        if !hi.is_finite() {
            return None;
        }
        lo = hi;
        g_lo = g(lo);
    }
    None
}

/// Kinetostatics with friction where guides bear at two points.
#[derive(Clone, Debug)]
pub struct GuideFriction {
    /// The result in the form of [`crate::machines::friction::friction_circle`] (with
    /// every joint's friction, the guides' included).
    pub with: WithFriction,
    /// Each guide's two normal forces with friction.
    pub reactions: Vec<GuideReaction>,
    /// Each guide's friction force magnitude (N).
    pub friction: Vec<f64>,
    /// Whether a guide jams (no finite friction force balances it; `with.real` is then
    /// the frictionless solution and the efficiency `None`).
    pub jammed: bool,
}

/// The unit friction direction (world) at guide `g` (against the sliding of the link on
/// the guide) and the sliding speed, or `None` when it does not slide.
fn against_sliding(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    g: &TwoPointGuide,
) -> Option<(Vec2, f64)> {
    let PlanarJoint::Slider(s) = &l.joints[g.joint] else {
        return None;
    };
    let (dir, _, x) = line(l, q, g)?;
    let v_link = l.point_velocity(q, qd, s.link, &s.p);
    let v_guide = if s.guide == GROUND {
        Vec2::zeros()
    } else {
        let (rg, _) = l.pose(q, s.guide);
        Vec2::new(qd[3 * s.guide], qd[3 * s.guide + 1]) + perp(&(x - rg)) * qd[3 * s.guide + 2]
    };
    let u = (v_link - v_guide).dot(&dir);
    (u != 0.0).then(|| (dir * -u.signum(), u.abs()))
}

/// The friction force `mag` of guide `g` along `u` as point forces (on the link at its
/// slider point, the opposite on a moving guide at the coincident point).
fn guide_forces(l: &Linkage, q: &DVector<f64>, g: &TwoPointGuide, u: Vec2, mag: f64) -> Loads {
    let PlanarJoint::Slider(s) = &l.joints[g.joint] else {
        return Loads::default();
    };
    let mut out = Loads::default();
    out.forces.push(PointForce {
        link: s.link,
        p: s.p,
        force: u * mag,
    });
    if s.guide != GROUND {
        let x = l.point_position(q, s.link, &s.p);
        let (rg, tg) = l.pose(q, s.guide);
        out.forces.push(PointForce {
            link: s.guide,
            p: rotate(-tg, &(x - rg)) + l.links[s.guide].com,
            force: -u * mag,
        });
    }
    out
}

fn plus(a: &Loads, b: &Loads) -> Loads {
    let mut c = a.clone();
    c.forces.extend(b.forces.iter().cloned());
    c.torques.extend(b.torques.iter().copied());
    c
}

/// Kinetostatics at the motion `(q, q̇, q̈)` under `loads` (driver rate `sd`) with the
/// friction `fr` of every joint, the joints of `guides` bearing at two points with the
/// friction `f (|N_a| + |N_b|)`; at most `max_iter` outer repetitions, stopping when the
/// driving effort changes by less than `tol` (relative).
#[allow(clippy::too_many_arguments)]
pub fn solve_with_guides(
    l: &Linkage,
    (q, qd, qdd): (&DVector<f64>, &DVector<f64>, &DVector<f64>),
    loads: &Loads,
    sd: f64,
    fr: &[JointFriction],
    guides: &[TwoPointGuide],
    tol: f64,
    max_iter: usize,
) -> GuideFriction {
    let ideal = solve(l, q, qdd, loads);
    let others: Vec<JointFriction> = fr
        .iter()
        .filter(|j| !guides.iter().any(|g| g.joint == j.joint))
        .copied()
        .collect();
    let coef = |g: &TwoPointGuide| {
        fr.iter()
            .find(|j| j.joint == g.joint)
            .map_or(0.0, |j| j.coefficient)
    };
    let dirs: Vec<Option<(Vec2, f64)>> = guides
        .iter()
        .map(|g| against_sliding(l, q, qd, g))
        .collect();
    let mut mags = vec![0.0; guides.len()];
    let (mut real, mut pins, mut pin_loss) = (ideal.clone(), Loads::default(), 0.0);
    let (mut iterations, mut converged, mut jammed) = (0, false, false);
    let guide_loads = |mags: &[f64], skip: usize| {
        let mut out = Loads::default();
        for (i, g) in guides.iter().enumerate() {
            if let (true, Some((u, _))) = (i != skip, dirs[i]) {
                out = plus(&out, &guide_forces(l, q, g, u, mags[i]));
            }
        }
        out
    };
    'outer: while iterations < max_iter {
        iterations += 1;
        (pins, pin_loss) = friction_loads(l, q, qd, &real, &others);
        for (i, g) in guides.iter().enumerate() {
            let Some((u, _)) = dirs[i] else { continue };
            let base = plus(&plus(loads, &pins), &guide_loads(&mags, i));
            let k0 = solve(l, q, qdd, &base);
            let k1 = solve(l, q, qdd, &plus(&base, &guide_forces(l, q, g, u, 1.0)));
            let (Some(r0), Some(r1)) = (split(l, q, &k0, g), split(l, q, &k1, g)) else {
                continue;
            };
            let beta = [r1.forces[0] - r0.forces[0], r1.forces[1] - r0.forces[1]];
            match friction_force(coef(g), r0.forces, beta) {
                Some(f) => mags[i] = f,
                None => {
                    jammed = true;
                    break 'outer;
                }
            }
        }
        let next = solve(
            l,
            q,
            qdd,
            &plus(&plus(loads, &pins), &guide_loads(&mags, usize::MAX)),
        );
        let change = (next.driving - real.driving).abs();
        let scale = ideal.driving.abs().max(next.driving.abs()).max(1e-300);
        real = next;
        if change <= tol * scale && iterations > 1 {
            converged = true;
            break;
        }
    }
    if jammed {
        real = ideal.clone();
    }
    let loss = pin_loss
        + dirs
            .iter()
            .zip(&mags)
            .map(|(d, m)| d.map_or(0.0, |(_, u)| u * m))
            .sum::<f64>();
    let reactions = guides
        .iter()
        .filter_map(|g| split(l, q, &real, g))
        .collect();
    let friction_loads = plus(&pins, &guide_loads(&mags, usize::MAX));
    let driving_power = real.driving * sd;
    GuideFriction {
        with: WithFriction {
            efficiency: (!jammed && driving_power > 0.0).then(|| 1.0 - loss / driving_power),
            ideal,
            real,
            friction_loads,
            friction_power: loss,
            driving_power,
            iterations,
            converged: converged && !jammed,
        },
        reactions,
        friction: mags,
        jammed,
    }
}
