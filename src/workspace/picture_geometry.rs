//! The geometry of the workspace picture, independent of the viewer: the pooled occupancy
//! grid of a [`WorkspaceResult`] read back cell by cell, its boundary as a triangle mesh
//! (surface nets: one vertex per dual cube whose eight voxel centres are mixed occupied
//! and empty, one quad across every edge between an occupied and an empty voxel centre),
//! a cut-away ([`Cutaway`]: the quarter of the workspace on one side of two half-planes
//! through the base axis is removed) with its section (the grid's layers that contain
//! those half-planes, one square per occupied voxel), the manipulability per voxel that
//! colours both, and a representative pose of the robot (inside the removed quarter,
//! where the arm is most mobile).
//!
//! The occupancy is taken through the result's public interface only
//! ([`WorkspaceResult::is_occupied`] at the centre of each cell of the lattice `h ℤ³`
//! over the bounding box, [`WorkspaceResult::voxels`] and the kept points for the
//! manipulability), so it is the grid the volume was measured on.

use crate::core::spatial::Vec3;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::{Model, WORLD};
use crate::workspace::WorkspaceResult;

/// Largest block of cells read back (one byte and one float each).
pub const MAX_CELLS: usize = 1 << 25;

/// The occupancy of a workspace on the lattice `h ℤ³`, with an empty margin of two
/// cells around the bounding box, and the mean manipulability per occupied cell (NaN
/// where no sample told it).
#[derive(Clone, Debug)]
pub struct Occupancy {
    /// Cell edge (m).
    pub h: f64,
    /// Global index of the block's first cell: cell `(i, j, k)` covers
    /// `[i h, (i + 1) h) × [j h, (j + 1) h) × [k h, (k + 1) h)`.
    pub i0: [i64; 3],
    /// Cells per axis.
    pub n: [usize; 3],
    /// Occupied, x fastest.
    pub occupied: Vec<bool>,
    /// Mean translational manipulability per cell (NaN: empty or unknown).
    pub value: Vec<f32>,
}

/// A triangle mesh with one scalar per vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScalarMesh {
    /// Vertex positions (world, m).
    pub vertices: Vec<[f32; 3]>,
    /// Triangles, counter-clockwise seen from the side the normal points to.
    pub triangles: Vec<[u32; 3]>,
    /// Value per vertex (manipulability).
    pub values: Vec<f32>,
}

/// The plane of the cross-section: `x[axis] = at`, through the base axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// World axis normal to the plane (0: x, 1: y, 2: z).
    pub axis: usize,
    /// Coordinate of the plane along it (m).
    pub at: f64,
}

