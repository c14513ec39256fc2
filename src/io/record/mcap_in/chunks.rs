//! A scan of the file's uncompressed chunks before the `mcap` crate reads them: an inner
//! record that runs past its chunk's end is an error here, not an overflow there.

use crate::io::record::mcap_in::cursor::Cursor;
use crate::io::record::mcap_in::record_fault::RecordFault;

/// MCAP magic (start and end of a file).
const MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// Record opcodes this module looks for before the `mcap` crate reads the file.
const OP_FOOTER: u8 = 0x02;
pub(super) const OP_CHUNK: u8 = 0x06;

/// Finds the records of uncompressed chunks that run past their chunk's end, before the
/// `mcap` crate's linear reader sees them: mcap 0.26 subtracts such a record's length from
/// what is left of the chunk without a check (`linear_reader.rs:745`), which panics with
/// overflow checks and, without them, wraps and reads the records after the chunk as
/// chunk content (found by the `mcap_reader` fuzz target). Anything else that is
/// inconsistent ends this scan quietly and is left to the reader's own errors. The reader
/// streams, so a chunk cut short by the end of the file is checked as far as it goes.
/// Returns the record number and the message.
pub(super) fn check_uncompressed_chunks(bytes: &[u8]) -> Result<(), (usize, RecordFault)> {
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
fn check_chunk_records(body: &[u8]) -> Result<(), RecordFault> {
    let mut c = Cursor { buf: body };
    let header = (|| {
        c.take(8 + 8 + 8 + 4)?;
        let n = c.len32()?;
        let compression = c.take(n)?;
        let size = c.u64()?;
        Ok::<_, RecordFault>((compression.is_empty(), size))
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
            return Err(RecordFault::ChunkOverrun {
                at,
                size,
                len,
                left: left.saturating_sub(9),
            });
        }
        at += 9 + len;
    }
    Ok(())
}
