//! From what the stream collected to a [`Recording`]: the joint-state topic, its joint
//! names, the epoch, frames (partial messages filled in within the budget), transforms
//! placed on the nearest frame, effort limits, and the header.

use crate::io::record::from_ros2::stamp_nanos;
use crate::io::record::mcap_in::collected::Collected;
use crate::io::record::mcap_out::{
    KEY_EFFORT_LIMITS, KEY_EPOCH, KEY_JOINT_NAMES, KEY_NAME, METADATA_NAME, TOPIC_JOINT_STATES,
    TOPIC_ROBOT_DESCRIPTION,
};
use crate::io::record::record_error::RecordError;
use crate::io::record::ros2;
use crate::io::record::{CollisionEvent, Frame, Header, PointCloud, Recording, Transform};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// A malformed value of the armsim metadata record.
fn bad_meta(file: &Path, key: &str, e: String) -> RecordError {
    RecordError::malformed(file, format!("metadata '{METADATA_NAME}', key '{key}'"), e)
}

impl Collected {
    pub(super) fn into_recording(mut self, file: &Path) -> Result<Recording, RecordError> {
        let meta = self.metadata.take().unwrap_or_default();
        let (topic, states) = self.take_joint_states();
        let joint_names = joint_names(&states, &meta, topic.as_deref(), file)?;
        let epoch = match meta.get(KEY_EPOCH) {
            Some(text) => Some(
                text.trim()
                    .parse::<u64>()
                    .map_err(|e| bad_meta(file, KEY_EPOCH, format!("'{text}': {e}")))?,
            ),
            None => self.earliest_stamp(&states),
        };
        let seconds = |ns: u64| seconds_after(ns, epoch.unwrap_or(0));
        let filled = self.budget.as_ref().map_or(usize::MAX, |b| b.filled);
        let mut frames = frames_from_states(
            &states,
            &joint_names,
            topic.as_deref(),
            filled,
            seconds,
            file,
        )?;
        self.place_transforms(&mut frames, seconds);
        let effort_limits =
            effort_limits(&meta, self.robot_description.as_deref(), &joint_names, file)?;
        let name = meta.get(KEY_NAME).cloned().unwrap_or_else(|| {
            file.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        });
        let metadata = meta
            .into_iter()
            .filter(|(k, _)| {
                ![KEY_NAME, KEY_JOINT_NAMES, KEY_EFFORT_LIMITS, KEY_EPOCH].contains(&k.as_str())
            })
            .collect();

        Ok(Recording {
            header: Header {
                name,
                joint_names,
                effort_limits,
                static_tf: self.static_tf,
                robot_description: self.robot_description,
                metadata,
                epoch_ns: epoch,
            },
            frames: frames.into_iter().map(|(_, f)| f).collect(),
            clouds: self
                .clouds
                .into_iter()
                .map(|(ns, c)| PointCloud {
                    t: seconds(ns),
                    ..c
                })
                .collect(),
            torque_check: self.torque_check.unwrap_or_default(),
            collisions: self
                .collisions
                .into_iter()
                .map(|(ns, e)| CollisionEvent {
                    t: seconds(ns),
                    ..e
                })
                .collect(),
            obstacles: self.obstacles.unwrap_or_default(),
        })
    }

    /// The joint states of `/joint_states`, else of the first topic that has them, with
    /// the topic.
    fn take_joint_states(&mut self) -> (Option<String>, Vec<ros2::JointState>) {
        let topic = if self.joint_states.contains_key(TOPIC_JOINT_STATES) {
            Some(TOPIC_JOINT_STATES.to_string())
        } else {
            self.joint_state_topics.first().cloned()
        };
        let states = topic
            .as_ref()
            .and_then(|t| self.joint_states.remove(t))
            .unwrap_or_default();
        (topic, states)
    }

