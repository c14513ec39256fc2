//! Closest points of the simplest features, in closed form (Ericson, *Real-Time Collision
//! Detection*, 5.1.5 and 5.1.9): two segments, a point and a triangle, two triangles. The
//! swept spheres of [`crate::collision`]'s shapes and the triangle pairs of the mesh–mesh
//! distance rest on them.

use parry3d_f64::math::Vector;

/// Closest points of segments `p1`–`q1` and `p2`–`q2` (Ericson, *Real-Time Collision
/// Detection*, §5.1.9), parallel and degenerate segments included.
pub fn closest_segments(p1: Vector, q1: Vector, p2: Vector, q2: Vector) -> (Vector, Vector) {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let tiny = 1e-300;
    let (s, t) = if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            // Parallel segments: any s works, t (and then s) are clamped below.
            let s = if denom > 1e-14 * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    (p1 + d1 * s, p2 + d2 * t)
}

/// Squared distance and nearest points of triangles `s` and `t` (0 and a common point
/// when they meet).
pub fn triangle_pair(s: &[Vector; 3], t: &[Vector; 3]) -> (f64, Vector, Vector) {
    let mut best = (f64::INFINITY, s[0], t[0]);
    let mut keep = |d2: f64, p: Vector, q: Vector| {
        if d2 < best.0 {
            best = (d2, p, q);
        }
    };
    for i in 0..3 {
        let (p0, p1) = (s[i], s[(i + 1) % 3]);
        for j in 0..3 {
            let (c1, c2) = closest_segments(p0, p1, t[j], t[(j + 1) % 3]);
            keep((c2 - c1).length_squared(), c1, c2);
        }
    }
    for v in s {
        let q = closest_on_triangle(*v, t);
        keep((q - *v).length_squared(), *v, q);
    }
    for v in t {
        let p = closest_on_triangle(*v, s);
        keep((*v - p).length_squared(), p, *v);
    }
    if best.0 > 0.0 {
        for (x, y) in [(s, t), (t, s)] {
            for i in 0..3 {
                if let Some(c) = edge_crosses(x[i], x[(i + 1) % 3], y) {
                    return (0.0, c, c);
                }
            }
        }
    }
    best
}

/// The point of triangle `t` nearest to `p` (Ericson 5.1.5, by Voronoi regions).
pub fn closest_on_triangle(p: Vector, t: &[Vector; 3]) -> Vector {
    let (a, b, c) = (t[0], t[1], t[2]);
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom <= 0.0 {
        // A degenerate (flat) triangle: its edges hold the nearest point.
        let cands = [
            closest_segments(p, p, a, b).1,
            closest_segments(p, p, b, c).1,
            closest_segments(p, p, c, a).1,
        ];
        return cands
            .into_iter()
            .min_by(|x, y| {
                (*x - p)
                    .length_squared()
                    .total_cmp(&(*y - p).length_squared())
            })
            .unwrap_or(a);
    }
    let (v, w) = (vb / denom, vc / denom);
    a + ab * v + ac * w
}

/// Where segment `p q` crosses the face of triangle `t` (strictly from one side to the
/// other, or touching it at an end), if it does.
fn edge_crosses(p: Vector, q: Vector, t: &[Vector; 3]) -> Option<Vector> {
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let (dp, dq) = (n.dot(p - t[0]), n.dot(q - t[0]));
    if (dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || dp == dq {
        return None;
    }
    let x = p + (q - p) * (dp / (dp - dq));
    let inside = (0..3).all(|i| {
        let (u, v) = (t[i], t[(i + 1) % 3]);
        n.dot((v - u).cross(x - u)) >= 0.0
    });
    inside.then_some(x)
}
