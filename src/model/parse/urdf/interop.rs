//! `urdf_rs::Robot` ⇄ armsim: the robot type the Rust ecosystem passes around (k,
//! urdf-viz, rapier3d-urdf) taken in and given back.
//!
//! This module owns the two conversions and nothing else:
//! - [`ModelSpec::from_urdf_rs`] turns a `Robot` into the [`ModelSpec`] the URDF text
//!   reader would produce, with the reader's own rules (floating and planar joints
//!   expanded, limits, inertias, colours of named materials), and
//!   [`Model::from_urdf_rs`] builds it with [`Model::build`], so the model, the warnings
//!   and the errors are those of loading the text (messages name the robot instead of a
//!   file, and carry no line: a `Robot` has none);
//! - [`Model::to_urdf_rs`] writes a [`Model`] back as a `Robot` that builds into the same
//!   model.
//!
//! What a `Robot` cannot carry is not given back: gravity, rotor inertias and gear ratios
//! (DH tables), the armature. What urdf-rs has already dropped or defaulted cannot be
//! warned about (a missing `<limit>` reads as zeros there, hence as a joint locked at 0).

use crate::core::spatial::{matrix_to_rpy, rpy_to_matrix, Mat3, Se3, Vec3};
use crate::model::parse::urdf::{joints, links};
use crate::model::spec::{Geometry, JointSpec, JointType, LinkSpec, MimicSpec, ModelSpec, Shape};
use crate::model::{Joint, LoadOptions, Model, ModelError, ModelWarning};
use std::collections::HashMap;

/// How far (in m, or in rotation-matrix entries) a joint's child frame may sit from its
/// joint frame and still be written as the child of that joint: rounding only.
const SAME_FRAME: f64 = 1e-12;

impl ModelSpec {
    /// The [`ModelSpec`] of an `urdf_rs::Robot`, as [`crate::model::parse::urdf::parse`]
    /// reads the same robot from text. Messages name `urdf_rs::Robot 'NAME'`.
    pub fn from_urdf_rs(robot: &urdf_rs::Robot) -> Result<ModelSpec, ModelError> {
        let source = format!("urdf_rs::Robot '{}'", robot.name);
        let mut warnings = Vec::new();
        let name = if robot.name.is_empty() {
            warnings.push(ModelError::new(
                &source,
                None,
                "<robot>",
                "missing 'name' attribute: named 'robot'",
            ));
            "robot".to_string()
        } else {
            robot.name.clone()
        };
        let mut materials: HashMap<&str, [f64; 4]> = HashMap::new();
        for m in &robot.materials {
            if let Some(c) = &m.color {
                materials.entry(m.name.as_str()).or_insert(c.rgba.0);
            }
        }
        let mut spec_links = Vec::with_capacity(robot.links.len());
        for l in &robot.links {
            spec_links.push(link_spec(l, &source, &mut materials)?);
        }
        let mut spec_joints = Vec::with_capacity(robot.joints.len());
        for j in &robot.joints {
            let (js, extra) = joint_specs(j, &source, &mut warnings)?;
            spec_joints.extend(js);
            spec_links.extend(extra);
        }
        Ok(ModelSpec {
            name,
            source,
            root_offset: Se3::identity(),
            links: spec_links,
            joints: spec_joints,
            urdf_text: urdf_rs::write_to_string(robot).ok(),
            gravity: None,
            warnings,
        })
    }
}

