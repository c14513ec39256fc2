//! Switchable physical effects: gravity, joint friction, rotor inertia and gearing, joint
//! elasticity, payload and external wrenches. An [`Effects`] value names what a
//! computation includes; an effect that is `None` (or an empty wrench list) is not
//! computed at all, not multiplied by zero. `Data::effect_runs` counts how often each
//! effect's code ran, so tests can prove a left-out effect never executes.
//!
//! Models:
//! - **Friction** (per coordinate): `τ_f(q̇) = b q̇ + [F_c + (F_s − F_c) e^{−(q̇/v_s)²}]
//!   tanh(q̇/ε)`: viscous, Coulomb and Stribeck stiction, regularised by `tanh` with a small `ε`.
//!   The regularisation keeps the torque continuous and smooth through `q̇ = 0` (bounded slope
//!   `F_s/ε`): no sign-function chattering for the integrators, no event detection, and
//!   zero friction at rest so a static torque check is not biased. The price is a creep
//!   velocity of order `ε` under loads below stiction; `ε = 1e-3` rad/s by default.
//! - **Rotor and gear** (per coordinate): reflected rotor inertia (armature) `I_m N²` on the
//!   mass-matrix diagonal, on top of the model's own `model.armature` (which every
//!   algorithm includes; the loaders leave it zero and put the file's `motor_inertia` and
//!   `gear_ratio` here, so a rotor is counted once) (the rotors' gyroscopic coupling is
//!   neglected, as in the usual armature model); motor torque `τ_m = τ/(N η)` when the motor drives
//!   (`τ q̇ ≥ 0`) and `τ η / N` when it is back-driven.
//! - **Elasticity** (Spong's reduced flexible-joint model, the two-mass torsional chain in
//!   each joint): link side `M(q) q̈ + h(q, q̇) = τ_s`, motor side `B θ̈ + τ_s = τ_m`, with
//!   `τ_s = K (θ − q) + D (θ̇ − q̇)`. The motor angles `θ` are extra states.
//! - **Payload**: a rigid body fixed to a link, added to that body's inertia.
//! - **External wrenches**: force and moment at a link's origin, in world axes.

use crate::core::spatial::{Force, Inertia, InertiaO, Vec3};
use crate::dynamics::crba::crba_impl;
use crate::dynamics::rnea::rnea_impl;
use crate::dynamics::terms::Terms;
use crate::kinematics::forward_kinematics;
use crate::model::data::{Data, EffectSet};
use crate::model::{Model, WORLD};
use nalgebra::DMatrix;

/// Viscous + Coulomb + Stribeck friction per coordinate (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Friction {
    /// Viscous coefficient `b` (N m s/rad).
    pub viscous: Vec<f64>,
    /// Coulomb level `F_c` (N m).
    pub coulomb: Vec<f64>,
    /// Breakaway (stiction) level `F_s ≥ F_c` (N m).
    pub stiction: Vec<f64>,
    /// Stribeck velocity `v_s` (rad/s).
    pub stribeck_velocity: Vec<f64>,
    /// Regularisation velocity `ε` (rad/s).
    pub smoothing: f64,
}

impl Friction {
    /// From the model file (`<dynamics damping friction>`): viscous = damping, Coulomb =
    /// stiction = friction, `v_s = 0.1`, `ε = 1e-3`.
    pub fn from_model(model: &Model) -> Self {
        let pick = |f: fn(&crate::model::Joint) -> f64| -> Vec<f64> {
            (0..model.nv).map(|k| f(model.dof_joint(k))).collect()
        };
        Friction {
            viscous: pick(|j| j.damping),
            coulomb: pick(|j| j.friction),
            stiction: pick(|j| j.friction),
            stribeck_velocity: vec![0.1; model.nv],
            smoothing: 1e-3,
        }
    }

    /// Friction torque on coordinate `k` at rate `v`.
    #[inline]
    pub fn torque(&self, k: usize, v: f64) -> f64 {
        let (fc, fs, vs) = (self.coulomb[k], self.stiction[k], self.stribeck_velocity[k]);
        let r = v / vs;
        self.viscous[k] * v + (fc + (fs - fc) * (-r * r).exp()) * (v / self.smoothing).tanh()
    }

