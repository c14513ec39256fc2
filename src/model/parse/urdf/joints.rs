//! `<joint>` elements: type, links, origin, axis, limits, mimic and dynamics.
//!
//! A malformed joint is an error, as in urdfdom (the tree would be wrong), except for
//! repeated child tags (the first is used) and an empty `<dynamics>`. Floating and planar
//! joints, which armsim's one-axis bodies cannot express directly, become chains of
//! one-axis joints through massless links (see [`expand`]), as Pinocchio's free-flyer and
//! planar joints place them.

use crate::core::spatial::{Se3, Vec3};
use crate::model::model_error::ModelError;
use crate::model::parse::urdf::urdf_reader::{Node, Reader};
use crate::model::spec::{JointSpec, JointType, Limits, LinkSpec, MimicSpec};

/// A `<joint>`: the joint (several for floating and planar ones) and the massless links
/// such a chain needs.
pub(super) fn read_joint(
    rd: &mut Reader<'_>,
    node: Node<'_, '_>,
) -> Result<(Vec<JointSpec>, Vec<LinkSpec>), ModelError> {
    let Some(name) = node.attribute("name") else {
        return Err(rd.err(node, "<joint>", "missing 'name' attribute"));
    };
    let el = format!("joint '{name}'");
    let Some(type_name) = node.attribute("type") else {
        return Err(rd.err(node, &el, "missing 'type' attribute"));
    };
    let jtype = match type_name {
        "revolute" => Some(JointType::Revolute),
        "continuous" => Some(JointType::Continuous),
        "prismatic" => Some(JointType::Prismatic),
        "fixed" => Some(JointType::Fixed),
        "floating" | "planar" => None,
        "spherical" => {
            return Err(rd.err(
                node,
                &el,
                "joint type 'spherical' is not supported (nor is it by urdfdom)",
            ))
        }
        other => {
            return Err(rd.err(
                node,
                &el,
                format!(
                    "unknown joint type '{other}' (expected revolute, continuous, prismatic, fixed, floating or planar)"
                ),
            ))
        }
    };
    let parent = link_ref(rd, node, "parent", &el)?;
    let child = link_ref(rd, node, "child", &el)?;
    let origin = rd.origin(node, &el).map_err(|b| rd.fail(b, &el))?;
    let axis = match rd.first(node, "axis", &el) {
        Some(a) => rd
            .vec3(a, "xyz")
            .and_then(|v| v.ok_or_else(|| rd.bad(a, "<axis>: missing 'xyz' attribute"))),
        None => Ok(Vec3::x()),
    }
    .map_err(|b| rd.fail(b, &el))?;
    let line = Some(rd.line(node));
    let Some(jtype) = jtype else {
        let floating = type_name == "floating";
        let line = Some(rd.line(node));
        let (joints, links, msgs) = expand(name, floating, (&parent, &child), origin, axis, line);
        for msg in msgs {
            rd.warn(node, &el, msg);
        }
        return Ok((joints, links));
    };
    let mut js = JointSpec::new(name, jtype, parent, child);
    js.origin = origin;
    js.axis = axis;
    js.line = line;
    js.limits = limits(rd, node, &el, jtype, type_name)?;
    js.mimic = mimic(rd, node, &el)?;
    if let Some(d) = rd.first(node, "dynamics", &el) {
        let damping = rd.scalar(d, "damping").map_err(|b| rd.fail(b, &el))?;
        let friction = rd.scalar(d, "friction").map_err(|b| rd.fail(b, &el))?;
        if damping.is_none() && friction.is_none() {
            rd.warn(
                d,
                &el,
                "<dynamics> gives neither damping nor friction: ignored",
            );
        }
        js.damping = damping.unwrap_or(0.0);
        js.friction = friction.unwrap_or(0.0);
    }
    Ok((vec![js], Vec::new()))
}

/// The `link` attribute of the first `<parent>` or `<child>`.
fn link_ref(
    rd: &mut Reader<'_>,
    node: Node<'_, '_>,
    tag: &str,
    el: &str,
) -> Result<String, ModelError> {
    let Some(n) = rd.first(node, tag, el) else {
        return Err(rd.err(node, el, format!("missing <{tag}>")));
    };
    match n.attribute("link") {
        Some(l) => Ok(l.to_string()),
        None => Err(rd.err(n, el, format!("<{tag}>: missing 'link' attribute"))),
    }
}

/// The joint's limits: a revolute or prismatic joint needs a `<limit>`, whose `effort`
/// and `velocity` are required (URDF spec, urdfdom); `lower`/`upper` default to 0.
fn limits(
    rd: &mut Reader<'_>,
    node: Node<'_, '_>,
    el: &str,
    jtype: JointType,
    type_name: &str,
) -> Result<Limits, ModelError> {
    let Some(l) = rd.first(node, "limit", el) else {
        if matches!(jtype, JointType::Revolute | JointType::Prismatic) {
            return Err(rd.err(node, el, format!("a {type_name} joint needs a <limit>")));
        }
        return Ok(Limits::unlimited());
    };
    let lower = rd.scalar(l, "lower").map_err(|b| rd.fail(b, el))?;
    let upper = rd.scalar(l, "upper").map_err(|b| rd.fail(b, el))?;
    let mut ve = [0.0; 2];
    for (k, a) in ["effort", "velocity"].iter().enumerate() {
        let v = rd.required(l, a, 1).map_err(|b| rd.fail(b, el))?[0];
        if v < 0.0 {
            return Err(rd.err(l, el, format!("<limit {a}=\"{v}\">: must not be negative")));
        }
        ve[k] = v;
    }
    Ok(limits_of(
        jtype,
        lower.unwrap_or(0.0),
        upper.unwrap_or(0.0),
        ve[0],
        ve[1],
    ))
}

