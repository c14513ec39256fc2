//! Structural analysis (problem book ch. 1; Assur 1914, Artobolevsky's classification):
//! the linkage split into its initial mechanism (the driven link on the frame, class I)
//! and Assur groups, each a set of links and lower pairs with zero mobility,
//! `3 n = 2 p₅`, that cannot be split into smaller such sets.
//!
//! The groups are found from the frame outward: with `K` the bodies placed so far (the
//! frame and the driven link at first), the smallest connected set `S` of the other links
//! whose pairs inside `S` and between `S` and `K` number `p = 3|S|/2` is the next group;
//! it joins `K`, and so on until every link is placed.
//!
//! - **Class** of a group: II for a dyad (two links, three pairs); otherwise the number
//!   of pairs of the longest closed contour of its internal pairs (a four-link contour:
//!   class IV), or, with no contour, the most internal pairs on one link (the base link of
//!   a triad carries three: class III). The mechanism's class is its highest group class.
//! - **Order**: the number of external pairs (those joining the group to `K`).
//! - **Kind** of a dyad (R revolute, P prismatic, read external–internal–external):
//!   1 RRR, 2 RRP, 3 RPR, 4 PRP, 5 RPP.
//!
//! Higher pairs are replaced first: a pin in a slot (`Slider` without `prismatic`) becomes
//! a block turning on the pin (R) and sliding in the slot (P), a virtual link named
//! `block <joint>`; a cam contact of circles and lines
//! ([`crate::machines::linkage::higher_pair`]) becomes a link `contact <name>` with a
//! revolute at the centre of curvature of each profile (`<name> on <body>`), or a
//! prismatic pair along a flat face (its centre of curvature is at infinity).

use crate::machines::linkage::description::{Driver, Linkage, PlanarJoint, GROUND};

/// A lower pair of the structural graph.
#[derive(Clone, Debug, PartialEq)]
pub struct Pair {
    /// Joint name (as in the linkage).
    pub name: String,
    /// `'R'` or `'P'`.
    pub kind: char,
    /// The two structural bodies (indices into [`Structure::bodies`]).
    pub bodies: (usize, usize),
}

/// One Assur group.
#[derive(Clone, Debug, PartialEq)]
pub struct AssurGroup {
    /// Its links (indices into [`Structure::bodies`]).
    pub links: Vec<usize>,
    /// Pairs inside the group (indices into [`Structure::pairs`]).
    pub internal: Vec<usize>,
    /// Pairs joining it to what was placed before.
    pub external: Vec<usize>,
    /// Class (2 for a dyad).
    pub class: usize,
    /// Order (number of external pairs).
    pub order: usize,
    /// A dyad's pairs read external–internal–external (`"RRP"`), and its kind 1–5.
    pub kind: Option<(String, usize)>,
}

/// A higher pair replaced by a fictitious binary link and two lower pairs at the centres
/// of curvature of the two profiles at the contact (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct ReplacedPair {
    /// The contact's name.
    pub contact: String,
    /// The replacing link (index into [`Structure::bodies`]).
    pub link: usize,
    /// Its two lower pairs (indices into [`Structure::pairs`]): on `a`, then on `b`.
    pub pairs: [usize; 2],
    /// The link's length (the centre distance of two circles; `None` on a line).
    pub length: Option<f64>,
}

/// The structural decomposition.
#[derive(Clone, Debug, PartialEq)]
pub struct Structure {
    /// Body names: `ground`, the links, then virtual blocks.
    pub bodies: Vec<String>,
    /// The lower pairs.
    pub pairs: Vec<Pair>,
    /// The driven link and the pair joining it to the frame (the initial mechanism).
    pub initial: Option<(usize, usize)>,
    /// The groups, in the order they are attached.
    pub groups: Vec<AssurGroup>,
    /// Links no group could take (a mobility above one, or redundant pairs).
    pub unassigned: Vec<usize>,
    /// The mechanism's class: the highest group class (1 with no group).
    pub class: usize,
    /// The higher pairs (cam contacts) replaced by lower pairs.
    pub higher_pairs: Vec<ReplacedPair>,
}