    /// The slope `∂τ_f/∂q̇` of [`Friction::torque`] on coordinate `k` at rate `v`:
    /// `b + (F_s − F_c)(−2 q̇/v_s²) e^{−(q̇/v_s)²} tanh(q̇/ε) + [F_c + (F_s − F_c)
    /// e^{−(q̇/v_s)²}] (1 − tanh²(q̇/ε))/ε`.
    #[inline]
    pub fn slope(&self, k: usize, v: f64) -> f64 {
        let (fc, fs, vs) = (self.coulomb[k], self.stiction[k], self.stribeck_velocity[k]);
        let (r, t) = (v / vs, (v / self.smoothing).tanh());
        let bump = (fs - fc) * (-r * r).exp();
        self.viscous[k] - 2.0 * r / vs * bump * t + (fc + bump) * (1.0 - t * t) / self.smoothing
    }
}

/// Rotor inertia, gear ratio and gear efficiency per coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct Rotor {
    /// Rotor inertia `I_m` on the motor side (kg m²).
    pub inertia: Vec<f64>,
    /// Gear ratio `N` (motor turns per joint turn).
    pub gear_ratio: Vec<f64>,
    /// Gear efficiency `η` in (0, 1].
    pub efficiency: Vec<f64>,
}

impl Rotor {
    /// From the model file (`motor_inertia`, `gear_ratio`), with efficiency `eta`.
    pub fn from_model(model: &Model, eta: f64) -> Self {
        Rotor {
            inertia: (0..model.nv)
                .map(|k| model.dof_joint(k).motor_inertia)
                .collect(),
            gear_ratio: (0..model.nv)
                .map(|k| model.dof_joint(k).gear_ratio)
                .collect(),
            efficiency: vec![eta; model.nv],
        }
    }

    /// Reflected inertia `I_m N²` of coordinate `k`.
    #[inline]
    pub fn armature(&self, k: usize) -> f64 {
        self.inertia[k] * self.gear_ratio[k] * self.gear_ratio[k]
    }

    /// Motor torque for joint torque `tau` at joint rate `qd`.
    pub fn motor_torque(&self, k: usize, tau: f64, qd: f64) -> f64 {
        let (n, eta) = (self.gear_ratio[k], self.efficiency[k]);
        if tau * qd >= 0.0 {
            tau / (n * eta)
        } else {
            tau * eta / n
        }
    }
}

/// Joint elasticity: spring `K`, damper `D` and motor-side inertia `B` per coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct Elasticity {
    /// Joint stiffness `K` (N m/rad).
    pub stiffness: Vec<f64>,
    /// Joint damping `D` (N m s/rad).
    pub damping: Vec<f64>,
    /// Motor-side inertia `B` reflected to the joint, `I_m N²` (kg m²), > 0.
    pub motor_inertia: Vec<f64>,
}

/// A rigid payload fixed to a link.
#[derive(Clone, Debug, PartialEq)]
pub struct Payload {
    /// The link carrying it.
    pub link: usize,
    /// Its inertia in the link frame.
    pub inertia: Inertia,
    body: usize,
    inertia_body: InertiaO,
}

impl Payload {
    /// A payload on link `link` with inertia given in the link frame.
    pub fn new(model: &Model, link: usize, inertia: Inertia) -> Result<Self, EffectsError> {
        let l = model
            .links
            .get(link)
            .ok_or(EffectsError::PayloadLinkMissing { link })?;
        if l.body == WORLD {
            return Err(EffectsError::PayloadOnWorld {
                link: l.name.clone(),
            });
        }
        if inertia.mass.is_nan() || inertia.mass < 0.0 || !inertia.mass.is_finite() {
            return Err(EffectsError::PayloadMass { mass: inertia.mass });
        }
        Ok(Payload {
            link,
            inertia,
            body: l.body,
            inertia_body: InertiaO::from_inertia(&inertia.transformed(&l.offset)),
        })
    }

