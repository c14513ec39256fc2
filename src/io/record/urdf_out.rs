//! The `/robot_description` of a recording: URDF text for any model armsim loads.
//!
//! Owned here: [`robot_description`] (the original text for URDF models),
//! [`generate_urdf`] (a URDF for a [`ModelSpec`] from a DH table or a generated chain) and
//! [`absolute_mesh_uris`] (every mesh URI that resolves on this machine rewritten as an
//! absolute `file://` URI, so that viewers of a recording find the meshes).
//!
//! The generated URDF loads back into [`crate::model::Model`] with the same link frames and
//! joint coordinates:
//! - a joint whose spec has a distal `child_offset` (standard DH: `Rz(θ) Tz(d) Tx(a)
//!   Rx(α)` after the joint motion) becomes the movable joint into an extra massless link
//!   `<child>_joint_frame`, then a fixed joint `<child>_offset` carrying the offset;
//! - a base offset becomes a fixed joint `world_joint` from an extra `world` link;
//! - rotations are written as URDF `rpy` by a decomposition that stays accurate at
//!   pitch = ±90° (round trip error ~1e-16); numbers are printed in shortest round-trip
//!   form.
//!
//! Infinite limits are written the URDF way: revolute joints without position limits as
//! `continuous`, prismatic ones as ±`f64::MAX`, and infinite effort or velocity as `0`
//! (which armsim's URDF loader reads as "none"). URDF cannot hold gravity, rotor inertia or
//! gear ratios; the file says so in a comment when the model has them.
//!
//! Models without visual geometry get simple shapes for viewers: a sphere on the root, a
//! cylinder along each movable joint's axis, a cylinder for every link offset, a small
//! sphere on each leaf link.

use crate::collision::resolve::{file_uri, resolve_with, PackagePaths};
use crate::core::spatial::{rot_z, rotation_z_to, Mat3, Se3, Vec3};
use crate::model::{Geometry, JointType, ModelSpec, Shape};
use std::collections::{HashMap, HashSet};
use std::fmt::Write as _;
use std::path::Path;

/// The URDF text of a model: the file's own text when the model came from a URDF (as
/// kept in the spec, or read again from `model_path`), else [`generate_urdf`].
pub fn robot_description(model_path: &Path, spec: &ModelSpec) -> String {
    if let Some(text) = &spec.urdf_text {
        return text.clone();
    }
    let ext = model_path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "urdf" || ext == "xml" {
        if let Ok(text) = crate::core::files::read_input_string(model_path) {
            return text;
        }
    }
    generate_urdf(spec)
}

/// `urdf` with the `filename` of every `<mesh>` that resolves (against `base`, the model
/// file's directory, and `pkgs`; see [`crate::collision::resolve`]) replaced by the
/// absolute `file://` URI of its file. Meshes that do not resolve keep their URI and are
/// returned as `(uri, why)`; the rest of the text is untouched. Text that is not XML is
/// returned as it is.
pub fn absolute_mesh_uris(
    urdf: &str,
    base: Option<&Path>,
    pkgs: &PackagePaths,
) -> (String, Vec<(String, String)>) {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    // The model loader refuses deeper files; the pre-scan keeps roxmltree's recursion
    // off a deep text that reaches here first.
    if crate::core::xml_guard::too_deep(urdf, 256).is_some() {
        return (urdf.to_string(), Vec::new());
    }
    let Ok(doc) = roxmltree::Document::parse_with_options(urdf, opts) else {
        return (urdf.to_string(), Vec::new());
    };
    let mut edits: Vec<(std::ops::Range<usize>, String)> = Vec::new();
    let mut missing = Vec::new();
    for node in doc.descendants().filter(|n| n.has_tag_name("mesh")) {
        let Some(attr) = node.attributes().find(|a| a.name() == "filename") else {
            continue;
        };
        match resolve_with(attr.value(), base, pkgs) {
            Ok(p) => edits.push((attr.range_value(), esc(&file_uri(&p)))),
            Err(e) => {
                if !missing
                    .iter()
                    .any(|(u, _): &(String, String)| u == attr.value())
                {
                    missing.push((attr.value().to_string(), e.0));
                }
            }
        }
    }
    let mut out = String::with_capacity(urdf.len() + 64 * edits.len());
    let mut at = 0;
    for (range, uri) in edits {
        out.push_str(&urdf[at..range.start]);
        out.push_str(&uri);
        at = range.end;
    }
    out.push_str(&urdf[at..]);
    (out, missing)
}

