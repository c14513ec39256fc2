//! Batched forward kinematics of one link's origin: eight configurations at once, one
//! per SIMD lane, in `f64` (struct of arrays, `[f64; 8]` per quantity).
//!
//! [`ToolChain`] walks the bodies from the root to the link's body once, at build time,
//! and [`ToolChain::positions`] then runs the same recursion as
//! [`crate::kinematics::forward_kinematics`] + [`crate::kinematics::frame_placement`] for eight
//! configurations: `oMi = oM_parent · placement_i · J_i(q_i)`, the placement's rotation applied as
//! a column shuffle when it is a signed permutation, the joint as a two-column rotation or a
//! column shift, `sin`/`cos` by [`crate::core::fastmath::sin_cos`]'s branch-free algorithm per
//! lane. Rotations that no later translation uses (after the last body whose origin or
//! stroke moves the link origin, e.g. a wrist roll under a tool on its axis) are skipped.
//!
//! Every lane loop is a straight line over `[f64; 8]`, which the compiler turns into one
//! AVX-512 register, two AVX2 registers or four SSE2 registers, depending on the
//! instruction set [`Isa`] detected at run time (`#[target_feature]` entries; the binary
//! stays baseline x86-64). [`ToolChain::positions_lanes`] is `#[inline(always)]` so that a
//! caller's own `#[target_feature]` entry (the workspace sampler's) compiles it with its
//! features. No fused multiply-add is written and Rust never contracts `a * b + c`, so
//! every lane performs the scalar code's operations in the scalar code's order on every
//! instruction set: the positions agree with the scalar FK to rounding (tested to 1e-12 m)
//! and are bitwise the same on every [`Isa`].
//!
//! [`ToolChain::for_pose`] keeps every rotation and [`ToolChain::poses`] returns the link's
//! full pose (rotation and translation), for batched frame placements
//! ([`crate::kinematics::pose_lanes`]).
//!
//! The planner's collision checker batches in `f32` lanes (`planning::simd`); a workspace
//! volume needs the `f64` positions of the scalar FK, hence this separate kernel.

// Lane loops index several arrays by the lane (rotation entries, translations, joint
// values): an explicit index keeps the scalar code's operations visible.
#![allow(clippy::needless_range_loop)]

use crate::core::simd_lanes::sin_cos8;
pub use crate::core::simd_lanes::{lanes_in_range, Isa, Lanes, LANES};
use crate::model::{BodyKind, Model, WORLD};

/// One body of the chain, with what its step needs.
#[derive(Clone, Debug)]
struct Step {
    kind: BodyKind,
    q_index: usize,
    q_mult: f64,
    q_offset: f64,
    /// Placement rotation (row-major) when it is neither the identity nor a permutation.
    rot: Option<[f64; 9]>,
    /// Signed permutation: column `c` of the result is `sign × column row` of the parent.
    perm: Option<[(usize, f64); 3]>,
    trans: [f64; 3],
    /// The root body (its parent is the world).
    root: bool,
    /// Whether the placement's rotation is applied (some later translation, the tool
    /// offset or this body's prismatic stroke uses it).
    place_rot: bool,
    /// Whether the joint's rotation is applied (some later translation or the tool offset
    /// uses the columns it turns).
    joint_rot: bool,
}

/// The chain from the root to one link, for batched position FK.
#[derive(Clone, Debug)]
pub struct ToolChain {
    steps: Vec<Step>,
    /// The link's offset in its body frame (translation).
    offset: [f64; 3],
    /// The offset's rotation (row-major), for [`ToolChain::poses`].
    offset_rot: [f64; 9],
    /// Every rotation is kept ([`ToolChain::for_pose`]): [`ToolChain::poses`] may run.
    full_pose: bool,
    nq: usize,
    isa: Isa,
}

/// A pose per lane: rotation (row-major, 9 entries) and translation.
#[derive(Clone, Copy)]
struct Pose8 {
    r: [Lanes; 9],
    t: [Lanes; 3],
}

