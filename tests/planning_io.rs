//! Planning inputs: every MotionBenchMaker problem of the benchmark data (MoveIt planning
//! scenes and motion plan requests, `validity.json`) and the SRDFs of the spherized
//! models read into armsim's types, checked against values read by hand from the files;
//! broken inputs refused with the file, the line, the element and the problem.
//!
//! The benchmark data lives outside the repository, at `../shared/benchmarks/
//! motion-planning` relative to the crate root.

use armsim::collision::Obstacle;
use armsim::core::spatial::{axis_angle, rot_z, Mat3, Vec3};
use armsim::model::{Model, Shape};
use armsim::planning::moveit::{self, parse_request, parse_scene, quaternion_matrix};
use armsim::planning::plan_error::PlanningInputError;
use armsim::planning::srdf::{self, parse_srdf};
use std::path::PathBuf;

const ROBOTS: [&str; 2] = ["panda", "ur5"];
const SCENES: [&str; 3] = ["table_pick", "bookshelf_small", "box"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bench() -> PathBuf {
    let d = root().join("../shared/benchmarks/motion-planning");
    assert!(
        d.is_dir(),
        "the motion-planning benchmark data is expected at {} (../shared/benchmarks/motion-planning beside the clone)",
        d.display()
    );
    d
}

fn model(robot: &str) -> Model {
    let p = root().join(format!("robots/spherized/{robot}_spherized.urdf"));
    Model::load(&p).unwrap_or_else(|e| panic!("{e}")).0
}

fn max_abs_diff(a: &Mat3, b: &Mat3) -> f64 {
    (a - b).abs().max()
}

/// The error must print as `FILE:LINE: ELEMENT: …MESSAGE…`.
fn assert_error(e: &PlanningInputError, file: &str, line: usize, element: &str, message: &str) {
    assert_eq!(e.file, file, "{e}");
    assert_eq!(e.line, Some(line), "{e}");
    assert_eq!(e.key, element, "{e}");
    assert!(e.message.contains(message), "{e}\n  lacks: {message}");
    assert!(
        e.to_string()
            .starts_with(&format!("{file}:{line}: {element}: ")),
        "{e}"
    );
}

#[test]
fn all_600_benchmark_problems_parse_into_obstacles_and_model_order_joint_values() {
    let dir = bench();
    for robot in ROBOTS {
        let m = model(robot);
        let fingers = if robot == "panda" { 2 } else { 6 };
        let validity = moveit::load_validity(dir.join(robot).join("validity.json")).unwrap();
        assert_eq!(validity.robot, robot);
        assert_eq!(validity.joints, m.dof_names());
        let (mut boxes, mut cylinders, mut invalid) = (0, 0, 0);
        for scene in SCENES {
            let pairs = moveit::problem_pairs(dir.join(robot).join(scene)).unwrap();
            assert_eq!(pairs.len(), 100, "{robot}/{scene}");
            let listed = &validity.problems[scene];
            assert_eq!(listed.len(), 100, "{robot}/{scene}");
            for (k, (p, v)) in pairs.iter().zip(listed).enumerate() {
                assert_eq!(p.id, format!("{:04}", k + 1));
                assert_eq!(v.problem, p.id);
                assert_eq!(
                    p.scene.file_name().unwrap(),
                    format!("scene{}.yaml", p.id).as_str()
                );
                invalid += usize::from(!v.valid);
                let obstacles = moveit::load_scene(&p.scene).unwrap_or_else(|e| panic!("{e}"));
                for o in &obstacles {
                    match o.shape {
                        Shape::Box { .. } => boxes += 1,
                        Shape::Cylinder { .. } => cylinders += 1,
                        _ => panic!("{}: {:?}", p.scene.display(), o.shape),
                    }
                    let r = o.pose.rot;
                    assert!(max_abs_diff(&(r.transpose() * r), &Mat3::identity()) < 1e-12);
                }
                let (req, warnings) =
                    moveit::load_request(&p.request, &m).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(req.joints, m.dof_names());
                assert_eq!((req.start.len(), req.goal.len()), (m.nv, m.nv));
                // The finger joints are listed in the start state but fixed in the model.
                assert_eq!(warnings.len(), fingers, "{warnings:?}");
                assert!(warnings.iter().all(|w| w.message.contains("not movable")));
            }
        }
        // Counted with grep over the scene files: 2000 boxes, 600 cylinders per robot;
        // validity.json marks 1 (Panda) and 4 (UR5) problems invalid.
        assert_eq!((boxes, cylinders), (2000, 600), "{robot}");
        assert_eq!(invalid, if robot == "panda" { 1 } else { 4 }, "{robot}");
    }
}

#[test]
fn panda_table_pick_0001_box_object2_has_the_hand_read_size_and_pose() {
    let obstacles = moveit::load_scene(bench().join("panda/table_pick/scene0001.yaml")).unwrap();
    let names: Vec<&str> = obstacles.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names.len(), 12);
    assert_eq!(names[..4], ["Can1", "Cube", "Object1", "Object2"]);
    let o = &obstacles[3];
    // primitives: - type: box, dimensions: [0.2, 0.02, 0.4]
    assert_eq!(
        o.shape,
        Shape::Box {
            size: [0.2, 0.02, 0.4]
        }
    );
    assert_eq!(
        o.pose.trans,
        Vec3::new(0.6435179474935337, 0.8962887843757334, 0.3984669621486253)
    );
    // orientation [0, 0, z, w] = [0, 0, -0.1166228298102158, 0.9931762761801439]: a turn
    // about z by 2 atan2(z, w) = -0.2337776466 rad; cos = 1 - 2 z², sin = 2 z w.
    let theta = 2.0 * f64::atan2(-0.1166228298102158, 0.9931762761801439);
    assert!((theta - -0.23377764661144285).abs() < 1e-15);
    assert!(max_abs_diff(&o.pose.rot, &rot_z(theta)) < 1e-15);
    let (c, s) = (0.9727982311341149, -0.2316540556570016);
    let hand = Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    assert!(max_abs_diff(&o.pose.rot, &hand) < 1e-15, "{}", o.pose.rot);
    // A cylinder's dimensions are [height, radius]: Can1 [0.12, 0.03].
    assert_eq!(
        obstacles[0].shape,
        Shape::Cylinder {
            radius: 0.03,
            length: 0.12
        }
    );
}

