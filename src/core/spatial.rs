//! Spatial algebra: rigid transforms (SE(3)), spatial motion and force vectors and the
//! 6-D rigid-body inertia, in f64 on nalgebra.
//!
//! Conventions (the same as Pinocchio's, so formulas can be checked side by side):
//! - A [`Se3`] `aMb` maps coordinates in frame `b` to frame `a`: `p_a = R p_b + t`.
//! - A [`Motion`] is `(v, w)`: linear part first, angular part second; `v` is the velocity
//!   of the point at the origin of the frame it is expressed in.
//! - A [`Force`] is `(f, n)`: force first, moment about the frame origin second.
//! - Motion and force cross products follow Featherstone, *Rigid Body Dynamics
//!   Algorithms* (RBDA) eqs. 2.31–2.34, written in the (linear, angular) ordering.

use nalgebra::{Matrix3, Vector3};

/// 3-vector shorthand.
pub type Vec3 = Vector3<f64>;
/// 3×3 matrix shorthand.
pub type Mat3 = Matrix3<f64>;

/// Skew-symmetric matrix `[v]×` with `[v]× u = v × u`.
#[inline]
pub fn skew(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Component `k` (0, 1, 2) of `v`, selected without indexing memory (a runtime index
/// would force `v` through the stack and stall on store forwarding in hot loops).
#[inline(always)]
pub fn component(v: &Vec3, k: usize) -> f64 {
    match k {
        0 => v.x,
        1 => v.y,
        _ => v.z,
    }
}

/// Column `k` of `m`, selected without indexing memory.
#[inline(always)]
pub fn column(m: &Mat3, k: usize) -> Vec3 {
    match k {
        0 => Vec3::new(m[(0, 0)], m[(1, 0)], m[(2, 0)]),
        1 => Vec3::new(m[(0, 1)], m[(1, 1)], m[(2, 1)]),
        _ => Vec3::new(m[(0, 2)], m[(1, 2)], m[(2, 2)]),
    }
}

/// The unit vector `e_k` times `x`.
#[inline(always)]
pub fn unit(k: usize, x: f64) -> Vec3 {
    match k {
        0 => Vec3::new(x, 0.0, 0.0),
        1 => Vec3::new(0.0, x, 0.0),
        _ => Vec3::new(0.0, 0.0, x),
    }
}

/// Rotation about x by `a` radians.
pub fn rot_x(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    Mat3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Rotation about y by `a` radians.
pub fn rot_y(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    Mat3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation about z by `a` radians.
pub fn rot_z(a: f64) -> Mat3 {
    let (s, c) = a.sin_cos();
    Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// URDF roll-pitch-yaw: fixed-axis X, then Y, then Z, i.e. `R = Rz(yaw) Ry(pitch) Rx(roll)`.
pub fn rpy_to_matrix(rpy: [f64; 3]) -> Mat3 {
    rot_z(rpy[2]) * rot_y(rpy[1]) * rot_x(rpy[0])
}

/// Roll-pitch-yaw of a rotation matrix (inverse of [`rpy_to_matrix`]; pitch in [-π/2, π/2]).
pub fn matrix_to_rpy(r: &Mat3) -> [f64; 3] {
    let pitch = (-r[(2, 0)]).atan2((r[(2, 1)].powi(2) + r[(2, 2)].powi(2)).sqrt());
    let roll = r[(2, 1)].atan2(r[(2, 2)]);
    let yaw = r[(1, 0)].atan2(r[(0, 0)]);
    [roll, pitch, yaw]
}

/// Rotation about a unit `axis` by `angle` (Rodrigues' formula).
pub fn axis_angle(axis: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let k = skew(axis);
    Mat3::identity() + k * s + k * k * (1.0 - c)
}

/// A rotation `R` with `R e_z = axis` for a unit `axis`.
///
/// Axis-aligned directions (±x, ±y, ±z) give exact signed permutation matrices so that
/// models built from them carry no rounding; other directions use the shortest rotation.
pub fn rotation_z_to(axis: &Vec3) -> Mat3 {
    let exact = |x: f64| x == 0.0 || x.abs() == 1.0;
    if exact(axis.x) && exact(axis.y) && exact(axis.z) {
        // Columns (e1, e2, axis) forming a right-handed frame with e3 = axis.
        let (e1, e2) = if axis.z != 0.0 {
            (Vec3::x(), Vec3::y() * axis.z)
        } else if axis.y != 0.0 {
            (Vec3::z(), Vec3::x() * axis.y)
        } else {
            (Vec3::y(), Vec3::z() * axis.x)
        };
        return Mat3::from_columns(&[e1, e2, *axis]);
    }
    let z = Vec3::z();
    let c = z.dot(axis);
    let k = z.cross(axis);
    let s = k.norm();
    if s < 1e-15 {
        return if c > 0.0 {
            Mat3::identity()
        } else {
            rot_x(std::f64::consts::PI)
        };
    }
    axis_angle(&(k / s), s.atan2(c))
}

/// A rigid transform `aMb`: rotation `rot` and translation `trans` (origin of `b` in `a`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3 {
    /// Rotation matrix (frame `b` axes expressed in frame `a`).
    pub rot: Mat3,
    /// Translation: origin of `b` expressed in `a`.
    pub trans: Vec3,
}

impl Default for Se3 {
    fn default() -> Self {
        Self::identity()
    }
}

impl Se3 {
    /// The identity transform.
    pub fn identity() -> Self {
        Self {
            rot: Mat3::identity(),
            trans: Vec3::zeros(),
        }
    }

    /// Builds a transform from a rotation and a translation.
    pub fn new(rot: Mat3, trans: Vec3) -> Self {
        Self { rot, trans }
    }

    /// Pure translation.
    pub fn from_translation(trans: Vec3) -> Self {
        Self {
            rot: Mat3::identity(),
            trans,
        }
    }

    /// Pure rotation.
    pub fn from_rotation(rot: Mat3) -> Self {
        Self {
            rot,
            trans: Vec3::zeros(),
        }
    }

    /// URDF `<origin xyz=".." rpy=".."/>`.
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Self {
        Self::new(rpy_to_matrix(rpy), Vec3::from(xyz))
    }

    /// Composition `aMc = aMb * bMc`.
    #[inline(always)]
    pub fn mul(&self, other: &Se3) -> Se3 {
        Se3 {
            rot: self.rot * other.rot,
            trans: self.rot * other.trans + self.trans,
        }
    }

    /// Inverse `bMa`.
    #[inline]
    pub fn inverse(&self) -> Se3 {
        let rt = self.rot.transpose();
        Se3 {
            rot: rt,
            trans: -(rt * self.trans),
        }
    }

    /// `self.inverse() * other` without forming the inverse.
    #[inline]
    pub fn inv_mul(&self, other: &Se3) -> Se3 {
        let rt = self.rot.transpose();
        Se3 {
            rot: rt * other.rot,
            trans: rt * (other.trans - self.trans),
        }
    }

    /// Maps a point from `b` to `a`.
    #[inline]
    pub fn act_point(&self, p: &Vec3) -> Vec3 {
        self.rot * p + self.trans
    }

    /// Moves a motion vector from frame `b` to frame `a` (`Ad_aMb`).
    #[inline]
    pub fn act_motion(&self, m: &Motion) -> Motion {
        let w = self.rot * m.w;
        Motion {
            v: self.rot * m.v + self.trans.cross(&w),
            w,
        }
    }

    /// Moves a motion vector from frame `a` to frame `b` (`Ad_aMb^{-1}`).
    #[inline]
    pub fn act_inv_motion(&self, m: &Motion) -> Motion {
        let rt = self.rot.transpose();
        Motion {
            v: rt * (m.v - self.trans.cross(&m.w)),
            w: rt * m.w,
        }
    }

    /// Moves a force vector from frame `b` to frame `a` (dual adjoint).
    #[inline]
    pub fn act_force(&self, f: &Force) -> Force {
        let fa = self.rot * f.f;
        Force {
            f: fa,
            n: self.rot * f.n + self.trans.cross(&fa),
        }
    }

    /// Moves a force vector from frame `a` to frame `b`.
    #[inline]
    pub fn act_inv_force(&self, f: &Force) -> Force {
        let rt = self.rot.transpose();
        Force {
            f: rt * f.f,
            n: rt * (f.n - self.trans.cross(&f.f)),
        }
    }

    /// The transform with its rotation projected back onto SO(3) by one Newton–Schulz step
    /// towards the orthogonal polar factor, `R ← R (3I − RᵀR) / 2`: the orthonormality
    /// error `E = RᵀR − I` becomes `−(3/4) E² − (1/4) E³`, so an error of 1e-10 drops to
    /// rounding in one step, and the correction is symmetric (no column is favoured, the
    /// rotation angle is not biased). A product of many transforms (a twist integrated step
    /// by step) loses orthonormality like `N eps` otherwise; the kinematics never needs
    /// this, since it rebuilds every placement from the joint angles.
    pub fn orthonormalized(&self) -> Se3 {
        let e = self.rot.transpose() * self.rot;
        Se3 {
            rot: self.rot * (Mat3::identity() * 3.0 - e) * 0.5,
            trans: self.trans,
        }
    }

    /// Row-major 3×3 rotation as nested arrays (the CLI's JSON shape).
    pub fn rotation_rows(&self) -> [[f64; 3]; 3] {
        let r = &self.rot;
        [
            [r[(0, 0)], r[(0, 1)], r[(0, 2)]],
            [r[(1, 0)], r[(1, 1)], r[(1, 2)]],
            [r[(2, 0)], r[(2, 1)], r[(2, 2)]],
        ]
    }
}

/// A spatial motion vector (twist): linear part `v`, angular part `w`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Motion {
    /// Linear velocity of the point at the expressing frame's origin.
    pub v: Vec3,
    /// Angular velocity.
    pub w: Vec3,
}

impl Motion {
    /// The zero motion.
    pub fn zero() -> Self {
        Self {
            v: Vec3::zeros(),
            w: Vec3::zeros(),
        }
    }

    /// Builds a motion from its linear and angular parts.
    pub fn new(v: Vec3, w: Vec3) -> Self {
        Self { v, w }
    }

    /// Motion cross product `self ×m other` (RBDA eq. 2.31, reordered).
    #[inline]
    pub fn cross_motion(&self, o: &Motion) -> Motion {
        Motion {
            v: self.w.cross(&o.v) + self.v.cross(&o.w),
            w: self.w.cross(&o.w),
        }
    }

    /// Force cross product `self ×f f` (RBDA eq. 2.32, reordered).
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force {
            f: self.w.cross(&f.f),
            n: self.w.cross(&f.n) + self.v.cross(&f.f),
        }
    }

    /// `self + o`.
    #[inline]
    pub fn add(&self, o: &Motion) -> Motion {
        Motion {
            v: self.v + o.v,
            w: self.w + o.w,
        }
    }

    /// `self * s`.
    #[inline]
    pub fn scale(&self, s: f64) -> Motion {
        Motion {
            v: self.v * s,
            w: self.w * s,
        }
    }

    /// `[v; w]` as an array of six.
    pub fn to_array(&self) -> [f64; 6] {
        [self.v.x, self.v.y, self.v.z, self.w.x, self.w.y, self.w.z]
    }
}

/// A spatial force vector (wrench): force `f`, moment `n` about the frame origin.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Force {
    /// Linear force.
    pub f: Vec3,
    /// Moment about the expressing frame's origin.
    pub n: Vec3,
}

impl Force {
    /// The zero force.
    pub fn zero() -> Self {
        Self {
            f: Vec3::zeros(),
            n: Vec3::zeros(),
        }
    }

    /// Builds a force from its linear and angular parts.
    pub fn new(f: Vec3, n: Vec3) -> Self {
        Self { f, n }
    }

    /// `self + o`.
    #[inline]
    pub fn add(&self, o: &Force) -> Force {
        Force {
            f: self.f + o.f,
            n: self.n + o.n,
        }
    }

    /// Power pairing `<m, f>`.
    #[inline]
    pub fn dot_motion(&self, m: &Motion) -> f64 {
        self.f.dot(&m.v) + self.n.dot(&m.w)
    }
}

/// Rigid-body inertia: mass, centre of mass `com` and rotational inertia `inertia_com`
/// about the centre of mass, all expressed in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the expressing frame (m).
    pub com: Vec3,
    /// Inertia tensor about the centre of mass, expressing-frame axes (kg m²).
    pub inertia_com: Mat3,
}

