//! Batched forward kinematics of one link's origin: eight configurations at once, one
//! per SIMD lane, in `f64` (struct of arrays, `[f64; 8]` per quantity).
//!
//! [`ToolChain`] walks the bodies from the root to the link's body once, at build time,
//! and [`ToolChain::positions`] then runs the same recursion as
//! [`super::forward_kinematics`] + [`super::frame_placement`] for eight configurations:
//! `oMi = oM_parent · placement_i · J_i(q_i)`, the placement's rotation applied as a column
//! shuffle when it is a signed permutation, the joint as a two-column rotation or a
//! column shift, `sin`/`cos` by [`crate::fastmath::sin_cos`]'s branch-free algorithm per
//! lane. Every lane loop is a straight line over `[f64; 8]`, which the compiler turns into
//! two AVX2 registers (4 × f64 each) inside a `#[target_feature(enable = "avx2")]` entry
//! chosen at run time, and into four SSE2 registers otherwise; the binary stays baseline
//! x86-64. No fused multiply-add is used, so every lane performs the scalar code's
//! operations in the scalar code's order: the positions agree with the scalar FK to
//! rounding (tested to 1e-12 m).
//!
//! The planner's collision checker batches in `f32` lanes (`planning::simd`); a workspace
//! volume needs the `f64` positions of the scalar FK, hence this separate kernel.

// Lane loops index several arrays by the lane (rotation entries, translations, joint
// values): an explicit index keeps the scalar code's operations visible.
#![allow(clippy::needless_range_loop)]

use crate::model::{BodyKind, Model, WORLD};

/// Lanes per batch.
pub const LANES: usize = 8;

/// Eight values, one per lane.
pub type Lanes = [f64; LANES];

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
}

/// The chain from the root to one link, for batched position FK.
#[derive(Clone, Debug)]
pub struct ToolChain {
    steps: Vec<Step>,
    /// The link's offset in its body frame (translation).
    offset: [f64; 3],
    nq: usize,
    avx2: bool,
}

/// A pose per lane: rotation (row-major, 9 entries) and translation.
#[derive(Clone, Copy)]
struct Pose8 {
    r: [Lanes; 9],
    t: [Lanes; 3],
}

/// `(sin x, cos x)` per lane, [`crate::fastmath::sin_cos`]'s algorithm (valid for
/// `|x| ≤ 1e5`; the caller checks).
#[inline(always)]
fn sin_cos8(x: &Lanes) -> (Lanes, Lanes) {
    use crate::fastmath::{C, FRAC_2_PI, PIO2_1, PIO2_2, PIO2_3, S};
    const SHIFTER: f64 = 6_755_399_441_055_744.0;
    let mut so = [0.0; LANES];
    let mut co = [0.0; LANES];
    for l in 0..LANES {
        let x = x[l];
        let t = x * FRAC_2_PI + SHIFTER;
        // The low mantissa bits of `t` are k (two's complement): no float-to-int
        // conversion, which AVX2 lacks for 64-bit integers.
        let kb = t.to_bits();
        let kf = t - SHIFTER;
        let r = ((x - kf * PIO2_1) - kf * PIO2_2) - kf * PIO2_3;
        let z = r * r;
        let ps = ((((S[0] * z + S[1]) * z + S[2]) * z + S[3]) * z + S[4]) * z + S[5];
        let s = r + r * z * ps;
        let pc = ((((C[0] * z + C[1]) * z + C[2]) * z + C[3]) * z + C[4]) * z + C[5];
        let c = 1.0 - 0.5 * z + z * z * pc;
        let swap = kb & 1 != 0;
        let (sv, cv) = if swap { (c, s) } else { (s, c) };
        let sin_neg = (kb & 2) << 62;
        let cos_neg = (kb.wrapping_add(1) & 2) << 62;
        so[l] = f64::from_bits(sv.to_bits() ^ sin_neg);
        co[l] = f64::from_bits(cv.to_bits() ^ cos_neg);
    }
    (so, co)
}

impl ToolChain {
    /// The chain of `model` from the root to the body of link `link` (whose origin is
    /// computed). `None` when the link is fixed to the world.
    pub fn new(model: &Model, link: usize) -> Option<ToolChain> {
        let l = &model.links[link];
        if l.body == WORLD {
            return None;
        }
        let mut bodies = Vec::new();
        let mut b = l.body;
        while b != WORLD {
            bodies.push(b);
            b = model.parent[b];
        }
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
                }
            })
            .collect();
        let o = l.offset.trans;
        Some(ToolChain {
            steps,
            offset: [o.x, o.y, o.z],
            nq: model.nv,
            avx2: detect_avx2(),
        })
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
        if self.avx2 {
            // SAFETY: `avx2` is set only when the CPU reports AVX2.
            unsafe { positions_avx2(self, q, out) };
            return;
        }
        self.positions_generic(q, out);
    }

    #[inline(always)]
    fn positions_generic(&self, q: &[Lanes], out: &mut [Lanes; 3]) {
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
        let [ox, oy, oz] = self.offset;
        for (a, o) in out.iter_mut().enumerate() {
            for l in 0..LANES {
                let r = &pose.r;
                o[l] = ((r[3 * a][l] * ox + r[3 * a + 1][l] * oy) + r[3 * a + 2][l] * oz)
                    + pose.t[a][l];
            }
        }
    }
}

/// Runs `positions_generic` compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn positions_avx2(chain: &ToolChain, q: &[Lanes], out: &mut [Lanes; 3]) {
    chain.positions_generic(q, out)
}

fn detect_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
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
        if let Some(p) = st.perm {
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

/// Whether every lane's joint value is in the range of the branch-free `sin_cos`
/// (`|x| ≤ 1e5`; checked on the coordinates with a margin for gear ratios and offsets),
/// and finite; the caller falls back to the scalar FK otherwise.
pub fn lanes_in_range(q: &[Lanes]) -> bool {
    q.iter().all(|v| v.iter().all(|x| x.abs() <= 1e4))
}
