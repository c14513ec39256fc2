//! MCAP recordings: the writer checked with the `mcap` crate's own reader, the reader's
//! round trip, other tools' layouts, the URDF of DH models, malformed and fuzzed input,
//! and the interrupt flag.

mod common;

use armsim::collision::Obstacle;
use armsim::core::interrupt;
use armsim::core::spatial::Se3;
use armsim::io::record::mcap_in::{read_mcap, read_mcap_bytes};
use armsim::io::record::mcap_out::{write_recording, McapWriter};
use armsim::io::record::obstacle_markers::markers_of;
use armsim::io::record::record_error::RecordError;
use armsim::io::record::ros2::{self, RosMessage};
use armsim::io::record::tf;
use armsim::io::record::urdf_out;
use armsim::io::record::{CollisionEvent, Frame, Header, PointCloud, Recording, TorqueRow};
use armsim::kinematics::{
    compute_joint_jacobians, forward_kinematics, frame_jacobian, frame_placement, manipulability,
    Expressed,
};
use armsim::model::data::Data;
use armsim::model::parse::urdf;
use armsim::model::Model;
use armsim::model::Shape;
use mcap::records::MessageHeader;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The fixed epoch of the test recordings (2025-11-24T16:00:00Z in Unix ns), so that their
/// bytes do not depend on the wall clock.
const EPOCH: u64 = 1_764_000_000_000_000_000;

/// A fresh directory under the target's test scratch space.
fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("recording")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The UR5 moving along a smooth trajectory: one frame (with the link transforms) per 10 ms,
/// a workspace cloud with manipulability and one without values, a torque check and
/// collision events.
fn ur5_recording(frames: usize) -> Recording {
    let path = root().join("robots/ur5.urdf");
    let (model, _) = Model::load(&path).unwrap();
    let spec = Model::read_spec(&path).unwrap();
    let mut data = Data::new(&model);
    let n = model.nv;
    let (mut header, robot_tf) = Header::for_model("ur5 wave", &path, &model, &spec);
    header.metadata = vec![
        ("scenario".into(), "tests/recording.rs".into()),
        ("dt".into(), "0.01".into()),
    ];
    header.epoch_ns = Some(EPOCH);
    let frames = (0..frames)
        .map(|k| {
            let t = k as f64 * 0.01;
            let w = std::f64::consts::PI;
            let q: Vec<f64> = (0..n).map(|i| 0.5 * (w * t + i as f64).sin()).collect();
            let qd: Vec<f64> = (0..n).map(|i| 0.5 * w * (w * t + i as f64).cos()).collect();
            let tau: Vec<f64> = (0..n).map(|i| 10.0 * q[i] - 0.1 * qd[i]).collect();
            robot_tf.frame_at(&model, &mut data, t, &q, &qd, &tau)
        })
        .collect();
    let tool = model.link_id("tool0").unwrap();
    let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
    let mut points = Vec::new();
    let mut values = Vec::new();
    let mut jac = nalgebra::DMatrix::zeros(6, n);
    for _ in 0..200 {
        let q: Vec<f64> = (0..n).map(|_| rng.random_range(-3.0..3.0)).collect();
        compute_joint_jacobians(&model, &mut data, &q);
        let p = frame_placement(&model, &data, tool).trans;
        points.push([p.x as f32, p.y as f32, p.z as f32]);
        frame_jacobian(&model, &data, tool, Expressed::World, &mut jac);
        values.push(manipulability(&jac) as f32);
    }
    let clouds = vec![
        PointCloud {
            t: 0.0,
            frame: "base_link".into(),
            points: points.clone(),
            values,
        },
        PointCloud {
            t: 0.05,
            frame: "world".into(),
            points: points[..10].to_vec(),
            values: Vec::new(),
        },
    ];
    let torque_check = model
        .dof_names()
        .into_iter()
        .enumerate()
        .map(|(i, joint)| TorqueRow {
            joint,
            peak_torque: 10.0 + i as f64 / 3.0,
            rms_torque: 0.1 * i as f64,
            peak_speed: 1.0 / 7.0,
            peak_power: 1e-7 * i as f64,
            limit: (i != 2).then_some(150.0),
            velocity_limit: (i % 2 == 0).then_some(3.15),
            margin: (i != 2).then_some(-2.5 + i as f64),
            ok: i != 1,
            first_violation: (i == 1).then_some(0.12),
        })
        .collect();
    let collisions = vec![
        CollisionEvent {
            t: 0.02,
            body_a: "wrist_3_link".into(),
            body_b: "table".into(),
        },
        CollisionEvent {
            t: 0.02,
            body_a: "forearm_link".into(),
            body_b: "table".into(),
        },
        CollisionEvent {
            t: 0.03,
            body_a: "wrist_3_link".into(),
            body_b: "table".into(),
        },
    ];
    Recording {
        header,
        frames,
        clouds,
        torque_check,
        collisions,
        obstacles: Vec::new(),
    }
}

/// The recording `read_mcap` should return for `rec`: the same, with the metadata sorted
/// by key and the armsim version added.
fn expected_read_back(rec: &Recording) -> Recording {
    let mut e = rec.clone();
    e.header
        .metadata
        .push(("armsim_version".into(), env!("CARGO_PKG_VERSION").into()));
    e.header.metadata.sort();
    e
}

