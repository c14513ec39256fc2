//! The in-memory [`Recording`] and its parts: the [`Header`], the time-ordered
//! [`Frame`]s with their [`Transform`]s, point clouds, the torque-check table, collision
//! events and the scene's obstacles as markers ([`ObstacleMarker`]). Data only: the
//! writers and readers live beside it.

use serde::{Deserialize, Serialize};

/// A rigid transform between two named frames (ROS `geometry_msgs/TransformStamped`
/// without the stamp). Rotation is a unit quaternion `[x, y, z, w]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// The parent frame.
    pub parent: String,
    /// The child frame.
    pub child: String,
    /// Translation of the child in the parent (m).
    pub translation: [f64; 3],
    /// Rotation of the child in the parent, `[x, y, z, w]`.
    pub rotation: [f64; 4],
}

/// One time step: joint positions, velocities and torques (in `joint_names` order) and the
/// link poses at that time (one transform per link, parent → child as in the URDF tree).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Frame {
    /// Time since the start (s).
    pub t: f64,
    /// Joint positions (rad or m).
    pub q: Vec<f64>,
    /// Joint velocities (rad/s or m/s).
    pub qd: Vec<f64>,
    /// Joint torques (N·m or N).
    pub tau: Vec<f64>,
    /// Link poses at this time.
    pub tf: Vec<Transform>,
}

/// A point cloud (e.g. a sampled workspace) with one optional scalar per point
/// (e.g. manipulability); `values` is empty or as long as `points`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PointCloud {
    /// Time (s).
    pub t: f64,
    /// The frame the points are given in.
    pub frame: String,
    /// The points (m).
    pub points: Vec<[f32; 3]>,
    /// One scalar per point, or none.
    pub values: Vec<f32>,
}

/// One row of a torque check (per joint).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TorqueRow {
    /// The joint.
    pub joint: String,
    /// Largest absolute torque (N·m or N).
    pub peak_torque: f64,
    /// Root-mean-square torque (N·m or N).
    pub rms_torque: f64,
    /// Largest absolute speed (rad/s or m/s).
    pub peak_speed: f64,
    /// Largest absolute mechanical power (W).
    pub peak_power: f64,
    /// Effort limit (N·m or N); `None` when the model has none.
    pub limit: Option<f64>,
    /// Velocity limit; `None` when the model has none.
    pub velocity_limit: Option<f64>,
    /// Margin in % of the effort limit (negative when violated).
    pub margin: Option<f64>,
    /// Within every limit.
    pub ok: bool,
    /// First time the joint exceeds a limit.
    pub first_violation: Option<f64>,
}

/// A contact between two bodies (links or obstacles) at time `t`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CollisionEvent {
    /// Time (s).
    pub t: f64,
    /// The first body.
    pub body_a: String,
    /// The second body.
    pub body_b: String,
}

/// Everything that is known before the first frame.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Header {
    /// Scenario (or recording) name.
    pub name: String,
    /// The moving joints, in the order of every frame's vectors.
    pub joint_names: Vec<String>,
    /// Effort limit per joint (`None`: none in the model).
    pub effort_limits: Vec<Option<f64>>,
    /// Fixed frames (e.g. `world` → base link, fixed joints).
    pub static_tf: Vec<Transform>,
    /// URDF text of the robot, so viewers can rebuild it.
    pub robot_description: Option<String>,
    /// Free-form key/value metadata (scenario path, armsim version, ...).
    pub metadata: Vec<(String, String)>,
    /// Wall-clock time of `t = 0` in nanoseconds since the Unix epoch: an MCAP file's log
    /// times and stamps are `epoch_ns + t`. `None`: the writer takes the wall clock when
    /// it creates the file. The reader sets it (see `mcap_in`).
    #[serde(default)]
    pub epoch_ns: Option<u64>,
}

/// A whole recording in memory.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Recording {
    /// What is known before the first frame.
    pub header: Header,
    /// The time steps, in time order.
    pub frames: Vec<Frame>,
    /// Point clouds (e.g. a sampled workspace).
    pub clouds: Vec<PointCloud>,
    /// The torque check, one row per joint.
    pub torque_check: Vec<TorqueRow>,
    /// Contacts found along the motion.
    pub collisions: Vec<CollisionEvent>,
    /// The scene's obstacles (fixed for the whole recording).
    #[serde(default)]
    pub obstacles: Vec<ObstacleMarker>,
}

/// The primitive of a marker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum MarkerShape {
    /// A box; `scale` = side lengths.
    Cube,
    /// An ellipsoid; `scale` = diameters.
    Sphere,
    /// A cylinder along local z; `scale` = (diameter x, diameter y, length).
    Cylinder,
    /// A mesh file; `scale` per axis.
    Mesh {
        /// `file://` URI (or the URI as written when the file was not found).
        uri: String,
    },
}

/// One drawable shape of an obstacle, as a ROS marker describes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObstacleMarker {
    /// The obstacle's name (shared by the shapes of one obstacle).
    pub name: String,
    /// The primitive.
    pub shape: MarkerShape,
    /// Its size (see [`MarkerShape`]).
    pub scale: [f64; 3],
    /// Pose of the shape's centre: `parent` is the frame, `child` the name.
    pub pose: Transform,
    /// RGBA in `[0, 1]`.
    pub color: [f32; 4],
}
