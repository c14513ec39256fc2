//! Arguments from Python: vectors and row batches as `f64` slices (numpy arrays are
//! read in place; lists and other sequences are copied), checked for length and NaN
//! before anything reaches the Rust algorithms; frame / expression arguments; counts,
//! indices and seeds (taken as [`Int`], any Python integer, so that a negative or huge
//! value gets a message naming the argument instead of a bare `OverflowError`).

use crate::errors::err;
use armsim::{Expressed, Model};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// A 1-D argument: a contiguous float64 numpy array read in place, or an owned copy.
///
/// The in-place read skips numpy's borrow registry (it costs more than the small
/// algorithms): the functions that take a `Vector` hold the GIL from reading to the end of
/// the computation and never write into an argument, so no Rust borrow can alias it and
/// Python code cannot run in between. The slice borrows the argument, which keeps the
/// array alive.
pub enum Vector<'a> {
    Array(&'a [f64]),
    Owned(Vec<f64>),
}

impl Vector<'_> {
    pub fn slice(&self) -> &[f64] {
        match self {
            Vector::Array(s) => s,
            Vector::Owned(v) => v,
        }
    }
}

/// Index of the first non-finite value.
fn first_bad(x: &[f64]) -> Option<usize> {
    x.iter().position(|v| !v.is_finite())
}

/// Reads `obj` as a vector of `n` finite values called `what`.
pub fn vector<'a>(obj: &'a Bound<'_, PyAny>, what: &str, n: usize) -> PyResult<Vector<'a>> {
    let v = match obj.cast::<PyArray1<f64>>() {
        // SAFETY: contiguous (checked); read without the borrow registry, see `Vector`.
        Ok(a) if a.is_c_contiguous() => {
            Vector::Array(unsafe { a.as_slice() }.expect("checked contiguous"))
        }
        Ok(a) => Vector::Owned(a.readonly().as_array().to_vec()),
        Err(_) => Vector::Owned(obj.extract::<Vec<f64>>().map_err(|_| {
            err(format!(
                "{what}: expected a 1-D sequence of {n} floats, got {}",
                type_name(obj)
            ))
        })?),
    };
    let s = v.slice();
    if s.len() != n {
        return Err(err(format!(
            "{what}: {} values for {n} coordinates",
            s.len()
        )));
    }
    if let Some(i) = first_bad(s) {
        return Err(err(format!("{what}[{i}] is not finite ({})", s[i])));
    }
    Ok(v)
}

/// `obj`'s shape as numpy sees it, for messages.
fn dims(obj: &Bound<'_, PyAny>) -> String {
    obj.py()
        .import("numpy")
        .and_then(|np| np.call_method1("shape", (obj,)))
        .and_then(|s| s.str().map(|s| s.to_string()))
        .unwrap_or_else(|_| type_name(obj))
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// A row-major batch of `rows × cols` finite values (`cols` checked), as owned or
/// borrowed data.
pub struct Rows<'py> {
    arr: Option<PyReadonlyArray2<'py, f64>>,
    owned: Vec<f64>,
    pub rows: usize,
}

impl Rows<'_> {
    pub fn slice(&self) -> &[f64] {
        match &self.arr {
            Some(a) => a.as_slice().expect("checked contiguous"),
            None => &self.owned,
        }
    }
}

/// `obj` as a C-ordered float64 numpy array when it is not one already (float32 and
/// integer arrays, nested lists: what the single-call functions accept), or an error
/// naming `what`, the expected shape and what was given.
fn as_float64<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    shape: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let np = obj.py().import("numpy")?;
    let given = match obj.getattr("dtype") {
        Ok(d) => format!("{} of dtype {}", type_name(obj), d),
        Err(_) => type_name(obj),
    };
    np.call_method1("ascontiguousarray", (obj, "float64"))
        .map_err(|_| {
            err(format!(
                "{what}: expected numbers of shape {shape}, got {given}"
            ))
        })
}