/// Copies the times of `want` into `got` after checking they agree to the nanosecond.
fn align_times(got: &mut Recording, want: &Recording) {
    let close = |a: f64, b: f64| assert!((a - b).abs() <= 1e-9, "time {a} vs {b}");
    assert_eq!(got.frames.len(), want.frames.len());
    for (g, w) in got.frames.iter_mut().zip(&want.frames) {
        close(g.t, w.t);
        g.t = w.t;
    }
    assert_eq!(got.clouds.len(), want.clouds.len());
    for (g, w) in got.clouds.iter_mut().zip(&want.clouds) {
        close(g.t, w.t);
        g.t = w.t;
    }
    assert_eq!(got.collisions.len(), want.collisions.len());
    for (g, w) in got.collisions.iter_mut().zip(&want.collisions) {
        close(g.t, w.t);
        g.t = w.t;
    }
}

#[test]
fn written_file_passes_the_mcap_crates_own_reader() {
    let rec = ur5_recording(50);
    let dir = scratch("mcap_crate");
    let path = dir.join("ur5.mcap");
    assert_eq!(write_recording(&path, &rec).unwrap(), path);
    let bytes = std::fs::read(&path).unwrap();

    // Header record: the ROS 2 profile.
    let first = mcap::read::LinearReader::new(&bytes)
        .unwrap()
        .next()
        .unwrap()
        .unwrap();
    match first {
        mcap::records::Record::Header(h) => {
            assert_eq!(h.profile, "ros2");
            assert!(h.library.starts_with("armsim "), "{}", h.library);
        }
        other => panic!("first record is not a header: {other:?}"),
    }

    // Every message, in file order.
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let mut last_log = 0u64;
    let mut joint_states = Vec::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        check_message(&m, last_log);
        last_log = m.log_time;
        if m.channel.topic == "/joint_states" {
            joint_states.push((
                m.log_time,
                ros2::decode::<ros2::JointState>(&m.data).unwrap(),
            ));
        }
        *counts.entry(m.channel.topic.clone()).or_default() += 1;
    }
    let want: BTreeMap<String, usize> = [
        ("/robot_description", 1),
        ("/tf_static", 1),
        ("/joint_states", 50),
        ("/tf", 50),
        ("/armsim/workspace", 2),
        ("/armsim/torque_check", 1),
        ("/armsim/collisions", 2),
    ]
    .into_iter()
    .map(|(t, n)| (t.to_string(), n))
    .collect();
    assert_eq!(counts, want);

    // Joint states: names, values and stamps as written, `t` after the epoch.
    for ((log_time, js), f) in joint_states.iter().zip(&rec.frames) {
        assert_eq!(*log_time, EPOCH + (f.t * 1e9).round() as u64);
        assert_eq!(js.header.stamp.to_nanos(), Some(*log_time));
        assert_eq!(js.name, rec.header.joint_names);
        assert_eq!(js.position, f.q);
        assert_eq!(js.velocity, f.qd);
        assert_eq!(js.effort, f.tau);
    }

    check_summary(&bytes, &rec);
}

/// One message: a ros2msg schema matching its topic, CDR with a little-endian header, log
/// and publish times equal and not before `last_log`; start-up messages at the epoch
/// with transient-local durability.
fn check_message(m: &mcap::Message, last_log: u64) {
    let schema = m
        .channel
        .schema
        .as_ref()
        .expect("every channel has a schema");
    assert_eq!(schema.encoding, "ros2msg");
    assert_eq!(m.channel.message_encoding, "cdr");
    let want_schema = match m.channel.topic.as_str() {
        "/joint_states" => ros2::JointState::NAME,
        "/tf" | "/tf_static" => ros2::TfMessage::NAME,
        "/robot_description" => ros2::StringMsg::NAME,
        "/armsim/workspace" => ros2::PointCloud2::NAME,
        "/armsim/torque_check" | "/armsim/collisions" => ros2::DiagnosticArray::NAME,
        t => panic!("unexpected topic {t}"),
    };
    assert_eq!(schema.name, want_schema);
    assert!(
        std::str::from_utf8(&schema.data).unwrap().contains("MSG: ")
            || schema.name == ros2::StringMsg::NAME
    );
    assert!(m.log_time >= last_log, "log times decrease");
    assert_eq!(m.publish_time, m.log_time);
    assert_eq!(&m.data[..4], &[0, 1, 0, 0], "CDR little-endian header");
    if m.channel.topic == "/robot_description" || m.channel.topic == "/tf_static" {
        assert_eq!(
            m.log_time, EPOCH,
            "start-up messages are logged at the epoch"
        );
        assert!(m.channel.metadata["offered_qos_profiles"].contains("durability: 1"));
    }
}

