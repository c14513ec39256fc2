//! What every Rerun logger shares: entity paths from unescaped parts ([`path`],
//! [`link_entity`], [`child`]), the SDK's errors as [`RerunError::Sdk`], timed chunks on
//! the [`TIMELINE`], and the `f32` forms of rotations and points Rerun takes.

use crate::core::spatial::{Mat3, Vec3};
use crate::io::record::rerun::rerun_sink::{RerunError, TIMELINE};
use nalgebra::{Rotation3, UnitQuaternion};
use rerun::{EntityPath, EntityPathPart, RecordingStream, TimeColumn};

/// The SDK's error `e` as [`RerunError::Sdk`].
pub(super) fn sdk(e: impl std::fmt::Display) -> RerunError {
    RerunError::Sdk(e.to_string())
}

/// Sends `cols` for `ent` as one chunk on the [`TIMELINE`], one row per time in `times`.
pub(super) fn send_timed(
    stream: &RecordingStream,
    ent: impl Into<EntityPath>,
    times: impl IntoIterator<Item = f64>,
    cols: impl IntoIterator<Item = rerun::SerializedComponentColumn>,
) -> Result<(), RerunError> {
    stream
        .send_columns(ent, [TimeColumn::new_duration_secs(TIMELINE, times)], cols)
        .map_err(sdk)
}

/// `world/robot/<link>`, the link name as one (escaped) path part.
pub fn link_entity(link: &str) -> EntityPath {
    path(&["world", "robot", link])
}

/// An entity path from unescaped parts.
pub fn path(parts: &[&str]) -> EntityPath {
    EntityPath::new(parts.iter().map(|p| EntityPathPart::new(*p)).collect())
}

/// `base` with one more (escaped) path part.
pub(super) fn child(base: &EntityPath, part: &str) -> EntityPath {
    base.join(&EntityPath::new(vec![EntityPathPart::new(part)]))
}

/// The rotation `r` as Rerun's `[x, y, z, w]` quaternion.
pub(super) fn quat_xyzw(r: &Mat3) -> [f32; 4] {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
    [q.i as f32, q.j as f32, q.k as f32, q.w as f32]
}

/// `v` as Rerun's `f32` triple.
pub(super) fn f32x3(v: &Vec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

#[cfg(test)]
mod tests {
    use crate::io::record::rerun::rerun_entities::link_entity;

    #[test]
    fn entity_paths_escape_link_names() {
        assert_eq!(
            link_entity("base_link").to_string(),
            "/world/robot/base_link"
        );
        let odd = link_entity("a/b c");
        assert_eq!(odd.len(), 3);
    }
}
