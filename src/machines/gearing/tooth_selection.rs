//! Choosing standard tooth counts for a required train ratio (problem book ch. 10,
//! docs/reference_data.md §M1): every whole-number set within the ratio tolerance that
//! meets the conditions, ranked by size (the largest gear, then the sum of teeth) and
//! then by the ratio error.
//!
//! Schemes and their conditions (standard gears of one module, `z ≥ z_min`):
//!
//! ```text
//! two_stage:   u = (z2/z1)(z4/z3);   coaxial (reverted): z1 + z2 = z3 + z4
//! planetary:   2K-H, sun 1, planets 2 (k of them), fixed ring 3, carrier out:
//!              u = 1 + z3/z1;  coaxial z3 = z1 + 2 z2;  assembly (z1 + z3)/k ∈ ℤ;
//!              neighbours (z2 + 2h_a*) < (z1 + z2) sin(π/k)
//!              (the classic proportion z1 : z2 : z3 : (z1 + z3)/k = 1 : (u−2)/2 : (u−1) : u/k)
//! compound_planetary: sun 1, planet block 2/2' (2 meshes 1, 2' meshes the fixed ring 3):
//!              u = 1 + z2 z3/(z1 z2');  coaxial z1 + z2 = z3 − z2';
//!              assembly (z1 z2' + z3 z2)/(k gcd(z2, z2')) ∈ ℤ;
//!              neighbours (max(z2, z2') + 2h_a*) < (z1 + z2) sin(π/k)
//! ```
//!
//! The ratio error is `(u' − u)/u`, `u'` the achieved ratio.

use std::f64::consts::PI;

/// The train layout whose tooth counts are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrainScheme {
    /// Two ordinary external stages 1–2 and 3–4 (2 and 3 on one shaft).
    TwoStage {
        /// Input and output shafts coaxial (a reverted train): `z1 + z2 = z3 + z4`.
        coaxial: bool,
    },
    /// Simple 2K-H planetary, ring fixed, sun in, carrier out.
    Planetary,
    /// 2K-H planetary with a compound planet 2/2', ring fixed, sun in, carrier out.
    CompoundPlanetary,
}

impl TrainScheme {
    /// The TOML spelling.
    pub fn name(self) -> &'static str {
        match self {
            TrainScheme::TwoStage { .. } => "two_stage",
            TrainScheme::Planetary => "planetary",
            TrainScheme::CompoundPlanetary => "compound_planetary",
        }
    }

    /// The gear names of its tooth counts, in order.
    pub fn gear_names(self) -> &'static [&'static str] {
        match self {
            TrainScheme::TwoStage { .. } => &["1", "2", "3", "4"],
            TrainScheme::Planetary => &["1", "2", "3"],
            TrainScheme::CompoundPlanetary => &["1", "2", "2'", "3"],
        }
    }
}

/// What is required.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Requirement {
    /// Layout.
    pub scheme: TrainScheme,
    /// Required ratio `u = ω_in/ω_out` (> 1 for the planetary schemes).
    pub ratio: f64,
    /// Largest relative ratio error `|u' − u|/u`.
    pub tolerance: f64,
    /// Smallest tooth count of any gear.
    pub min_teeth: u32,
    /// Largest tooth count of any gear.
    pub max_teeth: u32,
    /// Equally spaced planets `k` (planetary schemes).
    pub planets: u32,
    /// Addendum factor `h_a*` (neighbour condition).
    pub addendum: f64,
}

