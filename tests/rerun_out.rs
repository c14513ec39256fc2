//! Rerun output (src/recording/rerun_out.rs): recordings of real models written as .rrd,
//! read back with the rerun crate's own decoder, and checked entity by entity. Needs the
//! `rerun` feature (on by default).
#![cfg(feature = "rerun")]

mod common;

use armsim::dynamics::rnea;
use armsim::io::record::rerun::rerun_out::{
    colormap, link_entity, log_recording, log_workspace, log_workspace_scene, path, RerunError,
    RerunReport, RerunSink,
};
use armsim::io::record::Header;
use armsim::io::record::{CollisionEvent, PointCloud, Recording, TorqueRow};
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::workspace::{sample_workspace, WorkspaceOptions};
use common::rrd::{decode, Contents};
use std::collections::BTreeSet;
use std::path::PathBuf;

const FRAMES: usize = 30;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tmp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("armsim_rerun_{tag}_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A smooth motion around the neutral pose with RNEA torques, a workspace cloud with
/// manipulability, one collision event and a torque-check table.
fn recording(model: &Model, name: &str) -> Recording {
    let source = std::path::Path::new(&model.source);
    let spec = Model::read_spec(source).unwrap();
    let (header, robot_tf) = Header::for_model(name, source, model, &spec);
    let mut rec = Recording {
        header,
        ..Default::default()
    };
    let mut data = Data::new(model);
    let q0 = model.neutral();
    let n = model.nv;
    for k in 0..FRAMES {
        let t = k as f64 * 0.05;
        let w = 2.0;
        let q: Vec<f64> = (0..n)
            .map(|i| q0[i] + 0.4 * (w * t + i as f64).sin())
            .collect();
        let qd: Vec<f64> = (0..n).map(|i| 0.4 * w * (w * t + i as f64).cos()).collect();
        let qdd: Vec<f64> = (0..n)
            .map(|i| -0.4 * w * w * (w * t + i as f64).sin())
            .collect();
        let tau = rnea(model, &mut data, &q, &qd, &qdd).to_vec();
        rec.frames
            .push(robot_tf.frame_at(model, &mut data, t, &q, &qd, &tau));
    }
    let ws = sample_workspace(
        model,
        &WorkspaceOptions {
            samples: 1 << 12,
            replicates: 2,
            extras: true,
            extras_samples: Some(1 << 10),
            keep_points: 400,
            quiet: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(ws.points.len(), 400);
    rec.clouds.push(PointCloud {
        t: 0.0,
        frame: "world".into(),
        points: ws.points.iter().map(|p| p.p.map(|x| x as f32)).collect(),
        values: ws.points.iter().map(|p| p.manipulability as f32).collect(),
    });
    let links: Vec<&str> = rec.frames[0].tf.iter().map(|t| t.child.as_str()).collect();
    rec.collisions.push(CollisionEvent {
        t: rec.frames[FRAMES / 2].t,
        body_a: links[links.len() - 1].to_string(),
        body_b: links[0].to_string(),
    });
    rec.torque_check.push(TorqueRow {
        joint: rec.header.joint_names[0].clone(),
        peak_torque: 1.0,
        rms_torque: 0.5,
        peak_speed: 0.8,
        peak_power: 0.8,
        limit: rec.header.effort_limits[0],
        velocity_limit: None,
        margin: Some(50.0),
        ok: true,
        first_violation: None,
    });
    rec
}

fn check_model(rel: &str) {
    let model = common::load(rel);
    let spec = Model::read_spec(&root().join(rel)).unwrap();
    let rec = recording(&model, &model.name);
    let dir = tmp_dir(&model.name);
    let out = dir.join(format!("{}.rrd", model.name));
    let report = log_recording(&rec, Some(&spec), None, &RerunSink::Save(out.clone())).unwrap();
    assert!(out.is_file());
    assert_eq!(report.bytes, Some(std::fs::metadata(&out).unwrap().len()));
    // No temporary file left next to it.
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "{left:?}");

    let c = decode(&out);
    check_view(&c);
    check_link_poses(&c, &model, &rec, &report);
    check_plots_and_events(&c, &rec, &report);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The blueprint frames the motion from outside it, hides the skeleton behind the drawn
/// bodies, and there is only the `time` timeline.
fn check_view(c: &Contents) {
    assert!(c.blueprint_msgs > 0, "blueprint stored");
    // The 3-D view's eye looks at a point inside the box of the link origins over the
    // motion, from outside it.
    let (eye, target) = c.eye.expect("EyeControls3D in the blueprint");
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for (t, _) in c.poses.values().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(t[k]);
            hi[k] = hi[k].max(t[k]);
        }
    }
    assert!(
        (0..3).all(|k| lo[k] - 0.2 <= target[k] && target[k] <= hi[k] + 0.2),
        "{target:?} {lo:?} {hi:?}"
    );
    assert!(
        (0..3).any(|k| eye[k] < lo[k] - 0.2 || eye[k] > hi[k] + 0.2),
        "{eye:?} {lo:?} {hi:?}"
    );
    // Bodies are drawn, so the skeleton is left out of the 3-D view.
    assert!(
        c.view_queries
            .iter()
            .any(|q| q == "- /world/robot/skeleton"),
        "{:?}",
        c.view_queries
    );
    assert_eq!(
        c.timelines,
        BTreeSet::from(["time".to_string()]),
        "only the time timeline"
    );
}

/// Every link has an entity with one transform per frame (besides a `world` root), at
/// the world placement forward kinematics gives (f32 precision).
fn check_link_poses(c: &Contents, model: &Model, rec: &Recording, report: &RerunReport) {
    // Every link has an entity and (besides a `world` root) one transform per frame.
    let tf_links: BTreeSet<&str> = rec
        .header
        .static_tf
        .iter()
        .chain(&rec.frames[0].tf)
        .map(|t| t.child.as_str())
        .collect();
    let mut tf_rows = 0;
    for l in &model.links {
        let e = link_entity(&l.name).to_string();
        assert!(c.entities.contains(&e), "{e} missing");
        let rows = c.rows(&e, "Transform3D:translation");
        assert_eq!(rows, c.rows(&e, "Transform3D:quaternion"), "{e}");
        if tf_links.contains(l.name.as_str()) {
            assert_eq!(rows, FRAMES, "{e}");
        }
        tf_rows += rows;
    }
    assert_eq!(tf_rows, FRAMES * tf_links.len());

    // The logged poses are the world placements of forward kinematics (f32 precision).
    let mut data = Data::new(model);
    for (k, f) in rec.frames.iter().enumerate() {
        armsim::kinematics::forward_kinematics(model, &mut data, &f.q);
        for (li, l) in model.links.iter().enumerate() {
            let Some(poses) = c.poses.get(&link_entity(&l.name).to_string()) else {
                continue;
            };
            let m = armsim::kinematics::frame_placement(model, &data, li);
            let (t, q) = poses[k];
            for (a, ta) in t.iter().enumerate() {
                assert!(
                    (*ta as f64 - m.trans[a]).abs() < 1e-5,
                    "{} frame {k}",
                    l.name
                );
            }
            let r = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                q[3] as f64,
                q[0] as f64,
                q[1] as f64,
                q[2] as f64,
            ))
            .to_rotation_matrix();
            assert!((r.matrix() - m.rot).amax() < 1e-5, "{} frame {k}", l.name);
        }
    }
    assert_eq!(report.moving_links, tf_links.len());
    assert_eq!(report.frames, FRAMES);
}

