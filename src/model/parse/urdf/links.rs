//! `<link>` and `<material>` elements: inertia, visual and collision geometry, colours.
//!
//! As in urdfdom, a malformed `<inertial>`, `<visual>`, `<collision>` or `<material>` is
//! left out (or what urdfdom keeps of it is kept) with a warning that says what was done
//! instead. The one error here is a negative moment of inertia written on the diagonal.

use crate::core::spatial::{Inertia, Mat3, Se3, Vec3};
use crate::model::model_error::ModelError;
use crate::model::parse::urdf::urdf_reader::{Bad, Node, Reader};
use crate::model::spec::{Geometry, LinkSpec, Shape};
use std::collections::HashMap;

/// Colours of named materials: top-level ones, then those first defined inside a visual
/// (urdfdom makes those global too).
#[derive(Default)]
pub(super) struct Materials(HashMap<String, [f64; 4]>);

/// A top-level `<material>`: a name and an optional `<color rgba>`.
pub(super) fn read_top_material(rd: &mut Reader<'_>, node: Node<'_, '_>, mats: &mut Materials) {
    let Some(name) = node.attribute("name") else {
        rd.warn(
            node,
            "<material>",
            "missing 'name' attribute: the material is ignored",
        );
        return;
    };
    let element = format!("material '{name}'");
    if mats.0.contains_key(name) {
        rd.warn(
            node,
            &element,
            "defined more than once: the first definition is used",
        );
        return;
    }
    if let Some(rgba) = color(rd, node, &element) {
        mats.0.insert(name.to_string(), rgba);
    }
}

/// The `rgba` of the first `<color>` of a material, if well formed.
fn color(rd: &mut Reader<'_>, material: Node<'_, '_>, element: &str) -> Option<[f64; 4]> {
    let c = rd.first(material, "color", element)?;
    match rd.required(c, "rgba", 4) {
        Ok(v) => Some([v[0], v[1], v[2], v[3]]),
        Err(b) => {
            rd.warn_bad(b, element, "the colour is ignored");
            None
        }
    }
}

/// A `<link>`; `None` (with a warning) for a link without a name.
pub(super) fn read_link(
    rd: &mut Reader<'_>,
    node: Node<'_, '_>,
    mats: &mut Materials,
) -> Result<Option<LinkSpec>, ModelError> {
    let Some(name) = node.attribute("name") else {
        rd.warn(
            node,
            "<link>",
            "missing 'name' attribute: the link is ignored",
        );
        return Ok(None);
    };
    let el = format!("link '{name}'");
    let mut link = LinkSpec::new(name);
    link.line = Some(rd.line(node));
    if let Some(i) = rd.first(node, "inertial", &el) {
        link.inertial = inertial(rd, i, &el)?;
    }
    let visuals: Vec<_> = node.children().filter(|&n| rd.is(n, "visual")).collect();
    for v in visuals {
        if let Some(mut g) = geometry(rd, v, &el) {
            g.rgba = visual_color(rd, v, &el, mats);
            link.visuals.push(g);
        }
    }
    let collisions: Vec<_> = node.children().filter(|&n| rd.is(n, "collision")).collect();
    for c in collisions {
        if let Some(g) = geometry(rd, c, &el) {
            link.collisions.push(g);
        }
    }
    Ok(Some(link))
}

/// An `<inertial>`: what urdfdom keeps of a malformed one is kept (a mass without a
/// tensor is a point mass), with a warning.
fn inertial(rd: &mut Reader<'_>, node: Node<'_, '_>, el: &str) -> Result<Inertia, ModelError> {
    const IGNORED: &str = "the <inertial> is ignored (a massless link)";
    let frame = match rd.origin(node, el) {
        Ok(f) => f,
        Err(b) => {
            rd.warn_bad(b, el, IGNORED);
            return Ok(Inertia::zero());
        }
    };
    let Some(m) = rd.first(node, "mass", el) else {
        rd.warn(node, el, format!("<inertial>: missing <mass>: {IGNORED}"));
        return Ok(Inertia::zero());
    };
    let mass = match rd.required(m, "value", 1) {
        Ok(v) => v[0],
        Err(b) => {
            rd.warn_bad(b, el, IGNORED);
            return Ok(Inertia::zero());
        }
    };
    let point = |rd: &mut Reader<'_>, bad: Bad| {
        rd.warn_bad(bad, el, "the tensor is taken as zero (a point mass)");
        Inertia::new(mass, Vec3::zeros(), Mat3::zeros()).transformed(&frame)
    };
    let Some(i) = rd.first(node, "inertia", el) else {
        let bad = rd.bad(node, "<inertial>: missing <inertia>");
        return Ok(point(rd, bad));
    };
    let mut v = [0.0; 6];
    for (k, a) in ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]
        .iter()
        .enumerate()
    {
        match rd.required(i, a, 1) {
            Ok(x) => v[k] = x[0],
            Err(b) => return Ok(point(rd, b)),
        }
    }
    inertia_of(mass, v, &frame).map_err(|e| rd.err(i, el, e.to_string()))
}

/// A moment of inertia written negative on the diagonal, beyond the rounding clamped.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "<inertia {axis}=\"{value}\">: a moment of inertia cannot be negative (beyond the \
     {tol:.1e} kg m² of rounding that is clamped)"
)]
pub(crate) struct NegativeMoment {
    /// The attribute (`ixx`, `iyy`, `izz`).
    pub(crate) axis: &'static str,
    /// The moment given.
    pub(crate) value: f64,
    /// The rounding tolerance that is clamped.
    pub(crate) tol: f64,
}

