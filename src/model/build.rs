//! Compiling a validated [`ModelSpec`] into a [`Model`]: unique names, one tree with one
//! root and no cycle, links and joints re-indexed in depth-first order, coordinates for
//! the independent movable joints (mimic joints follow theirs), one body per movable
//! joint carrying the inertias of the links rigidly attached to it.

use crate::core::spatial::{rotation_z_to, Inertia, InertiaO, Mat3, Se3, Vec3};
use crate::model::body_frames::{aligned_axis, push_permutations_up, snap_signed_permutation};
use crate::model::compiled::{BodyKind, Joint, Link, Model, WORLD};
use crate::model::mimic::{self, Resolved};
use crate::model::model_error::{ModelError, ModelWarning};
use crate::model::spec::{JointSpec, JointType, LinkSpec, ModelSpec};
use std::collections::HashMap;

pub(super) struct Builder<'a> {
    pub(super) spec: &'a ModelSpec,
    pub(super) warnings: Vec<ModelWarning>,
}

/// The joint tree of the spec: each link's parent joint and child joints (spec indices),
/// and the root link.
struct Tree {
    parent_joint: Vec<Option<usize>>,
    children: Vec<Vec<usize>>,
    root: usize,
}

/// How the spec's links and joints map onto the model's: the tree order, the coordinates
/// and the resolved mimic relations (all by spec index).
struct Indexing<'a> {
    link_ix: &'a HashMap<&'a str, usize>,
    parent_joint: &'a [Option<usize>],
    order_links: Vec<usize>,
    order_joints: Vec<usize>,
    /// Spec index → model index.
    new_link: Vec<usize>,
    new_joint: Vec<usize>,
    mimic: Vec<Resolved>,
    dof_of_spec_joint: Vec<Option<usize>>,
}

impl<'a> Builder<'a> {
    pub(super) fn err_joint(&self, j: &JointSpec, msg: impl Into<String>) -> ModelError {
        ModelError::new(
            &self.spec.source,
            j.line,
            format!("joint '{}'", j.name),
            msg,
        )
    }

    pub(super) fn err_link(&self, l: &LinkSpec, msg: impl Into<String>) -> ModelError {
        ModelError::new(&self.spec.source, l.line, format!("link '{}'", l.name), msg)
    }

