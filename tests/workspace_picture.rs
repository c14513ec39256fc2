//! The geometry of the workspace picture (src/recording/workspace_picture.rs) on a
//! workspace whose shape is known exactly: the Cartesian P-P-P robot reaches the box
//! x ∈ [0, 1], y ∈ [0, 0.8], z ∈ [0.2, 0.7] (robots/textbook_cartesian_ppp.toml), whose
//! faces lie on the planes of a 0.1 m voxel lattice, with manipulability 1 everywhere
//! (its tool Jacobian is the identity).

mod common;

use armsim::core::spatial::Vec3;
use armsim::workspace::picture_geometry::{
    base_axis, representative_pose, Cutaway, Occupancy, Section,
};
use armsim::workspace::{sample_workspace, WorkspaceOptions};
use std::collections::HashMap;

const H: f64 = 0.1;
const LO: [f64; 3] = [0.0, 0.0, 0.2];
const HI: [f64; 3] = [1.0, 0.8, 0.7];
/// Cells per axis of the box.
const N: [usize; 3] = [10, 8, 5];

fn box_workspace() -> (armsim::model::Model, armsim::workspace::WorkspaceResult) {
    let model = common::load("robots/textbook_cartesian_ppp.toml");
    let ws = sample_workspace(
        &model,
        &WorkspaceOptions {
            samples: 1 << 17,
            replicates: 2,
            voxel: H,
            extras: true,
            keep_points: 1000,
            quiet: true,
            ..Default::default()
        },
    )
    .unwrap();
    (model, ws)
}

/// Distance from `p` (inside the box) to the box's surface.
fn depth(p: [f32; 3]) -> f64 {
    (0..3)
        .map(|k| (p[k] as f64 - LO[k]).min(HI[k] - p[k] as f64))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn box_boundary_is_a_closed_outward_surface_on_the_voxel_faces() {
    let (_, ws) = box_workspace();
    let occ = Occupancy::from_workspace(&ws).expect("a 3-D workspace");
    assert_eq!(occ.count(), N[0] * N[1] * N[2]);
    let mesh = occ.boundary_mesh();
    // One vertex per dual cube that straddles the surface: the (n+1)³ cubes around the
    // box minus the (n−1)³ inside it; two triangles per exposed voxel face.
    let [a, b, c] = N;
    assert_eq!(
        mesh.vertices.len(),
        (a + 1) * (b + 1) * (c + 1) - (a - 1) * (b - 1) * (c - 1)
    );
    assert_eq!(mesh.triangles.len(), 2 * 2 * (a * b + b * c + a * c));
    // Vertices lie in the box, on its faces (the mean of midpoints between an occupied
    // and an empty voxel centre, which are on the faces), inset by h/4 along the edges
    // and h/3 at the corners.
    let mut on_face = 0;
    for &v in &mesh.vertices {
        for k in 0..3 {
            assert!(
                v[k] as f64 >= LO[k] - 1e-6 && v[k] as f64 <= HI[k] + 1e-6,
                "{v:?}"
            );
        }
        let d = depth(v);
        assert!(d <= H / 3.0 + 1e-6, "{v:?} is {d} m inside");
        if d < 1e-6 {
            on_face += 1;
        }
    }
    let faces = 2 * ((a - 1) * (b - 1) + (b - 1) * (c - 1) + (a - 1) * (c - 1));
    assert_eq!(on_face, faces);
    // Closed and consistently oriented: every directed edge once, its reverse once.
    let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(i, j), &n) in &edges {
        assert_eq!(n, 1, "edge {i}–{j} used {n} times");
        assert_eq!(edges.get(&(j, i)), Some(&1), "edge {i}–{j} has no twin");
    }
    // Outward: the enclosed volume (divergence theorem) is the box's, less the chamfer
    // of h²/4 per unit length along its 9.2 m of edges (less still at the corners).
    let p = |i: u32| {
        let v = mesh.vertices[i as usize];
        Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
    };
    let vol: f64 = mesh
        .triangles
        .iter()
        .map(|t| p(t[0]).dot(&p(t[1]).cross(&p(t[2]))) / 6.0)
        .sum();
    let expected = 0.4 - 9.2 * H * H / 4.0;
    assert!(
        (vol - expected).abs() < 8.0 * H.powi(3),
        "{vol} vs {expected}"
    );
    // Manipulability of a Cartesian robot: 1 in every voxel.
    assert!(mesh.values.iter().all(|v| (v - 1.0).abs() < 1e-6));
}

/// Area of a mesh whose triangles all face `-axis`.
fn area_facing_negative(m: &armsim::workspace::picture_geometry::ScalarMesh, axis: usize) -> f64 {
    let v = |i: u32| {
        let q = m.vertices[i as usize];
        Vec3::new(q[0] as f64, q[1] as f64, q[2] as f64)
    };
    m.triangles
        .iter()
        .map(|t| {
            let n = (v(t[1]) - v(t[0])).cross(&(v(t[2]) - v(t[0])));
            assert!(n[axis] < 0.0, "{n:?} does not face -{axis}");
            0.5 * n.norm()
        })
        .sum()
}

