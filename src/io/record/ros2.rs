//! The ROS 2 messages armsim records, as serde structs in ROS field order, with their
//! `ros2msg` schema texts and their CDR encoding (little-endian CDR behind the 4-byte
//! encapsulation header `00 01 00 00`, as ROS 2 and `ros2 bag` write it).
//!
//! Owned here: the message structs, [`RosMessage`] (schema name + schema text), [`encode`]
//! and [`decode`]. The mapping between these messages and [`crate::io::record`] types lives
//! in `mcap_out` (writing) and `mcap_in` (reading).
//!
//! Schema texts use the concatenated form of rosbag2 / `mcap-ros2-support`: the top-level
//! definition, then one section per dependency, each opened by a line of 80 `=` and a
//! `MSG: package/Type` line. Field types are written fully qualified (`std_msgs/Header`),
//! which every ros2msg parser accepts.

use byteorder::{BigEndian, LittleEndian};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Encapsulation header of little-endian plain CDR (`CDR_LE`).
pub const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// MCAP schema encoding of ROS 2 `.msg` definitions.
pub const SCHEMA_ENCODING: &str = "ros2msg";

/// MCAP message encoding of CDR-serialized ROS 2 messages.
pub const MESSAGE_ENCODING: &str = "cdr";

/// A ROS 2 message type: its schema name (`package/msg/Type`) and full `ros2msg` text.
pub trait RosMessage: Serialize + DeserializeOwned {
    /// Schema name, e.g. `sensor_msgs/msg/JointState`.
    const NAME: &'static str;
    /// The definition with all its dependencies (see the module docs).
    const SCHEMA: &'static str;
}

/// Whether an MCAP schema name denotes the ROS 2 type `name` (`pkg/msg/Type`), also
/// accepting the short form `pkg/Type` some writers use.
pub fn schema_is(schema_name: &str, name: &str) -> bool {
    schema_name == name || schema_name == name.replacen("/msg/", "/", 1)
}

