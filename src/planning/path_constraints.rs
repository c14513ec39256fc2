//! Path constraints on a tool: what they are ([`PathConstraint`]), their values at a
//! configuration, and the certificate that a straight joint-space edge satisfies them at
//! **every** point, not only at its ends.
//!
//! Each constraint is one to three scalar functions `h(q) ≤ 0`:
//! - [`ConstraintKind::Axis`]: `h = ∠(R(q) a, d) − tol`, a tool axis `a` (link frame)
//!   within `tol` of a world direction `d` (a cup kept upright);
//! - [`ConstraintKind::Orientation`]: `h = ∠(R(q) R*ᵀ) − tol`, the geodesic distance to a
//!   full orientation;
//! - [`ConstraintKind::Position`]: a point of the link inside a box (`|lᵢ| − hᵢ`, three
//!   functions, `l` the point in the box's frame), a sphere (`|p − c| − r`) or a cylinder
//!   (radial `ρ − r` and axial `|l_z| − h`).
//!
//! **The edge certificate.** Every function is 1-Lipschitz in the tool's rotation angle
//! (rad) or in its point's displacement (m). Along an edge `a → b`, the tool turns by at
//! most `Lr = Σ wᵣ,ₖ |bₖ − aₖ|` (`wᵣ,ₖ` the sum of `|multiplier|` of the revolute joints
//! coordinate `k` drives on the link's chain) and the point moves by at most
//! `Lp = Σ wₚ,ₖ |bₖ − aₖ|` (`wₚ,ₖ` adds each revolute joint's distance bound from its axis
//! to the point, [`ConstraintSet::new`], and 1 per prismatic joint). At the fraction `t`
//! of the edge `h ≤ min(h(a) + t L, h(b) + (1 − t) L)`, whose largest value over `t` is
//! `(h(a) + h(b) + L) / 2`: an edge with `(h(a) + h(b) + L) / 2 ≤ 0` for every function
//! satisfies the constraints everywhere along it ([`ConstraintSet::edge_certified`]).
//!
//! Nothing here allocates after [`ConstraintSet::new`].

use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::kinematics::ik::rotation_log;
use crate::kinematics::{compute_frame_jacobian, frame_placement, Expressed};
use crate::model::data::Data;
use crate::model::Model;
use crate::model::{BodyKind, WORLD};

/// The region a point of the tool must stay in (in its `pose`'s frame).
#[derive(Clone, Debug, PartialEq)]
pub enum RegionShape {
    /// A box of these half-extents along the frame's axes.
    Box {
        /// Half-extents (m).
        half: [f64; 3],
    },
    /// A ball centred on the frame's origin.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A cylinder along the frame's `z` axis, centred on its origin.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Half of the length (m).
        half_length: f64,
    },
}

/// What a [`PathConstraint`] asks of its link.
#[derive(Clone, Debug, PartialEq)]
pub enum ConstraintKind {
    /// The link's unit `axis` (its own frame) stays within `tolerance` (rad) of the world
    /// unit `direction`.
    Axis {
        /// Axis in the link frame (unit).
        axis: Vec3,
        /// World direction (unit).
        direction: Vec3,
        /// Largest angle (rad), in (0, π).
        tolerance: f64,
    },
    /// The link's orientation stays within the geodesic angle `tolerance` of `rotation`.
    Orientation {
        /// The orientation aimed at (world).
        rotation: Mat3,
        /// Largest angle (rad), in (0, π).
        tolerance: f64,
    },
    /// The point `offset` (link frame) stays inside `shape` placed at `pose` (world).
    Position {
        /// The point on the link.
        offset: Vec3,
        /// The region's frame in the world.
        pose: Se3,
        /// The region.
        shape: RegionShape,
    },
}

/// One constraint on one link of the model, along the whole path.
#[derive(Clone, Debug, PartialEq)]
pub struct PathConstraint {
    /// The constrained link (index into [`Model::links`]).
    pub link: usize,
    /// What is asked.
    pub kind: ConstraintKind,
}

/// Most scalar functions of all constraints together.
pub const MAX_FUNCTIONS: usize = 12;

impl PathConstraint {
    /// How many scalar functions `h ≤ 0` it is.
    pub fn functions(&self) -> usize {
        match &self.kind {
            ConstraintKind::Axis { .. } | ConstraintKind::Orientation { .. } => 1,
            ConstraintKind::Position { shape, .. } => match shape {
                RegionShape::Box { .. } => 3,
                RegionShape::Sphere { .. } => 1,
                RegionShape::Cylinder { .. } => 2,
            },
        }
    }

    /// Whether its functions are angles (rad) rather than distances (m).
    fn rotational(&self) -> bool {
        !matches!(self.kind, ConstraintKind::Position { .. })
    }

