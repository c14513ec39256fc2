//! Recording values from decoded ROS 2 messages, for `mcap_in`: stamps, transforms,
//! point clouds of any PointCloud2 layout (`x, y, z` as float32 or float64, a scalar field
//! of any numeric type, either byte order, rows with padding), and torque-check rows from
//! diagnostic statuses. Every offset is checked against the data before it is read.

use crate::io::record::mcap_out::CLOUD_SCALAR_FIELD;
use crate::io::record::message_error::MessageError;
use crate::io::record::ros2::{self, datatype, level};
use crate::io::record::{PointCloud, TorqueRow, Transform};

/// A stamp in nanoseconds since the Unix epoch; an error for an invalid `nanosec` or a
/// stamp before 1970.
pub(super) fn stamp_nanos(t: &ros2::Time) -> Result<u64, MessageError> {
    if t.nanosec >= 1_000_000_000 {
        return Err(MessageError::StampNanosec(t.nanosec));
    }
    t.to_nanos().ok_or(MessageError::StampBeforeEpoch(t.sec))
}

/// A transform from its message (stamp dropped).
pub(super) fn from_msg(ts: ros2::TransformStamped) -> Transform {
    let tr = ts.transform.translation;
    let r = ts.transform.rotation;
    Transform {
        parent: ts.header.frame_id,
        child: ts.child_frame_id,
        translation: [tr.x, tr.y, tr.z],
        rotation: [r.x, r.y, r.z, r.w],
    }
}

/// Reads one value of `dt` at `off`; `None` out of bounds or for an unknown datatype.
fn read_value(data: &[u8], off: usize, dt: u8, big_endian: bool) -> Option<f64> {
    let size = datatype::size(dt)?;
    let b = data.get(off..off.checked_add(size)?)?;
    macro_rules! num {
        ($t:ty) => {{
            let a: [u8; std::mem::size_of::<$t>()] = b.try_into().ok()?;
            if big_endian {
                <$t>::from_be_bytes(a) as f64
            } else {
                <$t>::from_le_bytes(a) as f64
            }
        }};
    }
    Some(match dt {
        datatype::INT8 => num!(i8),
        datatype::UINT8 => num!(u8),
        datatype::INT16 => num!(i16),
        datatype::UINT16 => num!(u16),
        datatype::INT32 => num!(i32),
        datatype::UINT32 => num!(u32),
        datatype::FLOAT32 => num!(f32),
        _ => num!(f64),
    })
}

/// A point cloud from its message, stamped at `t = 0` (the reader sets the time).
pub(super) fn cloud_from_msg(m: &ros2::PointCloud2) -> Result<PointCloud, MessageError> {
    let step = m.point_step as usize;
    let field = |name: &str| m.fields.iter().find(|f| f.name == name);
    let check = |f: &ros2::PointField| -> Result<(usize, u8), MessageError> {
        let size = datatype::size(f.datatype).ok_or_else(|| MessageError::UnknownDatatype {
            name: f.name.clone(),
            datatype: f.datatype,
        })?;
        let off = f.offset as usize;
        if off.checked_add(size).is_none_or(|end| end > step) {
            return Err(MessageError::FieldOutsidePoint {
                name: f.name.clone(),
                offset: f.offset,
                size,
                step,
            });
        }
        Ok((off, f.datatype))
    };
    let mut xyz = [(0usize, 0u8); 3];
    for (slot, name) in xyz.iter_mut().zip(["x", "y", "z"]) {
        let f = field(name).ok_or_else(|| MessageError::NoField(name.to_string()))?;
        if f.datatype != datatype::FLOAT32 && f.datatype != datatype::FLOAT64 {
            return Err(MessageError::CoordinateType {
                name: name.to_string(),
                datatype: f.datatype,
            });
        }
        *slot = check(f)?;
    }
    let scalar = match field(CLOUD_SCALAR_FIELD).or_else(|| field("intensity")) {
        Some(f) => Some(check(f)?),
        None => None,
    };
    let (w, h) = (m.width as usize, m.height as usize);
    let row_len = w.checked_mul(step).ok_or(MessageError::RowOverflow)?;
    let row_step = m.row_step as usize;
    if h > 1 && row_step < row_len {
        return Err(MessageError::RowStepShort { row_step, row_len });
    }
    if w > 0 && h > 0 {
        let need = (h - 1)
            .checked_mul(row_step)
            .and_then(|x| x.checked_add(row_len))
            .ok_or(MessageError::CloudOverflow)?;
        if need > m.data.len() {
            return Err(MessageError::DataShort {
                width: w,
                height: h,
                step,
                need,
                have: m.data.len(),
            });
        }
    }
    // Bounded by the data length: every point takes at least 4 bytes of it.
    let count = w.saturating_mul(h);
    let mut points = Vec::with_capacity(count);
    let mut values = Vec::with_capacity(if scalar.is_some() { count } else { 0 });
    let be = m.is_bigendian;
    for r in 0..h {
        for c in 0..w {
            let base = r * row_step + c * step;
            let get = |(off, dt): (usize, u8)| {
                read_value(&m.data, base + off, dt, be).ok_or(MessageError::PointOutside(r * w + c))
            };
            points.push([
                get(xyz[0])? as f32,
                get(xyz[1])? as f32,
                get(xyz[2])? as f32,
            ]);
            if let Some(s) = scalar {
                values.push(get(s)? as f32);
            }
        }
    }
    Ok(PointCloud {
        t: 0.0,
        frame: m.header.frame_id.clone(),
        points,
        values,
    })
}

/// A torque-check row from its status: numbers as text, `none` or absent for no value.
pub(super) fn torque_row(s: &ros2::DiagnosticStatus) -> Result<TorqueRow, MessageError> {
    let opt = |k: &str| -> Result<Option<f64>, MessageError> {
        match s.value(k) {
            None | Some("none") => Ok(None),
            Some(v) => v
                .trim()
                .parse::<f64>()
                .map(Some)
                .map_err(|e| MessageError::NotANumber {
                    status: s.name.clone(),
                    key: k.to_string(),
                    value: v.to_string(),
                    source: e,
                }),
        }
    };
    let num = |k: &str| -> Result<f64, MessageError> {
        opt(k)?.ok_or_else(|| MessageError::MissingValue {
            status: s.name.clone(),
            key: k.to_string(),
        })
    };
    Ok(TorqueRow {
        joint: s.name.clone(),
        peak_torque: num("peak_torque")?,
        rms_torque: num("rms_torque")?,
        peak_speed: num("peak_speed")?,
        peak_power: num("peak_power")?,
        limit: opt("limit")?,
        velocity_limit: opt("velocity_limit")?,
        margin: opt("margin")?,
        ok: s.level == level::OK,
        first_violation: opt("first_violation")?,
    })
}
