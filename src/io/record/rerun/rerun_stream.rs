//! A Rerun recording stream for a [`RerunSink`]: the sink checked before any work
//! ([`check_sink`]), the stream opened in memory or to a spawned viewer ([`open`]), and
//! finished ([`finish`]: the `.rrd` written atomically, or the viewer flushed).

use crate::io::record::rerun::rerun_entities::sdk;
use crate::io::record::rerun::rerun_sink::{RerunError, RerunSink, APP_ID};
use rerun::{RecordingStream, RecordingStreamBuilder};
use std::path::Path;

/// Refuses a sink that cannot be written before any work: a save path that is not a file
/// name, is a directory, or lies in a missing directory.
pub(super) fn check_sink(sink: &RerunSink) -> Result<(), RerunError> {
    if let RerunSink::Save(p) = sink {
        let out = |msg: String| RerunError::Output {
            path: p.clone(),
            msg,
        };
        if p.file_name().is_none() {
            return Err(out("not a file name".into()));
        }
        if p.is_dir() {
            return Err(out("is a directory".into()));
        }
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            return Err(out(format!("directory '{}' does not exist", dir.display())));
        }
    }
    Ok(())
}

/// The in-memory storage of a stream that is saved (`None` for a spawned viewer).
pub(super) type Storage = Option<rerun::sink::MemorySinkStorage>;

/// Opens a stream named `name` for `sink` (in memory to save, or to a spawned viewer),
/// with only the `time` timeline.
pub(super) fn open(sink: &RerunSink, name: &str) -> Result<(RecordingStream, Storage), RerunError> {
    let b = RecordingStreamBuilder::new(APP_ID)
        .enabled(true)
        .recording_name(name);
    match sink {
        RerunSink::Save(_) => b.memory().map(|(s, st)| (s, Some(st))).map_err(sdk),
        RerunSink::Spawn => b
            .spawn()
            .map(|s| (s, None))
            .map_err(|e| RerunError::Viewer(format!("{e} (is `rerun` on PATH?)"))),
    }
    .inspect(|(s, _)| {
        // Only the `time` timeline: no log_tick / log_time columns.
        s.set_log_tick_enabled(false);
        s.set_log_time_enabled(false);
    })
}

/// Finishes the stream: writes the `.rrd` atomically (its size returned) or flushes the
/// viewer.
pub(super) fn finish(
    stream: &RecordingStream,
    storage: Storage,
    sink: &RerunSink,
) -> Result<Option<u64>, RerunError> {
    match (sink, storage) {
        (RerunSink::Save(p), Some(st)) => {
            let bytes = st.drain_as_bytes().map_err(sdk)?;
            crate::core::files::write_atomic(p, &bytes).map_err(|e| RerunError::Output {
                path: p.clone(),
                msg: format!("cannot write: {e}"),
            })?;
            Ok(Some(bytes.len() as u64))
        }
        _ => {
            stream
                .flush_blocking()
                .map_err(|e| RerunError::Viewer(e.to_string()))?;
            Ok(None)
        }
    }
}
