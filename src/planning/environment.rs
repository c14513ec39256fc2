//! The planning environment: exact obstacle primitives in f32, and the lane test "does a
//! sphere (one per lane) overlap this obstacle".
//!
//! Each test is the closed-form distance from the sphere centre to the solid, compared
//! with the radius (squared, no square root where it can be avoided):
//! - sphere: `|c − o|² < (r + R)²`;
//! - box: `p = Rᵀ(c − o)`, `d_i = max(|p_i| − h_i, 0)`, `|d|² < r²` (zero inside);
//! - cylinder along its z: `d_ρ = max(√(p_x² + p_y²) − R, 0)`, `d_z = max(|p_z| − h, 0)`,
//!   `d_ρ² + d_z² < r²` (the point-to-rectangle distance in the plane through the axis);
//! - capsule along its z: `p_z` clamped to `[−h, h]`, `|p − (0, 0, z)|² < (r + R)²`.
//!
//! Touching counts as free (strict `<`), as in the dense re-check of the tests.

use crate::collision::Obstacle;
use crate::model::Shape;
use crate::planning::lanes::{Mask, P3};
use crate::planning::plan_error::PlanSetupError;
use crate::planning::simd::{Simd, W};

/// Shape of an [`EnvObstacle`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EnvShape {
    /// Sphere of this radius.
    Sphere(f32),
    /// Box with these half extents.
    Box([f32; 3]),
    /// Cylinder along local z: radius, half length.
    Cylinder(f32, f32),
    /// Capsule along local z: radius, half length of the segment.
    Capsule(f32, f32),
}

/// An obstacle as the checker uses it.
#[derive(Clone, Debug)]
pub struct EnvObstacle {
    /// Shape in its frame.
    pub shape: EnvShape,
    /// World position of its frame.
    pub center: [f32; 3],
    /// `Rᵀ` (world → obstacle frame), row-major.
    pub rot_t: [[f32; 3]; 3],
    /// Radius of a sphere about `center` containing the obstacle.
    pub bound: f32,
}

/// Obstacles, with their names for reports.
#[derive(Clone, Debug, Default)]
pub struct Environment {
    /// The obstacles.
    pub obstacles: Vec<EnvObstacle>,
    /// Their names.
    pub names: Vec<String>,
}

impl Environment {
    /// Converts obstacles; meshes are refused with the obstacle's name.
    pub fn new(obstacles: &[Obstacle]) -> Result<Environment, PlanSetupError> {
        let mut env = Environment::default();
        for o in obstacles {
            env.push(o)?;
        }
        Ok(env)
    }

    /// Adds one obstacle.
    pub fn push(&mut self, o: &Obstacle) -> Result<(), PlanSetupError> {
        let f = |x: f64| x as f32;
        let (shape, bound) = match &o.shape {
            Shape::Sphere { radius } => (EnvShape::Sphere(f(*radius)), *radius),
            Shape::Box { size } => {
                let h = size.map(|s| s / 2.0);
                let b = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
                (EnvShape::Box(h.map(f)), b)
            }
            Shape::Cylinder { radius, length } => (
                EnvShape::Cylinder(f(*radius), f(length / 2.0)),
                (radius * radius + length * length / 4.0).sqrt(),
            ),
            Shape::Capsule { radius, length } => (
                EnvShape::Capsule(f(*radius), f(length / 2.0)),
                radius + length / 2.0,
            ),
            Shape::Mesh { uri, .. } => {
                return Err(PlanSetupError::Obstacle {
                    name: o.name.clone(),
                    problem: format!(
                        "mesh obstacles ('{uri}') are not supported by the planner; use boxes, \
                         spheres, cylinders or capsules"
                    ),
                })
            }
        };
        let r = o.pose.rot;
        let t = o.pose.trans;
        self.obstacles.push(EnvObstacle {
            shape,
            center: [f(t.x), f(t.y), f(t.z)],
            rot_t: [
                [f(r[(0, 0)]), f(r[(1, 0)]), f(r[(2, 0)])],
                [f(r[(0, 1)]), f(r[(1, 1)]), f(r[(2, 1)])],
                [f(r[(0, 2)]), f(r[(1, 2)]), f(r[(2, 2)])],
            ],
            bound: (bound * (1.0 + 1e-6)) as f32,
        });
        self.names.push(o.name.clone());
        Ok(())
    }

    /// Number of obstacles.
    pub fn len(&self) -> usize {
        self.obstacles.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.obstacles.is_empty()
    }
}

