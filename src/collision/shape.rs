//! Collision shapes (parry3d-f64 shapes built from [`crate::model::Shape`]) and the
//! pairwise queries: intersection, signed distance and witness points.
//!
//! parry 0.31 works in glam types (`glamx::DPose3`, `DVec3`, `DQuat`); [`to_pose`] and
//! [`to_vec3`] convert at this boundary, so nothing outside this module sees them.
//!
//! Conventions: URDF cylinders and capsules are along z (parry's cylinder is along y: it
//! is turned by +90° about x); box sizes are full side lengths; a mesh is scaled per axis
//! (a negative scale product reverses the triangle winding) and becomes either a triangle
//! mesh or, with the convex-hull option, its convex hull.
//!
//! **Signed distance.** Positive: the separation; negative: minus the penetration depth
//! (the shortest translation that separates the shapes).
//! - Two spheres/capsules: closed form (segment–segment distance minus the radii), exact
//!   both ways.
//! - A capsule and a box, cylinder or convex hull: the capsule's segment against the shape
//!   (GJK; EPA when they overlap), minus the radius, exact both ways, and much faster than
//!   GJK on the rounded shape, which converges slowly near contact.
//! - Two triangle meshes apart: closed-form triangle distances over both meshes' box
//!   trees descended together ([`crate::collision::mesh_pair`]); a query bounded by a
//!   margin (is the distance below it?) uses parry's `closest_points`, faster there.
//! - Other pairs: parry's `distance` when apart (spheres against anything by point
//!   projection; GJK otherwise, to a relative 1.5e-7); when overlapping, GJK+EPA for convex
//!   pairs (exact for polytopes) with buffers kept in [`Scratch`], and parry's `contact`
//!   for spheres (exact) and triangle meshes (the deepest *triangle* contact: crossing
//!   surfaces report a depth near 0; use convex hulls when depths matter).
//! - A triangle mesh is a surface, so a shape wholly inside a *closed* mesh touches no
//!   triangle: that case is caught by a containment test (a point of the inner shape
//!   against the mesh's pseudo-normals) and reported as minus the distance to the
//!   enclosing surface, a lower bound of the depth. Open meshes are surfaces only.

use crate::collision::closest_features::closest_segments;
use crate::collision::mesh::MeshData;
use crate::collision::mesh_pair::{MeshGap, TriTree};
use crate::collision::shape_error::ShapeError;
use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::model::Shape;
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Matrix, Pose, Rotation, Vector};
use parry3d_f64::query::epa::EPA;
use parry3d_f64::query::gjk::{self, CsoPoint, GJKResult, VoronoiSimplex};
use parry3d_f64::query::{self, ClosestPoints};
use parry3d_f64::shape::{Segment, SharedShape, SupportMap, TriMesh, TriMeshFlags};
use std::sync::{Arc, OnceLock};

/// Se3 (nalgebra) → parry pose (glam).
#[inline]
pub fn to_pose(m: &Se3) -> Pose {
    let r = &m.rot;
    let mat = Matrix::from_cols(
        Vector::new(r[(0, 0)], r[(1, 0)], r[(2, 0)]),
        Vector::new(r[(0, 1)], r[(1, 1)], r[(2, 1)]),
        Vector::new(r[(0, 2)], r[(1, 2)], r[(2, 2)]),
    );
    Pose::from_parts(
        Vector::new(m.trans.x, m.trans.y, m.trans.z),
        Rotation::from_mat3(&mat).normalize(),
    )
}

/// parry (glam) vector → nalgebra vector.
#[inline]
pub fn to_vec3(v: Vector) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// What a [`CollisionShape`] was built as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeKind {
    /// Box.
    Box,
    /// Sphere.
    Sphere,
    /// Cylinder (along z).
    Cylinder,
    /// Capsule (along z).
    Capsule,
    /// Triangle mesh (a surface; `closed` says whether it encloses a volume).
    TriMesh {
        /// Every edge shared by exactly two consistently oriented triangles.
        closed: bool,
    },
    /// Convex hull of a mesh.
    ConvexHull,
}

