//! `armsim dynamics`: joint torques (RNEA or a Lagrange reference), mass matrix, bias,
//! gravity torques and energies at one state with the chosen effects; with `--tau` the
//! forward-dynamics accelerations.

use crate::cli::{link_id, load, parse_values, print_json, rows, ModelArgs};
use armsim::core::diag::fmt_num;
use armsim::core::spatial::{Inertia, Mat3, Vec3};
use armsim::dynamics::{self, Effects, Friction, Payload, Rotor};
use armsim::model::data::Data;
use armsim::model::Model;
use clap::ValueEnum;
use serde_json::json;

#[derive(clap::Args)]
pub struct DynamicsArgs {
    #[command(flatten)]
    pub m: ModelArgs,
    /// Joint positions, comma separated.
    #[arg(long, allow_hyphen_values = true)]
    pub q: String,
    /// Joint velocities (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub v: Option<String>,
    /// Joint accelerations (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub a: Option<String>,
    /// Joint torques: also compute q̈ by forward dynamics.
    #[arg(long, allow_hyphen_values = true)]
    pub tau: Option<String>,
    /// Gravity vector x,y,z (default: the model's, (0, 0, -9.81)).
    #[arg(long, allow_hyphen_values = true)]
    pub gravity: Option<String>,
    /// Include joint friction from the model file (<dynamics damping friction>).
    #[arg(long)]
    pub friction: bool,
    /// Include rotor inertia and gearing from the model file (motor_inertia, gear_ratio).
    #[arg(long)]
    pub rotor: bool,
    /// Gear efficiency for --rotor, in (0, 1].
    #[arg(long, default_value_t = 1.0)]
    pub efficiency: f64,
    /// Payload: LINK,MASS[,cx,cy,cz] (point mass at the COM in the link frame).
    #[arg(long, allow_hyphen_values = true)]
    pub payload: Option<String>,
    /// Formulation for tau: rnea (default), lagrange-trace or lagrange-energy (slow
    /// references; rigid model with gravity only).
    #[arg(long, value_enum, default_value = "rnea")]
    pub method: MethodArg,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    Rnea,
    LagrangeTrace,
    LagrangeEnergy,
}

/// The largest model the Lagrange formulations run on (`∂M/∂q` holds nv³ values: 256³
/// is 128 MiB).
const MAX_LAGRANGE_DOF: usize = 256;

/// Refuses a model too large for the mass matrix, or for the Lagrange formulations.
fn check_size(model: &Model, o: &DynamicsArgs) -> Result<(), String> {
    armsim::model::data::dense_fits(model).map_err(|m| format!("{}: {m}", model.source))?;
    if matches!(
        o.method,
        MethodArg::LagrangeTrace | MethodArg::LagrangeEnergy
    ) && model.nv > MAX_LAGRANGE_DOF
    {
        return Err(format!(
            "--method: the Lagrange formulations hold nv³ values (∂M/∂q): {} degrees of \
             freedom is more than the {MAX_LAGRANGE_DOF} they accept; use rnea",
            model.nv
        ));
    }
    Ok(())
}

/// `armsim dynamics`.
pub fn run(a: &DynamicsArgs) -> Result<(), String> {
    dynamics_cmd(&load(&a.m)?, &a.q, a, a.m.json)
}

fn parse_triple(what: &str, s: &str) -> Result<Vec3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("--{what}: expected x,y,z numbers, got '{s}'"))?;
    if v.len() != 3 || !v.iter().all(|x| x.is_finite()) {
        return Err(format!(
            "--{what}: expected three finite numbers x,y,z, got '{s}'"
        ));
    }
    Ok(Vec3::new(v[0], v[1], v[2]))
}

fn parse_payload(model: &Model, s: &str) -> Result<Payload, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 2 && parts.len() != 5 {
        return Err(format!(
            "--payload: expected LINK,MASS[,cx,cy,cz], got '{s}'"
        ));
    }
    let link = link_id(model, parts[0])?;
    let nums: Vec<f64> = parts[1..]
        .iter()
        .map(|t| t.parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("--payload: '{s}' has a value that is not a number"))?;
    if !nums.iter().all(|x| x.is_finite()) || nums[0] < 0.0 {
        return Err(format!(
            "--payload: mass and centre of mass must be finite, mass ≥ 0 ('{s}')"
        ));
    }
    let com = if nums.len() == 4 {
        Vec3::new(nums[1], nums[2], nums[3])
    } else {
        Vec3::zeros()
    };
    Payload::new(model, link, Inertia::new(nums[0], com, Mat3::zeros())).map_err(|e| e.to_string())
}

