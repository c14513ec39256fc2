//! The constraint equations `Φ(q, s) = 0` of a planar linkage, their Jacobian `Φ_q`, the
//! velocity right side `−Φ_t` and the acceleration right side `γ`, in body coordinates
//! (Haug 1989, §3.3; Nikravesh 1988, §§3.5–3.7, 4.4–4.6).
//!
//! Rows, in joint order, the driver last. With `A = A(θ)`, `s = p − c` a point relative
//! to the centre of mass, `perp(v) = (−v_y, v_x)` (so `∂(A s)/∂θ = perp(A s)`):
//! - pin of `P_a` on `a` and `P_b` on `b` (Haug eq. 3.3.10): `Φ = r_a + A_a s_a − r_b − A_b s_b`
//!   (2 rows); `Φ_q = [I, perp(A_a s_a), −I, −perp(A_b s_b)]`;
//!   `γ = A_a s_a θ̇_a² − A_b s_b θ̇_b²` (eq. 3.3.12);
//! - point `P` of `l` on the line through `Q` along `u` of guide `g` (Haug §3.3.3, the
//!   translational joint's first equation): with `n = A_g n'` the line normal and
//!   `d = r_P − r_Q`, `Φ = n · d`; `Φ_q` has `[nᵀ, n · perp(A_l s_P)]` for `l` and
//!   `[−nᵀ, perp(n) · d − n · perp(A_g s_Q)]` for `g`;
//!   `γ = θ̇_g² n · d − 2 θ̇_g perp(n) · ḋ + n · (A_l s_P θ̇_l² − A_g s_Q θ̇_g²)`;
//! - the prismatic joint's second equation `Φ = θ_l − θ_g − α₀`, `γ = 0`;
//! - a higher pair (cam contact): one row, [`crate::machines::linkage::contact_rows`];
//! - angle driver `Φ = θ_l − θ_ref − s`: `−Φ_t = ṡ`, `γ = s̈`;
//! - slide driver `Φ = u · (r_P − p₀) − s`: `−Φ_t = ṡ`, `γ = u · A_l s_P θ̇_l² + s̈`.
//!
//! In general `γ = −(Φ_q q̇)_q q̇ − 2 Φ_qt q̇ − Φ_tt` (Haug eq. 3.1.11); the tests check these
//! closed forms against finite differences of `Φ_q q̇`.

use crate::machines::linkage::contact_rows;
use crate::machines::linkage::description::{Driver, Linkage, PlanarJoint, GROUND};
use crate::machines::linkage::{perp, Vec2};
use nalgebra::{DMatrix, DVector};

/// What a row of `Φ` belongs to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RowOwner {
    /// Joint `index`, component (`"x"`, `"y"`, `"line"`, `"angle"`).
    Joint(usize, &'static str),
    /// The driver.
    Driver,
}

/// The owner of each row of `Φ`.
pub fn row_owners(l: &Linkage) -> Vec<RowOwner> {
    let mut v = Vec::with_capacity(l.nrows());
    for (k, j) in l.joints.iter().enumerate() {
        match j {
            PlanarJoint::Revolute { .. } => {
                v.push(RowOwner::Joint(k, "x"));
                v.push(RowOwner::Joint(k, "y"));
            }
            PlanarJoint::Slider(s) => {
                v.push(RowOwner::Joint(k, "line"));
                if s.prismatic.is_some() {
                    v.push(RowOwner::Joint(k, "angle"));
                }
            }
            PlanarJoint::Contact(_) => v.push(RowOwner::Joint(k, "contact")),
        }
    }
    v.push(RowOwner::Driver);
    v
}

fn theta(q: &DVector<f64>, b: usize) -> f64 {
    if b == GROUND {
        0.0
    } else {
        q[3 * b + 2]
    }
}

fn omega(qd: &DVector<f64>, b: usize) -> f64 {
    theta(qd, b)
}

