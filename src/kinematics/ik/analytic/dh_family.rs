//! Standard Denavit–Hartenberg parameters recovered from a [`Model`]'s geometry.
//!
//! A `Model` keeps no DH table (URDF and DH files compile to the same body placements), so
//! the closed forms read their parameters back from the joint axes at `q = 0`: the axis of
//! joint `j` is the line `L_j` through the origin of its body frame along the body's joint
//! axis (sign included), and the standard (distal) DH frames are rebuilt from consecutive
//! lines:
//!
//! - frame `j` (`1 ≤ j < n`) has `z_j` along `L_j`, its origin on `L_j` at the foot of the
//!   common normal from `L_{j-1}`, and `x_j` along that normal (for intersecting axes,
//!   `±z_{j-1} × z_j`); for parallel axes the normal through the previous origin is taken,
//!   so `d_j = 0`; for coincident axes `x_j = x_{j-1}`;
//! - the sign of `x_j` is the one closest to `x_{j-1}` (the smallest `|θ|` offset); where
//!   both are at 90° it makes `α_j ∈ [0, π]`; frame 0 takes `x_0 = x_1`, so `θ_1` has no
//!   offset, with its origin at the foot of the world origin on `L_1`;
//! - a prismatic joint's line is only a direction: it is placed on the next joint's axis
//!   when that is a parallel revolute axis (the Stanford arm's boom), otherwise through
//!   the previous frame's origin;
//! - the last frame `n` has `z_n = z_{n-1}` (`α_n = 0`); with `tool_on_axis` its origin is
//!   the foot of the target link's origin on `L_n` (`a_n = 0`) and `x_n` the link's `x`
//!   projected, otherwise its origin is the link origin itself.
//!
//! The world → frame 0 transform is the `base`, frame `n` → target link the `tool`. Values
//! within 1e-12 of 0 (lengths) or of a multiple of π/2 (angles) are snapped, and the table
//! is checked against the model's own forward kinematics at three configurations: if it
//! does not reproduce them to 1e-10 the extraction fails (a model the rules do not fit).
//! On the bundled DH files the rules return the file's own table (UR5, Puma 560; the
//! Stanford arm's differs by sign conventions only).

use crate::core::spatial::{column, Mat3, Se3, Vec3};
use crate::kinematics::ik::analytic::ik_error::IkError;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::Model;
use std::f64::consts::{FRAC_PI_2, PI};

/// Axes closer to parallel than this (`|sin|`) are parallel.
const PAR_TOL: f64 = 1e-12;
/// Lines closer than this (m) intersect; lengths below it are zero.
const DIST_TOL: f64 = 1e-12;
/// Angles within this of a multiple of π/2 are snapped to it.
const ANGLE_SNAP: f64 = 1e-12;
/// Pose agreement required between the table and the model's forward kinematics.
const VERIFY_TOL: f64 = 1e-10;

/// `(sin, cos)` of an angle, exact at the multiples of π/2 (so that `α = π/2` gives
/// `cos α = 0`, not 6e-17).
#[inline]
pub fn exact_sin_cos(x: f64) -> (f64, f64) {
    if x == 0.0 {
        (0.0, 1.0)
    } else if x == FRAC_PI_2 {
        (1.0, 0.0)
    } else if x == -FRAC_PI_2 {
        (-1.0, 0.0)
    } else if x == PI || x == -PI {
        (0.0, -1.0)
    } else {
        x.sin_cos()
    }
}

/// The standard DH transform `Rz(θ) Tz(d) Tx(a) Rx(α)` with `sin/cos θ` given.
#[inline]
pub fn dh_transform_sc(st: f64, ct: f64, d: f64, a: f64, sa: f64, ca: f64) -> Se3 {
    Se3::new(
        Mat3::new(ct, -ca * st, sa * st, st, ca * ct, -sa * ct, 0.0, sa, ca),
        Vec3::new(a * ct, a * st, d),
    )
}

/// The standard DH transform `Rz(θ) Tz(d) Tx(a) Rx(α)`.
#[inline]
pub fn dh_transform(theta: f64, d: f64, a: f64, alpha: f64) -> Se3 {
    let (st, ct) = theta.sin_cos();
    let (sa, ca) = exact_sin_cos(alpha);
    dh_transform_sc(st, ct, d, a, sa, ca)
}