impl Model {
    /// Builds the model of an `urdf_rs::Robot` (from `urdf_rs::read_file`, k, urdf-viz):
    /// the same model, warnings and errors as [`Model::load`] of the robot's URDF text,
    /// through the same [`ModelSpec`] and [`Model::build`].
    ///
    /// ```
    /// use armsim::model::Model;
    /// let robot = urdf_rs::read_from_string(
    ///     r#"<robot name="arm">
    ///          <link name="base"/>
    ///          <link name="tool">
    ///            <inertial><mass value="1"/>
    ///              <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>
    ///            </inertial>
    ///          </link>
    ///          <joint name="j1" type="revolute">
    ///            <parent link="base"/><child link="tool"/>
    ///            <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    ///            <limit lower="-1" upper="1" effort="10" velocity="2"/>
    ///          </joint>
    ///        </robot>"#,
    /// )
    /// .expect("valid URDF");
    /// let (model, warnings) = Model::from_urdf_rs(&robot)?;
    /// assert_eq!((model.nv, warnings.len()), (1, 0));
    /// assert_eq!(model.dof_names(), ["j1"]);
    /// // And back: a Robot that k or urdf-viz can use, building into the same model.
    /// let back = model.to_urdf_rs();
    /// assert_eq!(back.joints[0].limit.upper, 1.0);
    /// let (again, _) = Model::from_urdf_rs(&back)?;
    /// assert_eq!(again.upper, model.upper);
    /// # Ok::<(), armsim::model::ModelError>(())
    /// ```
    pub fn from_urdf_rs(robot: &urdf_rs::Robot) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::from_urdf_rs_with(robot, &LoadOptions::default())
    }

    /// [`Model::from_urdf_rs`] with the options of [`Model::load_with`] (`strict`,
    /// `ignore_mimic`).
    pub fn from_urdf_rs_with(
        robot: &urdf_rs::Robot,
        opts: &LoadOptions,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::build_with(ModelSpec::from_urdf_rs(robot)?, opts)
    }

    /// The model as an `urdf_rs::Robot` that [`Model::from_urdf_rs`] builds into the same
    /// model (links, joints, origins, axes, limits, mimic relations as resolved,
    /// inertias, geometry and colours). A joint whose child frame is not its joint frame
    /// (DH tables) becomes the joint to a massless link `J_frame` and a fixed joint
    /// `J_offset` from there to the child; a root link placed away from the world gets a
    /// fixed joint `ROOT_world_joint` from a massless link `ROOT_world`. Gravity, rotor
    /// inertias and gear ratios have no place in a `Robot` and are left out.
    pub fn to_urdf_rs(&self) -> urdf_rs::Robot {
        let mut links: Vec<urdf_rs::Link> = self.links.iter().map(robot_link).collect();
        let mut joints = Vec::with_capacity(self.joints.len());
        if let Some(root) = self.links.first() {
            if !near_identity(&root.offset) {
                let world = format!("{}_world", root.name);
                links.insert(0, massless_link(&world));
                joints.push(fixed_joint(
                    format!("{world}_joint"),
                    &world,
                    &root.name,
                    &root.offset,
                ));
            }
        }
        for j in &self.joints {
            let child = &self.links[j.child_link].name;
            let offset = self.child_offset(j);
            let mut rj = robot_joint(self, j);
            if near_identity(&offset) {
                joints.push(rj);
            } else {
                let frame = format!("{}_frame", j.name);
                links.push(massless_link(&frame));
                rj.child.link.clone_from(&frame);
                joints.push(rj);
                joints.push(fixed_joint(
                    format!("{}_offset", j.name),
                    &frame,
                    child,
                    &offset,
                ));
            }
        }
        urdf_rs::Robot {
            name: self.name.clone(),
            version: None,
            links,
            joints,
            materials: Vec::new(),
        }
    }

    /// Joint frame (after the joint's motion) → child link frame: identity for URDF
    /// models up to rounding, the distal part of the link transform for DH tables.
    fn child_offset(&self, j: &Joint) -> Se3 {
        let parent = &self.links[j.parent_link];
        let child = &self.links[j.child_link];
        let joint_frame = parent.offset.mul(&j.origin);
        // Both in the parent body's frame (the world's for the root); a body's coordinate
        // is 0 when its joint's own value is 0.
        let child_frame = match j.body {
            Some(b) => self.placement[b].mul(&child.offset),
            None => child.offset,
        };
        joint_frame.inv_mul(&child_frame)
    }
}

/// The [`LinkSpec`] of an urdf-rs link: the reader's inertia (a negative diagonal moment
/// is an error) and geometry, colours resolved through the named materials (`mats`, to
/// which a material first defined in a visual is added, as urdfdom does).
fn link_spec<'r>(
    l: &'r urdf_rs::Link,
    source: &str,
    mats: &mut HashMap<&'r str, [f64; 4]>,
) -> Result<LinkSpec, ModelError> {
    let el = format!("link '{}'", l.name);
    let i = &l.inertial.inertia;
    let tensor = [i.ixx, i.ixy, i.ixz, i.iyy, i.iyz, i.izz];
    let frame = pose(&l.inertial.origin);
    let mut spec = LinkSpec::new(&l.name);
    spec.inertial = links::inertia_of(l.inertial.mass.value, tensor, &frame)
        .map_err(|e| ModelError::new(source, None, &el, e.to_string()))?;
    for v in &l.visual {
        let mut g = geometry(&v.origin, &v.geometry);
        g.rgba = v.material.as_ref().and_then(|m| match &m.color {
            Some(c) => Some(*mats.entry(m.name.as_str()).or_insert(c.rgba.0)),
            None => mats.get(m.name.as_str()).copied(),
        });
        spec.visuals.push(g);
    }
    for c in &l.collision {
        spec.collisions.push(geometry(&c.origin, &c.geometry));
    }
    Ok(spec)
}

