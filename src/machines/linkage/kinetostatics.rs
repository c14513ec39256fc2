//! Kinetostatics: the joint forces and the driving effort (balancing torque or force)
//! that make the linkage follow a known motion, from the constrained equations of motion
//! with Lagrange multipliers (Haug 1989, §6.3, eq. 6.3.18, inverse dynamics §6.6;
//! Nikravesh 1988, §6.5):
//!
//! ```text
//! M q̈ − Φ_qᵀ λ = Q      ⇒      Φ_qᵀ λ = M q̈ − Q,
//! ```
//!
//! with `M = diag(m_i, m_i, J_i)` in centroidal coordinates (no velocity terms), `Q` the
//! applied forces (gravity `m_i g`, point forces `F` with moment `(A s) × F`, torques),
//! and `q̈` from the kinematics. `−M q̈` is d'Alembert's inertia force system; the
//! equation is its equilibrium with the loads and the constraint reactions. Because
//! each constraint's generalised force is `Φ_qᵀ λ` and the sign is `−`:
//! - a pin `Φ = r_Pa − r_Pb` gives the force `λ` on link `a` at `P` (and `−λ` on `b`);
//! - a point-on-line row gives the force `λ n` (`n` the line normal) on the sliding link
//!   at the point, and `−λ n` on the guide; a prismatic angle row a couple `λ`;
//! - a higher pair (cam contact) gives the force `λ ν` on `a` along the common normal
//!   through the contact point (`λ > 0` presses the profiles together);
//! - the angle driver `θ_l − θ_ref − s` gives the driving torque `λ` on the driven link
//!   (the balancing torque), the slide driver the driving force `λ` along its line.
//!
//! For a proper linkage (`Φ_q` square and regular) the solution is unique. With
//! redundant constraints the forces are statically indeterminate: the minimum-norm `λ`
//! is returned and `rank` says so. The shaking force and moment are what the linkage
//! exerts on the frame (the negatives of the ground reactions, the driver's reaction
//! couple included).

use crate::core::least_squares::min_norm_solve;
use crate::machines::linkage::constraints::{jacobian_mat, row_owners, RowOwner};
use crate::machines::linkage::description::{Driver, Linkage, PlanarJoint, GROUND};
use crate::machines::linkage::higher_pair::HigherPair;
use crate::machines::linkage::{cross, rotate, Vec2};
use nalgebra::DVector;

/// A force at a point of a link.
#[derive(Clone, Debug, PartialEq)]
pub struct PointForce {
    /// The link.
    pub link: usize,
    /// The point, in the link frame.
    pub p: Vec2,
    /// The force (world).
    pub force: Vec2,
}

/// Applied loads.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Loads {
    /// Gravity acceleration (world), e.g. `(0, −9.81)`.
    pub gravity: Vec2,
    /// Point forces.
    pub forces: Vec<PointForce>,
    /// Torques `(link, torque)`, counter-clockwise positive.
    pub torques: Vec<(usize, f64)>,
}

/// The diagonal of `M`.
pub fn mass_diagonal(l: &Linkage) -> DVector<f64> {
    let mut m = DVector::zeros(l.ncoords());
    for (i, k) in l.links.iter().enumerate() {
        m[3 * i] = k.mass;
        m[3 * i + 1] = k.mass;
        m[3 * i + 2] = k.inertia;
    }
    m
}

/// The applied generalised forces `Q` at `q`.
pub fn applied_forces(l: &Linkage, q: &DVector<f64>, loads: &Loads) -> DVector<f64> {
    let mut f = DVector::zeros(l.ncoords());
    for (i, k) in l.links.iter().enumerate() {
        f[3 * i] += k.mass * loads.gravity.x;
        f[3 * i + 1] += k.mass * loads.gravity.y;
    }
    for pf in &loads.forces {
        let arm = rotate(q[3 * pf.link + 2], &l.offset(pf.link, &pf.p));
        f[3 * pf.link] += pf.force.x;
        f[3 * pf.link + 1] += pf.force.y;
        f[3 * pf.link + 2] += cross(&arm, &pf.force);
    }
    for &(k, t) in &loads.torques {
        f[3 * k + 2] += t;
    }
    f
}

/// The reaction of one joint.
#[derive(Clone, Debug, PartialEq)]
pub struct JointForce {
    /// PlanarJoint index in [`Linkage::joints`].
    pub joint: usize,
    /// PlanarJoint name.
    pub name: String,
    /// The link the force acts on (a moving link).
    pub on: usize,
    /// The body exerting it ([`GROUND`] for the frame).
    pub by: usize,
    /// Force on `on` (world), at the joint point.
    pub force: Vec2,
    /// Couple on `on` (prismatic joints), counter-clockwise positive.
    pub couple: f64,
}

/// The result of [`solve`].
#[derive(Clone, Debug)]
pub struct Kinetostatics {
    /// Lagrange multipliers, one per row of `Φ`.
    pub lambda: DVector<f64>,
    /// Driving torque (angle driver, N m) or force (slide driver, N): the driver's `λ`.
    pub driving: f64,
    /// PlanarJoint reactions, in joint order.
    pub joint_forces: Vec<JointForce>,
    /// d'Alembert inertia force `−m a_G` and couple `−J α` of each link.
    pub inertia: Vec<(Vec2, f64)>,
    /// Force the linkage exerts on the frame.
    pub shaking_force: Vec2,
    /// Moment about the world origin the linkage exerts on the frame (the driver's
    /// reaction included).
    pub shaking_moment: f64,
    /// Rank of `Φ_q` (less than the rows: statically indeterminate).
    pub rank: usize,
    /// `‖Φ_qᵀ λ − (M q̈ − Q)‖∞`.
    pub residual: f64,
}

