//! Sphere covers of collision primitives, with a stated maximum overshoot.
//!
//! The planner sees the robot as spheres. URDF `<sphere>` elements are taken as given; every
//! other primitive (box, cylinder, capsule), and a mesh ([`crate::planning::mesh_sdf`]), is covered
//! by spheres from its signed distance function `φ` (negative inside) by a greedy medial cover
//! over adaptive cells:
//!
//! 1. **Cells.** The shape's bounding box is cut into cubes, each split in eight while it
//!    may cross the surface (`|φ(g)| ≤ h`, `g` its centre, `h` its half-diagonal) and is
//!    larger than the finest level (`h ≤ δ/4`). A cube with `φ(g) > h` lies outside the
//!    shape (`φ` is 1-Lipschitz) and is dropped; one with `φ(g) < −h` lies inside and is
//!    kept whole; the finest cubes that may cross the surface are kept. The kept cubes
//!    contain the shape, and each lies in the ball `B(g, h)`.
//! 2. **Spheres.** Repeatedly, the deepest kept cell whose ball is not yet covered gets
//!    a sphere of radius `δ − φ(g)` about its centre; it covers every cell whose ball it
//!    contains (`|g' − g| + h' ≤ δ − φ(g)`), its own included (`φ(g) ≤ h ≤ δ/4`).
//!
//! On a sphere of radius `δ − φ(g)` about `g`, `φ ≤ δ`: the **overshoot is at most δ**;
//! every cell's ball is inside a sphere, so the **shape is inside the union**. Deep cells
//! give large spheres first, and the fine cells at the surface let each reach within
//! `δ/4` of its full radius: a tube of radius `R` takes one sphere per
//! `2√(R δ + δ²/2)` of its length (a UR5 link about 20 at δ = 1 cm, where a uniform grid
//! with slack `δ/2` took thousands). The cells are bounded: past 400 000, δ is raised
//! (the bound then holds for the raised δ, which [`cover`] returns). A capsule needs no
//! cells: spheres of radius `R + δ` on its segment, spaced `2√(2Rδ + δ²)`, cover it
//! exactly with overshoot `δ`.

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
/// cells). Any signed distance works (a mesh's, see [`crate::planning::mesh_sdf`]); with an
/// unsigned one (an open mesh) the spheres wrap the surface.
pub fn cover_sdf(
    sdf: &dyn Fn([f64; 3]) -> f64,
    center: [f64; 3],
    he: [f64; 3],
    delta: f64,
) -> (Vec<([f64; 3], f64)>, f64) {
    let mut delta = delta;
    loop {
        if let Some(cells) = cells(sdf, center, he, delta, MAX_CELLS) {
            return (greedy_cover(sdf, cells, delta), delta);
        }
        delta *= 1.25;
    }
}

/// Most cells a cover may use before δ is raised.
const MAX_CELLS: usize = 400_000;

/// A kept cell: centre, half-diagonal, `φ` at the centre.
type Cell = ([f64; 3], f64, f64);

/// The kept cells of step 1 (module docs), or `None` past `max` cells.
fn cells(
    sdf: &dyn Fn([f64; 3]) -> f64,
    center: [f64; 3],
    he: [f64; 3],
    delta: f64,
    max: usize,
) -> Option<Vec<Cell>> {
    // Finest cube side: half-diagonal δ/4. Top cubes: 2^levels finer sides, about 16 δ.
    let fine = delta / (2.0 * 3f64.sqrt());
    let levels = 3;
    let top = fine * f64::from(1 << levels);
    let counts = he.map(|h| ((2.0 * h) / top).ceil().max(1.0) as usize);
    if counts.iter().map(|&c| c as f64).product::<f64>() > max as f64 {
        return None;
    }
    let origin = [0, 1, 2].map(|a| center[a] - 0.5 * top * counts[a] as f64);
    let mut out = Vec::new();
    let mut stack: Vec<([f64; 3], f64)> = Vec::new();
    for i in 0..counts[0] {
        for j in 0..counts[1] {
            for k in 0..counts[2] {
                let g = [i, j, k].map(|x| x as f64 + 0.5);
                stack.push(([0, 1, 2].map(|a| origin[a] + top * g[a]), top));
                while let Some((g, side)) = stack.pop() {
                    let h = side * 3f64.sqrt() / 2.0;
                    let phi = sdf(g);
                    if phi > h {
                        continue;
                    }
                    if phi < -h || side <= fine * (1.0 + 1e-9) {
                        out.push((g, h, phi));
                        if out.len() > max {
                            return None;
                        }
                        continue;
                    }
                    let q = side / 4.0;
                    for c in 0..8 {
                        let d = [0, 1, 2].map(|a| if c >> a & 1 == 1 { q } else { -q });
                        stack.push(([g[0] + d[0], g[1] + d[1], g[2] + d[2]], side / 2.0));
                    }
                }
            }
        }
    }
    Some(out)
}