impl Default for Inertia {
    fn default() -> Self {
        Self::zero()
    }
}

impl Inertia {
    /// A massless body.
    pub fn zero() -> Self {
        Self {
            mass: 0.0,
            com: Vec3::zeros(),
            inertia_com: Mat3::zeros(),
        }
    }

    /// Builds an inertia from mass, centre of mass and the tensor about the centre of mass.
    pub fn new(mass: f64, com: Vec3, inertia_com: Mat3) -> Self {
        Self {
            mass,
            com,
            inertia_com,
        }
    }

    /// Whether the body has neither mass nor rotational inertia.
    pub fn is_zero(&self) -> bool {
        self.mass == 0.0 && self.inertia_com == Mat3::zeros()
    }

    /// The same body expressed in frame `a`, given `aMb` with `self` expressed in `b`.
    pub fn transformed(&self, a_m_b: &Se3) -> Inertia {
        Inertia {
            mass: self.mass,
            com: a_m_b.act_point(&self.com),
            inertia_com: a_m_b.rot * self.inertia_com * a_m_b.rot.transpose(),
        }
    }

    /// Combined inertia of two bodies expressed in the same frame (parallel-axis theorem).
    pub fn combined(&self, o: &Inertia) -> Inertia {
        let m = self.mass + o.mass;
        if m == 0.0 {
            return Inertia {
                mass: 0.0,
                com: Vec3::zeros(),
                inertia_com: self.inertia_com + o.inertia_com,
            };
        }
        let com = (self.com * self.mass + o.com * o.mass) / m;
        let d1 = self.com - com;
        let d2 = o.com - com;
        let steiner =
            |d: &Vec3, mass: f64| (Mat3::identity() * d.norm_squared() - d * d.transpose()) * mass;
        Inertia {
            mass: m,
            com,
            inertia_com: self.inertia_com
                + o.inertia_com
                + steiner(&d1, self.mass)
                + steiner(&d2, o.mass),
        }
    }

