//! What the MCAP reader keeps while it streams through a file: the schemas and channels
//! seen so far ([`SchemaRec`], [`Channel`] and the [`Kind`] of message each carries), the
//! decoded messages ([`Collected`]), and the [`Budget`] that bounds them by the file's size.

use crate::io::record::obstacle_markers::ObstacleMarker;
use crate::io::record::ros2;
use crate::io::record::{CollisionEvent, PointCloud, TorqueRow, Transform};
use std::collections::{BTreeMap, HashMap};

/// What a channel carries, as far as this reader cares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Kind {
    JointState,
    Tf,
    TfStatic,
    RobotDescription,
    Cloud,
    TorqueCheck,
    Collisions,
    Obstacles,
    Ignored,
}

#[derive(PartialEq)]
pub(super) struct SchemaRec {
    pub(super) name: String,
    pub(super) encoding: String,
    pub(super) data: Vec<u8>,
}

#[derive(PartialEq)]
pub(super) struct ChannelRec {
    pub(super) schema_id: u16,
    pub(super) topic: String,
    pub(super) message_encoding: String,
    pub(super) metadata: BTreeMap<String, String>,
}

pub(super) struct Channel {
    pub(super) rec: ChannelRec,
    pub(super) kind: Kind,
    pub(super) count: usize,
}

/// Smallest limits on the messages, their total payload and the joint values filled in for
/// joints a message lacks (they grow with the file; see [`Budget`]).
const MIN_MESSAGES: usize = 1 << 20;
const MIN_PAYLOAD: usize = 64 << 20;
const MIN_FILLED: usize = 1 << 22;

/// Limits that keep a small, highly compressed file from expanding into gigabytes of
/// frames: what a legitimate recording of that size can hold, with a wide margin.
pub(super) struct Budget {
    pub(super) messages: usize,
    pub(super) payload: usize,
    pub(super) filled: usize,
}

impl Budget {
    pub(super) fn for_file(len: usize) -> Self {
        Budget {
            messages: (len / 4).max(MIN_MESSAGES),
            payload: len.saturating_mul(64).max(MIN_PAYLOAD),
            filled: len.saturating_mul(4).max(MIN_FILLED),
        }
    }
}

/// Everything collected while streaming through the file.
#[derive(Default)]
pub(super) struct Collected {
    pub(super) schemas: HashMap<u16, SchemaRec>,
    pub(super) channels: HashMap<u16, Channel>,
    /// Joint states per topic, and the topics in order of first message.
    pub(super) joint_states: HashMap<String, Vec<ros2::JointState>>,
    pub(super) joint_state_topics: Vec<String>,
    pub(super) tf: Vec<(u64, Transform)>,
    pub(super) static_tf: Vec<Transform>,
    /// Child frame → its index in `static_tf` (last wins, in linear time).
    pub(super) static_index: HashMap<String, usize>,
    pub(super) robot_description: Option<String>,
    /// Clouds and collision events with their stamps (ns; `t` is set once the epoch is
    /// known).
    pub(super) clouds: Vec<(u64, PointCloud)>,
    pub(super) torque_check: Option<Vec<TorqueRow>>,
    pub(super) collisions: Vec<(u64, CollisionEvent)>,
    pub(super) obstacles: Option<Vec<ObstacleMarker>>,
    pub(super) metadata: Option<BTreeMap<String, String>>,
    pub(super) budget: Option<Budget>,
}