impl EnvObstacle {
    /// Lanes where the sphere `(c, r)` overlaps the obstacle.
    #[inline(always)]
    pub fn overlaps<S: Simd>(&self, tok: S, c: &P3<S>, r: W<S>) -> Mask {
        let o = &self.center;
        let dx = c.x - tok.splat(o[0]);
        let dy = c.y - tok.splat(o[1]);
        let dz = c.z - tok.splat(o[2]);
        let local = |k: usize| {
            let m = &self.rot_t[k];
            tok.splat(m[0])
                .mul_add(dx, tok.splat(m[1]).mul_add(dy, tok.splat(m[2]) * dz))
        };
        let zero = tok.splat(0.0);
        match self.shape {
            EnvShape::Sphere(rad) => {
                let rr = r + tok.splat(rad);
                W::norm2(dx, dy, dz).lt(rr * rr)
            }
            EnvShape::Box(h) => {
                let ex = (local(0).abs() - tok.splat(h[0])).max(zero);
                let ey = (local(1).abs() - tok.splat(h[1])).max(zero);
                let ez = (local(2).abs() - tok.splat(h[2])).max(zero);
                W::norm2(ex, ey, ez).lt(r * r)
            }
            EnvShape::Cylinder(rad, h) => {
                let (px, py) = (local(0), local(1));
                let er = (px.mul_add(px, py * py).sqrt() - tok.splat(rad)).max(zero);
                let ez = (local(2).abs() - tok.splat(h)).max(zero);
                er.mul_add(er, ez * ez).lt(r * r)
            }
            EnvShape::Capsule(rad, h) => {
                let pz = local(2);
                let z = pz.max(tok.splat(-h)).min(tok.splat(h));
                let rr = r + tok.splat(rad);
                W::norm2(local(0), local(1), pz - z).lt(rr * rr)
            }
        }
    }

    /// Lanes where a sphere of radius `r` at `c`, moving with velocity `vel` (per unit of
    /// the edge parameter) and acceleration at most `2k`, may come within `r` of the
    /// obstacle within `h` of now. The distance `D` to a convex solid is convex and `C¹`
    /// outside it with a unit gradient `ĝ`, so `D'' ≥ ĝ·c'' ≥ −2k` and `D` stays above `r`
    /// where `D ≥ r + |ĝ·vel| h + k h²`. With `e = D ĝ` (centre minus the nearest point)
    /// the test is `D² ≥ (r + k h²) D + |e·vel| h`; inside (`D = 0`) it is a hit.
    #[inline(always)]
    pub fn rate_overlaps<S: Simd>(
        &self,
        tok: S,
        c: &P3<S>,
        vel: &P3<S>,
        r: W<S>,
        h: W<S>,
        k: W<S>,
    ) -> Mask {
        let o = &self.center;
        let d = [
            c.x - tok.splat(o[0]),
            c.y - tok.splat(o[1]),
            c.z - tok.splat(o[2]),
        ];
        let world = [vel.x, vel.y, vel.z];
        let (p, v) = (self.to_local(tok, &d), self.to_local(tok, &world));
        let zero = tok.splat(0.0);
        // `e` (centre minus nearest point, obstacle frame) and the surface's offset `s`
        // from the point set `e` is measured to (a sphere's centre, a capsule's segment).
        let (e, s) = match self.shape {
            EnvShape::Sphere(rad) => (p, rad),
            EnvShape::Capsule(rad, hl) => {
                let z = p[2].max(tok.splat(-hl)).min(tok.splat(hl));
                ([p[0], p[1], p[2] - z], rad)
            }
            EnvShape::Box(hb) => {
                // (No array `map`: its closure would not inline into the SIMD callers.)
                let off = |i: usize| p[i] - p[i].max(tok.splat(-hb[i])).min(tok.splat(hb[i]));
                ([off(0), off(1), off(2)], 0.0)
            }
            EnvShape::Cylinder(rad, hl) => {
                let rho = p[0].mul_add(p[0], p[1] * p[1]).sqrt();
                // Radial part scaled by (ρ − R)⁺/ρ; ρ = 0 lies inside radially.
                let out = (rho - tok.splat(rad)).max(zero);
                let scale = out * recip_or_zero(tok, rho);
                let z = p[2] - p[2].max(tok.splat(-hl)).min(tok.splat(hl));
                ([p[0] * scale, p[1] * scale, z], 0.0)
            }
        };
        let len = W::norm2(e[0], e[1], e[2]).sqrt();
        let dist = len - tok.splat(s);
        let rate = (e[0] * v[0] + e[1] * v[1] + e[2] * v[2]).abs();
        // D ≥ r + |ê·vel| h + k h², times |e| (> 0 wherever D > 0).
        let lhs = (dist - r - k * h * h) * len;
        let safe = (rate * h).lt(lhs) & zero.lt(dist);
        !safe
    }

    /// `Rᵀ v`: a world vector in the obstacle's frame (a method, not a closure, so that it
    /// inlines into the `#[target_feature]` callers with its intrinsics).
    #[inline(always)]
    fn to_local<S: Simd>(&self, tok: S, v: &[W<S>; 3]) -> [W<S>; 3] {
        let m = &self.rot_t;
        let row = |k: usize| {
            tok.splat(m[k][0]).mul_add(
                v[0],
                tok.splat(m[k][1]).mul_add(v[1], tok.splat(m[k][2]) * v[2]),
            )
        };
        [row(0), row(1), row(2)]
    }

    /// Lanes where the sphere `(c, r)` overlaps the obstacle's bounding sphere.
    #[inline(always)]
    pub fn near<S: Simd>(&self, tok: S, c: &P3<S>, r: W<S>) -> Mask {
        let rr = r + tok.splat(self.bound);
        c.dist2(&P3::splat(tok, &self.center)).lt(rr * rr)
    }
}

/// `1/x` where `x > 0`, else 0 (no division in the lane types: `x` is a length).
#[inline(always)]
fn recip_or_zero<S: Simd>(tok: S, x: W<S>) -> W<S> {
    let mut l = S::store(x);
    for v in &mut l.0 {
        *v = if *v > 0.0 { 1.0 / *v } else { 0.0 };
    }
    tok.load(&l)
}