/// A CDR encoding or decoding failure.
#[derive(Debug, thiserror::Error)]
pub enum CdrError {
    /// Fewer than 4 bytes: no encapsulation header.
    #[error("message too short for a CDR encapsulation header ({0} bytes)")]
    TooShort(usize),
    /// An encapsulation other than plain CDR (big- or little-endian).
    #[error("unsupported CDR encapsulation {0:02x} {1:02x} (expected plain CDR: 00 00 or 00 01)")]
    Encapsulation(u8, u8),
    /// The payload does not match the message definition.
    #[error("CDR: {0}")]
    Cdr(#[from] cdr_encoding::Error),
}

/// Serializes `msg` as little-endian CDR with its encapsulation header.
pub fn encode<T: Serialize>(msg: &T) -> Result<Vec<u8>, CdrError> {
    let body = cdr_encoding::to_vec::<T, LittleEndian>(msg)?;
    let mut out = Vec::with_capacity(4 + body.len());
    out.extend_from_slice(&CDR_LE);
    out.extend_from_slice(&body);
    Ok(out)
}

/// Deserializes a CDR message (big- or little-endian plain CDR; the two option bytes and
/// any trailing padding are ignored). Sequence lengths are checked against the bytes
/// left, so a corrupt length fails instead of allocating.
pub fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, CdrError> {
    let (head, body) = match bytes.split_first_chunk::<4>() {
        Some((h, b)) => (h, b),
        None => return Err(CdrError::TooShort(bytes.len())),
    };
    let value = match (head[0], head[1]) {
        (0x00, 0x01) => cdr_encoding::from_bytes::<T, LittleEndian>(body)?.0,
        (0x00, 0x00) => cdr_encoding::from_bytes::<T, BigEndian>(body)?.0,
        (a, b) => return Err(CdrError::Encapsulation(a, b)),
    };
    Ok(value)
}

/// One `MSG:` section of a concatenated definition.
macro_rules! section {
    ($name:literal, $def:expr) => {
        concat!(
            "\n================================================================================\n",
            "MSG: ",
            $name,
            "\n",
            $def
        )
    };
}

/// The definition of one message type, without its dependencies (a literal, for `concat!`).
macro_rules! defs {
    (time) => {
        "int32 sec\nuint32 nanosec\n"
    };
    (header) => {
        "builtin_interfaces/Time stamp\nstring frame_id\n"
    };
    (vector3) => {
        "float64 x\nfloat64 y\nfloat64 z\n"
    };
    (quaternion) => {
        "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n"
    };
    (transform) => {
        "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n"
    };
    (transform_stamped) => {
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n"
    };
    (point_field) => {
        "uint8 INT8 = 1\nuint8 UINT8 = 2\nuint8 INT16 = 3\nuint8 UINT16 = 4\n\
uint8 INT32 = 5\nuint8 UINT32 = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\n\
string name\nuint32 offset\nuint8 datatype\nuint32 count\n"
    };
    (key_value) => {
        "string key\nstring value\n"
    };
    (duration) => {
        "int32 sec\nuint32 nanosec\n"
    };
    (point) => {
        "float64 x\nfloat64 y\nfloat64 z\n"
    };
    (pose) => {
        "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n"
    };
    (color_rgba) => {
        "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n"
    };
    (compressed_image) => {
        "std_msgs/Header header\nstring format\nuint8[] data\n"
    };
    (uv_coordinate) => {
        "float32 u\nfloat32 v\n"
    };
    (mesh_file) => {
        "string filename\nuint8[] data\n"
    };
    (marker) => {
        "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ARROW_STRIP=12\n\
int32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n\
std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n\
geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\n\
visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n\
visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n"
    };
    (diagnostic_status) => {
        "byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\n\
byte level\nstring name\nstring message\nstring hardware_id\ndiagnostic_msgs/KeyValue[] values\n"
    };
}

/// The dependency sections of `geometry_msgs/TransformStamped`.
macro_rules! transform_stamped_deps {
    () => {
        concat!(
            section!("std_msgs/Header", defs!(header)),
            section!("builtin_interfaces/Time", defs!(time)),
            section!("geometry_msgs/Transform", defs!(transform)),
            section!("geometry_msgs/Vector3", defs!(vector3)),
            section!("geometry_msgs/Quaternion", defs!(quaternion)),
        )
    };
}

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Time {
    /// Seconds (signed, as in ROS 2).
    pub sec: i32,
    /// Nanoseconds within the second, `< 1e9`.
    pub nanosec: u32,
}

impl Time {
    /// The time `ns` nanoseconds after the epoch, if the seconds fit an `i32`.
    pub fn from_nanos(ns: u64) -> Option<Time> {
        let sec = i32::try_from(ns / 1_000_000_000).ok()?;
        Some(Time {
            sec,
            nanosec: (ns % 1_000_000_000) as u32,
        })
    }

    /// Nanoseconds since the epoch; `None` before it (negative seconds).
    pub fn to_nanos(&self) -> Option<u64> {
        let sec = u64::try_from(self.sec).ok()?;
        Some(sec * 1_000_000_000 + u64::from(self.nanosec))
    }
}

impl RosMessage for Time {
    const NAME: &'static str = "builtin_interfaces/msg/Time";
    const SCHEMA: &'static str = defs!(time);
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Header {
    /// Time stamp.
    pub stamp: Time,
    /// Frame the data is expressed in.
    pub frame_id: String,
}

/// `sensor_msgs/msg/JointState`: `velocity` and `effort` are empty or as long as `name`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointState {
    /// Stamp; the frame is unused.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions (rad or m).
    pub position: Vec<f64>,
    /// Velocities (rad/s or m/s).
    pub velocity: Vec<f64>,
    /// Efforts (N·m or N).
    pub effort: Vec<f64>,
}

impl RosMessage for JointState {
    const NAME: &'static str = "sensor_msgs/msg/JointState";
    const SCHEMA: &'static str = concat!(
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
        section!("std_msgs/Header", defs!(header)),
        section!("builtin_interfaces/Time", defs!(time)),
    );
}

/// `geometry_msgs/msg/Vector3`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w (scalar part).
    pub w: f64,
}