/// A shape in its own frame, with the fixed rotation that maps URDF conventions onto
/// parry's (cylinders) folded into [`CollisionShape::frame`].
#[derive(Clone)]
pub struct CollisionShape {
    /// The parry shape.
    pub(crate) shape: SharedShape,
    /// Geometry frame → parry shape frame (identity except for cylinders).
    pub frame: Se3,
    /// What it was built as.
    pub kind: ShapeKind,
    /// A point of the shape in the parry shape frame (for containment tests).
    pub(crate) inner_point: Vector,
    /// Spheres and capsules as a segment swept by a radius (closed-form queries).
    swept: Option<Swept>,
    /// A triangle mesh's box tree for mesh–mesh distances ([`crate::collision::mesh_pair`]),
    /// built at its first such query (most meshes never need one).
    tree: Option<Arc<OnceLock<TriTree>>>,
}

/// A segment `a`–`b` (parry shape frame) swept by radius `r`: a sphere (`a == b`) or a
/// capsule. Distances between two of them are closed-form (segment–segment distance
/// minus the radii), exact for penetration too: a translation changes the segment
/// distance at most by its length, and moving along the closest-point direction (or
/// across both axes when they cross) achieves it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Swept {
    a: Vector,
    b: Vector,
    r: f64,
}

impl std::fmt::Debug for CollisionShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CollisionShape")
            .field("kind", &self.kind)
            .field("frame", &self.frame)
            .finish()
    }
}

fn positive(x: f64, what: &str) -> Result<f64, ShapeError> {
    if x.is_finite() && x > MAX_COORD {
        Err(ShapeError::TooLarge {
            what: what.to_string(),
            value: x,
            max: MAX_COORD,
        })
    } else if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(ShapeError::NotPositive {
            what: what.to_string(),
            value: x,
        })
    }
}

/// Farthest a scaled mesh vertex may lie from its mesh origin: 10⁹ m. Far beyond any
/// scene, and far enough below the f64 range that areas and volumes stay finite.
pub const MAX_COORD: f64 = 1e9;

