//! Sphere covers of collision primitives, with a stated maximum overshoot.
//!
//! The planner sees the robot as spheres. URDF `<sphere>` elements are taken as given; every
//! other primitive (box, cylinder, capsule), and a mesh ([`super::mesh_sdf`]), is covered by spheres from its signed distance
//! function `φ` (negative inside) by a greedy medial cover:
//!
//! 1. grid points `p` at spacing `s` over the shape's bounding box, keeping those with
//!    `φ(p) ≤ s√3/2` (every point of the shape is within `s√3/2` of a kept point);
//! 2. repeatedly, the deepest uncovered point `p` gets a sphere of radius `δ − φ(p)`; it
//!    marks as covered the points within `radius − s√3/2` of its centre.
//!
//! `φ` is 1-Lipschitz, so on a sphere of radius `δ − φ(p)` about `p`, `φ ≤ δ`: the
//! **overshoot is at most δ**. With `s = δ/√3` the slack `s√3/2` is `δ/2` and every kept
//! point has `φ ≤ δ/2`, so every sphere has radius ≥ `δ/2` ≥ the slack: a point of the shape
//! is within the slack of a kept grid point, which is either the centre of a sphere (and
//! inside it) or within `radius − slack` of one; so the **shape is inside the union**.
//! For primitives of more than about 70 δ per axis, δ is raised until the grid has at most
//! 400 000 points (the bound then holds for the raised δ, which [`cover`] returns). A capsule needs no grid: spheres of radius `R + δ` on its
//! segment, spaced `2√(2Rδ + δ²)`, cover it exactly with overshoot `δ`.

/// A primitive in its own frame (boxes by half extents; cylinders and capsules along z).
#[derive(Clone, Copy, Debug)]
pub enum Primitive {
    /// Half extents.
    Box([f64; 3]),
    /// Radius, half length.
    Cylinder(f64, f64),
    /// Radius, half length of the segment.
    Capsule(f64, f64),
    /// Radius.
    Sphere(f64),
}

