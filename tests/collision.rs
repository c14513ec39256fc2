//! Collision checking against hand-computed references: signed distances of spheres and
//! boxes (closed forms), a planted collision along a joint trajectory (contact time from
//! the arm's geometry), self-collision filtering, mesh files (STL binary/ASCII, OBJ, DAE)
//! against the primitive box they describe, missing meshes, and the allocation-free hot
//! loop.

#[path = "common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocs;

use armsim::collision::{
    Body, CollisionData, CollisionError, CollisionModel, CollisionOptions, MissingMeshes, Obstacle,
    ObstacleSpec, Scope, ShapeKind, TrajectoryOptions,
};
use armsim::core::spatial::{Se3, Vec3};
use armsim::model::{Geometry, JointSpec, JointType, LinkSpec, Model, ModelSpec, Shape};
use rand::{Rng, SeedableRng};
use std::path::PathBuf;

// ---------------------------------------------------------------------------------------
// Helpers and closed-form references.

fn data(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn load(rel: &str) -> Model {
    Model::load(data(rel)).unwrap_or_else(|e| panic!("{e}")).0
}

/// A free-floating probe: three prismatic joints (x, y, z) carrying `shape` (q = its
/// centre).
fn probe_model(shape: Shape) -> Model {
    let mut links: Vec<LinkSpec> = ["world", "px", "py", "probe"]
        .iter()
        .map(|n| LinkSpec::new(*n))
        .collect();
    links[3].collisions.push(Geometry {
        origin: Se3::identity(),
        shape,
        rgba: None,
    });
    let joints = [("world", "px"), ("px", "py"), ("py", "probe")]
        .iter()
        .enumerate()
        .map(|(k, (p, c))| {
            let mut j = JointSpec::new(format!("t{k}"), JointType::Prismatic, *p, *c);
            j.axis = Vec3::new(
                (k == 0) as u8 as f64,
                (k == 1) as u8 as f64,
                (k == 2) as u8 as f64,
            );
            j
        })
        .collect();
    let spec = ModelSpec {
        name: "probe".into(),
        source: "probe".into(),
        root_offset: Se3::identity(),
        links,
        joints,
        urdf_text: None,
        gravity: None,
        warnings: Vec::new(),
    };
    Model::build(spec).unwrap().0
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Signed distance from point `p` (box frame) to a box of half extents `h`.
fn box_sdf(p: [f64; 3], h: [f64; 3]) -> f64 {
    let q = [p[0].abs() - h[0], p[1].abs() - h[1], p[2].abs() - h[2]];
    if q.iter().all(|x| *x <= 0.0) {
        q.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    } else {
        norm(q.map(|x| x.max(0.0)))
    }
}

fn sphere_box(c: [f64; 3], r: f64, center: [f64; 3], size: [f64; 3]) -> f64 {
    box_sdf(
        [c[0] - center[0], c[1] - center[1], c[2] - center[2]],
        size.map(|s| s / 2.0),
    ) - r
}

/// Signed distance between two axis-aligned boxes (penetration: the smallest overlap).
fn box_box(ca: [f64; 3], sa: [f64; 3], cb: [f64; 3], sb: [f64; 3]) -> f64 {
    let g: Vec<f64> = (0..3)
        .map(|k| (ca[k] - cb[k]).abs() - (sa[k] + sb[k]) / 2.0)
        .collect();
    if g.iter().any(|x| *x > 0.0) {
        norm([g[0].max(0.0), g[1].max(0.0), g[2].max(0.0)])
    } else {
        g.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
}

fn random_point(rng: &mut rand::rngs::SmallRng, half: f64) -> [f64; 3] {
    [0, 1, 2].map(|_| rng.random_range(-half..half))
}

/// Distance of the probe to obstacle 0 at `c`, checking the witness points.
fn probe_distance(model: &Model, cm: &CollisionModel, cd: &mut CollisionData, c: [f64; 3]) -> f64 {
    cm.update(model, cd, &c);
    let d = cm.min_distance(cd, Scope::Environment).unwrap();
    assert_eq!(d.a, Body::Link(model.link_id("probe").unwrap()));
    assert_eq!(d.b, Body::Obstacle(0));
    let gap = norm([0, 1, 2].map(|k| d.point_a[k] - d.point_b[k]));
    if d.distance > 1e-6 {
        assert!(
            (gap - d.distance).abs() < 1e-9,
            "witness gap {gap} vs {}",
            d.distance
        );
    }
    d.distance
}

// ---------------------------------------------------------------------------------------
// Primitive distances against closed forms.

#[test]
fn sphere_sphere_matches_closed_form() {
    let model = probe_model(Shape::Sphere { radius: 0.3 });
    let ob = Obstacle::sphere("ball", 0.2, [0.1, -0.2, 0.3]);
    let cm = CollisionModel::new(&model, vec![ob], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let mut rng = rand::rngs::SmallRng::seed_from_u64(1);
    let (mut apart, mut overlapping) = (0, 0);
    for _ in 0..500 {
        let c = random_point(&mut rng, 1.5);
        let want = norm([c[0] - 0.1, c[1] + 0.2, c[2] - 0.3]) - 0.5;
        let got = probe_distance(&model, &cm, &mut cd, c);
        assert!((got - want).abs() < 1e-9, "at {c:?}: {got} vs {want}");
        let hit = cm.first_collision(&cd, Scope::All).is_some();
        assert_eq!(hit, want <= 0.0, "collision flag at {c:?} (d = {want})");
        if want > 0.0 {
            apart += 1
        } else {
            overlapping += 1
        }
    }
    assert!(
        apart > 100 && overlapping > 5,
        "{apart} apart, {overlapping} overlapping"
    );
}

#[test]
fn sphere_box_matches_closed_form_axis_aligned_and_rotated() {
    let model = probe_model(Shape::Sphere { radius: 0.15 });
    let size = [0.8, 0.5, 0.3];
    let center = [0.2, 0.1, -0.1];
    let mut rng = rand::rngs::SmallRng::seed_from_u64(2);
    // Axis-aligned.
    let cm = CollisionModel::new(
        &model,
        vec![Obstacle::cuboid("box", size, center)],
        &CollisionOptions::default(),
    )
    .unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let mut inside = 0;
    for _ in 0..600 {
        let c = random_point(&mut rng, 0.7);
        let want = sphere_box(c, 0.15, center, size);
        let got = probe_distance(&model, &cm, &mut cd, c);
        assert!((got - want).abs() < 1e-9, "at {c:?}: {got} vs {want}");
        inside +=
            (box_sdf([0, 1, 2].map(|k| c[k] - center[k]), size.map(|s| s / 2.0)) < 0.0) as usize;
    }
    assert!(inside > 10, "only {inside} centres inside the box");
    // Rotated box: the reference works in the box frame.
    let pose = Se3::from_xyz_rpy(center, [0.3, -0.7, 1.1]);
    let cm = CollisionModel::new(
        &model,
        vec![Obstacle::new("box", Shape::Box { size }, pose)],
        &CollisionOptions::default(),
    )
    .unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    for _ in 0..600 {
        let c = random_point(&mut rng, 1.0);
        let local = pose.inverse().act_point(&Vec3::from(c));
        let want = box_sdf(local.into(), size.map(|s| s / 2.0)) - 0.15;
        let got = probe_distance(&model, &cm, &mut cd, c);
        assert!(
            (got - want).abs() < 1e-9,
            "rotated, at {c:?}: {got} vs {want}"
        );
    }
}

#[test]
fn box_box_axis_aligned_matches_closed_form() {
    let sa = [0.2, 0.4, 0.6];
    let model = probe_model(Shape::Box { size: sa });
    let sb = [1.0, 0.5, 0.3];
    let cb = [0.1, 0.0, 0.2];
    // The same box twice: written axis-aligned, and turned by 90° about z with x and y
    // sizes swapped.
    let obstacles = [
        Obstacle::cuboid("box", sb, cb),
        Obstacle::new(
            "box",
            Shape::Box {
                size: [sb[1], sb[0], sb[2]],
            },
            Se3::from_xyz_rpy(cb, [0.0, 0.0, std::f64::consts::FRAC_PI_2]),
        ),
    ];
    let mut rng = rand::rngs::SmallRng::seed_from_u64(3);
    for ob in obstacles {
        let cm = CollisionModel::new(&model, vec![ob], &CollisionOptions::default()).unwrap();
        let mut cd = CollisionData::new(&model, &cm);
        let mut overlapping = 0;
        for _ in 0..600 {
            let c = random_point(&mut rng, 1.2);
            let want = box_box(c, sa, cb, sb);
            let got = probe_distance(&model, &cm, &mut cd, c);
            assert!((got - want).abs() < 1e-9, "at {c:?}: {got} vs {want}");
            overlapping += (want < 0.0) as usize;
        }
        assert!(overlapping > 20, "only {overlapping} overlapping samples");
    }
}

#[test]
fn cylinders_and_capsules_are_along_z() {
    // Sphere probe against a cylinder (r 0.1, length 1) and a capsule (r 0.1, cylindrical
    // part 1) standing along z at the origin: beside the axis the distance is radial,
    // beyond the ends it is axial (cylinder) or from the end point (capsule).
    let model = probe_model(Shape::Sphere { radius: 0.05 });
    for (shape, end) in [
        (
            Shape::Cylinder {
                radius: 0.1,
                length: 1.0,
            },
            false,
        ),
        (
            Shape::Capsule {
                radius: 0.1,
                length: 1.0,
            },
            true,
        ),
    ] {
        let cm = CollisionModel::new(
            &model,
            vec![Obstacle::new("post", shape, Se3::identity())],
            &CollisionOptions::default(),
        )
        .unwrap();
        let mut cd = CollisionData::new(&model, &cm);
        let side = probe_distance(&model, &cm, &mut cd, [0.0, 0.4, 0.3]);
        assert!((side - 0.25).abs() < 1e-7, "side {side}");
        let top = probe_distance(&model, &cm, &mut cd, [0.0, 0.0, 0.9]);
        let want = if end {
            0.9 - 0.5 - 0.1 - 0.05
        } else {
            0.9 - 0.5 - 0.05
        };
        assert!((top - want).abs() < 1e-7, "top {top} vs {want}");
    }
}

#[test]
fn capsule_box_matches_closed_form() {
    // Capsule along z (segment half-length 0.3, r 0.1) against an axis-aligned box: the
    // Minkowski difference of the segment and the box is a box elongated in z, so the
    // segment's distance splits per axis, and when the segment is inside, its depth is
    // the smallest escape along an axis. Signed distance = segment distance - r, or
    // -(depth + r).
    let (h, r) = (0.3, 0.1);
    let model = probe_model(Shape::Capsule {
        radius: r,
        length: 2.0 * h,
    });
    let size = [0.6, 0.4, 0.5];
    let center = [0.1, -0.1, 0.2];
    let cm = CollisionModel::new(
        &model,
        vec![Obstacle::cuboid("box", size, center)],
        &CollisionOptions::default(),
    )
    .unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let half = size.map(|x| x / 2.0);
    let ext = [half[0], half[1], half[2] + h];
    let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
    let (mut apart, mut inside) = (0, 0);
    for _ in 0..600 {
        let c = random_point(&mut rng, 1.0);
        let rel = [0, 1, 2].map(|k| c[k] - center[k]);
        let want = box_sdf(rel, ext) - r;
        let got = probe_distance(&model, &cm, &mut cd, c);
        assert!((got - want).abs() < 1e-9, "at {c:?}: {got} vs {want}");
        assert_eq!(cm.first_collision(&cd, Scope::All).is_some(), want <= 0.0);
        if want > 0.0 {
            apart += 1;
        } else if box_sdf(rel, ext) < 0.0 {
            inside += 1;
        }
    }
    assert!(
        apart > 100 && inside > 20,
        "{apart} apart, {inside} with the segment inside"
    );
}

/// A random parry pose: translation within 0.8, rotation vector within 3.
fn random_pose(rng: &mut rand::rngs::SmallRng) -> parry3d_f64::math::Pose {
    use parry3d_f64::math::{Pose, Vector};
    let t = random_point(rng, 0.8);
    let w = random_point(rng, 3.0);
    Pose::new(Vector::new(t[0], t[1], t[2]), Vector::new(w[0], w[1], w[2]))
}

/// The rotation matrix of a parry pose.
fn rotation_of(p: &parry3d_f64::math::Pose) -> armsim::core::spatial::Mat3 {
    let m = parry3d_f64::math::Matrix::from_quat(p.rotation);
    armsim::core::spatial::Mat3::from_columns(&[
        Vec3::new(m.x_axis.x, m.x_axis.y, m.x_axis.z),
        Vec3::new(m.y_axis.x, m.y_axis.y, m.y_axis.z),
        Vec3::new(m.z_axis.x, m.z_axis.y, m.z_axis.z),
    ])
}

/// The distance between segments `p1 q1` and `p2 q2` by brute force: golden-section
/// search along the first segment of the point-to-segment distance (a convex function).
fn segment_segment_distance(
    p1: parry3d_f64::math::Vector,
    q1: parry3d_f64::math::Vector,
    p2: parry3d_f64::math::Vector,
    q2: parry3d_f64::math::Vector,
) -> f64 {
    use parry3d_f64::math::Vector;
    let point_segment = |p: Vector, a: Vector, b: Vector| {
        let d = b - a;
        let t = ((p - a).dot(d) / d.dot(d)).clamp(0.0, 1.0);
        (p - (a + d * t)).length()
    };
    let f = |s: f64| point_segment(p1 + (q1 - p1) * s, p2, q2);
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if f(m1) <= f(m2) {
            hi = m2
        } else {
            lo = m1
        }
    }
    f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
}

#[test]
fn capsule_capsule_matches_closed_form_and_parry_gjk() {
    // Probe capsule along z (cylindrical part 1, r 0.1) centred at c; obstacle capsule
    // along x (part 2, r 0.2) at the origin. The axes are orthogonal and axis-aligned, so
    // the segment distance splits per axis: x beyond ±1, y, and z from 0 to [cz ± 0.5].
    let model = probe_model(Shape::Capsule {
        radius: 0.1,
        length: 1.0,
    });
    let bar = Obstacle::new(
        "bar",
        Shape::Capsule {
            radius: 0.2,
            length: 2.0,
        },
        Se3::from_xyz_rpy([0.0; 3], [0.0, std::f64::consts::FRAC_PI_2, 0.0]),
    );
    let cm = CollisionModel::new(&model, vec![bar], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let mut rng = rand::rngs::SmallRng::seed_from_u64(6);
    let mut overlapping = 0;
    for _ in 0..500 {
        let c = random_point(&mut rng, 1.6);
        let dx = (c[0].abs() - 1.0).max(0.0);
        let dz = (c[2].abs() - 0.5).max(0.0);
        let want = norm([dx, c[1], dz]) - 0.3;
        let got = probe_distance(&model, &cm, &mut cd, c);
        assert!((got - want).abs() < 1e-12, "at {c:?}: {got} vs {want}");
        assert_eq!(cm.first_collision(&cd, Scope::All).is_some(), want <= 0.0);
        overlapping += (want < 0.0) as usize;
    }
    assert!(overlapping > 20, "{overlapping}");

    // Random poses: the segment distance against a brute-force reference (golden-section
    // search of the point-to-segment distance along the first axis, a convex function),
    // and against parry's GJK (whose distances are realised by points of the shapes, so
    // bound the true one from above).
    use parry3d_f64::math::Vector;
    let (ha, ra, hb, rb) = (0.4, 0.1, 0.7, 0.15);
    let (mut compared, mut overlapping) = (0, 0);
    for _ in 0..300 {
        let (pa, pb) = (random_pose(&mut rng), random_pose(&mut rng));
        let z = |h: f64| Vector::new(0.0, 0.0, h);
        let want =
            segment_segment_distance(pa * z(-ha), pa * z(ha), pb * z(-hb), pb * z(hb)) - ra - rb;
        // The probe carries capsule a, turned in its link frame and moved by q.
        let mut m = probe_model(Shape::Capsule {
            radius: ra,
            length: 2.0 * ha,
        });
        m.links[3].collisions[0].origin = Se3::new(rotation_of(&pa), Vec3::zeros());
        let ob = Obstacle::new(
            "b",
            Shape::Capsule {
                radius: rb,
                length: 2.0 * hb,
            },
            Se3::new(
                rotation_of(&pb),
                Vec3::new(pb.translation.x, pb.translation.y, pb.translation.z),
            ),
        );
        let cm = CollisionModel::new(&m, vec![ob], &CollisionOptions::default()).unwrap();
        let mut cd = CollisionData::new(&m, &cm);
        let t = pa.translation;
        let got = probe_distance(&m, &cm, &mut cd, [t.x, t.y, t.z]);
        assert!((got - want).abs() < 1e-9, "{got} vs reference {want}");
        let gjk = parry3d_f64::query::distance(
            &pa,
            &parry3d_f64::shape::Capsule::new_z(ha, ra),
            &pb,
            &parry3d_f64::shape::Capsule::new_z(hb, rb),
        )
        .unwrap()
        .distance;
        assert!(
            got.max(0.0) <= gjk + 1e-12 && gjk - got.max(0.0) < 1e-4,
            "{got} vs GJK {gjk}"
        );
        compared += 1;
        overlapping += (want < 0.0) as usize;
    }
    assert!(overlapping > 10, "{overlapping}");
    assert!(compared > 100, "{compared}");
}

// ---------------------------------------------------------------------------------------
// The test arm: adjacency, self-collision, disabled pairs.

fn arm() -> (Model, usize, usize, usize, usize, usize, usize) {
    let m = load("tests/data/collision_arm.urdf");
    let id = |n: &str| m.link_id(n).unwrap();
    let ids = (
        id("base_link"),
        id("link1"),
        id("link2"),
        id("link3"),
        id("link4"),
        id("tool"),
    );
    (m, ids.0, ids.1, ids.2, ids.3, ids.4, ids.5)
}

fn pair(a: usize, b: usize) -> (Body, Body) {
    (Body::Link(a.min(b)), Body::Link(a.max(b)))
}

#[test]
fn adjacent_links_are_not_tested_and_their_overlap_is_not_reported() {
    let (model, base, l1, l2, l3, l4, tool) = arm();
    let cm = CollisionModel::new(&model, vec![], &CollisionOptions::default()).unwrap();
    let tested: Vec<(Body, Body)> = cm
        .tested_pairs(Scope::SelfCollision)
        .into_iter()
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    // One joint apart, or on the same body (tool is fixed to link4).
    for (a, b) in [
        (base, l1),
        (l1, l2),
        (l2, l3),
        (l3, l4),
        (l4, tool),
        (l3, tool),
    ] {
        assert!(!tested.contains(&pair(a, b)), "adjacent pair tested");
    }
    let mut want = vec![
        pair(base, l2),
        pair(base, l3),
        pair(base, l4),
        pair(base, tool),
        pair(l1, l3),
        pair(l1, l4),
        pair(l1, tool),
        pair(l2, l4),
        pair(l2, tool),
    ];
    want.sort();
    let mut got = tested.clone();
    got.sort();
    assert_eq!(got, want);

    // At q = 0 the column overlaps the base and link2 by 0.01: not reported.
    let mut cd = CollisionData::new(&model, &cm);
    cm.update(&model, &mut cd, &[0.0; 4]);
    assert!(cm.first_collision(&cd, Scope::All).is_none());
    for (a, b) in [(base, l1), (l1, l2)] {
        let d = cm.body_distance(&cd, Body::Link(a), Body::Link(b)).unwrap();
        assert!(d < -0.005 && d > -0.015, "adjacent overlap {d}");
    }
    // Minimum self distance: base top (z 0.1) to link2's underside (z 0.35).
    let d = cm.min_distance(&mut cd, Scope::SelfCollision).unwrap();
    assert_eq!((d.a, d.b), pair(base, l2));
    assert!((d.distance - 0.25).abs() < 1e-9, "{}", d.distance);
    assert!((d.point_a[2] - 0.1).abs() < 1e-9 && (d.point_b[2] - 0.35).abs() < 1e-9);
}

#[test]
fn folded_arm_self_collision_is_found_and_the_disable_list_works() {
    let (model, _base, l1, l2, _l3, l4, _tool) = arm();
    // Joint 3 at pi folds link3 back over link2 (a level higher, 0.01 apart); link4 then
    // comes back at link2's level and runs through it over x in [-0.05, 0.15]. Its
    // cross-section (0.06 × 0.06 at the centre of link2's 0.1 × 0.1) must move 0.08 in y
    // or z to get out: signed distance -0.08.
    let q = [0.0, 0.0, std::f64::consts::PI, 0.0];
    let cm = CollisionModel::new(&model, vec![], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    cm.update(&model, &mut cd, &q);
    let hit = cm.first_collision(&cd, Scope::SelfCollision).unwrap();
    assert_eq!((hit.0.min(hit.1), hit.0.max(hit.1)), pair(l2, l4));
    let mut all = Vec::new();
    cm.collisions(&mut cd, Scope::All, &mut all);
    assert_eq!(all.len(), 1, "{all:?}");
    assert!((all[0].distance + 0.08).abs() < 1e-9, "{}", all[0].distance);
    let d = cm.min_distance(&mut cd, Scope::SelfCollision).unwrap();
    assert!((d.distance + 0.08).abs() < 1e-9);

    // Disabled: the next closest pair is link4 over the column top (z 0.37 vs 0.36).
    let opts = CollisionOptions {
        disabled_pairs: vec![["link4".into(), "link2".into()]],
        ..Default::default()
    };
    let cm = CollisionModel::new(&model, vec![], &opts).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    cm.update(&model, &mut cd, &q);
    assert!(cm.first_collision(&cd, Scope::All).is_none());
    let d = cm.min_distance(&mut cd, Scope::SelfCollision).unwrap();
    assert_eq!((d.a, d.b), pair(l1, l4));
    assert!((d.distance - 0.01).abs() < 1e-7, "{}", d.distance);

    // Unknown names are errors, not silently ignored.
    let bad = CollisionOptions {
        disabled_pairs: vec![["link4".into(), "lnk2".into()]],
        ..Default::default()
    };
    match CollisionModel::new(&model, vec![], &bad) {
        Err(CollisionError::DisabledPair { reason, .. }) => assert!(reason.contains("lnk2")),
        other => panic!("{other:?}"),
    }
}

// ---------------------------------------------------------------------------------------
// Trajectories.

/// The wall: y in [0.25, 0.45], x in [1.0, 1.6], z in [0.3, 0.5]. Turning joint 1 by θ
/// brings the tool sphere (centre at radius 1.2, r 0.05) to y = 1.2 sin θ + 0.05: contact
/// at sin θ = 1/6, before anything else (link4's far corner is then at y = 0.238).
fn wall() -> Obstacle {
    Obstacle::cuboid("wall", [0.6, 0.2, 0.2], [1.3, 0.35, 0.4])
}

#[test]
fn planted_collision_is_caught_at_the_analytic_time_with_the_right_pair() {
    let (model, _, _, _, _, _, tool) = arm();
    let cm = CollisionModel::new(&model, vec![wall()], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    // q1(t) = 0.5 t, sampled every 0.1 s over [0, 1].
    let times: Vec<f64> = (0..=10).map(|k| k as f64 * 0.1).collect();
    let qs: Vec<Vec<f64>> = times.iter().map(|t| vec![0.5 * t, 0.0, 0.0, 0.0]).collect();
    let t_contact = (1.0f64 / 6.0).asin() / 0.5;
    for tol in [1e-3, 1e-6, 1e-9] {
        let opts = TrajectoryOptions {
            time_tolerance: tol,
            ..Default::default()
        };
        let r = cm
            .check_trajectory(&model, &mut cd, &times, &qs, &opts)
            .unwrap();
        let c = r.first_collision.expect("the planted collision");
        assert_eq!(c.names, ("tool".to_string(), "wall".to_string()));
        assert_eq!(
            (c.pairs[0].a, c.pairs[0].b),
            (Body::Link(tool), Body::Obstacle(0))
        );
        assert_eq!(c.pairs.len(), 1);
        assert_eq!(c.sample, 4);
        let lo = c.last_free.unwrap();
        assert!(
            lo <= t_contact && t_contact <= c.time,
            "{lo} {t_contact} {}",
            c.time
        );
        assert!(c.time - lo <= tol && c.time - t_contact <= tol + 1e-12);
        assert!((c.q[0] - 0.5 * c.time).abs() < 1e-15);
        // Distance series: before contact it is the tool's gap to the wall face.
        assert_eq!(r.distances.len(), times.len());
        for s in &r.distances {
            let d = s.environment.unwrap();
            if s.time < t_contact {
                let want = 0.25 - 1.2 * (0.5 * s.time).sin() - 0.05;
                assert!(
                    (d.distance - want).abs() < 1e-9,
                    "t {}: {}",
                    s.time,
                    d.distance
                );
                assert_eq!(d.a, Body::Link(tool));
            } else if s.time < 0.65 {
                // The tool centre is inside the wall until y = 1.2 sin(0.5 t) passes 0.45.
                assert!(d.distance < 0.0, "t {}: {}", s.time, d.distance);
            }
            assert!(s.self_collision.unwrap().distance > 0.0);
        }
        // At t = 0.6 the tool centre (y = 0.355) is 0.095 from the wall's faces at
        // y = 0.25 and y = 0.45: depth 0.095 + 0.05.
        let at = |t: f64| {
            r.distances
                .iter()
                .find(|s| (s.time - t).abs() < 1e-12)
                .unwrap()
                .environment
                .unwrap()
        };
        let y = 1.2 * 0.3f64.sin();
        let want = -((y - 0.25).min(0.45 - y) + 0.05);
        assert!(
            (at(0.6).distance - want).abs() < 1e-9,
            "{} vs {want}",
            at(0.6).distance
        );
        let (tmin, dmin) = r.min_environment.unwrap();
        assert!(
            dmin.distance <= want + 1e-9 && tmin > t_contact,
            "{tmin} {dmin:?} {want}"
        );
    }
}

#[test]
fn max_step_catches_a_thin_wall_passed_between_samples() {
    let (model, _, _, _, _, _, _) = arm();
    // A 2 cm wall at y in [0.30, 0.32]; one segment q1: 0 → 1 rad over 1 s.
    let thin = Obstacle::cuboid("thin", [0.6, 0.02, 0.2], [1.3, 0.31, 0.4]);
    let cm = CollisionModel::new(&model, vec![thin], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let times = [0.0, 1.0];
    let qs = [[0.0; 4], [1.0, 0.0, 0.0, 0.0]];
    let coarse = cm
        .check_trajectory(&model, &mut cd, &times, &qs, &TrajectoryOptions::default())
        .unwrap();
    assert!(coarse.first_collision.is_none(), "both samples are free");
    let fine = TrajectoryOptions {
        max_step: Some(0.05),
        ..Default::default()
    };
    let r = cm
        .check_trajectory(&model, &mut cd, &times, &qs, &fine)
        .unwrap();
    let c = r.first_collision.expect("caught between the samples");
    let t_contact = (0.25f64 / 1.2).asin();
    assert!(c.last_free.unwrap() <= t_contact && t_contact <= c.time);
    assert!(c.time - t_contact <= 1e-6);
    assert_eq!(c.names.1, "thin");
}

#[test]
fn margin_turns_near_misses_into_collisions() {
    let (model, ..) = arm();
    // At q1 = 0.15 the tool is 0.2 - 1.2 sin 0.15 = 0.0207 from the wall.
    let gap = 0.2 - 1.2 * 0.15f64.sin();
    let q = [0.15, 0.0, 0.0, 0.0];
    for (margin, hit) in [(0.0, false), (gap - 1e-6, false), (gap + 1e-6, true)] {
        let opts = CollisionOptions {
            margin,
            ..Default::default()
        };
        let cm = CollisionModel::new(&model, vec![wall()], &opts).unwrap();
        let mut cd = CollisionData::new(&model, &cm);
        assert_eq!(
            cm.in_collision(&model, &mut cd, &q, Scope::All),
            hit,
            "margin {margin}"
        );
    }
}

#[test]
fn trajectory_input_is_validated() {
    let (model, ..) = arm();
    let cm = CollisionModel::new(&model, vec![wall()], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let o = TrajectoryOptions::default();
    let q = vec![0.0; 4];
    for (times, qs) in [
        (vec![0.0, 0.0], vec![q.clone(), q.clone()]),
        (vec![0.0], vec![q.clone(), q.clone()]),
        (vec![0.0], vec![vec![0.0; 3]]),
        (vec![f64::NAN], vec![q.clone()]),
    ] {
        assert!(matches!(
            cm.check_trajectory(&model, &mut cd, &times, &qs, &o),
            Err(CollisionError::Trajectory(_))
        ));
    }
}

// ---------------------------------------------------------------------------------------
// Meshes.

const CUBES: [&str; 4] = ["cube_binary.stl", "cube_ascii.stl", "cube.obj", "cube.dae"];

fn mesh_opts(convex_hulls: bool) -> CollisionOptions {
    CollisionOptions {
        convex_hulls,
        obstacle_dir: Some(data("tests/data/meshes")),
        ..Default::default()
    }
}

#[test]
fn mesh_cubes_give_the_primitive_box_distances() {
    // Every file describes the unit cube (DAE: ±1 with <unit meter="0.5">); placed with
    // scale (0.2, 0.4, 0.6) and a rotation, it must measure like the box primitive.
    let model = probe_model(Shape::Sphere { radius: 0.05 });
    let scale = [0.2, 0.4, 0.6];
    let pose = Se3::from_xyz_rpy([0.1, -0.2, 0.05], [0.2, 0.3, -0.4]);
    let h = scale.map(|s| s / 2.0);
    let mut rng = rand::rngs::SmallRng::seed_from_u64(4);
    let points: Vec<[f64; 3]> = (0..300).map(|_| random_point(&mut rng, 0.7)).collect();
    for file in CUBES {
        for hull in [false, true] {
            let ob = Obstacle::new(
                "cube",
                Shape::Mesh {
                    uri: file.to_string(),
                    scale,
                },
                pose,
            );
            let cm = CollisionModel::new(&model, vec![ob], &mesh_opts(hull))
                .unwrap_or_else(|e| panic!("{file}: {e}"));
            assert!(cm.warnings().is_empty(), "{:?}", cm.warnings());
            let mut cd = CollisionData::new(&model, &cm);
            let (mut checked, mut touching) = (0, 0);
            for &c in &points {
                let local = pose.inverse().act_point(&Vec3::from(c));
                let sdf = box_sdf(local.into(), h);
                let got = probe_distance(&model, &cm, &mut cd, c);
                if sdf > 0.0 {
                    // Outside (sphere may still overlap the surface): same as the box.
                    let want = sdf - 0.05;
                    assert!(
                        (got - want).abs() < 1e-9,
                        "{file} hull={hull} at {c:?}: {got} vs {want}"
                    );
                    checked += 1;
                    touching += (want < 0.0) as usize;
                } else {
                    // Centre inside: a collision; the hull measures the full depth.
                    assert!(got < 0.0, "{file} hull={hull}: inside but {got}");
                    if hull {
                        assert!((got - (sdf - 0.05)).abs() < 1e-6, "{got} vs {}", sdf - 0.05);
                    }
                    assert!(cm.first_collision(&cd, Scope::All).is_some());
                }
            }
            assert!(checked > 100 && touching > 0, "{checked} {touching}");
        }
    }
}

#[test]
fn dae_node_transforms_place_the_geometry() {
    // box_node_transform.dae: unit cube scaled (1, 2, 1), turned 90° about z, moved to
    // (1, 2, 3): the box of size (2, 1, 1) centred at (1, 2, 3).
    let model = probe_model(Shape::Sphere { radius: 0.1 });
    let ob = Obstacle::new(
        "m",
        Shape::Mesh {
            uri: "box_node_transform.dae".into(),
            scale: [1.0; 3],
        },
        Se3::identity(),
    );
    let cm = CollisionModel::new(&model, vec![ob], &mesh_opts(false)).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    for c in [
        [1.0, 2.0, 4.0],
        [2.5, 2.0, 3.0],
        [1.0, 3.0, 3.0],
        [-0.5, 0.9, 1.7],
    ] {
        let want = sphere_box(c, 0.1, [1.0, 2.0, 3.0], [2.0, 1.0, 1.0]);
        let got = probe_distance(&model, &cm, &mut cd, c);
        assert!((got - want).abs() < 1e-9, "at {c:?}: {got} vs {want}");
    }
}

#[test]
fn a_shape_wholly_inside_a_closed_mesh_is_in_collision() {
    let model = probe_model(Shape::Sphere { radius: 0.05 });
    let ob = Obstacle::new(
        "cube",
        Shape::Mesh {
            uri: "cube_binary.stl".into(),
            scale: [1.0; 3],
        },
        Se3::identity(),
    );
    let cm = CollisionModel::new(&model, vec![ob], &mesh_opts(false)).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    // Centre at (0.2, 0, 0): 0.3 from the +x face, the sphere touches no triangle.
    assert!(cm.in_collision(&model, &mut cd, &[0.2, 0.0, 0.0], Scope::All));
    let d = cm.min_distance(&mut cd, Scope::All).unwrap();
    assert!((d.distance + 0.25).abs() < 1e-9, "{}", d.distance);
    assert!(!cm.in_collision(&model, &mut cd, &[0.6, 0.0, 0.0], Scope::All));
}

#[test]
fn model_mesh_uris_resolve_and_missing_ones_are_reported() {
    // relative path, package:// found among the model's ancestors (tests/data/meshes),
    // and a package that exists nowhere.
    let model = load("tests/data/mesh_probe.urdf");
    let probe = Obstacle::sphere("probe", 0.1, [0.0, 0.0, 1.0]);
    let probe2 = Obstacle::sphere("probe2", 0.1, [5.0, 0.0, 1.0]);
    let cm =
        CollisionModel::new(&model, vec![probe, probe2], &CollisionOptions::default()).unwrap();
    assert_eq!(cm.unprotected_links(), ["missing".to_string()]);
    let w = cm.warnings().join("\n");
    assert!(
        w.contains("mesh_probe.urdf") && w.contains("link 'missing'"),
        "{w}"
    );
    assert!(
        w.contains("package://no_such_package/meshes/part.stl"),
        "{w}"
    );
    let mut cd = CollisionData::new(&model, &cm);
    cm.update(&model, &mut cd, &[]);
    let id = |n: &str| Body::Link(model.link_id(n).unwrap());
    let d = cm
        .body_distance(&cd, id("relative"), Body::Obstacle(0))
        .unwrap();
    assert!((d - (1.0 - 0.5 - 0.1)).abs() < 1e-9, "{d}");
    // The package cube is scaled to height 0.6.
    let d = cm
        .body_distance(&cd, id("package"), Body::Obstacle(1))
        .unwrap();
    assert!((d - (1.0 - 0.3 - 0.1)).abs() < 1e-9, "{d}");
    assert!(cm
        .body_distance(&cd, id("missing"), Body::Obstacle(0))
        .is_none());

    let strict = CollisionOptions {
        missing_meshes: MissingMeshes::Error,
        ..Default::default()
    };
    match CollisionModel::new(&model, vec![], &strict) {
        Err(e @ CollisionError::Mesh { .. }) => {
            let s = e.to_string();
            assert!(
                s.contains("mesh_probe.urdf") && s.contains("'missing'"),
                "{s}"
            );
            assert!(s.contains("no_such_package"), "{s}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn collision_options_package_path_finds_a_package() {
    // mesh_probe.urdf's link 'missing' names package://no_such_package/meshes/part.stl;
    // a package directory given in CollisionOptions::package_path makes it resolve.
    let model = load("tests/data/mesh_probe.urdf");
    let dir = std::env::temp_dir().join(format!("armsim_pkgpath_{}", std::process::id()));
    let meshes = dir.join("no_such_package/meshes");
    std::fs::create_dir_all(&meshes).unwrap();
    std::fs::copy(
        data("tests/data/meshes/cube_binary.stl"),
        meshes.join("part.stl"),
    )
    .unwrap();
    let opts = CollisionOptions {
        package_path: vec![dir.clone()],
        ..Default::default()
    };
    // The link sits at x = -5: a sphere of radius 0.1 centred 1 m above it.
    let probe = Obstacle::sphere("probe", 0.1, [-5.0, 0.0, 1.0]);
    let cm = CollisionModel::new(&model, vec![probe], &opts).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert!(cm.unprotected_links().is_empty(), "{:?}", cm.warnings());
    let mut cd = CollisionData::new(&model, &cm);
    cm.update(&model, &mut cd, &[]);
    let link = Body::Link(model.link_id("missing").unwrap());
    // The unit cube's top face at z = 0.5: 1 - 0.5 - 0.1.
    let d = cm.body_distance(&cd, link, Body::Obstacle(0)).unwrap();
    assert!((d - 0.4).abs() < 1e-9, "{d}");
}

#[test]
fn mesh_against_mesh() {
    // The link 'relative' of mesh_probe.urdf is the unit cube at the origin (a closed
    // triangle mesh); obstacles: the same cube as a mesh, 2 m above, and overlapping it by
    // 0.2 in z.
    let model = load("tests/data/mesh_probe.urdf");
    let cube = |name: &str, z: f64| {
        Obstacle::new(
            name,
            Shape::Mesh {
                uri: "cube.obj".into(),
                scale: [1.0; 3],
            },
            Se3::from_xyz_rpy([0.0, 0.0, z], [0.0; 3]),
        )
    };
    for hull in [false, true] {
        let cm = CollisionModel::new(
            &model,
            vec![cube("far", 3.0), cube("near", 0.8)],
            &mesh_opts(hull),
        )
        .unwrap();
        let mut cd = CollisionData::new(&model, &cm);
        cm.update(&model, &mut cd, &[]);
        let link = Body::Link(model.link_id("relative").unwrap());
        let far = cm.body_distance(&cd, link, Body::Obstacle(0)).unwrap();
        assert!((far - 2.0).abs() < 1e-9, "hull={hull}: {far}");
        // Depth: exact for the hulls; crossing triangle surfaces have no depth (≤ 0).
        let near = cm.body_distance(&cd, link, Body::Obstacle(1)).unwrap();
        if hull {
            assert!((near + 0.2).abs() < 1e-9, "hull: {near}");
        } else {
            assert!(near <= 0.0, "{near}");
        }
        let mut hits = Vec::new();
        cm.collisions(&mut cd, Scope::Environment, &mut hits);
        let names: Vec<(&str, &str)> = hits
            .iter()
            .map(|p| (cm.body_name(p.a), cm.body_name(p.b)))
            .collect();
        assert_eq!(names, [("relative", "near")], "hull={hull}");
    }
}

#[test]
fn scenes_can_be_shared_across_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<CollisionModel>();
    send_sync::<CollisionData>();
}

#[test]
fn file_uris_and_absolute_paths_resolve() {
    let model = probe_model(Shape::Sphere { radius: 0.1 });
    let abs = data("tests/data/meshes/cube.obj");
    for uri in [
        format!("file://{}", abs.display()),
        abs.display().to_string(),
    ] {
        let ob = Obstacle::new(
            "cube",
            Shape::Mesh {
                uri: uri.clone(),
                scale: [1.0; 3],
            },
            Se3::identity(),
        );
        // No obstacle_dir: absolute URIs do not need one.
        let cm = CollisionModel::new(&model, vec![ob], &CollisionOptions::default())
            .unwrap_or_else(|e| panic!("{uri}: {e}"));
        let mut cd = CollisionData::new(&model, &cm);
        let d = probe_distance(&model, &cm, &mut cd, [0.0, 0.0, 1.0]);
        assert!((d - 0.4).abs() < 1e-9);
    }
    // Obstacle meshes that cannot be found are always errors.
    let ob = Obstacle::new(
        "ghost",
        Shape::Mesh {
            uri: "no/such/file.stl".into(),
            scale: [1.0; 3],
        },
        Se3::identity(),
    );
    match CollisionModel::new(&model, vec![ob], &CollisionOptions::default()) {
        Err(CollisionError::Obstacle { name, reason }) => {
            assert_eq!(name, "ghost");
            assert!(reason.contains("no/such/file.stl"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn bundled_ur5_has_a_collision_mesh_on_every_arm_link() {
    let model = load("robots/ur5.urdf");
    let cm = CollisionModel::new(&model, vec![], &CollisionOptions::default()).unwrap();
    assert!(
        cm.unprotected_links().is_empty(),
        "{:?}",
        cm.unprotected_links()
    );
    assert!(cm.warnings().is_empty(), "{:?}", cm.warnings());
    let mut meshed: Vec<&str> = (0..cm.num_shapes())
        .map(|k| cm.shape(k))
        .filter(|(_, s)| matches!(s.kind, ShapeKind::TriMesh { .. }))
        .map(|(b, _)| cm.body_name(b))
        .collect();
    meshed.sort();
    assert_eq!(
        meshed,
        [
            "base_link_inertia",
            "forearm_link",
            "shoulder_link",
            "upper_arm_link",
            "wrist_1_link",
            "wrist_2_link",
            "wrist_3_link"
        ]
    );
}

/// Vertices of a binary STL file (read here, independently of `collision::mesh`).
fn stl_vertices(path: &std::path::Path) -> Vec<Vec3> {
    let b = std::fs::read(path).unwrap();
    let n = u32::from_le_bytes(b[80..84].try_into().unwrap()) as usize;
    assert_eq!(b.len(), 84 + 50 * n, "{}: not a binary STL", path.display());
    let f = |at: usize| f32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as f64;
    (0..n)
        .flat_map(|t| (0..3).map(move |k| 84 + 50 * t + 12 + 12 * k))
        .map(|at| Vec3::new(f(at), f(at + 4), f(at + 8)))
        .collect()
}

#[test]
fn ur5_forearm_mesh_to_box_distance_matches_its_vertices() {
    // UR5 at q = (0, -0.5, 0.5, 0, 0, 0): upper arm raised, forearm horizontal. A box
    // with horizontal faces, wide enough to cover the forearm's footprint, is placed above
    // it and then beside it (x face). Against a plane face the distance from a triangle
    // mesh is attained at a vertex, so the expected value is the vertex set's gap to the
    // face: the STL vertices (read in this test) moved to world by FK and the file's
    // collision origin.
    let model = load("robots/ur5.urdf");
    let q = [0.0, -0.5, 0.5, 0.0, 0.0, 0.0];
    let mut kin = armsim::model::data::Data::new(&model);
    armsim::kinematics::forward_kinematics(&model, &mut kin, &q);
    let li = model.link_id("forearm_link").unwrap();
    let link = &model.links[li];
    assert_eq!(link.collisions.len(), 1);
    let g = &link.collisions[0];
    let Shape::Mesh { uri, .. } = &g.shape else {
        panic!("forearm collision is not a mesh")
    };
    assert!(uri.ends_with("meshes/ur5/collision/forearm.stl"), "{uri}");
    let pose = kin.o_m_i[link.body].mul(&link.offset).mul(&g.origin);
    let verts: Vec<Vec3> = stl_vertices(&data("robots/meshes/ur5/collision/forearm.stl"))
        .iter()
        .map(|v| pose.act_point(v))
        .collect();
    let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
    for v in &verts {
        lo = lo.inf(v);
        hi = hi.sup(v);
    }
    // The real forearm: 0.39225 m between the joint axes, ~0.49 m of casing along x.
    assert!(
        (0.45..0.55).contains(&(hi.x - lo.x)),
        "forearm extent {lo:?} .. {hi:?}"
    );
    let gap = 0.05;
    let centre = (lo + hi) * 0.5;
    let above = Obstacle::cuboid(
        "above",
        [2.0, 2.0, 0.2],
        [centre.x, centre.y, hi.z + gap + 0.1],
    );
    // Beside: a 0.2 m thick slab spanning the whole arm in y and z, its -x face 0.03 m
    // beyond the forearm's farthest vertex in +x.
    let beside = Obstacle::cuboid("beside", [0.2, 2.0, 2.0], [hi.x + 0.03 + 0.1, 0.0, 0.0]);
    let cm =
        CollisionModel::new(&model, vec![above, beside], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    cm.update(&model, &mut cd, &q);
    let zmax = verts.iter().map(|v| v.z).fold(f64::NEG_INFINITY, f64::max);
    let xmax = verts.iter().map(|v| v.x).fold(f64::NEG_INFINITY, f64::max);
    let want_above = (hi.z + gap) - zmax;
    let want_beside = (hi.x + 0.03) - xmax;
    let d_above = cm
        .body_distance(&cd, Body::Link(li), Body::Obstacle(0))
        .unwrap();
    let d_beside = cm
        .body_distance(&cd, Body::Link(li), Body::Obstacle(1))
        .unwrap();
    assert!(
        (d_above - want_above).abs() < 1e-6,
        "{d_above} vs {want_above}"
    );
    assert!(
        (d_beside - want_beside).abs() < 1e-6,
        "{d_beside} vs {want_beside}"
    );
    // Lowered to 1 cm below the forearm's top, the box is in collision with it.
    let low = Obstacle::cuboid(
        "low",
        [2.0, 2.0, 0.2],
        [centre.x, centre.y, hi.z - 0.01 + 0.1],
    );
    let cm = CollisionModel::new(&model, vec![low], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    cm.update(&model, &mut cd, &q);
    assert!(
        cm.body_distance(&cd, Body::Link(li), Body::Obstacle(0))
            .unwrap()
            <= 0.0
    );
}

// ---------------------------------------------------------------------------------------
// Scenario-file obstacles.

#[test]
fn obstacle_specs_from_toml() {
    #[derive(serde::Deserialize)]
    struct File {
        obstacle: Vec<ObstacleSpec>,
    }
    let text = r#"
        [[obstacle]]
        name = "wall"
        shape = "box"
        size = [0.6, 0.2, 0.2]
        xyz = [1.3, 0.35, 0.4]

        [[obstacle]]
        name = "ball"
        shape = "sphere"
        radius = 0.1
        xyz = [-1.0, 0.0, 0.4]
        rpy = [0.0, 0.0, 1.0]
    "#;
    let f: File = toml::from_str(text).unwrap();
    let (model, ..) = arm();
    let cm = CollisionModel::from_specs(&model, &f.obstacle, &CollisionOptions::default()).unwrap();
    assert_eq!(cm.obstacles()[0], wall());
    let mut cd = CollisionData::new(&model, &cm);
    cm.update(&model, &mut cd, &[0.0; 4]);
    let d = cm.min_distance(&mut cd, Scope::Environment).unwrap();
    assert_eq!(cm.body_name(d.b), "wall");
    assert!((d.distance - 0.2).abs() < 1e-9);

    for (bad, why) in [
        ("name = 'a'\nshape = 'box'\nradius = 0.1", "not 'radius'"),
        (
            "name = 'a'\nshape = 'cylinder'\nradius = 0.1",
            "needs 'length'",
        ),
        ("name = 'a'\nshape = 'sphere'\nradius = -0.1", "positive"),
    ] {
        let spec: ObstacleSpec = toml::from_str(bad).unwrap();
        let e = CollisionModel::from_specs(&model, &[spec], &CollisionOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(why), "{e}");
    }
    assert!(toml::from_str::<ObstacleSpec>("name = 'a'\nshape = 'cone'").is_err());
    // Names must not clash with links or each other.
    let clash = Obstacle::sphere("link2", 0.1, [5.0, 0.0, 0.0]);
    assert!(CollisionModel::new(&model, vec![clash], &CollisionOptions::default()).is_err());
}

// ---------------------------------------------------------------------------------------
// Hot loop.

#[test]
fn queries_do_not_allocate_once_warm() {
    let (model, ..) = arm();
    let obstacles = vec![
        wall(),
        Obstacle::sphere("ball", 0.1, [-0.8, 0.3, 0.4]),
        Obstacle::new(
            "post",
            Shape::Cylinder {
                radius: 0.05,
                length: 1.0,
            },
            Se3::from_xyz_rpy([0.0, -0.9, 0.5], [0.0; 3]),
        ),
        Obstacle::new(
            "bar",
            Shape::Capsule {
                radius: 0.05,
                length: 1.0,
            },
            Se3::from_xyz_rpy([0.0, 0.9, 0.5], [1.0, 0.0, 0.0]),
        ),
    ];
    let cm = CollisionModel::new(&model, obstacles, &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let mut rng = rand::rngs::SmallRng::seed_from_u64(5);
    let qs: Vec<[f64; 4]> = (0..200)
        .map(|_| [0, 1, 2, 3].map(|_| rng.random_range(-3.0..3.0)))
        .collect();
    let mut warm = || {
        let mut hits = 0;
        for q in &qs {
            cm.update(&model, &mut cd, q);
            hits += cm.first_collision(&cd, Scope::All).is_some() as usize;
            let _ = cm.min_distance(&mut cd, Scope::Environment);
            let _ = cm.min_distance(&mut cd, Scope::SelfCollision);
        }
        hits
    };
    let hits = warm();
    assert!(hits > 10 && hits < 190, "{hits} of 200 in collision");
    let before = allocs();
    warm();
    assert_eq!(allocs() - before, 0, "allocations in the hot loop");
}
