//! [`RecordError`]: the errors of the MCAP writer and reader, each naming the file.

use crate::io::record::mcap_in::record_fault::RecordFault;
use std::path::PathBuf;

/// A recording could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The file (or its temporary sibling) could not be created, written or renamed.
    #[error("{}: {source}", file.display())]
    Io {
        /// The recording file.
        file: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The MCAP layer failed: a write error, or a malformed MCAP file.
    #[error("{}: MCAP: {source}", file.display())]
    Mcap {
        /// The recording file.
        file: PathBuf,
        /// The error of the `mcap` crate.
        source: mcap::McapError,
    },
    /// What was asked to be written cannot be (wrong lengths, bad times, ...).
    #[error("{}: {message}", file.display())]
    Invalid {
        /// The recording file.
        file: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A record or message of the file is malformed (found by the reader's own checks).
    #[error("{}: {context}: {fault}", file.display())]
    Record {
        /// The recording file.
        file: PathBuf,
        /// Where: `topic '/tf', message 12` or `record 3 (opcode 0x06)`.
        context: String,
        /// What is wrong.
        #[source]
        fault: Box<RecordFault>,
    },
    /// A record or message of the file is malformed.
    #[error("{}: {context}: {message}", file.display())]
    Malformed {
        /// The recording file.
        file: PathBuf,
        /// Where: `topic '/tf', message 12` or `record 3 (channel)`.
        context: String,
        /// What is wrong.
        message: String,
    },
}

impl RecordError {
    pub(crate) fn io(file: impl Into<PathBuf>, source: std::io::Error) -> Self {
        RecordError::Io {
            file: file.into(),
            source,
        }
    }

    pub(crate) fn mcap(file: impl Into<PathBuf>, source: mcap::McapError) -> Self {
        RecordError::Mcap {
            file: file.into(),
            source,
        }
    }

    pub(crate) fn invalid(file: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        RecordError::Invalid {
            file: file.into(),
            message: message.into(),
        }
    }

    pub(crate) fn record(
        file: impl Into<PathBuf>,
        context: impl Into<String>,
        fault: RecordFault,
    ) -> Self {
        RecordError::Record {
            file: file.into(),
            context: context.into(),
            fault: Box::new(fault),
        }
    }

    pub(crate) fn malformed(
        file: impl Into<PathBuf>,
        context: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        RecordError::Malformed {
            file: file.into(),
            context: context.into(),
            message: message.into(),
        }
    }
}