/// `Φ(q, s)` into `out` (length [`Linkage::nrows`]).
pub fn residual(l: &Linkage, q: &DVector<f64>, s: f64, out: &mut DVector<f64>) {
    assert_eq!(out.len(), l.nrows());
    let mut r = 0;
    for j in &l.joints {
        match j {
            PlanarJoint::Revolute { a, pa, b, pb, .. } => {
                let d = l.point_position(q, *a, pa) - l.point_position(q, *b, pb);
                out[r] = d.x;
                out[r + 1] = d.y;
                r += 2;
            }
            PlanarJoint::Slider(sl) => {
                let d = l.point_position(q, sl.link, &sl.p)
                    - l.point_position(q, sl.guide, &sl.through);
                let n = crate::machines::linkage::rotate(theta(q, sl.guide), &perp(&sl.dir));
                out[r] = n.dot(&d);
                r += 1;
                if let Some(a0) = sl.prismatic {
                    out[r] = theta(q, sl.link) - theta(q, sl.guide) - a0;
                    r += 1;
                }
            }
            PlanarJoint::Contact(c) => {
                out[r] = contact_rows::geometry(l, q, c).gap;
                r += 1;
            }
        }
    }
    out[r] = match &l.driver {
        Driver::Angle { link, relative_to } => theta(q, *link) - theta(q, *relative_to) - s,
        Driver::Slide {
            link,
            p,
            through,
            dir,
        } => dir.dot(&(l.point_position(q, *link, p) - through)) - s,
    };
}

/// Adds `row_vec` (∂Φ/∂(x, y) and ∂Φ/∂θ) for body `b` at row `r`.
fn put(out: &mut DMatrix<f64>, r: usize, b: usize, dx: f64, dy: f64, dth: f64) {
    if b == GROUND {
        return;
    }
    out[(r, 3 * b)] += dx;
    out[(r, 3 * b + 1)] += dy;
    out[(r, 3 * b + 2)] += dth;
}

/// `Φ_q` into `out` ([`Linkage::nrows`] × [`Linkage::ncoords`]).
pub fn jacobian(l: &Linkage, q: &DVector<f64>, out: &mut DMatrix<f64>) {
    assert_eq!(out.shape(), (l.nrows(), l.ncoords()));
    out.fill(0.0);
    let mut r = 0;
    for j in &l.joints {
        match j {
            PlanarJoint::Revolute { a, pa, b, pb, .. } => {
                let ta = perp(&l.arm(q, *a, pa));
                let tb = perp(&l.arm(q, *b, pb));
                put(out, r, *a, 1.0, 0.0, ta.x);
                put(out, r + 1, *a, 0.0, 1.0, ta.y);
                if *b != GROUND {
                    put(out, r, *b, -1.0, 0.0, -tb.x);
                    put(out, r + 1, *b, 0.0, -1.0, -tb.y);
                }
                r += 2;
            }
            PlanarJoint::Slider(sl) => {
                let d = l.point_position(q, sl.link, &sl.p)
                    - l.point_position(q, sl.guide, &sl.through);
                let n = crate::machines::linkage::rotate(theta(q, sl.guide), &perp(&sl.dir));
                let tl = perp(&l.arm(q, sl.link, &sl.p));
                put(out, r, sl.link, n.x, n.y, n.dot(&tl));
                if sl.guide != GROUND {
                    let tg = perp(&l.arm(q, sl.guide, &sl.through));
                    put(out, r, sl.guide, -n.x, -n.y, perp(&n).dot(&d) - n.dot(&tg));
                }
                r += 1;
                if sl.prismatic.is_some() {
                    put(out, r, sl.link, 0.0, 0.0, 1.0);
                    put(out, r, sl.guide, 0.0, 0.0, -1.0);
                    r += 1;
                }
            }
            PlanarJoint::Contact(c) => {
                for (b, d, dth) in contact_rows::jacobian_entries(l, q, c) {
                    put(out, r, b, d.x, d.y, dth);
                }
                r += 1;
            }
        }
    }
    match &l.driver {
        Driver::Angle { link, relative_to } => {
            put(out, r, *link, 0.0, 0.0, 1.0);
            put(out, r, *relative_to, 0.0, 0.0, -1.0);
        }
        Driver::Slide { link, p, dir, .. } => {
            let t = perp(&l.arm(q, *link, p));
            put(out, r, *link, dir.x, dir.y, dir.dot(&t));
        }
    }
}