    /// The interior margin projections aim at: a quarter of the tolerance (or of the
    /// region's smallest half-size), at most 0.05 rad or 0.02 m.
    fn margin(&self) -> f64 {
        match &self.kind {
            ConstraintKind::Axis { tolerance, .. }
            | ConstraintKind::Orientation { tolerance, .. } => (0.25 * tolerance).min(0.05),
            ConstraintKind::Position { shape, .. } => {
                let small = match shape {
                    RegionShape::Box { half } => half[0].min(half[1]).min(half[2]),
                    RegionShape::Sphere { radius } => *radius,
                    RegionShape::Cylinder {
                        radius,
                        half_length,
                    } => radius.min(*half_length),
                };
                (0.25 * small).min(0.02)
            }
        }
    }

    /// Why it cannot be used, if it cannot (bad link, non-finite or out-of-range values).
    pub fn problem(&self, model: &Model) -> Option<String> {
        if self.link >= model.links.len() {
            return Some(format!("link index {} is not in the model", self.link));
        }
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let tol_ok = |t: f64| t > 0.0 && t < std::f64::consts::PI;
        match &self.kind {
            ConstraintKind::Axis {
                axis,
                direction,
                tolerance,
            } => {
                if !finite(axis.as_slice()) || !finite(direction.as_slice()) {
                    return Some("the axis and direction must be finite".into());
                }
                if (axis.norm() - 1.0).abs() > 1e-9 || (direction.norm() - 1.0).abs() > 1e-9 {
                    return Some("the axis and direction must be unit vectors".into());
                }
                (!tol_ok(*tolerance)).then(|| format!("tolerance {tolerance} rad is not in (0, π)"))
            }
            ConstraintKind::Orientation {
                rotation,
                tolerance,
            } => {
                let ortho = (rotation.transpose() * rotation - Mat3::identity()).norm() < 1e-9
                    && rotation.determinant() > 0.0;
                if !finite(rotation.as_slice()) || !ortho {
                    return Some("the orientation is not a rotation".into());
                }
                (!tol_ok(*tolerance)).then(|| format!("tolerance {tolerance} rad is not in (0, π)"))
            }
            ConstraintKind::Position {
                offset,
                pose,
                shape,
            } => {
                let sizes: Vec<f64> = match shape {
                    RegionShape::Box { half } => half.to_vec(),
                    RegionShape::Sphere { radius } => vec![*radius],
                    RegionShape::Cylinder {
                        radius,
                        half_length,
                    } => vec![*radius, *half_length],
                };
                let all = offset
                    .iter()
                    .chain(pose.trans.iter())
                    .chain(pose.rot.iter());
                if !all.copied().all(f64::is_finite) {
                    return Some("the offset and the region's pose must be finite".into());
                }
                sizes
                    .iter()
                    .any(|s| !(s.is_finite() && *s > 0.0))
                    .then(|| format!("the region's sizes {sizes:?} must be positive and finite"))
            }
        }
    }
}

/// The constraints of a query with their buffers and Lipschitz weights.
#[derive(Clone, Debug)]
pub struct ConstraintSet {
    /// The constraints.
    pub constraints: Vec<PathConstraint>,
    /// Per scalar function: its constraint.
    owner: Vec<usize>,
    /// Per scalar function, per coordinate: the Lipschitz weight.
    weights: Vec<f64>,
    /// Per scalar function: the interior margin.
    margins: Vec<f64>,
    nv: usize,
    data: Data,
    jac: Vec<f64>,
}

/// Bounds on how fast a link point moves and turns per unit of each coordinate.
fn lipschitz(model: &Model, link: usize, offset: &Vec3) -> Result<(Vec<f64>, Vec<f64>), String> {
    let nv = model.nv;
    let (mut rot, mut pos) = (vec![0.0; nv], vec![0.0; nv]);
    let l = &model.links[link];
    // Distance bound from the current body's origin to the point, grown up the chain.
    let mut reach = l.offset.trans.norm() + offset.norm();
    let mut b = l.body;
    while b != WORLD {
        let k = model.q_index[b];
        let m = model.q_mult[b].abs();
        match model.kind[b] {
            BodyKind::RevoluteX | BodyKind::RevoluteY | BodyKind::RevoluteZ => {
                rot[k] += m;
                pos[k] += m * reach;
            }
            BodyKind::PrismaticX | BodyKind::PrismaticY | BodyKind::PrismaticZ => {
                pos[k] += m;
                let travel =
                    model.lower[k].abs().max(model.upper[k].abs()) * m + model.q_offset[b].abs();
                if !travel.is_finite() {
                    return Err(format!(
                        "prismatic joint '{}' has no finite limits: the tool's motion along an edge cannot be bounded",
                        model.dof_joint(k).name
                    ));
                }
                reach += travel;
            }
        }
        reach += model.placement[b].trans.norm();
        b = model.parent[b];
    }
    Ok((rot, pos))
}