/// The force of joint `k` from its multiplier rows starting at `r` (one on each body
/// pair), adding its share to the shaking force and moment `shaking` when it holds a link
/// to the ground; returns it and the number of rows it owns.
fn joint_force(
    l: &Linkage,
    q: &DVector<f64>,
    k: usize,
    lambda: &DVector<f64>,
    r: usize,
    shaking: &mut (Vec2, f64),
) -> (JointForce, usize) {
    let j = &l.joints[k];
    match j {
        PlanarJoint::Revolute { name, a, pa, b, .. } => {
            let f_on_a = Vec2::new(lambda[r], lambda[r + 1]);
            let (on, by, f) = if *a == GROUND {
                (*b, *a, -f_on_a)
            } else {
                (*a, *b, f_on_a)
            };
            if by == GROUND {
                let at = l.point_position(q, *a, pa);
                shaking.0 -= f;
                shaking.1 -= cross(&at, &f);
            }
            let jf = JointForce {
                joint: k,
                name: name.clone(),
                on,
                by,
                force: f,
                couple: 0.0,
            };
            (jf, 2)
        }
        PlanarJoint::Slider(s) => {
            let theta_g = if s.guide == GROUND {
                0.0
            } else {
                q[3 * s.guide + 2]
            };
            let n = rotate(theta_g, &crate::machines::linkage::perp(&s.dir));
            let f = n * lambda[r];
            let couple = if s.prismatic.is_some() {
                lambda[r + 1]
            } else {
                0.0
            };
            if s.guide == GROUND {
                let at = l.point_position(q, s.link, &s.p);
                shaking.0 -= f;
                shaking.1 -= cross(&at, &f) + couple;
            }
            let jf = JointForce {
                joint: k,
                name: s.name.clone(),
                on: s.link,
                by: s.guide,
                force: f,
                couple,
            };
            (jf, 1 + usize::from(s.prismatic.is_some()))
        }
        PlanarJoint::Contact(c) => (contact_force(l, q, k, c, lambda[r], shaking), 1),
    }
}

/// A higher pair's force `λ ν` on `a` along the common normal, through the contact point
/// (the generalised force `Φ_qᵀ λ` acts at `a`'s centre on the same line of action).
fn contact_force(
    l: &Linkage,
    q: &DVector<f64>,
    k: usize,
    c: &HigherPair,
    lambda: f64,
    shaking: &mut (Vec2, f64),
) -> JointForce {
    let g = crate::machines::linkage::contact_rows::geometry(l, q, c);
    let f_on_a = g.normal * lambda;
    let (on, by, f) = if c.a == GROUND {
        (c.b, c.a, -f_on_a)
    } else {
        (c.a, c.b, f_on_a)
    };
    if by == GROUND {
        shaking.0 -= f;
        shaking.1 -= cross(&g.point, &f);
    }
    JointForce {
        joint: k,
        name: c.name.clone(),
        on,
        by,
        force: f,
        couple: 0.0,
    }
}

/// PlanarJoint forces and driving effort for the motion `(q, q̇, q̈)` under `loads`.
pub fn solve(l: &Linkage, q: &DVector<f64>, qdd: &DVector<f64>, loads: &Loads) -> Kinetostatics {
    let m = mass_diagonal(l);
    let rhs = m.component_mul(qdd) - applied_forces(l, q, loads);
    let jt = jacobian_mat(l, q).transpose();
    let sol = min_norm_solve(&jt, &rhs, None);
    let lambda = sol.x;
    let mut joint_forces = Vec::with_capacity(l.joints.len());
    // Shaking force and moment on the ground.
    let mut shaking = (Vec2::zeros(), 0.0);
    let owners = row_owners(l);
    let mut r = 0;
    let mut driving = 0.0;
    while r < owners.len() {
        match &owners[r] {
            RowOwner::Joint(k, _) => {
                let (jf, rows) = joint_force(l, q, *k, &lambda, r, &mut shaking);
                joint_forces.push(jf);
                r += rows;
            }
            RowOwner::Driver => {
                driving = lambda[r];
                match &l.driver {
                    Driver::Angle { relative_to, .. } => {
                        if *relative_to == GROUND {
                            shaking.1 -= driving;
                        }
                    }
                    Driver::Slide { link, p, dir, .. } => {
                        let f = dir * driving;
                        let at = l.point_position(q, *link, p);
                        shaking.0 -= f;
                        shaking.1 -= cross(&at, &f);
                    }
                }
                r += 1;
            }
        }
    }
    let inertia = l
        .links
        .iter()
        .enumerate()
        .map(|(i, k)| {
            (
                -Vec2::new(qdd[3 * i], qdd[3 * i + 1]) * k.mass,
                -qdd[3 * i + 2] * k.inertia,
            )
        })
        .collect();
    Kinetostatics {
        lambda,
        driving,
        joint_forces,
        inertia,
        shaking_force: shaking.0,
        shaking_moment: shaking.1,
        rank: sol.rank,
        residual: sol.residual,
    }
}
