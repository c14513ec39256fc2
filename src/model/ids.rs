//! Typed indices for the public API: a [`FrameId`] names a link frame, a [`JointId`] a
//! joint, so that a frame cannot be passed where a joint is meant. Inside the hot loops
//! the model keeps plain `usize` arrays (with [`crate::model::WORLD`] as the "no parent"
//! marker); these wrappers are what callers hold.

use crate::model::compiled::Model;

/// A link frame of a [`Model`] (from [`Model::frame`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FrameId(pub usize);

/// A joint of a [`Model`] (from [`Model::joint`]), fixed joints included.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointId(pub usize);

impl FrameId {
    /// The link index into [`Model::links`].
    pub fn index(self) -> usize {
        self.0
    }
}

impl JointId {
    /// The joint index into [`Model::joints`].
    pub fn index(self) -> usize {
        self.0
    }
}

impl Model {
    /// The link frame called `name`.
    pub fn frame(&self, name: &str) -> Option<FrameId> {
        self.link_id(name).map(FrameId)
    }

    /// The joint called `name`.
    pub fn joint(&self, name: &str) -> Option<JointId> {
        self.joint_id(name).map(JointId)
    }

    /// The name of a frame.
    pub fn frame_name(&self, f: FrameId) -> &str {
        &self.links[f.0].name
    }

    /// The parent body of body `i`, `None` for a body attached to the world (the
    /// `Option` form of the [`crate::model::WORLD`] marker).
    pub fn parent_body(&self, i: usize) -> Option<usize> {
        (self.parent[i] != crate::model::compiled::WORLD).then_some(self.parent[i])
    }
}
