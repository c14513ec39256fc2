//! Geometric conditions of a gear train (docs/reference_data.md §M1): coaxiality of standard
//! gears (`A = m (z₁ + z₂)/2` external, `m (z₂ − z₁)/2` internal, equal along every
//! branch that joins one axis to another), missing tooth counts found from those
//! equations, the equal-spacing assembly condition of planets and the neighbour (tip
//! clearance) condition.
//!
//! Axes are grouped into classes: a carrier and the frame-held gears meshing with its
//! planets share the main axis; groups stated `coaxial` join their classes. A body whose
//! spur meshes reach the same class by two meshes must see the same centre distance in
//! both.

use crate::machines::gearing::train::{Element, GearTrain, MeshKind, TrainError};

/// One linear condition `Σ c_g z_g = d` on tooth counts, with what it states.
#[derive(Clone, Debug)]
struct Condition {
    /// `Σ c_g z_g` of the first side.
    left: Vec<(usize, f64)>,
    /// Of the second side (empty for a stated centre distance).
    right: Vec<(usize, f64)>,
    rhs: f64,
    element: Element,
    what: String,
}

/// One check's outcome, for the report.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// `"coaxiality"`, `"centre_distance"`, `"assembly"` or `"neighbours"`.
    pub kind: &'static str,
    /// What was checked, with the numbers.
    pub detail: String,
    /// Whether it holds.
    pub ok: bool,
}

/// A tooth count found from a condition.
#[derive(Clone, Debug, PartialEq)]
pub struct DerivedTeeth {
    /// Gear index.
    pub gear: usize,
    /// Tooth count.
    pub teeth: u32,
    /// The condition it came from.
    pub from: String,
}

fn find(parent: &mut [usize], i: usize) -> usize {
    let mut r = i;
    while parent[r] != r {
        r = parent[r];
    }
    parent[i] = r;
    r
}

/// Axis class of every body (see the module docs).
pub fn axis_classes(t: &GearTrain) -> Vec<usize> {
    let n = t.bodies.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let join = |p: &mut Vec<usize>, a: usize, b: usize| {
        let (ra, rb) = (find(p, a), find(p, b));
        p[ra] = rb;
    };
    for m in &t.meshes {
        let (ba, bb) = (t.gears[m.gears[0]].body, t.gears[m.gears[1]].body);
        for (x, y) in [(ba, bb), (bb, ba)] {
            if let (Some(c), None) = (t.bodies[x].carrier, t.bodies[y].carrier) {
                join(&mut parent, y, c);
            }
        }
    }
    for g in &t.coaxial {
        for w in g.windows(2) {
            join(&mut parent, w[0], w[1]);
        }
    }
    (0..n).map(|i| find(&mut parent, i)).collect()
}

/// `A = Σ c_g z_g` of a spur mesh (`c = ± m/2`), when both modules are known.
fn distance_terms(t: &GearTrain, e: usize) -> Option<Vec<(usize, f64)>> {
    let m = &t.meshes[e];
    if m.kind != MeshKind::Spur {
        return None;
    }
    let [a, b] = m.gears;
    let (ma, mb) = (t.gears[a].module?, t.gears[b].module?);
    let (sa, sb) = if t.gears[a].internal {
        (1.0, -1.0)
    } else if t.gears[b].internal {
        (-1.0, 1.0)
    } else {
        (1.0, 1.0)
    };
    Some(vec![(a, sa * ma / 2.0), (b, sb * mb / 2.0)])
}

fn mesh_label(t: &GearTrain, e: usize) -> String {
    let [a, b] = t.meshes[e].gears;
    format!("{}–{}", t.gears[a].name, t.gears[b].name)
}

