//! Mimic relations (`q = multiplier · q_master + offset`), resolved to independent
//! coordinates, as urdfdom and Pinocchio read them.
//!
//! A mimic tag that cannot be honoured is ignored with a warning, and its joint is an
//! independent coordinate: on a fixed joint, with a master that does not exist or is
//! fixed, and on every joint of a cycle of mimic relations. Chains (`a` mimics `b` which
//! mimics `c`) compose into one relation on the final master.

use crate::model::spec::{JointSpec, ModelSpec};
use crate::model::ModelWarning;
use std::collections::HashMap;

/// The independent master (spec index), multiplier and offset of a joint that mimics
/// another.
pub(super) type Resolved = Option<(usize, f64, f64)>;

/// Per spec joint, its [`Resolved`] relation; warnings for the relations ignored.
pub(super) fn resolve(
    spec: &ModelSpec,
    joint_ix: &HashMap<&str, usize>,
) -> (Vec<Resolved>, Vec<ModelWarning>) {
    let joints = &spec.joints;
    let n = joints.len();
    let mut warnings = Vec::new();
    let warn = |w: &mut Vec<ModelWarning>, j: &JointSpec, msg: String| {
        w.push(ModelWarning::new(
            &spec.source,
            j.line,
            format!("joint '{}'", j.name),
            msg,
        ))
    };
    // The direct master of each joint whose mimic tag is honoured.
    let mut master: Vec<Option<usize>> = vec![None; n];
    for (ji, j) in joints.iter().enumerate() {
        let Some(m) = &j.mimic else { continue };
        if !j.jtype.is_movable() {
            let msg = format!(
                "<mimic joint=\"{}\"> on a fixed joint: ignored (a fixed joint does not move)",
                m.joint
            );
            warn(&mut warnings, j, msg);
            continue;
        }
        match joint_ix.get(m.joint.as_str()) {
            None => warn(
                &mut warnings,
                j,
                format!(
                    "mimic: master joint '{}' does not exist: the mimic tag is ignored ('{}' is an independent coordinate)",
                    m.joint, j.name
                ),
            ),
            Some(&mi) if !joints[mi].jtype.is_movable() => warn(
                &mut warnings,
                j,
                format!(
                    "mimic: master joint '{}' is fixed: the mimic tag is ignored ('{}' is an independent coordinate)",
                    m.joint, j.name
                ),
            ),
            Some(&mi) => master[ji] = Some(mi),
        }
    }
    // Joints on a cycle of relations become independent.
    let on_cycle: Vec<bool> = (0..n)
        .map(|ji| {
            let mut cur = master[ji];
            for _ in 0..n {
                match cur {
                    Some(c) if c == ji => return true,
                    Some(c) => cur = master[c],
                    None => return false,
                }
            }
            false
        })
        .collect();
    // One warning per cycle, at its first joint in file order.
    let mut said = vec![false; n];
    for ji in (0..n).filter(|&ji| on_cycle[ji]) {
        if said[ji] {
            continue;
        }
        let mut names = vec![joints[ji].name.clone()];
        let mut cur = master[ji];
        while let Some(c) = cur.filter(|&c| c != ji) {
            said[c] = true;
            names.push(joints[c].name.clone());
            cur = master[c];
        }
        let ignored = names.join(", ");
        names.push(joints[ji].name.clone());
        let msg = format!(
            "mimic: the mimic relations form a cycle ({}): the mimic tags of {ignored} are ignored (independent coordinates)",
            names.join(" → "),
        );
        warn(&mut warnings, &joints[ji], msg);
    }
    for ji in 0..n {
        if on_cycle[ji] {
            master[ji] = None;
        }
    }
    // Compose chains onto their independent master.
    let resolved = (0..n)
        .map(|ji| {
            let mut cur = master[ji]?;
            let m = joints[ji].mimic.as_ref()?;
            let (mut mult, mut off) = (m.multiplier, m.offset);
            while let Some(next) = master[cur] {
                // q = mult (m' q' + o') + off
                let mm = joints[cur].mimic.as_ref()?;
                off += mult * mm.offset;
                mult *= mm.multiplier;
                cur = next;
            }
            Some((cur, mult, off))
        })
        .collect();
    (resolved, warnings)
}
