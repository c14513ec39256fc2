//! What an arm run's MCAP says about the scene around the motion: the obstacles as a
//! `visualization_msgs/MarkerArray` on `/armsim/obstacles`, and the wall-clock epoch the
//! times count from.
//!
//! References: the obstacles as written in `tests/data/scenarios/obstacle_markers.toml`
//! (sizes, poses from xyz/rpy, capsule caps placed by hand), and
//! `tests/data/obstacle_markers.golden.json`, which Foxglove's Python decoders
//! (`tools/check_mcap.py --markers-json`, PyPI `mcap` + `mcap-ros2-support`) read from
//! the same scenario's recording: armsim's bytes must decode to the same values, so these
//! tests never need Python.

use armsim::core::spatial::{rpy_to_matrix, Mat3, Vec3};
use armsim::io::record::mcap_in::{read_mcap, read_mcap_bytes};
use armsim::io::record::obstacle_markers::{MarkerShape, ObstacleMarker};
use armsim::io::record::ros2::{self, RosMessage};
use armsim::io::record::tf::to_se3;
use armsim::io::record::Recording;
use armsim::scenarios::arm::{self, RunOptions};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

const SCENARIO: &str = "tests/data/scenarios/obstacle_markers.toml";
const GOLDEN: &str = "tests/data/obstacle_markers.golden.json";

/// Runs the obstacle scenario into a fresh directory: the MCAP's path, and the wall clock
/// (Unix ns) just before and after the run.
fn record(tag: &str) -> (PathBuf, u64, u64) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("scene_{tag}"));
    let _ = std::fs::remove_dir_all(&dir);
    let path = root().join(SCENARIO);
    let text = std::fs::read_to_string(&path).unwrap();
    let opts = RunOptions {
        out_dir: Some(dir.clone()),
        ..Default::default()
    };
    let before = armsim::io::record::mcap_out::wall_clock_ns();
    arm::run(&path, &text, &opts).unwrap_or_else(|e| panic!("{e}"));
    let after = armsim::io::record::mcap_out::wall_clock_ns();
    (dir.join("obstacle_markers.mcap"), before, after)
}

/// An obstacle as the scenario file writes it: the expected marker shape and scale, and
/// its world pose from `xyz`/`rpy` (the base offset does not move obstacles).
struct Expected {
    name: &'static str,
    shape: MarkerShape,
    scale: [f64; 3],
    xyz: [f64; 3],
    rpy: [f64; 3],
}

fn expected() -> Vec<Expected> {
    let mesh = std::fs::canonicalize(root().join("tests/data/meshes/cube_binary.stl")).unwrap();
    let e = |name, shape, scale, xyz, rpy| Expected {
        name,
        shape,
        scale,
        xyz,
        rpy,
    };
    let half_pi = std::f64::consts::FRAC_PI_2;
    vec![
        e(
            "table",
            MarkerShape::Cube,
            [0.8, 0.6, 0.04],
            [0.5, 0.0, -0.02],
            [0.0, 0.0, 0.3],
        ),
        e(
            "ball",
            MarkerShape::Sphere,
            [0.14; 3],
            [0.3, 0.4, 0.5],
            [0.0; 3],
        ),
        e(
            "post",
            MarkerShape::Cylinder,
            [0.06, 0.06, 0.9],
            [-0.4, 0.2, 0.45],
            [0.2, -0.1, 0.0],
        ),
        // The capsule (r 0.02, cylinder 0.5) lies along world -y (roll 90°): a cylinder and
        // its two caps at local z = ±0.25, i.e. world y = -0.5 ∓ 0.25.
        e(
            "rail",
            MarkerShape::Cylinder,
            [0.04, 0.04, 0.5],
            [0.0, -0.5, 0.6],
            [half_pi, 0.0, 0.0],
        ),
        e(
            "rail",
            MarkerShape::Sphere,
            [0.04; 3],
            [0.0, -0.75, 0.6],
            [half_pi, 0.0, 0.0],
        ),
        e(
            "rail",
            MarkerShape::Sphere,
            [0.04; 3],
            [0.0, -0.25, 0.6],
            [half_pi, 0.0, 0.0],
        ),
        e(
            "fixture",
            MarkerShape::Mesh {
                uri: format!("file://{}", mesh.display()),
            },
            [0.1, 0.2, 0.05],
            [0.6, -0.3, 0.1],
            [0.0, 0.4, 0.0],
        ),
    ]
}

