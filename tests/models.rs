//! Model loading and forward kinematics against independent references: the UR5 URDF
//! against its DH table, the Panda URDF against its modified-DH table, the spherical
//! R-R-P arm against its closed forms, a tree against hand-derived frames, mimic joints.

mod common;

use armsim::core::spatial::Vec3;
use armsim::kinematics::{self, Expressed};
use armsim::model::data::Data;
use armsim::model::{JointType, Model};
use common::{load, pose_diff};
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

fn tool_pose(model: &Model, data: &mut Data, q: &[f64], link: &str) -> armsim::core::spatial::Se3 {
    kinematics::forward_kinematics(model, data, q);
    kinematics::frame_placement(model, data, model.link_id(link).expect(link))
}

/// Two models of one arm give the same tool pose on `n` random configurations.
fn same_tool(a: &Model, la: &str, b: &Model, lb: &str, n: usize, tol: f64) {
    assert_eq!(a.nv, b.nv);
    let (mut da, mut db) = (Data::new(a), Data::new(b));
    let mut rng = SmallRng::seed_from_u64(1);
    let mut worst = 0.0f64;
    for _ in 0..n {
        let q = a.random_q(&mut rng);
        let d = pose_diff(
            &tool_pose(a, &mut da, &q, la),
            &tool_pose(b, &mut db, &q, lb),
        );
        worst = worst.max(d);
    }
    assert!(
        worst <= tol,
        "{} '{la}' vs {} '{lb}': worst difference {worst:e}",
        a.source,
        b.source
    );
}

#[test]
fn ur5_urdf_and_dh_table_give_the_same_tool_pose() {
    let urdf = load("robots/ur5.urdf");
    let dh = load("robots/ur5_dh.toml");
    assert_eq!(urdf.dof_names(), dh.dof_names());
    same_tool(&urdf, "tool0", &dh, "tool", 1000, 1e-12);
}

#[test]
fn panda_urdf_and_modified_dh_table_give_the_same_flange_pose() {
    let urdf = load("robots/panda.urdf");
    let dh = load("robots/panda_mdh.toml");
    // The URDF carries the gripper (one independent finger coordinate); compare the arm.
    assert_eq!(urdf.nv, 8);
    assert_eq!(dh.nv, 7);
    let (mut du, mut dd) = (Data::new(&urdf), Data::new(&dh));
    let mut rng = SmallRng::seed_from_u64(2);
    let mut worst = 0.0f64;
    for _ in 0..1000 {
        let q7 = dh.random_q(&mut rng);
        // The eighth coordinate is the (mimic) finger: 2 cm open.
        let q8: Vec<f64> = q7.iter().copied().chain([0.02]).collect();
        let d = pose_diff(
            &tool_pose(&urdf, &mut du, &q8, "panda_link8"),
            &tool_pose(&dh, &mut dd, &q7, "tool"),
        );
        worst = worst.max(d);
    }
    assert!(worst <= 1e-12, "worst difference {worst:e}");
}

#[test]
fn spherical_rrp_matches_closed_form_fk_and_inverse() {
    let m = load("robots/textbook_spherical_rrp.toml");
    assert_eq!(m.nv, 3);
    assert_eq!(m.dof_joint(2).jtype, JointType::Prismatic);
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(3);
    for _ in 0..1000 {
        let q = m.random_q(&mut rng);
        let (g1, b2, r) = (q[0], q[1], q[2]);
        let p = tool_pose(&m, &mut data, &q, "tool").trans;
        let expect = Vec3::new(
            r * g1.cos() * b2.cos(),
            r * g1.sin() * b2.cos(),
            r * b2.sin(),
        );
        assert!((p - expect).norm() < 1e-12, "q {q:?}: {p:?} vs {expect:?}");
        // Closed-form inverse, unique inside these limits (|g1| < pi, |b2| < pi/2, r > 0).
        let inv = [
            p.y.atan2(p.x),
            p.z.atan2((p.x * p.x + p.y * p.y).sqrt()),
            p.norm(),
        ];
        for k in 0..3 {
            assert!((inv[k] - q[k]).abs() < 1e-12, "inverse {inv:?} vs q {q:?}");
        }
    }
}