impl Primitive {
    /// Signed distance from `p` to the surface (negative inside).
    pub fn sdf(&self, p: [f64; 3]) -> f64 {
        match *self {
            Primitive::Box(h) => {
                let q = [p[0].abs() - h[0], p[1].abs() - h[1], p[2].abs() - h[2]];
                let out =
                    (q[0].max(0.0).powi(2) + q[1].max(0.0).powi(2) + q[2].max(0.0).powi(2)).sqrt();
                out + q[0].max(q[1]).max(q[2]).min(0.0)
            }
            Primitive::Cylinder(r, h) => {
                let dr = (p[0] * p[0] + p[1] * p[1]).sqrt() - r;
                let dz = p[2].abs() - h;
                (dr.max(0.0).powi(2) + dz.max(0.0).powi(2)).sqrt() + dr.max(dz).min(0.0)
            }
            Primitive::Capsule(r, h) => {
                let z = p[2].clamp(-h, h);
                (p[0] * p[0] + p[1] * p[1] + (p[2] - z).powi(2)).sqrt() - r
            }
            Primitive::Sphere(r) => (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - r,
        }
    }

    /// Half extents of the bounding box.
    fn half_extents(&self) -> [f64; 3] {
        match *self {
            Primitive::Box(h) => h,
            Primitive::Cylinder(r, h) => [r, r, h],
            Primitive::Capsule(r, h) => [r, r, h + r],
            Primitive::Sphere(r) => [r; 3],
        }
    }
}

/// Spheres `(centre, radius)` in the primitive's frame covering it, and the overshoot bound
/// they meet (`delta`, or more for very large primitives: see the module docs).
pub fn cover(shape: &Primitive, delta: f64) -> (Vec<([f64; 3], f64)>, f64) {
    match *shape {
        Primitive::Sphere(r) => (vec![([0.0; 3], r)], 0.0),
        Primitive::Capsule(r, h) => (cover_capsule(r, h, delta), delta),
        _ => cover_sdf(&|p| shape.sdf(p), [0.0; 3], shape.half_extents(), delta),
    }
}

/// The greedy medial cover (module docs) of the shape with signed distance `sdf` inside
/// the box `center ± he`, and the overshoot bound it meets (`delta`, raised past 400 000
/// grid points). Any signed distance works (a mesh's, see [`super::mesh_sdf`]); with an
/// unsigned one (an open mesh) the spheres wrap the surface.
pub fn cover_sdf(
    sdf: &dyn Fn([f64; 3]) -> f64,
    center: [f64; 3],
    he: [f64; 3],
    delta: f64,
) -> (Vec<([f64; 3], f64)>, f64) {
    let mut delta = delta;
    let points = |d: f64| {
        he.iter()
            .map(|h| (2.0 * h / (d / 3f64.sqrt())).ceil() + 1.0)
            .product::<f64>()
    };
    while points(delta) > 4e5 {
        delta *= 1.25;
    }
    (cover_grid(sdf, center, he, delta), delta)
}

fn cover_capsule(r: f64, h: f64, delta: f64) -> Vec<([f64; 3], f64)> {
    let big = r + delta;
    let reach = (big * big - r * r).sqrt(); // half the spacing that keeps the cover closed
    let n = ((2.0 * h) / (2.0 * reach)).ceil().max(0.0) as usize;
    (0..=n)
        .map(|i| {
            let z = if n == 0 {
                0.0
            } else {
                -h + 2.0 * h * i as f64 / n as f64
            };
            ([0.0, 0.0, z], big)
        })
        .collect()
}

fn cover_grid(
    sdf: &dyn Fn([f64; 3]) -> f64,
    center: [f64; 3],
    he: [f64; 3],
    delta: f64,
) -> Vec<([f64; 3], f64)> {
    let s = delta / 3f64.sqrt();
    let slack = s * 3f64.sqrt() / 2.0;
    let counts = he.map(|h| ((2.0 * h) / s).ceil() as usize + 1);
    let mut pts: Vec<([f64; 3], f64)> = Vec::new();
    for i in 0..counts[0] {
        for j in 0..counts[1] {
            for k in 0..counts[2] {
                let p = [
                    center[0] - he[0] + (2.0 * he[0]) * i as f64 / (counts[0] - 1).max(1) as f64,
                    center[1] - he[1] + (2.0 * he[1]) * j as f64 / (counts[1] - 1).max(1) as f64,
                    center[2] - he[2] + (2.0 * he[2]) * k as f64 / (counts[2] - 1).max(1) as f64,
                ];
                let phi = sdf(p);
                if phi <= slack {
                    pts.push((p, phi));
                }
            }
        }
    }
    // Deepest first; ties broken by position so the cover is deterministic.
    pts.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.partial_cmp(&b.0).unwrap()));
    let mut covered = vec![false; pts.len()];
    let mut out = Vec::new();
    for i in 0..pts.len() {
        if covered[i] {
            continue;
        }
        let (c, phi) = pts[i];
        let r = delta - phi;
        let reach2 = (r - slack).max(0.0).powi(2);
        for (k, (p, _)) in pts.iter().enumerate() {
            let d2 = (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2);
            if d2 <= reach2 {
                covered[k] = true;
            }
        }
        covered[i] = true;
        out.push((c, r));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checks both claims on a dense random sample: every point of the shape is inside
    /// some sphere, and no sphere reaches further than `delta` outside the shape.
    fn check_cover(shape: Primitive, delta: f64) -> usize {
        let (spheres, used) = cover(&shape, delta);
        assert_eq!(used, delta);
        let he = shape.half_extents();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..20000 {
            let p = [rnd() * he[0], rnd() * he[1], rnd() * he[2]];
            if shape.sdf(p) <= 0.0 {
                let inside = spheres.iter().any(|(c, r)| {
                    ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt()
                        <= *r + 1e-12
                });
                assert!(inside, "{shape:?}: point {p:?} not covered");
            }
        }
        for (c, r) in &spheres {
            // The farthest a sphere reaches outside: max over its surface of φ, sampled.
            for _ in 0..400 {
                let d = [rnd(), rnd(), rnd()];
                let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-9);
                let p = [
                    c[0] + r * d[0] / n,
                    c[1] + r * d[1] / n,
                    c[2] + r * d[2] / n,
                ];
                assert!(
                    shape.sdf(p) <= delta + 1e-12,
                    "{shape:?}: overshoot at {p:?}"
                );
            }
        }
        spheres.len()
    }

    #[test]
    fn covers_contain_the_shape_and_overshoot_at_most_delta() {
        check_cover(Primitive::Box([0.05, 0.1, 0.2]), 0.01);
        check_cover(Primitive::Cylinder(0.06, 0.15), 0.01);
        check_cover(Primitive::Capsule(0.05, 0.2), 0.005);
        check_cover(Primitive::Box([0.3, 0.01, 0.01]), 0.004);
    }

    #[test]
    fn capsule_cover_is_spheres_of_radius_r_plus_delta_on_the_segment() {
        let (s, _) = cover(&Primitive::Capsule(0.05, 0.2), 0.01);
        // Spacing 2√(2Rδ + δ²) = 2√0.0011 ≈ 0.0663 → ceil(0.4 / 0.0663) = 7 gaps.
        assert_eq!(s.len(), 8);
        assert!(s.iter().all(|(_, r)| (*r - 0.06).abs() < 1e-15));
    }

    #[test]
    fn sdf_of_a_box_is_euclidean_outside_and_minus_the_face_distance_inside() {
        let b = Primitive::Box([1.0, 2.0, 3.0]);
        assert!((b.sdf([2.0, 3.0, 0.0]) - 2f64.sqrt()).abs() < 1e-15);
        assert!((b.sdf([0.5, 0.0, 0.0]) + 0.5).abs() < 1e-15);
    }
}
