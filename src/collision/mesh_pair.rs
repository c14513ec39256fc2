//! The distance between two triangle meshes: a simultaneous descent of their box trees,
//! nearer node pairs first, pruned by the best distance so far, with closed-form
//! triangle–triangle distances at the leaves.
//!
//! parry 0.31 measures a mesh against a mesh as a mesh against a *shape*: for each
//! triangle of one near the other mesh's whole box, a fresh search of the other mesh,
//! with GJK at every triangle pair. The iiwa's links 5 and 7 (about 5 000 and 11 000
//! triangles) 3 cm apart took it 15–43 ms a query; this descent takes 1–4.6 ms. Asked only
//! whether two meshes are nearer than a bound, parry's `closest_points` with that margin is
//! faster still (0.27 against 0.72 ms on the same pair), so [`crate::collision`] keeps it
//! for those queries.
//!
//! **Nodes.** Each tree's boxes are axis-aligned in its mesh frame. Two nodes are at least
//! as far apart as the largest of three gaps: their boxes' gap in `a`'s frame, with `b`'s
//! box carried over as the box around its turned box (centre `R c + t`, half sizes
//! `|R| e`); the same in `b`'s frame; and the gap of their balls (around the box centre,
//! to the farthest vertex), which turning does not loosen.
//!
//! **Triangles.** A triangle pair is skipped when their balls or either triangle's plane
//! (all of the other's vertices on one side of it, farther than the best) prove it no
//! nearer than the best pair found; otherwise it is measured in closed form
//! ([`crate::collision::closest_features`]). A zero distance (the meshes meet) is
//! returned as such, and the caller measures the penetration its own way.

use crate::collision::closest_features::triangle_pair;
use parry3d_f64::math::{Matrix, Pose, Vector};

/// Triangles per leaf, at most.
const LEAF: usize = 2;

/// A node: its box (mesh frame) and either two children (`count == 0`: `first` and
/// `first + 1`) or `count` triangles from `first`.
#[derive(Clone, Copy, Debug)]
struct Node {
    centre: Vector,
    half: Vector,
    /// The farthest vertex from `centre`: a ball that turning does not loosen.
    radius: f64,
    first: u32,
    count: u32,
}

/// A triangle mesh's box tree, its triangles in leaf order.
#[derive(Clone, Debug)]
pub struct TriTree {
    nodes: Vec<Node>,
    tris: Vec<[Vector; 3]>,
    /// Per triangle (same order), a ball around it: centre and radius.
    balls: Vec<(Vector, f64)>,
    /// Per triangle, its unit normal `n` and `n · v₀` (zero for a degenerate one).
    planes: Vec<(Vector, f64)>,
}

/// The nearest points of two meshes found by [`TriTree::distance`]: the distance and a
/// point on each (world frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshGap {
    /// Distance; 0 when a triangle of one meets a triangle of the other.
    pub distance: f64,
    /// On the first mesh.
    pub a: Vector,
    /// On the second.
    pub b: Vector,
}

impl TriTree {
    /// The tree of the triangles `indices` over `vertices` (mesh frame).
    pub fn new(vertices: &[Vector], indices: &[[u32; 3]]) -> TriTree {
        let mut tris: Vec<[Vector; 3]> = indices
            .iter()
            .map(|t| t.map(|i| vertices[i as usize]))
            .collect();
        let mut nodes = vec![leaf_box(&tris, 0, tris.len())];
        if tris.len() > LEAF {
            split(&mut nodes, &mut tris, 0);
        }
        let balls = tris
            .iter()
            .map(|t| {
                let c = (t[0] + t[1] + t[2]) / 3.0;
                let r = t.iter().map(|v| (*v - c).length()).fold(0.0, f64::max);
                (c, r)
            })
            .collect();
        let planes = tris
            .iter()
            .map(|t| {
                let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                (n, n.dot(t[0]))
            })
            .collect();
        TriTree {
            nodes,
            tris,
            balls,
            planes,
        }
    }

    /// Whether the mesh has no triangle.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The nearest points of this mesh at `pa` and `other` at `pb` if they are nearer
    /// than `bound` (`f64::INFINITY`: always), else `None`.
    pub fn distance(&self, pa: &Pose, other: &TriTree, pb: &Pose, bound: f64) -> Option<MeshGap> {
        if self.is_empty() || other.is_empty() {
            return None;
        }
        let p = pa.inv_mul(pb);
        let rot = Matrix::from_quat(p.rotation);
        let abs = Matrix::from_cols(rot.x_axis.abs(), rot.y_axis.abs(), rot.z_axis.abs());
        let mut s = Descent {
            a: self,
            b: other,
            pose: p,
            rot,
            abs,
            rot_t: rot.transpose(),
            abs_t: abs.transpose(),
            best2: bound * bound,
            found: None,
        };
        s.visit(0, 0);
        let (a, b) = s.found?;
        let distance = (b - a).length();
        (distance < bound).then(|| MeshGap {
            distance,
            a: *pa * a,
            b: *pa * b,
        })
    }
}