#[test]
fn object_pose_composes_before_the_primitive_pose() {
    // ur5/table_pick/scene0001.yaml, Can1: pose = position p, a turn about z
    // (quaternion [0, 0, 0.99725…, 0.07409…], θ = 2.99327 rad); primitive pose = position
    // [0.85, 0, 0.8], identity. World = p + Rz(θ) [0.85, 0, 0.8].
    let obstacles = moveit::load_scene(bench().join("ur5/table_pick/scene0001.yaml")).unwrap();
    let can = &obstacles[0];
    assert_eq!(can.name, "Can1");
    let theta = 2.0 * f64::atan2(0.9972514405491772, 0.07409159414259425);
    let p = [
        -0.06371788662107358,
        -0.1102475820769556,
        0.08705641176758652,
    ];
    let expect = Vec3::new(
        p[0] + 0.85 * theta.cos(),
        p[1] + 0.85 * theta.sin(),
        p[2] + 0.8,
    );
    assert!(
        (can.pose.trans - expect).norm() < 1e-14,
        "{}",
        can.pose.trans
    );
    // Computed separately (Python, same formula): [-0.904385627272669, 0.0153619312082325, 0.8870564117675865].
    assert!(
        (can.pose.trans - Vec3::new(-0.904385627272669, 0.0153619312082325, 0.8870564117675865))
            .norm()
            < 1e-14
    );
    assert!(max_abs_diff(&can.pose.rot, &rot_z(theta)) < 1e-14);
}