impl ToolChain {
    /// The chain of `model` from the root to the body of link `link` (whose origin is
    /// computed). `None` when the link is fixed to the world.
    pub fn new(model: &Model, link: usize) -> Option<ToolChain> {
        let l = &model.links[link];
        if l.body == WORLD {
            return None;
        }
        let mut bodies: Vec<usize> = model.support(l.body).collect();
        bodies.reverse();
        let steps = bodies
            .iter()
            .map(|&i| {
                let pl = &model.placement[i];
                let root = model.parent[i] == WORLD;
                let rot = (root
                    || (!model.placement_identity[i] && model.placement_perm[i].is_none()))
                .then(|| {
                    let m = &pl.rot;
                    [
                        m[(0, 0)],
                        m[(0, 1)],
                        m[(0, 2)],
                        m[(1, 0)],
                        m[(1, 1)],
                        m[(1, 2)],
                        m[(2, 0)],
                        m[(2, 1)],
                        m[(2, 2)],
                    ]
                });
                Step {
                    kind: model.kind[i],
                    q_index: model.q_index[i],
                    q_mult: model.q_mult[i],
                    q_offset: model.q_offset[i],
                    rot,
                    perm: if root || model.placement_identity[i] {
                        None
                    } else {
                        model.placement_perm[i]
                    },
                    trans: [pl.trans.x, pl.trans.y, pl.trans.z],
                    root,
                    place_rot: true,
                    joint_rot: true,
                }
            })
            .collect();
        let (o, r) = (l.offset.trans, &l.offset.rot);
        let mut chain = ToolChain {
            steps,
            offset: [o.x, o.y, o.z],
            offset_rot: std::array::from_fn(|k| r[(k / 3, k % 3)]),
            full_pose: false,
            nq: model.nv,
            isa: Isa::at_most(None),
        };
        chain.skip_unused_rotations();
        Some(chain)
    }

    /// [`ToolChain::new`] keeping every rotation, for the link's full pose
    /// ([`ToolChain::poses`]).
    pub fn for_pose(model: &Model, link: usize) -> Option<ToolChain> {
        let mut chain = ToolChain::new(model, link)?;
        for st in &mut chain.steps {
            (st.place_rot, st.joint_rot) = (true, true);
        }
        chain.full_pose = true;
        Some(chain)
    }

    /// Clears the rotation flags of the trailing steps whose rotation no later
    /// translation, prismatic stroke or tool offset uses: walking back from the link,
    /// the rotation after a step is needed when the link's offset, or a later step's
    /// translation or stroke, reads it. The last joint's rotation is also skipped when it
    /// is revolute and the offset lies on its axis (the columns it turns are multiplied
    /// by zeros; only the sign of a zero position could differ).
    fn skip_unused_rotations(&mut self) {
        let nonzero = |v: &[f64; 3]| v.iter().any(|&x| x != 0.0);
        let mut needed_after = nonzero(&self.offset);
        let last = self.steps.len() - 1;
        for (i, st) in self.steps.iter_mut().enumerate().rev() {
            let prismatic = !st.kind.is_revolute();
            st.place_rot = needed_after || prismatic;
            st.joint_rot = needed_after && !prismatic;
            if i == last && st.joint_rot {
                let (a, b) = turned_columns(st.kind);
                st.joint_rot = self.offset[a] != 0.0 || self.offset[b] != 0.0;
            }
            needed_after |= nonzero(&st.trans) || prismatic;
        }
    }

    /// Runs [`Self::positions`] on at most `max` (to compare instruction sets; every one
    /// gives bitwise the same positions).
    pub fn limit_isa(&mut self, max: Isa) {
        self.isa = Isa::at_most(Some(max));
    }

    /// The instruction set [`Self::positions`] runs on.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Coordinates per configuration.
    pub fn nq(&self) -> usize {
        self.nq
    }

