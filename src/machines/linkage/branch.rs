//! Assembly modes (branches): the structural groups of a linkage and the sign of each
//! group's Jacobian determinant.
//!
//! A driven single-loop or multi-loop linkage decomposes into groups that can be solved
//! one after the other (Assur groups: the crank, then the dyad closing the first loop,
//! then the next dyad, …). Structurally this is the block-triangular form of the driven
//! Jacobian `Φ_q` (Duff & Reid, "An implementation of Tarjan's algorithm for the block
//! triangularization of a matrix", ACM TOMS 4, 1978): a perfect matching of equations to
//! coordinates (augmenting paths), then the strongly connected components (Tarjan 1972)
//! of the graph "equation `i` uses the coordinate matched to equation `j`". Each
//! component with more than one equation closes a loop; its two (or more) assembly modes
//! are told apart by the sign of the determinant of its block of `Φ_q` — for a four-bar's
//! coupler–rocker dyad that is the orientation of the triangle at the coupler–rocker pin.
//!
//! The sign changes only where the block is singular (a change point, a limit position).
//! The indicator reported is the determinant divided by the product of the block's row
//! norms (Hadamard's ratio, in `[−1, 1]`), so it is scale-free and its magnitude says how
//! far the group is from singular.

use crate::machines::linkage::constraints::jacobian_mat;
use crate::machines::linkage::description::Linkage;
use nalgebra::{DMatrix, DVector};

/// One structural group: equations (rows of `Φ_q`) and the coordinates they determine.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StructuralGroup {
    /// Rows of `Φ_q`, ascending.
    pub rows: Vec<usize>,
    /// Columns (coordinates), ascending.
    pub cols: Vec<usize>,
    /// Links whose coordinates the group determines.
    pub links: Vec<usize>,
    /// Name: the links joined by `+`.
    pub name: String,
}

/// `|indicator|` below which a group counts as singular (its sign is then undefined).
pub const GROUP_SINGULAR_TOL: f64 = 1e-6;

/// A generic point near `q` (angles moved by irrational amounts) where no entry of `Φ_q`
/// vanishes by accident, so its pattern is the structural one.
fn generic(q: &DVector<f64>) -> DVector<f64> {
    let mut g = q.clone();
    for (i, x) in g.iter_mut().enumerate() {
        *x += 0.1 + 0.3819660112501051 * (i as f64 + 1.0).sqrt();
    }
    g
}

/// Rows of `jac` chosen greedily (in order) so that they are linearly independent.
fn independent_rows(jac: &DMatrix<f64>) -> Vec<usize> {
    let mut basis: Vec<DVector<f64>> = Vec::new();
    let mut rows = Vec::new();
    for i in 0..jac.nrows() {
        let mut v: DVector<f64> = jac.row(i).transpose();
        let n0 = v.norm();
        if n0 == 0.0 {
            continue;
        }
        for b in &basis {
            let c = b.dot(&v);
            v -= b * c;
        }
        if v.norm() > 1e-9 * n0 {
            let n = v.norm();
            basis.push(v / n);
            rows.push(i);
        }
    }
    rows
}

/// Kuhn's augmenting-path matching of rows to columns on the pattern `adj[row]`.
fn match_rows(adj: &[Vec<usize>], ncols: usize) -> Option<Vec<usize>> {
    fn augment(r: usize, adj: &[Vec<usize>], seen: &mut [bool], col_row: &mut [usize]) -> bool {
        for &c in &adj[r] {
            if seen[c] {
                continue;
            }
            seen[c] = true;
            if col_row[c] == usize::MAX || augment(col_row[c], adj, seen, col_row) {
                col_row[c] = r;
                return true;
            }
        }
        false
    }
    let mut col_row = vec![usize::MAX; ncols];
    for r in 0..adj.len() {
        let mut seen = vec![false; ncols];
        if !augment(r, adj, &mut seen, &mut col_row) {
            return None;
        }
    }
    let mut row_col = vec![usize::MAX; adj.len()];
    for (c, &r) in col_row.iter().enumerate() {
        if r != usize::MAX {
            row_col[r] = c;
        }
    }
    Some(row_col)
}