    /// Momentum `I v` of a body moving with spatial velocity `v` (RBDA eq. 2.63).
    #[inline]
    pub fn mul_motion(&self, m: &Motion) -> Force {
        // Momentum about the frame origin: p = m (v + w × c), L = I_c w + c × p.
        let f = (m.v + m.w.cross(&self.com)) * self.mass;
        let n = self.inertia_com * m.w + self.com.cross(&f);
        Force { f, n }
    }

    /// Kinetic energy `½ vᵀ I v`.
    pub fn kinetic_energy(&self, m: &Motion) -> f64 {
        0.5 * self.mul_motion(m).dot_motion(m)
    }
}

/// Rigid-body inertia in *origin form*: mass `m`, first moment `h = m c` and rotational
/// inertia `i_o` about the expressing frame's origin. Transforming and adding are linear in
/// `(m, h, i_o)`, which makes it the form of choice for composite inertias (CRBA).
/// As a 6×6 matrix in (linear, angular) order: `[[m 1, −[h]×], [[h]×, I_O]]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InertiaO {
    /// Mass.
    pub m: f64,
    /// First moment of mass `m c`.
    pub h: Vec3,
    /// Rotational inertia about the frame origin.
    pub i_o: Mat3,
}

impl InertiaO {
    /// The zero inertia.
    pub fn zero() -> Self {
        Self {
            m: 0.0,
            h: Vec3::zeros(),
            i_o: Mat3::zeros(),
        }
    }