impl CollisionShape {
    /// A primitive (box, sphere, cylinder, capsule); meshes go through
    /// [`CollisionShape::from_mesh`].
    pub fn primitive(shape: &Shape) -> Result<CollisionShape, ShapeError> {
        let simple = |shape, kind| CollisionShape {
            shape,
            frame: Se3::identity(),
            kind,
            inner_point: Vector::ZERO,
            swept: None,
            tree: None,
        };
        Ok(match shape {
            Shape::Box { size } => {
                for (k, s) in size.iter().enumerate() {
                    positive(*s, &format!("box size[{k}]"))?;
                }
                simple(
                    SharedShape::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0),
                    ShapeKind::Box,
                )
            }
            Shape::Sphere { radius } => {
                let r = positive(*radius, "sphere radius")?;
                CollisionShape {
                    swept: Some(Swept {
                        a: Vector::ZERO,
                        b: Vector::ZERO,
                        r,
                    }),
                    ..simple(SharedShape::ball(r), ShapeKind::Sphere)
                }
            }
            Shape::Capsule { radius, length } => {
                let r = positive(*radius, "capsule radius")?;
                if !(length.is_finite() && *length >= 0.0 && *length <= MAX_COORD) {
                    return Err(ShapeError::CapsuleLength(*length));
                }
                let h = length / 2.0;
                CollisionShape {
                    swept: Some(Swept {
                        a: Vector::new(0.0, 0.0, -h),
                        b: Vector::new(0.0, 0.0, h),
                        r,
                    }),
                    ..simple(SharedShape::capsule_z(h, r), ShapeKind::Capsule)
                }
            }
            Shape::Cylinder { radius, length } => {
                let r = positive(*radius, "cylinder radius")?;
                let l = positive(*length, "cylinder length")?;
                // parry's cylinder is along y: Rx(+90°) takes y onto z.
                let rx = Mat3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0);
                CollisionShape {
                    shape: SharedShape::cylinder(l / 2.0, r),
                    frame: Se3::from_rotation(rx),
                    kind: ShapeKind::Cylinder,
                    inner_point: Vector::ZERO,
                    swept: None,
                    tree: None,
                }
            }
            Shape::Mesh { .. } => return Err(ShapeError::MeshNotLoaded),
        })
    }

    /// A mesh, scaled per axis, as a triangle mesh or (`convex_hull`) its convex hull.
    /// A flat mesh has no hull: it is kept as a triangle mesh and the second value says so.
    /// The scale must be finite and non-zero and keep every vertex within [`MAX_COORD`]
    /// metres of the mesh origin.
    pub fn from_mesh(
        mesh: &MeshData,
        scale: [f64; 3],
        convex_hull: bool,
    ) -> Result<(CollisionShape, Option<String>), ShapeError> {
        if scale.iter().any(|s| !s.is_finite() || *s == 0.0) {
            return Err(ShapeError::MeshScale(scale));
        }
        let vertices: Vec<Vector> = mesh
            .vertices
            .iter()
            .map(|p| Vector::new(p[0] * scale[0], p[1] * scale[1], p[2] * scale[2]))
            .collect();
        // The scale is finite, but the scaled vertices may not be (1e300 × 1e10).
        if let Some(v) = vertices
            .iter()
            .find(|v| !(v.x.abs() <= MAX_COORD && v.y.abs() <= MAX_COORD && v.z.abs() <= MAX_COORD))
        {
            return Err(ShapeError::BeyondRange {
                scale,
                vertex: [v.x, v.y, v.z],
                limit: MAX_COORD,
            });
        }
        let inner_point = vertices.first().copied().unwrap_or(Vector::ZERO);
        let mut note = None;
        if convex_hull {
            if let Some(shape) = SharedShape::convex_hull(&vertices) {
                return Ok((
                    CollisionShape {
                        shape,
                        frame: Se3::identity(),
                        kind: ShapeKind::ConvexHull,
                        inner_point,
                        swept: None,
                        tree: None,
                    },
                    None,
                ));
            }
            note = Some("the mesh is flat (no convex hull): kept as a triangle mesh".to_string());
        }
        let mut m = mesh.clone();
        if scale[0] * scale[1] * scale[2] < 0.0 {
            m.flip();
        }
        let closed = m.is_closed();
        let mut flags = TriMeshFlags::empty();
        if closed {
            if m.signed_volume6() < 0.0 {
                m.flip();
            }
            // Pseudo-normals make point containment well defined.
            flags |= TriMeshFlags::ORIENTED;
        }
        let tri = TriMesh::with_flags(vertices, m.triangles, flags)
            .map_err(|e| ShapeError::InvalidTriMesh(format!("{e:?}")))?;
        Ok((
            CollisionShape {
                shape: SharedShape::new(tri),
                frame: Se3::identity(),
                kind: ShapeKind::TriMesh { closed },
                inner_point,
                swept: None,
                tree: Some(Arc::default()),
            },
            note,
        ))
    }

    /// World bounding box at `pose`.
    #[inline]
    pub(crate) fn aabb(&self, pose: &Pose) -> Aabb {
        self.shape.compute_aabb(pose)
    }

    /// A triangle mesh's box tree, built at the first call.
    fn mesh_tree(&self) -> Option<&TriTree> {
        let cell = self.tree.as_ref()?;
        let mesh = self.shape.as_trimesh()?;
        Some(cell.get_or_init(|| TriTree::new(mesh.vertices(), mesh.indices())))
    }

    fn closed_mesh(&self) -> bool {
        matches!(self.kind, ShapeKind::TriMesh { closed: true })
    }
}

/// Smallest distance between two boxes (0 when they overlap): a lower bound of the
/// distance between anything they contain.
#[inline]
pub fn aabb_gap(a: &Aabb, b: &Aabb) -> f64 {
    let d = (a.mins - b.maxs).max(b.mins - a.maxs).max(Vector::ZERO);
    d.length()
}

#[inline]
fn aabb_contains(outer: &Aabb, inner: &Aabb) -> bool {
    outer.mins.cmple(inner.mins).all() && inner.maxs.cmple(outer.maxs).all()
}

