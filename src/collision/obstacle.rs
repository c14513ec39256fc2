//! Environment obstacles: a named shape at a fixed world pose, and the serde-friendly
//! [`ObstacleSpec`] a scenario file describes them with.
//!
//! ```toml
//! [[obstacle]]
//! name = "table"
//! shape = "box"          # box | sphere | cylinder | capsule | mesh
//! size = [1.2, 0.8, 0.05] # box: full side lengths (m)
//! xyz = [0.6, 0.0, -0.025]
//! rpy = [0.0, 0.0, 0.0]  # roll, pitch, yaw (rad), as URDF
//!
//! [[obstacle]]
//! name = "post"
//! shape = "cylinder"     # cylinders and capsules are along their local z
//! radius = 0.05
//! length = 1.0
//! xyz = [0.5, 0.4, 0.5]
//!
//! [[obstacle]]
//! name = "fixture"
//! shape = "mesh"
//! mesh = "meshes/fixture.stl"  # relative to CollisionOptions::obstacle_dir
//! scale = [0.001, 0.001, 0.001]
//! ```
//!
//! Each shape takes exactly its own fields (`box`: `size`; `sphere`: `radius`;
//! `cylinder`/`capsule`: `radius`, `length` (for a capsule, of the cylindrical part);
//! `mesh`: `mesh`, optional `scale`); any other one is an error, so that a typo does not
//! pass silently.

use crate::collision::collision_error::CollisionError;
use crate::core::spatial::Se3;
use crate::model::Shape;
use serde::{Deserialize, Serialize};

/// Shape kind of an [`ObstacleSpec`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ObstacleShape {
    /// Box (`size`).
    Box,
    /// Sphere (`radius`).
    Sphere,
    /// Cylinder along local z (`radius`, `length`).
    Cylinder,
    /// Capsule along local z (`radius`, `length` of the cylindrical part).
    Capsule,
    /// Mesh file (`mesh`, optional `scale`).
    Mesh,
}

/// An obstacle as written in a scenario file (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    /// Unique name (also distinct from every link name).
    pub name: String,
    /// Shape kind.
    pub shape: ObstacleShape,
    /// Box side lengths (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[f64; 3]>,
    /// Sphere, cylinder or capsule radius (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Cylinder length, or length of a capsule's cylindrical part (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    /// Mesh file or URI (STL, OBJ, DAE).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// Mesh scale per axis (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<[f64; 3]>,
    /// Position (m).
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Orientation as URDF roll, pitch, yaw (rad).
    #[serde(default)]
    pub rpy: [f64; 3],
}

/// An obstacle: a shape at a fixed world pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Unique name.
    pub name: String,
    /// The shape (box sizes are full side lengths; cylinders and capsules along local z;
    /// mesh URIs are resolved against [`crate::collision::CollisionOptions::obstacle_dir`]).
    pub shape: Shape,
    /// World → obstacle frame.
    pub pose: Se3,
}

impl Obstacle {
    /// An obstacle from its parts.
    pub fn new(name: impl Into<String>, shape: Shape, pose: Se3) -> Self {
        Self {
            name: name.into(),
            shape,
            pose,
        }
    }

    /// An axis-aligned box with full side lengths `size` centred at `center`.
    pub fn cuboid(name: impl Into<String>, size: [f64; 3], center: [f64; 3]) -> Self {
        Self::new(
            name,
            Shape::Box { size },
            Se3::from_xyz_rpy(center, [0.0; 3]),
        )
    }

    /// A sphere of radius `radius` centred at `center`.
    pub fn sphere(name: impl Into<String>, radius: f64, center: [f64; 3]) -> Self {
        Self::new(
            name,
            Shape::Sphere { radius },
            Se3::from_xyz_rpy(center, [0.0; 3]),
        )
    }
}

impl ObstacleSpec {
    /// Checks the fields against the shape kind and builds the [`Obstacle`].
    pub fn to_obstacle(&self) -> Result<Obstacle, CollisionError> {
        let name = &self.name;
        let err = |reason: String| CollisionError::Obstacle {
            name: name.clone(),
            reason,
        };
        if name.is_empty() {
            return Err(err("empty name".to_string()));
        }
        let fields = [
            ("size", self.size.is_some()),
            ("radius", self.radius.is_some()),
            ("length", self.length.is_some()),
            ("mesh", self.mesh.is_some()),
            ("scale", self.scale.is_some()),
        ];
        let (needs, allowed): (&[&str], &[&str]) = match self.shape {
            ObstacleShape::Box => (&["size"], &["size"]),
            ObstacleShape::Sphere => (&["radius"], &["radius"]),
            ObstacleShape::Cylinder | ObstacleShape::Capsule => {
                (&["radius", "length"], &["radius", "length"])
            }
            ObstacleShape::Mesh => (&["mesh"], &["mesh", "scale"]),
        };
        let kind = serde_json::to_value(self.shape)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        for (f, present) in fields {
            if present && !allowed.contains(&f) {
                return Err(err(format!(
                    "a {kind} takes {}, not '{f}'",
                    allowed.join(", ")
                )));
            }
        }
        for (f, present) in fields {
            if !present && needs.contains(&f) {
                return Err(err(format!("a {kind} needs '{f}'")));
            }
        }
        if self.xyz.iter().chain(&self.rpy).any(|x| !x.is_finite()) {
            return Err(err("non-finite xyz or rpy".to_string()));
        }
        let max = crate::collision::shape::MAX_COORD;
        if self.xyz.iter().any(|x| x.abs() > max) {
            return Err(err(format!(
                "xyz {:?} lies beyond the {max:e} m accepted for collision geometry",
                self.xyz
            )));
        }
        let shape = match self.shape {
            ObstacleShape::Box => Shape::Box {
                size: self.size.unwrap_or_default(),
            },
            ObstacleShape::Sphere => Shape::Sphere {
                radius: self.radius.unwrap_or_default(),
            },
            ObstacleShape::Cylinder => Shape::Cylinder {
                radius: self.radius.unwrap_or_default(),
                length: self.length.unwrap_or_default(),
            },
            ObstacleShape::Capsule => Shape::Capsule {
                radius: self.radius.unwrap_or_default(),
                length: self.length.unwrap_or_default(),
            },
            ObstacleShape::Mesh => Shape::Mesh {
                uri: self.mesh.clone().unwrap_or_default(),
                scale: self.scale.unwrap_or([1.0; 3]),
            },
        };
        Ok(Obstacle::new(
            name.clone(),
            shape,
            Se3::from_xyz_rpy(self.xyz, self.rpy),
        ))
    }
}