/// The coaxiality and stated-centre-distance conditions.
fn conditions(t: &GearTrain) -> Vec<Condition> {
    let class = axis_classes(t);
    let mut out = Vec::new();
    for (e, m) in t.meshes.iter().enumerate() {
        if let (Some(a), Some(terms)) = (m.centre_distance, distance_terms(t, e)) {
            out.push(Condition {
                left: terms,
                right: Vec::new(),
                rhs: a,
                element: Element::Mesh(e),
                what: format!("centre distance of {} = {a} mm", mesh_label(t, e)),
            });
        }
    }
    for p in 0..t.bodies.len() {
        // Spur meshes of body p, by the axis class of the other body.
        let mut by_class: Vec<(usize, usize)> = Vec::new();
        for (e, m) in t.meshes.iter().enumerate() {
            let (ba, bb) = (t.gears[m.gears[0]].body, t.gears[m.gears[1]].body);
            let other = if ba == p {
                bb
            } else if bb == p {
                ba
            } else {
                continue;
            };
            if distance_terms(t, e).is_some() {
                by_class.push((class[other], e));
            }
        }
        for (i, &(c, e0)) in by_class.iter().enumerate() {
            if let Some(&(_, e1)) = by_class[i + 1..].iter().find(|(c1, _)| *c1 == c) {
                out.push(Condition {
                    left: distance_terms(t, e0).unwrap_or_default(),
                    right: distance_terms(t, e1).unwrap_or_default(),
                    rhs: 0.0,
                    element: Element::Mesh(e1),
                    what: format!(
                        "coaxiality: {} and {} join '{}' to one axis, so their centre distances are equal",
                        mesh_label(t, e0),
                        mesh_label(t, e1),
                        t.bodies[p].name
                    ),
                });
            }
        }
    }
    out
}

impl Condition {
    /// `left − right` merged by gear: the equation `Σ k_g z_g = rhs`.
    fn merged(&self) -> Vec<(usize, f64)> {
        let mut out: Vec<(usize, f64)> = Vec::new();
        let terms = self.left.iter().copied();
        for (g, k) in terms.chain(self.right.iter().map(|&(g, k)| (g, -k))) {
            match out.iter_mut().find(|(h, _)| *h == g) {
                Some(t) => t.1 += k,
                None => out.push((g, k)),
            }
        }
        out.retain(|(_, k)| *k != 0.0);
        out
    }
}

fn side(t: &GearTrain, terms: &[(usize, f64)]) -> f64 {
    terms.iter().map(|(g, k)| k * t.z(*g) as f64).sum()
}

