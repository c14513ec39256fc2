//! Friction in a linkage's joints by friction circles (docs/reference_data.md §M4 "beyond the
//! book": the efficiency of a mechanism over its cycle), iterated because the reactions
//! depend on the friction they cause.
//!
//! A pin of radius `r` with coefficient `f` carries its reaction `R` tangent to the
//! friction circle of radius `ρ = f r` instead of through the centre: the same force
//! through the centre plus the couple `ρ |R|` that opposes the relative rotation of the
//! two bodies. A slider's normal force `N` brings the force `f |N|` along the guide,
//! against the relative sliding velocity (the couple of a prismatic joint's edge
//! pressures is left out). A cam contact's normal force `N` brings `f |N|` along the
//! common tangent at the contact point, against the sliding velocity. These friction loads are added to the applied loads and
//! [`crate::machines::linkage::kinetostatics::solve`] is repeated with the reactions it returns
//! until the driving effort settles (the directions of relative motion come from the kinematics
//! and do not change; the magnitudes form a contraction for small friction).
//!
//! Instantaneous efficiency `η = 1 − N_f/N_d`: `N_f` the power the friction loads take
//! out, `N_d` the driver's power. Because the ideal constraints do no work, the driver's
//! power with friction exceeds the frictionless one by exactly `N_f` (checked through
//! [`crate::machines::linkage::virtual_power`]).

use crate::machines::linkage::contact_rows;
use crate::machines::linkage::description::{Linkage, PlanarJoint, GROUND};
use crate::machines::linkage::higher_pair::HigherPair;
use crate::machines::linkage::kinetostatics::{solve, Kinetostatics, Loads, PointForce};
use crate::machines::linkage::{perp, rotate, Vec2};
use nalgebra::DVector;

/// Friction of one joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointFriction {
    /// Index in [`Linkage::joints`].
    pub joint: usize,
    /// Coefficient `f` (pin: with the journal fit factor already applied).
    pub coefficient: f64,
    /// Pin radius (m; unused for sliders).
    pub pin_radius: f64,
}

/// The state with friction.
#[derive(Clone, Debug)]
pub struct WithFriction {
    /// Kinetostatics without friction.
    pub ideal: Kinetostatics,
    /// Kinetostatics with the converged friction loads.
    pub real: Kinetostatics,
    /// The friction loads of the last iteration (couples and forces only).
    pub friction_loads: Loads,
    /// Power the friction takes out (W, ≥ 0).
    pub friction_power: f64,
    /// Driver power with friction (W).
    pub driving_power: f64,
    /// `1 − N_f/N_d` when the driver does work (`N_d > 0`), else `None`.
    pub efficiency: Option<f64>,
    /// Iterations used.
    pub iterations: usize,
    /// The driving effort settled within the tolerance.
    pub converged: bool,
}

/// Relative angular velocity of bodies `a` and `b`.
fn omega_rel(qd: &DVector<f64>, a: usize, b: usize) -> f64 {
    let w = |k: usize| if k == GROUND { 0.0 } else { qd[3 * k + 2] };
    w(a) - w(b)
}