/// Tarjan's strongly connected components of the graph `edges[v]`.
fn tarjan(edges: &[Vec<usize>]) -> Vec<Vec<usize>> {
    struct St<'a> {
        edges: &'a [Vec<usize>],
        index: Vec<usize>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut St, v: usize) {
        s.index[v] = s.next;
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on[v] = true;
        for k in 0..s.edges[v].len() {
            let w = s.edges[v][k];
            if s.index[w] == usize::MAX {
                visit(s, w);
                s.low[v] = s.low[v].min(s.low[w]);
            } else if s.on[w] {
                s.low[v] = s.low[v].min(s.index[w]);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on[w] = false;
                comp.push(w);
                if w == v {
                    break;
                }
            }
            comp.sort_unstable();
            s.out.push(comp);
        }
    }
    let n = edges.len();
    let mut s = St {
        edges,
        index: vec![usize::MAX; n],
        low: vec![0; n],
        on: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v] == usize::MAX {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The structural groups with more than one equation (the loops), from the pattern of
/// `Φ_q` near `q`. Redundant equations (dependent rows at `q`) are left out first. Empty
/// when the driven system is not square (more inputs needed) or has no perfect matching.
pub fn structural_groups(l: &Linkage, q: &DVector<f64>) -> Vec<StructuralGroup> {
    let jac_q = jacobian_mat(l, q);
    let rows = independent_rows(&jac_q);
    let n = l.ncoords();
    if rows.len() != n {
        return Vec::new();
    }
    let jg = jacobian_mat(l, &generic(q));
    let big = jg.amax().max(1e-300);
    let adj: Vec<Vec<usize>> = rows
        .iter()
        .map(|&r| (0..n).filter(|&c| jg[(r, c)].abs() > 1e-12 * big).collect())
        .collect();
    let Some(row_col) = match_rows(&adj, n) else {
        return Vec::new();
    };
    let mut col_owner = vec![0usize; n];
    for (i, &c) in row_col.iter().enumerate() {
        col_owner[c] = i;
    }
    let edges: Vec<Vec<usize>> = adj
        .iter()
        .enumerate()
        .map(|(i, cs)| {
            cs.iter()
                .map(|&c| col_owner[c])
                .filter(|&j| j != i)
                .collect()
        })
        .collect();
    let mut groups: Vec<StructuralGroup> = tarjan(&edges)
        .into_iter()
        .filter(|comp| comp.len() > 1)
        .map(|comp| {
            let mut rs: Vec<usize> = comp.iter().map(|&i| rows[i]).collect();
            let mut cs: Vec<usize> = comp.iter().map(|&i| row_col[i]).collect();
            rs.sort_unstable();
            cs.sort_unstable();
            let mut links: Vec<usize> = cs.iter().map(|c| c / 3).collect();
            links.dedup();
            let name = links
                .iter()
                .map(|&k| l.links[k].name.as_str())
                .collect::<Vec<_>>()
                .join("+");
            StructuralGroup {
                rows: rs,
                cols: cs,
                links,
                name,
            }
        })
        .collect();
    groups.sort_by_key(|g| g.rows[0]);
    groups
}

/// Each group's branch indicator at `q`: `det(block) / Π ‖block row‖`.
pub fn indicators(l: &Linkage, groups: &[StructuralGroup], q: &DVector<f64>) -> Vec<f64> {
    indicators_from(groups, &jacobian_mat(l, q))
}

/// Each group's branch indicator from the driven Jacobian `jac`.
pub fn indicators_from(groups: &[StructuralGroup], jac: &DMatrix<f64>) -> Vec<f64> {
    groups
        .iter()
        .map(|g| {
            let k = g.rows.len();
            let block = DMatrix::from_fn(k, k, |i, j| jac[(g.rows[i], g.cols[j])]);
            let norms: f64 = (0..k).map(|i| block.row(i).norm()).product();
            if norms == 0.0 {
                0.0
            } else {
                block.determinant() / norms
            }
        })
        .collect()
}

/// The sign of an indicator, or 0 where the group is singular.
pub fn sign(indicator: f64) -> i8 {
    if indicator.abs() < GROUP_SINGULAR_TOL {
        0
    } else if indicator > 0.0 {
        1
    } else {
        -1
    }
}