/// `v × w` of a Jacobian column's angular part with `r`: the point's linear column.
#[inline]
fn point_column(jac: &[f64], nv: usize, k: usize, r: &Vec3) -> (Vec3, Vec3) {
    let v = Vec3::new(jac[k], jac[nv + k], jac[2 * nv + k]);
    let w = Vec3::new(jac[3 * nv + k], jac[4 * nv + k], jac[5 * nv + k]);
    (v + w.cross(r), w)
}

impl ConstraintSet {
    /// The set for `model`, or why a constraint cannot be used (named by its index).
    pub fn new(model: &Model, constraints: &[PathConstraint]) -> Result<ConstraintSet, String> {
        let nv = model.nv;
        let (mut owner, mut weights, mut margins) = (Vec::new(), Vec::new(), Vec::new());
        for (i, c) in constraints.iter().enumerate() {
            if let Some(p) = c.problem(model) {
                return Err(format!("path constraint {i}: {p}"));
            }
            let zero = Vec3::zeros();
            let offset = match &c.kind {
                ConstraintKind::Position { offset, .. } => offset,
                _ => &zero,
            };
            let (rot, pos) = lipschitz(model, c.link, offset)
                .map_err(|e| format!("path constraint {i}: {e}"))?;
            for _ in 0..c.functions() {
                owner.push(i);
                weights.extend_from_slice(if c.rotational() { &rot } else { &pos });
                margins.push(c.margin());
            }
        }
        if owner.len() > MAX_FUNCTIONS {
            return Err(format!(
                "{} path constraints are too many (at most {MAX_FUNCTIONS} scalar conditions)",
                constraints.len()
            ));
        }
        Ok(ConstraintSet {
            constraints: constraints.to_vec(),
            owner,
            weights,
            margins,
            nv,
            data: Data::new(model),
            jac: vec![0.0; 6 * nv],
        })
    }

    /// Number of scalar functions.
    pub fn len(&self) -> usize {
        self.owner.len()
    }

    /// Whether there are no constraints.
    pub fn is_empty(&self) -> bool {
        self.owner.is_empty()
    }

    /// The interior margin of function `j`.
    pub fn margin(&self, j: usize) -> f64 {
        self.margins[j]
    }

    /// The values `h(q)` into `h` and, when `grad` is given, their gradients (row `j` at
    /// `grad[j * nv..]`). Returns the number of functions.
    pub fn eval(
        &mut self,
        model: &Model,
        q: &[f64],
        h: &mut [f64],
        mut grad: Option<&mut [f64]>,
    ) -> usize {
        let nv = self.nv;
        let mut j = 0;
        for c in &self.constraints {
            compute_frame_jacobian(
                model,
                &mut self.data,
                q,
                c.link,
                Expressed::WorldAligned,
                &mut self.jac,
            );
            let t = frame_placement(model, &self.data, c.link);
            let n = c.functions();
            let g = grad.as_deref_mut().map(|g| &mut g[j * nv..(j + n) * nv]);
            eval_one(c, &t, &self.jac, nv, &mut h[j..j + n], g);
            j += n;
        }
        j
    }

    /// Whether the straight edge between configurations with values `ha` and `hb` is
    /// certified: `(h(a) + h(b) + L) / 2 ≤ 0` for every function (module docs). A slack of
    /// 1e-9 covers the rounding of the values.
    pub fn edge_certified(&self, ha: &[f64], hb: &[f64], a: &[f32], b: &[f32]) -> bool {
        let nv = self.nv;
        (0..self.len()).all(|j| {
            let w = &self.weights[j * nv..(j + 1) * nv];
            let l: f64 = (0..nv)
                .map(|k| w[k] * ((b[k] as f64) - (a[k] as f64)).abs())
                .sum();
            0.5 * (ha[j] + hb[j] + l) + 1e-9 <= 0.0
        })
    }

    /// The largest `Σ w |Δ|` over the functions for a step `a → b`.
    pub fn step_bound(&self, j: usize, a: &[f32], b: &[f32]) -> f64 {
        let w = &self.weights[j * self.nv..(j + 1) * self.nv];
        (0..self.nv)
            .map(|k| w[k] * ((b[k] - a[k]) as f64).abs())
            .sum()
    }