/// Whether one shape lies wholly inside the other, a closed triangle mesh (which the
/// triangle-wise queries cannot see). Call only when the surfaces do not intersect.
fn contained(
    a: &CollisionShape,
    pa: &Pose,
    aabb_a: &Aabb,
    b: &CollisionShape,
    pb: &Pose,
    aabb_b: &Aabb,
) -> bool {
    (a.closed_mesh()
        && aabb_contains(aabb_a, aabb_b)
        && a.shape.contains_point(pa, *pb * b.inner_point))
        || (b.closed_mesh()
            && aabb_contains(aabb_b, aabb_a)
            && b.shape.contains_point(pb, *pa * a.inner_point))
}

/// One side of a pair query: the shape, its world pose and its world box.
#[derive(Clone, Copy)]
pub struct Placed<'a> {
    /// The shape.
    pub shape: &'a CollisionShape,
    /// World pose of the parry shape frame.
    pub pose: &'a Pose,
    /// World bounding box.
    pub aabb: &'a Aabb,
}

/// Reusable GJK/EPA workspace, so that penetration depths of convex pairs allocate
/// nothing once warm (parry's `contact` builds a fresh EPA polytope on every call).
#[derive(Default)]
pub struct Scratch {
    simplex: VoronoiSimplex,
    epa: EPA,
}

impl Clone for Scratch {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Scratch")
    }
}

/// Signed distance and surface witness points of two swept spheres, if both are.
#[inline]
fn swept_pair(a: Placed, b: Placed) -> Option<(f64, Vector, Vector)> {
    let (sa, sb) = (a.shape.swept?, b.shape.swept?);
    let (c1, c2) = closest_segments(
        *a.pose * sa.a,
        *a.pose * sa.b,
        *b.pose * sb.a,
        *b.pose * sb.b,
    );
    let v = c2 - c1;
    let len = v.length();
    let n = if len > 1e-12 {
        v / len
    } else {
        // Crossing axes: separate across both (or across either when parallel).
        let (d1, d2) = (
            *a.pose * sa.b - *a.pose * sa.a,
            *b.pose * sb.b - *b.pose * sb.a,
        );
        let cross = d1.cross(d2);
        cross
            .try_normalize()
            .or_else(|| d1.any_orthonormal_vector().try_normalize())
            .or_else(|| d2.any_orthonormal_vector().try_normalize())
            .unwrap_or(Vector::X)
    };
    Some((len - sa.r - sb.r, c1 + n * sa.r, c2 - n * sb.r))
}

/// Outcome of the closed-form and segment-core paths.
enum Fast {
    /// Neither applies: use parry's general queries.
    Skip,
    /// The signed distance exceeds the bound.
    Far,
    /// Signed distance (≤ bound) and world points on `a` and `b`.
    Hit(f64, Vector, Vector),
}

/// A capsule against a convex shape that is neither a sphere nor a capsule: its segment
/// against the shape (GJK, and EPA when they overlap), minus the radius. Exact: the
/// distance of the segment sweeps off at rate one along the witness normal, and the depth
/// of the origin in `CSO ⊕ ball(r)` is the depth in the CSO plus `r`. Much faster than
/// GJK on the rounded support map, which converges slowly near contact. Without `depth`,
/// an overlapping segment answers `-r` (enough for a yes/no test).
fn capsule_convex(
    cap: Placed,
    sw: Swept,
    other: Placed,
    g2: &dyn SupportMap,
    bound: f64,
    depth: bool,
    scratch: &mut Scratch,
) -> Fast {
    let seg = Segment::new(sw.a, sw.b);
    let pos12 = cap.pose.inv_mul(other.pose);
    let max_dist = if bound.is_finite() {
        bound + sw.r
    } else {
        f64::MAX
    };
    let dir = pos12.translation.try_normalize().unwrap_or(Vector::X);
    scratch
        .simplex
        .reset(CsoPoint::from_shapes(&pos12, &seg, g2, dir));
    // Points in the capsule's frame: p1 on the segment, p2 on the other shape.
    let (d, p1, p2, n) =
        match gjk::closest_points(&pos12, &seg, g2, max_dist, true, &mut scratch.simplex) {
            GJKResult::ClosestPoints(p1, p2, n) => {
                let v = p2 - p1;
                let len = v.length();
                (len, p1, p2, if len > 0.0 { v / len } else { n })
            }
            GJKResult::NoIntersection(_) => return Fast::Far,
            GJKResult::Intersection if !depth => {
                let p = cap.pose.translation;
                return Fast::Hit(-sw.r, p, p);
            }
            GJKResult::Intersection => {
                match scratch
                    .epa
                    .closest_points(&pos12, &seg, g2, &scratch.simplex)
                {
                    Some((p1, p2, n)) => ((p2 - p1).dot(n).min(0.0), p1, p2, n),
                    None => return Fast::Skip,
                }
            }
            GJKResult::Proximity(_) => return Fast::Skip,
        };
    let sd = d - sw.r;
    if sd > bound {
        return Fast::Far;
    }
    Fast::Hit(sd, *cap.pose * (p1 + n * sw.r), *cap.pose * p2)
}