/// Bodies and lower pairs of `l`: body 0 is the frame, `1 + i` link `i`, then the blocks
/// replacing pins in slots.
fn graph(l: &Linkage) -> (Vec<String>, Vec<Pair>) {
    let mut bodies: Vec<String> = std::iter::once("ground".to_string())
        .chain(l.links.iter().map(|k| k.name.clone()))
        .collect();
    let id = |b: usize| if b == GROUND { 0 } else { b + 1 };
    let mut pairs = Vec::new();
    for j in &l.joints {
        match j {
            PlanarJoint::Revolute { name, a, b, .. } => pairs.push(Pair {
                name: name.clone(),
                kind: 'R',
                bodies: (id(*a), id(*b)),
            }),
            PlanarJoint::Slider(s) if s.prismatic.is_some() => pairs.push(Pair {
                name: s.name.clone(),
                kind: 'P',
                bodies: (id(s.link), id(s.guide)),
            }),
            PlanarJoint::Slider(s) => {
                bodies.push(format!("block {}", s.name));
                let blk = bodies.len() - 1;
                pairs.push(Pair {
                    name: s.name.clone(),
                    kind: 'R',
                    bodies: (id(s.link), blk),
                });
                pairs.push(Pair {
                    name: format!("{} slot", s.name),
                    kind: 'P',
                    bodies: (blk, id(s.guide)),
                });
            }
            PlanarJoint::Contact(c) => {
                let (ka, kb) = c.replacement_kinds();
                let (na, nb) = (bodies[id(c.a)].clone(), bodies[id(c.b)].clone());
                bodies.push(format!("contact {}", c.name));
                let link = bodies.len() - 1;
                pairs.push(Pair {
                    name: format!("{} on {na}", c.name),
                    kind: ka,
                    bodies: (id(c.a), link),
                });
                pairs.push(Pair {
                    name: format!("{} on {nb}", c.name),
                    kind: kb,
                    bodies: (link, id(c.b)),
                });
            }
        }
    }
    (bodies, pairs)
}

/// The higher pairs of `l` replaced by a link and two lower pairs each, found in the graph
/// by their body names (`contact <name>`).
fn replaced(l: &Linkage, bodies: &[String], pairs: &[Pair]) -> Vec<ReplacedPair> {
    l.joints
        .iter()
        .filter_map(|j| match j {
            PlanarJoint::Contact(c) => Some(c),
            _ => None,
        })
        .filter_map(|c| {
            let link = bodies
                .iter()
                .position(|b| *b == format!("contact {}", c.name))?;
            let mut at = pairs
                .iter()
                .enumerate()
                .filter(|(_, p)| p.bodies.0 == link || p.bodies.1 == link)
                .map(|(k, _)| k);
            let pair_ids = [at.next()?, at.next()?];
            Some(ReplacedPair {
                contact: c.name.clone(),
                link,
                pairs: pair_ids,
                length: c.centre_distance(),
            })
        })
        .collect()
}

/// Decomposes `l` into its initial mechanism and Assur groups (module doc).
pub fn decompose(l: &Linkage) -> Structure {
    let (bodies, pairs) = graph(l);
    let n = bodies.len();
    let driven = l.driven_link() + 1;
    let initial = match &l.driver {
        Driver::Angle { relative_to, .. } if *relative_to != GROUND => None,
        Driver::Angle { .. } => pairs
            .iter()
            .position(|p| p.kind == 'R' && (p.bodies == (0, driven) || p.bodies == (driven, 0))),
        Driver::Slide { .. } => pairs
            .iter()
            .position(|p| p.kind == 'P' && (p.bodies == (0, driven) || p.bodies == (driven, 0))),
    };
    let mut known = vec![false; n];
    known[0] = true;
    if initial.is_some() {
        known[driven] = true;
    }
    let mut groups = Vec::new();
    while let Some(g) = next_group(&pairs, &known) {
        for &b in &g.links {
            known[b] = true;
        }
        groups.push(g);
    }
    let unassigned: Vec<usize> = (1..n).filter(|&b| !known[b]).collect();
    let class = groups.iter().map(|g| g.class).max().unwrap_or(1);
    let higher_pairs = replaced(l, &bodies, &pairs);
    Structure {
        higher_pairs,
        bodies,
        pairs,
        initial: initial.map(|p| (driven, p)),
        groups,
        unassigned,
        class,
    }
}

/// Largest number of links searched for one group.
const MAX_GROUP_LINKS: usize = 8;

/// The smallest connected zero-mobility set of unplaced bodies attached to `known`.
fn next_group(pairs: &[Pair], known: &[bool]) -> Option<AssurGroup> {
    let free: Vec<usize> = (0..known.len()).filter(|&b| !known[b]).collect();
    if free.len() > 24 {
        return None;
    }
    for size in (2..=free.len().min(MAX_GROUP_LINKS)).step_by(2) {
        let mut pick = Vec::new();
        if let Some(g) = search(pairs, known, &free, size, 0, &mut pick) {
            return Some(g);
        }
    }
    None
}