/// One row of a standard DH table, with the joint variable separated out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DhRow {
    /// Revolute: the offset, `θ = q + theta`. Prismatic: the fixed angle `θ`.
    pub theta: f64,
    /// Revolute: the fixed `d`. Prismatic: the offset, `d = q + d`.
    pub d: f64,
    /// Common-normal length `a` (m), signed.
    pub a: f64,
    /// Twist `α` (rad).
    pub alpha: f64,
    /// Revolute (`true`) or prismatic.
    pub revolute: bool,
}

impl DhRow {
    /// `A(q)`: the transform from the previous DH frame to this row's frame.
    pub fn transform(&self, q: f64) -> Se3 {
        if self.revolute {
            dh_transform(q + self.theta, self.d, self.a, self.alpha)
        } else {
            dh_transform(self.theta, q + self.d, self.a, self.alpha)
        }
    }

    /// The DH variable (`θ` or `d`) for joint value `q`.
    pub fn variable(&self, q: f64) -> f64 {
        if self.revolute {
            q + self.theta
        } else {
            q + self.d
        }
    }

    /// The joint value for DH variable `v` (`θ` or `d`).
    pub fn joint(&self, v: f64) -> f64 {
        if self.revolute {
            v - self.theta
        } else {
            v - self.d
        }
    }
}

/// Forward kinematics of a 6-row table: `base · A_1(q_1) ⋯ A_6(q_6) · tool`.
pub fn table_fk(base: &Se3, rows: &[DhRow; 6], tool: &Se3, q: &[f64; 6]) -> Se3 {
    let mut t = *base;
    for (row, &qi) in rows.iter().zip(q) {
        t = t.mul(&row.transform(qi));
    }
    t.mul(tool)
}

/// A serial chain as a standard DH table: `world_M_link(q) = base · A_1(q_1) ⋯ A_n(q_n) · tool`.
#[derive(Clone, Debug, PartialEq)]
pub struct DhChain {
    /// World → DH frame 0.
    pub base: Se3,
    /// The rows, joint 1 first (the model's coordinate order).
    pub rows: Vec<DhRow>,
    /// DH frame `n` → the target link.
    pub tool: Se3,
    /// Lower position limit of each joint.
    pub lower: Vec<f64>,
    /// Upper position limit of each joint.
    pub upper: Vec<f64>,
    /// The target link's name.
    pub link_name: String,
}

impl DhChain {
    /// Number of joints.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the chain has no joint.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// DH frame `n` in DH frame 0.
    pub fn flange(&self, q: &[f64]) -> Se3 {
        let mut t = Se3::identity();
        for (row, &qi) in self.rows.iter().zip(q) {
            t = t.mul(&row.transform(qi));
        }
        t
    }

    /// Origins of DH frames `0..=n`, in DH frame 0.
    pub fn origins(&self, q: &[f64]) -> Vec<Vec3> {
        let mut t = Se3::identity();
        let mut v = vec![t.trans];
        for (row, &qi) in self.rows.iter().zip(q) {
            t = t.mul(&row.transform(qi));
            v.push(t.trans);
        }
        v
    }

    /// World placement of the target link.
    pub fn placement(&self, q: &[f64]) -> Se3 {
        self.base.mul(&self.flange(q)).mul(&self.tool)
    }

