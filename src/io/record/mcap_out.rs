//! Streaming MCAP writer: a [`Recording`] as ROS 2 messages (CDR, `ros2msg` schemas,
//! profile `ros2`), in zstd-compressed chunks, that `ros2 bag`, Foxglove, `mcap` tools and
//! Rerun read.
//!
//! Owned here: [`McapWriter`] and [`write_recording`]. Topics:
//!
//! | topic | type | when |
//! |---|---|---|
//! | `/robot_description` | `std_msgs/msg/String` | once at start (if the header has one) |
//! | `/tf_static` | `tf2_msgs/msg/TFMessage` | once at start (if there are static frames) |
//! | `/joint_states` | `sensor_msgs/msg/JointState` | every frame |
//! | `/tf` | `tf2_msgs/msg/TFMessage` | every frame with transforms |
//! | `/armsim/workspace` | `sensor_msgs/msg/PointCloud2` | each point cloud |
//! | `/armsim/torque_check` | `diagnostic_msgs/msg/DiagnosticArray` | each torque check |
//! | `/armsim/collisions` | `diagnostic_msgs/msg/DiagnosticArray` | one per contact time |
//! | `/armsim/obstacles` | `visualization_msgs/msg/MarkerArray` | once at start (see `obstacles`) |
//!
//! `/robot_description`, `/tf_static` and `/armsim/obstacles` carry rosbag2's
//! transient-local ("latched") QoS in their channel metadata. A metadata record named
//! `armsim` holds the header's name, the armsim version, the joint names and effort
//! limits, the epoch, and the header's free-form metadata.
//!
//! **Time.** Simulation time `t` (seconds, `t ≥ 0`) is written as wall-clock time: `t`
//! after the *epoch*, the Unix time in nanoseconds of `t = 0` — [`Header::epoch_ns`], or
//! the wall clock when the writer is created if that is `None` (an arm run sets it to the
//! run's start). The epoch is in the metadata as `armsim.epoch_ns` (decimal). `epoch + t`
//! is the messages' `header.stamp`; `log_time = publish_time` is the same time, raised
//! where needed so that log times never decrease (collision events written after later
//! frames keep their own stamp but are logged at the latest time written). The start-up
//! messages are logged at the epoch. Tests pass a fixed epoch for reproducible files.
//!
//! **Atomicity.** The file is written to a temporary sibling and renamed over the target by
//! [`McapWriter::finish`] after an fsync. A writer dropped without `finish` removes its
//! temporary file and leaves the target untouched; an interrupted run that calls `finish`
//! (see `recording::interrupt`) leaves a complete, valid MCAP.

use crate::io::record::obstacle_markers::{self, ObstacleMarker};
use crate::io::record::record_error::RecordError;
use crate::io::record::ros2::{self, datatype, level, RosMessage};
use crate::io::record::{
    CollisionEvent, Frame, Header, PointCloud, Recording, TorqueRow, Transform,
};
use mcap::records::{MessageHeader, Metadata};
use mcap::{Compression, WriteOptions, Writer};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Topic of the joint states.
pub const TOPIC_JOINT_STATES: &str = "/joint_states";
/// Topic of the moving frames.
pub const TOPIC_TF: &str = "/tf";
/// Topic of the fixed frames.
pub const TOPIC_TF_STATIC: &str = "/tf_static";
/// Topic of the URDF text.
pub const TOPIC_ROBOT_DESCRIPTION: &str = "/robot_description";
/// Topic of the point clouds.
pub const TOPIC_WORKSPACE: &str = "/armsim/workspace";
/// Topic of the torque check.
pub const TOPIC_TORQUE_CHECK: &str = "/armsim/torque_check";
/// Topic of the collision events.
pub const TOPIC_COLLISIONS: &str = "/armsim/collisions";
/// Topic of the scene's obstacles.
pub const TOPIC_OBSTACLES: &str = "/armsim/obstacles";
/// Name of the metadata record.
pub const METADATA_NAME: &str = "armsim";
/// Name of the optional scalar field of the point clouds.
pub const CLOUD_SCALAR_FIELD: &str = "manipulability";