    pub(crate) fn on_body(&self) -> (usize, &InertiaO) {
        (self.body, &self.inertia_body)
    }
}

/// A wrench applied to a link: force and moment at the link origin, in world axes.
#[derive(Clone, Debug, PartialEq)]
pub struct ExternalWrench {
    /// The link it acts on.
    pub link: usize,
    /// Force (N), world axes.
    pub force: Vec3,
    /// Moment about the link origin (N m), world axes.
    pub moment: Vec3,
}

/// What a dynamics computation includes. `Effects::default()` is the bare rigid model
/// without gravity.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Effects {
    /// Gravity vector (world), or none.
    pub gravity: Option<Vec3>,
    /// Joint friction.
    pub friction: Option<Friction>,
    /// Rotor inertia and gearing.
    pub rotor: Option<Rotor>,
    /// Joint elasticity (motor angles become states).
    pub elasticity: Option<Elasticity>,
    /// Payload.
    pub payload: Option<Payload>,
    /// External wrenches (none when empty).
    pub external: Vec<ExternalWrench>,
}

impl Effects {
    /// Gravity only.
    pub fn gravity(g: Vec3) -> Self {
        Effects {
            gravity: Some(g),
            ..Default::default()
        }
    }

    /// The set of effects included.
    pub fn set(&self) -> EffectSet {
        let bits = [
            self.gravity.is_some(),
            self.friction.is_some(),
            self.rotor.is_some(),
            self.elasticity.is_some(),
            self.payload.is_some(),
            !self.external.is_empty(),
        ];
        EffectSet(
            bits.iter()
                .enumerate()
                .fold(0u8, |acc, (i, &b)| acc | ((b as u8) << i)),
        )
    }

    /// The names of the effects included, in a fixed order.
    pub fn names(&self) -> Vec<&'static str> {
        self.set().names()
    }

    /// Checks per-coordinate vectors against the model.
    pub fn validate(&self, model: &Model) -> Result<(), EffectsError> {
        let n = model.nv;
        let len = |name: &'static str, l: usize| {
            if l == n {
                Ok(())
            } else {
                Err(EffectsError::Length {
                    name,
                    values: l,
                    coordinates: n,
                })
            }
        };
        if let Some(g) = &self.gravity {
            if !g.iter().all(|x| x.is_finite()) {
                return Err(EffectsError::Gravity);
            }
        }
        if let Some(f) = &self.friction {
            len("friction.viscous", f.viscous.len())?;
            len("friction.coulomb", f.coulomb.len())?;
            len("friction.stiction", f.stiction.len())?;
            len("friction.stribeck_velocity", f.stribeck_velocity.len())?;
            if !positive(&f.smoothing) || !f.stribeck_velocity.iter().all(positive) {
                return Err(EffectsError::Friction);
            }
        }
        if let Some(r) = &self.rotor {
            len("rotor.inertia", r.inertia.len())?;
            len("rotor.gear_ratio", r.gear_ratio.len())?;
            len("rotor.efficiency", r.efficiency.len())?;
            if !r.efficiency.iter().all(|e| positive(e) && *e <= 1.0) {
                return Err(EffectsError::RotorEfficiency);
            }
        }
        if let Some(e) = &self.elasticity {
            len("elasticity.stiffness", e.stiffness.len())?;
            len("elasticity.damping", e.damping.len())?;
            len("elasticity.motor_inertia", e.motor_inertia.len())?;
            if !e.stiffness.iter().all(positive) || !e.motor_inertia.iter().all(positive) {
                return Err(EffectsError::Elasticity);
            }
        }
        for w in &self.external {
            if w.link >= model.links.len() {
                return Err(EffectsError::WrenchLink { link: w.link });
            }
        }
        Ok(())
    }
}