/// Closed forms (two spheres/capsules) and the capsule segment path, when they apply.
/// `Hit` when the signed distance is ≤ `bound`.
fn fast_pair(a: Placed, b: Placed, bound: f64, depth: bool, scratch: &mut Scratch) -> Fast {
    if let Some((d, p, q)) = swept_pair(a, b) {
        return if d <= bound {
            Fast::Hit(d, p, q)
        } else {
            Fast::Far
        };
    }
    let capsule = |x: &Placed| {
        if x.shape.kind == ShapeKind::Capsule {
            x.shape.swept
        } else {
            None
        }
    };
    if let (Some(sw), Some(g2)) = (capsule(&a), b.shape.shape.as_support_map()) {
        if b.shape.kind != ShapeKind::Sphere {
            return capsule_convex(a, sw, b, g2, bound, depth, scratch);
        }
    }
    if let (Some(sw), Some(g1)) = (capsule(&b), a.shape.shape.as_support_map()) {
        if a.shape.kind != ShapeKind::Sphere {
            return match capsule_convex(b, sw, a, g1, bound, depth, scratch) {
                Fast::Hit(d, p, q) => Fast::Hit(d, q, p),
                other => other,
            };
        }
    }
    Fast::Skip
}

/// Whether the two shapes overlap or touch, the boxes assumed to overlap already.
pub fn intersects(a: Placed, b: Placed) -> bool {
    // Without depths no EPA runs: a scratch on the stack allocates nothing.
    match fast_pair(a, b, 0.0, false, &mut Scratch::default()) {
        Fast::Hit(..) => return true,
        Fast::Far => return false,
        Fast::Skip => {}
    }
    let hit = match query::intersection_test(a.pose, &*a.shape.shape, b.pose, &*b.shape.shape) {
        Ok(r) => r.intersecting,
        Err(_) => unsigned_distance(a, b) <= 0.0,
    };
    hit || contained(a.shape, a.pose, a.aabb, b.shape, b.pose, b.aabb)
}

/// Whether the signed distance is at most `margin` (> 0).
pub fn within(a: Placed, b: Placed, margin: f64) -> bool {
    match fast_pair(a, b, margin, false, &mut Scratch::default()) {
        Fast::Hit(..) => return true,
        Fast::Far => return false,
        Fast::Skip => {}
    }
    unsigned_distance(a, b) <= margin || contained(a.shape, a.pose, a.aabb, b.shape, b.pose, b.aabb)
}

/// Unsigned distance (0 when overlapping; surface distance for triangle meshes).
pub fn unsigned_distance(a: Placed, b: Placed) -> f64 {
    if let Some(g) = mesh_gap(a, b) {
        return g.map_or(f64::MAX, |g| g.distance);
    }
    query::distance(a.pose, &*a.shape.shape, b.pose, &*b.shape.shape)
        .map(|r| r.distance)
        .unwrap_or_else(|_| {
            panic!(
                "parry cannot measure the distance between a {:?} and a {:?}",
                a.shape.kind, b.shape.kind
            )
        })
}

