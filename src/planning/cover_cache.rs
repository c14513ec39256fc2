//! Sphere covers of mesh files, and allowed-collision matrices, kept on disk between
//! runs, so that a robot's set-up pays for them once per machine. A cover is stored under a key
//! made of the mesh file's bytes (FNV-1a hash and length), the scale, the overshoot and [`VERSION`]
//! (raised when the cover algorithm changes); a file that is missing, unreadable or malformed is
//! ignored and the cover computed again.
//!
//! The folder is `$ARMSIM_CACHE_DIR`, else `$XDG_CACHE_HOME/armsim`, else
//! `$HOME/.cache/armsim`; `ARMSIM_NO_CACHE=1` turns the cache off. Files are written
//! atomically.

use std::path::PathBuf;

/// Raised when the cover algorithm changes, so old files are not read.
// 3: the mesh readers refuse what they once read (DAE units, strides, partial triangle
// lists, issue 28): covers computed from such files by older builds must not be served.
// 4: a cover's note carries the DAE reader's warnings (an `<instance_geometry>` naming no
// geometry), which covers stored by older builds lack.
const VERSION: u32 = 4;

/// Most spheres a stored cover may have (a larger file is ignored).
const MAX_SPHERES: usize = 1_000_000;

/// The cache folder, or `None` when it is turned off or no folder is known.
fn dir() -> Option<PathBuf> {
    if std::env::var_os("ARMSIM_NO_CACHE").is_some_and(|v| v != "0") {
        return None;
    }
    if let Some(d) = std::env::var_os("ARMSIM_CACHE_DIR") {
        return Some(PathBuf::from(d));
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
        return Some(PathBuf::from(d).join("armsim"));
    }
    std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache").join("armsim"))
}

/// The file of a cover of the mesh `bytes`.
fn file(bytes: &[u8], scale: [f64; 3], delta: f64) -> Option<PathBuf> {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |b: u8| {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    };
    for &b in bytes {
        eat(b);
    }
    for x in scale.iter().chain([&delta]) {
        for b in x.to_bits().to_le_bytes() {
            eat(b);
        }
    }
    for b in VERSION.to_le_bytes() {
        eat(b);
    }
    Some(dir()?.join(format!("cover-{h:016x}-{}.txt", bytes.len())))
}

/// A cover: spheres `(centre, radius)` and a note.
pub type StoredCover = (Vec<([f64; 3], f64)>, Option<String>);

/// A stored cover of the mesh `bytes`, if there is a valid one.
pub fn load(bytes: &[u8], scale: [f64; 3], delta: f64) -> Option<StoredCover> {
    let text = std::fs::read_to_string(file(bytes, scale, delta)?).ok()?;
    let mut lines = text.lines();
    if lines.next()? != format!("armsim-cover {VERSION}") {
        return None;
    }
    let note = lines.next()?;
    let note = (!note.is_empty()).then(|| note.to_string());
    let mut spheres = Vec::new();
    for line in lines {
        let v: Vec<f64> = line
            .split(' ')
            .map(|x| x.parse().ok())
            .collect::<Option<_>>()?;
        let ok = v.len() == 4 && v.iter().all(|x| x.is_finite()) && v[3] > 0.0;
        if !ok || spheres.len() >= MAX_SPHERES {
            return None;
        }
        spheres.push(([v[0], v[1], v[2]], v[3]));
    }
    (!spheres.is_empty()).then_some((spheres, note))
}

/// Stores a cover (errors are ignored: the cache only saves time).
pub fn store(
    bytes: &[u8],
    scale: [f64; 3],
    delta: f64,
    spheres: &[([f64; 3], f64)],
    note: Option<&str>,
) {
    let Some(path) = file(bytes, scale, delta) else {
        return;
    };
    let mut text = format!(
        "armsim-cover {VERSION}\n{}\n",
        note.unwrap_or("").replace('\n', " ")
    );
    for (c, r) in spheres {
        text += &format!("{} {} {} {}\n", c[0], c[1], c[2], r);
    }
    if let Some(d) = path.parent() {
        let _ = std::fs::create_dir_all(d);
    }
    let _ = crate::core::files::write_atomic(&path, text.as_bytes());
}

/// FNV-1a over `parts`, each followed by its length.
pub fn fingerprint<'a>(parts: impl IntoIterator<Item = &'a [u8]>) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &b in part.iter().chain(&(part.len() as u64).to_le_bytes()) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

/// The text stored under `name` (a file name in the cache folder), if any.
pub fn load_text(name: &str) -> Option<String> {
    std::fs::read_to_string(dir()?.join(name)).ok()
}

/// Stores `text` under `name` (errors are ignored: the cache only saves time).
pub fn store_text(name: &str, text: &str) {
    let Some(d) = dir() else {
        return;
    };
    let _ = std::fs::create_dir_all(&d);
    let _ = crate::core::files::write_atomic(&d.join(name), text.as_bytes());
}
