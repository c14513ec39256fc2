//! The compiled [`Model`] and its parts: [`Link`]s and [`Joint`]s as the user sees them,
//! the flat per-body arrays of the hot paths with each body's [`BodyKind`], the [`WORLD`]
//! marker, and the queries on the tree (support, common ancestor, names to indices).
//! Loading and compiling are in `mod.rs` and `build.rs`.

use crate::core::spatial::{Inertia, InertiaO, Se3, Vec3};
use crate::model::spec::{Geometry, JointType, Limits};
use std::collections::HashMap;

/// Marker for "no parent body" (attached to the world).
pub const WORLD: usize = usize::MAX;

/// How a body moves relative to its parent: about or along one axis of its own frame.
/// Axis-aligned joints (±x, ±y, ±z) keep the URDF frame, a negative direction folding into
/// the coordinate's sign; any other axis gets a body frame whose z is the axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// Rotation `Rx(q)`.
    RevoluteX,
    /// Rotation `Ry(q)`.
    RevoluteY,
    /// Rotation `Rz(q)`.
    RevoluteZ,
    /// Translation `Tx(q)`.
    PrismaticX,
    /// Translation `Ty(q)`.
    PrismaticY,
    /// Translation `Tz(q)`.
    PrismaticZ,
}

impl BodyKind {
    /// The kind for a revolute (`true`) or prismatic joint about/along axis `k` (0, 1, 2).
    pub fn new(revolute: bool, k: usize) -> Self {
        match (revolute, k) {
            (true, 0) => BodyKind::RevoluteX,
            (true, 1) => BodyKind::RevoluteY,
            (true, _) => BodyKind::RevoluteZ,
            (false, 0) => BodyKind::PrismaticX,
            (false, 1) => BodyKind::PrismaticY,
            (false, _) => BodyKind::PrismaticZ,
        }
    }

    /// Index of the joint axis in the body frame.
    #[inline(always)]
    pub fn axis_index(&self) -> usize {
        match self {
            BodyKind::RevoluteX | BodyKind::PrismaticX => 0,
            BodyKind::RevoluteY | BodyKind::PrismaticY => 1,
            BodyKind::RevoluteZ | BodyKind::PrismaticZ => 2,
        }
    }

    /// Whether the joint rotates.
    #[inline(always)]
    pub fn is_revolute(&self) -> bool {
        matches!(
            self,
            BodyKind::RevoluteX | BodyKind::RevoluteY | BodyKind::RevoluteZ
        )
    }
}

/// A joint as the user sees it (all joints, fixed ones included), in tree order.
#[derive(Clone, Debug)]
pub struct Joint {
    /// Joint name.
    pub name: String,
    /// Joint type.
    pub jtype: JointType,
    /// Parent link index.
    pub parent_link: usize,
    /// Child link index.
    pub child_link: usize,
    /// Parent link frame → joint frame at q = 0.
    pub origin: Se3,
    /// Unit axis in the joint frame.
    pub axis: Vec3,
    /// Limits.
    pub limits: Limits,
    /// Master joint index, multiplier and offset, for mimic joints.
    pub mimic: Option<(usize, f64, f64)>,
    /// Body index for movable joints.
    pub body: Option<usize>,
    /// Coordinate index for independent movable joints (mimic joints have none).
    pub dof: Option<usize>,
    /// Viscous damping (N m s/rad) from the file.
    pub damping: f64,
    /// Coulomb friction (N m) from the file.
    pub friction: f64,
    /// Rotor inertia (kg m²).
    pub motor_inertia: f64,
    /// Gear ratio.
    pub gear_ratio: f64,
}

