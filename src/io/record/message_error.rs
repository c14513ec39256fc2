//! [`MessageError`]: why a decoded ROS 2 message of a recording cannot be read into the
//! recording's values (a bad stamp, a point cloud whose layout does not fit its data, a
//! diagnostic status without its numbers, joint arrays of different lengths). The MCAP
//! reader adds the file, the topic and the message index.

use crate::io::record::ros2::CdrError;

/// A message that decodes but does not make sense, or does not decode.
#[derive(Debug, thiserror::Error)]
pub enum MessageError {
    /// The CDR payload does not decode as the channel's message type.
    #[error("{message_type}: {source}")]
    Decode {
        /// The ROS 2 type name (`sensor_msgs/msg/JointState`).
        message_type: &'static str,
        /// The decoder's error.
        source: CdrError,
    },
    /// A stamp's `nanosec` is not below one second.
    #[error("time stamp nanosec {0} ≥ 1e9")]
    StampNanosec(u32),
    /// A stamp before the Unix epoch.
    #[error("time stamp before the epoch ({0} s)")]
    StampBeforeEpoch(i32),
    /// A point field with a datatype ROS 2 does not define.
    #[error("field '{name}': unknown datatype {datatype}")]
    UnknownDatatype {
        /// The field.
        name: String,
        /// Its datatype code.
        datatype: u8,
    },
    /// A point field that runs past the point step.
    #[error("field '{name}' (offset {offset}, {size} bytes) does not fit the point step {step}")]
    FieldOutsidePoint {
        /// The field.
        name: String,
        /// Its offset in the point.
        offset: u32,
        /// Its size in bytes.
        size: usize,
        /// The point step.
        step: usize,
    },
    /// A coordinate field (`x`, `y`, `z`) is missing.
    #[error("no field '{0}'")]
    NoField(String),
    /// A coordinate field that is neither float32 nor float64.
    #[error("field '{name}' has datatype {datatype} (expected FLOAT32 or FLOAT64)")]
    CoordinateType {
        /// The field.
        name: String,
        /// Its datatype code.
        datatype: u8,
    },
    /// `width × point_step` does not fit in memory sizes.
    #[error("width × point_step overflows")]
    RowOverflow,
    /// Rows shorter than their points.
    #[error("row_step {row_step} is shorter than width × point_step = {row_len}")]
    RowStepShort {
        /// The declared row step.
        row_step: usize,
        /// `width × point_step`.
        row_len: usize,
    },
    /// The cloud's size does not fit in memory sizes.
    #[error("cloud size overflows")]
    CloudOverflow,
    /// The data is shorter than the points it declares.
    #[error("{width}×{height} points of {step} bytes need {need} bytes, the data has {have}")]
    DataShort {
        /// Points per row.
        width: usize,
        /// Rows.
        height: usize,
        /// The point step.
        step: usize,
        /// The bytes the points need.
        need: usize,
        /// The bytes there are.
        have: usize,
    },
    /// A point whose values lie outside the data.
    #[error("point {0} lies outside the data")]
    PointOutside(usize),
    /// A diagnostic value that is not a number.
    #[error("status '{status}': {key} = '{value}': {source}")]
    NotANumber {
        /// The status (joint) name.
        status: String,
        /// The key.
        key: String,
        /// The value as written.
        value: String,
        /// The parse error.
        source: std::num::ParseFloatError,
    },
    /// A diagnostic status without a value it needs.
    #[error("status '{status}': no value '{key}'")]
    MissingValue {
        /// The status name.
        status: String,
        /// The key.
        key: String,
    },
    /// A joint state's arrays of different lengths.
    #[error("{count} {what} for {names} names")]
    JointArrays {
        /// How many values there are.
        count: usize,
        /// `positions`, `velocities` or `efforts`.
        what: &'static str,
        /// How many names there are.
        names: usize,
    },
}
