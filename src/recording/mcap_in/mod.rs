//! MCAP reader: any MCAP file with ROS 2 (CDR) messages of the types `mcap_out` writes,
//! back into a [`Recording`] — armsim's own files and other tools' (`ros2 bag`, ...).
//!
//! Owned here: [`read_mcap`] and [`read_mcap_bytes`]. What is read:
//!
//! - `sensor_msgs/msg/JointState` (on `/joint_states`, else the first topic that has
//!   them) → frames. Joint names come from the first message; later messages are matched
//!   by name (a joint a message lacks keeps its previous value, NaN before the first;
//!   extra names are ignored). `velocity`/`effort` may be empty. Frames are sorted by time.
//! - `tf2_msgs/msg/TFMessage` on `/tf` → each transform goes to the frame nearest to its
//!   stamp (replacing a transform with the same child there); without joint states, one
//!   frame per distinct stamp (with empty `q`).
//! - `/tf_static` → `header.static_tf` (one per child frame, last wins);
//!   `std_msgs/msg/String` on `/robot_description` → `header.robot_description`.
//! - `sensor_msgs/msg/PointCloud2` (any topic) → clouds: `x, y, z` float32 or float64, and
//!   a scalar from the field `manipulability` (else `intensity`), any numeric type.
//! - `diagnostic_msgs/msg/DiagnosticArray` on `/armsim/torque_check` (last message) and
//!   `/armsim/collisions` → torque check and collision events.
//! - `visualization_msgs/msg/MarkerArray` on `/armsim/obstacles` (last message) →
//!   obstacles (see `obstacles::from_message`).
//! - The metadata record `armsim` → name, joint names and effort limits (used when there
//!   are no joint states, or to fill limits), the rest into `header.metadata`, sorted by key.
//!   Effort limits otherwise come from the robot description's URDF, if it parses.
//!
//! Times are the messages' `header.stamp` minus the recording's epoch, in seconds, so that
//! a recording starts at 0 whatever wall-clock time it was made at: the epoch is the
//! metadata's `armsim.epoch_ns` (armsim's files, see `mcap_out`), else the earliest stamp
//! of a joint state, transform, cloud or collision (other tools' files); it is returned as
//! `header.epoch_ns` (`None` for a file with neither). A stamp before the epoch gives a
//! negative time. Everything else is ignored: unknown topics, schemas, encodings,
//! attachments.
//!
//! The file is untrusted input: records are parsed here with bounds checks (lengths are
//! checked against the bytes left before anything is allocated), the `mcap` crate's
//! streaming reader decompresses chunks with a record-length limit, and any malformed
//! record or message is an error naming the file and the record or topic and message
//! index — never a panic. Totals are bounded by the file size too, so that a small, highly
//! compressed file cannot expand into gigabytes: at most max(size / 4, 2^20) messages,
//! max(64 × size, 64 MiB) of message payload, and max(4 × size, 2^22) joint values filled in
//! for joints that partial joint-state messages lack.

use super::error::RecordError;
use super::from_ros2::{cloud_from_msg, from_msg, stamp_nanos, torque_row};
use super::mcap_out::{
    KEY_EFFORT_LIMITS, KEY_EPOCH, KEY_JOINT_NAMES, KEY_NAME, METADATA_NAME, TOPIC_COLLISIONS,
    TOPIC_JOINT_STATES, TOPIC_OBSTACLES, TOPIC_ROBOT_DESCRIPTION, TOPIC_TF, TOPIC_TF_STATIC,
    TOPIC_TORQUE_CHECK,
};
use super::obstacles::{self, ObstacleMarker};
use super::ros2::{self, schema_is, RosMessage};
use super::{CollisionEvent, Frame, Header, PointCloud, Recording, TorqueRow, Transform};
use mcap::records::op;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Smallest limit on one record inside a compressed chunk.
const MIN_RECORD_LIMIT: usize = 64 << 20;
/// Largest limit on one record inside a compressed chunk.
const MAX_RECORD_LIMIT: usize = 1 << 30;
/// Smallest limits on the messages, their total payload and the joint values filled in for
/// joints a message lacks (they grow with the file; see [`Budget`]).
const MIN_MESSAGES: usize = 1 << 20;
const MIN_PAYLOAD: usize = 64 << 20;
const MIN_FILLED: usize = 1 << 22;