/// Metadata keys the writer sets itself (the header's metadata may not use them, except
/// `armsim_version`, which then replaces the writer's).
pub(crate) const KEY_NAME: &str = "name";
pub(crate) const KEY_VERSION: &str = "armsim_version";
pub(crate) const KEY_JOINT_NAMES: &str = "armsim.joint_names";
pub(crate) const KEY_EFFORT_LIMITS: &str = "armsim.effort_limits";
pub(crate) const KEY_EPOCH: &str = "armsim.epoch_ns";

/// rosbag2's QoS of a latched topic (reliable, transient local, keep last 1), numeric form.
const LATCHED_QOS: &str = "- history: 1\n  depth: 1\n  reliability: 1\n  durability: 1\n  \
deadline:\n    sec: 2147483647\n    nsec: 4294967295\n  lifespan:\n    sec: 2147483647\n    \
nsec: 4294967295\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 2147483647\n    \
nsec: 4294967295\n  avoid_ros_namespace_conventions: false\n";

/// One topic: its channel id and the next sequence number.
#[derive(Clone, Copy)]
struct Chan {
    id: u16,
    seq: u32,
}

/// Writes a recording frame by frame (see the module docs).
pub struct McapWriter {
    path: PathBuf,
    tmp: PathBuf,
    writer: Option<Writer<BufWriter<File>>>,
    joint_names: Vec<String>,
    hardware_id: String,
    epoch_ns: u64,
    last_log_time: u64,
    joint_states: Option<Chan>,
    tf: Option<Chan>,
    workspace: Option<Chan>,
    torque_check: Option<Chan>,
    collisions: Option<Chan>,
}

/// The Unix time of `t` seconds after `epoch_ns`, in nanoseconds and as a ROS time;
/// `None` unless `t` is finite, `≥ 0` and the sum fits a ROS time (seconds in an `i32`:
/// before 2038-01-19).
fn nanos(epoch_ns: u64, t: f64) -> Option<(u64, ros2::Time)> {
    if !(0.0..2_147_483_648.0).contains(&t) {
        return None;
    }
    let ns = epoch_ns.checked_add((t * 1e9).round() as u64)?;
    Some((ns, ros2::Time::from_nanos(ns)?))
}

/// The wall clock now, in nanoseconds since the Unix epoch (0 if the clock is before it).
pub fn wall_clock_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
}

/// Shortest text that parses back to the same `f64`.
pub(crate) fn fmt_f64(x: f64) -> String {
    format!("{x:?}")
}

fn fmt_opt(x: Option<f64>) -> String {
    x.map(fmt_f64).unwrap_or_else(|| "none".to_string())
}