/// A link: a named frame rigidly attached to a body (or to the world).
#[derive(Clone, Debug)]
pub struct Link {
    /// Link name.
    pub name: String,
    /// The joint whose child this link is (None for the root).
    pub parent_joint: Option<usize>,
    /// The body carrying this link's frame, or [`WORLD`].
    pub body: usize,
    /// Body frame → link frame (world → link frame when `body == WORLD`).
    pub offset: Se3,
    /// Whether `offset` is exactly the identity (the link frame is the body frame).
    pub offset_is_identity: bool,
    /// Inertia in the link frame, as read.
    pub inertial: Inertia,
    /// Visual geometry in the link frame.
    pub visuals: Vec<Geometry>,
    /// Collision geometry in the link frame.
    pub collisions: Vec<Geometry>,
}

/// The immutable model. Hot-path arrays are indexed by body (one per movable joint,
/// parents before children).
#[derive(Clone, Debug)]
pub struct Model {
    /// Robot name.
    pub name: String,
    /// File it was loaded from.
    pub source: String,
    /// Links in tree (depth-first) order; the root first.
    pub links: Vec<Link>,
    /// Joints in tree order (fixed ones included).
    pub joints: Vec<Joint>,
    /// Number of independent coordinates (q, v and tau have this length).
    pub nv: usize,
    /// The joint index of each coordinate, in order.
    pub dof_joints: Vec<usize>,
    /// Body parent (or [`WORLD`]); `parent[i] < i`.
    pub parent: Vec<usize>,
    /// Parent body frame → this body's frame at q = 0.
    pub placement: Vec<Se3>,
    /// For placements whose rotation is a signed permutation (URDF `rpy` in multiples of
    /// π/2, DH twists of ±90°): column `c` of the rotation is `sign · e_row`, as
    /// `(row, sign)`. Products with it are column shuffles (see `kinematics::fk`).
    pub placement_perm: Vec<Option<[(usize, f64); 3]>>,
    /// Whether each placement rotation is exactly the identity (after the permutations
    /// have been pushed up the tree).
    pub placement_identity: Vec<bool>,
    /// Motion type of each body.
    pub kind: Vec<BodyKind>,
    /// The coordinate that drives each body.
    pub q_index: Vec<usize>,
    /// Mimic multiplier of each body (1 for independent joints).
    pub q_mult: Vec<f64>,
    /// Mimic offset of each body (0 for independent joints).
    pub q_offset: Vec<f64>,
    /// Whether any body is a mimic joint.
    pub has_mimic: bool,
    /// Mean number of ancestors per body (1 for a single joint, ~n/2 for a chain).
    pub mean_depth: f64,
    /// Inertia of each body in its body frame (links on fixed joints merged in).
    pub inertia: Vec<Inertia>,
    /// The same inertias in origin form (for the recursive dynamics).
    pub inertia_o: Vec<InertiaO>,
    /// The same inertias as 6×6 matrices (for ABA).
    pub inertia6: Vec<nalgebra::Matrix6<f64>>,
    /// The joint index of each body.
    pub body_joint: Vec<usize>,
    /// Lower position limit per coordinate.
    pub lower: Vec<f64>,
    /// Upper position limit per coordinate.
    pub upper: Vec<f64>,
    /// Velocity limit per coordinate.
    pub velocity_limit: Vec<f64>,
    /// Effort limit per coordinate.
    pub effort_limit: Vec<f64>,
    /// Gravity the file asks for (default `(0, 0, -9.81)`); every dynamics function that
    /// does not take an [`Effects`](crate::dynamics::Effects) reads it, as in Pinocchio.
    pub gravity: Vec3,
    /// Rotor armature per coordinate (kg m² for a revolute joint, kg for a prismatic one),
    /// as Pinocchio's `model.armature`: RNEA adds `armature[k] q̈_k` to `τ_k`, CRBA adds it
    /// to `M_kk`, ABA to the joint's articulated inertia, and the kinetic energy
    /// `½ armature[k] q̇_k²`. Zero on load: the file's `motor_inertia` and `gear_ratio`
    /// feed the switchable [`Rotor`](crate::dynamics::Rotor) effect instead, which adds
    /// on top, so a rotor is never counted twice.
    pub armature: Vec<f64>,
    /// URDF text of the model, when it came from one.
    pub urdf_text: Option<String>,
    pub(super) link_index: HashMap<String, usize>,
    pub(super) joint_index: HashMap<String, usize>,
}