/// Joint plots with their limit lines, the skeleton, tool path, cloud, collision markers
/// and the torque report.
fn check_plots_and_events(c: &Contents, rec: &Recording, report: &RerunReport) {
    // Joint plots: one torque and one position sample per frame, ± limit lines.
    for (k, j) in rec.header.joint_names.iter().enumerate() {
        let tau = path(&["plots", "torque", j]).to_string();
        assert_eq!(c.rows(&tau, "Scalars:scalars"), FRAMES, "{tau}");
        assert!(c.has_static(&tau, "SeriesLines:names"));
        let q = path(&["plots", "q", j]).to_string();
        assert_eq!(c.rows(&q, "Scalars:scalars"), FRAMES, "{q}");
        let lim = rec.header.effort_limits[k];
        for side in ["upper_limit", "lower_limit"] {
            let e = format!("{tau}/{side}");
            assert_eq!(
                c.rows(&e, "Scalars:scalars"),
                if lim.is_some() { 2 } else { 0 },
                "{e}"
            );
        }
    }
    // Skeleton per frame, the tool path, the cloud, the collision.
    assert_eq!(
        c.rows("/world/robot/skeleton", "LineStrips3D:strips"),
        FRAMES
    );
    assert!(c.has_static("/world/tool_path", "LineStrips3D:strips"));
    assert_eq!(c.rows("/log/info", "TextLog:text"), 1);
    // The cloud at its time (t = 0), coloured by manipulability.
    assert_eq!(c.rows("/world/workspace/cloud_0", "Points3D:positions"), 1);
    assert_eq!(c.rows("/world/workspace/cloud_0", "Points3D:colors"), 1);
    assert_eq!(report.points, 400);
    assert_eq!(c.rows("/log/collisions", "TextLog:text"), 1);
    let e = &rec.collisions[0];
    for b in [&e.body_a, &e.body_b] {
        let ent = format!("{}/collision", link_entity(b));
        // The marker, then its clearing at the next frame.
        assert_eq!(c.rows(&ent, "Boxes3D:half_sizes"), 2, "{ent}");
    }
    assert!(c.has_static("/reports/torque_check", "TextDocument:text"));
    assert!(report.tool.is_some());
}

