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

mod assemble;
mod chunks;
mod collected;
mod cursor;
pub mod record_fault;
mod records;
use crate::io::record::mcap_in::chunks::{check_uncompressed_chunks, OP_CHUNK};
use crate::io::record::mcap_in::collected::{Budget, Collected};
use crate::io::record::record_error::RecordError;
use crate::io::record::Recording;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use std::path::Path;

/// Smallest limit on one record inside a compressed chunk.
const MIN_RECORD_LIMIT: usize = 64 << 20;
/// Largest limit on one record inside a compressed chunk.
const MAX_RECORD_LIMIT: usize = 1 << 30;
/// Reads an MCAP file into a [`Recording`] (see the module docs).
pub fn read_mcap(path: &Path) -> Result<Recording, RecordError> {
    let bytes = crate::core::files::read_input(path).map_err(|e| RecordError::io(path, e))?;
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

fn read_inner(bytes: &[u8], file: &Path) -> Result<Recording, RecordError> {
    check_uncompressed_chunks(bytes).map_err(|(record, fault)| {
        RecordError::record(
            file,
            format!("record {record} (opcode {OP_CHUNK:#04x})"),
            fault,
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
            .with_validate_chunk_crcs(true)
            // The data and summary sections' CRCs (0: not computed), and nothing after the
            // closing magic: a flipped byte outside a chunk or appended garbage is refused.
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true),
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
                c.record(opcode, data).map_err(|(ctx, fault)| {
                    let ctx =
                        ctx.unwrap_or_else(|| format!("record {record} (opcode {opcode:#04x})"));
                    RecordError::record(file, ctx, fault)
                })?;
            }
        }
    }
    c.into_recording(file)
}