#[test]
fn a_general_quaternion_is_the_rotation_about_its_axis_by_twice_its_angle() {
    // panda/box/scene0001.yaml, side_cap: orientation [x, y, z, w].
    let q = [
        -0.0283616206065852,
        0.3818591884381666,
        0.068_423_335_353_746, // 0.06842333535374601 in the file: the same f64
        0.9212477548743235,
    ];
    let v = Vec3::new(q[0], q[1], q[2]);
    let reference = axis_angle(&v.normalize(), 2.0 * f64::atan2(v.norm(), q[3]));
    let r = quaternion_matrix(q).unwrap();
    assert!(max_abs_diff(&r, &reference) < 1e-15, "{r} vs {reference}");
    // Scaling the quaternion does not change the rotation (it is normalised).
    let r3 = quaternion_matrix(q.map(|c| 3.0 * c)).unwrap();
    assert!(max_abs_diff(&r3, &r) < 1e-15);
    assert!(quaternion_matrix([0.0; 4]).is_none());
    let cap = moveit::load_scene(bench().join("panda/box/scene0001.yaml"))
        .unwrap()
        .into_iter()
        .find(|o| o.name == "side_cap")
        .unwrap();
    assert!(max_abs_diff(&cap.pose.rot, &reference) < 1e-15);
    assert_eq!(
        cap.shape,
        Shape::Box {
            size: [0.7, 0.7, 0.04]
        }
    );
}

#[test]
fn panda_table_pick_0001_request_has_the_hand_read_start_and_goal() {
    let m = model("panda");
    let (req, warnings) =
        moveit::load_request(bench().join("panda/table_pick/request0001.yaml"), &m).unwrap();
    assert_eq!(req.start, [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]);
    assert_eq!(
        req.goal,
        [
            -1.451140183264752,
            -0.9510103288438848,
            2.419034489081648,
            -1.139058262758865,
            -2.647403722074262,
            2.824576369312635,
            0.8869533207576928
        ]
    );
    assert_eq!(req.group.as_deref(), Some("panda_arm"));
    assert_eq!(req.planner_id.as_deref(), Some("BKPIECEGood"));
    assert_eq!(req.allowed_planning_time, Some(60.0));
    let w: Vec<String> = warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 2);
    assert!(w[0].contains(":24: start_state.joint_state.name[7]: joint 'panda_finger_joint1' is not movable in the model (fixed): its value 0.065 is ignored"), "{w:?}");
}

const PANDA_REVERSED: &str = "start_state:
  joint_state:
    name: [panda_joint7, panda_joint6, panda_joint5, panda_joint4, panda_joint3, panda_joint2, panda_joint1]
    position: [7, 6, 5, 4, 3, 2, 1]
goal_constraints:
  - joint_constraints:
      - {joint_name: panda_joint3, position: 0.3}
      - {joint_name: panda_joint1, position: 0.1}
      - {joint_name: panda_joint2, position: 0.2}
      - {joint_name: panda_joint7, position: 0.7}
      - {joint_name: panda_joint5, position: 0.5}
      - {joint_name: panda_joint4, position: 0.4}
      - {joint_name: panda_joint6, position: 0.6}
";

#[test]
fn request_values_are_put_in_model_order_whatever_the_file_order() {
    let (req, w) = parse_request(PANDA_REVERSED, "r.yaml", &model("panda")).unwrap();
    assert!(w.is_empty());
    assert_eq!(req.start, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
    assert_eq!(req.goal, [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]);
    assert_eq!(req.group, None);
}

#[test]
fn several_primitives_of_one_object_become_obstacles_id_id1_id2() {
    let yaml = "world:
  collision_objects:
    - id: rack
      pose: {position: {x: 1, y: 0, z: 0}, orientation: {x: 0, y: 0, z: 0, w: 1}}
      operation: 0
      header: {frame_id: world}
      primitives:
        - {type: box, dimensions: [1, 2, 3]}
        - {type: sphere, dimensions: [0.5]}
        - {type: 3, dimensions: [2, 0.25]}
      primitive_poses:
        - {position: [0, 0, 1]}
        - {position: [0, 0, 2], orientation: [0, 0, 0, 1]}
        - {}
    - id: post
      primitives: [{type: sphere, dimensions: [0.1]}]
      primitive_poses: [{}]
";
    let o = parse_scene(yaml, "s.yaml", &[]).unwrap();
    let names: Vec<&str> = o.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["rack", "rack/1", "rack/2", "post"]);
    let expect = [
        Obstacle::cuboid("rack", [1.0, 2.0, 3.0], [1.0, 0.0, 1.0]),
        Obstacle::sphere("rack/1", 0.5, [1.0, 0.0, 2.0]),
        Obstacle::new(
            "rack/2",
            Shape::Cylinder {
                radius: 0.25,
                length: 2.0,
            },
            armsim::core::spatial::Se3::from_xyz_rpy([1.0, 0.0, 0.0], [0.0; 3]),
        ),
        Obstacle::sphere("post", 0.1, [0.0; 3]),
    ];
    assert_eq!(o, expect);
    // An empty world is no obstacles; the model's root link may be named as the frame.
    assert!(parse_scene("name: empty\n", "s.yaml", &[])
        .unwrap()
        .is_empty());
    let in_base = yaml.replace("frame_id: world", "frame_id: panda_link0");
    assert!(parse_scene(&in_base, "s.yaml", &[]).is_err());
    assert_eq!(
        parse_scene(&in_base, "s.yaml", &["panda_link0"]).unwrap(),
        expect
    );
}