    /// World positions of the link origin for eight configurations: `q[k][lane]` is
    /// coordinate `k` of lane `lane` (`q.len()` = the model's `nv`); writes
    /// `out[axis][lane]`.
    pub fn positions(&self, q: &[Lanes], out: &mut [Lanes; 3]) {
        assert_eq!(q.len(), self.nq, "one lane array per coordinate");
        #[cfg(target_arch = "x86_64")]
        match self.isa {
            // SAFETY: `isa` is at most what `Isa::detected` found on this CPU.
            Isa::Avx512 => return unsafe { positions_avx512(self, q, out) },
            Isa::Avx2 => return unsafe { positions_avx2(self, q, out) },
            Isa::Baseline => {}
        }
        self.positions_lanes(q, out);
    }

    /// The pose of the link's body for eight configurations: the chain's steps from the
    /// root (rotations the chain skips are left as they were).
    #[inline(always)]
    fn body_pose(&self, q: &[Lanes]) -> Pose8 {
        let mut pose = Pose8 {
            r: [[0.0; LANES]; 9],
            t: [[0.0; LANES]; 3],
        };
        for st in &self.steps {
            let mut qs = [0.0; LANES];
            for (l, v) in qs.iter_mut().enumerate() {
                *v = q[st.q_index][l] * st.q_mult + st.q_offset;
            }
            step(st, &mut pose, &qs);
        }
        pose
    }

    /// [`Self::positions`] compiled with the caller's instruction set (inlined into it;
    /// `q.len()` must be the model's `nv`).
    #[inline(always)]
    pub fn positions_lanes(&self, q: &[Lanes], out: &mut [Lanes; 3]) {
        let pose = self.body_pose(q);
        let [ox, oy, oz] = self.offset;
        if self.offset == [0.0; 3] {
            *out = pose.t;
            return;
        }
        for (a, o) in out.iter_mut().enumerate() {
            for l in 0..LANES {
                let r = &pose.r;
                o[l] = ((r[3 * a][l] * ox + r[3 * a + 1][l] * oy) + r[3 * a + 2][l] * oz)
                    + pose.t[a][l];
            }
        }
    }
}

impl ToolChain {
    /// World poses of the link for eight configurations (a chain from
    /// [`ToolChain::for_pose`]): `out[0..9]` the rotation row-major, `out[9..12]` the
    /// translation, each `[lane]`; the scalar `frame_placement`'s operations in its order.
    pub fn poses(&self, q: &[Lanes], out: &mut [Lanes; 12]) {
        assert!(
            self.full_pose,
            "poses need a chain from ToolChain::for_pose"
        );
        assert_eq!(q.len(), self.nq, "one lane array per coordinate");
        #[cfg(target_arch = "x86_64")]
        match self.isa {
            // SAFETY: `isa` is at most what `Isa::detected` found on this CPU.
            Isa::Avx512 => return unsafe { poses_avx512(self, q, out) },
            Isa::Avx2 => return unsafe { poses_avx2(self, q, out) },
            Isa::Baseline => {}
        }
        self.poses_lanes(q, out);
    }

    /// [`Self::poses`] compiled with the caller's instruction set.
    #[inline(always)]
    fn poses_lanes(&self, q: &[Lanes], out: &mut [Lanes; 12]) {
        let pose = self.body_pose(q);
        // oM_link = oM_body · offset: R = R_b R_o, t = R_b o + t_b.
        let (r, m, o) = (&pose.r, &self.offset_rot, &self.offset);
        for row in 0..3 {
            for c in 0..3 {
                for l in 0..LANES {
                    out[3 * row + c][l] = (r[3 * row][l] * m[c] + r[3 * row + 1][l] * m[3 + c])
                        + r[3 * row + 2][l] * m[6 + c];
                }
            }
            for l in 0..LANES {
                out[9 + row][l] = ((r[3 * row][l] * o[0] + r[3 * row + 1][l] * o[1])
                    + r[3 * row + 2][l] * o[2])
                    + pose.t[row][l];
            }
        }
    }
}

/// Runs `poses_lanes` compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn poses_avx2(chain: &ToolChain, q: &[Lanes], out: &mut [Lanes; 12]) {
    chain.poses_lanes(q, out)
}