/// Limits that keep a small, highly compressed file from expanding into gigabytes of
/// frames: what a legitimate recording of that size can hold, with a wide margin.
struct Budget {
    messages: usize,
    payload: usize,
    filled: usize,
}

impl Budget {
    fn for_file(len: usize) -> Self {
        Budget {
            messages: (len / 4).max(MIN_MESSAGES),
            payload: len.saturating_mul(64).max(MIN_PAYLOAD),
            filled: len.saturating_mul(4).max(MIN_FILLED),
        }
    }
}

/// Reads an MCAP file into a [`Recording`] (see the module docs).
pub fn read_mcap(path: &Path) -> Result<Recording, RecordError> {
    let bytes = crate::io::read_input(path).map_err(|e| RecordError::io(path, e))?;
    read_mcap_bytes(&bytes, path)
}

/// [`read_mcap`] on bytes already in memory; `file` names them in errors.
pub fn read_mcap_bytes(bytes: &[u8], file: &Path) -> Result<Recording, RecordError> {
    // Defence in depth: this module indexes nothing unchecked, but the decompressors are
    // third-party code; a panic there becomes an error, not an abort of the caller.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| read_inner(bytes, file)))
        .unwrap_or_else(|_| {
            Err(RecordError::malformed(
                file,
                "file",
                "internal error: the MCAP decoder panicked",
            ))
        })
}

/// A bounds-checked little-endian reader over one record.
struct Cursor<'a> {
    buf: &'a [u8],
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if n > self.buf.len() {
            return Err(format!(
                "length {n} exceeds the {} bytes left in the record",
                self.buf.len()
            ));
        }
        let (head, tail) = self.buf.split_at(n);
        self.buf = tail;
        Ok(head)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }

    fn u16(&mut self) -> Result<u16, String> {
        Ok(u16::from_le_bytes(self.array()?))
    }

    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.array()?))
    }

    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.array()?))
    }

    fn len32(&mut self) -> Result<usize, String> {
        usize::try_from(self.u32()?).map_err(|e| e.to_string())
    }

    fn string(&mut self) -> Result<String, String> {
        let n = self.len32()?;
        let b = self.take(n)?;
        String::from_utf8(b.to_vec()).map_err(|_| "string is not UTF-8".to_string())
    }

    fn map(&mut self) -> Result<BTreeMap<String, String>, String> {
        let n = self.len32()?;
        let mut inner = Cursor { buf: self.take(n)? };
        let mut m = BTreeMap::new();
        while !inner.buf.is_empty() {
            let k = inner.string()?;
            let v = inner.string()?;
            if m.contains_key(&k) {
                return Err(format!("duplicate key '{k}' in a map"));
            }
            m.insert(k, v);
        }
        Ok(m)
    }
}

/// What a channel carries, as far as this reader cares.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    JointState,
    Tf,
    TfStatic,
    RobotDescription,
    Cloud,
    TorqueCheck,
    Collisions,
    Obstacles,
    Ignored,
}

#[derive(PartialEq)]
struct SchemaRec {
    name: String,
    encoding: String,
    data: Vec<u8>,
}

#[derive(PartialEq)]
struct ChannelRec {
    schema_id: u16,
    topic: String,
    message_encoding: String,
    metadata: BTreeMap<String, String>,
}

struct Channel {
    rec: ChannelRec,
    kind: Kind,
    count: usize,
}

fn kind_of(schema: Option<&SchemaRec>, ch: &ChannelRec) -> Kind {
    let Some(s) = schema else {
        return Kind::Ignored;
    };
    if ch.message_encoding != ros2::MESSAGE_ENCODING {
        return Kind::Ignored;
    }
    let is = |name: &str| schema_is(&s.name, name);
    let topic = ch.topic.as_str();
    if is(ros2::JointState::NAME) {
        Kind::JointState
    } else if is(ros2::TfMessage::NAME) && topic == TOPIC_TF {
        Kind::Tf
    } else if is(ros2::TfMessage::NAME) && topic == TOPIC_TF_STATIC {
        Kind::TfStatic
    } else if is(ros2::StringMsg::NAME) && topic == TOPIC_ROBOT_DESCRIPTION {
        Kind::RobotDescription
    } else if is(ros2::PointCloud2::NAME) {
        Kind::Cloud
    } else if is(ros2::DiagnosticArray::NAME) && topic == TOPIC_TORQUE_CHECK {
        Kind::TorqueCheck
    } else if is(ros2::DiagnosticArray::NAME) && topic == TOPIC_COLLISIONS {
        Kind::Collisions
    } else if is(ros2::MarkerArray::NAME) && topic == TOPIC_OBSTACLES {
        Kind::Obstacles
    } else {
        Kind::Ignored
    }
}

