//! Obstacles given as Python dicts (`Planner.plan(obstacles=[...])`): `shape` ("box" with
//! `size`, "sphere" with `radius`, "cylinder" or "capsule" with `radius` and `length`),
//! optional `xyz` and `rpy` (world frame), optional `name`. Unknown keys, missing ones and
//! non-finite or non-positive sizes are refused with the obstacle's index and key.

use crate::errors::err;
use armsim::collision::Obstacle;
use armsim::core::spatial::Se3;
use armsim::model::Shape;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The obstacles of a list of dicts.
pub fn from_py(list: &Bound<'_, PyAny>) -> PyResult<Vec<Obstacle>> {
    let list = list
        .cast::<PyList>()
        .map_err(|_| err("obstacles: expected a list of dicts"))?;
    let mut out = Vec::with_capacity(list.len());
    for (i, item) in list.iter().enumerate() {
        let d = item
            .cast::<PyDict>()
            .map_err(|_| err(format!("obstacles[{i}]: expected a dict")))?;
        out.push(one(i, d)?);
    }
    Ok(out)
}

fn one(i: usize, d: &Bound<'_, PyDict>) -> PyResult<Obstacle> {
    let at = |k: &str| format!("obstacles[{i}].{k}");
    let get = |k: &str| d.get_item(k);
    let num = |k: &str| -> PyResult<f64> {
        let v: f64 = get(k)?
            .ok_or_else(|| err(format!("{}: missing", at(k))))?
            .extract()
            .map_err(|_| err(format!("{}: expected a number", at(k))))?;
        if v.is_finite() && v > 0.0 && v <= 1e4 {
            Ok(v)
        } else {
            Err(err(format!(
                "{}: expected a positive size up to 1e4 m, got {v}",
                at(k)
            )))
        }
    };
    let triple = |k: &str, default: [f64; 3], positive: bool| -> PyResult<[f64; 3]> {
        match get(k)? {
            None => Ok(default),
            Some(v) => {
                let x: Vec<f64> = v
                    .extract()
                    .map_err(|_| err(format!("{}: expected three numbers", at(k))))?;
                let ok = x.len() == 3
                    && x.iter()
                        .all(|v| v.is_finite() && v.abs() <= 1e4 && (!positive || *v > 0.0));
                if !ok {
                    return Err(err(format!(
                        "{}: expected three finite numbers{}, got {x:?}",
                        at(k),
                        if positive { " > 0 (m)" } else { "" }
                    )));
                }
                Ok([x[0], x[1], x[2]])
            }
        }
    };
    let shape_name: String = get("shape")?
        .ok_or_else(|| {
            err(format!(
                "{}: missing (box, sphere, cylinder or capsule)",
                at("shape")
            ))
        })?
        .extract()
        .map_err(|_| err(format!("{}: expected a string", at("shape"))))?;
    let (shape, keys): (Shape, &[&str]) = match shape_name.as_str() {
        "box" => {
            if get("size")?.is_none() {
                return Err(err(format!("{}: missing", at("size"))));
            }
            (
                Shape::Box {
                    size: triple("size", [0.0; 3], true)?,
                },
                &["size"],
            )
        }
        "sphere" => (
            Shape::Sphere {
                radius: num("radius")?,
            },
            &["radius"],
        ),
        "cylinder" => (
            Shape::Cylinder {
                radius: num("radius")?,
                length: num("length")?,
            },
            &["radius", "length"],
        ),
        "capsule" => (
            Shape::Capsule {
                radius: num("radius")?,
                length: num("length")?,
            },
            &["radius", "length"],
        ),
        other => {
            return Err(err(format!(
                "{}: expected box, sphere, cylinder or capsule, got '{other}'",
                at("shape")
            )))
        }
    };
    for k in d.keys() {
        let k: String = k
            .extract()
            .map_err(|_| err(format!("obstacles[{i}]: keys must be strings")))?;
        if !["name", "shape", "xyz", "rpy"].contains(&k.as_str()) && !keys.contains(&k.as_str()) {
            return Err(err(format!(
                "{}: not a key of a {shape_name} obstacle",
                at(&k)
            )));
        }
    }
    let name: String = match get("name")? {
        Some(v) => v
            .extract()
            .map_err(|_| err(format!("{}: expected a string", at("name"))))?,
        None => format!("obstacle_{i}"),
    };
    let xyz = triple("xyz", [0.0; 3], false)?;
    let rpy = triple("rpy", [0.0; 3], false)?;
    Ok(Obstacle::new(name, shape, Se3::from_xyz_rpy(xyz, rpy)))
}