impl Occupancy {
    /// Reads the pooled occupancy of `ws`; `None` for a planar workspace, an empty or
    /// non-finite bounding box, or a block over [`MAX_CELLS`].
    pub fn from_workspace(ws: &WorkspaceResult) -> Option<Occupancy> {
        let h = ws.voxel;
        if ws.planar || h.is_nan() || h <= 0.0 {
            return None;
        }
        let mut i0 = [0i64; 3];
        let mut n = [0usize; 3];
        for k in 0..3 {
            let (lo, hi) = (ws.bbox[0][k], ws.bbox[1][k]);
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return None;
            }
            // Two empty layers around the occupied cells: the mesh closes inside.
            i0[k] = (lo / h).floor() as i64 - 2;
            n[k] = ((hi / h).floor() as i64 + 3 - i0[k]) as usize;
        }
        let cells = n[0].checked_mul(n[1])?.checked_mul(n[2])?;
        if cells > MAX_CELLS {
            return None;
        }
        let mut occ = Occupancy {
            h,
            i0,
            n,
            occupied: vec![false; cells],
            value: vec![f32::NAN; cells],
        };
        for c in 0..cells {
            let l = occ.local(c);
            // The outermost layer stays empty whatever the grid says.
            if (0..3).any(|k| l[k] == 0 || l[k] + 1 == n[k]) {
                continue;
            }
            occ.occupied[c] = ws.is_occupied(&occ.center(l));
        }
        occ.fill_values(ws);
        Some(occ)
    }

    /// Local index of flat cell `c`.
    fn local(&self, c: usize) -> [usize; 3] {
        [
            c % self.n[0],
            (c / self.n[0]) % self.n[1],
            c / (self.n[0] * self.n[1]),
        ]
    }

    /// Flat index of local cell `l`.
    pub fn flat(&self, l: [usize; 3]) -> usize {
        (l[2] * self.n[1] + l[1]) * self.n[0] + l[0]
    }

    /// Centre of local cell `l` (world, m).
    pub fn center(&self, l: [usize; 3]) -> Vec3 {
        let c = |k: usize| (self.i0[k] + l[k] as i64) as f64 * self.h + 0.5 * self.h;
        Vec3::new(c(0), c(1), c(2))
    }

    /// Local cell containing world point `p`, if inside the block.
    fn locate(&self, p: &[f64; 3]) -> Option<[usize; 3]> {
        let mut l = [0usize; 3];
        for k in 0..3 {
            let i = (p[k] / self.h).floor() as i64 - self.i0[k];
            if i < 0 || i >= self.n[k] as i64 {
                return None;
            }
            l[k] = i as usize;
        }
        Some(l)
    }

    /// Occupied cells.
    pub fn count(&self) -> usize {
        self.occupied.iter().filter(|&&o| o).count()
    }

    /// Mean manipulability per occupied cell: the Jacobian pass's voxel statistics when
    /// it ran, else the mean over the kept points in the cell; cells without either take
    /// the mean of their known neighbours (a few passes).
    fn fill_values(&mut self, ws: &WorkspaceResult) {
        if !ws.voxels.is_empty() {
            for v in &ws.voxels {
                let l: Option<Vec<usize>> = (0..3)
                    .map(|k| {
                        let i = v.index[k] - self.i0[k];
                        (0..self.n[k] as i64).contains(&i).then_some(i as usize)
                    })
                    .collect();
                if let Some(l) = l {
                    let c = self.flat([l[0], l[1], l[2]]);
                    if self.occupied[c] {
                        self.value[c] = v.manipulability_mean as f32;
                    }
                }
            }
        } else {
            let mut sum = vec![0.0f64; self.value.len()];
            let mut count = vec![0u32; self.value.len()];
            for p in &ws.points {
                if let Some(l) = self.locate(&p.p) {
                    let c = self.flat(l);
                    sum[c] += p.manipulability;
                    count[c] += 1;
                }
            }
            for c in 0..sum.len() {
                if count[c] > 0 && self.occupied[c] {
                    self.value[c] = (sum[c] / count[c] as f64) as f32;
                }
            }
        }
        for _ in 0..4 {
            let missing: Vec<usize> = (0..self.value.len())
                .filter(|&c| self.occupied[c] && self.value[c].is_nan())
                .collect();
            if missing.is_empty() {
                break;
            }
            let filled: Vec<(usize, f32)> = missing
                .iter()
                .filter_map(|&c| self.neighbour_mean(c).map(|v| (c, v)))
                .collect();
            for (c, v) in filled {
                self.value[c] = v;
            }
        }
    }

    /// Mean of the known values among the 26 neighbours of flat cell `c`.
    fn neighbour_mean(&self, c: usize) -> Option<f32> {
        let l = self.local(c);
        let (mut s, mut k) = (0.0f32, 0u32);
        for dz in -1i64..=1 {
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let m = [l[0] as i64 + dx, l[1] as i64 + dy, l[2] as i64 + dz];
                    if (0..3).any(|a| m[a] < 0 || m[a] >= self.n[a] as i64) {
                        continue;
                    }
                    let v = self.value[self.flat(m.map(|x| x as usize))];
                    if v.is_finite() {
                        s += v;
                        k += 1;
                    }
                }
            }
        }
        (k > 0).then(|| s / k as f32)
    }

    /// Empty cells with at least four occupied face neighbours, per occupied cell: the
    /// holes that too few samples for the cell size leave (a solid has none but along
    /// concave edges; a half-filled speckle has about one in six).
    pub fn hole_fraction(&self) -> f64 {
        let (mut occupied, mut holes) = (0usize, 0usize);
        for c in 0..self.occupied.len() {
            if self.occupied[c] {
                occupied += 1;
                continue;
            }
            let l = self.local(c);
            let mut around = 0;
            for k in 0..3 {
                for d in [-1i64, 1] {
                    let x = l[k] as i64 + d;
                    if x >= 0 && x < self.n[k] as i64 {
                        let mut m = l;
                        m[k] = x as usize;
                        around += self.occupied[self.flat(m)] as usize;
                    }
                }
            }
            holes += (around >= 4) as usize;
        }
        holes as f64 / occupied.max(1) as f64
    }

    /// The same occupancy on cells of `2 h` (a cell is occupied when any of its eight
    /// halves is; its value is their mean), with the same empty margin.
    pub fn coarsened(&self) -> Occupancy {
        let mut i0 = [0i64; 3];
        let mut n = [0usize; 3];
        for k in 0..3 {
            i0[k] = self.i0[k].div_euclid(2) - 2;
            n[k] = ((self.i0[k] + self.n[k] as i64 - 1).div_euclid(2) + 3 - i0[k]) as usize;
        }
        let cells = n[0] * n[1] * n[2];
        let mut out = Occupancy {
            h: 2.0 * self.h,
            i0,
            n,
            occupied: vec![false; cells],
            value: vec![f32::NAN; cells],
        };
        let mut sum = vec![0.0f64; cells];
        let mut count = vec![0u32; cells];
        for c in 0..self.occupied.len() {
            if !self.occupied[c] {
                continue;
            }
            let l = self.local(c);
            let g: [usize; 3] = std::array::from_fn(|k| {
                ((self.i0[k] + l[k] as i64).div_euclid(2) - i0[k]) as usize
            });
            let cc = out.flat(g);
            out.occupied[cc] = true;
            if self.value[c].is_finite() {
                sum[cc] += self.value[c] as f64;
                count[cc] += 1;
            }
        }
        for c in 0..cells {
            if count[c] > 0 {
                out.value[c] = (sum[c] / count[c] as f64) as f32;
            }
        }
        out
    }

    /// Largest finite value (0 when none).
    pub fn max_value(&self) -> f32 {
        self.value
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0, f32::max)
    }

    /// The boundary of the occupied set as a closed mesh (surface nets): a vertex in every
    /// dual cube (eight neighbouring voxel centres) that holds both occupied and empty
    /// centres, at the mean of the midpoints of its mixed edges; a quad (two triangles)
    /// across every edge between an occupied and an empty centre, facing the empty one.
    /// Vertex values: the mean value of the cube's occupied centres.
    pub fn boundary_mesh(&self) -> ScalarMesh {
        let [nx, ny, nz] = self.n;
        if nx < 2 || ny < 2 || nz < 2 {
            return ScalarMesh::default();
        }
        let dual = |l: [usize; 3]| (l[2] * (ny - 1) + l[1]) * (nx - 1) + l[0];
        let mut vid = vec![u32::MAX; (nx - 1) * (ny - 1) * (nz - 1)];
        let mut mesh = ScalarMesh::default();
        for z in 0..nz - 1 {
            for y in 0..ny - 1 {
                for x in 0..nx - 1 {
                    if let Some((p, v)) = self.dual_vertex([x, y, z]) {
                        vid[dual([x, y, z])] = mesh.vertices.len() as u32;
                        mesh.vertices.push(p);
                        mesh.values.push(v);
                    }
                }
            }
        }
        for z in 1..nz - 1 {
            for y in 1..ny - 1 {
                for x in 1..nx - 1 {
                    let a = [x, y, z];
                    let occ_a = self.occupied[self.flat(a)];
                    for d in 0..3 {
                        let mut b = a;
                        b[d] += 1;
                        if b[d] >= self.n[d] || self.occupied[self.flat(b)] == occ_a {
                            continue;
                        }
                        // The four dual cubes around edge a–b, counter-clockwise about +d.
                        let (u, v) = ((d + 1) % 3, (d + 2) % 3);
                        let shift = |du: usize, dv: usize| {
                            let mut c = a;
                            c[u] -= du;
                            c[v] -= dv;
                            vid[dual(c)]
                        };
                        let q = [shift(1, 1), shift(0, 1), shift(0, 0), shift(1, 0)];
                        let q = if occ_a { q } else { [q[3], q[2], q[1], q[0]] };
                        mesh.triangles.push([q[0], q[1], q[2]]);
                        mesh.triangles.push([q[0], q[2], q[3]]);
                    }
                }
            }
        }
        mesh
    }

    /// The surface-nets vertex of the dual cube whose lowest corner is local cell `l`.
    fn dual_vertex(&self, l: [usize; 3]) -> Option<([f32; 3], f32)> {
        let corner = |b: usize| [l[0] + (b & 1), l[1] + (b >> 1 & 1), l[2] + (b >> 2 & 1)];
        let occ: [bool; 8] = std::array::from_fn(|b| self.occupied[self.flat(corner(b))]);
        if occ.iter().all(|&o| o) || occ.iter().all(|&o| !o) {
            return None;
        }
        let (mut p, mut k) = (Vec3::zeros(), 0.0);
        for a in 0..8usize {
            for bit in [1usize, 2, 4] {
                let b = a | bit;
                if b != a && occ[a] != occ[b] {
                    p += 0.5 * (self.center(corner(a)) + self.center(corner(b)));
                    k += 1.0;
                }
            }
        }
        let p = p / k;
        let (mut s, mut m) = (0.0f32, 0u32);
        for (b, &o) in occ.iter().enumerate() {
            let v = self.value[self.flat(corner(b))];
            if o && v.is_finite() {
                s += v;
                m += 1;
            }
        }
        let v = if m > 0 { s / m as f32 } else { f32::NAN };
        Some(([p.x as f32, p.y as f32, p.z as f32], v))
    }

    /// The occupied cells of the layer that contains the plane `section`, as one square
    /// (two triangles, four vertices of the cell's value) per cell, lying in the plane and
    /// facing `-axis` when `toward_negative`, else `+axis`; with `below = Some((k, c))`
    /// only the cells whose centre has `x[k] < c`.
    pub fn section_mesh(
        &self,
        section: Section,
        toward_negative: bool,
        below: Option<(usize, f64)>,
    ) -> ScalarMesh {
        let s = section.axis.min(2);
        let layer = (section.at / self.h).floor() as i64 - self.i0[s];
        let mut mesh = ScalarMesh::default();
        if layer < 0 || layer >= self.n[s] as i64 {
            return mesh;
        }
        let (u, v) = ((s + 1) % 3, (s + 2) % 3);
        for b in 0..self.n[v] {
            for a in 0..self.n[u] {
                let mut l = [0usize; 3];
                l[s] = layer as usize;
                l[u] = a;
                l[v] = b;
                let c = self.flat(l);
                if !self.occupied[c] || below.is_some_and(|(k, x)| self.center(l)[k] >= x) {
                    continue;
                }
                let lo = |k: usize| (self.i0[k] + l[k] as i64) as f64 * self.h;
                let first = mesh.vertices.len() as u32;
                for (du, dv) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                    let mut p = [0.0f32; 3];
                    p[s] = section.at as f32;
                    p[u] = (lo(u) + du * self.h) as f32;
                    p[v] = (lo(v) + dv * self.h) as f32;
                    mesh.vertices.push(p);
                    mesh.values.push(self.value[c]);
                }
                let q = [first, first + 1, first + 2, first + 3];
                let q = if toward_negative {
                    [q[3], q[2], q[1], q[0]]
                } else {
                    q
                };
                mesh.triangles.push([q[0], q[1], q[2]]);
                mesh.triangles.push([q[0], q[2], q[3]]);
            }
        }
        mesh
    }

    /// The section of a cut-away: the two half-planes through the base axis that bound
    /// the removed quarter, each facing into it.
    pub fn cutaway_section(&self, cut: &Cutaway) -> ScalarMesh {
        let [u, v] = cut.across;
        let mut a = self.section_mesh(
            Section {
                axis: u,
                at: cut.base[u],
            },
            true,
            Some((v, cut.base[v])),
        );
        let b = self.section_mesh(
            Section {
                axis: v,
                at: cut.base[v],
            },
            true,
            Some((u, cut.base[u])),
        );
        a.append(&b);
        a
    }
}