    /// From the centre-of-mass form: `I_O = I_c − m [c]×²`.
    pub fn from_inertia(i: &Inertia) -> Self {
        let cx = skew(&i.com);
        Self {
            m: i.mass,
            h: i.com * i.mass,
            i_o: i.inertia_com - cx * cx * i.mass,
        }
    }

    /// The same body expressed in frame `a`, given `aMb` and `self` in `b`:
    /// `h' = R h + m p`, `I' = R I Rᵀ − ([Rh]×[p]× + [p]×[Rh]×) − m [p]×²`, evaluated with
    /// `[a]×[b]× = b aᵀ − (a·b) 1` and the symmetry of `I`.
    #[inline]
    pub fn transformed(&self, a_m_b: &Se3) -> InertiaO {
        let (m, h, [xx, xy, xz, yy, yz, zz]) = self.transformed_parts(a_m_b);
        InertiaO {
            m,
            h,
            i_o: Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz),
        }
    }

    /// [`InertiaO::transformed`] as its numbers: `(m, h', [xx, xy, xz, yy, yz, zz])` of
    /// `I'` (for callers that store them otherwise, as [`crate::core::sym6::Sym6`]).
    #[inline(always)]
    pub fn transformed_parts(&self, a_m_b: &Se3) -> (f64, Vec3, [f64; 6]) {
        let r = &a_m_b.rot;
        let p = a_m_b.trans;
        let a = r * self.h;
        let t = r * self.i_o;
        let m = self.m;
        let diag = 2.0 * a.dot(&p) + m * p.norm_squared();
        // Entry (i, j) of R I Rᵀ − (a pᵀ + p aᵀ) − m p pᵀ, built from scalars (element
        // writes into a matrix read back as vectors stall on store forwarding).
        let e = |i: usize, j: usize| {
            t[(i, 0)] * r[(j, 0)] + t[(i, 1)] * r[(j, 1)] + t[(i, 2)] * r[(j, 2)]
                - (a[i] * p[j] + p[i] * a[j])
                - m * p[i] * p[j]
        };
        let (xx, yy, zz) = (e(0, 0) + diag, e(1, 1) + diag, e(2, 2) + diag);
        let (xy, xz, yz) = (e(0, 1), e(0, 2), e(1, 2));
        (m, a + p * m, [xx, xy, xz, yy, yz, zz])
    }

    /// `self + o` (both in the same frame).
    #[inline]
    pub fn add(&self, o: &InertiaO) -> InertiaO {
        InertiaO {
            m: self.m + o.m,
            h: self.h + o.h,
            i_o: self.i_o + o.i_o,
        }
    }

    /// Momentum `I v`: `f = m v − h × ω`, `n = I_O ω + h × v`.
    #[inline(always)]
    pub fn mul_motion(&self, m: &Motion) -> Force {
        Force {
            f: m.v * self.m - self.h.cross(&m.w),
            n: self.i_o * m.w + self.h.cross(&m.v),
        }
    }

    /// The 6×6 matrix in (linear, angular) order.
    pub fn to_matrix(&self) -> nalgebra::Matrix6<f64> {
        let mut out = nalgebra::Matrix6::zeros();
        let hx = skew(&self.h);
        out.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Mat3::identity() * self.m));
        out.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-hx));
        out.fixed_view_mut::<3, 3>(3, 0).copy_from(&hx);
        out.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.i_o);
        out
    }
}