/// `geometry_msgs/msg/Transform`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Transform {
    /// Translation.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/msg/TransformStamped`: the pose of `child_frame_id` in `header.frame_id`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// Child frame.
    pub child_frame_id: String,
    /// Parent → child.
    pub transform: Transform,
}

impl RosMessage for TransformStamped {
    const NAME: &'static str = "geometry_msgs/msg/TransformStamped";
    const SCHEMA: &'static str = concat!(defs!(transform_stamped), transform_stamped_deps!());
}

/// `tf2_msgs/msg/TFMessage` (the type of `/tf` and `/tf_static`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

impl RosMessage for TfMessage {
    const NAME: &'static str = "tf2_msgs/msg/TFMessage";
    const SCHEMA: &'static str = concat!(
        "geometry_msgs/TransformStamped[] transforms\n",
        section!("geometry_msgs/TransformStamped", defs!(transform_stamped)),
        transform_stamped_deps!(),
    );
}

/// `std_msgs/msg/String`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct StringMsg {
    /// The text.
    pub data: String,
}

impl RosMessage for StringMsg {
    const NAME: &'static str = "std_msgs/msg/String";
    const SCHEMA: &'static str = "string data\n";
}

/// `sensor_msgs/msg/PointField` datatypes.
pub mod datatype {
    /// `INT8`.
    pub const INT8: u8 = 1;
    /// `UINT8`.
    pub const UINT8: u8 = 2;
    /// `INT16`.
    pub const INT16: u8 = 3;
    /// `UINT16`.
    pub const UINT16: u8 = 4;
    /// `INT32`.
    pub const INT32: u8 = 5;
    /// `UINT32`.
    pub const UINT32: u8 = 6;
    /// `FLOAT32`.
    pub const FLOAT32: u8 = 7;
    /// `FLOAT64`.
    pub const FLOAT64: u8 = 8;

    /// Size in bytes of one value of `datatype`, `None` for an unknown datatype.
    pub fn size(datatype: u8) -> Option<usize> {
        match datatype {
            INT8 | UINT8 => Some(1),
            INT16 | UINT16 => Some(2),
            INT32 | UINT32 | FLOAT32 => Some(4),
            FLOAT64 => Some(8),
            _ => None,
        }
    }
}

/// `sensor_msgs/msg/PointField`: one field of each point of a [`PointCloud2`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PointField {
    /// Field name (`x`, `y`, `z`, `intensity`, ...).
    pub name: String,
    /// Byte offset in the point.
    pub offset: u32,
    /// One of [`datatype`].
    pub datatype: u8,
    /// Number of values.
    pub count: u32,
}

/// `sensor_msgs/msg/PointCloud2`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PointCloud2 {
    /// Stamp and frame.
    pub header: Header,
    /// Rows (1 for an unordered cloud).
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// Layout of a point.
    pub fields: Vec<PointField>,
    /// Byte order of `data`.
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// The points.
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
    /// No invalid (NaN) points.
    pub is_dense: bool,
}

impl RosMessage for PointCloud2 {
    const NAME: &'static str = "sensor_msgs/msg/PointCloud2";
    const SCHEMA: &'static str = concat!(
        "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n\
bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n",
        section!("std_msgs/Header", defs!(header)),
        section!("builtin_interfaces/Time", defs!(time)),
        section!("sensor_msgs/PointField", defs!(point_field)),
    );
}

/// `diagnostic_msgs/msg/KeyValue`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct KeyValue {
    /// Key.
    pub key: String,
    /// Value.
    pub value: String,
}

/// `diagnostic_msgs/msg/DiagnosticStatus` levels.
pub mod level {
    /// `OK`.
    pub const OK: u8 = 0;
    /// `WARN`.
    pub const WARN: u8 = 1;
    /// `ERROR`.
    pub const ERROR: u8 = 2;
    /// `STALE`.
    pub const STALE: u8 = 3;
}