/// Why a payload or a set of effects does not fit the model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EffectsError {
    /// The payload's link index is past the model's links.
    #[error("payload: link index {link} does not exist")]
    PayloadLinkMissing {
        /// The link index given.
        link: usize,
    },
    /// The payload's link does not move.
    #[error("payload: link '{link}' is fixed to the world; a payload there loads no joint")]
    PayloadOnWorld {
        /// The link's name.
        link: String,
    },
    /// The payload's mass is negative, infinite or NaN.
    #[error("payload: mass {mass} is not a non-negative number")]
    PayloadMass {
        /// The mass given (kg).
        mass: f64,
    },
    /// A per-coordinate vector of the wrong length.
    #[error("{name}: {values} values for {coordinates} coordinates")]
    Length {
        /// The vector (`friction.viscous`, `rotor.inertia`, …).
        name: &'static str,
        /// Its length.
        values: usize,
        /// The model's coordinates.
        coordinates: usize,
    },
    /// A gravity component is infinite or NaN.
    #[error("gravity: non-finite component")]
    Gravity,
    /// A friction smoothing or Stribeck velocity is not positive.
    #[error("friction: smoothing and Stribeck velocities must be positive")]
    Friction,
    /// A rotor efficiency outside `(0, 1]`.
    #[error("rotor.efficiency: must be in (0, 1]")]
    RotorEfficiency,
    /// An elastic joint's stiffness or motor inertia is not positive.
    #[error("elasticity: stiffness and motor inertia must be positive")]
    Elasticity,
    /// An external wrench's link index is past the model's links.
    #[error("external wrench: link index {link} does not exist")]
    WrenchLink {
        /// The link index given.
        link: usize,
    },
}

/// `x > 0` (false for NaN).
fn positive(x: &f64) -> bool {
    *x > 0.0
}

/// Fills `data.f_ext` (body frames) from the wrenches; needs `data.o_m_i` current.
pub(super) fn gather_wrenches(model: &Model, data: &mut Data, wrenches: &[ExternalWrench]) {
    for f in data.f_ext.iter_mut() {
        *f = Force::zero();
    }
    for w in wrenches {
        let link = &model.links[w.link];
        if link.body == WORLD {
            continue;
        }
        let o_m_b = data.o_m_i[link.body];
        let p = o_m_b.act_point(&link.offset.trans);
        // Moment about the world origin, then into body coordinates.
        let at_origin = Force::new(w.force, w.moment + p.cross(&w.force));
        let fb = o_m_b.act_inv_force(&at_origin);
        data.f_ext[link.body] = data.f_ext[link.body].add(&fb);
    }
}

/// The effects one call acts on, borrowed (so callers can leave some out without
/// cloning): forward and inverse dynamics and their derivatives.
pub(crate) struct Applied<'e> {
    pub gravity: Option<&'e Vec3>,
    pub friction: Option<&'e Friction>,
    pub rotor: Option<&'e Rotor>,
    pub payload: Option<&'e Payload>,
    pub external: &'e [ExternalWrench],
}

impl<'e> Applied<'e> {
    /// The model's own gravity and nothing else.
    pub(crate) fn of_model(model: &'e Model) -> Self {
        Applied {
            gravity: Some(&model.gravity),
            friction: None,
            rotor: None,
            payload: None,
            external: &[],
        }
    }

    /// Every effect of `effects` but elasticity (whose motor angles are extra states,
    /// not terms of the rigid recursion).
    pub(crate) fn of(effects: &'e Effects) -> Self {
        Applied {
            gravity: effects.gravity.as_ref(),
            friction: effects.friction.as_ref(),
            rotor: effects.rotor.as_ref(),
            payload: effects.payload.as_ref(),
            external: &effects.external,
        }
    }
}

/// The effects' prologue, written once for inverse dynamics, forward dynamics and their
/// derivatives: what the rigid recursion adds for the [`Applied`] gravity, payload,
/// external wrenches and rotor armature (friction is the callers': it enters outside the
/// recursion). [`EffectTerms::set_up`] counts each included effect's run, gathers the
/// wrenches into body frames (after forward kinematics at `q`), and fills the armature per
/// coordinate; the buffers are `data`'s own, taken for the call (no allocation) and given
/// back by [`EffectTerms::restore`].
pub(crate) struct EffectTerms<'e> {
    gravity: Option<&'e Vec3>,
    f_ext: Option<Vec<Force>>,
    /// The payload's inertia on its body.
    pub payload: Option<(usize, &'e InertiaO)>,
    armature: Option<Vec<f64>>,
}