#[test]
fn spherized_srdfs_give_their_disabled_pairs() {
    for (robot, n, first) in [
        ("panda", 34, ("panda_link0", "panda_link1")),
        ("ur5", 88, ("base_link", "shoulder_link")),
    ] {
        let path = root().join(format!("robots/spherized/{robot}.srdf"));
        let (pairs, warnings) = srdf::load_disabled_pairs(&path, &model(robot)).unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(pairs.len(), n, "{robot}");
        assert_eq!((pairs[0].0.as_str(), pairs[0].1.as_str()), first, "{robot}");
        let s = srdf::load_srdf(&path).unwrap();
        assert_eq!(s.disabled.len(), n);
        let text = std::fs::read_to_string(&path).unwrap();
        let line = 1 + text[..text.find("<disable_collisions").unwrap()]
            .matches('\n')
            .count();
        assert_eq!(s.disabled[0].line, line);
    }
    let s = srdf::load_srdf(root().join("robots/spherized/panda.srdf")).unwrap();
    let arm = s.groups.iter().find(|g| g.name == "panda_arm").unwrap();
    assert_eq!(
        arm.chains,
        [("panda_link0".to_string(), "panda_link8".to_string())]
    );
}

#[test]
fn srdf_pairs_with_unknown_links_are_skipped_with_a_warning_and_enable_collisions_removes_pairs() {
    let text = r#"<robot name="panda">
  <disable_collisions link1="panda_link0" link2="panda_link1" reason="Adjacent"/>
  <disable_collisions link1="panda_link1" link2="panda_link9" reason="Never"/>
  <disable_collisions link1="panda_link2" link2="panda_link3" reason="Adjacent"/>
  <enable_collisions link1="panda_link3" link2="panda_link2"/>
</robot>"#;
    let s = parse_srdf(text, "p.srdf").unwrap();
    let (pairs, w) = s.disabled_pairs(&model("panda"));
    assert_eq!(
        pairs,
        [("panda_link0".to_string(), "panda_link1".to_string())]
    );
    assert_eq!(w.len(), 1);
    assert_error(
        &w[0],
        "p.srdf",
        3,
        "<disable_collisions link1=\"panda_link1\" link2=\"panda_link9\">",
        "link 'panda_link9' is not in model 'panda': pair ignored",
    );
}

// ---------------------------------------------------------------------------------------
// Broken inputs.
// ---------------------------------------------------------------------------------------

/// The Panda table_pick scene 0001 with `from` replaced by `to` (once; it must be there).
fn scene_with(from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(bench().join("panda/table_pick/scene0001.yaml")).unwrap();
    assert_eq!(text.matches(from).count(), 1, "{from}");
    text.replacen(from, to, 1)
}

#[test]
fn truncated_yaml_is_refused_at_the_line_it_stops() {
    let text = std::fs::read_to_string(bench().join("panda/table_pick/scene0001.yaml")).unwrap();
    // Cut inside the flow list `position: [0.308…, 0.839…, …]` of Can1 (line 34).
    let cut = text.find("0.8398608492910964").unwrap();
    let e = parse_scene(&text[..cut], "cut.yaml", &[]).unwrap_err();
    assert_error(
        &e,
        "cut.yaml",
        34,
        "YAML",
        "did not find expected node content",
    );
    // Cut just after `primitives:` of Can1 (line 36): valid YAML, but the object (from
    // line 33) has lost its id, written after it.
    let cut = text
        .find("primitives:\n        - dimensions: [0.12")
        .unwrap();
    let e = parse_scene(&text[..cut + "primitives:".len()], "cut.yaml", &[]).unwrap_err();
    assert_error(
        &e,
        "cut.yaml",
        33,
        "world.collision_objects[0]",
        "missing key 'id'",
    );
}

