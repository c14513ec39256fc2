//! [`Terms`]: what one call of the recursive algorithms adds to the model's rigid bodies —
//! gravity (or none), body-frame external forces, a payload inertia on one body, and rotor
//! armature on top of `model.armature`. The public functions take everything from the
//! model ([`Terms::of_model`]: its gravity, nothing else); the effect composition and the
//! simulator build their own (gravity off, a payload, the rotor effect's armature).

use crate::core::spatial::{Force, InertiaO, Vec3};
use crate::model::Model;

/// Per-call additions to the rigid model (see the module docs). `Terms::default()` is the
/// bare model without gravity.
#[derive(Clone, Copy, Default)]
pub(crate) struct Terms<'e> {
    /// World gravity, or none (the gravity code does not run).
    pub gravity: Option<&'e Vec3>,
    /// One wrench per body, body frame.
    pub f_ext: Option<&'e [Force]>,
    /// An extra inertia (body coordinates) on one body.
    pub payload: Option<(usize, &'e InertiaO)>,
    /// Armature per coordinate added to `model.armature` (the rotor effect's `I_m N²`).
    pub rotor_armature: Option<&'e [f64]>,
}

impl<'e> Terms<'e> {
    /// The model as it is: its gravity, no forces, no payload, no extra armature.
    pub fn of_model(model: &'e Model) -> Self {
        Terms {
            gravity: Some(&model.gravity),
            ..Terms::default()
        }
    }

    /// [`Terms::of_model`] with external forces.
    pub fn with_forces(model: &'e Model, f_ext: &'e [Force]) -> Self {
        Terms {
            f_ext: Some(f_ext),
            ..Terms::of_model(model)
        }
    }

    /// The armature of coordinate `k`: the model's plus the extra one.
    #[inline(always)]
    pub fn armature(&self, model: &Model, k: usize) -> f64 {
        match self.rotor_armature {
            Some(a) => model.armature[k] + a[k],
            None => model.armature[k],
        }
    }
}
