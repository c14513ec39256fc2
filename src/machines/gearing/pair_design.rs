//! The textbook's pair design for a given centre distance (program BANHRANG,
//! docs/reference_data.md §M2 (c)): tooth counts from `A`, `m` and the ratio, the total shift
//! the centre distance needs, and the split of the shift between the gears that balances
//! the specific sliding at the two ends of the path of contact, subject to no undercut,
//! tip thickness ≥ 0.4 m and contact ratio ≥ 1.1.
//!
//! Specific sliding at a point of the line of action at distances `ρ₁` from `N₁` and
//! `ρ₂ = N₁N₂ − ρ₁` from `N₂`, with `u = z₂/z₁`: `ζ₁ = 1 − ρ₂/(u ρ₁)`,
//! `ζ₂ = 1 − u ρ₁/ρ₂`. Each is largest at the root of its gear (the start and end of the
//! path of contact); the split is balanced when `|ζ₁| = |ζ₂|` there.

use crate::machines::gearing::involute::{bisect, inv};
use crate::machines::gearing::pair::{pair, PairGeometry, PairKind, PairSpec};

/// A designed pair.
#[derive(Clone, Debug, PartialEq)]
pub struct Design {
    /// `z₁ = trunc(2A/(m(1 + i)))` (rounded when within 0.1 % of an integer),
    /// `z₂ = round(z₁ i)`.
    pub teeth: [u32; 2],
    /// Working pressure angle from `cos α_w = (r_b1 + r_b2)/A`.
    pub alpha_w: f64,
    /// Total shift `x_t = (z₁ + z₂)(inv α_w − inv α)/(2 tan α)`.
    pub total_shift: f64,
    /// Centre-distance factor `λ = (A − a₀)/m`.
    pub centre_factor: f64,
    /// Tip reduction `ν = x_t − λ`.
    pub tip_reduction: f64,
    /// `z₁ + z₂ ≥ 34 − round(17 x_t)`.
    pub feasible: bool,
    /// The chosen shifts.
    pub shift: [f64; 2],
    /// Largest specific sliding on each gear at the chosen shifts.
    pub sliding: [f64; 2],
    /// Whether every constraint holds at the chosen shifts.
    pub constraints_met: bool,
    /// The pair at the chosen shifts.
    pub pair: PairGeometry,
}

/// Largest specific sliding `(|ζ₁|, |ζ₂|)` of an external pair.
pub fn specific_sliding(g: &PairGeometry) -> [f64; 2] {
    let [a, b] = [&g.gears[0], &g.gears[1]];
    let u = b.teeth as f64 / a.teeth as f64;
    let n1n2 = g.line_of_action.unwrap_or(0.0);
    let l1 = (a.ra * a.ra - a.rb * a.rb).sqrt();
    let l2 = (b.ra * b.ra - b.rb * b.rb).sqrt();
    // Start of contact (gear 1's root): ρ₂ = l₂; end (gear 2's root): ρ₁ = l₁.
    let (r1s, r2s) = (n1n2 - l2, l2);
    let (r1e, r2e) = (l1, n1n2 - l1);
    [(1.0 - r2s / (u * r1s)).abs(), (1.0 - u * r1e / r2e).abs()]
}

/// Designs a pair for centre distance `a`, module `m`, pressure angle `alpha`, ratio
/// `i ≥ 1`, standard tooth data `ha`, `c`.
pub fn design(a: f64, m: f64, alpha: f64, i: f64, ha: f64, c: f64) -> Option<Design> {
    // The book truncates; a quotient a hair below an integer is that integer (a ratio given
    // to three decimals puts 2A/(m(1 + i)) = 18.9994 where 19/41 fits A exactly).
    let q = 2.0 * a / (m * (1.0 + i));
    let z1 = if (q - q.round()).abs() <= 1e-3 * q {
        q.round()
    } else {
        q.trunc()
    };
    let z2 = (z1 * i).round();
    if z1 < 3.0 {
        return None;
    }
    let a0 = m * (z1 + z2) / 2.0;
    let cw = a0 * alpha.cos() / a;
    if !(cw > 0.0 && cw <= 1.0) {
        return None;
    }
    let aw = cw.acos();
    let xt = (z1 + z2) * (inv(aw) - inv(alpha)) / (2.0 * alpha.tan());
    let lambda = (a - a0) / m;
    let spec = |x1: f64| PairSpec {
        kind: PairKind::External,
        module: m,
        teeth: [z1 as u32, z2 as u32],
        pressure_angle: alpha,
        addendum: ha,
        clearance: c,
        shift: [x1, xt - x1],
        helix: 0.0,
        face_width: None,
        centre_distance: None,
    };
    let zmin = crate::machines::gearing::pair::z_min_book(ha, alpha, 0.0);
    let (lo, hi) = ((zmin - z1) / zmin, xt - (zmin - z2) / zmin);
    let imbalance = |x1: f64| {
        let s = specific_sliding(&pair(&spec(x1)));
        s[0] - s[1]
    };
    // Balance inside the undercut bounds (or the nearer bound).
    let x1 = if lo <= hi {
        bisect(imbalance, lo, hi).unwrap_or(if imbalance(lo).abs() < imbalance(hi).abs() {
            lo
        } else {
            hi
        })
    } else {
        xt / 2.0
    };
    let g = pair(&spec(x1));
    let sliding = specific_sliding(&g);
    let ok = lo <= hi
        && g.gears.iter().all(|gg| gg.s_tip >= 0.4 * m && !gg.undercut)
        && g.eps_alpha >= 1.1;
    Some(Design {
        teeth: [z1 as u32, z2 as u32],
        alpha_w: aw,
        total_shift: xt,
        centre_factor: lambda,
        tip_reduction: xt - lambda,
        feasible: z1 + z2 >= 34.0 - (17.0 * xt).round(),
        shift: [x1, xt - x1],
        sliding,
        constraints_met: ok,
        pair: g,
    })
}