#[test]
fn tree_gives_correct_frames_on_both_branches() {
    let m = load("tests/data/dual_arm.urdf");
    assert_eq!(
        m.dof_names(),
        [
            "left_shoulder",
            "left_elbow",
            "right_shoulder",
            "right_elbow"
        ]
    );
    let mut data = Data::new(&m);
    let mut rng = SmallRng::seed_from_u64(4);
    let tip = |side: f64, a: f64, b: f64| {
        Vec3::new(
            0.3 * a.cos() + 0.25 * (a + b).cos(),
            0.2 * side,
            1.0 + 0.3 * a.sin() + 0.25 * (a + b).sin(),
        )
    };
    for _ in 0..200 {
        let q: Vec<f64> = (0..4).map(|_| rng.random_range(-3.0..3.0)).collect();
        let l = tool_pose(&m, &mut data, &q, "left_tool").trans;
        let r = tool_pose(&m, &mut data, &q, "right_tool").trans;
        assert!((l - tip(1.0, q[0], q[1])).norm() < 1e-14);
        assert!((r - tip(-1.0, q[2], q[3])).norm() < 1e-14);
        // A branch's Jacobian has zero columns for the other branch.
        let mut j = DMatrix::zeros(6, 4);
        kinematics::compute_joint_jacobians(&m, &mut data, &q);
        kinematics::frame_jacobian(
            &m,
            &data,
            m.link_id("left_tool").unwrap(),
            Expressed::World,
            &mut j,
        );
        assert_eq!(j.columns(2, 2).abs().max(), 0.0);
        assert!(j.columns(0, 2).abs().max() > 0.1);
    }
}

#[test]
fn mimic_joints_follow_their_master_and_are_not_coordinates() {
    let m = load("tests/data/mimic_gripper.urdf");
    // shoulder, elbow, finger_left_joint; finger_right and knuckle are mimic joints.
    assert_eq!(m.dof_names(), ["shoulder", "elbow", "finger_left_joint"]);
    assert_eq!(m.nbodies(), 5);
    let mut data = Data::new(&m);
    let q = [0.3, -0.7, 0.015];
    kinematics::forward_kinematics(&m, &mut data, &q);
    let palm = kinematics::frame_placement(&m, &data, m.link_id("palm").unwrap());
    let right = kinematics::frame_placement(&m, &data, m.link_id("finger_right").unwrap());
    let knuckle = kinematics::frame_placement(&m, &data, m.link_id("knuckle").unwrap());
    // finger_right: q = -1 * 0.015 + 0.01 along palm y, from (0, -0.02, 0.05).
    let local = palm.inv_mul(&right).trans;
    assert!(
        (local - Vec3::new(0.0, -0.02 - 0.005, 0.05)).norm() < 1e-15,
        "{local:?}"
    );
    // knuckle mimics finger_right with multiplier 10: angle 10 * (-0.005) = -0.05 about x.
    let rel = right.inv_mul(&knuckle);
    let angle = rel.rot[(2, 1)].atan2(rel.rot[(1, 1)]);
    assert!((angle + 0.05).abs() < 1e-15, "{angle}");
    let (mj, mult, off) = m.joints[m.joint_id("knuckle_joint").unwrap()]
        .mimic
        .unwrap();
    assert_eq!(m.joints[mj].name, "finger_left_joint");
    assert!((mult + 10.0).abs() < 1e-15 && (off - 0.1).abs() < 1e-15);
}

#[test]
fn fixed_joints_are_folded_but_their_links_stay_queryable() {
    let m = load("robots/ur5.urdf");
    let movable = m.joints.iter().filter(|j| j.jtype.is_movable()).count();
    assert_eq!(m.nbodies(), movable);
    assert!(m.joints.len() > movable, "the UR5 URDF has fixed joints");
    for l in &m.links {
        assert!(m.link_id(&l.name).is_some());
    }
}

#[test]
fn standard_and_modified_dh_describe_the_same_planar_arm() {
    let std_text = "convention = \"standard\"\n[[joint]]\ntype = \"R\"\na = 0.4\ncontinuous = true\n[[joint]]\ntype = \"R\"\na = 0.3\ncontinuous = true\n";
    let mod_text = "convention = \"modified\"\n[[joint]]\ntype = \"R\"\ncontinuous = true\n[[joint]]\ntype = \"R\"\na = 0.4\ncontinuous = true\n[tool]\nxyz = [0.3, 0.0, 0.0]\n";
    let s = Model::build(armsim::model::parse::dh_table::parse(std_text, "std.toml").unwrap())
        .unwrap()
        .0;
    let m = Model::build(armsim::model::parse::dh_table::parse(mod_text, "mod.toml").unwrap())
        .unwrap()
        .0;
    same_tool(&s, "tool", &m, "tool", 200, 1e-15);
    let mut d = Data::new(&s);
    let p = tool_pose(&s, &mut d, &[0.5, -1.2], "tool").trans;
    let expect = Vec3::new(
        0.4 * 0.5f64.cos() + 0.3 * (-0.7f64).cos(),
        0.4 * 0.5f64.sin() + 0.3 * (-0.7f64).sin(),
        0.0,
    );
    assert!((p - expect).norm() < 1e-15);
}