#[cfg(test)]
mod tests {
    use crate::core::spatial::*;

    #[test]
    fn origin_form_transform_matches_com_form() {
        let i = Inertia::new(
            2.5,
            Vec3::new(0.1, -0.3, 0.2),
            Mat3::new(0.2, 0.01, -0.02, 0.01, 0.3, 0.03, -0.02, 0.03, 0.25),
        );
        let t = Se3::from_xyz_rpy([0.4, -0.2, 0.7], [0.3, 1.1, -0.6]);
        let a = InertiaO::from_inertia(&i).transformed(&t);
        let b = InertiaO::from_inertia(&i.transformed(&t));
        assert!((a.m - b.m).abs() < 1e-15);
        assert!((a.h - b.h).norm() < 1e-14);
        assert!((a.i_o - b.i_o).norm() < 1e-13, "{} vs {}", a.i_o, b.i_o);
        let m = Motion::new(Vec3::new(0.3, 0.4, -0.5), Vec3::new(1.0, -2.0, 0.5));
        let (fa, fb) = (InertiaO::from_inertia(&i).mul_motion(&m), i.mul_motion(&m));
        assert!((fa.f - fb.f).norm() < 1e-14 && (fa.n - fb.n).norm() < 1e-14);
        let mat = InertiaO::from_inertia(&i).to_matrix();
        let x = nalgebra::Vector6::new(0.3, 0.4, -0.5, 1.0, -2.0, 0.5);
        let y = mat * x;
        assert!((y.fixed_rows::<3>(0) - fb.f).norm() < 1e-14);
        assert!((y.fixed_rows::<3>(3) - fb.n).norm() < 1e-14);
    }