/// URDF roll-pitch-yaw of a rotation (`R = Rz(yaw) Ry(pitch) Rx(roll)`), accurate at and
/// near pitch = ±90°: the yaw is removed exactly before roll and pitch are read.
pub fn matrix_to_rpy_robust(r: &Mat3) -> [f64; 3] {
    let yaw = r[(1, 0)].atan2(r[(0, 0)]);
    let rp = rot_z(-yaw) * r; // = Ry(pitch) Rx(roll)
    let pitch = (-rp[(2, 0)]).atan2(rp[(0, 0)]);
    let roll = (-rp[(1, 2)]).atan2(rp[(1, 1)]);
    [roll, pitch, yaw]
}

/// Shortest text that parses back to the same value.
fn num(x: f64) -> String {
    format!("{x:?}")
}

fn nums(v: &[f64]) -> String {
    v.iter().map(|&x| num(x)).collect::<Vec<_>>().join(" ")
}

fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

fn origin(p: &Se3) -> String {
    let rpy = matrix_to_rpy_robust(&p.rot);
    format!(
        "<origin xyz=\"{}\" rpy=\"{}\"/>",
        nums(&[p.trans.x, p.trans.y, p.trans.z]),
        nums(&rpy)
    )
}

fn shape(s: &Shape) -> String {
    match s {
        Shape::Box { size } => format!("<box size=\"{}\"/>", nums(size)),
        Shape::Cylinder { radius, length } => format!(
            "<cylinder radius=\"{}\" length=\"{}\"/>",
            num(*radius),
            num(*length)
        ),
        Shape::Capsule { radius, length } => format!(
            "<capsule radius=\"{}\" length=\"{}\"/>",
            num(*radius),
            num(*length)
        ),
        Shape::Sphere { radius } => format!("<sphere radius=\"{}\"/>", num(*radius)),
        Shape::Mesh { uri, scale } => format!(
            "<mesh filename=\"{}\" scale=\"{}\"/>",
            esc(uri),
            nums(scale)
        ),
    }
}

/// One `<visual>` or `<collision>` element.
fn geometry(tag: &str, g: &Geometry, material: Option<&str>) -> String {
    let mut s = format!(
        "    <{tag}>\n      {}\n      <geometry>{}</geometry>\n",
        origin(&g.origin),
        shape(&g.shape)
    );
    match (g.rgba, material) {
        (Some(c), _) if tag == "visual" => {
            let _ = writeln!(
                s,
                "      <material name=\"rgba {0}\"><color rgba=\"{0}\"/></material>",
                nums(&c)
            );
        }
        (None, Some(m)) => {
            let _ = writeln!(s, "      <material name=\"{m}\"/>");
        }
        _ => {}
    }
    let _ = writeln!(s, "    </{tag}>");
    s
}

/// A cylinder from the origin to `to`, or `None` for a zero-length segment.
fn segment(to: &Vec3, radius: f64) -> Option<Geometry> {
    let len = to.norm();
    if len < 1e-9 {
        return None;
    }
    let origin = Se3::new(rotation_z_to(&(to / len)), to * 0.5);
    Some(Geometry {
        origin,
        shape: Shape::Cylinder {
            radius,
            length: len,
        },
        rgba: None,
    })
}

/// Names not yet taken in `used`: `base`, else `base_1`, `base_2`, ...
fn unique(used: &mut HashSet<String>, base: &str) -> String {
    let mut name = base.to_string();
    let mut k = 1;
    while used.contains(&name) {
        name = format!("{base}_{k}");
        k += 1;
    }
    used.insert(name.clone());
    name
}

/// A URDF joint as it will be written.
struct UJoint {
    name: String,
    jtype: JointType,
    parent: String,
    child: String,
    origin: Se3,
    axis: Vec3,
    spec: Option<usize>,
}