/// Fills the missing tooth counts from the conditions (each one with a single unknown
/// in turn), then checks every condition. Returns what was derived and the checks; a
/// violated condition is an error unless the train is `profile_shifted` (then a failed
/// check).
pub fn resolve_teeth(t: &mut GearTrain) -> Result<(Vec<DerivedTeeth>, Vec<Check>), TrainError> {
    let conds = conditions(t);
    let mut derived = Vec::new();
    loop {
        let mut progress = false;
        for c in &conds {
            let terms = c.merged();
            let unknown: Vec<&(usize, f64)> = terms
                .iter()
                .filter(|(g, _)| t.gears[*g].teeth.is_none())
                .collect();
            if unknown.len() != 1 {
                continue;
            }
            let (g, k) = *unknown[0];
            let known: f64 = terms
                .iter()
                .filter(|(h, _)| *h != g)
                .map(|(h, kh)| kh * t.z(*h) as f64)
                .sum();
            let z = (c.rhs - known) / k;
            let zr = z.round();
            if !(z.is_finite() && zr >= 1.0 && (z - zr).abs() < 1e-6 && zr < 1e6) {
                return Err(TrainError::new(
                    Element::Gear(g),
                    "teeth",
                    format!(
                        "the tooth count of '{}' from {} would be {z:.4}: not a positive whole number",
                        t.gears[g].name, c.what
                    ),
                ));
            }
            t.gears[g].teeth = Some(zr as u32);
            derived.push(DerivedTeeth {
                gear: g,
                teeth: zr as u32,
                from: c.what.clone(),
            });
            progress = true;
        }
        if !progress {
            break;
        }
    }
    if let Some(g) = t.gears.iter().position(|g| g.teeth.is_none()) {
        return Err(TrainError::new(
            Element::Gear(g),
            "teeth",
            format!(
                "the tooth count of '{}' is missing and no coaxiality condition or mesh `centre_distance` (with modules) fixes it",
                t.gears[g].name
            ),
        ));
    }
    let mut checks = Vec::new();
    for c in &conds {
        let (lhs, rhs) = (side(t, &c.left), side(t, &c.right) + c.rhs);
        let ok = (lhs - rhs).abs() <= 1e-9 * (1.0 + rhs.abs());
        let detail = if c.right.is_empty() {
            format!("{} (standard gears give {lhs} mm)", c.what)
        } else {
            format!("{} (A = {lhs} mm and {rhs} mm)", c.what)
        };
        if !ok && !t.profile_shifted {
            return Err(TrainError::new(
                c.element,
                if c.right.is_empty() {
                    "centre_distance"
                } else {
                    "gears"
                },
                format!("{detail}: violated (set `profile_shifted = true` for non-standard gears)"),
            ));
        }
        checks.push(Check {
            kind: if !c.right.is_empty() {
                "coaxiality"
            } else {
                "centre_distance"
            },
            detail,
            ok,
        });
    }
    Ok((derived, checks))
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The planet arm of body `p` on its carrier: the centre distance of its first spur mesh
/// with a frame-held gear (mm).
pub fn planet_arm(t: &GearTrain, p: usize) -> Option<f64> {
    t.meshes.iter().enumerate().find_map(|(e, m)| {
        let (ba, bb) = (t.gears[m.gears[0]].body, t.gears[m.gears[1]].body);
        let other = if ba == p {
            bb
        } else if bb == p {
            ba
        } else {
            return None;
        };
        if t.bodies[other].carrier.is_none() {
            t.centre_distance(e)
        } else {
            None
        }
    })
}

/// Equal-spacing assembly `(z_a z_pb ± z_b z_pa)/(n gcd(z_pa, z_pb)) ∈ ℤ` and the
/// neighbour condition `d_a < 2 a sin(π/n)` for carriers with `n ≥ 2` planets; a
/// violation is an error.
pub fn planet_checks(t: &GearTrain) -> Result<Vec<Check>, TrainError> {
    let mut out = Vec::new();
    for c in (0..t.bodies.len()).filter(|&c| t.bodies[c].is_carrier && t.bodies[c].planets > 1) {
        let n = t.bodies[c].planets as u64;
        let elem = t.bodies[c].element;
        for p in (0..t.bodies.len()).filter(|&p| t.bodies[p].carrier == Some(c)) {
            // (planet gear, central gear, internal mesh) of p's meshes with central gears.
            let central: Vec<(usize, usize, bool)> = t
                .meshes
                .iter()
                .filter_map(|m| {
                    let [a, b] = m.gears;
                    let (pa, pb) = (t.gears[a].body == p, t.gears[b].body == p);
                    let (pg, cg) = if pa {
                        (a, b)
                    } else if pb {
                        (b, a)
                    } else {
                        return None;
                    };
                    (t.bodies[t.gears[cg].body].carrier.is_none()).then_some((
                        pg,
                        cg,
                        t.gears[cg].internal,
                    ))
                })
                .collect();
            if let [(pa, a, ia), rest @ ..] = central.as_slice() {
                for (pb, b, ib) in rest {
                    let (za, zb) = (t.z(*a) as i64, t.z(*b) as i64);
                    let (zpa, zpb) = (t.z(*pa) as i64, t.z(*pb) as i64);
                    let num = if ia != ib {
                        za * zpb + zb * zpa
                    } else {
                        (za * zpb - zb * zpa).abs()
                    };
                    let den = n as i64 * gcd(zpa as u64, zpb as u64) as i64;
                    let ok = num % den == 0;
                    let detail = format!(
                        "{n} planets '{}' between '{}' and '{}': ({za}·{zpb} {} {zb}·{zpa})/({n}·{}) = {:.4}",
                        t.bodies[p].name,
                        t.gears[*a].name,
                        t.gears[*b].name,
                        if ia != ib { "+" } else { "−" },
                        den / n as i64,
                        num as f64 / den as f64
                    );
                    if !ok {
                        return Err(TrainError::new(
                            elem,
                            "planets",
                            format!("{detail}: not a whole number, so the planets cannot be equally spaced"),
                        ));
                    }
                    out.push(Check {
                        kind: "assembly",
                        detail,
                        ok,
                    });
                }
            }
            let Some(arm) = planet_arm(t, p) else {
                continue;
            };
            for g in t.gears_on(p) {
                let Some(m) = t.gears[g].module else { continue };
                let da = m * (t.z(g) as f64 + 2.0);
                let room = 2.0 * arm * (std::f64::consts::PI / n as f64).sin();
                let ok = da < room;
                let detail = format!(
                    "{n} planets: tip diameter of '{}' {da:.2} mm < 2 a sin(π/{n}) = {room:.2} mm",
                    t.gears[g].name
                );
                if !ok {
                    return Err(TrainError::new(
                        elem,
                        "planets",
                        format!("{detail} fails: neighbouring planets collide"),
                    ));
                }
                out.push(Check {
                    kind: "neighbours",
                    detail,
                    ok,
                });
            }
        }
    }
    Ok(out)
}