fn temp_path(path: &Path) -> Result<PathBuf, RecordError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| {
        RecordError::invalid(path, "not a file name (the path ends in '..' or '/')")
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok(dir.join(format!(
        ".{}.{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )))
}

impl McapWriter {
    /// Creates the temporary file beside `path`, writes the `armsim` metadata record,
    /// `/robot_description` and `/tf_static`. Times count from `header.epoch_ns`, or from
    /// now if that is `None`.
    pub fn create(path: &Path, header: &Header) -> Result<Self, RecordError> {
        let epoch_ns = header.epoch_ns.unwrap_or_else(wall_clock_ns);
        let Some((_, epoch_stamp)) = nanos(epoch_ns, 0.0) else {
            return Err(RecordError::invalid(
                path,
                format!("epoch {epoch_ns} ns is after the end of ROS time (2038-01-19)"),
            ));
        };
        let tmp = temp_path(path)?;
        let file = File::create(&tmp).map_err(|e| RecordError::io(&tmp, e))?;
        let mut w = McapWriter {
            path: path.to_path_buf(),
            tmp,
            writer: None,
            joint_names: header.joint_names.clone(),
            hardware_id: header.name.clone(),
            epoch_ns,
            last_log_time: epoch_ns,
            joint_states: None,
            tf: None,
            workspace: None,
            torque_check: None,
            collisions: None,
        };
        // From here on, an error drops `w`, which removes the temporary file.
        let metadata = w.metadata_record(header)?;
        let opts = WriteOptions::new()
            .compression(Some(Compression::Zstd))
            .profile("ros2")
            .library(format!("armsim {}", env!("CARGO_PKG_VERSION")))
            // Single-threaded zstd: deterministic output and no worker threads.
            .compression_threads(0);
        let writer = opts
            .create(BufWriter::new(file))
            .map_err(|e| RecordError::mcap(&w.path, e))?;
        w.writer = Some(writer);
        w.mcap(|m| m.write_metadata(&metadata))?;
        if let Some(urdf) = &header.robot_description {
            let mut ch = w.channel::<ros2::StringMsg>(TOPIC_ROBOT_DESCRIPTION, true)?;
            let msg = ros2::StringMsg { data: urdf.clone() };
            w.write(&mut ch, epoch_ns, &msg)?;
        }
        if !header.static_tf.is_empty() {
            let mut ch = w.channel::<ros2::TfMessage>(TOPIC_TF_STATIC, true)?;
            let msg = tf_message(&header.static_tf, epoch_stamp);
            w.write(&mut ch, epoch_ns, &msg)?;
        }
        Ok(w)
    }

    /// The target path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The epoch: Unix time in nanoseconds of `t = 0`.
    pub fn epoch_ns(&self) -> u64 {
        self.epoch_ns
    }

    fn metadata_record(&self, header: &Header) -> Result<Metadata, RecordError> {
        let mut m = BTreeMap::new();
        m.insert(KEY_NAME.to_string(), header.name.clone());
        m.insert(
            KEY_VERSION.to_string(),
            env!("CARGO_PKG_VERSION").to_string(),
        );
        let json = |v: serde_json::Result<String>| {
            v.map_err(|e| RecordError::invalid(&self.path, format!("metadata: {e}")))
        };
        m.insert(
            KEY_JOINT_NAMES.to_string(),
            json(serde_json::to_string(&header.joint_names))?,
        );
        let limits: Vec<Option<String>> = header
            .effort_limits
            .iter()
            .map(|l| l.map(fmt_f64))
            .collect();
        m.insert(
            KEY_EFFORT_LIMITS.to_string(),
            json(serde_json::to_string(&limits))?,
        );
        m.insert(KEY_EPOCH.to_string(), self.epoch_ns.to_string());
        let mut seen = std::collections::HashSet::new();
        for (k, v) in &header.metadata {
            if !seen.insert(k.as_str()) {
                return Err(RecordError::invalid(
                    &self.path,
                    format!("metadata: duplicate key '{k}'"),
                ));
            }
            if k != KEY_VERSION && m.contains_key(k) {
                return Err(RecordError::invalid(
                    &self.path,
                    format!("metadata: the key '{k}' is reserved for armsim"),
                ));
            }
            m.insert(k.clone(), v.clone());
        }
        Ok(Metadata {
            name: METADATA_NAME.to_string(),
            metadata: m,
        })
    }

    fn mcap<T>(
        &mut self,
        f: impl FnOnce(&mut Writer<BufWriter<File>>) -> mcap::McapResult<T>,
    ) -> Result<T, RecordError> {
        let w = self
            .writer
            .as_mut()
            .ok_or_else(|| RecordError::invalid(&self.path, "the writer is closed"))?;
        f(w).map_err(|e| RecordError::mcap(&self.path, e))
    }

    fn channel<M: RosMessage>(&mut self, topic: &str, latched: bool) -> Result<Chan, RecordError> {
        let schema =
            self.mcap(|w| w.add_schema(M::NAME, ros2::SCHEMA_ENCODING, M::SCHEMA.as_bytes()))?;
        let mut meta = BTreeMap::new();
        if latched {
            meta.insert("offered_qos_profiles".to_string(), LATCHED_QOS.to_string());
        }
        let id = self.mcap(|w| w.add_channel(schema, topic, ros2::MESSAGE_ENCODING, &meta))?;
        Ok(Chan { id, seq: 0 })
    }

    /// Writes `msg` stamped at `stamp_ns`, logged at `max(stamp_ns, last log time)`.
    fn write<M: RosMessage>(
        &mut self,
        ch: &mut Chan,
        stamp_ns: u64,
        msg: &M,
    ) -> Result<(), RecordError> {
        let data = ros2::encode(msg)
            .map_err(|e| RecordError::invalid(&self.path, format!("{}: {e}", M::NAME)))?;
        let log_time = stamp_ns.max(self.last_log_time);
        let header = MessageHeader {
            channel_id: ch.id,
            sequence: ch.seq,
            log_time,
            publish_time: log_time,
        };
        self.mcap(|w| w.write_to_known_channel(&header, &data))?;
        ch.seq = ch.seq.wrapping_add(1);
        self.last_log_time = log_time;
        Ok(())
    }

    fn stamp(&self, t: f64, what: &str) -> Result<(u64, ros2::Time), RecordError> {
        nanos(self.epoch_ns, t).ok_or_else(|| {
            RecordError::invalid(
                &self.path,
                format!(
                    "{what}: time {t} s is not finite and ≥ 0, or is past the end of ROS \
                     time (2038-01-19) from the epoch {} ns",
                    self.epoch_ns
                ),
            )
        })
    }

    /// Opens a topic on first use.
    fn topic<M: RosMessage>(
        &mut self,
        slot: fn(&mut Self) -> &mut Option<Chan>,
        topic: &str,
    ) -> Result<Chan, RecordError> {
        if let Some(c) = *slot(self) {
            return Ok(c);
        }
        let c = self.channel::<M>(topic, false)?;
        *slot(self) = Some(c);
        Ok(c)
    }

    /// Writes one frame: `/joint_states`, and `/tf` when the frame has transforms.
    pub fn write_frame(&mut self, frame: &Frame) -> Result<(), RecordError> {
        let n = self.joint_names.len();
        let what = format!("frame at t = {}", frame.t);
        if frame.q.len() != n {
            return Err(RecordError::invalid(
                &self.path,
                format!("{what}: {} positions for {n} joints", frame.q.len()),
            ));
        }
        for (name, v) in [("velocities", &frame.qd), ("efforts", &frame.tau)] {
            if !v.is_empty() && v.len() != n {
                return Err(RecordError::invalid(
                    &self.path,
                    format!("{what}: {} {name} for {n} joints", v.len()),
                ));
            }
        }
        let (ns, stamp) = self.stamp(frame.t, &what)?;
        let msg = ros2::JointState {
            header: ros2::Header {
                stamp,
                frame_id: String::new(),
            },
            name: self.joint_names.clone(),
            position: frame.q.clone(),
            velocity: frame.qd.clone(),
            effort: frame.tau.clone(),
        };
        let mut ch = self.topic::<ros2::JointState>(|s| &mut s.joint_states, TOPIC_JOINT_STATES)?;
        self.write(&mut ch, ns, &msg)?;
        self.joint_states = Some(ch);
        if !frame.tf.is_empty() {
            let mut ch = self.topic::<ros2::TfMessage>(|s| &mut s.tf, TOPIC_TF)?;
            self.write(&mut ch, ns, &tf_message(&frame.tf, stamp))?;
            self.tf = Some(ch);
        }
        Ok(())
    }

    /// Writes a point cloud on `/armsim/workspace`: float32 `x, y, z` and, when the cloud
    /// has values, a float32 `manipulability` field.
    pub fn write_cloud(&mut self, cloud: &PointCloud) -> Result<(), RecordError> {
        let what = format!("point cloud at t = {}", cloud.t);
        let with_values = !cloud.values.is_empty();
        if with_values && cloud.values.len() != cloud.points.len() {
            return Err(RecordError::invalid(
                &self.path,
                format!(
                    "{what}: {} values for {} points",
                    cloud.values.len(),
                    cloud.points.len()
                ),
            ));
        }
        let (ns, stamp) = self.stamp(cloud.t, &what)?;
        let point_step: u32 = if with_values { 16 } else { 12 };
        let width = u32::try_from(cloud.points.len())
            .ok()
            .filter(|&w| w.checked_mul(point_step).is_some())
            .ok_or_else(|| RecordError::invalid(&self.path, format!("{what}: too many points")))?;
        let mut data = Vec::with_capacity(cloud.points.len() * point_step as usize);
        for (i, p) in cloud.points.iter().enumerate() {
            for c in p {
                data.extend_from_slice(&c.to_le_bytes());
            }
            if let Some(v) = cloud.values.get(i) {
                data.extend_from_slice(&v.to_le_bytes());
            }
        }
        let field = |name: &str, offset: u32| ros2::PointField {
            name: name.to_string(),
            offset,
            datatype: datatype::FLOAT32,
            count: 1,
        };
        let mut fields = vec![field("x", 0), field("y", 4), field("z", 8)];
        if with_values {
            fields.push(field(CLOUD_SCALAR_FIELD, 12));
        }
        let is_dense = cloud.points.iter().all(|p| p.iter().all(|c| c.is_finite()));
        let msg = ros2::PointCloud2 {
            header: ros2::Header {
                stamp,
                frame_id: cloud.frame.clone(),
            },
            height: 1,
            width,
            fields,
            is_bigendian: false,
            point_step,
            row_step: point_step * width,
            data,
            is_dense,
        };
        let mut ch = self.topic::<ros2::PointCloud2>(|s| &mut s.workspace, TOPIC_WORKSPACE)?;
        self.write(&mut ch, ns, &msg)?;
        self.workspace = Some(ch);
        Ok(())
    }

    /// Writes a torque check at time `t` on `/armsim/torque_check`: one status per joint,
    /// level OK or ERROR, with the row's numbers as text (`none` where absent).
    pub fn write_torque_check(&mut self, t: f64, rows: &[TorqueRow]) -> Result<(), RecordError> {
        let (ns, stamp) = self.stamp(t, "torque check")?;
        let status = rows
            .iter()
            .map(|r| {
                let kv = |k: &str, v: String| ros2::KeyValue {
                    key: k.to_string(),
                    value: v,
                };
                ros2::DiagnosticStatus {
                    level: if r.ok { level::OK } else { level::ERROR },
                    name: r.joint.clone(),
                    message: if r.ok { "ok" } else { "limit exceeded" }.to_string(),
                    hardware_id: self.hardware_id.clone(),
                    values: vec![
                        kv("peak_torque", fmt_f64(r.peak_torque)),
                        kv("rms_torque", fmt_f64(r.rms_torque)),
                        kv("peak_speed", fmt_f64(r.peak_speed)),
                        kv("peak_power", fmt_f64(r.peak_power)),
                        kv("limit", fmt_opt(r.limit)),
                        kv("velocity_limit", fmt_opt(r.velocity_limit)),
                        kv("margin", fmt_opt(r.margin)),
                        kv("first_violation", fmt_opt(r.first_violation)),
                    ],
                }
            })
            .collect();
        self.write_diagnostics(
            |s| &mut s.torque_check,
            TOPIC_TORQUE_CHECK,
            ns,
            stamp,
            status,
        )
    }

    /// Writes a DiagnosticArray on a topic opened on first use.
    fn write_diagnostics(
        &mut self,
        slot: fn(&mut Self) -> &mut Option<Chan>,
        topic: &str,
        ns: u64,
        stamp: ros2::Time,
        status: Vec<ros2::DiagnosticStatus>,
    ) -> Result<(), RecordError> {
        let msg = ros2::DiagnosticArray {
            header: ros2::Header {
                stamp,
                frame_id: String::new(),
            },
            status,
        };
        let mut ch = self.topic::<ros2::DiagnosticArray>(slot, topic)?;
        self.write(&mut ch, ns, &msg)?;
        *slot(self) = Some(ch);
        Ok(())
    }

    /// Writes the scene's obstacles on `/armsim/obstacles` (latched): one MarkerArray
    /// stamped at the epoch (`t = 0`; logged later if later messages were written
    /// already). See [`crate::io::record::obstacle_markers`] for the markers.
    pub fn write_obstacles(&mut self, markers: &[ObstacleMarker]) -> Result<(), RecordError> {
        let (ns, stamp) = self.stamp(0.0, "obstacles")?;
        let msg = obstacle_markers::to_message(markers, stamp);
        let mut ch = self.channel::<ros2::MarkerArray>(TOPIC_OBSTACLES, true)?;
        self.write(&mut ch, ns, &msg)
    }

    /// Writes collision events on `/armsim/collisions`: one DiagnosticArray per run of
    /// events with the same time, one ERROR status per contact with `body_a`, `body_b`.
    pub fn write_collisions(&mut self, events: &[CollisionEvent]) -> Result<(), RecordError> {
        let mut rest = events;
        while let Some(first) = rest.first() {
            let n = rest.iter().take_while(|e| e.t == first.t).count().max(1);
            let (group, tail) = rest.split_at(n.min(rest.len()));
            rest = tail;
            let (ns, stamp) = self.stamp(first.t, "collision event")?;
            let status = group
                .iter()
                .map(|e| ros2::DiagnosticStatus {
                    level: level::ERROR,
                    name: "collision".to_string(),
                    message: format!("{} / {}", e.body_a, e.body_b),
                    hardware_id: self.hardware_id.clone(),
                    values: vec![
                        ros2::KeyValue {
                            key: "body_a".to_string(),
                            value: e.body_a.clone(),
                        },
                        ros2::KeyValue {
                            key: "body_b".to_string(),
                            value: e.body_b.clone(),
                        },
                    ],
                })
                .collect();
            self.write_diagnostics(|s| &mut s.collisions, TOPIC_COLLISIONS, ns, stamp, status)?;
        }
        Ok(())
    }

    /// Finishes the MCAP (summary, footer), flushes and fsyncs it, and renames it over the
    /// target. Returns the target path.
    pub fn finish(mut self) -> Result<PathBuf, RecordError> {
        let mut writer = self
            .writer
            .take()
            .ok_or_else(|| RecordError::invalid(&self.path, "the writer is closed"))?;
        writer
            .finish()
            .map_err(|e| RecordError::mcap(&self.path, e))?;
        let file = writer
            .into_inner()
            .into_inner()
            .map_err(|e| RecordError::io(&self.tmp, e.into_error()))?;
        file.sync_all().map_err(|e| RecordError::io(&self.tmp, e))?;
        drop(file);
        std::fs::rename(&self.tmp, &self.path).map_err(|e| RecordError::io(&self.path, e))?;
        // Make the rename durable too (best effort: not every platform can open a directory).
        if let Some(dir) = self.path.parent().filter(|d| !d.as_os_str().is_empty()) {
            if let Ok(d) = File::open(dir) {
                let _ = d.sync_all();
            }
        }
        Ok(self.path.clone())
    }
}

impl Drop for McapWriter {
    /// A writer that was not finished removes its temporary file.
    fn drop(&mut self) {
        // The mcap writer finishes itself on drop; the result goes away with the file.
        // After a successful `finish` the temporary file is already renamed away.
        drop(self.writer.take());
        let _ = std::fs::remove_file(&self.tmp);
    }
}

fn tf_message(tf: &[Transform], stamp: ros2::Time) -> ros2::TfMessage {
    ros2::TfMessage {
        transforms: tf
            .iter()
            .map(|t| ros2::TransformStamped {
                header: ros2::Header {
                    stamp,
                    frame_id: t.parent.clone(),
                },
                child_frame_id: t.child.clone(),
                transform: ros2::Transform {
                    translation: ros2::Vector3 {
                        x: t.translation[0],
                        y: t.translation[1],
                        z: t.translation[2],
                    },
                    rotation: ros2::Quaternion {
                        x: t.rotation[0],
                        y: t.rotation[1],
                        z: t.rotation[2],
                        w: t.rotation[3],
                    },
                },
            })
            .collect(),
    }
}

/// Writes a whole recording: header, obstacles, frames, clouds, the torque check (stamped
/// at the last frame's time, or 0 without frames) and the collision events.
pub fn write_recording(path: &Path, rec: &Recording) -> Result<PathBuf, RecordError> {
    let mut w = McapWriter::create(path, &rec.header)?;
    if !rec.obstacles.is_empty() {
        w.write_obstacles(&rec.obstacles)?;
    }
    for f in &rec.frames {
        w.write_frame(f)?;
    }
    for c in &rec.clouds {
        w.write_cloud(c)?;
    }
    if !rec.torque_check.is_empty() {
        let t = rec.frames.last().map_or(0.0, |f| f.t);
        w.write_torque_check(t, &rec.torque_check)?;
    }
    if !rec.collisions.is_empty() {
        w.write_collisions(&rec.collisions)?;
    }
    w.finish()
}