/// The frames the generated URDF adds to a spec's links, so that recorded transforms can
/// follow the same tree (see [`crate::io::record::tf::RobotTf`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UrdfLayout {
    /// The link above a base offset (`world`), when the spec has a base offset.
    pub world: Option<String>,
    /// Joint name → the intermediate link that is the joint's URDF child, for joints with a
    /// distal offset (the offset then joins it to the spec's child link).
    pub joint_frames: HashMap<String, String>,
}

/// The [`UrdfLayout`] of [`generate_urdf`]`(spec)`; empty for specs read from a URDF.
pub fn urdf_layout(spec: &ModelSpec) -> UrdfLayout {
    urdf_joints(spec).2
}

/// The URDF's extra links, its joints, and the layout.
fn urdf_joints(spec: &ModelSpec) -> (Vec<String>, Vec<UJoint>, UrdfLayout) {
    let mut link_names: HashSet<String> = spec.links.iter().map(|l| l.name.clone()).collect();
    let mut joint_names: HashSet<String> = spec.joints.iter().map(|j| j.name.clone()).collect();
    let mut joints: Vec<UJoint> = Vec::new();
    let mut extra_links: Vec<String> = Vec::new();
    let mut layout = UrdfLayout::default();
    let children: HashSet<&str> = spec.joints.iter().map(|j| j.child.as_str()).collect();
    if spec.root_offset != Se3::identity() {
        let world = unique(&mut link_names, "world");
        extra_links.push(world.clone());
        layout.world = Some(world.clone());
        for r in spec
            .links
            .iter()
            .filter(|l| !children.contains(l.name.as_str()))
        {
            joints.push(UJoint {
                name: unique(&mut joint_names, "world_joint"),
                jtype: JointType::Fixed,
                parent: world.clone(),
                child: r.name.clone(),
                origin: spec.root_offset,
                axis: Vec3::z(),
                spec: None,
            });
        }
    }
    for (i, j) in spec.joints.iter().enumerate() {
        if j.child_offset == Se3::identity() {
            joints.push(UJoint {
                name: j.name.clone(),
                jtype: j.jtype,
                parent: j.parent.clone(),
                child: j.child.clone(),
                origin: j.origin,
                axis: j.axis,
                spec: Some(i),
            });
        } else {
            let mid = unique(&mut link_names, &format!("{}_joint_frame", j.child));
            extra_links.push(mid.clone());
            layout.joint_frames.insert(j.name.clone(), mid.clone());
            joints.push(UJoint {
                name: j.name.clone(),
                jtype: j.jtype,
                parent: j.parent.clone(),
                child: mid.clone(),
                origin: j.origin,
                axis: j.axis,
                spec: Some(i),
            });
            joints.push(UJoint {
                name: unique(&mut joint_names, &format!("{}_offset", j.child)),
                jtype: JointType::Fixed,
                parent: mid,
                child: j.child.clone(),
                origin: j.child_offset,
                axis: Vec3::z(),
                spec: None,
            });
        }
    }
    (extra_links, joints, layout)
}