/// `diagnostic_msgs/msg/DiagnosticStatus`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DiagnosticStatus {
    /// One of [`level`].
    pub level: u8,
    /// What is checked.
    pub name: String,
    /// Summary.
    pub message: String,
    /// Hardware identifier.
    pub hardware_id: String,
    /// Values.
    pub values: Vec<KeyValue>,
}

impl DiagnosticStatus {
    /// The value of `key`, if present.
    pub fn value(&self, key: &str) -> Option<&str> {
        self.values
            .iter()
            .find(|kv| kv.key == key)
            .map(|kv| kv.value.as_str())
    }
}

/// `diagnostic_msgs/msg/DiagnosticArray`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DiagnosticArray {
    /// Stamp.
    pub header: Header,
    /// One status per checked item.
    pub status: Vec<DiagnosticStatus>,
}

impl RosMessage for DiagnosticArray {
    const NAME: &'static str = "diagnostic_msgs/msg/DiagnosticArray";
    const SCHEMA: &'static str = concat!(
        "std_msgs/Header header\ndiagnostic_msgs/DiagnosticStatus[] status\n",
        section!("std_msgs/Header", defs!(header)),
        section!("builtin_interfaces/Time", defs!(time)),
        section!("diagnostic_msgs/DiagnosticStatus", defs!(diagnostic_status)),
        section!("diagnostic_msgs/KeyValue", defs!(key_value)),
    );
}

/// `geometry_msgs/msg/Point`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Point {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Pose`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// Position.
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `std_msgs/msg/ColorRGBA` (components in `[0, 1]`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ColorRgba {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Opacity.
    pub a: f32,
}

/// `builtin_interfaces/msg/Duration`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Duration {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, `< 1e9`.
    pub nanosec: u32,
}

/// `sensor_msgs/msg/CompressedImage`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CompressedImage {
    /// Stamp and frame.
    pub header: Header,
    /// `jpeg`, `png`, ...
    pub format: String,
    /// The image file bytes.
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
}

/// `visualization_msgs/msg/UVCoordinate`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct UvCoordinate {
    /// u.
    pub u: f32,
    /// v.
    pub v: f32,
}

/// `visualization_msgs/msg/MeshFile`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MeshFile {
    /// File name (for its extension).
    pub filename: String,
    /// The file bytes.
    #[serde(with = "serde_bytes")]
    pub data: Vec<u8>,
}

/// `visualization_msgs/msg/Marker` types and actions.
pub mod marker {
    /// `CUBE`: a box, `scale` = side lengths.
    pub const CUBE: i32 = 1;
    /// `SPHERE`: an ellipsoid, `scale` = diameters.
    pub const SPHERE: i32 = 2;
    /// `CYLINDER`: along local z, `scale` = (diameter x, diameter y, length).
    pub const CYLINDER: i32 = 3;
    /// `TEXT_VIEW_FACING`: `text` facing the viewer, `scale.z` = letter height.
    pub const TEXT_VIEW_FACING: i32 = 9;
    /// `MESH_RESOURCE`: the mesh at `mesh_resource`, `scale` per axis.
    pub const MESH_RESOURCE: i32 = 10;
    /// `ADD` (= `MODIFY`).
    pub const ADD: i32 = 0;
    /// `DELETE`.
    pub const DELETE: i32 = 2;
    /// `DELETEALL`.
    pub const DELETEALL: i32 = 3;
}

/// `visualization_msgs/msg/Marker` (the ROS 2 Humble definition and later: with
/// texture and embedded-mesh fields).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Marker {
    /// Stamp and the frame `pose` is in.
    pub header: Header,
    /// Namespace; `(ns, id)` names the marker.
    pub ns: String,
    /// Id within `ns`.
    pub id: i32,
    /// One of [`marker`]'s types.
    #[serde(rename = "type")]
    pub kind: i32,
    /// One of [`marker`]'s actions.
    pub action: i32,
    /// Pose in `header.frame_id`.
    pub pose: Pose,
    /// Size (see [`marker`]).
    pub scale: Vector3,
    /// Colour.
    pub color: ColorRgba,
    /// Zero: forever.
    pub lifetime: Duration,
    /// Re-transformed into its frame every time step.
    pub frame_locked: bool,
    /// Points of line and point markers.
    pub points: Vec<Point>,
    /// Per-point colours.
    pub colors: Vec<ColorRgba>,
    /// Texture URI.
    pub texture_resource: String,
    /// Embedded texture.
    pub texture: CompressedImage,
    /// Texture coordinates.
    pub uv_coordinates: Vec<UvCoordinate>,
    /// Text of text markers (armsim also names its obstacles with it).
    pub text: String,
    /// Mesh URI of mesh markers.
    pub mesh_resource: String,
    /// Embedded mesh.
    pub mesh_file: MeshFile,
    /// Use the mesh file's own materials.
    pub mesh_use_embedded_materials: bool,
}

