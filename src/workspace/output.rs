//! CSV output of a workspace run, written atomically ([`crate::core::files::write_atomic`]): the
//! kept sample points, and the occupied voxels with their flags and Jacobian statistics.

use crate::workspace::grid::set_bits;
use crate::workspace::WorkspaceResult;
use std::fmt::Write as _;
use std::path::Path;

impl WorkspaceResult {
    /// The kept sample points as CSV: one column per joint (in [`Self::joint_names`]
    /// order), then `x, y, z` (m, world), `manipulability`, `condition`. Empty (header
    /// only) unless [`crate::workspace::WorkspaceOptions::keep_points`] was set.
    pub fn points_csv(&self) -> String {
        let mut s = String::new();
        for n in &self.joint_names {
            let _ = write!(s, "{n},");
        }
        s.push_str("x,y,z,manipulability,condition\n");
        for p in &self.points {
            for q in &p.q {
                let _ = write!(s, "{q},");
            }
            let _ = writeln!(
                s,
                "{},{},{},{},{}",
                p.p[0], p.p[1], p.p[2], p.manipulability, p.condition
            );
        }
        s
    }

    /// Writes [`Self::points_csv`] to `path` atomically.
    pub fn write_points_csv(&self, path: &Path) -> std::io::Result<()> {
        crate::core::files::write_atomic(path, self.points_csv().as_bytes())
    }

    /// Every occupied voxel (pixel) of the pooled occupancy as CSV: global index
    /// `i, j, k`, centre `x, y, z` (m, world), `boundary` (0/1), then the Jacobian-pass
    /// statistics (empty when no Jacobian-pass sample fell in the voxel): `samples`,
    /// `manipulability_mean, _min, _max`, `condition_mean, _min, _max`, `orientations`,
    /// `dexterous` (0/1).
    pub fn voxels_csv(&self) -> String {
        let mut s = String::from(
            "i,j,k,x,y,z,boundary,samples,manipulability_mean,manipulability_min,\
             manipulability_max,condition_mean,condition_min,condition_max,orientations,dexterous\n",
        );
        let mut stats = self.voxels.iter().peekable();
        for cell in set_bits(&self.union) {
            let g = self.grid.global(cell);
            let c = self.grid.center(cell);
            let b = crate::workspace::grid::Grid::test(&self.boundary_bits, cell);
            let _ = write!(
                s,
                "{},{},{},{},{},{},{}",
                g[0], g[1], g[2], c.x, c.y, c.z, b as u8
            );
            let key = |v: &[i64; 3]| (v[2], v[1], v[0]);
            while stats.peek().is_some_and(|v| key(&v.index) < key(&g)) {
                stats.next();
            }
            match stats.peek() {
                Some(v) if v.index == g => {
                    let _ = writeln!(
                        s,
                        ",{},{},{},{},{},{},{},{},{}",
                        v.samples,
                        v.manipulability_mean,
                        v.manipulability_min,
                        v.manipulability_max,
                        v.condition_mean,
                        v.condition_min,
                        v.condition_max,
                        v.orientations,
                        v.dexterous as u8
                    );
                }
                _ => s.push_str(",,,,,,,,,\n"),
            }
        }
        s
    }

    /// Writes [`Self::voxels_csv`] to `path` atomically.
    pub fn write_voxels_csv(&self, path: &Path) -> std::io::Result<()> {
        crate::core::files::write_atomic(path, self.voxels_csv().as_bytes())
    }
}

/// The text summary of a run's measure: headline, interval (or lower bound and the
/// samples needed), the voxel-bias and under-sampling terms.
pub fn summary_lines(r: &WorkspaceResult) -> Vec<String> {
    let (what, unit) = if r.planar {
        ("area", "m²")
    } else {
        ("volume", "m³")
    };
    let e = &r.estimate;
    let mut out = Vec::new();
    match e.interval {
        [Some(lo), Some(hi)] => out.push(format!(
            "{what}: {:.4} {unit}, 95 % interval [{lo:.4}, {hi:.4}] (±{:.2} %)",
            e.measure,
            100.0 * e.rel_half_width()
        )),
        [lo, _] => out.push(format!(
            "{what}: lower bound {:.4} {unit}, estimate {:.4} (too few samples for an interval: {:.1} % of the closed voxels unhit; about {} samples needed)",
            lo.unwrap_or(0.0),
            e.measure,
            100.0 * e.unhit_fraction,
            e.samples_needed.unwrap_or(0)
        )),
    }
    out.push(format!(
        "pooled occupancy {:.4} {unit}, closed and voxel-bias corrected {:.4} (voxel-size bias {:.4}, replicate spread {:.4}), slivers still to come {}",
        e.raw,
        e.corrected,
        e.voxel_bias,
        e.stderr,
        e.remaining
            .map_or("unknown".to_string(), |g| format!("about {g:.4}"))
    ));
    if let (Some(d), Some(x)) = (r.dexterous_interval, &r.extras) {
        out.push(format!(
            "dexterous {what}: ≥ {:.4} {unit} ({} voxels reach {} of {} orientation bins; a lower bound)",
            d[0].unwrap_or(0.0),
            x.dexterous_voxels,
            x.dexterous_min_bins,
            x.orientation_bins
        ));
    }
    out
}