/// The box of triangles `tris[first..first + count]`, as a leaf.
fn leaf_box(tris: &[[Vector; 3]], first: usize, count: usize) -> Node {
    let mut lo = Vector::splat(f64::INFINITY);
    let mut hi = Vector::splat(f64::NEG_INFINITY);
    for t in &tris[first..first + count] {
        for v in t {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    if count == 0 {
        (lo, hi) = (Vector::ZERO, Vector::ZERO);
    }
    let centre = (lo + hi) * 0.5;
    let radius = tris[first..first + count]
        .iter()
        .flatten()
        .map(|v| (*v - centre).length())
        .fold(0.0, f64::max);
    Node {
        centre,
        half: (hi - lo) * 0.5,
        radius,
        first: first as u32,
        count: count as u32,
    }
}

/// Splits leaf `n` (more than [`LEAF`] triangles) at the median of its triangles'
/// centroids along their widest axis, and its halves in turn (iteratively).
fn split(nodes: &mut Vec<Node>, tris: &mut [[Vector; 3]], n: usize) {
    let mut todo = vec![n];
    while let Some(n) = todo.pop() {
        let (first, count) = (nodes[n].first as usize, nodes[n].count as usize);
        let part = &mut tris[first..first + count];
        let centroid = |t: &[Vector; 3]| t[0] + t[1] + t[2];
        let (mut lo, mut hi) = (
            Vector::splat(f64::INFINITY),
            Vector::splat(f64::NEG_INFINITY),
        );
        for t in part.iter() {
            lo = lo.min(centroid(t));
            hi = hi.max(centroid(t));
        }
        let ext = hi - lo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = count / 2;
        part.select_nth_unstable_by(mid, |x, y| centroid(x)[axis].total_cmp(&centroid(y)[axis]));
        let left = nodes.len();
        nodes.push(leaf_box(tris, first, mid));
        nodes.push(leaf_box(tris, first + mid, count - mid));
        nodes[n].first = left as u32;
        nodes[n].count = 0;
        for (k, c) in [(left, mid), (left + 1, count - mid)] {
            if c > LEAF {
                todo.push(k);
            }
        }
    }
}

/// The state of one descent: `b`'s frame in `a`'s, and the best pair so far (in `a`'s
/// frame) with its squared distance.
struct Descent<'t> {
    a: &'t TriTree,
    b: &'t TriTree,
    pose: Pose,
    rot: Matrix,
    abs: Matrix,
    rot_t: Matrix,
    abs_t: Matrix,
    best2: f64,
    found: Option<(Vector, Vector)>,
}

impl Descent<'_> {
    /// Squared gap between node `i` of `a` and node `j` of `b`: the largest of their
    /// balls' gap and the gaps of each box against the box around the other turned into
    /// its frame.
    fn gap2(&self, i: usize, j: usize) -> f64 {
        let (na, nb) = (&self.a.nodes[i], &self.b.nodes[j]);
        let cb = self.pose * nb.centre;
        let in_a = ((na.centre - cb).abs() - na.half - self.abs * nb.half).max(Vector::ZERO);
        let d = self.rot_t * (na.centre - cb);
        let in_b = (d.abs() - nb.half - self.abs_t * na.half).max(Vector::ZERO);
        let ball = ((na.centre - cb).length() - na.radius - nb.radius).max(0.0);
        in_a.length_squared()
            .max(in_b.length_squared())
            .max(ball * ball)
    }

    /// Descends the node pair `(i, j)`, whose gap is below the best so far.
    fn visit(&mut self, i: usize, j: usize) {
        if self.best2 == 0.0 {
            return;
        }
        let (na, nb) = (self.a.nodes[i], self.b.nodes[j]);
        if na.count > 0 && nb.count > 0 {
            self.leaves(&na, &nb);
            return;
        }
        // Split the node that is not a leaf, or the larger one.
        let split_a =
            nb.count > 0 || (na.count == 0 && na.half.length_squared() >= nb.half.length_squared());
        let pairs = if split_a {
            let k = na.first as usize;
            [(k, j), (k + 1, j)]
        } else {
            let k = nb.first as usize;
            [(i, k), (i, k + 1)]
        };
        let g = [
            self.gap2(pairs[0].0, pairs[0].1),
            self.gap2(pairs[1].0, pairs[1].1),
        ];
        let order = if g[1] < g[0] { [1, 0] } else { [0, 1] };
        for k in order {
            if g[k] < self.best2 {
                self.visit(pairs[k].0, pairs[k].1);
            }
        }
    }

    /// Every triangle pair of two leaves that neither their balls nor their planes
    /// prove no nearer than the best so far.
    fn leaves(&mut self, na: &Node, nb: &Node) {
        let (a, b) = (self.a, self.b);
        for jb in nb.first as usize..(nb.first + nb.count) as usize {
            let (cb, rad_b) = b.balls[jb];
            let cb = self.pose * cb;
            let mut placed: Option<([Vector; 3], Vector, f64)> = None;
            for ia in na.first as usize..(na.first + na.count) as usize {
                let (ca, rad_a) = a.balls[ia];
                let gap = (ca - cb).length() - rad_a - rad_b;
                if gap > 0.0 && gap * gap >= self.best2 {
                    continue;
                }
                let (t, nt, ot) = *placed.get_or_insert_with(|| {
                    let v = &b.tris[jb];
                    let t = [self.pose * v[0], self.pose * v[1], self.pose * v[2]];
                    let n = self.rot * b.planes[jb].0;
                    (t, n, n.dot(t[0]))
                });
                let s = &a.tris[ia];
                let (ns, os) = a.planes[ia];
                let gap = plane_gap(ns, os, &t).max(plane_gap(nt, ot, s));
                if gap > 0.0 && gap * gap >= self.best2 {
                    continue;
                }
                let (d2, p, q) = triangle_pair(s, &t);
                if d2 < self.best2 {
                    self.best2 = d2;
                    self.found = Some((p, q));
                }
            }
        }
    }
}