/// Generated visuals of a model without any, by link: a rod along each joint offset, a
/// cylinder on each movable joint's axis, a sphere on the roots and the leaves.
type Visuals = HashMap<String, Vec<(Geometry, &'static str)>>;

/// A URDF for `spec` (see the module docs).
pub fn generate_urdf(spec: &ModelSpec) -> String {
    let (extra_links, joints, _) = urdf_joints(spec);
    let generate = spec.links.iter().all(|l| l.visuals.is_empty());
    let visuals = if generate {
        generated_visuals(spec, &joints)
    } else {
        HashMap::new()
    };
    let mut s = String::new();
    write_header(&mut s, spec, generate);
    for name in &extra_links {
        write_link(&mut s, name, None, &visuals);
    }
    for l in &spec.links {
        write_link(&mut s, &l.name, Some(l), &visuals);
    }
    for j in &joints {
        write_joint(&mut s, j, spec);
    }
    let _ = writeln!(s, "</robot>");
    s
}

/// The visuals drawn for a model that has none (see [`Visuals`]); their size follows
/// the arm's reach.
fn generated_visuals(spec: &ModelSpec, joints: &[UJoint]) -> Visuals {
    let children: HashSet<&str> = spec.joints.iter().map(|j| j.child.as_str()).collect();
    let roots: Vec<&str> = spec
        .links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|n| !children.contains(n))
        .collect();
    let reach: f64 = joints.iter().map(|j| j.origin.trans.norm()).sum();
    let r = (0.025 * reach).clamp(0.005, 0.06);
    let mut visuals: Visuals = HashMap::new();
    for j in joints {
        if let Some(g) = segment(&j.origin.trans, 0.6 * r) {
            visuals
                .entry(j.parent.clone())
                .or_default()
                .push((g, "armsim_link"));
        }
        if j.jtype.is_movable() && j.axis.norm() > 0.0 {
            let g = Geometry {
                origin: Se3::from_rotation(rotation_z_to(&j.axis.normalize())),
                shape: Shape::Cylinder {
                    radius: r,
                    length: 3.0 * r,
                },
                rgba: None,
            };
            visuals
                .entry(j.child.clone())
                .or_default()
                .push((g, "armsim_joint"));
        }
    }
    let parents: HashSet<&str> = joints.iter().map(|j| j.parent.as_str()).collect();
    for l in spec.links.iter().map(|l| l.name.as_str()) {
        let radius = if roots.contains(&l) {
            1.5 * r
        } else if !parents.contains(l) {
            0.6 * r
        } else {
            continue;
        };
        let g = Geometry {
            origin: Se3::identity(),
            shape: Shape::Sphere { radius },
            rgba: None,
        };
        visuals
            .entry(l.to_string())
            .or_default()
            .push((g, "armsim_joint"));
    }
    visuals
}

/// The XML declaration, the provenance comment, what URDF cannot hold (gravity, rotor
/// inertia, gear ratio), the robot element and the generated visuals' materials.
fn write_header(s: &mut String, spec: &ModelSpec, generate: bool) {
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<!-- Generated by armsim {} from {}. -->",
        env!("CARGO_PKG_VERSION"),
        esc(&spec.source).replace("--", "- -")
    );
    let mut lost = Vec::new();
    if let Some(g) = spec.gravity {
        lost.push(format!("gravity = [{}]", nums(&[g.x, g.y, g.z])));
    }
    for j in &spec.joints {
        if j.motor_inertia != 0.0 || j.gear_ratio != 1.0 {
            lost.push(format!(
                "{}: motor_inertia = {}, gear_ratio = {}",
                j.name,
                num(j.motor_inertia),
                num(j.gear_ratio)
            ));
        }
    }
    if !lost.is_empty() {
        let _ = writeln!(
            s,
            "<!-- Not representable in URDF: {}. -->",
            esc(&lost.join("; ")).replace("--", "- -")
        );
    }
    let _ = writeln!(s, "<robot name=\"{}\">", esc(&spec.name));
    if generate {
        let _ = writeln!(
            s,
            "  <material name=\"armsim_link\"><color rgba=\"0.75 0.75 0.78 1\"/></material>"
        );
        let _ = writeln!(
            s,
            "  <material name=\"armsim_joint\"><color rgba=\"0.95 0.55 0.15 1\"/></material>"
        );
    }
}

/// A `<link>`: its inertial, visuals and collisions (from `l`; none for an intermediate
/// link), and its generated visuals.
fn write_link(s: &mut String, name: &str, l: Option<&crate::model::LinkSpec>, visuals: &Visuals) {
    let _ = writeln!(s, "  <link name=\"{}\">", esc(name));
    if let Some(l) = l {
        let i = &l.inertial;
        if !i.is_zero() {
            let t = &i.inertia_com;
            let _ = writeln!(
                s,
                "    <inertial>\n      <origin xyz=\"{}\" rpy=\"0 0 0\"/>\n      <mass value=\"{}\"/>\n      \
<inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>\n    </inertial>",
                nums(&[i.com.x, i.com.y, i.com.z]),
                num(i.mass),
                num(t[(0, 0)]),
                num(t[(0, 1)]),
                num(t[(0, 2)]),
                num(t[(1, 1)]),
                num(t[(1, 2)]),
                num(t[(2, 2)])
            );
        }
        for g in &l.visuals {
            s.push_str(&geometry("visual", g, None));
        }
        for g in &l.collisions {
            s.push_str(&geometry("collision", g, None));
        }
    }
    for (g, m) in visuals.get(name).into_iter().flatten() {
        s.push_str(&geometry("visual", g, Some(m)));
    }
    let _ = writeln!(s, "  </link>");
}