fn dynamics_cmd(model: &Model, q: &str, o: &DynamicsArgs, as_json: bool) -> Result<(), String> {
    let q = parse_values(model, "q", q)?;
    let zeros = vec![0.0; model.nv];
    let v =
        o.v.as_deref()
            .map(|s| parse_values(model, "v", s))
            .transpose()?
            .unwrap_or_else(|| zeros.clone());
    let a =
        o.a.as_deref()
            .map(|s| parse_values(model, "a", s))
            .transpose()?
            .unwrap_or_else(|| zeros.clone());
    let tau_in = o
        .tau
        .as_deref()
        .map(|s| parse_values(model, "tau", s))
        .transpose()?;
    let g = match &o.gravity {
        Some(s) => parse_triple("gravity", s)?,
        None => model.gravity,
    };
    let effects = effects_of(model, o, g)?;
    check_size(model, o)?;
    let mut data = Data::new(model);
    let tau = match o.method {
        MethodArg::Rnea => {
            dynamics::inverse_dynamics(model, &mut data, &effects, &q, &v, &a).to_vec()
        }
        MethodArg::LagrangeTrace => dynamics::lagrange_trace(model, &mut data, &q, &v, &a, &g),
        MethodArg::LagrangeEnergy => dynamics::lagrange_energy(model, &mut data, &q, &v, &a, &g),
    };
    let bias = dynamics::inverse_dynamics(model, &mut data, &effects, &q, &v, &zeros).to_vec();
    let static_effects = Effects {
        friction: None,
        ..effects.clone()
    };
    let gravity_tau =
        dynamics::inverse_dynamics(model, &mut data, &static_effects, &q, &zeros, &zeros).to_vec();
    let mass = dynamics::mass_matrix(model, &mut data, &effects, &q).clone();
    let (ke, pe) = dynamics::energies_with(model, &mut data, &effects, &q, &v);
    let inputs = Inputs {
        model,
        q: &q,
        v: &v,
        a: &a,
        tau: tau_in.as_deref(),
    };
    inputs.finite("tau", &tau)?;
    inputs.finite("bias", &bias)?;
    inputs.finite("gravity torque", &gravity_tau)?;
    inputs.finite("mass matrix", mass.as_slice())?;
    inputs.finite("kinetic and potential energy", &[ke, pe])?;
    let qdd = tau_in
        .as_deref()
        .map(|t| forward_qdd(&inputs, &mut data, &effects, t, &mass))
        .transpose()?;
    let method = match o.method {
        MethodArg::Rnea => "rnea",
        MethodArg::LagrangeTrace => "lagrange-trace",
        MethodArg::LagrangeEnergy => "lagrange-energy",
    };
    if as_json {
        let mut out = json!({
            "joints": model.dof_names(),
            "effects": effects.names(),
            "method": method,
            "gravity_vector": [g.x, g.y, g.z],
            "tau": tau,
            "mass_matrix": rows(&mass),
            "bias": bias,
            "gravity": gravity_tau,
            "kinetic_energy": ke,
            "potential_energy": pe,
        });
        if let Some(qdd) = &qdd {
            out["qdd"] = json!(qdd);
        }
        print_json(&out);
        return Ok(());
    }
    print_text(
        model,
        &Results {
            effects: &effects,
            method,
            tau: &tau,
            bias: &bias,
            gravity_tau: &gravity_tau,
            qdd: qdd.as_deref(),
            mass: &mass,
            energies: (ke, pe),
        },
    );
    Ok(())
}

/// Forward dynamics for the given torques; an overflow names the inputs, a singular mass
/// matrix the joint (through the error of [`dynamics::forward_dynamics_with`]).
fn forward_qdd(
    inputs: &Inputs,
    data: &mut Data,
    effects: &Effects,
    tau: &[f64],
    mass: &nalgebra::DMatrix<f64>,
) -> Result<Vec<f64>, String> {
    let model = inputs.model;
    let qdd = dynamics::forward_dynamics_with(model, data, effects, inputs.q, inputs.v, tau)
        .map(|x| x.to_vec());
    let finite = qdd.as_ref().is_ok_and(|x| x.iter().all(|v| v.is_finite()));
    if !finite && mass.clone().cholesky().is_some() {
        // The mass matrix is fine: the accelerations overflowed.
        match &qdd {
            Ok(x) => inputs.finite("qdd", x)?,
            Err(_) => inputs.finite("qdd", &[f64::NAN])?,
        }
    }
    qdd.map_err(|e| format!("{}: forward dynamics: {e}", model.source))
}