/// A cut-away view: the quarter `x[u] < base[u] and x[v] < base[v]` of the workspace is
/// removed, `u`, `v` the two world axes across the base axis (x and y for a vertical
/// one), so that the two half-planes through the base axis that bound it show the
/// inside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cutaway {
    /// A point of the base axis (world, m).
    pub base: Vec3,
    /// The world axis nearest the base axis (2 for a vertical one).
    pub along: usize,
    /// The other two, in increasing order.
    pub across: [usize; 2],
}

impl Cutaway {
    /// The cut-away around the base axis through `base` along `axis`.
    pub fn new(base: Vec3, axis: &Vec3) -> Cutaway {
        let along = (0..3)
            .max_by(|&a, &b| axis[a].abs().total_cmp(&axis[b].abs()))
            .unwrap_or(2);
        let across = match along {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        };
        Cutaway {
            base,
            along,
            across,
        }
    }

    /// Whether `p` lies in the removed quarter.
    pub fn removes(&self, p: &[f64; 3]) -> bool {
        let [u, v] = self.across;
        p[u] < self.base[u] && p[v] < self.base[v]
    }
}

impl ScalarMesh {
    /// Splits the mesh by the cut-away `cut`: the triangles whose centroid lies in the
    /// removed quarter, and the others; unused vertices are dropped.
    pub fn cut(&self, cut: &Cutaway) -> (ScalarMesh, ScalarMesh) {
        let mut removed = Builder::new(self);
        let mut kept = Builder::new(self);
        for t in &self.triangles {
            let mut c = [0.0f64; 3];
            for &i in t {
                for (k, x) in c.iter_mut().enumerate() {
                    *x += self.vertices[i as usize][k] as f64 / 3.0;
                }
            }
            if cut.removes(&c) {
                removed.push(t);
            } else {
                kept.push(t);
            }
        }
        (removed.mesh, kept.mesh)
    }