/// Reads `obj` as an `(N, cols)` array of finite values called `what` (float64 arrays
/// are read in place; other numbers are converted first).
pub fn rows<'py>(obj: &Bound<'py, PyAny>, what: &str, cols: usize) -> PyResult<Rows<'py>> {
    let shape = format!("(N, {cols})");
    let a = match obj.extract::<PyReadonlyArray2<'py, f64>>() {
        Ok(a) => a,
        Err(_) => as_float64(obj, what, &shape)?
            .extract::<PyReadonlyArray2<'py, f64>>()
            .map_err(|_| err(format!("{what}: expected shape {shape}, got {}", dims(obj))))?,
    };
    let shape = a.shape().to_vec();
    if shape[1] != cols {
        return Err(err(format!(
            "{what}: shape ({}, {}), expected (N, {cols})",
            shape[0], shape[1]
        )));
    }
    let r = if a.is_c_contiguous() {
        Rows {
            arr: Some(a),
            owned: Vec::new(),
            rows: shape[0],
        }
    } else {
        Rows {
            owned: a.as_array().iter().copied().collect(),
            arr: None,
            rows: shape[0],
        }
    };
    if let Some(i) = first_bad(r.slice()) {
        return Err(err(format!(
            "{what}[{}, {}] is not finite",
            i / cols.max(1),
            i % cols.max(1)
        )));
    }
    Ok(r)
}

/// Reads `obj` as `(N, 4, 4)` homogeneous transforms (row-major per target).
pub fn poses(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[f64; 16]>> {
    let a = match obj.extract::<PyReadonlyArray3<'_, f64>>() {
        Ok(a) => a,
        Err(_) => as_float64(obj, what, "(N, 4, 4)")?
            .extract::<PyReadonlyArray3<'_, f64>>()
            .map_err(|_| {
                err(format!(
                    "{what}: expected shape (N, 4, 4), got {}",
                    dims(obj)
                ))
            })?,
    };
    let shape = a.shape();
    if shape[1] != 4 || shape[2] != 4 {
        return Err(err(format!(
            "{what}: shape ({}, {}, {}), expected (N, 4, 4)",
            shape[0], shape[1], shape[2]
        )));
    }
    let flat: Vec<f64> = a.as_array().iter().copied().collect();
    flat.chunks(16)
        .enumerate()
        .map(|(i, c)| {
            let mut t = [0.0; 16];
            t.copy_from_slice(c);
            crate::convert::check_pose(&t).map_err(|m| err(format!("{what}[{i}]: {m}")))?;
            Ok(t)
        })
        .collect()
}

/// A Python integer argument of any size (counts, indices, seeds). pyo3's own `i128`
/// raises a bare `OverflowError` beyond ±2^127, without the argument's name; this keeps
/// such a value (its sign and how to print it) so that [`size`] and [`seed`] can refuse
/// it with a message naming the argument. Not an integer: pyo3's `TypeError` naming the
/// argument, as for `i128`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Int {
    /// Within `i128`.
    Fits(i128),
    /// Beyond `i128`: its sign and its decimal text (or its size in bits when long).
    Huge { negative: bool, text: String },
}

impl From<i128> for Int {
    fn from(x: i128) -> Int {
        Int::Fits(x)
    }
}

impl<'a, 'py> FromPyObject<'a, 'py> for Int {
    type Error = PyErr;

    fn extract(obj: pyo3::Borrowed<'a, 'py, PyAny>) -> PyResult<Int> {
        match obj.extract::<i128>() {
            Ok(x) => Ok(Int::Fits(x)),
            Err(e) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()) => {
                let negative = obj.lt(0)?;
                // `str` of a very long int raises (Python's 4300-digit limit): give its size.
                let text = match obj.str() {
                    Ok(t) if t.len().is_ok_and(|n| n <= 80) => t.to_string(),
                    _ => format!(
                        "an integer of {} bits",
                        obj.call_method0("bit_length")?.extract::<u64>()?
                    ),
                };
                Ok(Int::Huge { negative, text })
            }
            Err(e) => Err(e),
        }
    }
}

/// `x` as a count or index called `what`: an error naming it unless `0 <= x` (and
/// `x` fits the platform's `usize`).
pub fn size(x: impl Into<Int>, what: &str) -> PyResult<usize> {
    in_range(x.into(), what, usize::MAX as u128)
}

