//! The transform tree of a recording for Rerun: every frame that is the child of some
//! transform, its static parent transform, and the world poses of all of them per frame.
//!
//! Budgets (a small recording must not expand into gigabytes of poses and of `.rrd`): a
//! tree of more than [`MAX_TREE_FRAMES`] transform frames is refused, and when the frames
//! times the tree's size exceed [`MAX_POSES`], only every k-th frame is drawn (a warning
//! says so; see [`frame_stride`]).

use crate::core::spatial::{Se3, Vec3};
use crate::io::record::rerun::rerun_sink::TooManyFrames;
use crate::io::record::{Frame, Recording, Transform};
use crate::model::ModelSpec;
use nalgebra::{Quaternion, UnitQuaternion};
use std::collections::HashMap;

/// The transform tree of a recording: every frame that is the child of some transform.
pub(super) struct Tree {
    pub(super) names: Vec<String>,
    pub(super) index: HashMap<String, usize>,
    /// Static parent → child transform of each link, if any.
    pub(super) statics: Vec<Option<(Option<usize>, Se3)>>,
    /// Whether the link has a transform in some frame.
    pub(super) moving: Vec<bool>,
}

fn se3_of(t: &Transform) -> Option<Se3> {
    let [x, y, z, w] = t.rotation;
    let ok = t
        .translation
        .iter()
        .chain(&t.rotation)
        .all(|v| v.is_finite());
    let n = (x * x + y * y + z * z + w * w).sqrt();
    if !ok || n < 1e-9 {
        return None;
    }
    let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    Some(Se3::new(
        *q.to_rotation_matrix().matrix(),
        Vec3::from(t.translation),
    ))
}

/// Most transform frames (links and tf children) the viewer draws: a robot has tens, a
/// ROS bag's tf tree a few hundred.
pub const MAX_TREE_FRAMES: usize = 10_000;

/// Most world poses (frames drawn × transform frames) the viewer computes and logs:
/// about 110 MB of poses.
pub const MAX_POSES: usize = 1_000_000;

/// The step between drawn frames so that `frames × tree_frames ≤ MAX_POSES` (1: all).
pub fn frame_stride(frames: usize, tree_frames: usize) -> usize {
    let per = tree_frames.max(1);
    let most = (MAX_POSES / per).max(1);
    frames.div_ceil(most).max(1)
}

/// Refuses a recording whose transform tree (with the model's links) is larger than
/// [`MAX_TREE_FRAMES`], before anything is opened or logged.
pub(super) fn check_size(rec: &Recording, spec: Option<&ModelSpec>) -> Result<(), TooManyFrames> {
    let mut names: std::collections::HashSet<&str> = std::collections::HashSet::new();
    let statics = rec.header.static_tf.iter().map(|t| t.child.as_str());
    let moving = rec
        .frames
        .iter()
        .flat_map(|f| f.tf.iter().map(|t| t.child.as_str()));
    let links = spec
        .into_iter()
        .flat_map(|s| s.links.iter().map(|l| l.name.as_str()));
    for n in statics.chain(moving).chain(links) {
        names.insert(n);
        if names.len() > MAX_TREE_FRAMES {
            break;
        }
    }
    if names.len() > MAX_TREE_FRAMES {
        let total: std::collections::HashSet<&str> = rec
            .header
            .static_tf
            .iter()
            .map(|t| t.child.as_str())
            .chain(
                rec.frames
                    .iter()
                    .flat_map(|f| f.tf.iter().map(|t| t.child.as_str())),
            )
            .chain(
                spec.into_iter()
                    .flat_map(|s| s.links.iter().map(|l| l.name.as_str())),
            )
            .collect();
        return Err(TooManyFrames {
            frames: total.len(),
            limit: MAX_TREE_FRAMES,
        });
    }
    Ok(())
}