    /// The longest joint-space step (L2) whose bound `L` stays below every function's
    /// margin: `min_j m_j / ‖w_j‖`.
    pub fn nominal_step(&self) -> f64 {
        let nv = self.nv;
        (0..self.len())
            .map(|j| {
                let w = &self.weights[j * nv..(j + 1) * nv];
                let n = w.iter().map(|x| x * x).sum::<f64>().sqrt();
                if n > 0.0 {
                    self.margins[j] / n
                } else {
                    f64::INFINITY
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Which constraint `q` violates, with by how much, if any (for messages).
    pub fn violation(&mut self, model: &Model, q: &[f64]) -> Option<String> {
        let mut h = [0.0; MAX_FUNCTIONS];
        let n = self.eval(model, q, &mut h, None);
        let j = (0..n).find(|&j| h[j] > 0.0)?;
        let c = &self.constraints[self.owner[j]];
        let name = &model.links[c.link].name;
        Some(match &c.kind {
            ConstraintKind::Axis { tolerance, .. } => format!(
                "the axis of '{name}' is {:.4} rad from its direction (tolerance {tolerance})",
                h[j] + tolerance
            ),
            ConstraintKind::Orientation { tolerance, .. } => format!(
                "'{name}' is turned {:.4} rad from its orientation (tolerance {tolerance})",
                h[j] + tolerance
            ),
            ConstraintKind::Position { .. } => format!(
                "the point of '{name}' is {:.4} mm outside its region",
                h[j] * 1e3
            ),
        })
    }
}

/// The functions (and gradients) of one constraint at the link pose `t` with the
/// world-aligned Jacobian `jac` (row-major 6 × nv: linear rows, then angular).
fn eval_one(
    c: &PathConstraint,
    t: &Se3,
    jac: &[f64],
    nv: usize,
    h: &mut [f64],
    grad: Option<&mut [f64]>,
) {
    match &c.kind {
        ConstraintKind::Axis {
            axis,
            direction,
            tolerance,
        } => {
            let u = t.rot * axis;
            let cr = u.cross(direction);
            let (s, co) = (cr.norm(), u.dot(direction));
            h[0] = s.atan2(co) - tolerance;
            if let Some(g) = grad {
                // dθ = −ω · (u × d) / |u × d|.
                let n = if s > 1e-12 { cr / s } else { Vec3::zeros() };
                for k in 0..nv {
                    let w = Vec3::new(jac[3 * nv + k], jac[4 * nv + k], jac[5 * nv + k]);
                    g[k] = -w.dot(&n);
                }
            }
        }
        ConstraintKind::Orientation {
            rotation,
            tolerance,
        } => {
            let phi = rotation_log(&(t.rot * rotation.transpose()));
            let th = phi.norm();
            h[0] = th - tolerance;
            if let Some(g) = grad {
                // d|φ| = ω · φ̂ (the error R R*ᵀ turns by ω on the left).
                let n = if th > 1e-12 { phi / th } else { Vec3::zeros() };
                for k in 0..nv {
                    let w = Vec3::new(jac[3 * nv + k], jac[4 * nv + k], jac[5 * nv + k]);
                    g[k] = w.dot(&n);
                }
            }
        }
        ConstraintKind::Position {
            offset,
            pose,
            shape,
        } => {
            let r = t.rot * offset;
            let p = t.trans + r;
            let l = pose.rot.transpose() * (p - pose.trans);
            // Per function: its value and its world gradient direction in p.
            let mut dirs = [Vec3::zeros(); 3];
            match shape {
                RegionShape::Box { half } => {
                    for i in 0..3 {
                        h[i] = l[i].abs() - half[i];
                        let e = pose.rot.column(i).into_owned();
                        dirs[i] = if l[i] >= 0.0 { e } else { -e };
                    }
                }
                RegionShape::Sphere { radius } => {
                    let d = p - pose.trans;
                    let n = d.norm();
                    h[0] = n - radius;
                    dirs[0] = if n > 1e-12 { d / n } else { Vec3::zeros() };
                }
                RegionShape::Cylinder {
                    radius,
                    half_length,
                } => {
                    let rho = (l.x * l.x + l.y * l.y).sqrt();
                    h[0] = rho - radius;
                    dirs[0] = if rho > 1e-12 {
                        pose.rot * Vec3::new(l.x / rho, l.y / rho, 0.0)
                    } else {
                        Vec3::zeros()
                    };
                    h[1] = l.z.abs() - half_length;
                    let e = pose.rot.column(2).into_owned();
                    dirs[1] = if l.z >= 0.0 { e } else { -e };
                }
            }
            if let Some(g) = grad {
                let n = c.functions();
                for k in 0..nv {
                    let (v, _) = point_column(jac, nv, k, &r);
                    for (i, d) in dirs.iter().enumerate().take(n) {
                        g[i * nv + k] = v.dot(d);
                    }
                }
            }
        }
    }
}
