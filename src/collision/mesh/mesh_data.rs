//! The indexed triangle mesh every reader produces ([`MeshData`]), with the vertex
//! welding the readers share and the triangle limit they enforce ([`MAX_TRIANGLES`]).

use crate::collision::mesh::mesh_error::{MeshError, NonFiniteVertex};
use nalgebra::Vector3;
use std::collections::HashMap;

/// An indexed triangle mesh in f64.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
    /// Triangles read but dropped for a repeated corner (zero area).
    pub dropped: usize,
    /// What the reader skipped and says so (a DAE `<instance_geometry>` whose URL names
    /// no geometry of the file), with the line; the caller names the file
    /// ([`MeshError::in_file`]) and prints them, or refuses them under `--strict`.
    pub warnings: Vec<MeshError>,
}

/// Most triangles in one mesh (after a DAE scene places its geometries): 5 million, what
/// a binary STL of [`crate::core::files::MAX_MESH_BYTES`] holds.
pub const MAX_TRIANGLES: usize = 5_000_000;

impl MeshData {
    /// Adds a triangle given by its corner positions, merging identical vertices through
    /// `index` (keyed by the bit patterns, `-0.0` folded onto `0.0`). A non-finite
    /// coordinate is an error.
    pub(super) fn push_triangle(
        &mut self,
        index: &mut HashMap<[u64; 3], u32>,
        tri: [[f64; 3]; 3],
    ) -> Result<(), NonFiniteVertex> {
        if let Some(p) = tri.iter().find(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(NonFiniteVertex(*p));
        }
        let mut ids = [0u32; 3];
        for (k, p) in tri.iter().enumerate() {
            let key = p.map(|x| (x + 0.0).to_bits());
            ids[k] = *index.entry(key).or_insert_with(|| {
                self.vertices.push(*p);
                (self.vertices.len() - 1) as u32
            });
        }
        // Triangles with a repeated corner carry no area.
        if ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2] {
            self.triangles.push(ids);
        } else {
            self.dropped += 1;
        }
        Ok(())
    }

    /// Whether every undirected edge is used by exactly two triangles, once in each
    /// direction (a closed, consistently oriented surface).
    pub fn is_closed(&self) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let mut directed: HashMap<(u32, u32), u32> =
            HashMap::with_capacity(self.triangles.len() * 3);
        for t in &self.triangles {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        directed
            .iter()
            .all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1))
    }

    /// Six times the signed volume enclosed (positive for outward-facing triangles).
    pub fn signed_volume6(&self) -> f64 {
        let v = |i: u32| Vector3::from(self.vertices[i as usize]);
        self.triangles
            .iter()
            .map(|t| v(t[0]).dot(&v(t[1]).cross(&v(t[2]))))
            .sum()
    }

    /// Reverses the winding of every triangle.
    pub fn flip(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }
}
