//! Critical speeds of a [`FlexibleRotor`] by exact transfer matrices (Myklestad–Prohl with the
//! continuous-beam field matrix): the second route behind [`crate::machines::vibration::rotor`]'s
//! finite elements.
//!
//! State `z = (y, θ, M, V)` with `M = EI y''`, `V = EI y'''`; free whirl at `ω` obeys
//! `EI y'''' = μ ω² y`, so with `β⁴ = μ ω²/EI` and Krylov's functions
//! `S = (ch + cos)/2`, `T = (sh + sin)/2`, `U = (ch − cos)/2`, `V = (sh − sin)/2` of `βL`
//! a segment maps `z(0)` to `z(L)` exactly. A disc adds `m ω² y` to `V`, a spring bearing
//! `−c y`; a rigid bearing makes `y = 0` there (one unknown combination is spent) and
//! adds its reaction as a new unknown. The end conditions (pinned: `y = M = 0`; free:
//! `M = V = 0`) leave a 2 × 2 determinant whose zeros in `ω` are the critical speeds.

use crate::machines::vibration::rotor::FlexibleRotor;
use nalgebra::{Matrix4, SMatrix};

type Z = SMatrix<f64, 4, 2>;

fn field(ei: f64, mu: f64, l: f64, omega: f64) -> Matrix4<f64> {
    let b = (mu * omega * omega / ei).powf(0.25);
    let x = b * l;
    let (ch, sh, c, s) = (x.cosh(), x.sinh(), x.cos(), x.sin());
    let (ss, tt, uu, vv) = (
        (ch + c) / 2.0,
        (sh + s) / 2.0,
        (ch - c) / 2.0,
        (sh - s) / 2.0,
    );
    Matrix4::new(
        ss,
        tt / b,
        uu / (ei * b * b),
        vv / (ei * b.powi(3)),
        b * vv,
        ss,
        tt / (ei * b),
        uu / (ei * b * b),
        ei * b * b * uu,
        ei * b * vv,
        ss,
        tt / b,
        ei * b.powi(3) * tt,
        ei * b * b * uu,
        b * vv,
        ss,
    )
}

fn normalise(z: &mut Z) {
    for j in 0..2 {
        let n = z.column(j).norm();
        if n > 0.0 {
            z.column_mut(j).unscale_mut(n);
        }
    }
}

/// The end-condition determinant at `omega` (its zeros are the critical speeds).
pub fn determinant(rotor: &FlexibleRotor, omega: f64) -> f64 {
    let len = rotor.length();
    let tol = 1e-9 * len;
    let rigid_at = |x: f64| {
        rotor
            .bearings
            .iter()
            .any(|b| b.stiffness.is_none() && (b.at - x).abs() <= tol)
    };
    let pinned_left = rigid_at(0.0);
    let pinned_right = rigid_at(len);
    // Unknown columns at x = 0: pinned (θ, V), free (y, θ).
    let mut z = if pinned_left {
        Z::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
    } else {
        Z::new(1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0)
    };
    let stations = rotor.stations();
    for (k, &xs) in stations.iter().enumerate() {
        if k > 0 {
            // Field from the previous station, segment by segment.
            let mut a = stations[k - 1];
            while a < xs - tol {
                let seg = rotor.segment_at(a + tol);
                let mut end = 0.0;
                let mut acc = 0.0;
                for s in &rotor.segments {
                    acc += s.length;
                    if a + tol < acc {
                        end = acc;
                        break;
                    }
                }
                let b = end.min(xs);
                z = field(seg.ei, seg.mu, b - a, omega) * z;
                a = b;
            }
        }
        // Point matrices at the station.
        let mut dv = 0.0;
        for d in rotor.discs.iter().filter(|d| (d.at - xs).abs() <= tol) {
            dv += d.mass * omega * omega;
        }
        for b in rotor.bearings.iter().filter(|b| (b.at - xs).abs() <= tol) {
            if let Some(c) = b.stiffness {
                dv -= c;
            }
        }
        for j in 0..2 {
            z[(3, j)] += dv * z[(0, j)];
        }
        let interior = k > 0 && k + 1 < stations.len();
        if interior && rigid_at(xs) {
            // y = 0: keep the combination of the two columns with zero deflection, and
            // add the reaction (a unit jump of V) as the second unknown.
            let (a0, a1) = (z[(0, 0)], z[(0, 1)]);
            let c0 = z.column(0) * a1 - z.column(1) * a0;
            z.set_column(0, &c0);
            z.set_column(1, &nalgebra::Vector4::new(0.0, 0.0, 0.0, 1.0));
        }
        normalise(&mut z);
    }
    let (r0, r1) = if pinned_right { (0, 2) } else { (2, 3) };
    z[(r0, 0)] * z[(r1, 1)] - z[(r0, 1)] * z[(r1, 0)]
}

/// Critical speeds below `omega_max`: sign changes of [`determinant`] on `scan` steps,
/// refined by bisection.
pub fn critical_speeds(rotor: &FlexibleRotor, omega_max: f64, scan: usize) -> Vec<f64> {
    let lo = omega_max * 1e-4;
    let step = (omega_max - lo) / scan as f64;
    let mut out = Vec::new();
    let mut prev = (lo, determinant(rotor, lo));
    for k in 1..=scan {
        let w = lo + step * k as f64;
        let d = determinant(rotor, w);
        if d == 0.0 {
            out.push(w);
        } else if prev.1 * d < 0.0 {
            let (mut a, mut fa, mut b) = (prev.0, prev.1, w);
            for _ in 0..100 {
                let m = 0.5 * (a + b);
                let fm = determinant(rotor, m);
                if fm * fa > 0.0 {
                    a = m;
                    fa = fm;
                } else {
                    b = m;
                }
                if b - a <= 1e-13 * b {
                    break;
                }
            }
            out.push(0.5 * (a + b));
        }
        prev = (w, d);
    }
    out
}
