//! The neutral description every loader produces (URDF, DH table, generated chain)
//! before validation: links and joints by name, in file order, with their source lines.

use crate::core::spatial::{Inertia, Se3, Vec3};

/// Joint type as written in a model file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    /// Rotation about the axis, within position limits.
    Revolute,
    /// Rotation about the axis without position limits (the coordinate is an angle).
    Continuous,
    /// Translation along the axis.
    Prismatic,
    /// No motion: folded away in the hot paths.
    Fixed,
}

impl JointType {
    /// Name used in URDF and in the CLI output.
    pub fn as_str(&self) -> &'static str {
        match self {
            JointType::Revolute => "revolute",
            JointType::Continuous => "continuous",
            JointType::Prismatic => "prismatic",
            JointType::Fixed => "fixed",
        }
    }

    /// Whether the joint contributes a coordinate.
    pub fn is_movable(&self) -> bool {
        !matches!(self, JointType::Fixed)
    }
}

/// Position, velocity and effort limits; `±inf` where a file gives none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Lower position limit (rad or m).
    pub lower: f64,
    /// Upper position limit (rad or m).
    pub upper: f64,
    /// Velocity limit (rad/s or m/s).
    pub velocity: f64,
    /// Effort limit (N m or N).
    pub effort: f64,
}

impl Limits {
    /// No limits at all.
    pub fn unlimited() -> Self {
        Self {
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            velocity: f64::INFINITY,
            effort: f64::INFINITY,
        }
    }
}

/// A `<mimic>`: `q = multiplier * q_master + offset`.
#[derive(Clone, Debug, PartialEq)]
pub struct MimicSpec {
    /// Name of the master joint.
    pub joint: String,
    /// Multiplier (default 1).
    pub multiplier: f64,
    /// Offset (default 0).
    pub offset: f64,
}

/// Collision or visual geometry, kept for collision checking and visualisation.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Box with full side lengths.
    Box {
        /// Side lengths (m).
        size: [f64; 3],
    },
    /// Cylinder along z.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
    },
    /// Capsule along z.
    Capsule {
        /// Radius (m).
        radius: f64,
        /// Length of the cylindrical part (m).
        length: f64,
    },
    /// Sphere.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// Mesh file, URI as written (`package://…`, relative or absolute path).
    Mesh {
        /// The URI as written in the file.
        uri: String,
        /// Per-axis scale.
        scale: [f64; 3],
    },
}

/// A piece of geometry attached to a link.
#[derive(Clone, Debug, PartialEq)]
pub struct Geometry {
    /// Pose of the geometry in the link frame.
    pub origin: Se3,
    /// The shape.
    pub shape: Shape,
    /// RGBA colour, where the file gives one.
    pub rgba: Option<[f64; 4]>,
}

/// One link as read from a file.
#[derive(Clone, Debug)]
pub struct LinkSpec {
    /// Unique link name.
    pub name: String,
    /// Inertia expressed in the link frame.
    pub inertial: Inertia,
    /// Visual geometry.
    pub visuals: Vec<Geometry>,
    /// Collision geometry.
    pub collisions: Vec<Geometry>,
    /// Source line, where known.
    pub line: Option<usize>,
}

impl LinkSpec {
    /// A massless link without geometry.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            inertial: Inertia::zero(),
            visuals: Vec::new(),
            collisions: Vec::new(),
            line: None,
        }
    }
}

/// One joint as read from a file.
#[derive(Clone, Debug)]
pub struct JointSpec {
    /// Unique joint name.
    pub name: String,
    /// Joint type.
    pub jtype: JointType,
    /// Parent link name.
    pub parent: String,
    /// Child link name.
    pub child: String,
    /// Parent link frame → joint frame at q = 0.
    pub origin: Se3,
    /// Joint axis in the joint frame (any non-zero length; normalised on build).
    pub axis: Vec3,
    /// Joint frame (after the joint motion) → child link frame. Identity for URDF;
    /// DH tables use it for the distal part of the link transform.
    pub child_offset: Se3,
    /// Limits.
    pub limits: Limits,
    /// Mimic relation, if any.
    pub mimic: Option<MimicSpec>,
    /// Viscous damping from `<dynamics>` (N m s/rad).
    pub damping: f64,
    /// Coulomb friction from `<dynamics>` (N m).
    pub friction: f64,
    /// Rotor inertia `I_m` (kg m²), from DH tables.
    pub motor_inertia: f64,
    /// Gear ratio `N`, from DH tables (1 when absent).
    pub gear_ratio: f64,
    /// Source line, where known.
    pub line: Option<usize>,
}

impl JointSpec {
    /// A joint with identity origin, z axis and no limits.
    pub fn new(
        name: impl Into<String>,
        jtype: JointType,
        parent: impl Into<String>,
        child: impl Into<String>,
    ) -> Self {
        Self {
            name: name.into(),
            jtype,
            parent: parent.into(),
            child: child.into(),
            origin: Se3::identity(),
            axis: Vec3::z(),
            child_offset: Se3::identity(),
            limits: Limits::unlimited(),
            mimic: None,
            damping: 0.0,
            friction: 0.0,
            motor_inertia: 0.0,
            gear_ratio: 1.0,
            line: None,
        }
    }
}

/// A whole mechanism as read from a file.
#[derive(Clone, Debug)]
pub struct ModelSpec {
    /// Robot name.
    pub name: String,
    /// The file it came from (for messages).
    pub source: String,
    /// World → root link frame.
    pub root_offset: Se3,
    /// Links in file order.
    pub links: Vec<LinkSpec>,
    /// Joints in file order.
    pub joints: Vec<JointSpec>,
    /// The file's URDF text, where it came from one (kept for recordings).
    pub urdf_text: Option<String>,
    /// Gravity the file asks for, if it says.
    pub gravity: Option<Vec3>,
    /// Problems the reader found and worked around (what was ignored or repaired, where);
    /// [`crate::model::Model::build`] reports them first among its warnings.
    pub warnings: Vec<crate::model::ModelWarning>,
}