/// The summary: statistics, zstd chunks, and the armsim metadata record.
fn check_summary(bytes: &[u8], rec: &Recording) {
    // Summary: statistics, zstd chunks, the metadata record.
    let summary = mcap::Summary::read(bytes).unwrap().expect("a summary");
    let stats = summary.stats.as_ref().unwrap();
    assert_eq!(stats.message_count, 107);
    assert_eq!(stats.channel_count, 7);
    assert_eq!(stats.metadata_count, 1);
    assert!(!summary.chunk_indexes.is_empty());
    assert!(summary
        .chunk_indexes
        .iter()
        .all(|c| c.compression == "zstd"));
    assert_eq!(summary.metadata_indexes.len(), 1);
    let meta = mcap::read::metadata(bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(meta.name, "armsim");
    assert_eq!(meta.metadata["name"], "ur5 wave");
    assert_eq!(meta.metadata["armsim_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(meta.metadata["scenario"], "tests/recording.rs");
    assert_eq!(meta.metadata["armsim.epoch_ns"], EPOCH.to_string());
    let names: Vec<String> = serde_json::from_str(&meta.metadata["armsim.joint_names"]).unwrap();
    assert_eq!(names, rec.header.joint_names);
}

#[test]
fn read_back_equals_written() {
    let rec = ur5_recording(50);
    let dir = scratch("round_trip");
    let path = dir.join("ur5.mcap");
    write_recording(&path, &rec).unwrap();
    let mut back = read_mcap(&path).unwrap();
    let want = expected_read_back(&rec);
    align_times(&mut back, &want);
    // Exact: joint values, transforms, clouds, torque check (numbers as shortest text).
    assert_eq!(back.header, want.header);
    for (g, w) in back.frames.iter().zip(&want.frames) {
        assert_eq!(g, w, "frame at t = {}", w.t);
    }
    assert_eq!(back.clouds, want.clouds);
    assert_eq!(back.torque_check, want.torque_check);
    assert_eq!(back.collisions, want.collisions);
    assert_eq!(back, want);
    // The URDF is the file's own text, its relative mesh paths (meshes/ur5/...) made
    // absolute file:// URIs of the bundled files.
    let robots = std::fs::canonicalize(root().join("robots")).unwrap();
    let text = std::fs::read_to_string(root().join("robots/ur5.urdf")).unwrap();
    let want_text = text.replace(
        "filename=\"meshes/",
        &format!("filename=\"file://{}/meshes/", robots.display()),
    );
    assert_ne!(want_text, text);
    assert_eq!(
        back.header.robot_description.as_deref(),
        Some(want_text.as_str())
    );
    // No temporary files are left beside it.
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("ur5.mcap")]);
}

#[test]
fn streaming_writer_finishes_on_interrupt_and_cleans_up_when_dropped() {
    let rec = ur5_recording(20);
    let dir = scratch("streaming");
    // Dropped without finish: no target, no temporary file.
    {
        let mut w = McapWriter::create(&dir.join("dropped.mcap"), &rec.header).unwrap();
        for f in &rec.frames[..5] {
            w.write_frame(f).unwrap();
        }
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
    // A loop that stops on the interrupt flag and finishes: a valid file with the frames
    // written so far.
    let path = dir.join("interrupted.mcap");
    let mut w = McapWriter::create(&path, &rec.header).unwrap();
    let mut written = 0;
    for (k, f) in rec.frames.iter().enumerate() {
        if k == 7 {
            interrupt::request();
        }
        if interrupt::requested() {
            break;
        }
        w.write_frame(f).unwrap();
        written += 1;
    }
    interrupt::reset();
    assert!(!path.exists(), "nothing at the target before finish");
    w.finish().unwrap();
    let back = read_mcap(&path).unwrap();
    assert_eq!(written, 7);
    assert_eq!(back.frames.len(), 7);
    assert_eq!(back.frames[6].q, rec.frames[6].q);
}

#[test]
fn invalid_writes_are_errors_naming_the_file() {
    let rec = ur5_recording(2);
    let dir = scratch("invalid");
    let path = dir.join("bad.mcap");
    let mut w = McapWriter::create(&path, &rec.header).unwrap();
    let mut f = rec.frames[0].clone();
    f.q.pop();
    let e = w.write_frame(&f).unwrap_err();
    assert!(matches!(e, RecordError::Invalid { .. }));
    assert!(e.to_string().contains("bad.mcap"), "{e}");
    assert!(e.to_string().contains("5 positions for 6 joints"), "{e}");
    let mut f = rec.frames[0].clone();
    f.t = -1.0;
    assert!(w
        .write_frame(&f)
        .unwrap_err()
        .to_string()
        .contains("time -1"));
    f.t = f64::NAN;
    assert!(w.write_frame(&f).is_err());
    let cloud = PointCloud {
        points: vec![[0.0; 3]; 2],
        values: vec![1.0],
        ..PointCloud::default()
    };
    assert!(w.write_cloud(&cloud).is_err());
    drop(w);
    let mut h = rec.header.clone();
    h.metadata.push(("name".into(), "x".into()));
    let e = McapWriter::create(&path, &h).err().expect("reserved key");
    assert!(e.to_string().contains("reserved"), "{e}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
}

/// Test MCAP files built with the `mcap` crate directly, as other tools write them.
struct Foreign {
    w: mcap::Writer<Cursor<Vec<u8>>>,
}

impl Foreign {
    fn new(opts: mcap::WriteOptions) -> Self {
        Foreign {
            w: opts.create(Cursor::new(Vec::new())).unwrap(),
        }
    }

    fn channel(&mut self, schema_name: &str, schema: &str, topic: &str) -> u16 {
        let s = self
            .w
            .add_schema(schema_name, "ros2msg", schema.as_bytes())
            .unwrap();
        self.w
            .add_channel(s, topic, "cdr", &BTreeMap::new())
            .unwrap()
    }

    fn write(&mut self, ch: u16, t: u64, data: &[u8]) {
        let h = MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: t,
            publish_time: t,
        };
        self.w.write_to_known_channel(&h, data).unwrap();
    }

    fn finish(mut self) -> Vec<u8> {
        self.w.finish().unwrap();
        self.w.into_inner().into_inner()
    }
}

fn stamp(ns: u64) -> ros2::Header {
    ros2::Header {
        stamp: ros2::Time::from_nanos(ns).unwrap(),
        frame_id: String::new(),
    }
}

fn tf_msg(ns: u64, parent: &str, child: &str, x: f64) -> ros2::TfMessage {
    let mut header = stamp(ns);
    header.frame_id = parent.into();
    ros2::TfMessage {
        transforms: vec![ros2::TransformStamped {
            header,
            child_frame_id: child.into(),
            transform: ros2::Transform {
                translation: ros2::Vector3 { x, y: 0.0, z: 0.0 },
                rotation: ros2::Quaternion {
                    w: 1.0,
                    ..Default::default()
                },
            },
        }],
    }
}

#[test]
fn reads_other_tools_layouts() {
    // Short schema names, joints in changing order and subsets, no velocities, a
    // big-endian message, lz4 chunks, transforms at their own rate.
    let mut f = Foreign::new(mcap::WriteOptions::new().compression(Some(mcap::Compression::Lz4)));
    let js = f.channel(
        "sensor_msgs/JointState",
        ros2::JointState::SCHEMA,
        "/joint_states",
    );
    let tfc = f.channel("tf2_msgs/msg/TFMessage", ros2::TfMessage::SCHEMA, "/tf");
    let other = f.channel("std_msgs/msg/String", ros2::StringMsg::SCHEMA, "/chatter");
    let state = |ns: u64, names: &[&str], pos: &[f64]| ros2::JointState {
        header: stamp(ns),
        name: names.iter().map(|s| s.to_string()).collect(),
        position: pos.to_vec(),
        velocity: vec![],
        effort: vec![],
    };
    let enc = |m: &ros2::JointState| ros2::encode(m).unwrap();
    f.write(js, 1_000, &enc(&state(1_000, &["a", "b"], &[1.0, 2.0])));
    f.write(
        tfc,
        1_100,
        &ros2::encode(&tf_msg(1_100, "base", "l1", 0.5)).unwrap(),
    );
    f.write(
        other,
        1_200,
        &ros2::encode(&ros2::StringMsg { data: "hi".into() }).unwrap(),
    );
    f.write(js, 2_000, &enc(&state(2_000, &["b", "a"], &[20.0, 10.0])));
    let mut be = vec![0u8, 0, 0, 0];
    be.extend(
        cdr_encoding::to_vec::<_, byteorder::BigEndian>(&state(3_000, &["b", "c"], &[30.0, 9.0]))
            .unwrap(),
    );
    f.write(js, 3_000, &be);
    f.write(
        tfc,
        2_900,
        &ros2::encode(&tf_msg(2_900, "base", "l1", 0.7)).unwrap(),
    );
    f.write(
        tfc,
        2_950,
        &ros2::encode(&tf_msg(2_950, "base", "l1", 0.8)).unwrap(),
    );
    let bytes = f.finish();
    let rec = read_mcap_bytes(&bytes, Path::new("foreign.mcap")).unwrap();
    assert_eq!(rec.header.joint_names, vec!["a", "b"]);
    assert_eq!(rec.header.name, "foreign");
    assert_eq!(rec.header.effort_limits, vec![None, None]);
    let q: Vec<Vec<f64>> = rec.frames.iter().map(|f| f.q.clone()).collect();
    assert_eq!(q, vec![vec![1.0, 2.0], vec![10.0, 20.0], vec![10.0, 30.0]]);
    assert!(rec
        .frames
        .iter()
        .all(|f| f.qd.is_empty() && f.tau.is_empty()));
    assert_eq!(rec.frames[0].tf.len(), 1);
    assert_eq!(rec.frames[0].tf[0].translation[0], 0.5);
    assert!(rec.frames[1].tf.is_empty());
    // Both later transforms are nearest to t = 3 µs: the last one wins.
    assert_eq!(rec.frames[2].tf.len(), 1);
    assert_eq!(rec.frames[2].tf[0].translation[0], 0.8);

    // Only transforms: one frame per stamp, without joint values.
    let mut f = Foreign::new(mcap::WriteOptions::new().use_chunks(false));
    let tfc = f.channel("tf2_msgs/msg/TFMessage", ros2::TfMessage::SCHEMA, "/tf");
    for k in 0..3u64 {
        f.write(
            tfc,
            k,
            &ros2::encode(&tf_msg(k * 10, "a", "b", k as f64)).unwrap(),
        );
    }
    let rec = read_mcap_bytes(&f.finish(), Path::new("tf_only.mcap")).unwrap();
    assert_eq!(rec.frames.len(), 3);
    assert!(rec.frames.iter().all(|f| f.q.is_empty() && f.tf.len() == 1));
    assert_eq!(rec.frames[2].t, 20e-9);
}

#[test]
fn malformed_messages_name_file_topic_and_index() {
    let mut f = Foreign::new(mcap::WriteOptions::new());
    let js = f.channel(
        "sensor_msgs/msg/JointState",
        ros2::JointState::SCHEMA,
        "/joint_states",
    );
    let ok = ros2::JointState {
        name: vec!["a".into()],
        position: vec![1.0],
        ..Default::default()
    };
    f.write(js, 0, &ros2::encode(&ok).unwrap());
    f.write(js, 1, &[0, 1, 0, 0, 0xff, 0xff]);
    let e = read_mcap_bytes(&f.finish(), Path::new("bad_msg.mcap")).unwrap_err();
    let s = e.to_string();
    assert!(matches!(e, RecordError::Record { .. }), "{s}");
    assert!(
        s.starts_with(
            "bad_msg.mcap: topic '/joint_states', message 1: sensor_msgs/msg/JointState: "
        ),
        "{s}"
    );

    let mut f = Foreign::new(mcap::WriteOptions::new());
    let js = f.channel(
        "sensor_msgs/msg/JointState",
        ros2::JointState::SCHEMA,
        "/joint_states",
    );
    let bad = ros2::JointState {
        name: vec!["a".into(), "b".into()],
        position: vec![1.0],
        ..Default::default()
    };
    f.write(js, 0, &ros2::encode(&bad).unwrap());
    let e = read_mcap_bytes(&f.finish(), Path::new("short.mcap")).unwrap_err();
    assert!(e.to_string().contains("1 positions for 2 names"), "{e}");
}

#[test]
fn partial_joint_states_cannot_expand_without_bound() {
    // 100 000 joints, then messages naming one joint each: every one would expand to
    // 100 000 values. A few are fine; more than the file's size allows are an error.
    let names: Vec<String> = (0..100_000).map(|k| format!("j{k}")).collect();
    let file = |partial: usize| {
        let mut f = Foreign::new(mcap::WriteOptions::new());
        let js = f.channel(
            "sensor_msgs/msg/JointState",
            ros2::JointState::SCHEMA,
            "/joint_states",
        );
        let full = ros2::JointState {
            name: names.clone(),
            position: vec![0.0; names.len()],
            ..Default::default()
        };
        f.write(js, 0, &ros2::encode(&full).unwrap());
        for k in 0..partial {
            let one = ros2::JointState {
                header: stamp(k as u64 + 1),
                name: vec!["j7".into()],
                position: vec![k as f64],
                ..Default::default()
            };
            f.write(js, k as u64 + 1, &ros2::encode(&one).unwrap());
        }
        f.finish()
    };
    let rec = read_mcap_bytes(&file(3), Path::new("few.mcap")).unwrap();
    assert_eq!(rec.frames.len(), 4);
    assert_eq!(rec.frames[3].q[7], 2.0);
    assert_eq!(rec.frames[3].q[8], 0.0);
    let e = read_mcap_bytes(&file(60), Path::new("many.mcap")).unwrap_err();
    assert!(
        e.to_string().contains("too many partial joint states"),
        "{e}"
    );
}

/// Uncompressed chunks: armsim reads them, and refuses (instead of misreading, or panicking
/// inside mcap 0.26's reader) a chunk whose first record claims more bytes than the chunk's
/// records hold, whether or not the file holds those bytes.
#[test]
fn uncompressed_chunk_records_must_end_inside_their_chunk() {
    let zstd = fuzz_seeds().remove(0);
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .create(Cursor::new(Vec::new()))
        .unwrap();
    for m in mcap::MessageStream::new(&zstd).unwrap() {
        w.write(&m.unwrap()).unwrap();
    }
    w.finish().unwrap();
    let good = w.into_inner().into_inner();
    let path = Path::new("uncompressed.mcap");
    // Messages only (the rewrite drops the metadata record): they all read back.
    let (rec, want) = (
        read_mcap_bytes(&good, path).unwrap(),
        read_mcap_bytes(&zstd, path).unwrap(),
    );
    assert_eq!(rec.frames, want.frames);
    assert_eq!(rec.clouds, want.clouds);
    assert_eq!(rec.torque_check, want.torque_check);
    assert_eq!(rec.collisions, want.collisions);
    assert_eq!(rec.header.robot_description, want.header.robot_description);
    // The first chunk (opcode 6) after the magic and the header record.
    let mut at = 8;
    let chunk = loop {
        let len = u64::from_le_bytes(good[at + 1..at + 9].try_into().unwrap()) as usize;
        if good[at] == 0x06 {
            break at;
        }
        at += 9 + len;
    };
    // Its body: times (16), uncompressed size (8) and CRC (4), compression "" (4), then the
    // records' size (8) and the records.
    let body = chunk + 9;
    let compression_len = u32::from_le_bytes(good[body + 28..body + 32].try_into().unwrap());
    assert_eq!(compression_len, 0, "the chunk is not uncompressed");
    let size_at = body + 32;
    let size = u64::from_le_bytes(good[size_at..size_at + 8].try_into().unwrap());
    let first = size_at + 8;
    for claim in [size - 8, size + 1000, u64::MAX - 3] {
        let mut bad = good.clone();
        bad[first + 1..first + 9].copy_from_slice(&claim.to_le_bytes());
        let e = read_mcap_bytes(&bad, path).unwrap_err().to_string();
        assert!(
            e.starts_with("uncompressed.mcap: record ")
                && e.contains(&format!(
                    "declares {claim} bytes of content, more than the {} left",
                    size - 9
                )),
            "{claim}: {e}"
        );
    }
}

#[test]
fn truncated_and_garbage_files_are_errors() {
    let dir = scratch("truncated");
    let path = dir.join("ok.mcap");
    write_recording(&path, &ur5_recording(10)).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let n = bytes.len();
    for cut in [0, 1, 7, 8, 9, 30, n / 4, n / 2, n - 30, n - 9, n - 8, n - 1] {
        let e = read_mcap_bytes(&bytes[..cut], Path::new("cut.mcap"))
            .expect_err(&format!("cut at {cut} of {n}"));
        assert!(e.to_string().starts_with("cut.mcap: "), "{e}");
    }
    for garbage in [
        &b"not an mcap file at all"[..],
        &[0u8; 64],
        &[0x89, b'M', b'C', b'A', b'P', b'0', b'\r', b'\n'],
    ] {
        assert!(read_mcap_bytes(garbage, Path::new("g.mcap")).is_err());
    }
    let missing = read_mcap(&dir.join("missing.mcap")).unwrap_err();
    assert!(matches!(missing, RecordError::Io { .. }));
    assert!(missing.to_string().contains("missing.mcap"));
}

/// Small valid files to mutate: armsim's own (zstd chunks) and the same messages without
/// chunks and without CRCs, so that mutations reach the records and the CDR payloads.
fn fuzz_seeds() -> Vec<Vec<u8>> {
    let mut rec = ur5_recording(3);
    rec.clouds[0].points.truncate(5);
    rec.clouds[0].values.truncate(5);
    zstd_and_plain(&rec, "seed")
}

/// The planar 2R (DH table, so its robot description is the generated URDF) for two
/// frames, with a three-point cloud, its torque check, one collision and two obstacles (a
/// box and a capsule: four markers and two labels): seeds of a few KiB
/// that the `mcap_reader` fuzz target mutates faster than the UR5 ones.
fn small_fuzz_seeds() -> Vec<Vec<u8>> {
    let path = root().join("robots/planar_2r.toml");
    let (model, _) = Model::load(&path).unwrap();
    let spec = Model::read_spec(&path).unwrap();
    let mut data = Data::new(&model);
    let (mut header, robot_tf) = Header::for_model("2r", &path, &model, &spec);
    header.epoch_ns = Some(EPOCH);
    let frames = (0..2)
        .map(|k| {
            let q = [0.1 * k as f64, -0.2];
            robot_tf.frame_at(
                &model,
                &mut data,
                0.01 * k as f64,
                &q,
                &[0.5, -0.5],
                &[1.0, 2.0],
            )
        })
        .collect();
    let mut big = ur5_recording(1);
    big.clouds[1].points.truncate(3);
    big.torque_check.truncate(2);
    for (row, joint) in big.torque_check.iter_mut().zip(model.dof_names()) {
        row.joint = joint;
    }
    let rec = Recording {
        header,
        frames,
        clouds: vec![big.clouds[1].clone()],
        torque_check: big.torque_check,
        collisions: big.collisions[..1].to_vec(),
        obstacles: markers_of(
            &[
                Obstacle::cuboid("box", [0.2, 0.1, 0.3], [0.5, 0.0, 0.15]),
                Obstacle::new(
                    "bar",
                    Shape::Capsule {
                        radius: 0.02,
                        length: 0.3,
                    },
                    Se3::from_xyz_rpy([0.3, 0.2, 0.4], [0.0, 1.0, 0.0]),
                ),
            ],
            "world",
            &Se3::identity(),
            None,
        ),
    };
    zstd_and_plain(&rec, "small_seed")
}

/// `rec` written by armsim (zstd chunks) and its messages rewritten without chunks and
/// without CRCs, so that mutations reach the records and the CDR payloads.
fn zstd_and_plain(rec: &Recording, name: &str) -> Vec<Vec<u8>> {
    // A directory per call: tests make seeds in parallel, and `scratch` empties its directory.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = scratch(&format!("fuzz_seeds_{call}"));
    let path = dir.join(format!("{name}.mcap"));
    write_recording(&path, rec).unwrap();
    let zstd = std::fs::read(&path).unwrap();
    let mut plain = mcap::WriteOptions::new()
        .use_chunks(false)
        .calculate_data_section_crc(false)
        .calculate_summary_section_crc(false)
        .create(Cursor::new(Vec::new()))
        .unwrap();
    for m in mcap::MessageStream::new(&zstd).unwrap() {
        plain.write(&m.unwrap()).unwrap();
    }
    plain.finish().unwrap();
    vec![zstd, plain.into_inner().into_inner()]
}

/// Where the seed recordings of the `mcap_reader` fuzz target are committed.
const MCAP_SEEDS: &str = "tests/data/recordings";

/// Writes [`fuzz_seeds`] as the `mcap_reader` fuzz target's seed files:
/// `cargo test --release --test recording -- --ignored write_mcap_seeds`.
#[test]
#[ignore]
fn write_mcap_seeds() {
    let dir = root().join(MCAP_SEEDS);
    std::fs::create_dir_all(&dir).unwrap();
    for (bytes, name) in all_seeds() {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
}

/// Every seed file with its name.
fn all_seeds() -> Vec<(Vec<u8>, &'static str)> {
    let names = [
        "ur5_zstd.mcap",
        "ur5_unchunked.mcap",
        "planar_2r_zstd.mcap",
        "planar_2r_unchunked.mcap",
    ];
    fuzz_seeds()
        .into_iter()
        .chain(small_fuzz_seeds())
        .zip(names)
        .collect()
}

/// The committed seed recordings are what [`fuzz_seeds`] and [`small_fuzz_seeds`] write
/// today, and they read back (three UR5 or two 2R frames, clouds, the torque check and the
/// collision events).
#[test]
fn committed_mcap_seeds_are_current() {
    let dir = root().join(MCAP_SEEDS);
    for (bytes, name) in all_seeds() {
        let path = dir.join(name);
        let rec = read_mcap(&path).unwrap_or_else(|e| panic!("{e}"));
        let want = read_mcap_bytes(&bytes, &path).unwrap();
        assert_eq!(rec.header.joint_names, want.header.joint_names, "{name}");
        assert_eq!(rec.frames, want.frames, "{name}");
        assert_eq!(rec.clouds, want.clouds, "{name}");
        assert_eq!(rec.torque_check, want.torque_check, "{name}");
        assert_eq!(rec.collisions, want.collisions, "{name}");
        assert_eq!(rec.obstacles, want.obstacles, "{name}");
        let (frames, joints, obstacle_shapes) = if name.starts_with("ur5") {
            (3, 6, 0)
        } else {
            (2, 2, 4)
        };
        assert_eq!(rec.obstacles.len(), obstacle_shapes, "{name}");
        assert_eq!(rec.frames.len(), frames, "{name}");
        assert_eq!(rec.header.joint_names.len(), joints, "{name}");
    }
}

fn assert_no_panic(bytes: &[u8]) {
    if let Err(e) = read_mcap_bytes(bytes, Path::new("fuzz.mcap")) {
        let message = e.to_string();
        assert!(!message.contains("panicked"), "{message}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(body in prop::collection::vec(any::<u8>(), 0..1024), magic in any::<bool>()) {
        let mut bytes = Vec::new();
        if magic {
            bytes.extend_from_slice(b"\x89MCAP0\r\n");
        }
        bytes.extend_from_slice(&body);
        assert_no_panic(&bytes);
    }

    #[test]
    fn mutated_valid_files_never_panic(
        seed in 0usize..2,
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
        cut in any::<prop::sample::Index>(),
        truncate in any::<bool>(),
    ) {
        thread_local!(static SEEDS: Vec<Vec<u8>> = fuzz_seeds());
        let mut bytes = SEEDS.with(|s| s[seed].clone());
        for (at, v) in edits {
            let i = at.index(bytes.len());
            bytes[i] = v;
        }
        if truncate {
            bytes.truncate(cut.index(bytes.len()));
        }
        assert_no_panic(&bytes);
    }
}

#[test]
fn dh_models_get_a_urdf_with_the_same_kinematics() {
    let mut rng = rand::rngs::SmallRng::seed_from_u64(11);
    let mut checked = 0;
    for path in common::robot_files() {
        let spec = Model::read_spec(&path).unwrap();
        let text = urdf_out::robot_description(&path, &spec);
        if path.extension().unwrap() == "urdf" {
            assert_eq!(text, std::fs::read_to_string(&path).unwrap());
            continue;
        }
        let (dh, dh_warnings) = Model::load(&path).unwrap();
        let uspec = urdf::parse(&text, "generated.urdf")
            .unwrap_or_else(|e| panic!("{}: {e}\n{text}", path.display()));
        let (gen, warnings) = Model::build(uspec).unwrap();
        // The same warnings as the table (e.g. puma560's textbook inertias).
        let messages = |w: &[armsim::model::ModelWarning]| {
            w.iter()
                .map(|w| (w.key.clone(), w.message.clone()))
                .collect::<Vec<_>>()
        };
        assert_eq!(
            messages(&warnings),
            messages(&dh_warnings),
            "{}",
            path.display()
        );
        assert_eq!(gen.dof_names(), dh.dof_names(), "{}", path.display());
        assert_eq!(gen.lower, dh.lower);
        assert_eq!(gen.upper, dh.upper);
        assert_eq!(gen.effort_limit, dh.effort_limit);
        assert_eq!(gen.velocity_limit, dh.velocity_limit);
        let (mut d1, mut d2) = (Data::new(&dh), Data::new(&gen));
        for _ in 0..20 {
            let q: Vec<f64> = (0..dh.nv)
                .map(|k| {
                    let (lo, hi) = (dh.lower[k].max(-3.0), dh.upper[k].min(3.0));
                    rng.random_range(lo..=hi)
                })
                .collect();
            forward_kinematics(&dh, &mut d1, &q);
            forward_kinematics(&gen, &mut d2, &q);
            for (l, link) in dh.links.iter().enumerate() {
                let g = gen
                    .link_id(&link.name)
                    .unwrap_or_else(|| panic!("{}: no link {}", path.display(), link.name));
                let diff = common::pose_diff(
                    &frame_placement(&dh, &d1, l),
                    &frame_placement(&gen, &d2, g),
                );
                assert!(diff < 1e-12, "{} {}: {diff:e}", path.display(), link.name);
            }
        }
        // The masses carry over (the links' inertias are written as given).
        let mass = |m: &Model| m.links.iter().map(|l| l.inertial.mass).sum::<f64>();
        assert_eq!(mass(&gen), mass(&dh));
        checked += 1;
    }
    assert!(checked >= 5, "only {checked} DH models");
}

#[test]
fn dh_robot_description_round_trips_through_a_recording() {
    let path = root().join("robots/puma560.toml");
    let spec = Model::read_spec(&path).unwrap();
    let (model, _) = Model::load(&path).unwrap();
    let urdf_text = urdf_out::robot_description(&path, &spec);
    let rec = Recording {
        header: Header {
            name: "puma".into(),
            joint_names: model.dof_names(),
            effort_limits: vec![None; model.nv],
            static_tf: tf::RobotTf::new(&model, &spec).static_transforms(),
            robot_description: Some(urdf_text.clone()),
            metadata: vec![],
            epoch_ns: Some(EPOCH),
        },
        frames: vec![Frame {
            t: 0.0,
            q: vec![0.1; model.nv],
            ..Frame::default()
        }],
        ..Recording::default()
    };
    let dir = scratch("dh_description");
    let file = dir.join("puma.mcap");
    write_recording(&file, &rec).unwrap();
    let back = read_mcap(&file).unwrap();
    assert_eq!(
        back.header.robot_description.as_deref(),
        Some(urdf_text.as_str())
    );
    assert_eq!(back.header.effort_limits, rec.header.effort_limits);
    assert_eq!(back.header.static_tf, rec.header.static_tf);
}

#[test]
fn recorded_transforms_follow_the_robot_description() {
    // For every model: the transforms (static and per frame) are exactly the joints of the
    // robot description, and composing them from the root gives every link's world pose.
    let mut rng = rand::rngs::SmallRng::seed_from_u64(5);
    for path in common::robot_files() {
        let spec = Model::read_spec(&path).unwrap();
        let (model, _) = Model::load(&path).unwrap();
        let text = urdf_out::robot_description(&path, &spec);
        let described = urdf::parse(&text, "description.urdf").unwrap();
        let robot_tf = tf::RobotTf::new(&model, &spec);
        let mut data = Data::new(&model);
        let q: Vec<f64> = (0..model.nv)
            .map(|k| rng.random_range(model.lower[k].max(-3.0)..=model.upper[k].min(3.0)))
            .collect();
        let frame = robot_tf.frame_at(&model, &mut data, 0.0, &q, &[], &[]);
        let all: Vec<_> = robot_tf
            .static_transforms()
            .into_iter()
            .chain(frame.tf)
            .collect();
        let mut edges: Vec<(String, String)> = all
            .iter()
            .map(|t| (t.parent.clone(), t.child.clone()))
            .collect();
        let mut joints: Vec<(String, String)> = described
            .joints
            .iter()
            .map(|j| (j.parent.clone(), j.child.clone()))
            .collect();
        edges.sort();
        joints.sort();
        assert_eq!(edges, joints, "{}", path.display());
        let parent: BTreeMap<&str, &armsim::io::record::Transform> =
            all.iter().map(|t| (t.child.as_str(), t)).collect();
        for (l, link) in model.links.iter().enumerate() {
            let mut pose = armsim::core::spatial::Se3::identity();
            let mut frame = link.name.as_str();
            while let Some(t) = parent.get(frame) {
                pose = tf::to_se3(t).mul(&pose);
                frame = &t.parent;
            }
            let diff = common::pose_diff(&pose, &frame_placement(&model, &data, l));
            assert!(diff < 1e-12, "{} {}: {diff:e}", path.display(), link.name);
        }
    }
}

/// Issue 28: bytes after the closing magic, and a flipped byte in a record outside the
/// chunks (the data section's CRC), are refused; the files as written read.
#[test]
fn appended_garbage_and_data_section_flips_are_refused() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/recordings/ur5_zstd.mcap");
    let bytes = std::fs::read(&path).unwrap();
    assert!(read_mcap_bytes(&bytes, Path::new("ok.mcap")).is_ok());
    let mut tail = bytes.clone();
    tail.extend_from_slice(b"garbage after the end");
    let e = read_mcap_bytes(&tail, Path::new("tail.mcap"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("tail.mcap"), "{e}");
    // The header record's profile string sits right after the magic and the record's
    // opcode and lengths: flip a byte of it.
    let mut flipped = bytes.clone();
    flipped[8 + 1 + 8 + 4] ^= 0x20;
    let got = read_mcap_bytes(&flipped, Path::new("flip.mcap"));
    assert!(got.is_err(), "a flipped header byte was accepted");
}