fn assert_matches_scenario(got: &[ObstacleMarker]) {
    let want = expected();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(g.name, w.name);
        assert_eq!(g.shape, w.shape, "{}", w.name);
        for k in 0..3 {
            assert!(
                (g.scale[k] - w.scale[k]).abs() < 1e-15,
                "{}: scale {:?}",
                w.name,
                g.scale
            );
        }
        assert_eq!(g.pose.parent, "world");
        let pose = to_se3(&g.pose);
        let dp = pose.trans - Vec3::from(w.xyz);
        assert!(dp.norm() < 1e-12, "{}: at {:?}", w.name, g.pose.translation);
        let r: Mat3 = rpy_to_matrix(w.rpy);
        assert!(
            (pose.rot - r).norm() < 1e-12,
            "{}: rotation {:?}",
            w.name,
            g.pose.rotation
        );
    }
}

#[test]
fn obstacle_markers_read_back_with_the_scenarios_sizes_and_poses() {
    let (mcap, _, _) = record("read_back");
    let rec: Recording = read_mcap(&mcap).unwrap();
    assert_matches_scenario(&rec.obstacles);
    // The labels are not shapes: seven shape markers for five obstacles.
    let names: std::collections::BTreeSet<&str> =
        rec.obstacles.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names.len(), 5);
}

/// A decoded marker in the golden file's form (see `tools/check_mcap.py`).
fn marker_json(m: &ros2::Marker, root: &str) -> Value {
    let p = m.pose.position;
    let o = m.pose.orientation;
    let c = m.color;
    let prefix = format!("file://{root}/");
    let mesh = match m.mesh_resource.strip_prefix(&prefix) {
        Some(rest) => format!("file://<root>/{rest}"),
        None => m.mesh_resource.clone(),
    };
    json!({
        "ns": m.ns, "id": m.id, "type": m.kind, "action": m.action,
        "frame_id": m.header.frame_id,
        "position": [p.x, p.y, p.z],
        "orientation": [o.x, o.y, o.z, o.w],
        "scale": [m.scale.x, m.scale.y, m.scale.z],
        "color": [c.r as f64, c.g as f64, c.b as f64, c.a as f64],
        "lifetime": [m.lifetime.sec, m.lifetime.nanosec],
        "frame_locked": m.frame_locked,
        "text": m.text,
        "mesh_resource": mesh,
    })
}

/// Equal values, numbers to the last bit or two (JSON text through two float parsers).
fn assert_same(got: &Value, want: &Value, at: &str) {
    match (got, want) {
        (Value::Number(a), Value::Number(b)) => {
            let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            assert!(
                (a - b).abs() <= 1e-15 * a.abs().max(1.0),
                "{at}: {a} vs {b}"
            );
        }
        (Value::Array(a), Value::Array(b)) => {
            assert_eq!(a.len(), b.len(), "{at}");
            for (k, (x, y)) in a.iter().zip(b).enumerate() {
                assert_same(x, y, &format!("{at}[{k}]"));
            }
        }
        (Value::Object(a), Value::Object(b)) => {
            assert_eq!(
                a.keys().collect::<Vec<_>>(),
                b.keys().collect::<Vec<_>>(),
                "{at}"
            );
            for (k, v) in b {
                assert_same(&a[k], v, &format!("{at}.{k}"));
            }
        }
        _ => assert_eq!(got, want, "{at}"),
    }
}

#[test]
fn obstacle_markers_decode_to_the_python_golden() {
    let (mcap, _, _) = record("golden");
    let bytes = std::fs::read(&mcap).unwrap();
    let golden: Value =
        serde_json::from_str(&std::fs::read_to_string(root().join(GOLDEN)).unwrap()).unwrap();
    let root_dir = std::fs::canonicalize(root()).unwrap();
    let mut found = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic != golden["topic"] {
            continue;
        }
        found += 1;
        let schema = m.channel.schema.as_ref().unwrap();
        assert_eq!(schema.name, ros2::MarkerArray::NAME);
        assert_eq!(schema.encoding, "ros2msg");
        assert_eq!(
            std::str::from_utf8(&schema.data).unwrap(),
            ros2::MarkerArray::SCHEMA
        );
        assert!(m.channel.metadata["offered_qos_profiles"].contains("durability: 1"));
        let msg: ros2::MarkerArray = ros2::decode(&m.data).unwrap();
        let got: Vec<Value> = msg
            .markers
            .iter()
            .map(|k| marker_json(k, &root_dir.display().to_string()))
            .collect();
        assert_same(&Value::Array(got), &golden["markers"], "markers");
    }
    assert_eq!(found, 1, "one MarkerArray on the topic");
}