/// `visualization_msgs/msg/MarkerArray`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MarkerArray {
    /// The markers.
    pub markers: Vec<Marker>,
}

impl RosMessage for MarkerArray {
    const NAME: &'static str = "visualization_msgs/msg/MarkerArray";
    const SCHEMA: &'static str = concat!(
        "visualization_msgs/Marker[] markers\n",
        section!("visualization_msgs/Marker", defs!(marker)),
        section!("std_msgs/Header", defs!(header)),
        section!("builtin_interfaces/Time", defs!(time)),
        section!("geometry_msgs/Pose", defs!(pose)),
        section!("geometry_msgs/Point", defs!(point)),
        section!("geometry_msgs/Quaternion", defs!(quaternion)),
        section!("geometry_msgs/Vector3", defs!(vector3)),
        section!("std_msgs/ColorRGBA", defs!(color_rgba)),
        section!("builtin_interfaces/Duration", defs!(duration)),
        section!("sensor_msgs/CompressedImage", defs!(compressed_image)),
        section!("visualization_msgs/UVCoordinate", defs!(uv_coordinate)),
        section!("visualization_msgs/MeshFile", defs!(mesh_file)),
    );
}

#[cfg(test)]
mod tests {
    use crate::io::record::ros2::*;

    #[test]
    fn schema_sections() {
        let sep = format!("\n{}\nMSG: ", "=".repeat(80));
        assert!(JointState::SCHEMA.starts_with("std_msgs/Header header\n"));
        assert_eq!(JointState::SCHEMA.matches(&sep).count(), 2);
        assert!(TfMessage::SCHEMA.contains(&format!("{sep}geometry_msgs/Quaternion\nfloat64 x\n")));
        assert_eq!(DiagnosticArray::SCHEMA.matches(&sep).count(), 4);
        // Every type MarkerArray uses, once each, and nothing it does not use.
        let sections: Vec<&str> = MarkerArray::SCHEMA
            .split(&sep)
            .skip(1)
            .map(|s| s.lines().next().unwrap())
            .collect();
        assert_eq!(
            sections,
            [
                "visualization_msgs/Marker",
                "std_msgs/Header",
                "builtin_interfaces/Time",
                "geometry_msgs/Pose",
                "geometry_msgs/Point",
                "geometry_msgs/Quaternion",
                "geometry_msgs/Vector3",
                "std_msgs/ColorRGBA",
                "builtin_interfaces/Duration",
                "sensor_msgs/CompressedImage",
                "visualization_msgs/UVCoordinate",
                "visualization_msgs/MeshFile",
            ]
        );
        for used in MarkerArray::SCHEMA
            .lines()
            .filter(|l| !l.contains('=') && !l.starts_with("MSG: "))
            .filter_map(|l| l.split_whitespace().next())
            .filter(|t| t.contains('/'))
        {
            let t = used.trim_end_matches("[]");
            assert!(sections.contains(&t), "{t} has no section");
        }
    }