/// Depth of overlapping shapes as a negative distance, with world contact points.
fn penetration(a: Placed, b: Placed, scratch: &mut Scratch) -> (f64, Vector, Vector) {
    let ball = a.shape.kind == ShapeKind::Sphere || b.shape.kind == ShapeKind::Sphere;
    if let (false, Some(g1), Some(g2)) = (
        ball,
        a.shape.shape.as_support_map(),
        b.shape.shape.as_support_map(),
    ) {
        // GJK then EPA, as parry's contact_support_map_support_map, with reused buffers.
        let pos12 = a.pose.inv_mul(b.pose);
        let dir = pos12.translation.try_normalize().unwrap_or(Vector::X);
        scratch
            .simplex
            .reset(CsoPoint::from_shapes(&pos12, g1, g2, dir));
        let res = gjk::closest_points(&pos12, g1, g2, 0.0, true, &mut scratch.simplex);
        let pts = match res {
            GJKResult::Intersection => scratch.epa.closest_points(&pos12, g1, g2, &scratch.simplex),
            GJKResult::ClosestPoints(p1, p2, n) => Some((p1, p2, n)),
            _ => None,
        };
        if let Some((p1, p2, n)) = pts {
            // Both points in a's frame.
            let dist = (p2 - p1).dot(n);
            return (dist.min(0.0), *a.pose * p1, *a.pose * p2);
        }
    }
    match query::contact(a.pose, &*a.shape.shape, b.pose, &*b.shape.shape, 0.0) {
        Ok(Some(c)) => (c.dist.min(0.0), c.point1, c.point2),
        _ => {
            let p = *a.pose * a.shape.inner_point;
            (0.0, p, p)
        }
    }
}

/// Signed distance and world witness points, by parry's general queries (two triangle
/// meshes apart: [`mesh_gap`]).
fn general(a: Placed, b: Placed, scratch: &mut Scratch, points: bool) -> (f64, Vector, Vector) {
    let gap = mesh_gap(a, b);
    let d = match gap {
        Some(g) => g.map_or(f64::MAX, |g| g.distance),
        None => unsigned_distance(a, b),
    };
    if d > 0.0 {
        let inside = contained(a.shape, a.pose, a.aabb, b.shape, b.pose, b.aabb);
        let sd = if inside { -d } else { d };
        if let (true, Some(Some(g))) = (points, gap) {
            return (sd, g.a, g.b);
        }
        if points {
            if let Ok(ClosestPoints::WithinMargin(p, q)) = query::closest_points(
                a.pose,
                &*a.shape.shape,
                b.pose,
                &*b.shape.shape,
                d * (1.0 + 1e-9) + 1e-12,
            ) {
                return (sd, p, q);
            }
        }
        let p = *a.pose * a.shape.inner_point;
        return (sd, p, p);
    }
    penetration(a, b, scratch)
}

/// Signed distance (see the module docs): positive separation, negative penetration.
pub fn signed_distance(a: Placed, b: Placed, scratch: &mut Scratch) -> f64 {
    match fast_pair(a, b, f64::INFINITY, true, scratch) {
        Fast::Hit(d, _, _) => d,
        _ => general(a, b, scratch, false).0,
    }
}

/// The signed distance if it is below `bound`, else `None`: GJK stops as soon as a
/// separating plane proves the distance at least `bound`, which prunes most pairs of a
/// minimum-distance search cheaply.
pub fn signed_distance_below(
    a: Placed,
    b: Placed,
    bound: f64,
    scratch: &mut Scratch,
) -> Option<f64> {
    match fast_pair(a, b, bound, true, scratch) {
        Fast::Hit(d, _, _) => return (d < bound).then_some(d),
        Fast::Far => return None,
        Fast::Skip => {}
    }
    // A closed mesh may contain the other shape: the surface distance does not bound.
    if !bound.is_finite() || a.shape.closed_mesh() || b.shape.closed_mesh() {
        let d = signed_distance(a, b, scratch);
        return (d < bound).then_some(d);
    }
    let (ga, gb) = (&*a.shape.shape, &*b.shape.shape);
    if bound <= 0.0 {
        // Only overlapping pairs can beat a penetration.
        let hit = query::intersection_test(a.pose, ga, b.pose, gb)
            .map(|r| r.intersecting)
            .unwrap_or(true);
        if !hit {
            return None;
        }
        let d = signed_distance(a, b, scratch);
        return (d < bound).then_some(d);
    }
    match query::closest_points(a.pose, ga, b.pose, gb, bound) {
        Ok(ClosestPoints::Disjoint) => None,
        Ok(ClosestPoints::WithinMargin(p, q)) => {
            let d = (q - p).length();
            (d < bound).then_some(d)
        }
        _ => {
            let d = signed_distance(a, b, scratch);
            (d < bound).then_some(d)
        }
    }
}