/// Cells bucketed on a grid, so that a sphere visits only the cells within its reach.
struct Buckets {
    size: f64,
    map: std::collections::HashMap<[i64; 3], Vec<u32>>,
}

impl Buckets {
    fn new(cells: &[Cell], size: f64) -> Buckets {
        let mut b = Buckets {
            size,
            map: Default::default(),
        };
        for (n, c) in cells.iter().enumerate() {
            b.map.entry(b.key(c.0)).or_default().push(n as u32);
        }
        b
    }

    fn key(&self, p: [f64; 3]) -> [i64; 3] {
        p.map(|x| (x / self.size).floor() as i64)
    }

    /// Calls `f` on every cell whose ball lies inside the sphere `(c, r)`.
    fn inside(&self, cells: &[Cell], c: [f64; 3], r: f64, mut f: impl FnMut(usize)) {
        let (lo, hi) = (self.key(c.map(|x| x - r)), self.key(c.map(|x| x + r)));
        for a in lo[0]..=hi[0] {
            for b in lo[1]..=hi[1] {
                for k in lo[2]..=hi[2] {
                    for &n in self.map.get(&[a, b, k]).map_or(&[][..], |v| v.as_slice()) {
                        let (p, h, _) = cells[n as usize];
                        if dist(p, c) + h <= r {
                            f(n as usize);
                        }
                    }
                }
            }
        }
    }
}

fn dist(p: [f64; 3], c: [f64; 3]) -> f64 {
    ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt()
}

/// Step 2 (module docs): for the deepest cell not yet covered, the sphere that covers it
/// and the most other uncovered cells, among centres on its inward normal (`−∇φ`, by
/// central differences) at depths `0, δ/2, …, 8δ`, each of radius `δ − φ(centre)`; until
/// every cell is covered.
fn greedy_cover(
    sdf: &dyn Fn([f64; 3]) -> f64,
    mut cells: Vec<Cell>,
    delta: f64,
) -> Vec<([f64; 3], f64)> {
    // Deepest first; ties broken by position so the cover is deterministic.
    cells.sort_by(|a, b| a.2.total_cmp(&b.2).then(a.0.partial_cmp(&b.0).unwrap()));
    let hmax = cells.iter().map(|c| c.1).fold(0.0, f64::max);
    let buckets = Buckets::new(&cells, (2.0 * hmax).max(delta));
    let mut covered = vec![false; cells.len()];
    let mut out = Vec::new();
    for i in 0..cells.len() {
        if covered[i] {
            continue;
        }
        let (p, h, phi) = cells[i];
        let mut best = (0usize, p, delta - phi);
        let e = delta / 4.0;
        let grad = [0, 1, 2].map(|a| {
            let (mut x, mut y) = (p, p);
            x[a] += e;
            y[a] -= e;
            (sdf(x) - sdf(y)) / (2.0 * e)
        });
        let norm = dist(grad, [0.0; 3]);
        let steps = if norm > 0.5 { 16 } else { 0 };
        for j in 0..=steps {
            let t = j as f64 * delta / 2.0;
            let c = [0, 1, 2].map(|a| p[a] - t * grad[a] / norm.max(1e-300));
            let r = delta - if j == 0 { phi } else { sdf(c) };
            if dist(c, p) + h > r {
                continue;
            }
            let mut gain = 0;
            buckets.inside(&cells, c, r, |n| gain += !covered[n] as usize);
            if gain > best.0 {
                best = (gain, c, r);
            }
        }
        let (_, c, r) = best;
        buckets.inside(&cells, c, r, |n| covered[n] = true);
        covered[i] = true;
        out.push((c, r));
    }
    out
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

#[cfg(test)]
mod tests {
    use crate::planning::spherize::*;

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
