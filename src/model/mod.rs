//! The immutable [`Model`] of a mechanism: a kinematic tree of links and joints, compiled
//! from a [`ModelSpec`] (URDF, DH table or generated chain) into flat arrays for the hot
//! paths.
//!
//! Compilation (see [`Model::build`]):
//! - the tree is walked depth-first (children in file order, iteratively, so deep chains
//!   cannot overflow the stack); that order is **the joint order** every command uses;
//! - every movable joint becomes a *body*; a joint about ±x, ±y or ±z keeps its URDF
//!   frame (the sign folds into the coordinate's multiplier), any other axis gets a body
//!   frame rotated so that the axis is its local z: every body then moves by `Rx/Ry/Rz(q)`
//!   or `Tx/Ty/Tz(q)`;
//! - fixed joints are folded away: their links become frames rigidly attached to a body
//!   (or to the world), still queryable by name, and their inertias are merged into the
//!   body they ride on;
//! - mimic joints (`q = multiplier * q_master + offset`) are bodies without a coordinate
//!   of their own: they read the master's coordinate.

mod build;
pub mod chain;
pub mod data;
mod ids;
mod inertia_check;
mod joint_transform;
mod mimic;
mod model_error;
pub mod parse;
mod sampling;
mod spec;
mod spec_check;

pub(crate) use crate::model::joint_transform::AxisX;
pub use crate::model::model_error::{ModelError, ModelWarning};
use build::Builder;
pub use ids::{FrameId, JointId};
pub use inertia_check::{clamp_tolerance, CLAMP_ABS, CLAMP_REL};
pub use spec::{Geometry, JointSpec, JointType, Limits, LinkSpec, MimicSpec, ModelSpec, Shape};

use crate::core::spatial::{Inertia, InertiaO, Mat3, Se3, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// How to load a model file.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions {
    /// Turn warnings into errors.
    pub strict: bool,
    /// Treat mimic joints as independent coordinates.
    pub ignore_mimic: bool,
}

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

/// If `r` is within 1e-14 of a signed permutation matrix, makes it exact and returns
/// each column's `(row, sign)`. The tolerance is far below any physical meaning: it only
/// removes the `cos(π/2) = 6e-17` left by `rpy` and DH angles of ±90°.
fn snap_signed_permutation(r: &mut Mat3) -> Option<[(usize, f64); 3]> {
    const TOL: f64 = 1e-14;
    let mut out = [(0usize, 0.0f64); 3];
    let mut used = [false; 3];
    for c in 0..3 {
        let row = (0..3).find(|&i| (r[(i, c)].abs() - 1.0).abs() < TOL)?;
        if used[row] || (0..3).any(|i| i != row && r[(i, c)].abs() > TOL) {
            return None;
        }
        used[row] = true;
        out[c] = (row, r[(row, c)].signum());
    }
    for c in 0..3 {
        for i in 0..3 {
            r[(i, c)] = if i == out[c].0 { out[c].1 } else { 0.0 };
        }
    }
    Some(out)
}

/// Pushes placement rotations up the tree, so that in chains the body frames line up and
/// most placements are pure translations.
///
/// For a body `i` whose placement rotation `P` maps the parent's joint axis onto a body
/// axis (a signed permutation, or any rotation about that axis), the parent's body
/// frame is redefined as `F_p' = F_p P`. Then `R_k(θ) P = P R_{k'}(sθ)` with
/// `Pᵀ e_k = s e_{k'}`: the parent's joint turns about axis `k'` with its coordinate sign
/// `s`, its own placement becomes `placement_p · P` (itself pushed further up in turn),
/// every child placement and link offset on the parent is premultiplied by `Pᵀ`, and its
/// inertia is re-expressed. Body frames are internal: link frames, Jacobians and dynamics
/// are unchanged. Bodies are visited children first; a parent absorbs one child's `P`.
fn push_permutations_up(m: &mut Model, links: &mut [Link]) {
    let nb = m.parent.len();
    let mut absorbed = vec![false; nb];
    for i in (0..nb).rev() {
        let p = m.parent[i];
        if p == WORLD || absorbed[p] {
            continue;
        }
        let perm = m.placement[i].rot;
        if perm == Mat3::identity() {
            continue;
        }
        // Any P that maps the parent's joint axis onto a body axis commutes through the
        // parent's joint: signed permutations, and rotations about that axis.
        let kind = m.kind[p];
        let axis = perm.transpose().column(kind.axis_index()).into_owned();
        let Some((k2, sign)) = aligned_axis(&axis) else {
            continue;
        };
        absorbed[p] = true;
        let pt = Se3::from_rotation(perm.transpose());
        m.kind[p] = BodyKind::new(kind.is_revolute(), k2);
        m.q_mult[p] *= sign;
        m.q_offset[p] *= sign;
        m.placement[p].rot *= perm;
        m.placement_perm[p] = snap_signed_permutation(&mut m.placement[p].rot);
        for c in p + 1..nb {
            if m.parent[c] == p {
                m.placement[c] = pt.mul(&m.placement[c]);
                m.placement_perm[c] = snap_signed_permutation(&mut m.placement[c].rot);
            }
        }
        for l in links.iter_mut().filter(|l| l.body == p) {
            l.offset = pt.mul(&l.offset);
            l.offset_is_identity = l.offset == Se3::identity();
        }
        m.inertia[p] = m.inertia[p].transformed(&pt);
    }
}