#[test]
fn a_missing_dimension_names_the_object_primitive_and_line() {
    let text = scene_with("dimensions: [0.25, 0.25, 0.25]", "dimensions: [0.25, 0.25]");
    let e = parse_scene(&text, "s.yaml", &[]).unwrap_err();
    assert_error(
        &e,
        "s.yaml",
        41,
        "world.collision_objects[1] 'Cube'.primitives[0].dimensions",
        "a box needs 3 dimension(s) [x, y, z] (full side lengths), found 2",
    );
    let text = scene_with("dimensions: [0.25, 0.25, 0.25]\n", "");
    let e = parse_scene(&text, "s.yaml", &[]).unwrap_err();
    assert_error(
        &e,
        "s.yaml",
        41,
        "world.collision_objects[1] 'Cube'.primitives[0]",
        "missing key 'dimensions'",
    );
}

#[test]
fn a_zero_or_malformed_quaternion_is_refused() {
    let text = scene_with(
        "orientation: [0, 0, 0.2514099244310241, 0.9678807002402656]",
        "orientation: [0, 0, 0, 0]",
    );
    let e = parse_scene(&text, "s.yaml", &[]).unwrap_err();
    assert_error(
        &e,
        "s.yaml",
        45,
        "world.collision_objects[1] 'Cube'.primitive_poses[0].orientation",
        "the quaternion [x, y, z, w] is zero",
    );
    let text = scene_with(
        "orientation: [0, 0, 0.2514099244310241, 0.9678807002402656]",
        "orientation: [0, 0, 0.2514099244310241]",
    );
    let e = parse_scene(&text, "s.yaml", &[]).unwrap_err();
    assert_error(
        &e,
        "s.yaml",
        45,
        "world.collision_objects[1] 'Cube'.primitive_poses[0].orientation",
        "expected 4 numbers, found 3",
    );
    // A quaternion whose sum of squares overflows is still a rotation; a position or a
    // size beyond 1e9 m is refused (a 1e300 m box gave "overlap by inf mm").
    let text = scene_with(
        "orientation: [0, 0, 0.2514099244310241, 0.9678807002402656]",
        "orientation: [0, 0, 1e200, 1e200]",
    );
    assert!(parse_scene(&text, "s.yaml", &[]).is_ok());
    let text = scene_with(
        "position: [-0.04815510236526688, 0.9893543728427527, 0.3484669621486253]",
        "position: [1e300, 0.9893543728427527, 0.3484669621486253]",
    );
    let e = parse_scene(&text, "s.yaml", &[]).unwrap_err();
    assert!(
        e.to_string()
            .contains("1e300 m is beyond the 1e9 m accepted for a position"),
        "{e}"
    );
    let text = scene_with(
        "orientation: [0, 0, 0.2514099244310241, 0.9678807002402656]",
        "orientation: [0, 0, .nan, 1]",
    );
    let e = parse_scene(&text, "s.yaml", &[]).unwrap_err();
    assert_error(
        &e,
        "s.yaml",
        45,
        "world.collision_objects[1] 'Cube'.primitive_poses[0].orientation[2]",
        "non-finite number NaN",
    );
}

#[test]
fn unsupported_scene_contents_are_refused_by_name() {
    let cases = [
        (
            "type: cylinder\n      id: Can1",
            "type: cone\n      id: Can1",
            38,
            "world.collision_objects[0] 'Can1'.primitives[0].type",
            "cone primitives are not supported",
        ),
        (
            "      id: Can1\n",
            "      id: Can1\n      meshes: [{vertices: [], triangles: []}]\n",
            40,
            "world.collision_objects[0] 'Can1'.meshes[0]",
            "meshes are not supported",
        ),
        (
            "      id: Can1\n",
            "      id: Can1\n      operation: REMOVE\n",
            40,
            "world.collision_objects[0] 'Can1'.operation",
            "operation REMOVE is not supported",
        ),
        (
            "      id: Can1\n",
            "      id: Can1\n      header: {frame_id: panda_hand}\n",
            40,
            "world.collision_objects[0] 'Can1'.header.frame_id",
            "frame 'panda_hand' is not supported",
        ),
        (
            "      id: Cube\n",
            "      id: Can1\n",
            40,
            "world.collision_objects[1]",
            "obstacle name 'Can1' is used twice",
        ),
    ];
    for (from, to, line, element, message) in cases {
        let e = parse_scene(&scene_with(from, to), "s.yaml", &[]).unwrap_err();
        assert_error(&e, "s.yaml", line, element, message);
    }
}

