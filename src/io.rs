//! File input and output at the program's edge. Reads accept only regular files of a
//! bounded size, so a path that names a device, a FIFO or a directory (`/dev/zero`, a
//! scenario's `model.file` pointing anywhere) is refused instead of read forever. Writes
//! never leave a half-written file: write to a temporary file in the same directory, flush
//! it to disk, then rename it over the target.

use std::io::{Read, Write};
use std::path::Path;

/// Largest input file armsim reads (models, scenarios, meshes, recordings): 2 GiB.
pub const MAX_INPUT_BYTES: u64 = 2 << 30;

/// Reads a whole input file, refusing anything but a regular file of at most
/// [`MAX_INPUT_BYTES`] (symbolic links are followed).
pub fn read_input(path: &Path) -> std::io::Result<Vec<u8>> {
    // Metadata before opening: opening a FIFO for reading would block until a writer came.
    let meta = std::fs::metadata(path)?;
    let refuse = |msg: String| Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, msg));
    if !meta.is_file() {
        return refuse(if meta.is_dir() {
            "is a directory".into()
        } else {
            "not a regular file (a device, FIFO or socket)".into()
        });
    }
    if meta.len() > MAX_INPUT_BYTES {
        return refuse(format!(
            "{} bytes: larger than the {} byte input limit",
            meta.len(),
            MAX_INPUT_BYTES
        ));
    }
    let file = std::fs::File::open(path)?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(MAX_INPUT_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return refuse("grew past the input limit while being read".into());
    }
    Ok(bytes)
}

/// [`read_input`] as UTF-8 text.
pub fn read_input_string(path: &Path) -> std::io::Result<String> {
    String::from_utf8(read_input(path)?).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

/// Writes `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "no file name"))?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