    pub(super) fn build(mut self) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        let spec = self.spec;
        let file = &spec.source;
        if spec.links.is_empty() {
            return Err(ModelError::new(
                file,
                None,
                "robot",
                "the model has no links",
            ));
        }
        if !self.check_finite_se3(&spec.root_offset) {
            return Err(ModelError::new(file, None, "base", "non-finite number"));
        }
        let link_ix = self.index_links()?;
        let joint_ix = self.index_joints()?;
        let tree = self.tree(&link_ix)?;
        let (order_links, order_joints) = self.depth_first(&tree, &link_ix)?;
        // Mimic resolution (relations that cannot be honoured are warned about).
        let (mimic, mimic_warnings) = mimic::resolve(spec, &joint_ix);
        self.warnings.extend(mimic_warnings);
        let mut ix = Indexing {
            link_ix: &link_ix,
            parent_joint: &tree.parent_joint,
            new_link: inverse(&order_links),
            new_joint: inverse(&order_joints),
            order_links,
            order_joints,
            mimic,
            dof_of_spec_joint: vec![None; spec.joints.len()],
        };
        // Coordinates: independent movable joints in tree order.
        let mut dof_joints = Vec::new();
        for &j in &ix.order_joints {
            if spec.joints[j].jtype.is_movable() && ix.mimic[j].is_none() {
                ix.dof_of_spec_joint[j] = Some(dof_joints.len());
                dof_joints.push(ix.new_joint[j]);
            }
        }
        let mut m = empty_model(spec, dof_joints);
        let mut links = compile_links(spec, &ix, &mut m);
        let joints = compile_joints(spec, &ix, &links);
        for k in 0..m.nv {
            let lim = joints[m.dof_joints[k]].limits;
            m.lower[k] = lim.lower;
            m.upper[k] = lim.upper;
            m.velocity_limit[k] = lim.velocity;
            m.effort_limit[k] = lim.effort;
        }
        push_permutations_up(&mut m, &mut links);
        finish(&mut m, links, joints);
        Ok((m, self.warnings))
    }

    /// Link name → spec index; names must be non-empty and unique, numbers valid.
    fn index_links(&self) -> Result<HashMap<&'a str, usize>, ModelError> {
        let spec = self.spec;
        let mut link_ix: HashMap<&'a str, usize> = HashMap::with_capacity(spec.links.len());
        for (i, l) in spec.links.iter().enumerate() {
            if l.name.is_empty() {
                return Err(self.err_link(l, "empty link name"));
            }
            if link_ix.insert(l.name.as_str(), i).is_some() {
                return Err(self.err_link(l, "duplicate link name"));
            }
            self.check_link(l)?;
        }
        Ok(link_ix)
    }

    /// Joint name → spec index; names must be non-empty and unique, numbers valid.
    fn index_joints(&self) -> Result<HashMap<&'a str, usize>, ModelError> {
        let spec = self.spec;
        let mut joint_ix: HashMap<&'a str, usize> = HashMap::with_capacity(spec.joints.len());
        for (i, j) in spec.joints.iter().enumerate() {
            if j.name.is_empty() {
                return Err(self.err_joint(j, "empty joint name"));
            }
            if joint_ix.insert(j.name.as_str(), i).is_some() {
                return Err(self.err_joint(j, "duplicate joint name"));
            }
            self.check_joint(j)?;
        }
        Ok(joint_ix)
    }

    /// The tree the joints make: existing parent and child links, one parent per link,
    /// exactly one root.
    fn tree(&self, link_ix: &HashMap<&str, usize>) -> Result<Tree, ModelError> {
        let spec = self.spec;
        let nl = spec.links.len();
        let mut parent_joint: Vec<Option<usize>> = vec![None; nl];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); nl];
        for (ji, j) in spec.joints.iter().enumerate() {
            let p = *link_ix.get(j.parent.as_str()).ok_or_else(|| {
                self.err_joint(j, format!("parent link '{}' does not exist", j.parent))
            })?;
            let c = *link_ix.get(j.child.as_str()).ok_or_else(|| {
                self.err_joint(j, format!("child link '{}' does not exist", j.child))
            })?;
            if p == c {
                return Err(self.err_joint(j, format!("link '{}' is its own parent", j.parent)));
            }
            if let Some(prev) = parent_joint[c] {
                return Err(self.err_joint(
                    j,
                    format!(
                        "link '{}' has two parents: it is already the child of joint '{}'",
                        j.child, spec.joints[prev].name
                    ),
                ));
            }
            parent_joint[c] = Some(ji);
            children[p].push(ji);
        }
        let roots: Vec<usize> = (0..nl).filter(|&i| parent_joint[i].is_none()).collect();
        if roots.len() > 1 {
            let names: Vec<String> = roots
                .iter()
                .take(5)
                .map(|&i| format!("'{}'", spec.links[i].name))
                .collect();
            return Err(ModelError::new(
                &spec.source,
                spec.links[roots[1]].line,
                format!("link '{}'", spec.links[roots[1]].name),
                format!(
                    "more than one root link ({} roots: {}{}); every link but one needs a parent joint",
                    roots.len(),
                    names.join(", "),
                    if roots.len() > 5 { ", …" } else { "" }
                ),
            ));
        }
        let Some(&root) = roots.first() else {
            // Every link has a parent: there is a cycle.
            let j = &spec.joints[parent_joint[0].unwrap_or(0)];
            return Err(self.err_joint(j, "the joints form a cycle: no root link"));
        };
        Ok(Tree {
            parent_joint,
            children,
            root,
        })
    }

    /// Links and joints in depth-first order from the root, children in file order
    /// (iterative: deep chains cannot overflow the stack); a link not reached sits on a
    /// cycle.
    fn depth_first(
        &self,
        tree: &Tree,
        link_ix: &HashMap<&str, usize>,
    ) -> Result<(Vec<usize>, Vec<usize>), ModelError> {
        let spec = self.spec;
        let nl = spec.links.len();
        let mut order_joints: Vec<usize> = Vec::with_capacity(spec.joints.len());
        let mut order_links: Vec<usize> = Vec::with_capacity(nl);
        let mut stack: Vec<usize> = vec![tree.root];
        while let Some(l) = stack.pop() {
            order_links.push(l);
            if let Some(j) = tree.parent_joint[l] {
                order_joints.push(j);
            }
            for &cj in tree.children[l].iter().rev() {
                let c = link_ix[spec.joints[cj].child.as_str()];
                stack.push(c);
            }
        }
        if order_links.len() != nl {
            // Links not reachable from the root sit on a cycle.
            let mut seen = vec![false; nl];
            for &l in &order_links {
                seen[l] = true;
            }
            let l = (0..nl).find(|&i| !seen[i]).unwrap_or(0);
            let j = &spec.joints[tree.parent_joint[l].unwrap_or(0)];
            return Err(self.err_joint(
                j,
                format!(
                    "the joints form a cycle through link '{}' (not reachable from root '{}')",
                    spec.links[l].name, spec.links[tree.root].name
                ),
            ));
        }
        Ok((order_links, order_joints))
    }
}