impl Tree {
    fn add(&mut self, name: &str) -> usize {
        if let Some(&i) = self.index.get(name) {
            return i;
        }
        self.names.push(name.to_string());
        self.statics.push(None);
        self.moving.push(false);
        self.index.insert(name.to_string(), self.names.len() - 1);
        self.names.len() - 1
    }

    pub(super) fn build(
        rec: &Recording,
        spec: Option<&ModelSpec>,
        warnings: &mut Vec<String>,
    ) -> Result<Tree, TooManyFrames> {
        let mut tree = Tree {
            names: Vec::new(),
            index: HashMap::new(),
            statics: Vec::new(),
            moving: Vec::new(),
        };
        let mut bad = 0usize;
        for t in &rec.header.static_tf {
            let c = tree.add(&t.child);
            match se3_of(t) {
                Some(m) => tree.statics[c] = Some((None, m)),
                None => bad += 1,
            }
        }
        for f in &rec.frames {
            for t in &f.tf {
                let c = tree.add(&t.child);
                tree.moving[c] = true;
            }
        }
        if let Some(s) = spec {
            for l in &s.links {
                tree.add(&l.name);
            }
        }
        if tree.names.len() > MAX_TREE_FRAMES {
            return Err(TooManyFrames {
                frames: tree.names.len(),
                limit: MAX_TREE_FRAMES,
            });
        }
        // Parents of static transforms, now that every child has an index.
        for t in &rec.header.static_tf {
            let p = tree.index.get(&t.parent).copied();
            if let Some((parent, _)) = tree.statics[tree.index[&t.child]].as_mut() {
                *parent = p;
            }
        }
        if bad > 0 {
            warnings.push(format!(
                "{bad} static transform(s) with a non-finite or zero rotation ignored"
            ));
        }
        Ok(tree)
    }

    /// World pose of every link for `frame` (`None`: statics only). Frames not reached
    /// from a known transform sit at the origin.
    pub(super) fn poses(
        &self,
        frame: Option<&Frame>,
        bad: &mut usize,
    ) -> (Vec<Se3>, Vec<Option<usize>>) {
        let n = self.names.len();
        let mut local: Vec<Option<(Option<usize>, Se3)>> = self.statics.clone();
        if let Some(f) = frame {
            for t in &f.tf {
                let c = self.index[&t.child];
                match se3_of(t) {
                    Some(m) => local[c] = Some((self.index.get(&t.parent).copied(), m)),
                    None => *bad += 1,
                }
            }
        }
        let parent: Vec<Option<usize>> = local.iter().map(|l| l.and_then(|(p, _)| p)).collect();
        // 0 unvisited, 1 on the current walk, 2 done.
        let mut state = vec![0u8; n];
        let mut world = vec![Se3::identity(); n];
        let mut walk = Vec::new();
        for start in 0..n {
            let mut i = start;
            // Walk up to a resolved link or a root; a cycle is cut where it closes.
            loop {
                if state[i] != 0 {
                    break;
                }
                state[i] = 1;
                walk.push(i);
                match parent[i] {
                    Some(p) if state[p] != 1 => i = p,
                    _ => break,
                }
            }
            while let Some(j) = walk.pop() {
                let base = match parent[j] {
                    Some(p) if state[p] == 2 => world[p],
                    _ => Se3::identity(),
                };
                world[j] = match &local[j] {
                    Some((_, m)) => base.mul(m),
                    None => base,
                };
                state[j] = 2;
            }
        }
        (world, parent)
    }
}

#[cfg(test)]
mod tests {
    use crate::io::record::rerun::rerun_tree::*;

    #[test]
    fn frame_stride_keeps_the_poses_within_the_budget() {
        assert_eq!(frame_stride(1000, 100), 1);
        assert_eq!(frame_stride(10_001, 100), 2);
        assert_eq!(frame_stride(200, 60_000), 13);
        for (f, n) in [(7, 3), (123_457, 89), (5, 2_000_000)] {
            let k = frame_stride(f, n);
            assert!(f.div_ceil(k) * n <= MAX_POSES.max(n), "{f} {n} {k}");
        }
    }
}