/// A joint's [`Limits`] from the numbers of its `<limit>` (`lower`/`upper` 0 when not
/// given): none on a fixed joint, no position limits on a continuous one, and a zero
/// velocity or effort read as "not given", hence unlimited (URDF writes 0 for that).
pub(crate) fn limits_of(
    jtype: JointType,
    lower: f64,
    upper: f64,
    effort: f64,
    velocity: f64,
) -> Limits {
    let positive_or_inf = |v: f64| if v > 0.0 { v } else { f64::INFINITY };
    match jtype {
        JointType::Fixed => Limits::unlimited(),
        JointType::Continuous => Limits {
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            velocity: positive_or_inf(velocity),
            effort: positive_or_inf(effort),
        },
        _ => Limits {
            lower,
            upper,
            velocity: positive_or_inf(velocity),
            effort: positive_or_inf(effort),
        },
    }
}

/// The first `<mimic joint multiplier offset>`.
fn mimic(
    rd: &mut Reader<'_>,
    node: Node<'_, '_>,
    el: &str,
) -> Result<Option<MimicSpec>, ModelError> {
    let Some(m) = rd.first(node, "mimic", el) else {
        return Ok(None);
    };
    let Some(joint) = m.attribute("joint") else {
        return Err(rd.err(m, el, "<mimic>: missing 'joint' attribute"));
    };
    let multiplier = rd.scalar(m, "multiplier").map_err(|b| rd.fail(b, el))?;
    let offset = rd.scalar(m, "offset").map_err(|b| rd.fail(b, el))?;
    Ok(Some(MimicSpec {
        joint: joint.to_string(),
        multiplier: multiplier.unwrap_or(1.0),
        offset: offset.unwrap_or(0.0),
    }))
}

/// A floating joint `J` becomes `J_x`, `J_y`, `J_z` (prismatic, unbounded) then `J_yaw`,
/// `J_pitch`, `J_roll` (continuous about z, y, x): the child is placed at
/// `origin · T(x, y, z) · Rz(yaw) Ry(pitch) Rx(roll)`, Pinocchio's free-flyer pose in
/// Euler angles (singular at pitch ±90°). A planar joint `J` becomes `J_x`, `J_y`, `J_yaw`
/// in the joint frame's xy plane, which is where Pinocchio puts it whatever the `<axis>`.
/// The links between are massless and named `J_x_link`, … . Returns the joints, the links
/// and the warnings to report on the joint (what it was modelled as; a planar `<axis>`
/// that is not z). Shared by the reader and [`super::interop`].
pub(crate) fn expand(
    name: &str,
    floating: bool,
    (parent, child): (&str, &str),
    origin: Se3,
    axis: Vec3,
    line: Option<usize>,
) -> (Vec<JointSpec>, Vec<LinkSpec>, Vec<String>) {
    use JointType::{Continuous as C, Prismatic as P};
    let type_name = if floating { "floating" } else { "planar" };
    let steps: &[(&str, JointType, Vec3)] = if floating {
        &[
            ("x", P, Vec3::new(1.0, 0.0, 0.0)),
            ("y", P, Vec3::new(0.0, 1.0, 0.0)),
            ("z", P, Vec3::new(0.0, 0.0, 1.0)),
            ("yaw", C, Vec3::new(0.0, 0.0, 1.0)),
            ("pitch", C, Vec3::new(0.0, 1.0, 0.0)),
            ("roll", C, Vec3::new(1.0, 0.0, 0.0)),
        ]
    } else {
        &[
            ("x", P, Vec3::new(1.0, 0.0, 0.0)),
            ("y", P, Vec3::new(0.0, 1.0, 0.0)),
            ("yaw", C, Vec3::new(0.0, 0.0, 1.0)),
        ]
    };
    let names: Vec<String> = steps.iter().map(|s| format!("{name}_{}", s.0)).collect();
    let how = if floating {
        "translations along the joint frame's axes, then rotations Rz(yaw) Ry(pitch) Rx(roll), singular at pitch ±90°"
    } else {
        "translations in the joint frame's xy plane, then a rotation about its z, as Pinocchio places a planar joint"
    };
    let mut warnings = vec![format!(
        "{type_name} joint: modelled as the one-axis joints {} ({how})",
        names.join(", ")
    )];
    let n = axis.norm();
    if !floating && n > 0.0 && (axis.z.abs() - n).abs() > 1e-12 * n {
        warnings.push(format!(
            "planar joint: <axis xyz=\"{} {} {}\"> is not the joint frame's z: ignored (the plane is the joint frame's xy, as in Pinocchio)",
            axis.x, axis.y, axis.z
        ));
    }
    let mut joints = Vec::new();
    let mut links = Vec::new();
    let mut prev = parent.to_string();
    for (k, (suffix, jtype, ax)) in steps.iter().enumerate() {
        let next = if k + 1 == steps.len() {
            child.to_string()
        } else {
            let mut l = LinkSpec::new(format!("{name}_{suffix}_link"));
            l.line = line;
            let n = l.name.clone();
            links.push(l);
            n
        };
        let mut js = JointSpec::new(&names[k], *jtype, &prev, &next);
        js.origin = if k == 0 { origin } else { Se3::identity() };
        js.axis = *ax;
        js.line = line;
        joints.push(js);
        prev = next;
    }
    (joints, links, warnings)
}
