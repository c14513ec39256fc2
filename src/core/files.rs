//! File input and output at the program's edge. Reads accept only regular files of a
//! bounded size, so a path that names a device, a FIFO or a directory (`/dev/zero`, a
//! scenario's `model.file` pointing anywhere) is refused instead of read forever, and a
//! file above its kind's size budget is refused from its metadata, before any of it is
//! read: text inputs (models, SRDF, scenarios, YAML) [`MAX_TEXT_BYTES`], meshes
//! [`MAX_MESH_BYTES`], recordings [`MAX_INPUT_BYTES`]. Writes
//! never leave a half-written file: write to a temporary file in the same directory, flush
//! it to disk, then rename it over the target.

use std::io::{Read, Write};
use std::path::Path;

/// Largest input file armsim reads at all (recordings): 2 GiB.
pub const MAX_INPUT_BYTES: u64 = 2 << 30;

/// Largest text input (URDF, DH table, SRDF, scenario, MoveIt YAML): 64 MiB. The largest
/// URDF of the ecosystem sweeps is under 1 MiB; the parsers hold a few copies of the text.
pub const MAX_TEXT_BYTES: u64 = 64 << 20;

/// Largest mesh file (STL, OBJ, DAE): 256 MiB (a binary STL of 5 million triangles).
pub const MAX_MESH_BYTES: u64 = 256 << 20;

/// Reads a whole input file, refusing anything but a regular file of at most
/// [`MAX_INPUT_BYTES`] (symbolic links are followed).
pub fn read_input(path: &Path) -> std::io::Result<Vec<u8>> {
    read_input_max(path, MAX_INPUT_BYTES)
}

/// A size in bytes for messages: `67108864 bytes (64 MiB)`.
fn bytes_text(n: u64) -> String {
    if n >= 1 << 20 {
        format!("{n} bytes ({} MiB)", n >> 20)
    } else {
        format!("{n} bytes")
    }
}

/// [`read_input`] with the size budget `max` (in bytes): a larger file is refused from
/// its metadata before it is opened, with a message giving both sizes.
pub fn read_input_max(path: &Path, max: u64) -> std::io::Result<Vec<u8>> {
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
    if meta.len() > max {
        return refuse(format!(
            "{}: larger than the {} limit for this kind of input",
            bytes_text(meta.len()),
            bytes_text(max)
        ));
    }
    let file = std::fs::File::open(path)?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max {
        return refuse(format!(
            "grew past the {} limit while being read",
            bytes_text(max)
        ));
    }
    Ok(bytes)
}

/// A text input (model, SRDF, scenario, YAML) as UTF-8, at most [`MAX_TEXT_BYTES`].
pub fn read_input_string(path: &Path) -> std::io::Result<String> {
    read_input_string_max(path, MAX_TEXT_BYTES)
}

/// [`read_input_max`] as UTF-8 text.
pub fn read_input_string_max(path: &Path, max: u64) -> std::io::Result<String> {
    String::from_utf8(read_input_max(path, max)?).map_err(|_| {
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