impl Model {
    /// Number of bodies (movable joints, mimic ones included).
    pub fn nbodies(&self) -> usize {
        self.parent.len()
    }

    /// Whether the bodies form one serial chain: every body the child of the one before
    /// (the first of the world).
    pub fn is_serial_chain(&self) -> bool {
        (0..self.nbodies()).all(|i| self.parent[i] == i.checked_sub(1).unwrap_or(WORLD))
    }

    /// `body` and its ancestors, deepest first, up to the root (nothing for [`WORLD`]).
    pub fn support(&self, body: usize) -> impl Iterator<Item = usize> + '_ {
        std::iter::successors((body != WORLD).then_some(body), |&b| {
            let p = self.parent[b];
            (p != WORLD).then_some(p)
        })
    }

    /// The deepest body that is an ancestor of both `a` and `b` (each its own ancestor),
    /// or [`WORLD`] (also when either is [`WORLD`]).
    pub fn common_ancestor(&self, a: usize, b: usize) -> usize {
        self.support(b)
            .find(|&x| self.support(a).any(|y| y == x))
            .unwrap_or(WORLD)
    }

    /// The arm's tool link, the default of every "which link" argument: follow the tree
    /// from the world while a body carries exactly one moving child, and take the last
    /// link (in tree order) fixed to the body where that stops — UR5 `tool0`, Panda
    /// `panda_hand_tcp` (its body carries the two fingers), iiwa `iiwa_link_ee`. When the
    /// world itself branches (two arms, a humanoid) there is no single tool, and the last
    /// link is returned.
    pub fn tool_link(&self) -> usize {
        let last = self.links.len() - 1;
        // One pass: each body's child when it has exactly one (`None` when it has none
        // or several), the world's likewise; then the walk.
        let nb = self.nbodies();
        let (mut child, mut count) = (vec![None; nb], vec![0u8; nb]);
        let (mut root, mut roots) = (None, 0u8);
        for b in 0..nb {
            let (slot, n) = match self.parent[b] {
                WORLD => (&mut root, &mut roots),
                p => (&mut child[p], &mut count[p]),
            };
            *n = n.saturating_add(1);
            *slot = (*n == 1).then_some(b);
        }
        let mut end = WORLD;
        let mut next = root;
        while let Some(b) = next {
            end = b;
            next = child[b];
        }
        if end == WORLD {
            return last;
        }
        (0..self.links.len())
            .rev()
            .find(|&l| self.links[l].body == end)
            .unwrap_or(last)
    }

    /// How far body `b`'s origin slides from its placement for coordinates in `[lo, hi]`:
    /// the largest `|m q + o|` of a prismatic joint, zero for a revolute one.
    pub fn stroke(&self, b: usize, lo: f64, hi: f64) -> f64 {
        if self.kind[b].is_revolute() {
            return 0.0;
        }
        let s = |q: f64| (self.q_mult[b] * q + self.q_offset[b]).abs();
        s(lo).max(s(hi))
    }

    /// Link index by name.
    pub fn link_id(&self, name: &str) -> Option<usize> {
        self.link_index.get(name).copied()
    }

    /// Joint index by name.
    pub fn joint_id(&self, name: &str) -> Option<usize> {
        self.joint_index.get(name).copied()
    }

    /// Names of the coordinates, in order.
    pub fn dof_names(&self) -> Vec<String> {
        self.dof_joints
            .iter()
            .map(|&j| self.joints[j].name.clone())
            .collect()
    }

    /// The joint driving coordinate `k`.
    pub fn dof_joint(&self, k: usize) -> &Joint {
        &self.joints[self.dof_joints[k]]
    }

    /// Whether coordinate `k` is an unbounded angle (continuous joint).
    pub fn is_continuous(&self, k: usize) -> bool {
        self.dof_joint(k).jtype == JointType::Continuous
    }
}