    /// Appends `other`.
    pub fn append(&mut self, other: &ScalarMesh) {
        let n = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.values.extend_from_slice(&other.values);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + n)));
    }
}

/// Collects triangles of a source mesh with their vertices renumbered.
struct Builder<'a> {
    src: &'a ScalarMesh,
    map: Vec<u32>,
    mesh: ScalarMesh,
}

impl<'a> Builder<'a> {
    fn new(src: &'a ScalarMesh) -> Self {
        Builder {
            src,
            map: vec![u32::MAX; src.vertices.len()],
            mesh: ScalarMesh::default(),
        }
    }

    fn push(&mut self, t: &[u32; 3]) {
        let mut out = [0u32; 3];
        for (k, &i) in t.iter().enumerate() {
            let i = i as usize;
            if self.map[i] == u32::MAX {
                self.map[i] = self.mesh.vertices.len() as u32;
                self.mesh.vertices.push(self.src.vertices[i]);
                self.mesh.values.push(self.src.values[i]);
            }
            out[k] = self.map[i];
        }
        self.mesh.triangles.push(out);
    }
}

/// The base of the tool's chain: the origin of its first joint (world) and that joint's
/// world axis.
pub fn base_axis(model: &Model, tool: &str) -> Option<(Vec3, Vec3)> {
    let link = &model.links[model.link_id(tool)?];
    let mut b = link.body;
    if b == WORLD {
        return None;
    }
    while model.parent[b] != WORLD {
        b = model.parent[b];
    }
    let m = &model.placement[b];
    Some((
        m.trans,
        m.rot.column(model.kind[b].axis_index()).into_owned(),
    ))
}