/// One admissible set of tooth counts.
#[derive(Clone, Debug, PartialEq)]
pub struct Selection {
    /// Tooth counts, in [`TrainScheme::gear_names`] order.
    pub teeth: Vec<u32>,
    /// Achieved ratio `u'`.
    pub ratio: f64,
    /// `(u' − u)/u`.
    pub error: f64,
    /// The conditions with their values, each holding.
    pub conditions: Vec<(String, f64)>,
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The achieved ratio of `z` in `scheme`.
pub fn ratio_of(scheme: TrainScheme, z: &[u32]) -> f64 {
    let f: Vec<f64> = z.iter().map(|&x| x as f64).collect();
    match scheme {
        TrainScheme::TwoStage { .. } => f[1] / f[0] * f[3] / f[2],
        TrainScheme::Planetary => 1.0 + f[2] / f[0],
        TrainScheme::CompoundPlanetary => 1.0 + f[1] * f[3] / (f[0] * f[2]),
    }
}

/// Checks every condition of `scheme` on `z`; `Some(conditions)` when all hold.
pub fn conditions(req: &Requirement, z: &[u32]) -> Option<Vec<(String, f64)>> {
    if z.iter().any(|&x| x < req.min_teeth || x > req.max_teeth) {
        return None;
    }
    let k = req.planets as u64;
    let sin = (PI / req.planets as f64).sin();
    let ha2 = 2.0 * req.addendum;
    match req.scheme {
        TrainScheme::TwoStage { coaxial } => {
            if coaxial && z[0] + z[1] != z[2] + z[3] {
                return None;
            }
            let mut c = vec![("ratio".to_string(), ratio_of(req.scheme, z))];
            if coaxial {
                c.push(("coaxial z1 + z2 = z3 + z4".into(), (z[0] + z[1]) as f64));
            }
            Some(c)
        }
        TrainScheme::Planetary => {
            let (z1, z2, z3) = (z[0] as u64, z[1] as u64, z[2] as u64);
            let room = (z1 + z2) as f64 * sin;
            let ok = z3 == z1 + 2 * z2
                && (z1 + z3) % k == 0
                && (req.planets == 1 || (z2 as f64 + ha2) < room);
            ok.then(|| {
                vec![
                    ("coaxial z3 = z1 + 2 z2".into(), z3 as f64),
                    ("assembly (z1 + z3)/k".into(), ((z1 + z3) / k) as f64),
                    (
                        "neighbours (z1 + z2) sin(π/k) − (z2 + 2h_a*)".into(),
                        room - z2 as f64 - ha2,
                    ),
                ]
            })
        }
        TrainScheme::CompoundPlanetary => {
            let (z1, z2, z2b, z3) = (z[0] as u64, z[1] as u64, z[2] as u64, z[3] as u64);
            let num = z1 * z2b + z3 * z2;
            let den = k * gcd(z2, z2b);
            let room = (z1 + z2) as f64 * sin;
            let big = z2.max(z2b) as f64;
            let ok =
                z1 + z2 + z2b == z3 && num % den == 0 && (req.planets == 1 || big + ha2 < room);
            ok.then(|| {
                vec![
                    ("coaxial z1 + z2 = z3 − z2'".into(), (z1 + z2) as f64),
                    (
                        "assembly (z1 z2' + z3 z2)/(k gcd(z2, z2'))".into(),
                        (num / den) as f64,
                    ),
                    (
                        "neighbours (z1 + z2) sin(π/k) − (max(z2, z2') + 2h_a*)".into(),
                        room - big - ha2,
                    ),
                ]
            })
        }
    }
}

/// Visits the candidate tooth-count sets of `req.scheme` whose ratio is near `u` (before
/// the conditions), by the scheme's free counts.
fn candidates(req: &Requirement, visit: &mut dyn FnMut(&[u32])) {
    let (lo, hi) = (req.min_teeth, req.max_teeth);
    let (u_lo, u_hi) = (
        req.ratio * (1.0 - req.tolerance),
        req.ratio * (1.0 + req.tolerance),
    );
    // The whole counts z with a z_lo ≤ z ≤ a z_hi (the ratio band), within the bounds.
    let band = |a_lo: f64, a_hi: f64| {
        let from = ((a_lo - 1e-9).ceil().max(lo as f64)) as u32;
        let to = ((a_hi + 1e-9).floor().min(hi as f64)).max(0.0) as u32;
        from..=to
    };
    match req.scheme {
        TrainScheme::TwoStage { coaxial } => {
            for z1 in lo..=hi {
                for z2 in lo..=hi {
                    for z3 in lo..=hi {
                        if coaxial {
                            if let Some(z4) = (z1 + z2).checked_sub(z3) {
                                visit(&[z1, z2, z3, z4]);
                            }
                        } else {
                            let k = z1 as f64 * z3 as f64 / z2 as f64;
                            for z4 in band(u_lo * k, u_hi * k) {
                                visit(&[z1, z2, z3, z4]);
                            }
                        }
                    }
                }
            }
        }
        TrainScheme::Planetary => {
            for z1 in lo..=hi {
                for z3 in band((u_lo - 1.0) * z1 as f64, (u_hi - 1.0) * z1 as f64) {
                    if z3 > z1 && (z3 - z1) % 2 == 0 {
                        visit(&[z1, (z3 - z1) / 2, z3]);
                    }
                }
            }
        }
        TrainScheme::CompoundPlanetary => {
            for z1 in lo..=hi {
                for z2 in lo..=hi {
                    for z2b in lo..=hi {
                        visit(&[z1, z2, z2b, z1 + z2 + z2b]);
                    }
                }
            }
        }
    }
}

/// Every admissible set, best first (smallest largest gear, then smallest sum of teeth,
/// then smallest `|error|`); at most `limit`.
pub fn select(req: &Requirement, limit: usize) -> Vec<Selection> {
    let mut found: Vec<Selection> = Vec::new();
    candidates(req, &mut |z| {
        let r = ratio_of(req.scheme, z);
        let error = (r - req.ratio) / req.ratio;
        if error.abs() > req.tolerance + 1e-12 {
            return;
        }
        if let Some(conditions) = conditions(req, z) {
            found.push(Selection {
                teeth: z.to_vec(),
                ratio: r,
                error,
                conditions,
            });
        }
    });
    let key = |s: &Selection| {
        (
            s.teeth.iter().copied().max().unwrap_or(0),
            s.teeth.iter().sum::<u32>(),
        )
    };
    found.sort_by(|a, b| {
        key(a)
            .cmp(&key(b))
            .then(a.error.abs().total_cmp(&b.error.abs()))
    });
    found.dedup_by(|a, b| a.teeth == b.teeth);
    found.truncate(limit);
    found
}