/// The inertia of mass `mass` with tensor `[ixx, ixy, ixz, iyy, iyz, izz]` about its
/// centre in the `<inertial>` frame `frame`, in the link frame; a negative moment written
/// on the diagonal is refused (the message says which). Shared by the reader and
/// [`super::interop`].
pub(crate) fn inertia_of(mass: f64, v: [f64; 6], frame: &Se3) -> Result<Inertia, NegativeMoment> {
    let [xx, xy, xz, yy, yz, zz] = v;
    // A negative moment written on the diagonal is not a rigid body, whatever the axes.
    let tol = crate::model::inertia_check::clamp_tolerance(xx.max(yy).max(zz));
    if let Some((a, d)) = [("ixx", xx), ("iyy", yy), ("izz", zz)]
        .into_iter()
        .find(|&(_, d)| d < -tol)
    {
        return Err(NegativeMoment {
            axis: a,
            value: d,
            tol,
        });
    }
    let tensor = Mat3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    Ok(Inertia::new(mass, Vec3::zeros(), tensor).transformed(frame))
}

/// A `<visual>` or `<collision>`'s origin and shape; `None` (with a warning) when either
/// is unusable.
fn geometry(rd: &mut Reader<'_>, node: Node<'_, '_>, el: &str) -> Option<Geometry> {
    let kind = node.tag_name().name();
    let ignored = format!("the <{kind}> is ignored");
    let origin = match rd.origin(node, el) {
        Ok(o) => o,
        Err(b) => {
            rd.warn_bad(b, el, &ignored);
            return None;
        }
    };
    let Some(g) = rd.first(node, "geometry", el) else {
        rd.warn(node, el, format!("<{kind}>: missing <geometry>: {ignored}"));
        return None;
    };
    match shape(rd, g, el) {
        Ok(shape) => Some(Geometry {
            origin,
            shape,
            rgba: None,
        }),
        Err(b) => {
            rd.warn_bad(b, el, &ignored);
            None
        }
    }
}

/// The first shape of a `<geometry>`.
fn shape(rd: &mut Reader<'_>, geom: Node<'_, '_>, el: &str) -> Result<Shape, Bad> {
    const KNOWN: &str = "<box>, <cylinder>, <sphere>, <capsule> or <mesh>";
    let mut shapes = geom.children().filter(|n| n.is_element());
    let Some(s) = shapes.next() else {
        return Err(rd.bad(geom, format!("<geometry>: no shape (expected {KNOWN})")));
    };
    let tag = s.tag_name().name();
    if let Some(extra) = shapes.next() {
        rd.warn(
            extra,
            el,
            format!("<geometry>: more than one shape: the first (<{tag}>) is used"),
        );
    }
    Ok(match tag {
        "box" => {
            let v = rd.required(s, "size", 3)?;
            Shape::Box {
                size: [v[0], v[1], v[2]],
            }
        }
        "sphere" => Shape::Sphere {
            radius: rd.required(s, "radius", 1)?[0],
        },
        "cylinder" => Shape::Cylinder {
            radius: rd.required(s, "radius", 1)?[0],
            length: rd.required(s, "length", 1)?[0],
        },
        "capsule" => Shape::Capsule {
            radius: rd.required(s, "radius", 1)?[0],
            length: rd.required(s, "length", 1)?[0],
        },
        "mesh" => mesh(rd, s, el)?,
        other => return Err(rd.bad(s, format!("unknown geometry <{other}> (expected {KNOWN})"))),
    })
}

/// A `<mesh filename scale>`; one scale number is a uniform scale (with a warning).
fn mesh(rd: &mut Reader<'_>, s: Node<'_, '_>, el: &str) -> Result<Shape, Bad> {
    let Some(uri) = s.attribute("filename") else {
        return Err(rd.bad(s, "<mesh>: missing 'filename' attribute"));
    };
    let scale = match rd.numbers(s, "scale", 3) {
        Ok(v) => v.map_or([1.0; 3], |v| [v[0], v[1], v[2]]),
        Err(b) => match rd.numbers(s, "scale", 1) {
            Ok(Some(u)) => {
                let msg = format!(
                    "<mesh scale=\"{}\">: one number: taken as a uniform scale",
                    u[0]
                );
                rd.warn(s, el, msg);
                [u[0]; 3]
            }
            _ => return Err(b),
        },
    };
    Ok(Shape::Mesh {
        uri: uri.to_string(),
        scale,
    })
}

/// The colour of a `<visual>`: its material's own `<color>`, else the named material's.
fn visual_color(
    rd: &mut Reader<'_>,
    visual: Node<'_, '_>,
    el: &str,
    mats: &mut Materials,
) -> Option<[f64; 4]> {
    let m = rd.first(visual, "material", el)?;
    let Some(name) = m.attribute("name") else {
        rd.warn(
            m,
            el,
            "<material>: missing 'name' attribute: the material is ignored",
        );
        return None;
    };
    match color(rd, m, el) {
        Some(rgba) => {
            mats.0.entry(name.to_string()).or_insert(rgba);
            Some(rgba)
        }
        None => mats.0.get(name).copied(),
    }
}