/// `inv[order[k]] = k`.
fn inverse(order: &[usize]) -> Vec<usize> {
    let mut inv = vec![0usize; order.len()];
    for (k, &i) in order.iter().enumerate() {
        inv[i] = k;
    }
    inv
}

/// A model with the spec's name, source and gravity, `dof_joints` as its coordinates, and
/// no bodies, links or joints yet.
fn empty_model(spec: &ModelSpec, dof_joints: Vec<usize>) -> Model {
    let nv = dof_joints.len();
    Model {
        name: spec.name.clone(),
        source: spec.source.clone(),
        links: Vec::new(),
        joints: Vec::new(),
        nv,
        dof_joints,
        parent: Vec::new(),
        placement: Vec::new(),
        placement_perm: Vec::new(),
        placement_identity: Vec::new(),
        kind: Vec::new(),
        q_index: Vec::new(),
        q_mult: Vec::new(),
        q_offset: Vec::new(),
        has_mimic: false,
        mean_depth: 0.0,
        inertia: Vec::new(),
        inertia_o: Vec::new(),
        inertia6: Vec::new(),
        body_joint: Vec::new(),
        lower: vec![0.0; nv],
        upper: vec![0.0; nv],
        velocity_limit: vec![0.0; nv],
        effort_limit: vec![0.0; nv],
        gravity: spec.gravity.unwrap_or(Vec3::new(0.0, 0.0, -9.81)),
        armature: vec![0.0; nv],
        urdf_text: spec.urdf_text.clone(),
        link_index: HashMap::new(),
        joint_index: HashMap::new(),
    }
}

/// The links in tree order: each on the body of its parent joint when that moves, else
/// on its parent link's body at a fixed offset; a link's inertia joins its body's.
fn compile_links(spec: &ModelSpec, ix: &Indexing, m: &mut Model) -> Vec<Link> {
    let mut links: Vec<Link> = Vec::with_capacity(spec.links.len());
    for &l in &ix.order_links {
        let ls = &spec.links[l];
        let (body, offset, pj) = match ix.parent_joint[l] {
            None => (WORLD, spec.root_offset, None),
            Some(j) => {
                let js = &spec.joints[j];
                let parent = &links[ix.new_link[ix.link_ix[js.parent.as_str()]]];
                let (pb, poff) = (parent.body, parent.offset);
                if js.jtype.is_movable() {
                    let (b, off_child) = add_body(m, ix, j, js, pb, &poff);
                    (b, off_child, Some(ix.new_joint[j]))
                } else {
                    (
                        pb,
                        poff.mul(&js.origin).mul(&js.child_offset),
                        Some(ix.new_joint[j]),
                    )
                }
            }
        };
        if body != WORLD && !ls.inertial.is_zero() {
            let merged = m.inertia[body].combined(&ls.inertial.transformed(&offset));
            m.inertia[body] = merged;
        }
        links.push(Link {
            name: ls.name.clone(),
            parent_joint: pj,
            body,
            offset_is_identity: offset == Se3::identity(),
            offset,
            inertial: ls.inertial,
            visuals: ls.visuals.clone(),
            collisions: ls.collisions.clone(),
        });
    }
    links
}

