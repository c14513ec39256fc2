//! Torques in a gear train from static equilibrium with mesh losses (docs/reference_data.md
//! §M1), in steady motion (no inertia torques).
//!
//! Each mesh `e` carries an unknown tooth torque `t_e` on its first gear (about that
//! gear's axis). Seen from the mesh's carrier `H`, the relative power flows from the
//! driving gear to the driven one with the mesh efficiency `η`:
//!
//! `τ_b = −s (z_b/z_a) η^{±1} t_e`  (`+1` when `a` drives, `−1` when it is driven),
//!
//! and the carrier takes `−(t_e + τ_b)`. Every body (fixed ones included) balances its
//! external torque against its meshes'. Unknown are the tooth torques, the torques on
//! the named members and the reactions of the fixed bodies: as many as bodies. Who drives
//! in each mesh depends on the solution, so the solve starts ideal (`η = 1`) and repeats
//! with the flow directions of the previous solution until they settle. With `η = 1`
//! this is the power balance `Σ M_b ω_b = 0`. For a simple planetary this reproduces
//! `η_1C = (1 − i₁₃ᶜ η₀)/(1 − i₁₃ᶜ)`.

use crate::machines::gearing::train::{Element, GearTrain, TrainError};
use nalgebra::{DMatrix, DVector};

/// The torques of one load case.
#[derive(Clone, Debug, PartialEq)]
pub struct Torques {
    /// Per body: the external torque on it (given, solved, or 0) (N m).
    pub body: Vec<f64>,
    /// Per mesh: the tooth torque on its first gear (N m, about that gear's axis, for all
    /// planets together).
    pub mesh: Vec<f64>,
    /// Per mesh: the first gear drives in the relative motion.
    pub first_drives: Vec<bool>,
    /// Per mesh: the relative power through it, `|t_e (ω_A − ω_H)|` (W for speeds in
    /// rad/s).
    pub relative_power: Vec<f64>,
    /// Direction iterations used.
    pub iterations: usize,
    /// The flow directions settled.
    pub converged: bool,
}

/// Solves the torques for the speeds `omega` (rad/s, per body), the `known` external
/// torques (body, N m) and the bodies whose torque is `unknown` (fixed bodies are always
/// unknown reactions).
pub fn solve_torques(
    t: &GearTrain,
    omega: &[f64],
    known: &[(usize, f64)],
    unknown: &[usize],
) -> Result<Torques, TrainError> {
    let nb = t.bodies.len();
    let ne = t.meshes.len();
    let mut unk: Vec<usize> = unknown.to_vec();
    unk.extend((0..nb).filter(|&b| t.bodies[b].fixed && !unknown.contains(&b)));
    let nu = ne + unk.len();
    if nu != nb {
        return Err(TrainError::new(
            Element::Train,
            "torques",
            format!(
                "the torques are not statically determinate: {nu} unknowns (tooth torques, named members, fixed reactions) for {nb} bodies"
            ),
        ));
    }
    let frames: Vec<_> = (0..ne).map(|e| t.mesh_frame(e)).collect::<Result<_, _>>()?;
    let mut first_drives = vec![true; ne];
    let mut ideal = true;
    let mut last = None;
    for it in 1..=30 {
        let mut a = DMatrix::<f64>::zeros(nb, nu);
        let mut rhs = DVector::<f64>::zeros(nb);
        for &(b, m) in known {
            rhs[b] -= m;
        }
        for (e, f) in frames.iter().enumerate() {
            let [ga, gb] = t.meshes[e].gears;
            let s = f.sign.unwrap_or(1) as f64;
            let eta = if ideal { 1.0 } else { t.meshes[e].efficiency };
            let k = -s * t.z(gb) as f64 / t.z(ga) as f64
                * if first_drives[e] { eta } else { 1.0 / eta };
            a[(f.bodies[0], e)] += 1.0;
            a[(f.bodies[1], e)] += k;
            if let Some(h) = f.carrier {
                a[(h, e)] -= 1.0 + k;
            }
        }
        for (j, &b) in unk.iter().enumerate() {
            a[(b, ne + j)] = 1.0;
        }
        let Some(x) = a.clone().lu().solve(&rhs) else {
            return Err(TrainError::new(
                Element::Train,
                "torques",
                "the torque equations are singular (the named members do not carry the load)",
            ));
        };
        let rel: Vec<f64> = frames
            .iter()
            .enumerate()
            .map(|(e, f)| x[e] * (omega[f.bodies[0]] - f.carrier.map_or(0.0, |h| omega[h])))
            .collect();
        // Power delivered to the first gear < 0: it drives.
        let dirs: Vec<bool> = rel
            .iter()
            .zip(&first_drives)
            .map(|(p, &d)| if p.abs() < 1e-12 { d } else { *p < 0.0 })
            .collect();
        let settled = !ideal && dirs == first_drives;
        let mut body = vec![0.0; nb];
        for &(b, m) in known {
            body[b] = m;
        }
        for (j, &b) in unk.iter().enumerate() {
            body[b] = x[ne + j] + 0.0;
        }
        let out = Torques {
            body,
            mesh: (0..ne).map(|e| x[e]).collect(),
            first_drives: first_drives.clone(),
            relative_power: rel.iter().map(|p| p.abs()).collect(),
            iterations: it,
            converged: settled,
        };
        if settled {
            return Ok(out);
        }
        last = Some(out);
        ideal = false;
        first_drives = dirs;
    }
    last.ok_or_else(|| TrainError::new(Element::Train, "torques", "no torque solution"))
}