#[test]
fn times_count_from_the_runs_wall_clock_start() {
    let (mcap, before, after) = record("epoch");
    let bytes = std::fs::read(&mcap).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let meta = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    let epoch: u64 = meta.metadata["armsim.epoch_ns"].parse().unwrap();
    assert!(
        before <= epoch && epoch <= after,
        "{before} ≤ {epoch} ≤ {after}"
    );
    let mut first_state = None;
    let mut latched = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        assert!(m.log_time >= epoch);
        match m.channel.topic.as_str() {
            "/joint_states" if first_state.is_none() => {
                let js: ros2::JointState = ros2::decode(&m.data).unwrap();
                first_state = Some((m.log_time, js.header.stamp.to_nanos().unwrap()));
            }
            "/robot_description" | "/tf_static" | "/armsim/obstacles" => {
                assert_eq!(m.log_time, epoch, "{} logged at the epoch", m.channel.topic);
                latched += 1;
            }
            _ => {}
        }
    }
    assert_eq!(latched, 3);
    // Simulated t = 0 is the epoch, in the log time and the header stamp alike.
    assert_eq!(first_state, Some((epoch, epoch)));
    // armsim's reader shows time from 0 again, and returns the epoch.
    let rec = read_mcap_bytes(&bytes, Path::new("epoch.mcap")).unwrap();
    assert_eq!(rec.header.epoch_ns, Some(epoch));
    assert_eq!(rec.frames[0].t, 0.0);
    assert!(rec.frames.last().unwrap().t < 60.0);
    assert!(!rec
        .header
        .metadata
        .iter()
        .any(|(k, _)| k == "armsim.epoch_ns"));
}

#[test]
fn other_tools_files_count_from_their_first_stamp() {
    // A ros2 bag-like file with wall-clock stamps and no armsim metadata: times from the
    // earliest stamp (here a transform's, 5 ms before the first joint state).
    let t0: u64 = 1_700_000_000_000_000_000;
    let mut w = mcap::WriteOptions::new()
        .create(std::io::Cursor::new(Vec::new()))
        .unwrap();
    let mut channel = |schema_name: &str, schema: &str, topic: &str| {
        let s = w
            .add_schema(schema_name, "ros2msg", schema.as_bytes())
            .unwrap();
        w.add_channel(s, topic, "cdr", &Default::default()).unwrap()
    };
    let js = channel(
        ros2::JointState::NAME,
        ros2::JointState::SCHEMA,
        "/joint_states",
    );
    let tf = channel(ros2::TfMessage::NAME, ros2::TfMessage::SCHEMA, "/tf");
    let header = |ns: u64| ros2::Header {
        stamp: ros2::Time::from_nanos(ns).unwrap(),
        frame_id: "base".into(),
    };
    let write = |w: &mut mcap::Writer<_>, ch: u16, ns: u64, data: Vec<u8>| {
        let h = mcap::records::MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: ns,
            publish_time: ns,
        };
        w.write_to_known_channel(&h, &data).unwrap();
    };
    let tf_msg = ros2::TfMessage {
        transforms: vec![ros2::TransformStamped {
            header: header(t0),
            child_frame_id: "l1".into(),
            transform: ros2::Transform {
                rotation: ros2::Quaternion {
                    w: 1.0,
                    ..Default::default()
                },
                ..Default::default()
            },
        }],
    };
    write(&mut w, tf, t0, ros2::encode(&tf_msg).unwrap());
    for k in 0..3u64 {
        let ns = t0 + 5_000_000 + k * 10_000_000;
        let m = ros2::JointState {
            header: header(ns),
            name: vec!["a".into()],
            position: vec![k as f64],
            ..Default::default()
        };
        write(&mut w, js, ns, ros2::encode(&m).unwrap());
    }
    w.finish().unwrap();
    let bytes = w.into_inner().into_inner();
    let rec = read_mcap_bytes(&bytes, Path::new("bag.mcap")).unwrap();
    assert_eq!(rec.header.epoch_ns, Some(t0));
    let t: Vec<f64> = rec.frames.iter().map(|f| f.t).collect();
    assert_eq!(t, [0.005, 0.015, 0.025]);
    assert!(rec.obstacles.is_empty());
}