#[test]
fn an_unknown_or_missing_goal_joint_is_refused_by_name() {
    let m = model("panda");
    let text = PANDA_REVERSED.replace("panda_joint6, position: 0.6", "panda_joint9, position: 0.6");
    let e = parse_request(&text, "r.yaml", &m).unwrap_err();
    assert_error(
        &e,
        "r.yaml",
        13,
        "goal_constraints[0].joint_constraints[6].joint_name",
        "joint 'panda_joint9' is not in model 'panda'",
    );
    let text = PANDA_REVERSED.replace("      - {joint_name: panda_joint6, position: 0.6}\n", "");
    let e = parse_request(&text, "r.yaml", &m).unwrap_err();
    assert_error(
        &e,
        "r.yaml",
        7,
        "goal_constraints[0].joint_constraints",
        "no value for joint(s) 'panda_joint6' of model 'panda'",
    );
    let text = PANDA_REVERSED.replace(
        "position: [7, 6, 5, 4, 3, 2, 1]",
        "position: [7, 6, 5, 4, 3, 2]",
    );
    let e = parse_request(&text, "r.yaml", &m).unwrap_err();
    assert_error(
        &e,
        "r.yaml",
        4,
        "start_state.joint_state.position",
        "6 position(s) for 7 joint name(s)",
    );
    let text = PANDA_REVERSED.replace(
        "    position: [7, 6, 5, 4, 3, 2, 1]\n",
        "    position: [7, 6, 5, 4, 3, 2, 1]\n  multi_dof_joint_state:\n    transforms: [{translation: [0, 0, 0], rotation: [0, 0, 0, 1]}, {translation: [0, 0, 0.5]}]\n",
    );
    let e = parse_request(&text, "r.yaml", &m).unwrap_err();
    assert_error(
        &e,
        "r.yaml",
        6,
        "start_state.multi_dof_joint_state.transforms[1]",
        "a moved base",
    );
    let text = PANDA_REVERSED.replace("panda_joint1, position: 0.1", "panda_joint3, position: 0.1");
    let e = parse_request(&text, "r.yaml", &m).unwrap_err();
    assert_error(
        &e,
        "r.yaml",
        8,
        "goal_constraints[0].joint_constraints[1].joint_name",
        "joint 'panda_joint3' is given twice (first on line 7)",
    );
}

#[test]
fn a_malformed_srdf_element_is_refused_with_file_and_line() {
    let text = "<?xml version=\"1.0\"?>\n<robot name=\"panda\">\n  <disable_collisions link1=\"panda_link0\" link2=\"panda_link1\"/>\n  <disable_collisions link1=\"panda_link1\" reason=\"Never\"/>\n</robot>\n";
    let e = parse_srdf(text, "bad.srdf").unwrap_err();
    assert_error(
        &e,
        "bad.srdf",
        4,
        "<disable_collisions>",
        "missing 'link2' attribute",
    );
    let e = parse_srdf(&text[..text.len() - 10], "bad.srdf").unwrap_err();
    assert_eq!((e.file.as_str(), e.key.as_str()), ("bad.srdf", "XML"));
    assert_eq!(e.line, Some(4), "{e}");
    assert!(e.message.contains("never closed"), "{e}");
}