/// A representative pose among the kept samples of `ws`: the most mobile one (largest
/// manipulability) whose tool point lies well inside the removed quarter of `cut` (at
/// least a sixth of the reach from both half-planes), at a height between the base and
/// the top of the workspace, and whose link origins all stay in that quarter (within a
/// twentieth of the reach). `None` when no kept sample qualifies.
pub fn representative_pose(model: &Model, ws: &WorkspaceResult, cut: &Cutaway) -> Option<Vec<f64>> {
    let [u, v] = cut.across;
    let a = cut.along;
    let reach = (0..3)
        .map(|k| 0.5 * (ws.bbox[1][k] - ws.bbox[0][k]))
        .fold(0.0, f64::max);
    let top = ws.bbox[1][a];
    let base = cut.base;
    let mut order: Vec<usize> = (0..ws.points.len())
        .filter(|&i| {
            let s = &ws.points[i];
            let p = &s.p;
            base[u] - p[u] >= reach / 6.0
                && base[v] - p[v] >= reach / 6.0
                && p[a] >= base[a]
                && p[a] <= base[a] + 0.7 * (top - base[a])
                && s.q.len() == model.nv
                && s.manipulability.is_finite()
        })
        .collect();
    order.sort_by(|&i, &j| {
        ws.points[j]
            .manipulability
            .total_cmp(&ws.points[i].manipulability)
    });
    let mut data = Data::new(model);
    let slack = 0.05 * reach.max(1e-3);
    order.into_iter().take(5000).find_map(|i| {
        let q = &ws.points[i].q;
        forward_kinematics(model, &mut data, q);
        let inside = (0..model.links.len()).all(|l| {
            let p = frame_placement(model, &data, l).trans;
            p[u] <= base[u] + slack && p[v] <= base[v] + slack
        });
        inside.then(|| q.clone())
    })
}