/// Everything collected while streaming through the file.
#[derive(Default)]
struct Collected {
    schemas: HashMap<u16, SchemaRec>,
    channels: HashMap<u16, Channel>,
    /// Joint states per topic, and the topics in order of first message.
    joint_states: HashMap<String, Vec<ros2::JointState>>,
    joint_state_topics: Vec<String>,
    tf: Vec<(u64, Transform)>,
    static_tf: Vec<Transform>,
    robot_description: Option<String>,
    /// Clouds and collision events with their stamps (ns; `t` is set once the epoch is
    /// known).
    clouds: Vec<(u64, PointCloud)>,
    torque_check: Option<Vec<TorqueRow>>,
    collisions: Vec<(u64, CollisionEvent)>,
    obstacles: Option<Vec<ObstacleMarker>>,
    metadata: Option<BTreeMap<String, String>>,
    budget: Option<Budget>,
}

/// MCAP magic (start and end of a file).
const MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// Record opcodes this module looks for before the `mcap` crate reads the file.
const OP_FOOTER: u8 = 0x02;
const OP_CHUNK: u8 = 0x06;

/// Finds the records of uncompressed chunks that run past their chunk's end, before the
/// `mcap` crate's linear reader sees them: mcap 0.26 subtracts such a record's length from
/// what is left of the chunk without a check (`linear_reader.rs:745`), which panics with
/// overflow checks and, without them, wraps and reads the records after the chunk as
/// chunk content (found by the `mcap_reader` fuzz target). Anything else that is
/// inconsistent ends this scan quietly and is left to the reader's own errors. The reader
/// streams, so a chunk cut short by the end of the file is checked as far as it goes.
/// Returns the record number and the message.
fn check_uncompressed_chunks(bytes: &[u8]) -> Result<(), (usize, String)> {
    let Some(mut rest) = bytes.strip_prefix(MAGIC) else {
        return Ok(());
    };
    let mut record = 0usize;
    while rest.len() >= 9 {
        let opcode = rest[0];
        let len = u64::from_le_bytes(rest[1..9].try_into().expect("8 bytes"));
        let end = usize::try_from(len)
            .ok()
            .and_then(|l| l.checked_add(9))
            .filter(|&e| e <= rest.len());
        // A record cut short by the end of the file: what there is of it.
        let body = &rest[9..end.unwrap_or(rest.len())];
        record += 1;
        if opcode == OP_CHUNK {
            check_chunk_records(body).map_err(|m| (record, m))?;
        }
        match end {
            Some(e) if opcode != OP_FOOTER => rest = &rest[e..],
            _ => return Ok(()),
        }
    }
    Ok(())
}

/// One chunk record's body, or what the file holds of it (MCAP spec: start and end time,
/// uncompressed size and CRC, compression, then `compressed_size` bytes of records): with no
/// compression, every inner record (opcode, u64 length, content) must end within the
/// declared records.
fn check_chunk_records(body: &[u8]) -> Result<(), String> {
    let mut c = Cursor { buf: body };
    let header = (|| {
        c.take(8 + 8 + 8 + 4)?;
        let n = c.len32()?;
        let compression = c.take(n)?;
        let size = c.u64()?;
        Ok::<_, String>((compression.is_empty(), size))
    })();
    let Ok((true, size)) = header else {
        return Ok(());
    };
    let records = c.buf;
    let mut at = 0u64;
    while at < size {
        let left = size - at;
        // The next record's length, if the file holds it.
        let Some(len) = usize::try_from(at)
            .ok()
            .and_then(|a| records.get(a.checked_add(1)?..a.checked_add(9)?))
            .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
        else {
            return Ok(());
        };
        if left < 9 || len > left - 9 {
            return Err(format!(
                "chunk: the record at byte {at} of its {size} bytes of records declares {len} \
                 bytes of content, more than the {} left",
                left.saturating_sub(9)
            ));
        }
        at += 9 + len;
    }
    Ok(())
}