#[test]
fn file_errors_name_the_path() {
    let dir = std::env::temp_dir().join(format!("armsim_planning_io_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene0007.yaml");
    std::fs::write(&scene, "world:\n  collision_objects:\n    - id: x\n      primitives: [{type: box, dimensions: [1, 1, -1]}]\n      primitive_poses: [{}]\n").unwrap();
    let file = scene.display().to_string();
    let e = moveit::load_scene(&scene).unwrap_err();
    assert_error(
        &e,
        &file,
        4,
        "world.collision_objects[0] 'x'.primitives[0].dimensions[2]",
        "must be positive and at most 1e9 m, found -1",
    );
    // A scene without its request.
    let e = moveit::problem_pairs(&dir).unwrap_err();
    assert!(
        e.to_string()
            .contains("scene0007.yaml has no request0007.yaml beside it"),
        "{e}"
    );
    std::fs::write(dir.join("request0007.yaml"), "x: 1\n").unwrap();
    std::fs::write(dir.join("scene0010.yaml"), "x: 1\n").unwrap();
    std::fs::write(dir.join("request0010.yaml"), "x: 1\n").unwrap();
    let pairs = moveit::problem_pairs(&dir).unwrap();
    let ids: Vec<&str> = pairs.iter().map(|p| p.id.as_str()).collect();
    assert_eq!(ids, ["0007", "0010"]);
    let e = moveit::load_scene(dir.join("missing.yaml")).unwrap_err();
    assert!(
        e.to_string().starts_with(&format!(
            "{}: file: cannot read",
            dir.join("missing.yaml").display()
        )),
        "{e}"
    );
    let e =
        moveit::parse_validity("{\"robot\": \"panda\",\n \"joints\": 3}", "v.json").unwrap_err();
    assert_eq!((e.file.as_str(), e.line), ("v.json", Some(2)), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn yaml_aliases_and_deep_nesting_are_refused_before_parsing() {
    let e = parse_scene("a: &x [1]\nb: *x\n", "s.yaml", &[]).unwrap_err();
    assert_error(&e, "s.yaml", 2, "YAML", "aliases");
    let deep = format!("a: {}{}\n", "[".repeat(200), "]".repeat(200));
    let e = parse_scene(&deep, "s.yaml", &[]).unwrap_err();
    assert_error(&e, "s.yaml", 1, "YAML", "nested deeper than 128 levels");
    // Far deeper, the parser's own limit speaks first.
    let deep = format!("a: {}{}\n", "[".repeat(100_000), "]".repeat(100_000));
    let e = parse_scene(&deep, "s.yaml", &[]).unwrap_err();
    assert_error(&e, "s.yaml", 1, "YAML", "recursion limit exceeded");
    // Block nesting counts too, and a literal block may hold '*' and brackets.
    let mut deep = String::new();
    for k in 0..200 {
        deep += &format!("{}k{k}:\n", " ".repeat(k));
    }
    let e = parse_scene(&deep, "s.yaml", &[]).unwrap_err();
    assert_error(&e, "s.yaml", 129, "YAML", "nested deeper than 128 levels");
    let text = "name: |\n  a *b [c {d\nworld: {collision_objects: []}\n";
    assert!(parse_scene(text, "s.yaml", &[]).unwrap().is_empty());
    let e = parse_scene("- 1\n- 2\n", "s.yaml", &[]).unwrap_err();
    assert_error(
        &e,
        "s.yaml",
        1,
        "YAML",
        "the document must be a mapping, found a list",
    );
    let e = parse_scene("", "s.yaml", &[]).unwrap_err();
    assert_eq!(e.to_string(), "s.yaml: YAML: the file is empty");
}

#[test]
fn every_truncation_of_a_scene_and_a_request_is_an_error_or_a_result_never_a_panic() {
    let m = model("ur5");
    let scene = std::fs::read_to_string(bench().join("ur5/table_pick/scene0001.yaml")).unwrap();
    let request = std::fs::read_to_string(bench().join("ur5/table_pick/request0001.yaml")).unwrap();
    let mut errors = 0;
    for cut in (0..scene.len())
        .step_by(7)
        .filter(|&c| scene.is_char_boundary(c))
    {
        if let Err(e) = parse_scene(&scene[..cut], "s.yaml", &[]) {
            assert!(e.line.is_some() || e.message.contains("empty"), "{e}");
            errors += 1;
        }
    }
    for cut in (0..request.len()).filter(|&c| request.is_char_boundary(c)) {
        if let Err(e) = parse_request(&request[..cut], "r.yaml", &m) {
            assert!(e.line.is_some() || e.message.contains("empty"), "{e}");
            errors += 1;
        }
    }
    assert!(errors > 100);
}