#[test]
fn ur5_recording_to_rrd() {
    check_model("robots/ur5.urdf");
}

#[test]
fn panda_recording_to_rrd() {
    check_model("robots/panda.urdf");
}

#[test]
fn visual_geometry_of_every_kind() {
    let rel = "tests/data/visual_arm.urdf";
    let model = common::load(rel);
    let spec = Model::read_spec(&root().join(rel)).unwrap();
    let rec = recording(&model, "visual_arm");
    let dir = tmp_dir("visual");
    let out = dir.join("visual.rrd");
    let report = log_recording(&rec, Some(&spec), None, &RerunSink::Save(out.clone())).unwrap();
    let c = decode(&out);
    let v = |l: &str, k: usize| format!("{}/visual_{k}", link_entity(l));
    assert!(c.has_static(&v("base_link", 0), "Boxes3D:half_sizes"));
    assert!(c.has_static(&v("link1", 0), "Cylinders3D:lengths"));
    assert!(c.has_static(&v("link1", 0), "Cylinders3D:colors"));
    assert!(c.has_static(&v("link1", 1), "Ellipsoids3D:half_sizes"));
    for (l, k) in [("link2", 0), ("link2", 1), ("link3", 0)] {
        assert!(
            c.has_static(&v(l, k), "Mesh3D:vertex_positions"),
            "{}",
            v(l, k)
        );
        assert!(c.has_static(&v(l, k), "Mesh3D:triangle_indices"));
        assert!(c.has_static(&v(l, k), "Mesh3D:vertex_normals"));
    }
    // Mesh origin and scale are baked into the vertices (link frame): the STL unit cube
    // scaled to 0.08 × 0.08 × 0.4 and pitched by 90° spans x 0 … 0.4 from its origin
    // (0.2, 0, 0); the OBJ cube mirrored in x spans 0 … 0.3.
    let bbox = |e: &str| {
        let v = &c.mesh_vertices[e];
        let mut b = [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]];
        for p in v {
            for a in 0..3 {
                b[0][a] = b[0][a].min(p[a]);
                b[1][a] = b[1][a].max(p[a]);
            }
        }
        b
    };
    let close = |a: [[f32; 3]; 2], b: [[f32; 3]; 2]| {
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .all(|(x, y)| (x - y).abs() < 1e-5)
    };
    let b = bbox(&v("link2", 0));
    assert!(close(b, [[0.0, -0.04, -0.04], [0.4, 0.04, 0.04]]), "{b:?}");
    let b = bbox(&v("link3", 0));
    assert!(close(b, [[0.0, -0.03, -0.03], [0.3, 0.03, 0.03]]), "{b:?}");
    // The missing visual mesh: the capsule collision shape instead, and a warning.
    assert!(c.has_static(&v("tool", 0), "Capsules3D:lengths"));
    assert_eq!(report.visuals, 7);
    assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
    assert!(report.warnings[0].contains("no_such_package"));
    assert_eq!(c.rows("/log/warnings", "TextLog:text"), 1);
    // The tool is the deepest link: on a fixed joint after link3.
    assert_eq!(report.tool.as_deref(), Some("tool"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scene_obstacles_are_drawn_in_world_coordinates() {
    use armsim::core::spatial::Se3;
    use armsim::io::record::rerun::rerun_out::{log_recording_with, SceneExtras};
    use armsim::model::{Geometry, Shape};
    let model = common::load("robots/ur5.urdf");
    let rec = recording(&model, "scene");
    let dir = tmp_dir("scene");
    let out = dir.join("scene.rrd");
    let g = |shape: Shape, xyz: [f64; 3]| Geometry {
        origin: Se3::from_xyz_rpy(xyz, [0.0; 3]),
        shape,
        rgba: None,
    };
    let cube = |uri: &str| Shape::Mesh {
        uri: uri.into(),
        scale: [0.1; 3],
    };
    let extras = SceneExtras {
        obstacles: vec![
            (
                "table".into(),
                g(
                    Shape::Box {
                        size: [0.8, 1.2, 0.04],
                    },
                    [0.45, 0.0, -0.025],
                ),
            ),
            (
                "ball".into(),
                g(Shape::Sphere { radius: 0.05 }, [0.5, 0.1, 0.3]),
            ),
            ("block".into(), g(cube("cube.obj"), [0.3, -0.4, 0.2])),
            ("ghost".into(), g(cube("no_such.obj"), [0.0; 3])),
        ],
        obstacle_dir: Some(root().join("tests/data/meshes")),
    };
    let report =
        log_recording_with(&rec, None, None, &extras, &RerunSink::Save(out.clone())).unwrap();
    let c = decode(&out);
    assert!(c.has_static("/world/obstacles/table", "Boxes3D:half_sizes"));
    assert!(c.has_static("/world/obstacles/ball", "Ellipsoids3D:half_sizes"));
    // The unit cube (vertices at ±0.5), scaled by 0.1 and placed at (0.3, -0.4, 0.2).
    let v = &c.mesh_vertices["/world/obstacles/block"];
    assert_eq!(v.len(), 8);
    for p in v {
        for (k, centre) in [0.3f32, -0.4, 0.2].iter().enumerate() {
            assert!(((p[k] - centre).abs() - 0.05).abs() < 1e-6, "{p:?}");
        }
    }
    assert!(!c.entities.contains("/world/obstacles/ghost"));
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("obstacle 'ghost'") && w.contains("no_such.obj")),
        "{:?}",
        report.warnings
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn geometry_from_the_embedded_urdf() {
    // No spec given: the URDF text in the header is parsed.
    let model = common::load("robots/ur5.urdf");
    let rec = recording(&model, "ur5");
    assert!(rec.header.robot_description.is_some());
    let dir = tmp_dir("embedded");
    let out = dir.join("e.rrd");
    let report = log_recording(&rec, None, None, &RerunSink::Save(out.clone())).unwrap();
    // The description names the bundled meshes by file:// URIs: every link with a visual
    // gets one Mesh3D per visual, with the vertices of its file.
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let c = decode(&out);
    let spec = Model::read_spec(&root().join("robots/ur5.urdf")).unwrap();
    let mut meshes = 0;
    for l in &spec.links {
        assert!(c.entities.contains(&link_entity(&l.name).to_string()));
        for (k, g) in l.visuals.iter().enumerate() {
            let armsim::model::Shape::Mesh { uri, .. } = &g.shape else {
                panic!("{}: visual {k} is not a mesh", l.name)
            };
            let file = root().join("robots").join(uri);
            let want = armsim::collision::mesh::load_mesh(&file)
                .unwrap()
                .vertices
                .len();
            let e = format!("{}/visual_{k}", link_entity(&l.name));
            let got = c.mesh_vertices.get(&e).map_or(0, |v| v.len());
            assert_eq!(got, want, "{e}: Mesh3D vertices");
            assert!(want > 100, "{e}: a real mesh, not a primitive");
            meshes += 1;
        }
    }
    assert_eq!(meshes, 7);
    assert_eq!(report.visuals, 7);

    // The same description with the original package:// URIs and no such package: the
    // seven visuals are reported missing in one warning (one reason), nothing fails.
    let mut pkg = rec.clone();
    let desc = pkg.header.robot_description.take().unwrap();
    let abs = std::fs::canonicalize(root().join("robots/meshes/ur5")).unwrap();
    pkg.header.robot_description = Some(desc.replace(
        &format!("file://{}/", abs.display()),
        "package://ur_description/meshes/ur5/",
    ));
    let report = log_recording(&pkg, None, None, &RerunSink::Save(dir.join("p.rrd"))).unwrap();
    assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
    assert!(
        report.warnings[0].starts_with("7 visual meshes not drawn ('package://ur_description/"),
        "{}",
        report.warnings[0]
    );
    assert!(report.warnings[0].contains("package 'ur_description' not found"));

    // Without any description: frames and plots only.
    let mut bare = rec.clone();
    bare.header.robot_description = None;
    let out2 = dir.join("bare.rrd");
    let r2 = log_recording(&bare, None, None, &RerunSink::Save(out2.clone())).unwrap();
    assert_eq!(r2.visuals, 0);
    assert!(r2.warnings.is_empty());
    let c2 = decode(&out2);
    assert_eq!(
        c2.rows("/world/robot/wrist_3_link", "Transform3D:translation"),
        FRAMES
    );

    // A broken description (malformed XML: a nameless link only warns, as in urdfdom) is a
    // warning, not an error.
    let mut broken = rec.clone();
    broken.header.robot_description = Some("<robot name='x'><link name='a'></robot>".into());
    let out3 = dir.join("broken.rrd");
    let r3 = log_recording(&broken, None, None, &RerunSink::Save(out3)).unwrap();
    assert!(r3.warnings[0].contains("robot description not usable"));
    assert_eq!(
        decode(&dir.join("broken.rrd")).rows("/log/warnings", "TextLog:text"),
        1
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn workspace_cloud_alone() {
    let dir = tmp_dir("ws");
    let out = dir.join("ws.rrd");
    let cloud = PointCloud {
        t: 0.0,
        frame: "world".into(),
        points: (0..100).map(|i| [i as f32 * 0.01, 0.0, 0.0]).collect(),
        values: (0..100).map(|i| i as f32).collect(),
    };
    let r = log_workspace(&cloud, &RerunSink::Save(out.clone())).unwrap();
    assert_eq!(r.points, 100);
    let c = decode(&out);
    assert_eq!(
        c.statics
            .get(&(
                "/world/workspace/cloud_0".to_string(),
                "Points3D:positions".to_string()
            ))
            .copied(),
        Some(1)
    );
    assert!(c.has_static("/world/workspace/cloud_0", "Points3D:colors"));
    assert_eq!(colormap(0.0), [68, 1, 84]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn malformed_frames_are_skipped_not_fatal() {
    let model = common::load("robots/ur5.urdf");
    let mut rec = recording(&model, "ur5");
    rec.frames[3].t = f64::NAN;
    rec.frames[4].tf[0].rotation = [0.0; 4];
    rec.frames[5].tf[1].translation = [f64::INFINITY, 0.0, 0.0];
    rec.header.static_tf[0].rotation = [f64::NAN, 0.0, 0.0, 1.0];
    // A cycle in the frame tree must not hang or overflow.
    rec.frames[6].tf[0].parent = rec.frames[6].tf[1].child.clone();
    let dir = tmp_dir("malformed");
    let out = dir.join("m.rrd");
    let r = log_recording(&rec, None, None, &RerunSink::Save(out.clone())).unwrap();
    assert_eq!(r.frames, FRAMES - 1);
    assert!(r.warnings.iter().any(|w| w.contains("non-finite time")));
    assert!(r
        .warnings
        .iter()
        .any(|w| w.contains("2 frame transform(s)")));
    assert!(r
        .warnings
        .iter()
        .any(|w| w.contains("1 static transform(s)")));
    // Every warning is kept in the text log.
    assert_eq!(
        decode(&out).rows("/log/warnings", "TextLog:text"),
        r.warnings.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_output_paths_are_errors() {
    let model = common::load("robots/ur5.urdf");
    let rec = recording(&model, "ur5");
    let dir = tmp_dir("bad");
    let missing = dir.join("no/such/dir/out.rrd");
    match log_recording(&rec, None, None, &RerunSink::Save(missing.clone())) {
        Err(e @ RerunError::Output { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("does not exist"), "{msg}");
        }
        other => panic!("expected an output error, got {other:?}"),
    }
    assert!(!missing.exists());
    // A directory as the output.
    assert!(matches!(
        log_recording(&rec, None, None, &RerunSink::Save(dir.clone())),
        Err(RerunError::Output { .. })
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Writes sample files for `rerun rrd verify` (see docs/rerun.md) into `$ARMSIM_RRD_DIR`
/// (default: `rerun-samples` under Cargo's target tmp directory):
/// `cargo test --release --test rerun_out -- --ignored write_samples --nocapture`.
#[test]
#[ignore]
fn write_samples() {
    let dir = std::env::var_os("ARMSIM_RRD_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("rerun-samples"));
    std::fs::create_dir_all(&dir).unwrap();
    for rel in [
        "robots/ur5.urdf",
        "robots/panda.urdf",
        "tests/data/visual_arm.urdf",
    ] {
        let model = common::load(rel);
        let spec = Model::read_spec(&root().join(rel)).unwrap();
        let rec = recording(&model, &model.name);
        let out = dir.join(format!("{}.rrd", model.name));
        let r = log_recording(&rec, Some(&spec), None, &RerunSink::Save(out.clone())).unwrap();
        eprintln!("wrote {} ({:?} bytes)", out.display(), r.bytes);
    }
}

fn armsim(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_armsim"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap()
}

#[test]
fn cli_workspace_rerun() {
    let dir = tmp_dir("cli_ws");
    let out = dir.join("ws.rrd");
    let o = armsim(&[
        "workspace",
        "robots/ur5.urdf",
        "--samples",
        "4096",
        "--replicates",
        "2",
        "--extras",
        "--rerun",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let c = decode(&out);
    // The robot at one pose inside the picture; the kept points on their own entity.
    assert_eq!(
        c.rows("/world/robot/wrist_3_link", "Transform3D:translation"),
        1
    );
    assert!(c.has_static("/world/workspace/points", "Points3D:positions"));
    assert!(c.has_static("/world/workspace/points", "Points3D:colors"));
    assert!(c.has_static("/world/workspace/boundary/back", "Mesh3D:vertex_positions"));
    assert!(String::from_utf8_lossy(&o.stdout).contains("wrote"));

    // A missing directory fails before sampling, with the path in the message.
    let bad = dir.join("missing/ws.rrd");
    let o = armsim(&[
        "workspace",
        "robots/ur5.urdf",
        "--samples",
        "4096",
        "--rerun",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("does not exist"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cli_view_errors() {
    let dir = tmp_dir("cli_view");
    let missing = dir.join("none.mcap");
    let out = dir.join("v.rrd");
    let o = armsim(&[
        "view",
        missing.to_str().unwrap(),
        "--save",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("none.mcap"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists());
    // --save and --spawn exclude each other.
    let o = armsim(&[
        "view",
        missing.to_str().unwrap(),
        "--save",
        out.to_str().unwrap(),
        "--spawn",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `armsim view` of a run's MCAP draws the scene's obstacles from its MarkerArray: one
/// static entity per shape, boxes and spheres with the scenario's half sizes, the capsule
/// as a cylinder and two spheres, the mesh with its scale and pose baked into the vertices.
#[test]
fn cli_view_draws_the_obstacles_of_a_run() {
    let dir = tmp_dir("cli_obstacles");
    let run = armsim(&[
        "run",
        "tests/data/scenarios/obstacle_markers.toml",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let rrd = dir.join("v.rrd");
    let mcap = dir.join("obstacle_markers.mcap");
    let o = armsim(&[
        "view",
        mcap.to_str().unwrap(),
        "--save",
        rrd.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let c = decode(&rrd);
    let e = |name: &str, k: usize| {
        path(&["world", "obstacles", name, &format!("shape_{k}")]).to_string()
    };
    assert_eq!(c.half_sizes[&e("table", 0)], vec![[0.4, 0.3, 0.02]]);
    assert_eq!(c.half_sizes[&e("ball", 1)], vec![[0.07; 3]]);
    assert!(c.has_static(&e("post", 2), "Cylinders3D:lengths"));
    assert!(c.has_static(&e("rail", 3), "Cylinders3D:radii"));
    assert_eq!(c.half_sizes[&e("rail", 4)], vec![[0.02; 3]]);
    assert_eq!(c.half_sizes[&e("rail", 5)], vec![[0.02; 3]]);
    assert!(c.has_static(&e("table", 0), "Boxes3D:labels"));
    // The fixture: a unit cube scaled to 0.1 × 0.2 × 0.05, pitched by 0.4 rad, at
    // (0.6, -0.3, 0.1): y spans ±0.1, x ±(0.05 cos 0.4 + 0.025 sin 0.4).
    let v = &c.mesh_vertices[&e("fixture", 6)];
    let span = |a: usize| {
        let lo = v.iter().map(|p| p[a]).fold(f32::INFINITY, f32::min);
        let hi = v.iter().map(|p| p[a]).fold(f32::NEG_INFINITY, f32::max);
        (lo, hi)
    };
    let hx = 0.05 * 0.4f32.cos() + 0.025 * 0.4f32.sin();
    let (x0, x1) = span(0);
    let (y0, y1) = span(1);
    assert!(
        (x0 - (0.6 - hx)).abs() < 1e-6 && (x1 - (0.6 + hx)).abs() < 1e-6,
        "{x0} {x1}"
    );
    assert!(
        (y0 + 0.4).abs() < 1e-6 && (y1 + 0.2).abs() < 1e-6,
        "{y0} {y1}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The workspace picture of the UR5: the boundary surface (both halves of the cut) has
/// its vertices between an occupied and an empty voxel centre of the run's own grid
/// (`WorkspaceResult::is_occupied`), the section is exactly the occupied voxels of the
/// layer through the base axis, coloured per vertex; the robot has a mesh on every link
/// with a visual; the blueprint has a 3-D view whose eye is outside the workspace and
/// hides the points and the front half.
#[test]
fn workspace_picture_shows_the_boundary_the_section_and_the_robot() {
    let model = common::load("robots/ur5.urdf");
    let spec = Model::read_spec(&root().join("robots/ur5.urdf")).unwrap();
    // Enough samples per voxel that the picture uses the run's own grid.
    let h = 0.08;
    let ws = sample_workspace(
        &model,
        &WorkspaceOptions {
            samples: 1 << 18,
            replicates: 2,
            voxel: h,
            extras: true,
            extras_samples: Some(1 << 14),
            keep_points: 20_000,
            quiet: true,
            ..Default::default()
        },
    )
    .unwrap();
    let dir = tmp_dir("ws_picture");
    let out = dir.join("ws.rrd");
    let report = log_workspace_scene(&model, &ws, &RerunSink::Save(out.clone())).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let c = decode(&out);

    let occupied = |i: [i64; 3]| {
        let p = i.map(|x| (x as f64 + 0.5) * h);
        ws.is_occupied(&armsim::core::spatial::Vec3::new(p[0], p[1], p[2]))
    };
    let mut vertices = 0;
    for half in ["back", "front"] {
        let e = format!("/world/workspace/boundary/{half}");
        assert!(c.has_static(&e, "Mesh3D:vertex_colors"), "{e}");
        assert!(c.has_static(&e, "Mesh3D:triangle_indices"), "{e}");
        for v in &c.mesh_vertices[&e] {
            // The dual cube (8 voxel centres) whose centre is nearest holds the vertex.
            let i0 = v.map(|x| (x as f64 / h).round() as i64 - 1);
            let corners: Vec<bool> = (0..8)
                .map(|b| occupied([i0[0] + (b & 1), i0[1] + (b >> 1 & 1), i0[2] + (b >> 2 & 1)]))
                .collect();
            assert!(
                corners.iter().any(|&o| o) && corners.iter().any(|&o| !o),
                "{e}: vertex {v:?} is not on the boundary"
            );
        }
        vertices += c.mesh_vertices[&e].len();
    }
    // A closed surface around about `boundary_voxels` voxels: at least that many
    // vertices, and of the same order.
    let b = ws.boundary_voxels as usize;
    assert!(vertices >= b / 2 && vertices <= 4 * b, "{vertices} vs {b}");

    // The section: the half-planes through the UR5's base axis (world z) that bound the
    // cut-away quarter x < 0, y < 0: y = 0 for x < 0 and x = 0 for y < 0, one square per
    // occupied voxel of the layers j = 0 and i = 0, each on an occupied voxel.
    let sec = "/world/workspace/section";
    let sv = &c.mesh_vertices[sec];
    assert!(c.has_static(sec, "Mesh3D:vertex_colors"));
    let lo = ws.bbox[0].map(|x| (x / h).floor() as i64 - 1);
    let hi = ws.bbox[1].map(|x| (x / h).floor() as i64 + 1);
    let mut layers = 0;
    for k in lo[2]..=hi[2] {
        for m in lo[0].min(lo[1])..0 {
            layers += occupied([m, 0, k]) as usize + occupied([0, m, k]) as usize;
        }
    }
    assert!(layers > 100, "{layers}");
    assert_eq!(sv.len(), 4 * layers);
    for q in sv.chunks(4) {
        let mean = |a: usize| q.iter().map(|v| v[a] as f64).sum::<f64>() / 4.0;
        let cell = |a: usize| (mean(a) / h).floor() as i64;
        if q.iter().all(|v| v[1] == 0.0) {
            assert!(mean(0) < 0.0 && occupied([cell(0), 0, cell(2)]), "{q:?}");
        } else {
            assert!(q.iter().all(|v| v[0] == 0.0), "{q:?} off both planes");
            assert!(mean(1) < 0.0 && occupied([0, cell(1), cell(2)]), "{q:?}");
        }
    }
    // The robot stands in the cut-away quarter: its tool is there.
    let tool = c.poses[&link_entity(&ws.tool).to_string()][0].0;
    assert!(tool[0] < 0.0 && tool[1] < 0.0, "{tool:?}");

    // The robot: a mesh on every link with a visual, at one pose.
    for l in spec.links.iter().filter(|l| !l.visuals.is_empty()) {
        let e = format!("{}/visual_0", link_entity(&l.name));
        assert!(c.mesh_vertices.contains_key(&e), "{e}");
    }
    assert_eq!(c.poses[&link_entity("wrist_3_link").to_string()].len(), 1);

    // The points, hidden; the colour scale explained.
    assert!(c.has_static("/world/workspace/points", "Points3D:colors"));
    assert_eq!(report.points, 20_000);
    assert_eq!(
        c.invisible,
        BTreeSet::from([
            "/world/workspace/points".to_string(),
            "/world/workspace/boundary/front".to_string()
        ])
    );
    let legend = &c.labels["/world/workspace/legend/labels"];
    assert!(
        legend.iter().any(|l| l.contains("manipulability")),
        "{legend:?}"
    );
    assert!(c.has_static("/reports/workspace", "TextDocument:text"));

    // A 3-D view, its eye outside the workspace's box, looking at a point inside it.
    assert!(
        c.view_classes.iter().any(|v| v == "3D"),
        "{:?}",
        c.view_classes
    );
    let (eye, target) = c.eye.expect("EyeControls3D");
    let [blo, bhi] = ws.bbox;
    assert!((0..3).any(|k| (eye[k] as f64) < blo[k] || (eye[k] as f64) > bhi[k]));
    assert!((0..3).all(|k| (target[k] as f64) > blo[k] - 0.3 && (target[k] as f64) < bhi[k] + 0.3));
    let _ = std::fs::remove_dir_all(&dir);
}