/// Depth-first choice of `size` bodies from `free[start..]`.
fn search(
    pairs: &[Pair],
    known: &[bool],
    free: &[usize],
    size: usize,
    start: usize,
    pick: &mut Vec<usize>,
) -> Option<AssurGroup> {
    if pick.len() == size {
        return group_of(pairs, known, pick);
    }
    for k in start..free.len() {
        pick.push(free[k]);
        if let Some(g) = search(pairs, known, free, size, k + 1, pick) {
            return Some(g);
        }
        pick.pop();
    }
    None
}

/// `S` as a group if it has `3|S|/2` pairs inside or to `known` and is connected.
fn group_of(pairs: &[Pair], known: &[bool], s: &[usize]) -> Option<AssurGroup> {
    let inside = |b: usize| s.contains(&b);
    let (mut internal, mut external) = (Vec::new(), Vec::new());
    for (k, p) in pairs.iter().enumerate() {
        let (a, b) = p.bodies;
        match (inside(a), inside(b)) {
            (true, true) => internal.push(k),
            (true, false) if known[b] => external.push(k),
            (false, true) if known[a] => external.push(k),
            _ => {}
        }
    }
    if 2 * (internal.len() + external.len()) != 3 * s.len() || !connected(pairs, &internal, s) {
        return None;
    }
    let class = if s.len() == 2 {
        2
    } else {
        let cycle = longest_cycle(pairs, &internal, s);
        if cycle >= 3 {
            cycle
        } else {
            s.iter()
                .map(|&b| {
                    internal
                        .iter()
                        .filter(|&&k| pairs[k].bodies.0 == b || pairs[k].bodies.1 == b)
                        .count()
                })
                .max()
                .unwrap_or(0)
        }
    };
    let kind = (s.len() == 2).then(|| dyad_kind(pairs, &internal, &external, s));
    Some(AssurGroup {
        links: s.to_vec(),
        order: external.len(),
        internal,
        external,
        class,
        kind,
    })
}

/// Whether the internal pairs connect all of `s`.
fn connected(pairs: &[Pair], internal: &[usize], s: &[usize]) -> bool {
    let mut seen = vec![s[0]];
    let mut grew = true;
    while grew {
        grew = false;
        for &k in internal {
            let (a, b) = pairs[k].bodies;
            for (x, y) in [(a, b), (b, a)] {
                if seen.contains(&x) && !seen.contains(&y) {
                    seen.push(y);
                    grew = true;
                }
            }
        }
    }
    seen.len() == s.len()
}

/// The number of pairs of the longest simple closed contour of internal pairs (0 if none).
fn longest_cycle(pairs: &[Pair], internal: &[usize], s: &[usize]) -> usize {
    fn walk(
        pairs: &[Pair],
        internal: &[usize],
        start: usize,
        at: usize,
        used: &mut Vec<usize>,
        visited: &mut Vec<usize>,
        best: &mut usize,
    ) {
        for &k in internal {
            if used.contains(&k) {
                continue;
            }
            let (a, b) = pairs[k].bodies;
            let next = if a == at {
                b
            } else if b == at {
                a
            } else {
                continue;
            };
            if next == start {
                *best = (*best).max(used.len() + 1);
            } else if !visited.contains(&next) {
                used.push(k);
                visited.push(next);
                walk(pairs, internal, start, next, used, visited, best);
                visited.pop();
                used.pop();
            }
        }
    }
    let mut best = 0;
    for &b in s {
        walk(
            pairs,
            internal,
            b,
            b,
            &mut Vec::new(),
            &mut vec![b],
            &mut best,
        );
    }
    best
}

/// A dyad's pair letters external–internal–external and its kind (1 RRR, 2 RRP, 3 RPR,
/// 4 PRP, 5 RPP).
fn dyad_kind(
    pairs: &[Pair],
    internal: &[usize],
    external: &[usize],
    s: &[usize],
) -> (String, usize) {
    let ext_of = |b: usize| {
        external
            .iter()
            .find(|&&k| pairs[k].bodies.0 == b || pairs[k].bodies.1 == b)
            .map_or('?', |&k| pairs[k].kind)
    };
    let mid = internal.first().map_or('?', |&k| pairs[k].kind);
    let (e1, e2) = (ext_of(s[0]), ext_of(s[1]));
    // R first where the two ends differ.
    let (e1, e2) = if e1 == 'P' && e2 == 'R' {
        (e2, e1)
    } else {
        (e1, e2)
    };
    let letters: String = [e1, mid, e2].iter().collect();
    let kind = match letters.as_str() {
        "RRR" => 1,
        "RRP" => 2,
        "RPR" => 3,
        "PRP" => 4,
        "RPP" => 5,
        _ => 0,
    };
    (letters, kind)
}