/// A `<joint>`: type (continuous for an unlimited revolute joint), parent, child, origin,
/// axis, and from the spec its limits, mimic relation and dynamics.
fn write_joint(s: &mut String, j: &UJoint, spec: &ModelSpec) {
    let js = j.spec.and_then(|i| spec.joints.get(i));
    let lim = js.map(|js| js.limits);
    let jtype = match (j.jtype, lim) {
        (JointType::Revolute, Some(l)) if l.lower.is_infinite() && l.upper.is_infinite() => {
            JointType::Continuous
        }
        (t, _) => t,
    };
    let _ = writeln!(
        s,
        "  <joint name=\"{}\" type=\"{}\">\n    <parent link=\"{}\"/>\n    <child link=\"{}\"/>\n    {}",
        esc(&j.name),
        jtype.as_str(),
        esc(&j.parent),
        esc(&j.child),
        origin(&j.origin)
    );
    if jtype.is_movable() {
        let _ = writeln!(
            s,
            "    <axis xyz=\"{}\"/>",
            nums(&[j.axis.x, j.axis.y, j.axis.z])
        );
    }
    if let (Some(js), Some(l)) = (js, lim) {
        let finite_or_zero = |x: f64| if x.is_finite() { x } else { 0.0 };
        let bound = |x: f64| x.clamp(f64::MIN, f64::MAX);
        match jtype {
            JointType::Revolute | JointType::Prismatic => {
                let _ = writeln!(
                    s,
                    "    <limit lower=\"{}\" upper=\"{}\" effort=\"{}\" velocity=\"{}\"/>",
                    num(bound(l.lower)),
                    num(bound(l.upper)),
                    num(finite_or_zero(l.effort)),
                    num(finite_or_zero(l.velocity))
                );
            }
            JointType::Continuous if l.effort.is_finite() || l.velocity.is_finite() => {
                let _ = writeln!(
                    s,
                    "    <limit effort=\"{}\" velocity=\"{}\"/>",
                    num(finite_or_zero(l.effort)),
                    num(finite_or_zero(l.velocity))
                );
            }
            _ => {}
        }
        if let Some(m) = &js.mimic {
            let _ = writeln!(
                s,
                "    <mimic joint=\"{}\" multiplier=\"{}\" offset=\"{}\"/>",
                esc(&m.joint),
                num(m.multiplier),
                num(m.offset)
            );
        }
        if js.damping != 0.0 || js.friction != 0.0 {
            let _ = writeln!(
                s,
                "    <dynamics damping=\"{}\" friction=\"{}\"/>",
                num(js.damping),
                num(js.friction)
            );
        }
    }
    let _ = writeln!(s, "  </joint>");
}

#[cfg(test)]
mod tests {
    use crate::core::spatial::rpy_to_matrix;
    use crate::io::record::urdf_out::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn rpy_round_trip_including_gimbal_lock() {
        let cases = [
            [0.1, 0.2, 0.3],
            [0.4, FRAC_PI_2, -1.0],
            [0.4, -FRAC_PI_2, 2.0],
            [-2.5, FRAC_PI_2 - 1e-9, 3.0],
            [3.1, -1.2, -3.1],
        ];
        for rpy in cases {
            let r = rpy_to_matrix(rpy);
            let back = rpy_to_matrix(matrix_to_rpy_robust(&r));
            assert!((back - r).abs().max() < 1e-15, "{rpy:?}");
        }
    }

    #[test]
    fn numbers_round_trip() {
        for x in [0.1, -1e-17, 1.0 / 3.0, 12345.678, f64::MAX] {
            assert_eq!(num(x).parse::<f64>().unwrap(), x);
        }
    }
}
