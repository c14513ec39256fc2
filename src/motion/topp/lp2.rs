//! An exact linear program in two variables, `max c·x` subject to half-planes
//! `n_k·x ≤ h_k` inside a box, by Seidel's incremental method (deterministic order):
//!
//! - start at the box corner that maximises `c·x`;
//! - add the half-planes one by one; while the current optimum satisfies the new one it
//!   stays optimal (the feasible set only shrank);
//! - otherwise some optimum of the enlarged problem lies on the new half-plane's boundary
//!   line `n_k·x = h_k` (the segment from any optimum to the old one crosses it), so the
//!   problem becomes one-dimensional along that line: `x = p₀ + t d`, each earlier
//!   half-plane and the box bound `t` from one side, and `c·d` picks the end.
//!
//! `O(m)` when the optimum rarely moves, `O(m²)` at worst, for `m` half-planes: TOPP-RA's
//! stages have a few dozen. No allocation.

/// The half-plane `na·a + nb·b ≤ h` in the variables `x = (a, b)`.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct HalfPlane {
    pub(super) na: f64,
    pub(super) nb: f64,
    pub(super) h: f64,
}

impl HalfPlane {
    fn value(&self, x: [f64; 2]) -> f64 {
        self.na * x[0] + self.nb * x[1]
    }

    /// Accepted excess of `n·x` over `h` at `x`: relative to the magnitudes involved.
    fn slack(&self, x: [f64; 2]) -> f64 {
        1e-12 * (self.h.abs() + (self.na * x[0]).abs() + (self.nb * x[1]).abs())
    }
}

/// `max c·x` over the half-planes `rows` and the box `lo ≤ x ≤ hi`: the maximiser, or
/// `None` when the set is empty (beyond rounding).
pub(super) fn maximize(
    c: [f64; 2],
    rows: &[HalfPlane],
    lo: [f64; 2],
    hi: [f64; 2],
) -> Option<[f64; 2]> {
    if lo[0] > hi[0] || lo[1] > hi[1] {
        return None;
    }
    let corner = |k: usize| if c[k] > 0.0 { hi[k] } else { lo[k] };
    let mut x = [corner(0), corner(1)];
    for (k, r) in rows.iter().enumerate() {
        if r.value(x) <= r.h + r.slack(x) {
            continue;
        }
        x = on_line(c, r, &rows[..k], lo, hi)?;
    }
    Some(x)
}

/// The one-dimensional problem on the line `r.n·x = r.h` under `earlier` and the box.
fn on_line(
    c: [f64; 2],
    r: &HalfPlane,
    earlier: &[HalfPlane],
    lo: [f64; 2],
    hi: [f64; 2],
) -> Option<[f64; 2]> {
    let nn = r.na * r.na + r.nb * r.nb;
    if nn == 0.0 {
        // `0 ≤ h` violated: empty.
        return None;
    }
    let p0 = [r.na * r.h / nn, r.nb * r.h / nn];
    let len = nn.sqrt();
    let d = [-r.nb / len, r.na / len];
    let (mut tlo, mut thi) = (f64::NEG_INFINITY, f64::INFINITY);
    // The box, coordinate by coordinate.
    for (((dk, pk), lk), hk) in d.iter().zip(p0).zip(lo).zip(hi) {
        if dk.abs() < 1e-15 {
            let tol = 1e-12 * (1.0 + pk.abs());
            if pk < lk - tol || pk > hk + tol {
                return None;
            }
        } else {
            let (t1, t2) = ((lk - pk) / dk, (hk - pk) / dk);
            tlo = tlo.max(t1.min(t2));
            thi = thi.min(t1.max(t2));
        }
    }
    for e in earlier {
        let nd = e.na * d[0] + e.nb * d[1];
        let rhs = e.h - e.value(p0);
        let scale = e.h.abs() + (e.na * p0[0]).abs() + (e.nb * p0[1]).abs();
        if nd.abs() <= 1e-13 * (e.na.abs() + e.nb.abs()) {
            if rhs < -1e-12 * scale {
                return None;
            }
        } else if nd > 0.0 {
            thi = thi.min(rhs / nd);
        } else {
            tlo = tlo.max(rhs / nd);
        }
    }
    if tlo > thi {
        // Empty unless the crossing is rounding.
        if tlo - thi > 1e-9 * (1.0 + tlo.abs().max(thi.abs())) {
            return None;
        }
        let t = 0.5 * (tlo + thi);
        (tlo, thi) = (t, t);
    }
    let cd = c[0] * d[0] + c[1] * d[1];
    let t = if cd > 0.0 { thi } else { tlo };
    Some([p0[0] + t * d[0], p0[1] + t * d[1]])
}

#[cfg(test)]
mod tests {
    use crate::motion::topp::lp2::*;

    fn hp(na: f64, nb: f64, h: f64) -> HalfPlane {
        HalfPlane { na, nb, h }
    }

    /// Brute force: every pairwise intersection of the lines (box included) that is
    /// feasible, the best objective.
    fn brute(c: [f64; 2], rows: &[HalfPlane], lo: [f64; 2], hi: [f64; 2]) -> Option<f64> {
        let mut all = rows.to_vec();
        all.extend([
            hp(1.0, 0.0, hi[0]),
            hp(-1.0, 0.0, -lo[0]),
            hp(0.0, 1.0, hi[1]),
            hp(0.0, -1.0, -lo[1]),
        ]);
        let mut best: Option<f64> = None;
        for i in 0..all.len() {
            for j in i + 1..all.len() {
                let (p, q) = (all[i], all[j]);
                let det = p.na * q.nb - p.nb * q.na;
                if det.abs() < 1e-12 {
                    continue;
                }
                let x = [
                    (p.h * q.nb - p.nb * q.h) / det,
                    (p.na * q.h - p.h * q.na) / det,
                ];
                if all.iter().all(|r| r.value(x) <= r.h + 1e-9) {
                    let v = c[0] * x[0] + c[1] * x[1];
                    best = Some(best.map_or(v, |b: f64| b.max(v)));
                }
            }
        }
        best
    }

    #[test]
    fn seidel_equals_vertex_enumeration_on_random_problems() {
        let mut state = 12345u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let (mut feasible, mut infeasible) = (0, 0);
        for _ in 0..3000 {
            let m = 1 + ((rnd() + 1.0) * 6.0) as usize;
            let rows: Vec<HalfPlane> = (0..m).map(|_| hp(rnd(), rnd(), rnd())).collect();
            let c = [rnd(), rnd()];
            let (lo, hi) = ([-2.0, -1.5], [1.0, 2.5]);
            let got = maximize(c, &rows, lo, hi);
            match (got, brute(c, &rows, lo, hi)) {
                (Some(x), Some(v)) => {
                    feasible += 1;
                    assert!((c[0] * x[0] + c[1] * x[1] - v).abs() < 1e-9, "{x:?} {v}");
                    assert!(rows.iter().all(|r| r.value(x) <= r.h + 1e-9));
                }
                (None, None) => infeasible += 1,
                (g, b) => panic!("seidel {g:?}, brute force {b:?}, rows {rows:?}, c {c:?}"),
            }
        }
        assert!(
            feasible > 500 && infeasible > 100,
            "{feasible} {infeasible}"
        );
    }
}
