//! Body frames made regular: rotations within 1e-14 of a signed permutation snapped
//! exact, axes exactly along ±x, ±y, ±z recognised, and placement rotations pushed up the
//! tree so that in chains most placements are pure translations (see `build.rs`).

use crate::core::spatial::{Mat3, Se3, Vec3};
use crate::model::compiled::{BodyKind, Link, Model, WORLD};

/// If `r` is within 1e-14 of a signed permutation matrix, makes it exact and returns
/// each column's `(row, sign)`. The tolerance is far below any physical meaning: it only
/// removes the `cos(π/2) = 6e-17` left by `rpy` and DH angles of ±90°.
pub(super) fn snap_signed_permutation(r: &mut Mat3) -> Option<[(usize, f64); 3]> {
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
pub(super) fn push_permutations_up(m: &mut Model, links: &mut [Link]) {
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
pub(super) fn aligned_axis(a: &Vec3) -> Option<(usize, f64)> {
    (0..3).find_map(|k| {
        let others_zero = (0..3).filter(|&i| i != k).all(|i| a[i] == 0.0);
        (others_zero && a[k].abs() == 1.0).then(|| (k, a[k]))
    })
}