#[test]
fn twenty_thousand_link_chain_loads_without_recursion() {
    // Built from the spec directly; the URDF route is exercised by tests/broken_models.rs.
    let spec = armsim::model::chain::chain_spec(20_000);
    let handle = std::thread::Builder::new()
        .stack_size(256 * 1024)
        .spawn(move || {
            let (m, _) = Model::build(spec).unwrap();
            let mut data = Data::new(&m);
            let q = vec![0.0; m.nv];
            kinematics::forward_kinematics(&m, &mut data, &q);
            kinematics::frame_placement(&m, &data, m.link_id("link20000").unwrap())
                .trans
                .z
        })
        .unwrap();
    let z = handle.join().unwrap();
    assert!((z - 0.1 * 19_999.0).abs() < 1e-9, "{z}");
}

/// Per link: its name and the `(radius, origin xyz)` of each collision sphere.
type LinkSpheres = Vec<(String, Vec<(f64, [f64; 3])>)>;

/// Collision spheres per link of a URDF, read independently of armsim's loader: for each
/// `<link>`, the `(radius, origin xyz)` of every `<collision><geometry><sphere>`, and the
/// number of collision elements that are not spheres.
fn collision_spheres(text: &str) -> (LinkSpheres, usize) {
    let doc = roxmltree::Document::parse(text).expect("XML");
    let nums = |s: &str| -> Vec<f64> { s.split_whitespace().map(|x| x.parse().unwrap()).collect() };
    let mut other = 0;
    let mut links = Vec::new();
    for link in doc
        .root_element()
        .children()
        .filter(|n| n.has_tag_name("link"))
    {
        let mut spheres = Vec::new();
        for c in link.children().filter(|n| n.has_tag_name("collision")) {
            let xyz = c
                .children()
                .find(|n| n.has_tag_name("origin"))
                .and_then(|o| o.attribute("xyz"))
                .map_or(vec![0.0; 3], nums);
            let shape = c
                .descendants()
                .find(|n| n.has_tag_name("sphere"))
                .and_then(|s| s.attribute("radius"));
            match shape {
                Some(r) => spheres.push((r.parse().unwrap(), [xyz[0], xyz[1], xyz[2]])),
                None => other += 1,
            }
        }
        links.push((link.attribute("name").unwrap().to_string(), spheres));
    }
    (links, other)
}

#[test]
fn spherized_planning_models_load_with_their_coordinates_and_every_collision_sphere() {
    let bench = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/benchmarks/motion-planning");
    let panda_joints: Vec<String> = (1..=7).map(|k| format!("panda_joint{k}")).collect();
    let ur5_joints: Vec<String> = [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    ]
    .map(String::from)
    .to_vec();
    for (robot, nv, total, names) in [("panda", 7, 59, panda_joints), ("ur5", 6, 40, ur5_joints)] {
        let rel = format!("robots/spherized/{robot}_spherized.urdf");
        let text =
            std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(&rel))
                .unwrap();
        // The repository copy is the benchmark's file, unchanged.
        let shared = bench.join(format!("{robot}/{robot}_spherized.urdf"));
        match std::fs::read_to_string(&shared) {
            Ok(s) => assert_eq!(s, text, "{rel} differs from {}", shared.display()),
            Err(e) => panic!(
                "benchmark data expected at {} (../shared beside the clone): {e}",
                shared.display()
            ),
        }
        let (model, warnings) =
            Model::load(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(&rel))
                .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(model.nv, nv, "{robot}");
        assert_eq!(model.dof_names(), names, "{robot}");
        // Only the Panda's fixed finger carries a <mimic> (ignored with a warning).
        let expect_warn = usize::from(robot == "panda");
        assert_eq!(warnings.len(), expect_warn, "{warnings:?}");
        let (links, other) = collision_spheres(&text);
        assert_eq!(other, 0, "{robot}: non-sphere collision elements");
        let mut count = 0;
        for (name, spheres) in &links {
            let l = &model.links[model.link_id(name).expect(name)];
            assert_eq!(l.collisions.len(), spheres.len(), "{robot} link {name}");
            for (g, (r, xyz)) in l.collisions.iter().zip(spheres) {
                assert_eq!(
                    g.shape,
                    armsim::model::Shape::Sphere { radius: *r },
                    "{name}"
                );
                assert_eq!(g.origin.trans, Vec3::from(*xyz), "{name}");
                assert_eq!(g.origin.rot, nalgebra::Matrix3::identity(), "{name}");
            }
            count += spheres.len();
        }
        assert_eq!(count, total, "{robot}: collision spheres");
    }
    // Hand-read: the Panda's base sphere, radius 0.08 at z = 0.05 of panda_link0.
    let (panda, _) = Model::load(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("robots/spherized/panda_spherized.urdf"),
    )
    .unwrap();
    let base = &panda.links[panda.link_id("panda_link0").unwrap()].collisions;
    assert_eq!(base.len(), 1);
    assert_eq!(base[0].shape, armsim::model::Shape::Sphere { radius: 0.08 });
    assert_eq!(base[0].origin.trans, Vec3::new(0.0, 0.0, 0.05));
    assert_eq!(
        panda.links[panda.link_id("panda_hand").unwrap()]
            .collisions
            .len(),
        18
    );
}