/// The joint specs of an urdf-rs joint (several, with massless links, for floating and
/// planar joints, whose warnings go to `warnings`).
fn joint_specs(
    j: &urdf_rs::Joint,
    source: &str,
    warnings: &mut Vec<ModelWarning>,
) -> Result<(Vec<JointSpec>, Vec<LinkSpec>), ModelError> {
    use urdf_rs::JointType as U;
    let el = format!("joint '{}'", j.name);
    let err = |msg: String| ModelError::new(source, None, &el, msg);
    let origin = pose(&j.origin);
    let axis = Vec3::from(j.axis.xyz.0);
    let (parent, child) = (j.parent.link.as_str(), j.child.link.as_str());
    let jtype = match j.joint_type {
        U::Revolute => JointType::Revolute,
        U::Continuous => JointType::Continuous,
        U::Prismatic => JointType::Prismatic,
        U::Fixed => JointType::Fixed,
        U::Floating | U::Planar => {
            let floating = j.joint_type == U::Floating;
            let (js, ls, msgs) =
                joints::expand(&j.name, floating, (parent, child), origin, axis, None);
            warnings.extend(msgs.into_iter().map(&err));
            return Ok((js, ls));
        }
        U::Spherical => {
            return Err(err(
                "joint type 'spherical' is not supported (nor is it by urdfdom)".into(),
            ))
        }
    };
    let lim = &j.limit;
    for (a, v) in [("effort", lim.effort), ("velocity", lim.velocity)] {
        if v < 0.0 {
            return Err(err(format!("<limit {a}=\"{v}\">: must not be negative")));
        }
    }
    let mut js = JointSpec::new(&j.name, jtype, parent, child);
    js.origin = origin;
    js.axis = axis;
    js.limits = joints::limits_of(jtype, lim.lower, lim.upper, lim.effort, lim.velocity);
    js.mimic = j.mimic.as_ref().map(|m| MimicSpec {
        joint: m.joint.clone(),
        multiplier: m.multiplier.unwrap_or(1.0),
        offset: m.offset.unwrap_or(0.0),
    });
    if let Some(d) = &j.dynamics {
        js.damping = d.damping;
        js.friction = d.friction;
    }
    Ok((vec![js], Vec::new()))
}

/// The pose of an urdf-rs origin.
fn pose(p: &urdf_rs::Pose) -> Se3 {
    Se3::new(rpy_to_matrix(p.rpy.0), Vec3::from(p.xyz.0))
}

/// The urdf-rs origin of a pose.
fn origin(t: &Se3) -> urdf_rs::Pose {
    urdf_rs::Pose {
        xyz: urdf_rs::Vec3(t.trans.into()),
        rpy: urdf_rs::Vec3(matrix_to_rpy(&t.rot)),
    }
}

/// A visual or collision of an urdf-rs link, without colour.
fn geometry(o: &urdf_rs::Pose, g: &urdf_rs::Geometry) -> Geometry {
    use urdf_rs::Geometry as G;
    let shape = match g {
        G::Box { size } => Shape::Box { size: size.0 },
        G::Cylinder { radius, length } => Shape::Cylinder {
            radius: *radius,
            length: *length,
        },
        G::Capsule { radius, length } => Shape::Capsule {
            radius: *radius,
            length: *length,
        },
        G::Sphere { radius } => Shape::Sphere { radius: *radius },
        G::Mesh { filename, scale } => Shape::Mesh {
            uri: filename.clone(),
            scale: scale.map_or([1.0; 3], |s| s.0),
        },
    };
    Geometry {
        origin: pose(o),
        shape,
        rgba: None,
    }
}

/// The urdf-rs geometry of a shape.
fn robot_geometry(s: &Shape) -> urdf_rs::Geometry {
    use urdf_rs::Geometry as G;
    match s {
        Shape::Box { size } => G::Box {
            size: urdf_rs::Vec3(*size),
        },
        Shape::Cylinder { radius, length } => G::Cylinder {
            radius: *radius,
            length: *length,
        },
        Shape::Capsule { radius, length } => G::Capsule {
            radius: *radius,
            length: *length,
        },
        Shape::Sphere { radius } => G::Sphere { radius: *radius },
        Shape::Mesh { uri, scale } => G::Mesh {
            filename: uri.clone(),
            scale: Some(urdf_rs::Vec3(*scale)),
        },
    }
}