fn read_inner(bytes: &[u8], file: &Path) -> Result<Recording, RecordError> {
    check_uncompressed_chunks(bytes).map_err(|(record, msg)| {
        RecordError::malformed(
            file,
            format!("record {record} (opcode {OP_CHUNK:#04x})"),
            msg,
        )
    })?;
    let limit = bytes
        .len()
        .saturating_mul(16)
        .clamp(MIN_RECORD_LIMIT, MAX_RECORD_LIMIT)
        .max(bytes.len());
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_record_length_limit(limit)
            .with_validate_chunk_crcs(true),
    );
    let mut c = Collected {
        budget: Some(Budget::for_file(bytes.len())),
        ..Collected::default()
    };
    let mut rest = bytes;
    let mut record = 0usize;
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| RecordError::mcap(file, e))? {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.max(1).min(rest.len());
                let (head, tail) = rest.split_at(n);
                reader.insert(n).copy_from_slice(head);
                reader.notify_read(n);
                rest = tail;
            }
            LinearReadEvent::Record { data, opcode } => {
                record += 1;
                c.record(opcode, data).map_err(|(ctx, msg)| {
                    let ctx =
                        ctx.unwrap_or_else(|| format!("record {record} (opcode {opcode:#04x})"));
                    RecordError::malformed(file, ctx, msg)
                })?;
            }
        }
    }
    c.into_recording(file)
}

/// An error in a record: the context when it is a message (`topic ..., message ...`), and
/// the message.
type RecErr = (Option<String>, String);

