//! A scene's obstacles in a recording: [`ObstacleMarker`] (one drawable shape of an
//! obstacle), made from the collision layer's obstacles ([`markers_of`]), and its ROS 2
//! form, a `visualization_msgs/msg/MarkerArray` ([`to_message`], [`from_message`]), which
//! `mcap_out` writes once on `/armsim/obstacles` and `mcap_in` reads back.
//!
//! Mapping (one marker per shape, namespace `obstacles`, ids 0, 1, … in order, `text` =
//! the obstacle's name, pose in `frame_id` = the recording's `world`):
//!
//! | obstacle | marker type | `scale` |
//! |---|---|---|
//! | box | `CUBE` | full side lengths |
//! | sphere | `SPHERE` | diameter ×3 |
//! | cylinder (along local z) | `CYLINDER` | `(2r, 2r, length)` |
//! | capsule (along local z) | `CYLINDER` + two `SPHERE`s at `±length/2` on local z | `(2r, 2r, length)`, `2r` ×3 |
//! | mesh | `MESH_RESOURCE`, `mesh_resource` = `file://` + absolute path (the URI as written when the file is not found) | the mesh scale |
//!
//! Each obstacle also gets a `TEXT_VIEW_FACING` label with its name (namespace
//! `obstacle_names`, id = obstacle index) 5 cm above its highest point, so that RViz and
//! Foxglove show the names; readers skip text markers (the name is in every shape's
//! `text`).

use crate::collision::resolve::resolve_uri;
use crate::collision::Obstacle;
use crate::core::spatial::{Se3, Vec3};
use crate::io::record::recording::Transform;
pub use crate::io::record::recording::{MarkerShape, ObstacleMarker};
use crate::io::record::ros2;
use crate::io::record::tf::{to_se3, to_transform};
use crate::model::Shape;
use std::path::Path;

/// Namespace of the shape markers.
pub const NS_SHAPES: &str = "obstacles";
/// Namespace of the name labels.
pub const NS_LABELS: &str = "obstacle_names";
/// Colour of the obstacles (RGBA): light steel blue, slightly transparent.
pub const COLOR: [f32; 4] = [0.62, 0.68, 0.78, 0.85];
/// Letter height of the name labels (m) and their clearance above the obstacle.
const LABEL_HEIGHT: f64 = 0.05;

/// The markers of `obstacles`, whose poses are in a frame placed at `frame_pose` in
/// `frame` (e.g. the robot base in `world`); mesh URIs are resolved against `mesh_dir`.
pub fn markers_of(
    obstacles: &[Obstacle],
    frame: &str,
    frame_pose: &Se3,
    mesh_dir: Option<&Path>,
) -> Vec<ObstacleMarker> {
    let mut out = Vec::new();
    for o in obstacles {
        let pose = frame_pose.mul(&o.pose);
        let mut push = |shape: MarkerShape, scale: [f64; 3], at: &Se3| {
            out.push(ObstacleMarker {
                name: o.name.clone(),
                shape,
                scale,
                pose: to_transform(frame, &o.name, at),
                color: COLOR,
            })
        };
        match &o.shape {
            Shape::Box { size } => push(MarkerShape::Cube, *size, &pose),
            Shape::Sphere { radius } => push(MarkerShape::Sphere, [2.0 * radius; 3], &pose),
            Shape::Cylinder { radius, length } => push(
                MarkerShape::Cylinder,
                [2.0 * radius, 2.0 * radius, *length],
                &pose,
            ),
            Shape::Capsule { radius, length } => {
                push(
                    MarkerShape::Cylinder,
                    [2.0 * radius, 2.0 * radius, *length],
                    &pose,
                );
                for s in [0.5, -0.5] {
                    let cap = pose.mul(&Se3::from_translation(Vec3::new(0.0, 0.0, s * length)));
                    push(MarkerShape::Sphere, [2.0 * radius; 3], &cap);
                }
            }
            Shape::Mesh { uri, scale } => {
                let uri = resolve_uri(uri, mesh_dir)
                    .ok()
                    .and_then(|p| std::fs::canonicalize(p).ok())
                    .map_or_else(|| uri.clone(), |p| format!("file://{}", p.display()));
                push(MarkerShape::Mesh { uri }, *scale, &pose)
            }
        }
    }
    out
}