/// How far the points `v` all lie on one side of the plane `n · x = o` (`n` a unit
/// normal, or zero): a lower bound of their distance to anything in the plane; negative
/// when the plane runs between them.
#[inline]
fn plane_gap(n: Vector, o: f64, v: &[Vector; 3]) -> f64 {
    let d = [n.dot(v[0]) - o, n.dot(v[1]) - o, n.dot(v[2]) - o];
    let (lo, hi) = (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]));
    lo.max(-hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::closest_features::closest_on_triangle;
    use parry3d_f64::math::Rotation;
    use parry3d_f64::query;
    use parry3d_f64::shape::{TriMesh, Triangle};

    /// A deterministic pseudo-random stream in [0, 1).
    fn stream(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn point(r: &mut impl FnMut() -> f64, scale: f64) -> Vector {
        Vector::new(r() - 0.5, r() - 0.5, r() - 0.5) * scale
    }

    #[test]
    fn triangle_pair_distance_equals_parrys_gjk_distance() {
        let mut r = stream(7);
        let mut met = 0;
        for k in 0..4000 {
            let s = [0, 1, 2].map(|_| point(&mut r, 1.0));
            let off = point(&mut r, if k % 2 == 0 { 1.5 } else { 0.4 });
            let t = [0, 1, 2].map(|_| point(&mut r, 1.0) + off);
            let (d2, p, q) = triangle_pair(&s, &t);
            let id = Pose::IDENTITY;
            let reference = query::distance(
                &id,
                &Triangle::new(s[0], s[1], s[2]),
                &id,
                &Triangle::new(t[0], t[1], t[2]),
            )
            .unwrap()
            .distance;
            let d = d2.sqrt();
            assert!((d - reference).abs() < 1e-9, "{k}: {d} vs {reference}");
            assert!(((q - p).length() - d).abs() < 1e-12);
            // The points lie on their triangles.
            assert!((closest_on_triangle(p, &s) - p).length() < 1e-9);
            assert!((closest_on_triangle(q, &t) - q).length() < 1e-9);
            met += usize::from(d == 0.0);
        }
        assert!(met > 100, "only {met} meeting pairs drawn");
    }

    /// A closed, bumpy sphere of `n × 2n` quads around `c`.
    fn bumpy(n: usize, c: Vector, r0: f64, seed: u64) -> (Vec<Vector>, Vec<[u32; 3]>) {
        let mut r = stream(seed);
        let mut v = vec![];
        for i in 0..=n {
            for j in 0..2 * n {
                let th = std::f64::consts::PI * i as f64 / n as f64;
                let ph = std::f64::consts::PI * j as f64 / n as f64;
                let rad = r0 * (1.0 + 0.1 * r());
                v.push(c + Vector::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * rad);
            }
        }
        let m = 2 * n as u32;
        let mut f = vec![];
        for i in 0..n as u32 {
            for j in 0..m {
                let (a, b) = (i * m + j, i * m + (j + 1) % m);
                let (c, d) = (a + m, b + m);
                f.push([a, c, b]);
                f.push([b, c, d]);
            }
        }
        (v, f)
    }

    #[test]
    fn mesh_distance_equals_parrys_composite_distance() {
        let mut r = stream(3);
        let (va, fa) = bumpy(12, Vector::ZERO, 0.3, 1);
        let (vb, fb) = bumpy(9, Vector::new(0.1, 0.0, 0.05), 0.2, 2);
        let (ta, tb) = (TriTree::new(&va, &fa), TriTree::new(&vb, &fb));
        let (ma, mb) = (TriMesh::new(va, fa).unwrap(), TriMesh::new(vb, fb).unwrap());
        let mut apart = 0;
        for k in 0..40 {
            let pa = Pose::from_parts(
                point(&mut r, 0.2),
                Rotation::from_scaled_axis(point(&mut r, 3.0)),
            );
            let pb = Pose::from_parts(
                point(&mut r, 0.2) + Vector::new(0.45 + 0.2 * r(), 0.0, 0.0),
                Rotation::from_scaled_axis(point(&mut r, 3.0)),
            );
            let reference = query::distance(&pa, &ma, &pb, &mb).unwrap().distance;
            apart += usize::from(reference > 0.0);
            let got = ta
                .distance(&pa, &tb, &pb, f64::INFINITY)
                .map_or(0.0, |g| g.distance);
            assert!(
                (got - reference).abs() < 1e-7 * (1.0 + reference),
                "{k}: {got} vs {reference}"
            );
            if let Some(g) = ta.distance(&pa, &tb, &pb, f64::INFINITY) {
                assert!(((g.b - g.a).length() - g.distance).abs() < 1e-12);
            }
            // A bound below the distance proves it is not nearer; above, the same answer.
            assert!(ta.distance(&pa, &tb, &pb, reference * 0.999).is_none());
            let under = ta.distance(&pa, &tb, &pb, reference * 1.001 + 1e-9);
            assert!((under.map_or(-1.0, |g| g.distance) - got).abs() < 1e-15);
        }
        assert!((25..40).contains(&apart), "{apart} of 40 poses apart");
    }

    #[test]
    fn iiwa_wrist_links_distance_equals_parrys_composite_distance() {
        // Real meshes: the iiwa's link 5 and link 7 collision STLs (about 5 000 and
        // 11 000 triangles), a few centimetres to a decimetre apart.
        let root =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/meshes/iiwa14/collision");
        let load = |name: &str| {
            let m = crate::collision::mesh::load_mesh(&root.join(name)).unwrap();
            let v: Vec<Vector> = m
                .vertices
                .iter()
                .map(|p| Vector::new(p[0], p[1], p[2]))
                .collect();
            (v, m.triangles)
        };
        let ((va, fa), (vb, fb)) = (load("link_5.stl"), load("link_7.stl"));
        assert!(
            fa.len() > 4000 && fb.len() > 10000,
            "{} {}",
            fa.len(),
            fb.len()
        );
        let (ta, tb) = (TriTree::new(&va, &fa), TriTree::new(&vb, &fb));
        let (ma, mb) = (TriMesh::new(va, fa).unwrap(), TriMesh::new(vb, fb).unwrap());
        let mut r = stream(11);
        let mut apart = 0;
        for k in 0..8 {
            let pa = Pose::from_parts(Vector::ZERO, Rotation::from_scaled_axis(point(&mut r, 3.0)));
            let pb = Pose::from_parts(
                Vector::new(0.0, 0.0, 0.25 + 0.1 * r()) + point(&mut r, 0.1),
                Rotation::from_scaled_axis(point(&mut r, 3.0)),
            );
            let reference = query::distance(&pa, &ma, &pb, &mb).unwrap().distance;
            let got = ta
                .distance(&pa, &tb, &pb, f64::INFINITY)
                .map_or(0.0, |g| g.distance);
            assert!((got - reference).abs() < 1e-7, "{k}: {got} vs {reference}");
            apart += usize::from(reference > 0.01);
        }
        assert!(apart >= 4, "{apart} of 8 poses a centimetre apart");
    }
}