/// Runs `poses_lanes` compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq")]
unsafe fn poses_avx512(chain: &ToolChain, q: &[Lanes], out: &mut [Lanes; 12]) {
    chain.poses_lanes(q, out)
}

/// Runs `positions_lanes` compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn positions_avx2(chain: &ToolChain, q: &[Lanes], out: &mut [Lanes; 3]) {
    chain.positions_lanes(q, out)
}

/// Runs `positions_lanes` compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512dq")]
unsafe fn positions_avx512(chain: &ToolChain, q: &[Lanes], out: &mut [Lanes; 3]) {
    chain.positions_lanes(q, out)
}

/// The two columns a revolute joint's rotation turns (see [`rotate`]).
fn turned_columns(kind: BodyKind) -> (usize, usize) {
    match kind {
        BodyKind::RevoluteX => (1, 2),
        BodyKind::RevoluteY => (2, 0),
        _ => (0, 1),
    }
}

/// `pose ← pose · placement · J(q)` (or `placement · J(q)` at the root).
#[inline(always)]
fn step(st: &Step, pose: &mut Pose8, q: &Lanes) {
    let [px, py, pz] = st.trans;
    if st.root {
        let m = st.rot.expect("the root keeps its rotation");
        for (k, r) in pose.r.iter_mut().enumerate() {
            *r = [m[k]; LANES];
        }
        pose.t = [[px; LANES], [py; LANES], [pz; LANES]];
    } else {
        let r = pose.r;
        // Translation first: it uses the parent's rotation.
        for a in 0..3 {
            for l in 0..LANES {
                pose.t[a][l] += (r[3 * a][l] * px + r[3 * a + 1][l] * py) + r[3 * a + 2][l] * pz;
            }
        }
        if !st.place_rot {
            // Nothing later reads the rotation.
        } else if let Some(p) = st.perm {
            for (c, &(src, sign)) in p.iter().enumerate() {
                for row in 0..3 {
                    for l in 0..LANES {
                        pose.r[3 * row + c][l] = r[3 * row + src][l] * sign;
                    }
                }
            }
        } else if let Some(m) = st.rot {
            for row in 0..3 {
                for c in 0..3 {
                    for l in 0..LANES {
                        pose.r[3 * row + c][l] = (r[3 * row][l] * m[c]
                            + r[3 * row + 1][l] * m[3 + c])
                            + r[3 * row + 2][l] * m[6 + c];
                    }
                }
            }
        }
    }
    match st.kind {
        _ if st.kind.is_revolute() && !st.joint_rot => {}
        BodyKind::RevoluteX => rotate(pose, 1, 2, q),
        BodyKind::RevoluteY => rotate(pose, 2, 0, q),
        BodyKind::RevoluteZ => rotate(pose, 0, 1, q),
        BodyKind::PrismaticX => slide(pose, 0, q),
        BodyKind::PrismaticY => slide(pose, 1, q),
        BodyKind::PrismaticZ => slide(pose, 2, q),
    }
}

/// `R ← R · R_k(q)`: columns `i`, `j` rotate (functions, not closures, so that they
/// inline into the AVX2 entry and are compiled with its features).
#[inline(always)]
fn rotate(pose: &mut Pose8, i: usize, j: usize, q: &Lanes) {
    let (s, c) = sin_cos8(q);
    for row in 0..3 {
        for l in 0..LANES {
            let a = pose.r[3 * row + i][l];
            let b = pose.r[3 * row + j][l];
            pose.r[3 * row + i][l] = c[l] * a + s[l] * b;
            pose.r[3 * row + j][l] = c[l] * b - s[l] * a;
        }
    }
}

/// `t ← t + R e_k q`.
#[inline(always)]
fn slide(pose: &mut Pose8, k: usize, q: &Lanes) {
    for a in 0..3 {
        for l in 0..LANES {
            pose.t[a][l] += pose.r[3 * a + k][l] * q[l];
        }
    }
}