/// For two triangle meshes (`None` otherwise), their nearest points
/// ([`TriTree::distance`], both box trees descended together). Unbounded, this is 10–20×
/// faster than parry's `distance`, a search of one mesh per triangle of the other (iiwa
/// links of 5 000 and 11 000 triangles 3 cm apart: 1–4.6 ms against 15–43 ms); bounded
/// by a margin, parry's `closest_points` is faster (0.27 ms against 0.72 ms a query on
/// the same pair), so the bounded queries keep it.
fn mesh_gap(a: Placed, b: Placed) -> Option<Option<MeshGap>> {
    let (ta, tb) = (a.shape.mesh_tree()?, b.shape.mesh_tree()?);
    Some(ta.distance(a.pose, tb, b.pose, f64::INFINITY))
}

/// Signed distance and world witness points (closest points when separated, the
/// deepest contact points when overlapping).
pub fn distance_and_points(a: Placed, b: Placed, scratch: &mut Scratch) -> (f64, Vec3, Vec3) {
    let (d, p, q) = match fast_pair(a, b, f64::INFINITY, true, scratch) {
        Fast::Hit(d, p, q) => (d, p, q),
        _ => general(a, b, scratch, true),
    };
    (d, to_vec3(p), to_vec3(q))
}

/// The signed distance if it is below `bound`, else `None`, for every pair, closed
/// meshes included: unless one shape may lie inside a closed mesh (the containment test
/// of the module docs), a separation above `bound` is proven by parry's `closest_points`
/// with `bound` as its margin, which prunes the mesh hierarchies at that distance instead
/// of measuring the full distance.
pub fn signed_distance_under(
    a: Placed,
    b: Placed,
    bound: f64,
    scratch: &mut Scratch,
) -> Option<f64> {
    match fast_pair(a, b, bound, true, scratch) {
        Fast::Hit(d, _, _) => return (d < bound).then_some(d),
        Fast::Far => return None,
        Fast::Skip => {}
    }
    let inside = || contained(a.shape, a.pose, a.aabb, b.shape, b.pose, b.aabb);
    if !bound.is_finite() || bound <= 0.0 || inside() {
        let d = signed_distance(a, b, scratch);
        return (d < bound).then_some(d);
    }
    let (ga, gb) = (&*a.shape.shape, &*b.shape.shape);
    match query::closest_points(a.pose, ga, b.pose, gb, bound) {
        Ok(ClosestPoints::Disjoint) => None,
        Ok(ClosestPoints::WithinMargin(p, q)) => {
            let d = (q - p).length();
            (d < bound).then_some(d)
        }
        _ => {
            let d = signed_distance(a, b, scratch);
            (d < bound).then_some(d)
        }
    }
}

/// Distance between two convex shapes at `pa`, `pb` (0 when they overlap), by GJK started
/// from `hint`, the separating direction of a previous call (in `a`'s frame), which is
/// updated: along a trajectory the pair's direction changes little and GJK then converges
/// in a few steps.
pub fn convex_distance(
    ga: &dyn SupportMap,
    pa: &Pose,
    gb: &dyn SupportMap,
    pb: &Pose,
    hint: &mut Vector,
    scratch: &mut Scratch,
) -> f64 {
    let pos12 = pa.inv_mul(pb);
    let dir = hint
        .try_normalize()
        .or_else(|| pos12.translation.try_normalize())
        .unwrap_or(Vector::X);
    scratch
        .simplex
        .reset(CsoPoint::from_shapes(&pos12, ga, gb, dir));
    match gjk::closest_points(&pos12, ga, gb, f64::MAX, true, &mut scratch.simplex) {
        GJKResult::ClosestPoints(p1, p2, n) => {
            *hint = n;
            (p2 - p1).length()
        }
        _ => 0.0,
    }
}