#[test]
fn box_sections_and_cutaway_are_the_voxel_layers_of_their_planes() {
    let (model, ws) = box_workspace();
    let occ = Occupancy::from_workspace(&ws).unwrap();
    // The layer y ∈ [0.3, 0.4) cut at x < 0.5: 5 × 5 squares of 0.01 m², in y = 0.35.
    let s = Section { axis: 1, at: 0.35 };
    let cut = occ.section_mesh(s, true, Some((0, 0.5)));
    assert_eq!(cut.triangles.len(), 2 * 25);
    assert!(cut.vertices.iter().all(|v| (v[1] - 0.35).abs() < 1e-7));
    assert!(cut.vertices.iter().all(|v| v[0] <= 0.5 + 1e-6));
    assert!((area_facing_negative(&cut, 1) - 0.25).abs() < 1e-6);
    // A vertical cut-away at (0.5, 0.4): the section is x = 0.5 for y < 0.4 (4 × 5
    // voxels) and y = 0.4 for x < 0.5 (5 × 5); the quarter's boundary faces are those with
    // a centroid in x < 0.5, y < 0.4.
    let c = Cutaway::new(Vec3::new(0.5, 0.4, 0.0), &Vec3::z());
    assert_eq!((c.along, c.across), (2, [0, 1]));
    let sec = occ.cutaway_section(&c);
    assert_eq!(sec.triangles.len(), 2 * (20 + 25));
    let on_x = sec
        .vertices
        .iter()
        .filter(|v| (v[0] - 0.5).abs() < 1e-7)
        .count();
    let on_y = sec
        .vertices
        .iter()
        .filter(|v| (v[1] - 0.4).abs() < 1e-7)
        .count();
    assert_eq!(
        (on_x, on_y),
        (4 * 20 + 2 * 5, 4 * 25 + 2 * 5),
        "shared edge at x = 0.5, y = 0.4"
    );
    let mesh = occ.boundary_mesh();
    let (removed, kept) = mesh.cut(&c);
    assert_eq!(
        removed.triangles.len() + kept.triangles.len(),
        mesh.triangles.len()
    );
    for (m, inside) in [(&removed, true), (&kept, false)] {
        for t in &m.triangles {
            let g: [f64; 3] = std::array::from_fn(|k| {
                t.iter()
                    .map(|&i| m.vertices[i as usize][k] as f64)
                    .sum::<f64>()
                    / 3.0
            });
            assert_eq!(g[0] < 0.5 && g[1] < 0.4, inside, "{g:?}");
        }
    }
    // The P-P-P's first joint slides along world x from the base at y = 0, z = 0.2: the
    // box lies at y ≥ 0, z ≥ 0.2, so nothing is in the quarter y < 0, z < 0.2 and no pose
    // qualifies as representative there.
    let (base, axis) = base_axis(&model, &ws.tool).unwrap();
    assert!((axis - Vec3::x()).norm() < 1e-12, "{axis:?}");
    let real = Cutaway::new(base, &axis);
    assert_eq!((real.along, real.across), (0, [1, 2]));
    assert!(occ.cutaway_section(&real).triangles.is_empty());
    assert!(representative_pose(&model, &ws, &real).is_none());
}

#[test]
fn coarsened_box_is_the_box_on_cells_twice_as_large() {
    let (_, ws) = box_workspace();
    let occ = Occupancy::from_workspace(&ws).unwrap();
    // A solid box has no holes.
    assert_eq!(occ.hole_fraction(), 0.0);
    let c = occ.coarsened();
    assert_eq!(c.h, 2.0 * H);
    // x ∈ [0, 1]: cells 0–4 of 0.2 m; y ∈ [0, 0.8]: 0–3; z ∈ [0.2, 0.7]: [0.2, 0.4) to
    // [0.6, 0.8), 1–3.
    assert_eq!(c.count(), 5 * 4 * 3);
    for (k, &o) in c.occupied.iter().enumerate() {
        let l = [k % c.n[0], (k / c.n[0]) % c.n[1], k / (c.n[0] * c.n[1])];
        let g: Vec<i64> = (0..3).map(|a| c.i0[a] + l[a] as i64).collect();
        let inside = (0..5).contains(&g[0]) && (0..4).contains(&g[1]) && (1..4).contains(&g[2]);
        assert_eq!(o, inside, "{g:?}");
        if o {
            assert!((c.value[k] - 1.0).abs() < 1e-6);
        }
    }
    // Its surface is closed: 2 triangles per exposed face of 5 × 4 × 3 cells.
    assert_eq!(
        c.boundary_mesh().triangles.len(),
        4 * (5 * 4 + 4 * 3 + 5 * 3)
    );
}
