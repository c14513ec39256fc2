//! A bounds-checked little-endian reader over one record's bytes: every length is
//! checked against the bytes left before anything is taken or allocated.

use crate::io::record::mcap_in::record_fault::RecordFault;
use std::collections::BTreeMap;

/// A bounds-checked little-endian reader over one record.
pub(super) struct Cursor<'a> {
    pub(super) buf: &'a [u8],
}

impl<'a> Cursor<'a> {
    pub(super) fn take(&mut self, n: usize) -> Result<&'a [u8], RecordFault> {
        if n > self.buf.len() {
            return Err(RecordFault::Overrun {
                n,
                left: self.buf.len(),
            });
        }
        let (head, tail) = self.buf.split_at(n);
        self.buf = tail;
        Ok(head)
    }

    pub(super) fn array<const N: usize>(&mut self) -> Result<[u8; N], RecordFault> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N)?);
        Ok(a)
    }

    pub(super) fn u16(&mut self) -> Result<u16, RecordFault> {
        Ok(u16::from_le_bytes(self.array()?))
    }

    pub(super) fn u32(&mut self) -> Result<u32, RecordFault> {
        Ok(u32::from_le_bytes(self.array()?))
    }

    pub(super) fn u64(&mut self) -> Result<u64, RecordFault> {
        Ok(u64::from_le_bytes(self.array()?))
    }

    pub(super) fn len32(&mut self) -> Result<usize, RecordFault> {
        Ok(usize::try_from(self.u32()?)?)
    }

    pub(super) fn string(&mut self) -> Result<String, RecordFault> {
        let n = self.len32()?;
        let b = self.take(n)?;
        String::from_utf8(b.to_vec()).map_err(|_| RecordFault::NotUtf8)
    }

    pub(super) fn map(&mut self) -> Result<BTreeMap<String, String>, RecordFault> {
        let n = self.len32()?;
        let mut inner = Cursor { buf: self.take(n)? };
        let mut m = BTreeMap::new();
        while !inner.buf.is_empty() {
            let k = inner.string()?;
            let v = inner.string()?;
            if m.contains_key(&k) {
                return Err(RecordFault::DuplicateKey(k));
            }
            m.insert(k, v);
        }
        Ok(m)
    }
}
