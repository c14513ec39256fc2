//! [`RecordFault`]: what the MCAP reader's own checks find wrong in one record (a length
//! past the record's end, a text that is not UTF-8, a schema or channel that is missing
//! or redefined, a chunk whose records overrun it, a message budget spent) or in the
//! message it carries ([`MessageError`]). [`crate::io::record::record_error::RecordError`]
//! adds the file and which record or message.

use crate::io::record::message_error::MessageError;

/// A malformed record or message.
#[derive(Debug, thiserror::Error)]
pub enum RecordFault {
    /// A length field that runs past the record's end.
    #[error("length {n} exceeds the {left} bytes left in the record")]
    Overrun {
        /// The declared length.
        n: usize,
        /// The bytes left in the record.
        left: usize,
    },
    /// A length that does not fit this machine's sizes.
    #[error("{0}")]
    Length(#[from] std::num::TryFromIntError),
    /// A string field that is not UTF-8.
    #[error("string is not UTF-8")]
    NotUtf8,
    /// A map field with a key twice.
    #[error("duplicate key '{0}' in a map")]
    DuplicateKey(String),
    /// An uncompressed chunk whose inner record runs past the chunk's records.
    #[error(
        "chunk: the record at byte {at} of its {size} bytes of records declares {len} bytes of content, more than the {left} left"
    )]
    ChunkOverrun {
        /// The inner record's offset in the chunk's records.
        at: u64,
        /// The size of the chunk's records.
        size: u64,
        /// The inner record's declared content length.
        len: u64,
        /// The bytes of content left after its header.
        left: u64,
    },
    /// A schema record with the reserved id 0.
    #[error("schema id 0 is reserved")]
    SchemaIdZero,
    /// A schema id defined twice, differently.
    #[error("schema {0} redefined differently")]
    SchemaRedefined(u16),
    /// A channel whose schema was not defined before it.
    #[error("channel '{topic}' refers to schema {schema}, not defined before it")]
    UnknownSchema {
        /// The channel's topic.
        topic: String,
        /// The schema id it names.
        schema: u16,
    },
    /// A channel id defined twice, differently.
    #[error("channel {0} redefined differently")]
    ChannelRedefined(u16),
    /// More messages than the file's size allows.
    #[error("more messages than a file of this size can hold")]
    TooManyMessages,
    /// More message payload than the file's size allows.
    #[error("the messages decompress to more data than a file of this size can hold")]
    TooMuchPayload,
    /// A message on a channel not defined before it.
    #[error("message on channel {0}, not defined before it")]
    UnknownChannel(u16),
    /// The message the record carries cannot be read.
    #[error(transparent)]
    Message(#[from] MessageError),
}
