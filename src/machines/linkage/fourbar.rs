//! Four-bar loops: Grashof classification, transmission angle, and the closed-form
//! position by circle intersection.
//!
//! Naming: ground pivots `O` (input) and `C` (output), input link `OA`, coupler `AB`,
//! output link `CB`; lengths `g = |OC|`, `a = |OA|`, `b = |AB|`, `c = |CB|`.
//!
//! - **Grashof** (Norton, *Design of Machinery*, §2.12): with `s`, `l` the shortest and
//!   longest lengths and `p`, `q` the others, `s + l < p + q` lets the shortest link turn
//!   fully relative to the others (crank-rocker when it is a side link, double crank when
//!   it is the ground, Grashof double rocker when it is the coupler); `s + l > p + q` is a
//!   triple rocker; `s + l = p + q` a change-point linkage (parallelogram,
//!   antiparallelogram and deltoid included), whose links all line up at the change
//!   points.
//! - **Transmission angle** `μ` (Norton §3.3): the angle at `B` between the coupler and
//!   the output link, `cos μ = (b² + c² − |AC|²) / (2 b c)`; its extremes over a turn of
//!   a crank are at the input angles 0 and π, where `|AC| = g − a` and `g + a`.
//! - **Position**: `B` is the intersection of the circles of radius `b` about `A` and `c`
//!   about `C`; the two intersections are the two assembly modes, `mode = ±1` the sign of
//!   the orientation of the triangle `A, C, B` (`(C − A) × (B − A)`).

use crate::machines::linkage::{cross, Vec2};

/// Grashof's condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GrashofClass {
    /// `s + l < p + q`.
    Grashof,
    /// `s + l > p + q`.
    NonGrashof,
    /// `s + l = p + q` (within a relative 1e-9).
    ChangePoint,
}

/// A four-bar's classification.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FourBarClass {
    /// Grashof's condition.
    pub class: GrashofClass,
    /// `"crank-rocker"`, `"rocker-crank"`, `"double-crank"`, `"double-rocker"`,
    /// `"triple-rocker"`, `"parallelogram"`, `"deltoid"` or `"change-point"`.
    pub kind: &'static str,
    /// `s + l`.
    pub s_plus_l: f64,
    /// `p + q`.
    pub p_plus_q: f64,
    /// Whether the input link can turn fully.
    pub input_rotates: bool,
    /// Whether the output link can turn fully.
    pub output_rotates: bool,
}

/// Classifies the four-bar with ground `g`, input `a`, coupler `b`, output `c`.
pub fn classify(g: f64, a: f64, b: f64, c: f64) -> FourBarClass {
    let links = [g, a, b, c];
    // Sort the indices, not the values: with a NaN no value need equal the "shortest".
    let mut order = [0, 1, 2, 3];
    order.sort_by(|&i, &j| links[i].total_cmp(&links[j]));
    let v = order.map(|i| links[i]);
    let (s, l) = (v[0], v[3]);
    let (sl, pq) = (s + l, v[1] + v[2]);
    let tol = 1e-9 * pq;
    let shortest = order[0];
    let class = if (sl - pq).abs() <= tol {
        GrashofClass::ChangePoint
    } else if sl < pq {
        GrashofClass::Grashof
    } else {
        GrashofClass::NonGrashof
    };
    let eq = |x: f64, y: f64| (x - y).abs() <= tol;
    let (kind, inp, out) = match class {
        GrashofClass::Grashof => match shortest {
            0 => ("double-crank", true, true),
            1 => ("crank-rocker", true, false),
            3 => ("rocker-crank", false, true),
            _ => ("double-rocker", false, false),
        },
        GrashofClass::NonGrashof => ("triple-rocker", false, false),
        GrashofClass::ChangePoint => {
            if eq(g, b) && eq(a, c) {
                ("parallelogram", true, true)
            } else if (eq(g, a) && eq(b, c)) || (eq(g, c) && eq(a, b)) {
                ("deltoid", true, true)
            } else {
                (
                    "change-point",
                    shortest == 1 || shortest == 0,
                    shortest == 3 || shortest == 0,
                )
            }
        }
    };
    FourBarClass {
        class,
        kind,
        s_plus_l: sl,
        p_plus_q: pq,
        input_rotates: inp,
        output_rotates: out,
    }
}

/// The angle at `b` between `b → a` and `b → c`, in `[0, π]`.
pub fn transmission_angle(a: &Vec2, b: &Vec2, c: &Vec2) -> f64 {
    let u = a - b;
    let w = c - b;
    cross(&u, &w).abs().atan2(u.dot(&w))
}

/// `(μ at input angle 0, μ at input angle π)`: the extremes of the transmission angle of
/// a four-bar whose input turns fully (`None` where the loop does not close there).
pub fn transmission_extremes(g: f64, a: f64, b: f64, c: f64) -> (Option<f64>, Option<f64>) {
    let mu = |diag: f64| {
        let cm = (b * b + c * c - diag * diag) / (2.0 * b * c);
        (cm.abs() <= 1.0 + 1e-12).then(|| cm.clamp(-1.0, 1.0).acos())
    };
    (mu((g - a).abs()), mu(g + a))
}

/// Closed-form position: `O = (0, 0)`, `C = (g, 0)`, input angle `phi`; returns `(A, B)`
/// for assembly `mode` (±1), or `None` where the loop cannot close.
pub fn position(g: f64, a: f64, b: f64, c: f64, phi: f64, mode: f64) -> Option<(Vec2, Vec2)> {
    let pa = Vec2::new(a * phi.cos(), a * phi.sin());
    let pc = Vec2::new(g, 0.0);
    let d = pc - pa;
    let dist = d.norm();
    if dist == 0.0 {
        return None;
    }
    let x = (b * b - c * c + dist * dist) / (2.0 * dist);
    let h2 = b * b - x * x;
    if h2 < -1e-12 * b * b {
        return None;
    }
    let h = h2.max(0.0).sqrt();
    let u = d / dist;
    let n = Vec2::new(-u.y, u.x);
    // (C − A) × (B − A) = dist · h · (u × n) · sign: n on the left gives a positive sign.
    Some((pa, pa + u * x + n * (h * mode.signum())))
}
