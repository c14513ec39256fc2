//! Forward kinematics of the bodies in eight lanes, their twists along an edge, and the
//! small vector helpers the speed bounds use.

use crate::model::WORLD;
use crate::planning::checker::checker_state::{CheckScratch, Checker};
use crate::planning::lanes::{LanePose, PoseM, L, P3};
use crate::planning::simd::{Simd, W};

impl Checker {
    /// World twist `(ω, v)` of body `i` per unit of the edge parameter: `ω = ω_p + Δ_i z_i`
    /// (revolute), `v = v_p + ω_p × (o_i − o_p)` (`+ Δ_i z_i` if prismatic), from the body's
    /// pose this batch stored in `s.poses` (a pose passed by reference kept the AVX2 build's
    /// rotation on the stack, and its store a `memcpy`).
    #[inline(always)]
    pub(super) fn body_twist<S: Simd>(&self, tok: S, i: usize, s: &CheckScratch) -> (P3<S>, P3<S>) {
        let b = &self.bodies[i];
        let zero = P3::splat(tok, &[0.0; 3]);
        let (wp, vp, op) = if b.parent == WORLD {
            (zero, zero, zero)
        } else {
            let t = &s.twist[b.parent];
            (
                P3::load(tok, &t[0]),
                P3::load(tok, &t[1]),
                P3::load(tok, &s.poses[b.parent].t),
            )
        };
        let d = tok.splat(s.body_delta[i]);
        let (k, pose) = (b.axis, &s.poses[i]);
        let z = P3 {
            x: tok.load(&pose.r[0][k]) * d,
            y: tok.load(&pose.r[1][k]) * d,
            z: tok.load(&pose.r[2][k]) * d,
        };
        let c = cross(&wp, &sub(&P3::load(tok, &pose.t), &op));
        let mut v = P3 {
            x: vp.x + c.x,
            y: vp.y + c.y,
            z: vp.z + c.z,
        };
        let w = if b.revolute {
            P3 {
                x: wp.x + z.x,
                y: wp.y + z.y,
                z: wp.z + z.z,
            }
        } else {
            v = P3 {
                x: v.x + z.x,
                y: v.y + z.y,
                z: v.z + z.z,
            };
            wp
        };
        (w, v)
    }

    /// World velocity per unit of the edge parameter of point `c` on body `b` (zero on the
    /// world): `v + ω × (c − o)` from the body's twist.
    #[inline(always)]
    pub(super) fn point_velocity<S: Simd>(
        &self,
        tok: S,
        b: usize,
        c: &P3<S>,
        s: &CheckScratch,
    ) -> P3<S> {
        if b == WORLD {
            return P3::splat(tok, &[0.0; 3]);
        }
        let t = &s.twist[b];
        let (w, v) = (P3::load(tok, &t[0]), P3::load(tok, &t[1]));
        let r = cross(&w, &sub(c, &P3::load(tok, &s.poses[b].t)));
        P3 {
            x: v.x + r.x,
            y: v.y + r.y,
            z: v.z + r.z,
        }
    }

    /// The pose of body `b` (or the world) stored by this batch.
    #[inline(always)]
    pub(super) fn stored_pose<S: Simd>(&self, tok: S, b: usize, s: &CheckScratch) -> LanePose<S> {
        if b == WORLD {
            let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            LanePose::splat(tok, &identity, &[0.0; 3])
        } else {
            LanePose::load(tok, &s.poses[b])
        }
    }

    /// `oM_parent · placement · J(q)` of body `i` in every lane.
    #[inline(always)]
    pub(super) fn body_pose<S: Simd>(
        &self,
        tok: S,
        i: usize,
        q: &[L],
        poses: &[PoseM],
    ) -> LanePose<S> {
        let b = &self.bodies[i];
        let qi = tok
            .load(&q[b.q_index])
            .mul_add(tok.splat(b.mult), tok.splat(b.offset));
        let mut out = if b.parent == WORLD {
            LanePose::splat(tok, &b.rot, &b.trans)
        } else {
            let p = LanePose::load(tok, &poses[b.parent]);
            let t = p.act(tok, &b.trans);
            let r = if b.rot_identity {
                p.r
            } else {
                let mut r = p.r;
                for (row, rr) in r.iter_mut().enumerate() {
                    for (col, x) in rr.iter_mut().enumerate() {
                        *x = p.r[row][0].mul_add(
                            tok.splat(b.rot[0][col]),
                            p.r[row][1].mul_add(
                                tok.splat(b.rot[1][col]),
                                p.r[row][2] * tok.splat(b.rot[2][col]),
                            ),
                        );
                    }
                }
                r
            };
            LanePose { r, t }
        };
        // Constant column indices in each arm: an index known only at run time would keep
        // the rotation on the stack (and its store into `s.poses` a `memcpy`).
        if b.revolute {
            let (sn, cs) = qi.sin_cos();
            match b.axis {
                0 => turn_columns::<S, 1, 2>(&mut out.r, cs, sn),
                1 => turn_columns::<S, 2, 0>(&mut out.r, cs, sn),
                _ => turn_columns::<S, 0, 1>(&mut out.r, cs, sn),
            }
        } else {
            let col = match b.axis {
                0 => [out.r[0][0], out.r[1][0], out.r[2][0]],
                1 => [out.r[0][1], out.r[1][1], out.r[2][1]],
                _ => [out.r[0][2], out.r[1][2], out.r[2][2]],
            };
            out.t.x = col[0].mul_add(qi, out.t.x);
            out.t.y = col[1].mul_add(qi, out.t.y);
            out.t.z = col[2].mul_add(qi, out.t.z);
        }
        out
    }
}

/// Turns columns `I` and `J` of `r` by the angle of `(cos, sin)` (a rotation about the
/// third axis, post-multiplied).
#[inline(always)]
fn turn_columns<S: Simd, const I: usize, const J: usize>(
    r: &mut [[W<S>; 3]; 3],
    cs: W<S>,
    sn: W<S>,
) {
    for row in r.iter_mut() {
        let (x, y) = (row[I], row[J]);
        row[I] = cs.mul_add(x, sn * y);
        row[J] = cs.mul_add(y, -(sn * x));
    }
}

/// `a − b`.
#[inline(always)]
pub(super) fn sub<S: Simd>(a: &P3<S>, b: &P3<S>) -> P3<S> {
    P3 {
        x: a.x - b.x,
        y: a.y - b.y,
        z: a.z - b.z,
    }
}

/// `a × b`.
#[inline(always)]
pub(super) fn cross<S: Simd>(a: &P3<S>, b: &P3<S>) -> P3<S> {
    P3 {
        x: a.y * b.z - a.z * b.y,
        y: a.z * b.x - a.x * b.z,
        z: a.x * b.y - a.y * b.x,
    }
}

/// `|v + ω × (c − o)|`: the speed of point `c` on a body with twist `(ω, v)` at origin `o`.
#[inline(always)]
pub(super) fn point_speed<S: Simd>(w: &P3<S>, v: &P3<S>, o: &P3<S>, c: &P3<S>) -> W<S> {
    let r = cross(w, &sub(c, o));
    W::norm2(v.x + r.x, v.y + r.y, v.z + r.z).sqrt()
}