/// `−Φ_t` for input rate `sd`: zero except `ṡ` in the driver row.
pub fn velocity_rhs(l: &Linkage, sd: f64) -> DVector<f64> {
    let mut v = DVector::zeros(l.nrows());
    v[l.nrows() - 1] = sd;
    v
}

/// `γ(q, q̇, s̈)` into `out`, so that `Φ_q q̈ = γ`.
pub fn gamma(l: &Linkage, q: &DVector<f64>, qd: &DVector<f64>, sdd: f64, out: &mut DVector<f64>) {
    assert_eq!(out.len(), l.nrows());
    let mut r = 0;
    for j in &l.joints {
        match j {
            PlanarJoint::Revolute { a, pa, b, pb, .. } => {
                let wa = omega(qd, *a);
                let wb = omega(qd, *b);
                let g = l.arm(q, *a, pa) * (wa * wa)
                    - if *b == GROUND {
                        Vec2::zeros()
                    } else {
                        l.arm(q, *b, pb) * (wb * wb)
                    };
                out[r] = g.x;
                out[r + 1] = g.y;
                r += 2;
            }
            PlanarJoint::Slider(sl) => {
                let wl = omega(qd, sl.link);
                let wg = omega(qd, sl.guide);
                let d = l.point_position(q, sl.link, &sl.p)
                    - l.point_position(q, sl.guide, &sl.through);
                let dd = l.point_velocity(q, qd, sl.link, &sl.p)
                    - l.point_velocity(q, qd, sl.guide, &sl.through);
                let n = crate::machines::linkage::rotate(theta(q, sl.guide), &perp(&sl.dir));
                let al = l.arm(q, sl.link, &sl.p);
                let ag = if sl.guide == GROUND {
                    Vec2::zeros()
                } else {
                    l.arm(q, sl.guide, &sl.through)
                };
                out[r] = wg * wg * n.dot(&d) - 2.0 * wg * perp(&n).dot(&dd)
                    + n.dot(&(al * (wl * wl) - ag * (wg * wg)));
                r += 1;
                if sl.prismatic.is_some() {
                    out[r] = 0.0;
                    r += 1;
                }
            }
            PlanarJoint::Contact(c) => {
                out[r] = contact_rows::gamma(l, q, qd, c);
                r += 1;
            }
        }
    }
    out[r] = match &l.driver {
        Driver::Angle { .. } => sdd,
        Driver::Slide { link, p, dir, .. } => {
            let w = omega(qd, *link);
            dir.dot(&l.arm(q, *link, p)) * w * w + sdd
        }
    };
}

/// `Φ(q, s)` as a new vector.
pub fn residual_vec(l: &Linkage, q: &DVector<f64>, s: f64) -> DVector<f64> {
    let mut v = DVector::zeros(l.nrows());
    residual(l, q, s, &mut v);
    v
}

/// `Φ_q` as a new matrix.
pub fn jacobian_mat(l: &Linkage, q: &DVector<f64>) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(l.nrows(), l.ncoords());
    jacobian(l, q, &mut m);
    m
}

/// `γ` as a new vector.
pub fn gamma_vec(l: &Linkage, q: &DVector<f64>, qd: &DVector<f64>, sdd: f64) -> DVector<f64> {
    let mut v = DVector::zeros(l.nrows());
    gamma(l, q, qd, sdd, &mut v);
    v
}