/// The state a command was given, for the message when a result is not finite.
struct Inputs<'a> {
    model: &'a Model,
    q: &'a [f64],
    v: &'a [f64],
    a: &'a [f64],
    tau: Option<&'a [f64]>,
}

impl Inputs<'_> {
    /// `Ok` when every value of `what` is finite, else an error naming the quantity (and
    /// its joint) and the largest input magnitudes, which overflowed the arithmetic.
    fn finite(&self, what: &str, vals: &[f64]) -> Result<(), String> {
        let Some(k) = vals.iter().position(|x| !x.is_finite()) else {
            return Ok(());
        };
        let names = self.model.dof_names();
        let at = match names.get(k) {
            Some(n) if vals.len() == names.len() => format!(" of joint '{n}'"),
            _ => String::new(),
        };
        let max = |x: &[f64]| fmt_num(x.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        let mass = self.model.inertia.iter().fold(0.0f64, |m, i| m.max(i.mass));
        let tau = self
            .tau
            .map_or(String::new(), |t| format!(", |tau| {}", max(t)));
        Err(format!(
            "{}: the {what}{at} is not finite ({}): the inputs overflow floating-point \
             arithmetic (largest |q| {}, |v| {}, |a| {}{tau}; largest link mass {} kg)",
            self.model.source,
            fmt_num(vals[k]),
            max(self.q),
            max(self.v),
            max(self.a),
            fmt_num(mass)
        ))
    }
}

/// A table cell: fixed with 6 decimals, `e` notation beyond 1e9 (no 300-digit numbers).
fn cell(x: f64, width: usize) -> String {
    if x.abs() < 1e9 {
        format!("{x:>width$.6}")
    } else {
        format!("{x:>width$.6e}")
    }
}

/// The effects the options name (gravity always; friction, rotor and payload on request),
/// checked against the model and the method.
fn effects_of(model: &Model, o: &DynamicsArgs, g: Vec3) -> Result<Effects, String> {
    let mut effects = Effects::gravity(g);
    if o.friction {
        effects.friction = Some(Friction::from_model(model));
    }
    if o.rotor {
        if !(o.efficiency > 0.0 && o.efficiency <= 1.0) {
            return Err(format!("--efficiency: {} is not in (0, 1]", o.efficiency));
        }
        effects.rotor = Some(Rotor::from_model(model, o.efficiency));
    }
    if let Some(p) = &o.payload {
        effects.payload = Some(parse_payload(model, p)?);
    }
    effects.validate(model).map_err(|e| e.to_string())?;
    if o.method != MethodArg::Rnea && effects.names() != ["gravity"] {
        return Err("--method lagrange-*: the Lagrange references cover the rigid model with gravity only; drop --friction/--rotor/--payload".into());
    }
    Ok(effects)
}

/// What `armsim dynamics` computed, for the text output.
struct Results<'a> {
    effects: &'a Effects,
    method: &'a str,
    tau: &'a [f64],
    bias: &'a [f64],
    gravity_tau: &'a [f64],
    qdd: Option<&'a [f64]>,
    mass: &'a nalgebra::DMatrix<f64>,
    energies: (f64, f64),
}

/// The text output of `armsim dynamics`.
fn print_text(model: &Model, r: &Results) {
    println!(
        "effects: {} (tau by {})",
        r.effects.names().join(", "),
        r.method
    );
    println!(
        "{:<24} {:>14} {:>14} {:>14}{}",
        "joint",
        "tau",
        "bias",
        "gravity",
        if r.qdd.is_some() {
            "            qdd"
        } else {
            ""
        }
    );
    for (k, name) in model.dof_names().iter().enumerate() {
        print!(
            "{:<24} {} {} {}",
            name,
            cell(r.tau[k], 14),
            cell(r.bias[k], 14),
            cell(r.gravity_tau[k], 14)
        );
        if let Some(qdd) = r.qdd {
            print!(" {}", cell(qdd[k], 14));
        }
        println!();
    }
    let (ke, pe) = r.energies;
    println!(
        "kinetic energy {} J, potential energy {} J",
        cell(ke, 0),
        cell(pe, 0)
    );
    println!("mass matrix:");
    for i in 0..model.nv {
        println!(
            "  {}",
            (0..model.nv)
                .map(|c| cell(r.mass[(i, c)], 11))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
}