/// An urdf-rs link of a model link: its inertia at its centre of mass, its geometry, each
/// coloured visual with a material of its own (`LINK_visual_K`).
fn robot_link(l: &crate::model::Link) -> urdf_rs::Link {
    let inertial = if l.inertial.is_zero() && l.inertial.com == Vec3::zeros() {
        urdf_rs::Inertial::default()
    } else {
        let t: &Mat3 = &l.inertial.inertia_com;
        urdf_rs::Inertial {
            origin: origin(&Se3::from_translation(l.inertial.com)),
            mass: urdf_rs::Mass {
                value: l.inertial.mass,
            },
            inertia: urdf_rs::Inertia {
                ixx: t[(0, 0)],
                ixy: t[(0, 1)],
                ixz: t[(0, 2)],
                iyy: t[(1, 1)],
                iyz: t[(1, 2)],
                izz: t[(2, 2)],
            },
        }
    };
    let visual = l
        .visuals
        .iter()
        .enumerate()
        .map(|(k, g)| urdf_rs::Visual {
            name: None,
            origin: origin(&g.origin),
            geometry: robot_geometry(&g.shape),
            material: g.rgba.map(|rgba| urdf_rs::Material {
                name: format!("{}_visual_{k}", l.name),
                color: Some(urdf_rs::Color {
                    rgba: urdf_rs::Vec4(rgba),
                }),
                texture: None,
            }),
        })
        .collect();
    let collision = l
        .collisions
        .iter()
        .map(|g| urdf_rs::Collision {
            name: None,
            origin: origin(&g.origin),
            geometry: robot_geometry(&g.shape),
        })
        .collect();
    urdf_rs::Link {
        name: l.name.clone(),
        inertial,
        visual,
        collision,
    }
}

/// An urdf-rs joint of a model joint: unlimited velocity and effort written as 0 (URDF's
/// "not given"), position limits of a continuous joint as 0.
fn robot_joint(m: &Model, j: &Joint) -> urdf_rs::Joint {
    use urdf_rs::JointType as U;
    let joint_type = match j.jtype {
        JointType::Revolute => U::Revolute,
        JointType::Continuous => U::Continuous,
        JointType::Prismatic => U::Prismatic,
        JointType::Fixed => U::Fixed,
    };
    let finite_or_zero = |v: f64| if v.is_finite() { v } else { 0.0 };
    let lim = &j.limits;
    urdf_rs::Joint {
        name: j.name.clone(),
        joint_type,
        origin: origin(&j.origin),
        parent: urdf_rs::LinkName {
            link: m.links[j.parent_link].name.clone(),
        },
        child: urdf_rs::LinkName {
            link: m.links[j.child_link].name.clone(),
        },
        axis: urdf_rs::Axis {
            xyz: urdf_rs::Vec3(j.axis.into()),
        },
        limit: urdf_rs::JointLimit {
            lower: finite_or_zero(lim.lower),
            upper: finite_or_zero(lim.upper),
            effort: finite_or_zero(lim.effort),
            velocity: finite_or_zero(lim.velocity),
            ..Default::default()
        },
        calibration: None,
        dynamics: (j.damping != 0.0 || j.friction != 0.0).then_some(urdf_rs::Dynamics {
            damping: j.damping,
            friction: j.friction,
        }),
        mimic: j.mimic.map(|(master, multiplier, offset)| urdf_rs::Mimic {
            joint: m.joints[master].name.clone(),
            multiplier: Some(multiplier),
            offset: Some(offset),
        }),
        safety_controller: None,
    }
}

/// A link with no inertia and no geometry.
fn massless_link(name: &str) -> urdf_rs::Link {
    urdf_rs::Link {
        name: name.to_string(),
        inertial: urdf_rs::Inertial::default(),
        visual: Vec::new(),
        collision: Vec::new(),
    }
}

/// A fixed joint `name` placing `child` at `t` in `parent`.
fn fixed_joint(name: String, parent: &str, child: &str, t: &Se3) -> urdf_rs::Joint {
    urdf_rs::Joint {
        name,
        joint_type: urdf_rs::JointType::Fixed,
        origin: origin(t),
        parent: urdf_rs::LinkName {
            link: parent.to_string(),
        },
        child: urdf_rs::LinkName {
            link: child.to_string(),
        },
        axis: urdf_rs::Axis::default(),
        limit: urdf_rs::JointLimit::default(),
        calibration: None,
        dynamics: None,
        mimic: None,
        safety_controller: None,
    }
}

/// Whether `t` is the identity up to [`SAME_FRAME`].
fn near_identity(t: &Se3) -> bool {
    (t.rot - Mat3::identity()).amax() <= SAME_FRAME && t.trans.amax() <= SAME_FRAME
}