fn color_msg(c: [f32; 4]) -> ros2::ColorRgba {
    ros2::ColorRgba {
        r: c[0],
        g: c[1],
        b: c[2],
        a: c[3],
    }
}

fn pose_msg(t: &Transform) -> ros2::Pose {
    ros2::Pose {
        position: ros2::Point {
            x: t.translation[0],
            y: t.translation[1],
            z: t.translation[2],
        },
        orientation: ros2::Quaternion {
            x: t.rotation[0],
            y: t.rotation[1],
            z: t.rotation[2],
            w: t.rotation[3],
        },
    }
}

/// Half the extent along the frame's z of a marker (0 for meshes, whose size is unknown).
fn half_height(m: &ObstacleMarker) -> f64 {
    if matches!(m.shape, MarkerShape::Mesh { .. }) {
        return 0.0;
    }
    let r = to_se3(&m.pose).rot;
    (0..3).map(|j| r[(2, j)].abs() * 0.5 * m.scale[j]).sum()
}

/// The MarkerArray of `markers` (see the module docs), stamped `stamp`.
pub fn to_message(markers: &[ObstacleMarker], stamp: ros2::Time) -> ros2::MarkerArray {
    let header = |frame: &str| ros2::Header {
        stamp,
        frame_id: frame.to_string(),
    };
    let mut out: Vec<ros2::Marker> = Vec::with_capacity(2 * markers.len());
    // Highest point and label anchor of each obstacle, in order of first appearance.
    let mut labels: Vec<(&str, &Transform, f64)> = Vec::new();
    for (k, m) in markers.iter().enumerate() {
        let (kind, mesh_resource) = match &m.shape {
            MarkerShape::Cube => (ros2::marker::CUBE, String::new()),
            MarkerShape::Sphere => (ros2::marker::SPHERE, String::new()),
            MarkerShape::Cylinder => (ros2::marker::CYLINDER, String::new()),
            MarkerShape::Mesh { uri } => (ros2::marker::MESH_RESOURCE, uri.clone()),
        };
        out.push(ros2::Marker {
            header: header(&m.pose.parent),
            ns: NS_SHAPES.to_string(),
            id: i32::try_from(k).unwrap_or(i32::MAX),
            kind,
            action: ros2::marker::ADD,
            pose: pose_msg(&m.pose),
            scale: ros2::Vector3 {
                x: m.scale[0],
                y: m.scale[1],
                z: m.scale[2],
            },
            color: color_msg(m.color),
            text: m.name.clone(),
            mesh_resource,
            ..Default::default()
        });
        let top = m.pose.translation[2] + half_height(m);
        match labels.iter_mut().find(|(n, _, _)| *n == m.name) {
            Some(l) => l.2 = l.2.max(top),
            None => labels.push((&m.name, &m.pose, top)),
        }
    }
    for (k, (name, pose, top)) in labels.into_iter().enumerate() {
        let mut at = pose.clone();
        at.translation[2] = top + LABEL_HEIGHT;
        at.rotation = [0.0, 0.0, 0.0, 1.0];
        out.push(ros2::Marker {
            header: header(&pose.parent),
            ns: NS_LABELS.to_string(),
            id: i32::try_from(k).unwrap_or(i32::MAX),
            kind: ros2::marker::TEXT_VIEW_FACING,
            action: ros2::marker::ADD,
            pose: pose_msg(&at),
            scale: ros2::Vector3 {
                x: 0.0,
                y: 0.0,
                z: LABEL_HEIGHT,
            },
            color: color_msg([1.0, 1.0, 1.0, 1.0]),
            text: name.to_string(),
            ..Default::default()
        });
    }
    ros2::MarkerArray { markers: out }
}