/// A body for movable joint `j` (spec index) under body `pb`, whose link sits at `poff`
/// on it: its placement (rotated so that the axis is a signed coordinate axis, snapped
/// to an exact permutation where it is one), kind, coordinate and mimic relation.
/// Returns the body and the child link's offset on it.
fn add_body(
    m: &mut Model,
    ix: &Indexing,
    j: usize,
    js: &JointSpec,
    pb: usize,
    poff: &Se3,
) -> (usize, Se3) {
    let axis = js.axis.normalize();
    let (k, sign, ra) = match aligned_axis(&axis) {
        Some((k, sign)) => (k, sign, Mat3::identity()),
        None => (2, 1.0, rotation_z_to(&axis)),
    };
    let b = m.parent.len();
    m.parent.push(pb);
    let mut pl = poff.mul(&js.origin).mul(&Se3::from_rotation(ra));
    let perm = snap_signed_permutation(&mut pl.rot);
    m.placement.push(pl);
    m.placement_perm.push(perm);
    m.kind
        .push(BodyKind::new(js.jtype != JointType::Prismatic, k));
    let (qi, mult, off) = match ix.mimic[j] {
        None => (
            ix.dof_of_spec_joint[j].expect("independent joint"),
            1.0,
            0.0,
        ),
        Some((master, mult, off)) => {
            m.has_mimic = true;
            (
                ix.dof_of_spec_joint[master].expect("resolved master"),
                mult,
                off,
            )
        }
    };
    // Body coordinate = sign · (mult · q + off) along +e_k.
    m.q_index.push(qi);
    m.q_mult.push(sign * mult);
    m.q_offset.push(sign * off);
    m.inertia.push(Inertia::zero());
    m.body_joint.push(ix.new_joint[j]);
    let off_child = Se3::from_rotation(ra.transpose()).mul(&js.child_offset);
    (b, off_child)
}

/// The joints in tree order, with model link indices, their body and coordinate, and
/// unbounded limits for continuous joints.
fn compile_joints(spec: &ModelSpec, ix: &Indexing, links: &[Link]) -> Vec<Joint> {
    let mut joints: Vec<Joint> = Vec::with_capacity(spec.joints.len());
    for &j in &ix.order_joints {
        let js = &spec.joints[j];
        let child_link = ix.new_link[ix.link_ix[js.child.as_str()]];
        let body = if js.jtype.is_movable() {
            Some(links[child_link].body)
        } else {
            None
        };
        let mut limits = js.limits;
        if js.jtype == JointType::Continuous {
            limits.lower = f64::NEG_INFINITY;
            limits.upper = f64::INFINITY;
        }
        joints.push(Joint {
            name: js.name.clone(),
            jtype: js.jtype,
            parent_link: ix.new_link[ix.link_ix[js.parent.as_str()]],
            child_link,
            origin: js.origin,
            axis: if js.jtype.is_movable() {
                js.axis.normalize()
            } else {
                js.axis
            },
            limits,
            mimic: ix.mimic[j].map(|(mj, a, b)| (ix.new_joint[mj], a, b)),
            body,
            dof: ix.dof_of_spec_joint[j],
            damping: js.damping,
            friction: js.friction,
            motor_inertia: js.motor_inertia,
            gear_ratio: js.gear_ratio,
        });
    }
    joints
}

/// The derived tables: tree depth, identity placements, spatial inertias, and the name
/// indices; then the links and joints go into the model.
fn finish(m: &mut Model, links: Vec<Link>, joints: Vec<Joint>) {
    let mut depth = vec![0usize; m.parent.len()];
    for i in 0..m.parent.len() {
        depth[i] = if m.parent[i] == WORLD {
            1
        } else {
            depth[m.parent[i]] + 1
        };
    }
    m.mean_depth = depth.iter().sum::<usize>() as f64 / depth.len().max(1) as f64;
    m.placement_identity = m
        .placement
        .iter()
        .map(|p| p.rot == Mat3::identity())
        .collect();
    m.inertia_o = m.inertia.iter().map(InertiaO::from_inertia).collect();
    m.inertia6 = m.inertia_o.iter().map(InertiaO::to_matrix).collect();
    m.link_index = links
        .iter()
        .enumerate()
        .map(|(i, l)| (l.name.clone(), i))
        .collect();
    m.joint_index = joints
        .iter()
        .enumerate()
        .map(|(i, j)| (j.name.clone(), i))
        .collect();
    m.links = links;
    m.joints = joints;
}