    #[test]
    fn rotation_z_to_maps_z_onto_axis() {
        for a in [
            Vec3::x(),
            -Vec3::x(),
            Vec3::y(),
            -Vec3::y(),
            Vec3::z(),
            -Vec3::z(),
            Vec3::new(1.0, 2.0, -3.0).normalize(),
            Vec3::new(0.0, 0.0, -1.0 + 1e-17).normalize(),
        ] {
            let r = rotation_z_to(&a);
            assert!((r * Vec3::z() - a).norm() < 1e-15, "{a:?}");
            assert!((r.determinant() - 1.0).abs() < 1e-14);
            assert!((r.transpose() * r - Mat3::identity()).norm() < 1e-14);
        }
    }

    #[test]
    fn inertia_momentum_matches_6x6_form() {
        // I = [[m 1, -m [c]x], [m [c]x, I_c - m [c]x [c]x]] in (linear, angular) order.
        let c = Vec3::new(0.1, -0.2, 0.3);
        let ic = Mat3::new(2.0, 0.1, 0.0, 0.1, 3.0, 0.2, 0.0, 0.2, 4.0);
        let i = Inertia::new(1.5, c, ic);
        let m = Motion::new(Vec3::new(0.3, 0.4, -0.5), Vec3::new(1.0, -2.0, 0.5));
        let cx = skew(&c);
        let f = m.v * 1.5 - cx * m.w * 1.5;
        let n = cx * m.v * 1.5 + (ic - cx * cx * 1.5) * m.w;
        let got = i.mul_motion(&m);
        assert!((got.f - f).norm() < 1e-14 && (got.n - n).norm() < 1e-14);
    }

    #[test]
    fn adjoint_round_trip_and_power_invariance() {
        let t = Se3::from_xyz_rpy([0.1, 0.2, -0.3], [0.4, -0.5, 0.6]);
        let m = Motion::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 0.25));
        let f = Force::new(Vec3::new(0.3, -0.1, 2.0), Vec3::new(0.7, 0.2, -0.4));
        let back = t.act_inv_motion(&t.act_motion(&m));
        assert!((back.v - m.v).norm() < 1e-14 && (back.w - m.w).norm() < 1e-14);
        let p1 = f.dot_motion(&m);
        let p2 = t.act_force(&f).dot_motion(&t.act_motion(&m));
        assert!((p1 - p2).abs() < 1e-13);
    }
}
