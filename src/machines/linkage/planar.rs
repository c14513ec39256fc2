//! Planar vectors and the small operations every linkage file uses: rotation by an
//! angle, the perpendicular, the planar cross product and angle wrapping.

/// Planar vector.
pub type Vec2 = nalgebra::Vector2<f64>;

/// `A(θ) v`: `v` rotated by `θ` (counter-clockwise positive).
#[inline]
pub fn rotate(theta: f64, v: &Vec2) -> Vec2 {
    let (s, c) = theta.sin_cos();
    Vec2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// `v` turned by +90°: `(−v_y, v_x)`. `d/dθ A(θ) v = perp(A(θ) v)`.
#[inline]
pub fn perp(v: &Vec2) -> Vec2 {
    Vec2::new(-v.y, v.x)
}

/// Planar cross product `a × b = a_x b_y − a_y b_x` (the z component).
#[inline]
pub fn cross(a: &Vec2, b: &Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Angle wrapped to `(−π, π]`.
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let mut x = a % t;
    if x > std::f64::consts::PI {
        x -= t;
    } else if x <= -std::f64::consts::PI {
        x += t;
    }
    x
}
