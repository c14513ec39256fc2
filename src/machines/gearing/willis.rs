//! Speeds of every body of a gear train by Willis' method (docs/reference_data.md §M1), in
//! exact rational arithmetic. Each mesh seen from its carrier `H` (the frame for fixed
//! axes) gives one linear equation
//!
//! `z_a (ω_A − ω_H) − s z_b (ω_B − ω_H) = 0`,  i.e. `(ω_A − ω_H)/(ω_B − ω_H) = s z_b / z_a`
//!
//! (`s = −1` external, `+1` internal, the arrow-rule sign for bevel/worm/crossed meshes),
//! and each fixed body `ω = 0`. The null space of these equations is the train's motion:
//! its dimension is the kinematic degree of freedom, checked against `W = 3n − 2p₅ − p₄`.
//! Given as many input speeds as degrees of freedom, every speed is an exact rational
//! combination of the inputs.

use crate::machines::gearing::rational::{null_space, solve, Overflow, Ratio};
use crate::machines::gearing::train::{Element, GearTrain, TrainError};

/// The motion space of a train.
#[derive(Clone, Debug, PartialEq)]
pub struct Kinematics {
    /// A basis of the body speeds (one vector per degree of freedom, over all bodies).
    pub basis: Vec<Vec<Ratio>>,
    /// Rank of the mesh and fixed-body equations.
    pub rank: usize,
    /// Per body: its sense of rotation is defined relative to the inputs (no unsigned
    /// bevel/worm mesh on the way).
    pub sense_defined: Vec<bool>,
}

impl Kinematics {
    /// The kinematic degree of freedom.
    pub fn dof(&self) -> usize {
        self.basis.len()
    }
}

/// Speeds as exact linear maps of the inputs, and their values.
#[derive(Clone, Debug, PartialEq)]
pub struct Speeds {
    /// The input bodies, in order.
    pub inputs: Vec<usize>,
    /// Per body: `ω_b = Σ_i map[b][i] u_i`.
    pub map: Vec<Vec<Ratio>>,
    /// Per body: the speed for the given input values (the inputs' unit).
    pub values: Vec<f64>,
}

fn overflow(_: Overflow) -> TrainError {
    TrainError::new(
        Element::Train,
        "gears",
        "exact arithmetic overflowed 128-bit integers (tooth-count products too large)",
    )
}

/// The mesh equations (one row per mesh, then one per fixed body); with `hold`, the
/// fixed bodies are released and `ω_hold = 0` instead (Willis' inversion).
fn equations(t: &GearTrain, hold: Option<usize>) -> Result<Vec<Vec<Ratio>>, TrainError> {
    let nb = t.bodies.len();
    let mut rows = Vec::new();
    for e in 0..t.meshes.len() {
        let f = t.mesh_frame(e)?;
        let s = f.sign.unwrap_or(1) as i128;
        let [ga, gb] = t.meshes[e].gears;
        let (za, zb) = (t.z(ga) as i128, t.z(gb) as i128);
        let mut row = vec![Ratio::ZERO; nb];
        row[f.bodies[0]] = Ratio::int(za);
        row[f.bodies[1]] = Ratio::int(-s * zb);
        if let Some(h) = f.carrier {
            row[h] = Ratio::int(-za + s * zb);
        }
        rows.push(row);
    }
    let fixed: Vec<usize> = match hold {
        Some(h) => vec![h],
        None => (0..nb).filter(|&b| t.bodies[b].fixed).collect(),
    };
    for b in fixed {
        let mut row = vec![Ratio::ZERO; nb];
        row[b] = Ratio::ONE;
        rows.push(row);
    }
    Ok(rows)
}