    #[test]
    fn marker_cdr_layout() {
        let m = Marker {
            id: 7,
            kind: marker::CUBE,
            scale: Vector3 {
                x: 1.0,
                y: 2.0,
                z: 3.0,
            },
            color: ColorRgba {
                r: 0.5,
                g: 0.25,
                b: 1.0,
                a: 1.0,
            },
            text: "t".into(),
            ..Default::default()
        };
        let b = encode(&m).unwrap();
        let f64s = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let expected: Vec<u8> = [
            &CDR_LE[..],
            &[0; 8],                                     // header.stamp
            &[1, 0, 0, 0, 0, 0, 0, 0], // frame_id "" (length 1: the NUL), padded to 4
            &[1, 0, 0, 0, 0, 0, 0, 0], // ns ""
            &[7, 0, 0, 0],             // id
            &[1, 0, 0, 0],             // type
            &[0, 0, 0, 0],             // action, at offset 32
            &[0, 0, 0, 0],             // padding: the pose's f64s start at offset 40
            &f64s(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]), // pose
            &f64s(&[1.0, 2.0, 3.0]),   // scale
            &[0.5f32, 0.25, 1.0, 1.0]
                .iter()
                .flat_map(|x| x.to_le_bytes())
                .collect::<Vec<u8>>(),
            &[0; 8],                      // lifetime
            &[0, 0, 0, 0],                // frame_locked + padding
            &[0, 0, 0, 0],                // points
            &[0, 0, 0, 0],                // colors
            &[1, 0, 0, 0, 0, 0, 0, 0],    // texture_resource ""
            &[0; 8],                      // texture.header.stamp
            &[1, 0, 0, 0, 0, 0, 0, 0],    // texture.header.frame_id
            &[1, 0, 0, 0, 0, 0, 0, 0],    // texture.format
            &[0, 0, 0, 0],                // texture.data
            &[0, 0, 0, 0],                // uv_coordinates
            &[2, 0, 0, 0, b't', 0, 0, 0], // text "t"
            &[1, 0, 0, 0, 0, 0, 0, 0],    // mesh_resource ""
            &[1, 0, 0, 0, 0, 0, 0, 0],    // mesh_file.filename
            &[0, 0, 0, 0],                // mesh_file.data
            &[0],                         // mesh_use_embedded_materials
        ]
        .concat();
        assert_eq!(b, expected);
        assert_eq!(decode::<Marker>(&b).unwrap(), m);
    }

    #[test]
    fn joint_state_cdr_layout() {
        let m = JointState {
            header: Header {
                stamp: Time { sec: 1, nanosec: 2 },
                frame_id: String::new(),
            },
            name: vec!["a".into()],
            position: vec![1.5],
            velocity: vec![],
            effort: vec![],
        };
        let b = encode(&m).unwrap();
        let expected: Vec<u8> = [
            &CDR_LE[..],
            &[1, 0, 0, 0, 2, 0, 0, 0],    // stamp
            &[1, 0, 0, 0, 0, 0, 0, 0],    // frame_id: length 1 (NUL), padded to 4
            &[1, 0, 0, 0],                // name: 1 element
            &[2, 0, 0, 0, b'a', 0, 0, 0], // "a" + NUL, padded to 4
            &[1, 0, 0, 0],                // position: 1 element; the f64 at offset 32 is aligned
            &1.5f64.to_le_bytes(),
            &[0, 0, 0, 0], // velocity
            &[0, 0, 0, 0], // effort
        ]
        .concat();
        assert_eq!(b, expected);
        assert_eq!(decode::<JointState>(&b).unwrap(), m);
    }

    #[test]
    fn decode_rejects_bad_input() {
        assert!(decode::<JointState>(&[0, 1]).is_err());
        assert!(decode::<JointState>(&[0, 7, 0, 0]).is_err());
        // A sequence claiming 2^32-1 names in a short buffer fails, not allocates.
        let mut b = CDR_LE.to_vec();
        b.extend_from_slice(&[0; 8]);
        b.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0]);
        b.extend_from_slice(&[0xff, 0xff, 0xff, 0xff]);
        assert!(decode::<JointState>(&b).is_err());
    }

    #[test]
    fn short_schema_names() {
        assert!(schema_is("sensor_msgs/JointState", JointState::NAME));
        assert!(schema_is("sensor_msgs/msg/JointState", JointState::NAME));
        assert!(!schema_is("sensor_msgs/msg/Joy", JointState::NAME));
    }
}