#[test]
fn spherized_panda_has_the_kinematics_of_the_bundled_panda() {
    let a = load("robots/spherized/panda_spherized.urdf");
    let b = load("robots/panda.urdf");
    // The bundled Panda's eighth coordinate is its (movable) finger.
    assert_eq!(b.dof_names()[..7], a.dof_names()[..]);
    assert_eq!(b.dof_names()[7], "panda_finger_joint1");
    let (mut da, mut db) = (Data::new(&a), Data::new(&b));
    let mut rng = SmallRng::seed_from_u64(3);
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let q = a.random_q(&mut rng);
        let qb: Vec<f64> = q.iter().copied().chain([0.02]).collect();
        for link in ["panda_link8", "panda_hand"] {
            let d = pose_diff(
                &tool_pose(&a, &mut da, &q, link),
                &tool_pose(&b, &mut db, &qb, link),
            );
            worst = worst.max(d);
        }
    }
    // The spherized file writes π/2 as 1.57079632679 (4.9e-12 rad short) on six joints:
    // up to ~3e-11 rad of rotation error, times ~1 m of arm; anything else shows as > 1e-4.
    assert!(worst < 1e-10, "worst difference {worst:e}");
}

#[test]
fn mimic_on_a_fixed_joint_is_ignored_with_a_warning_naming_file_line_and_joint() {
    let urdf = r#"<robot name="g">
  <link name="hand"/>
  <link name="finger"/>
  <link name="other"/>
  <joint name="slide" type="prismatic">
    <parent link="hand"/><child link="finger"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.2"/>
  </joint>
  <joint name="fixed_finger" type="fixed">
    <parent link="hand"/><child link="other"/>
    <mimic joint="slide" multiplier="-1"/>
  </joint>
</robot>"#;
    let (m, w) = Model::load_str(urdf, "g.urdf", &Default::default()).unwrap();
    assert_eq!(m.nv, 1);
    assert_eq!(m.dof_names(), ["slide"]);
    let fixed = &m.joints[m.joint_id("fixed_finger").unwrap()];
    assert_eq!(fixed.jtype, JointType::Fixed);
    assert!(fixed.mimic.is_none() && fixed.dof.is_none());
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(
        w[0].to_string(),
        "g.urdf:9: joint 'fixed_finger': <mimic joint=\"slide\"> on a fixed joint: ignored (a fixed joint does not move)"
    );
    // Strict loading turns it into the error.
    let strict = armsim::model::LoadOptions {
        strict: true,
        ..Default::default()
    };
    let e = Model::load_str(urdf, "g.urdf", &strict).unwrap_err();
    assert_eq!(e.line, Some(9));
}

#[test]
fn support_walks_from_a_body_to_the_root_and_stroke_bounds_a_prismatic_slide() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    // The full Panda: seven revolute joints in a chain, then a prismatic finger.
    let (m, _) = Model::load(root.join("robots/panda.urdf")).unwrap();
    let finger = m.links[m.link_id("panda_leftfinger").unwrap()].body;
    let chain: Vec<usize> = m.support(finger).collect();
    assert_eq!(chain.len(), 8);
    assert_eq!(chain[0], finger);
    for w in chain.windows(2) {
        assert_eq!(m.parent[w[0]], w[1]);
    }
    assert_eq!(m.parent[chain[7]], armsim::model::WORLD);
    assert_eq!(m.support(armsim::model::WORLD).count(), 0);
    // The finger slides 0–4 cm; a revolute joint does not slide.
    assert_eq!(m.stroke(finger, 0.0, 0.04), 0.04);
    assert_eq!(m.stroke(finger, -0.03, 0.01), 0.03);
    assert_eq!(m.stroke(chain[1], -3.0, 3.0), 0.0);
}

#[test]
fn tool_link_is_the_last_link_on_the_body_where_the_serial_chain_ends() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let tool = |file: &str| {
        let (m, _) = Model::load(root.join(file)).unwrap();
        m.links[m.tool_link()].name.clone()
    };
    // The UR5's last link is `base`, fixed to the world: the chain ends at wrist 3.
    assert_eq!(tool("robots/ur5.urdf"), "tool0");
    // The Panda's hand carries two fingers: the chain ends at link 7's body.
    assert_eq!(tool("robots/panda.urdf"), "panda_hand_tcp");
    assert_eq!(tool("robots/iiwa14.urdf"), "iiwa_link_ee");
    // Two arms on a fixed torso: no single tool, the last link.
    let (m, _) = Model::load(root.join("tests/data/dual_arm.urdf")).unwrap();
    assert_eq!(m.tool_link(), m.links.len() - 1);
}
