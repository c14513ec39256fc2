//! The transform tree of a recording for Rerun: every frame that is the child of some
//! transform, its static parent transform, and the world poses of all of them per frame.

use super::{Frame, Recording, Transform};
use crate::model::ModelSpec;
use crate::spatial::{Se3, Vec3};
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
    ) -> Tree {
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
        tree
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