    /// Puts each transform on the frame nearest to its stamp; without frames, one frame
    /// per distinct stamp.
    fn place_transforms(&mut self, frames: &mut Vec<(u64, Frame)>, seconds: impl Fn(u64) -> f64) {
        if frames.is_empty() {
            let mut by_time: BTreeMap<u64, Vec<Transform>> = BTreeMap::new();
            for (ns, t) in self.tf.drain(..) {
                push_tf(by_time.entry(ns).or_default(), t);
            }
            *frames = by_time
                .into_iter()
                .map(|(ns, tf)| {
                    (
                        ns,
                        Frame {
                            t: seconds(ns),
                            tf,
                            ..Frame::default()
                        },
                    )
                })
                .collect();
        } else {
            for (ns, t) in self.tf.drain(..) {
                let i = frames.partition_point(|(f, _)| *f < ns);
                let nearest = match (i.checked_sub(1), frames.get(i)) {
                    (Some(before), Some((after_ns, _))) => {
                        let before_ns = frames.get(before).map_or(0, |(b, _)| *b);
                        if ns - before_ns <= after_ns - ns {
                            before
                        } else {
                            i
                        }
                    }
                    (Some(before), None) => before,
                    (None, _) => 0,
                };
                if let Some((_, f)) = frames.get_mut(nearest) {
                    push_tf(&mut f.tf, t);
                }
            }
        }
    }

    /// The earliest stamp of a joint state (of `states`), transform, cloud or collision.
    fn earliest_stamp(&self, states: &[ros2::JointState]) -> Option<u64> {
        let js = states
            .iter()
            .filter_map(|m| stamp_nanos(&m.header.stamp).ok());
        js.chain(self.tf.iter().map(|(ns, _)| *ns))
            .chain(self.clouds.iter().map(|(ns, _)| *ns))
            .chain(self.collisions.iter().map(|(ns, _)| *ns))
            .min()
    }
}

/// Adds `t` to a frame's transforms, replacing one with the same child frame.
fn push_tf(tf: &mut Vec<Transform>, t: Transform) {
    match tf.iter_mut().find(|o| o.child == t.child) {
        Some(old) => *old = t,
        None => tf.push(t),
    }
}

/// Seconds from `epoch` to `ns` (both in ns; negative before the epoch), exact to the
/// nanosecond before the conversion to `f64`.
fn seconds_after(ns: u64, epoch: u64) -> f64 {
    (i128::from(ns) - i128::from(epoch)) as f64 / 1e9
}

/// The joint names: the first joint state's, else the metadata's; a name listed twice is
/// an error.
fn joint_names(
    states: &[ros2::JointState],
    meta: &BTreeMap<String, String>,
    topic: Option<&str>,
    file: &Path,
) -> Result<Vec<String>, RecordError> {
    let joint_names = match (states.first(), meta.get(KEY_JOINT_NAMES)) {
        (Some(first), _) => first.name.clone(),
        (None, Some(json)) => serde_json::from_str::<Vec<String>>(json)
            .map_err(|e| bad_meta(file, KEY_JOINT_NAMES, e.to_string()))?,
        (None, None) => Vec::new(),
    };
    let mut seen = std::collections::HashSet::new();
    if let Some(dup) = joint_names.iter().find(|n| !seen.insert(n.as_str())) {
        let ctx = match topic {
            Some(t) => format!("topic '{t}', message 0"),
            None => format!("metadata '{METADATA_NAME}'"),
        };
        return Err(RecordError::malformed(
            file,
            ctx,
            format!("joint '{dup}' listed twice"),
        ));
    }
    Ok(joint_names)
}