/// The friction loads for the reactions of `k` (and the friction power they take out).
pub(crate) fn friction_loads(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    k: &Kinetostatics,
    fr: &[JointFriction],
) -> (Loads, f64) {
    let mut out = Loads::default();
    let mut loss = 0.0;
    for jf in fr {
        let Some(r) = k.joint_forces.iter().find(|r| r.joint == jf.joint) else {
            continue;
        };
        match &l.joints[jf.joint] {
            PlanarJoint::Revolute { a, b, .. } => {
                let w = omega_rel(qd, *a, *b);
                let m = jf.coefficient * jf.pin_radius * r.force.norm();
                // Couple −sgn(w) m on a, +sgn(w) m on b.
                let c = -w.signum() * m;
                if w == 0.0 || m == 0.0 {
                    continue;
                }
                if *a != GROUND {
                    out.torques.push((*a, c));
                }
                if *b != GROUND {
                    out.torques.push((*b, -c));
                }
                loss += m * w.abs();
            }
            PlanarJoint::Slider(s) => {
                let x = l.point_position(q, s.link, &s.p);
                let theta_g = if s.guide == GROUND {
                    0.0
                } else {
                    q[3 * s.guide + 2]
                };
                let dir = rotate(theta_g, &s.dir);
                let v_link = l.point_velocity(q, qd, s.link, &s.p);
                let v_guide = if s.guide == GROUND {
                    Vec2::zeros()
                } else {
                    let (rg, _) = l.pose(q, s.guide);
                    Vec2::new(qd[3 * s.guide], qd[3 * s.guide + 1])
                        + perp(&(x - rg)) * qd[3 * s.guide + 2]
                };
                let u = (v_link - v_guide).dot(&dir);
                let f = jf.coefficient * r.force.norm();
                if u == 0.0 || f == 0.0 {
                    continue;
                }
                let force = dir * (-u.signum() * f);
                out.forces.push(PointForce {
                    link: s.link,
                    p: s.p,
                    force,
                });
                if s.guide != GROUND {
                    // The coincident point of the guide, in the guide's frame.
                    let (rg, tg) = l.pose(q, s.guide);
                    let local = rotate(-tg, &(x - rg)) + l.links[s.guide].com;
                    out.forces.push(PointForce {
                        link: s.guide,
                        p: local,
                        force: -force,
                    });
                }
                loss += f * u.abs();
            }
            PlanarJoint::Contact(c) => {
                loss += contact_friction(l, q, qd, c, jf.coefficient * r.force.norm(), &mut out);
            }
        }
    }
    (out, loss)
}

/// A cam contact's friction: `f |N|` along the common tangent at the contact point,
/// against the sliding of `a` on `b` (the total contact force leans by the friction
/// angle `atan f` from the normal), into `out`; returns its power loss `f |N| |u|`.
fn contact_friction(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    c: &HigherPair,
    f: f64,
    out: &mut Loads,
) -> f64 {
    let u = contact_rows::sliding_velocity(l, q, qd, c);
    if u == 0.0 || f == 0.0 {
        return 0.0;
    }
    let g = contact_rows::geometry(l, q, c);
    let force = perp(&g.normal) * (-u.signum() * f);
    for (b, sign) in [(c.a, 1.0), (c.b, -1.0)] {
        if b != GROUND {
            out.forces.push(PointForce {
                link: b,
                p: contact_rows::to_body_frame(l, q, b, &g.point),
                force: force * sign,
            });
        }
    }
    f * u.abs()
}

/// Kinetostatics with joint friction at the motion `(q, q̇, q̈)` under `loads`, the
/// driver's rate being `sd`; at most `max_iter` repetitions, stopping when the driving
/// effort changes by less than `tol` (relative).
#[allow(clippy::too_many_arguments)]
pub fn solve_with_friction(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    qdd: &DVector<f64>,
    loads: &Loads,
    sd: f64,
    fr: &[JointFriction],
    tol: f64,
    max_iter: usize,
) -> WithFriction {
    let ideal = solve(l, q, qdd, loads);
    let mut real = ideal.clone();
    let mut fl = Loads::default();
    let mut loss = 0.0;
    let (mut iterations, mut converged) = (0, false);
    let mut all = loads.clone();
    while iterations < max_iter {
        iterations += 1;
        let (f, p) = friction_loads(l, q, qd, &real, fr);
        all.forces.truncate(loads.forces.len());
        all.torques.truncate(loads.torques.len());
        all.forces.extend(f.forces.iter().cloned());
        all.torques.extend(f.torques.iter().copied());
        let next = solve(l, q, qdd, &all);
        let change = (next.driving - real.driving).abs();
        let scale = ideal.driving.abs().max(next.driving.abs()).max(1e-300);
        (real, fl, loss) = (next, f, p);
        if change <= tol * scale && iterations > 1 {
            converged = true;
            break;
        }
    }
    // `real` balances the applied loads plus `fl`, whose power loss is `loss`.
    let driving_power = real.driving * sd;
    WithFriction {
        efficiency: (driving_power > 0.0).then(|| 1.0 - loss / driving_power),
        ideal,
        real,
        friction_loads: fl,
        friction_power: loss,
        driving_power,
        iterations,
        converged,
    }
}