impl Collected {
    fn record(&mut self, opcode: u8, data: &[u8]) -> Result<(), RecErr> {
        let plain = |e: String| (None, e);
        let mut cur = Cursor { buf: data };
        match opcode {
            op::SCHEMA => {
                let id = cur.u16().map_err(plain)?;
                let name = cur.string().map_err(plain)?;
                let encoding = cur.string().map_err(plain)?;
                let n = cur.len32().map_err(plain)?;
                let data = cur.take(n).map_err(plain)?.to_vec();
                if id == 0 {
                    return Err(plain("schema id 0 is reserved".into()));
                }
                let rec = SchemaRec {
                    name,
                    encoding,
                    data,
                };
                match self.schemas.get(&id) {
                    Some(old) if *old != rec => {
                        return Err(plain(format!("schema {id} redefined differently")))
                    }
                    Some(_) => {}
                    None => {
                        self.schemas.insert(id, rec);
                    }
                }
            }
            op::CHANNEL => {
                let id = cur.u16().map_err(plain)?;
                let schema_id = cur.u16().map_err(plain)?;
                let topic = cur.string().map_err(plain)?;
                let message_encoding = cur.string().map_err(plain)?;
                let metadata = cur.map().map_err(plain)?;
                let rec = ChannelRec {
                    schema_id,
                    topic,
                    message_encoding,
                    metadata,
                };
                let schema = match schema_id {
                    0 => None,
                    s => Some(self.schemas.get(&s).ok_or_else(|| {
                        plain(format!(
                            "channel '{}' refers to schema {s}, not defined before it",
                            rec.topic
                        ))
                    })?),
                };
                match self.channels.get(&id) {
                    Some(old) if old.rec != rec => {
                        return Err(plain(format!("channel {id} redefined differently")))
                    }
                    Some(_) => {}
                    None => {
                        let kind = kind_of(schema, &rec);
                        self.channels.insert(
                            id,
                            Channel {
                                rec,
                                kind,
                                count: 0,
                            },
                        );
                    }
                }
            }
            op::MESSAGE => {
                let channel_id = cur.u16().map_err(plain)?;
                let _sequence = cur.u32().map_err(plain)?;
                let _log_time = cur.u64().map_err(plain)?;
                let _publish_time = cur.u64().map_err(plain)?;
                if let Some(b) = self.budget.as_mut() {
                    b.messages = b.messages.checked_sub(1).ok_or_else(|| {
                        plain("more messages than a file of this size can hold".into())
                    })?;
                    b.payload = b.payload.checked_sub(cur.buf.len()).ok_or_else(|| {
                        plain("the messages decompress to more data than a file of this size can hold".into())
                    })?;
                }
                let ch = self.channels.get_mut(&channel_id).ok_or_else(|| {
                    plain(format!(
                        "message on channel {channel_id}, not defined before it"
                    ))
                })?;
                let index = ch.count;
                ch.count += 1;
                let (kind, topic) = (ch.kind, ch.rec.topic.clone());
                self.message(kind, &topic, cur.buf)
                    .map_err(|e| (Some(format!("topic '{topic}', message {index}")), e))?;
            }
            op::METADATA => {
                let name = cur.string().map_err(plain)?;
                let map = cur.map().map_err(plain)?;
                if name == METADATA_NAME {
                    self.metadata = Some(map);
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn message(&mut self, kind: Kind, topic: &str, data: &[u8]) -> Result<(), String> {
        fn dec<M: RosMessage>(data: &[u8]) -> Result<M, String> {
            ros2::decode::<M>(data).map_err(|e| format!("{}: {e}", M::NAME))
        }
        match kind {
            Kind::Ignored => {}
            Kind::JointState => {
                let m: ros2::JointState = dec(data)?;
                let n = m.name.len();
                if m.position.len() != n {
                    return Err(format!("{} positions for {n} names", m.position.len()));
                }
                for (what, v) in [("velocities", &m.velocity), ("efforts", &m.effort)] {
                    if !v.is_empty() && v.len() != n {
                        return Err(format!("{} {what} for {n} names", v.len()));
                    }
                }
                stamp_nanos(&m.header.stamp)?;
                if !self.joint_states.contains_key(topic) {
                    self.joint_state_topics.push(topic.to_string());
                }
                self.joint_states
                    .entry(topic.to_string())
                    .or_default()
                    .push(m);
            }
            Kind::Tf | Kind::TfStatic => {
                let m: ros2::TfMessage = dec(data)?;
                for ts in m.transforms {
                    let ns = stamp_nanos(&ts.header.stamp)?;
                    let t = from_msg(ts);
                    if kind == Kind::Tf {
                        self.tf.push((ns, t));
                    } else if let Some(old) = self.static_tf.iter_mut().find(|o| o.child == t.child)
                    {
                        *old = t;
                    } else {
                        self.static_tf.push(t);
                    }
                }
            }
            Kind::RobotDescription => {
                let m: ros2::StringMsg = dec(data)?;
                self.robot_description = Some(m.data);
            }
            Kind::Cloud => {
                let m: ros2::PointCloud2 = dec(data)?;
                let ns = stamp_nanos(&m.header.stamp)?;
                self.clouds.push((ns, cloud_from_msg(&m)?));
            }
            Kind::TorqueCheck => {
                let m: ros2::DiagnosticArray = dec(data)?;
                stamp_nanos(&m.header.stamp)?;
                let rows = m
                    .status
                    .iter()
                    .map(torque_row)
                    .collect::<Result<Vec<_>, _>>()?;
                self.torque_check = Some(rows);
            }
            Kind::Collisions => {
                let m: ros2::DiagnosticArray = dec(data)?;
                let ns = stamp_nanos(&m.header.stamp)?;
                for s in &m.status {
                    let get = |k: &str| {
                        s.value(k)
                            .map(str::to_string)
                            .ok_or_else(|| format!("status '{}': no value '{k}'", s.name))
                    };
                    self.collisions.push((
                        ns,
                        CollisionEvent {
                            t: 0.0,
                            body_a: get("body_a")?,
                            body_b: get("body_b")?,
                        },
                    ));
                }
            }
            Kind::Obstacles => {
                let m: ros2::MarkerArray = dec(data)?;
                self.obstacles = Some(obstacles::from_message(&m));
            }
        }
        Ok(())
    }

    fn into_recording(mut self, file: &Path) -> Result<Recording, RecordError> {
        let meta = self.metadata.take().unwrap_or_default();
        let bad_meta = |key: &str, e: String| {
            RecordError::malformed(file, format!("metadata '{METADATA_NAME}', key '{key}'"), e)
        };
        // Joint states: /joint_states, else the first topic that has them.
        let topic = if self.joint_states.contains_key(TOPIC_JOINT_STATES) {
            Some(TOPIC_JOINT_STATES.to_string())
        } else {
            self.joint_state_topics.first().cloned()
        };
        let states = topic
            .as_ref()
            .and_then(|t| self.joint_states.remove(t))
            .unwrap_or_default();
        let joint_names = match (states.first(), meta.get(KEY_JOINT_NAMES)) {
            (Some(first), _) => first.name.clone(),
            (None, Some(json)) => serde_json::from_str::<Vec<String>>(json)
                .map_err(|e| bad_meta(KEY_JOINT_NAMES, e.to_string()))?,
            (None, None) => Vec::new(),
        };
        {
            let mut seen = std::collections::HashSet::new();
            if let Some(dup) = joint_names.iter().find(|n| !seen.insert(n.as_str())) {
                let ctx = match &topic {
                    Some(t) => format!("topic '{t}', message 0"),
                    None => format!("metadata '{METADATA_NAME}'"),
                };
                return Err(RecordError::malformed(
                    file,
                    ctx,
                    format!("joint '{dup}' listed twice"),
                ));
            }
        }
        let mut frames: Vec<(u64, Frame)> = Vec::with_capacity(states.len());
        let index: HashMap<&str, usize> = joint_names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.as_str(), i))
            .collect();
        let n = joint_names.len();
        let epoch = match meta.get(KEY_EPOCH) {
            Some(text) => Some(
                text.trim()
                    .parse::<u64>()
                    .map_err(|e| bad_meta(KEY_EPOCH, format!("'{text}': {e}")))?,
            ),
            None => self.earliest_stamp(&states),
        };
        let seconds = |ns: u64| seconds_after(ns, epoch.unwrap_or(0));
        let mut filled_left = self.budget.as_ref().map_or(usize::MAX, |b| b.filled);
        for (k, m) in states.iter().enumerate() {
            // Validated when read.
            let ns = stamp_nanos(&m.header.stamp).unwrap_or(0);
            let prev = frames.last().map(|(_, f)| f);
            let frame = if m.name == joint_names {
                Frame {
                    t: seconds(ns),
                    q: m.position.clone(),
                    qd: m.velocity.clone(),
                    tau: m.effort.clone(),
                    tf: Vec::new(),
                }
            } else {
                // Joints the message lacks are filled in: bounded, as that multiplies data.
                let arrays = [&m.position, &m.velocity, &m.effort]
                    .iter()
                    .filter(|v| !v.is_empty())
                    .count();
                let present = m
                    .name
                    .iter()
                    .filter(|name| index.contains_key(name.as_str()))
                    .count();
                filled_left = filled_left
                    .checked_sub(n.saturating_sub(present).saturating_mul(arrays))
                    .ok_or_else(|| {
                        RecordError::malformed(
                            file,
                            format!("topic '{}', message {k}", topic.as_deref().unwrap_or("")),
                            "too many partial joint states to expand for a file of this size",
                        )
                    })?;
                let pick = |vals: &[f64], prev: Option<&Vec<f64>>| -> Vec<f64> {
                    if vals.is_empty() {
                        return Vec::new();
                    }
                    let mut out: Vec<f64> = (0..n)
                        .map(|i| prev.and_then(|p| p.get(i)).copied().unwrap_or(f64::NAN))
                        .collect();
                    for (name, v) in m.name.iter().zip(vals) {
                        if let Some(slot) = index.get(name.as_str()).and_then(|&i| out.get_mut(i)) {
                            *slot = *v;
                        }
                    }
                    out
                };
                Frame {
                    t: seconds(ns),
                    q: pick(&m.position, prev.map(|f| &f.q)),
                    qd: pick(&m.velocity, prev.map(|f| &f.qd)),
                    tau: pick(&m.effort, prev.map(|f| &f.tau)),
                    tf: Vec::new(),
                }
            };
            frames.push((ns, frame));
        }
        frames.sort_by_key(|(ns, _)| *ns);
        // Transforms onto the nearest frame, or frames of their own.
        if frames.is_empty() {
            let mut by_time: BTreeMap<u64, Vec<Transform>> = BTreeMap::new();
            for (ns, t) in self.tf.drain(..) {
                push_tf(by_time.entry(ns).or_default(), t);
            }
            frames = by_time
                .into_iter()
                .map(|(ns, tf)| {
                    (
                        ns,
                        Frame {
                            t: seconds(ns),
                            tf,
                            ..Frame::default()
                        },
                    )
                })
                .collect();
        } else {
            for (ns, t) in self.tf.drain(..) {
                let i = frames.partition_point(|(f, _)| *f < ns);
                let nearest = match (i.checked_sub(1), frames.get(i)) {
                    (Some(before), Some((after_ns, _))) => {
                        let before_ns = frames.get(before).map_or(0, |(b, _)| *b);
                        if ns - before_ns <= after_ns - ns {
                            before
                        } else {
                            i
                        }
                    }
                    (Some(before), None) => before,
                    (None, _) => 0,
                };
                if let Some((_, f)) = frames.get_mut(nearest) {
                    push_tf(&mut f.tf, t);
                }
            }
        }
        // Effort limits: metadata, else the URDF, else none.
        let mut effort_limits = vec![None; n];
        if let Some(json) = meta.get(KEY_EFFORT_LIMITS) {
            let v: Vec<Option<String>> = serde_json::from_str(json)
                .map_err(|e| bad_meta(KEY_EFFORT_LIMITS, e.to_string()))?;
            if v.len() == n {
                for (slot, s) in effort_limits.iter_mut().zip(v) {
                    *slot = match s {
                        Some(s) => Some(
                            s.parse::<f64>()
                                .map_err(|e| bad_meta(KEY_EFFORT_LIMITS, format!("'{s}': {e}")))?,
                        ),
                        None => None,
                    };
                }
            }
        } else if let Some(urdf) = &self.robot_description {
            if let Ok(spec) = crate::model::urdf::parse(urdf, TOPIC_ROBOT_DESCRIPTION) {
                for (slot, name) in effort_limits.iter_mut().zip(&joint_names) {
                    *slot = spec
                        .joints
                        .iter()
                        .find(|j| &j.name == name)
                        .map(|j| j.limits.effort)
                        .filter(|e| e.is_finite());
                }
            }
        }
        let name = meta.get(KEY_NAME).cloned().unwrap_or_else(|| {
            file.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
        let metadata = meta
            .into_iter()
            .filter(|(k, _)| {
                ![KEY_NAME, KEY_JOINT_NAMES, KEY_EFFORT_LIMITS, KEY_EPOCH].contains(&k.as_str())
            })
            .collect();

        Ok(Recording {
            header: Header {
                name,
                joint_names,
                effort_limits,
                static_tf: self.static_tf,
                robot_description: self.robot_description,
                metadata,
                epoch_ns: epoch,
            },
            frames: frames.into_iter().map(|(_, f)| f).collect(),
            clouds: self
                .clouds
                .into_iter()
                .map(|(ns, c)| PointCloud {
                    t: seconds(ns),
                    ..c
                })
                .collect(),
            torque_check: self.torque_check.unwrap_or_default(),
            collisions: self
                .collisions
                .into_iter()
                .map(|(ns, e)| CollisionEvent {
                    t: seconds(ns),
                    ..e
                })
                .collect(),
            obstacles: self.obstacles.unwrap_or_default(),
        })
    }

    /// The earliest stamp of a joint state (of `states`), transform, cloud or collision.
    fn earliest_stamp(&self, states: &[ros2::JointState]) -> Option<u64> {
        let js = states
            .iter()
            .filter_map(|m| stamp_nanos(&m.header.stamp).ok());
        js.chain(self.tf.iter().map(|(ns, _)| *ns))
            .chain(self.clouds.iter().map(|(ns, _)| *ns))
            .chain(self.collisions.iter().map(|(ns, _)| *ns))
            .min()
    }
}

/// Adds `t` to a frame's transforms, replacing one with the same child frame.
fn push_tf(tf: &mut Vec<Transform>, t: Transform) {
    match tf.iter_mut().find(|o| o.child == t.child) {
        Some(old) => *old = t,
        None => tf.push(t),
    }
}

/// Seconds from `epoch` to `ns` (both in ns; negative before the epoch), exact to the
/// nanosecond before the conversion to `f64`.
fn seconds_after(ns: u64, epoch: u64) -> f64 {
    (i128::from(ns) - i128::from(epoch)) as f64 / 1e9
}