/// For a unit axis exactly equal to ±e_k, `(k, ±1)`.
fn aligned_axis(a: &Vec3) -> Option<(usize, f64)> {
    (0..3).find_map(|k| {
        let others_zero = (0..3).filter(|&i| i != k).all(|i| a[i] == 0.0);
        (others_zero && a[k].abs() == 1.0).then(|| (k, a[k]))
    })
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
    link_index: HashMap<String, usize>,
    joint_index: HashMap<String, usize>,
}

impl Model {
    /// Loads a model file, choosing the loader by extension (`.urdf`/`.xml` or `.toml`).
    /// Returns the model and the warnings.
    pub fn load(path: impl AsRef<Path>) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::load_with(path, &LoadOptions::default())
    }

    /// [`Model::load_with`] with only `strict` set.
    pub fn load_checked(
        path: impl AsRef<Path>,
        strict: bool,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::load_with(
            path,
            &LoadOptions {
                strict,
                ignore_mimic: false,
            },
        )
    }

    /// Reads a model file into a [`ModelSpec`] without validating the tree.
    pub fn read_spec(path: &Path) -> Result<ModelSpec, ModelError> {
        let file = path.display().to_string();
        let text = crate::core::files::read_input_string(path)
            .map_err(|e| ModelError::new(&file, None, "file", format!("cannot read: {e}")))?;
        Self::spec_from_str(&text, &file)
    }

    /// Parses model text into a [`ModelSpec`] without touching the filesystem (the
    /// string form of [`Model::read_spec`], used by the fuzz targets): `file` names the
    /// text in messages and its extension picks the loader (`.urdf`/`.xml` or `.toml`).
    pub fn spec_from_str(text: &str, file: &str) -> Result<ModelSpec, ModelError> {
        if text.trim().is_empty() {
            return Err(ModelError::new(file, None, "file", "the file is empty"));
        }
        let ext = Path::new(file)
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "urdf" | "xml" => parse::urdf::parse(text, file),
            "toml" => parse::dh_table::parse(text, file),
            _ => Err(ModelError::new(
                file,
                None,
                "file",
                "unknown model format: expected a .urdf or a .toml (DH table) file",
            )),
        }
    }

    /// Loads with options: `strict` fails on warnings; `ignore_mimic` makes every mimic
    /// joint an independent coordinate (as Pinocchio's default URDF parser does).
    pub fn load_with(
        path: impl AsRef<Path>,
        opts: &LoadOptions,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::build_with(Self::read_spec(path.as_ref())?, opts)
    }

    /// [`Model::load_with`] on text instead of a file: `file` names the text in messages
    /// and its extension picks the loader (see [`Model::spec_from_str`]).
    pub fn load_str(
        text: &str,
        file: &str,
        opts: &LoadOptions,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        Self::build_with(Self::spec_from_str(text, file)?, opts)
    }

    fn build_with(
        mut spec: ModelSpec,
        opts: &LoadOptions,
    ) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        if opts.ignore_mimic {
            for j in &mut spec.joints {
                j.mimic = None;
            }
        }
        let (m, w) = Model::build(spec)?;
        if opts.strict {
            if let Some(first) = w.into_iter().next() {
                return Err(first);
            }
            return Ok((m, Vec::new()));
        }
        Ok((m, w))
    }

    /// Number of bodies (movable joints, mimic ones included).
    pub fn nbodies(&self) -> usize {
        self.parent.len()
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

    /// Validates a spec and compiles it (see the module docs). The warnings start with
    /// the reader's ([`ModelSpec::warnings`]).
    pub fn build(mut spec: ModelSpec) -> Result<(Model, Vec<ModelWarning>), ModelError> {
        let mut warnings = std::mem::take(&mut spec.warnings);
        for l in spec.links.iter_mut() {
            warnings.extend(inertia_check::check(l, &spec.source)?);
        }
        Builder {
            spec: &spec,
            warnings,
        }
        .build()
    }
}
