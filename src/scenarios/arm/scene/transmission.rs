//! Gear trains as arm-joint transmissions: `[rotor_inertia.gear_train]` maps a joint to a
//! `kind = "gear_train"` file (relative to the scenario); the train's ratio `ω_in/ω_out`,
//! forward efficiency and inertia referred to the input become that joint's rotor gear
//! ratio, efficiency and an addition to its motor inertia (the rotor effect of
//! `crate::dynamics::effects`: armature `(I_m + J_train) N²`, motor torque `τ/(N η)`).

use crate::dynamics::Rotor;
use crate::scenarios::arm::scene::section_reader::Sections;
use crate::scenarios::gear_train::transmission_from_file;
use crate::scenarios::gear_train_report::Transmission;
use crate::scenarios::source::Source;
use serde::Serialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// One joint's gear train, as the report lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct JointTransmission {
    /// The joint (coordinate) name.
    pub joint: String,
    /// The gear-train file as resolved.
    pub file: String,
    /// The train between its input (motor) and output (joint).
    #[serde(flatten)]
    pub train: Transmission,
}

/// The joints' gear trains written into `rotor`; an unknown joint, an unreadable or
/// broken train, or one without a single input and an output is an error at the joint's
/// key, quoting the train file's own located message.
pub(super) fn apply(
    sx: &Sections,
    trains: &Spanned<BTreeMap<String, Spanned<String>>>,
    rotor: &mut Rotor,
) -> Result<Vec<JointTransmission>, crate::core::diag::LocatedError> {
    let cx: &Source = &sx.cx;
    let mut out = Vec::new();
    for (joint, rel) in trains.get_ref() {
        let key = format!("rotor_inertia.gear_train.{joint}");
        let Some(k) = sx.names.iter().position(|n| n == joint) else {
            return Err(cx.at(
                rel.span(),
                &key,
                format!(
                    "no joint '{joint}' in the model (joints: {})",
                    sx.names.join(", ")
                ),
            ));
        };
        let path = sx.dir.join(rel.get_ref());
        let train = transmission_from_file(&path)
            .map_err(|e| cx.at(rel.span(), &key, format!("gear train: {e}")))?;
        if train.efficiency_forward <= 0.0 || train.gear_ratio == 0.0 {
            return Err(cx.at(
                rel.span(),
                &key,
                format!(
                    "gear train {}: ratio {} and efficiency {} cannot drive the joint",
                    path.display(),
                    train.gear_ratio,
                    train.efficiency_forward
                ),
            ));
        }
        rotor.gear_ratio[k] = train.gear_ratio.abs();
        rotor.efficiency[k] = train.efficiency_forward.min(1.0);
        rotor.inertia[k] += train.inertia_input_side;
        out.push(JointTransmission {
            joint: joint.clone(),
            file: path.display().to_string(),
            train,
        });
    }
    Ok(out)
}