    /// Reads the table of the serial chain from the root to `link` (see the module docs).
    /// `tool_on_axis` puts frame `n` on the last joint's axis (6-DOF arms; the tool
    /// transform carries any offset) rather than at the link origin (position-only arms).
    ///
    /// Fails when the chain is not all of the model's coordinates in order, has mimic
    /// joints, or when the rebuilt table does not reproduce the model.
    pub fn from_model(model: &Model, link: usize, tool_on_axis: bool) -> Result<Self, IkError> {
        let unsupported = |m: String| Err(IkError::Unsupported(m));
        let Some(l) = model.links.get(link) else {
            return unsupported(format!(
                "link index {link} is out of range ({} links)",
                model.links.len()
            ));
        };
        let bodies = serial_bodies(model, l)?;
        let n = bodies.len();
        let mut data = Data::new(model);
        let zeros = vec![0.0; n];
        forward_kinematics(model, &mut data, &zeros);
        let mut p: Vec<Vec3> = Vec::with_capacity(n);
        let mut u: Vec<Vec3> = Vec::with_capacity(n);
        let mut rev: Vec<bool> = Vec::with_capacity(n);
        for &b in &bodies {
            let m = &data.o_m_i[b];
            let kind = model.kind[b];
            let axis = column(&m.rot, kind.axis_index()) * model.q_mult[b];
            p.push(m.trans);
            u.push(axis / axis.norm());
            rev.push(kind.is_revolute());
        }
        let tl = frame_placement(model, &data, link);

        // Prismatic lines: on the next axis when it is a parallel revolute one.
        let mut placed = rev.clone();
        for j in 0..n {
            if !rev[j] && j + 1 < n && rev[j + 1] && u[j].cross(&u[j + 1]).norm() < PAR_TOL {
                p[j] = p[j + 1];
                placed[j] = true;
            }
        }
        if !placed[0] {
            p[0] = Vec3::zeros();
        }
        let z0 = u[0];
        let o0 = p[0] + z0 * (-p[0]).dot(&z0);
        let mut o = vec![o0];
        let mut x: Vec<Vec3> = vec![Vec3::zeros()];
        let mut rows: Vec<DhRow> = Vec::with_capacity(n);
        for j in 1..=n {
            let zp = u[j - 1];
            let op = o[j - 1];
            let xp = if j == 1 { None } else { Some(x[j - 1]) };
            let (oj, xj, foot, zj) = if j < n {
                if !placed[j] {
                    p[j] = op;
                }
                let (oj, xj, foot) = common_normal(zp, op, xp, u[j], p[j]);
                (oj, xj, foot, u[j])
            } else {
                let (oj, xj, foot) = last_frame(zp, op, &tl, tool_on_axis);
                (oj, xj, foot, zp)
            };
            if j == 1 {
                x[0] = xj;
            }
            let xprev = x[j - 1];
            let d = (foot - op).dot(&zp);
            let a = (oj - foot).dot(&xj);
            let alpha = zp.cross(&zj).dot(&xj).atan2(zp.dot(&zj));
            let theta = xprev.cross(&xj).dot(&zp).atan2(xprev.dot(&xj));
            rows.push(DhRow {
                theta: snap_angle(theta),
                d: snap_len(d),
                a: snap_len(a),
                alpha: snap_angle(alpha),
                revolute: rev[j - 1],
            });
            o.push(oj);
            x.push(xj);
        }
        let frame = |xv: Vec3, zv: Vec3, ov: Vec3| {
            let yv = zv.cross(&xv);
            Se3::new(Mat3::from_columns(&[xv, yv, zv]), ov)
        };
        let base = frame(x[0], z0, o0);
        let flange_world = frame(x[n], u[n - 1], o[n]);
        let tool = flange_world.inv_mul(&tl);
        let chain = DhChain {
            base,
            rows,
            tool,
            lower: model.lower.clone(),
            upper: model.upper.clone(),
            link_name: l.name.clone(),
        };
        chain.verify(model, link, &mut data)?;
        Ok(chain)
    }

    /// Compares the table with the model's forward kinematics at three configurations.
    fn verify(&self, model: &Model, link: usize, data: &mut Data) -> Result<(), IkError> {
        let n = self.rows.len();
        for k in 0..3 {
            let q: Vec<f64> = (0..n)
                .map(|i| match k {
                    0 => 0.0,
                    1 => 0.3 + 0.41 * i as f64,
                    _ => -0.7 + 0.53 * ((i * 7 % 5) as f64),
                })
                .collect();
            forward_kinematics(model, data, &q);
            let want = frame_placement(model, data, link);
            let got = self.placement(&q);
            let err = (want.trans - got.trans)
                .amax()
                .max((want.rot - got.rot).amax());
            if err.is_nan() || err > VERIFY_TOL {
                return Err(IkError::Unsupported(format!(
                    "the DH table read from the model's axes does not reproduce its forward \
                     kinematics (error {err:.2e}): the chain does not fit the standard DH rules"
                )));
            }
        }
        Ok(())
    }
}

fn snap_len(v: f64) -> f64 {
    if v.abs() < DIST_TOL {
        0.0
    } else {
        v
    }
}

fn snap_angle(v: f64) -> f64 {
    for k in [-PI, -FRAC_PI_2, 0.0, FRAC_PI_2, PI] {
        if (v - k).abs() < ANGLE_SNAP {
            return if k == -PI { PI } else { k };
        }
    }
    v
}