/// `x` as a seed or a stream position called `what` (`0 … 2^64 − 1`), or an error
/// naming it.
pub fn seed(x: impl Into<Int>, what: &str) -> PyResult<u64> {
    in_range(x.into(), what, u64::MAX as u128)
}

/// `x` as a `T` (non-negative, at most `max`), or an error naming `what`.
fn in_range<T: TryFrom<i128>>(x: Int, what: &str, max: u128) -> PyResult<T> {
    match &x {
        Int::Fits(v) => T::try_from(*v).ok(),
        Int::Huge { .. } => None,
    }
    .ok_or_else(|| out_of_range(&x, what, max))
}

fn out_of_range(x: &Int, what: &str, max: u128) -> PyErr {
    let (negative, text) = match x {
        Int::Fits(v) => (*v < 0, v.to_string()),
        Int::Huge { negative, text } => (*negative, text.clone()),
    };
    if negative {
        err(format!(
            "{what}: expected a non-negative integer, got {text}"
        ))
    } else {
        err(format!(
            "{what}: {text} is larger than the largest accepted, {max}"
        ))
    }
}

/// A frame given by index or name.
pub fn frame(model: &Model, obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    if let Ok(i) = obj.extract::<Int>() {
        let n = model.links.len();
        return match &i {
            Int::Fits(k) => usize::try_from(*k).ok().filter(|&k| k < n),
            Int::Huge { .. } => None,
        }
        .ok_or_else(|| {
            let text = match i {
                Int::Fits(k) => k.to_string(),
                Int::Huge { text, .. } => text,
            };
            err(format!(
                "frame index {text} does not exist ({} has {n} frames)",
                model.name
            ))
        });
    }
    let name: String = obj
        .extract()
        .map_err(|_| err("frame: expected a frame index (int) or a frame name (str)"))?;
    frame_by_name(model, &name)
}

/// The frame called `name`, or an error listing the frames.
pub fn frame_by_name(model: &Model, name: &str) -> PyResult<usize> {
    model.link_id(name).ok_or_else(|| {
        let known: Vec<&str> = model.links.iter().map(|l| l.name.as_str()).collect();
        err(format!(
            "no frame '{name}' in {}; the frames are: {}",
            model.name,
            known.join(", ")
        ))
    })
}

/// The optional `reference` argument of the frame functions: [`expressed_obj`], or
/// `"world_aligned"` (LOCAL_WORLD_ALIGNED) when not given.
pub fn reference(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Expressed> {
    obj.map_or(Ok(Expressed::WorldAligned), expressed_obj)
}

/// [`expressed`] on a Python string, comparing with interned constants first (reading
/// a `str` costs an allocation under the abi3 API of Python 3.9).
pub fn expressed_obj(obj: &Bound<'_, PyAny>) -> PyResult<Expressed> {
    let py = obj.py();
    let known = [
        (pyo3::intern!(py, "world_aligned"), Expressed::WorldAligned),
        (pyo3::intern!(py, "local"), Expressed::Local),
        (pyo3::intern!(py, "world"), Expressed::World),
    ];
    for (s, e) in &known {
        if obj.is(s) {
            return Ok(*e);
        }
    }
    let s: String = obj
        .extract()
        .map_err(|_| err("reference: expected a string"))?;
    expressed(&s)
}

/// `"world_aligned"` (`"local_world_aligned"`), `"local"` or `"world"`.
pub fn expressed(s: &str) -> PyResult<Expressed> {
    match s {
        "world_aligned" => return Ok(Expressed::WorldAligned),
        "local" => return Ok(Expressed::Local),
        "world" => return Ok(Expressed::World),
        _ => {}
    }
    match s.to_ascii_lowercase().replace('-', "_").as_str() {
        "world_aligned" | "local_world_aligned" => Ok(Expressed::WorldAligned),
        "local" => Ok(Expressed::Local),
        "world" => Ok(Expressed::World),
        _ => Err(err(format!(
            "unknown reference frame '{s}': expected \"world_aligned\" (LOCAL_WORLD_ALIGNED), \"local\" or \"world\""
        ))),
    }
}