/// A frame per joint state, sorted by stamp. A message with other names than
/// `joint_names` is matched by name, the joints it lacks keeping their previous value;
/// at most `filled_left` values are filled in so.
fn frames_from_states(
    states: &[ros2::JointState],
    joint_names: &[String],
    topic: Option<&str>,
    mut filled_left: usize,
    seconds: impl Fn(u64) -> f64,
    file: &Path,
) -> Result<Vec<(u64, Frame)>, RecordError> {
    let mut frames: Vec<(u64, Frame)> = Vec::with_capacity(states.len());
    let index: HashMap<&str, usize> = joint_names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), i))
        .collect();
    let n = joint_names.len();
    for (k, m) in states.iter().enumerate() {
        // Validated when read.
        let ns = stamp_nanos(&m.header.stamp).unwrap_or(0);
        let prev = frames.last().map(|(_, f)| f);
        let frame = if m.name == joint_names {
            Frame {
                t: seconds(ns),
                q: m.position.clone(),
                qd: m.velocity.clone(),
                tau: m.effort.clone(),
                tf: Vec::new(),
            }
        } else {
            // Joints the message lacks are filled in: bounded, as that multiplies data.
            let arrays = [&m.position, &m.velocity, &m.effort]
                .iter()
                .filter(|v| !v.is_empty())
                .count();
            let present = m
                .name
                .iter()
                .filter(|name| index.contains_key(name.as_str()))
                .count();
            filled_left = filled_left
                .checked_sub(n.saturating_sub(present).saturating_mul(arrays))
                .ok_or_else(|| {
                    RecordError::malformed(
                        file,
                        format!("topic '{}', message {k}", topic.unwrap_or("")),
                        "too many partial joint states to expand for a file of this size",
                    )
                })?;
            let pick = |vals: &[f64], prev: Option<&Vec<f64>>| -> Vec<f64> {
                if vals.is_empty() {
                    return Vec::new();
                }
                let mut out: Vec<f64> = (0..n)
                    .map(|i| prev.and_then(|p| p.get(i)).copied().unwrap_or(f64::NAN))
                    .collect();
                for (name, v) in m.name.iter().zip(vals) {
                    if let Some(slot) = index.get(name.as_str()).and_then(|&i| out.get_mut(i)) {
                        *slot = *v;
                    }
                }
                out
            };
            Frame {
                t: seconds(ns),
                q: pick(&m.position, prev.map(|f| &f.q)),
                qd: pick(&m.velocity, prev.map(|f| &f.qd)),
                tau: pick(&m.effort, prev.map(|f| &f.tau)),
                tf: Vec::new(),
            }
        };
        frames.push((ns, frame));
    }
    frames.sort_by_key(|(ns, _)| *ns);
    Ok(frames)
}

/// Effort limits per joint: the metadata's, else the robot description's URDF (if it
/// parses), else none.
fn effort_limits(
    meta: &BTreeMap<String, String>,
    robot_description: Option<&str>,
    joint_names: &[String],
    file: &Path,
) -> Result<Vec<Option<f64>>, RecordError> {
    let n = joint_names.len();
    let mut effort_limits = vec![None; n];
    if let Some(json) = meta.get(KEY_EFFORT_LIMITS) {
        let v: Vec<Option<String>> = serde_json::from_str(json)
            .map_err(|e| bad_meta(file, KEY_EFFORT_LIMITS, e.to_string()))?;
        if v.len() == n {
            for (slot, s) in effort_limits.iter_mut().zip(v) {
                *slot =
                    match s {
                        Some(s) => Some(s.parse::<f64>().map_err(|e| {
                            bad_meta(file, KEY_EFFORT_LIMITS, format!("'{s}': {e}"))
                        })?),
                        None => None,
                    };
            }
        }
    } else if let Some(urdf) = robot_description {
        if let Ok(spec) = crate::model::parse::urdf::parse(urdf, TOPIC_ROBOT_DESCRIPTION) {
            for (slot, name) in effort_limits.iter_mut().zip(joint_names) {
                *slot = spec
                    .joints
                    .iter()
                    .find(|j| &j.name == name)
                    .map(|j| j.limits.effort)
                    .filter(|e| e.is_finite());
            }
        }
    }
    Ok(effort_limits)
}