/// The bodies from the world to link `l`, which must be a serial chain of all of the
/// model's coordinates, in order, without mimic joints.
fn serial_bodies(model: &Model, l: &crate::model::Link) -> Result<Vec<usize>, IkError> {
    let unsupported = |m: String| Err(IkError::Unsupported(m));
    let mut bodies: Vec<usize> = model.support(l.body).collect();
    bodies.reverse();
    let n = bodies.len();
    if n == 0 {
        return unsupported(format!("link '{}' is fixed to the world", l.name));
    }
    if n != model.nv {
        return unsupported(format!(
            "the chain to link '{}' has {n} joints but the model has {} coordinates: \
             analytic IK needs a serial chain made of all of them",
            l.name, model.nv
        ));
    }
    for (k, &b) in bodies.iter().enumerate() {
        let name = &model.joints[model.body_joint[b]].name;
        if model.q_index[b] != k || model.q_mult[b].abs() != 1.0 || model.q_offset[b] != 0.0 {
            return unsupported(format!(
                "joint '{name}' is a mimic joint or out of coordinate order"
            ));
        }
    }
    Ok(bodies)
}

/// A unit vector normal to `z`, from the world x (or y) axis.
fn any_normal(z: &Vec3) -> Vec3 {
    let mut v = Vec3::x() - z * z.x;
    if v.norm() < 1e-6 {
        v = Vec3::y() - z * z.y;
    }
    v.normalize()
}

/// Frame `j` from axis `j − 1` (direction `zp` through `op`, previous x axis `xp`, `None`
/// for the first) and axis `j` (`zj` through `pj`): the origin and x axis on the common
/// normal (sign kept towards `xp`), and the foot of the normal on axis `j − 1`.
fn common_normal(zp: Vec3, op: Vec3, xp: Option<Vec3>, zj: Vec3, pj: Vec3) -> (Vec3, Vec3, Vec3) {
    let cr = zp.cross(&zj);
    let sn = cr.norm();
    if sn < PAR_TOL {
        let dv = pj - op;
        let perp = dv - zp * dv.dot(&zp);
        let dist = perp.norm();
        if dist < DIST_TOL {
            (op, xp.unwrap_or_else(|| any_normal(&zp)), op)
        } else {
            let c = perp / dist;
            let xj = match xp {
                Some(xp) if xp.dot(&c) < 0.0 => -c,
                _ => c,
            };
            (op + perp, xj, op)
        }
    } else {
        // Closest points P on L_{j-1} (through op) and Q on L_j.
        let w0 = op - pj;
        let b = zp.dot(&zj);
        let dd = zp.dot(&w0);
        let e = zj.dot(&w0);
        let den = sn * sn;
        let s = (b * e - dd) / den;
        let t = (e - b * dd) / den;
        let pp = op + zp * s;
        let qq = pj + zj * t;
        let dvec = qq - pp;
        let dist = dvec.norm();
        let c = if dist < DIST_TOL {
            cr / sn
        } else {
            dvec / dist
        };
        let toward = xp.map(|xp| xp.dot(&c)).unwrap_or(0.0);
        let xj = if toward < -ANGLE_SNAP || (toward <= ANGLE_SNAP && cr.dot(&c) < 0.0) {
            -c
        } else {
            c
        };
        let oj = if dist < DIST_TOL { pp } else { qq };
        (oj, xj, pp)
    }
}

/// The last frame `n` on the last axis (`zp` through `op`): at the foot of the target
/// link's origin with its x axis projected (`tool_on_axis`, or the origin is on the axis),
/// else at the link origin with x towards it. Returns the origin, x axis and foot.
fn last_frame(zp: Vec3, op: Vec3, tl: &Se3, tool_on_axis: bool) -> (Vec3, Vec3, Vec3) {
    let dv = tl.trans - op;
    let along = dv.dot(&zp);
    let perp = dv - zp * along;
    let dist = perp.norm();
    let foot = op + zp * along;
    if tool_on_axis || dist < DIST_TOL {
        let lx = column(&tl.rot, 0);
        let mut v = lx - zp * lx.dot(&zp);
        if v.norm() < 1e-6 {
            let ly = column(&tl.rot, 1);
            v = ly - zp * ly.dot(&zp);
        }
        (foot, v.normalize(), foot)
    } else {
        (tl.trans, perp / dist, foot)
    }
}