/// The shapes of a MarkerArray: its `ADD` markers of type `CUBE`, `SPHERE`, `CYLINDER` and
/// `MESH_RESOURCE`, named by `text` (else `ns/id`); a zero or non-finite orientation
/// becomes the identity, others are normalised. Text and other markers are skipped.
pub fn from_message(msg: &ros2::MarkerArray) -> Vec<ObstacleMarker> {
    msg.markers
        .iter()
        .filter(|m| m.action == ros2::marker::ADD)
        .filter_map(|m| {
            let shape = match m.kind {
                ros2::marker::CUBE => MarkerShape::Cube,
                ros2::marker::SPHERE => MarkerShape::Sphere,
                ros2::marker::CYLINDER => MarkerShape::Cylinder,
                ros2::marker::MESH_RESOURCE => MarkerShape::Mesh {
                    uri: m.mesh_resource.clone(),
                },
                _ => return None,
            };
            let name = if m.text.is_empty() {
                format!("{}/{}", m.ns, m.id)
            } else {
                m.text.clone()
            };
            let o = m.pose.orientation;
            let norm = (o.x * o.x + o.y * o.y + o.z * o.z + o.w * o.w).sqrt();
            let rotation = if norm.is_finite() && norm > 1e-12 {
                [o.x / norm, o.y / norm, o.z / norm, o.w / norm]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            };
            let p = m.pose.position;
            Some(ObstacleMarker {
                pose: Transform {
                    parent: m.header.frame_id.clone(),
                    child: name.clone(),
                    translation: [p.x, p.y, p.z],
                    rotation,
                },
                name,
                shape,
                scale: [m.scale.x, m.scale.y, m.scale.z],
                color: [m.color.r, m.color.g, m.color.b, m.color.a],
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::core::spatial::rot_x;
    use crate::io::record::obstacle_markers::*;

    #[test]
    fn capsule_is_a_cylinder_between_two_spheres() {
        // A capsule lying along world y (local z turned by -90° about x), 1 m up.
        let pose = Se3::new(
            rot_x(-std::f64::consts::FRAC_PI_2),
            Vec3::new(0.0, 0.0, 1.0),
        );
        let o = Obstacle::new(
            "rail",
            Shape::Capsule {
                radius: 0.1,
                length: 0.6,
            },
            pose,
        );
        let m = markers_of(&[o], "world", &Se3::identity(), None);
        assert_eq!(m.len(), 3);
        assert_eq!(m[0].shape, MarkerShape::Cylinder);
        assert_eq!(m[0].scale, [0.2, 0.2, 0.6]);
        for (cap, y) in m[1..].iter().zip([0.3, -0.3]) {
            assert_eq!(cap.shape, MarkerShape::Sphere);
            assert_eq!(cap.scale, [0.2; 3]);
            let t = cap.pose.translation;
            assert!((t[0]).abs() < 1e-15 && (t[1] - y).abs() < 1e-15 && (t[2] - 1.0).abs() < 1e-15);
        }
        // Labelled once, 5 cm above the top (z = 1 + 0.1).
        let msg = to_message(&m, ros2::Time::default());
        let labels: Vec<_> = msg
            .markers
            .iter()
            .filter(|k| k.kind == ros2::marker::TEXT_VIEW_FACING)
            .collect();
        assert_eq!(labels.len(), 1);
        assert_eq!(labels[0].text, "rail");
        assert!((labels[0].pose.position.z - 1.15).abs() < 1e-12);
        assert_eq!(from_message(&msg), m);
    }

    #[test]
    fn unknown_markers_are_skipped_and_unnamed_ones_get_ns_and_id() {
        let msg = ros2::MarkerArray {
            markers: vec![
                ros2::Marker {
                    ns: "a".into(),
                    id: 4,
                    kind: ros2::marker::CUBE,
                    ..Default::default()
                },
                ros2::Marker {
                    kind: 4, // LINE_STRIP
                    ..Default::default()
                },
                ros2::Marker {
                    kind: ros2::marker::SPHERE,
                    action: ros2::marker::DELETE,
                    ..Default::default()
                },
            ],
        };
        let m = from_message(&msg);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].name, "a/4");
        assert_eq!(m[0].pose.rotation, [0.0, 0.0, 0.0, 1.0]);
    }
}