/// Bodies whose sense is defined from the `roots` (through signed meshes only; a mesh
/// seen from a carrier links its carrier too).
fn sense_defined(t: &GearTrain, roots: &[usize]) -> Result<Vec<bool>, TrainError> {
    let mut def = vec![false; t.bodies.len()];
    for &r in roots {
        def[r] = true;
    }
    loop {
        let mut changed = false;
        for e in 0..t.meshes.len() {
            let f = t.mesh_frame(e)?;
            if f.sign.is_none() {
                continue;
            }
            let mut group = vec![f.bodies[0], f.bodies[1]];
            group.extend(f.carrier);
            let known = group.iter().filter(|&&b| def[b]).count();
            if known > 0 && known < group.len() {
                for b in group {
                    def[b] = true;
                }
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    for (b, body) in t.bodies.iter().enumerate() {
        def[b] |= body.fixed;
    }
    Ok(def)
}

/// The motion space of `t` (tooth counts resolved). `roots` are the input bodies, for
/// the senses.
pub fn kinematics(t: &GearTrain, roots: &[usize]) -> Result<Kinematics, TrainError> {
    let rows = equations(t, None)?;
    let (basis, rank) = null_space(&rows, t.bodies.len()).map_err(overflow)?;
    Ok(Kinematics {
        basis,
        rank,
        sense_defined: sense_defined(t, roots)?,
    })
}

/// Speeds for `inputs` (body, value): as many as degrees of freedom, determining the
/// train.
pub fn speeds(
    t: &GearTrain,
    kin: &Kinematics,
    inputs: &[(usize, f64)],
) -> Result<Speeds, TrainError> {
    let k = kin.dof();
    let err = |i: usize, msg: String| TrainError::new(Element::Input(i), "member", msg);
    if inputs.len() != k {
        return Err(TrainError::new(
            if inputs.is_empty() {
                Element::Train
            } else {
                Element::Input(inputs.len() - 1)
            },
            "member",
            format!(
                "the train has {k} degree{} of freedom (W = 3n − 2p₅ − p₄ = {}): give {k} input speed{}, not {}",
                if k == 1 { "" } else { "s" },
                t.structural_mobility().0,
                if k == 1 { "" } else { "s" },
                inputs.len()
            ),
        ));
    }
    for (i, &(b, _)) in inputs.iter().enumerate() {
        if t.bodies[b].fixed {
            return Err(err(
                i,
                format!("'{}' is fixed: it cannot be an input", t.bodies[b].name),
            ));
        }
    }
    let a: Vec<Vec<Ratio>> = inputs
        .iter()
        .map(|&(b, _)| kin.basis.iter().map(|v| v[b]).collect())
        .collect();
    let nb = t.bodies.len();
    let mut map = vec![vec![Ratio::ZERO; k]; nb];
    for i in 0..k {
        let mut rhs = vec![Ratio::ZERO; k];
        rhs[i] = Ratio::ONE;
        let Some(c) = solve(&a, &rhs).map_err(overflow)? else {
            return Err(err(
                k - 1,
                format!(
                    "the inputs {} do not determine the train (they are tied to each other)",
                    inputs
                        .iter()
                        .map(|&(b, _)| format!("'{}'", t.bodies[b].name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        };
        for (b, row) in map.iter_mut().enumerate() {
            let mut s = Ratio::ZERO;
            for (j, cj) in c.iter().enumerate() {
                s = s
                    .plus(kin.basis[j][b].times(*cj).map_err(overflow)?)
                    .map_err(overflow)?;
            }
            row[i] = s;
        }
    }
    let values = map
        .iter()
        .map(|row| {
            // `+ 0.0` turns −0 into 0.
            row.iter()
                .zip(inputs)
                .map(|(r, &(_, u))| r.to_f64() * u)
                .sum::<f64>()
                + 0.0
        })
        .collect();
    Ok(Speeds {
        inputs: inputs.iter().map(|&(b, _)| b).collect(),
        map,
        values,
    })
}

/// Willis' ratio `i_ab^H = (ω_a − ω_H)/(ω_b − ω_H)` with the carrier held and the fixed
/// bodies released; `None` when the inverted train does not tie `a` to `b`.
pub fn relative_ratio(
    t: &GearTrain,
    a: usize,
    b: usize,
    h: usize,
) -> Result<Option<Ratio>, TrainError> {
    let rows = equations(t, Some(h))?;
    let (basis, _) = null_space(&rows, t.bodies.len()).map_err(overflow)?;
    let Some(v) = basis.iter().find(|v| !v[b].is_zero()) else {
        return Ok(None);
    };
    let r = v[a]
        .over(v[b])
        .map_err(overflow)?
        .ok_or_else(|| overflow(Overflow))?;
    for w in &basis {
        if w[a] != r.times(w[b]).map_err(overflow)? {
            return Ok(None);
        }
    }
    Ok(Some(r))
}