impl<'e> EffectTerms<'e> {
    /// Sets up `e`'s terms at `q` (see the type's docs).
    pub(crate) fn set_up(model: &Model, data: &mut Data, e: &Applied<'e>, q: &[f64]) -> Self {
        let f_ext = if e.external.is_empty() {
            None
        } else {
            data.effect_runs.external += 1;
            forward_kinematics(model, data, q);
            gather_wrenches(model, data, e.external);
            Some(std::mem::take(&mut data.f_ext))
        };
        if e.gravity.is_some() {
            data.effect_runs.gravity += 1;
        }
        let payload = e.payload.map(|p| {
            data.effect_runs.payload += 1;
            p.on_body()
        });
        let armature = e.rotor.map(|r| {
            data.effect_runs.rotor += 1;
            let mut a = std::mem::take(&mut data.scratch_nv2);
            for (k, x) in a.iter_mut().enumerate() {
                *x = r.armature(k);
            }
            a
        });
        EffectTerms {
            gravity: e.gravity,
            f_ext,
            payload,
            armature,
        }
    }

    /// The terms for the recursive algorithms.
    pub(crate) fn terms(&self) -> Terms<'_> {
        Terms {
            gravity: self.gravity,
            f_ext: self.f_ext.as_deref(),
            payload: self.payload,
            rotor_armature: self.armature.as_deref(),
        }
    }

    /// Gives the buffers back to `data` (`data.f_ext` then holds the gathered wrenches).
    pub(crate) fn restore(self, data: &mut Data) {
        if let Some(a) = self.armature {
            data.scratch_nv2 = a;
        }
        if let Some(f) = self.f_ext {
            data.f_ext = f;
        }
    }
}

/// Inverse dynamics with `effects`: the joint torques (link side) into `data.tau`.
/// With elasticity, `τ` is the spring torque the joints transmit; the motor torque is
/// `τ + B θ̈` (see [`elastic_forward_dynamics`] for the simulation side).
pub fn inverse_dynamics<'a>(
    model: &Model,
    data: &'a mut Data,
    effects: &Effects,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> &'a [f64] {
    data.effects_used = effects.set();
    // The rotor's armature is added below, after friction (the order the reported
    // torques were always summed in).
    let applied = Applied {
        rotor: None,
        ..Applied::of(effects)
    };
    let set = EffectTerms::set_up(model, data, &applied, q);
    rnea_impl(model, data, q, qd, qdd, &set.terms());
    set.restore(data);
    if let Some(fr) = &effects.friction {
        data.effect_runs.friction += 1;
        for (k, (t, v)) in data.tau.iter_mut().zip(qd).enumerate() {
            *t += fr.torque(k, *v);
        }
    }
    if let Some(r) = &effects.rotor {
        data.effect_runs.rotor += 1;
        for (k, (t, a)) in data.tau.iter_mut().zip(qdd).enumerate() {
            *t += r.armature(k) * a;
        }
    }
    &data.tau
}

/// Mass matrix with the payload and the rotor armature when they are included (on top of
/// `model.armature`, which is always there).
pub fn mass_matrix<'a>(
    model: &Model,
    data: &'a mut Data,
    effects: &Effects,
    q: &[f64],
) -> &'a DMatrix<f64> {
    data.effects_used = effects.set();
    let payload = effects.payload.as_ref().map(|p| {
        data.effect_runs.payload += 1;
        p.on_body()
    });
    crba_impl(model, data, q, payload);
    if let Some(r) = &effects.rotor {
        data.effect_runs.rotor += 1;
        for k in 0..model.nv {
            data.mass[(k, k)] += r.armature(k);
        }
    }
    &data.mass
}
