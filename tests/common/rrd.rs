//! Armsim's reader of `.rrd` files for the tests: decodes a file with the rerun crate's
//! own decoder and collects, per entity, what the checks need (row counts, static mesh
//! vertices and half sizes, poses, labels) and, from the blueprint, the views, their
//! queries, the 3-D view's eye and the entities a view hides.

use rerun::components::{HalfSize3D, Position3D, RotationQuat, Translation3D};
use rerun::external::re_log_encoding::rrd::DecoderApp;
use rerun::log::{Chunk, LogMsg};
use rerun::StoreKind;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A logged pose: translation and rotation `[x, y, z, w]`.
pub type Pose = ([f32; 3], [f32; 4]);

/// What an .rrd holds: per (entity, component) the temporal and static row counts.
#[derive(Default)]
pub struct Contents {
    pub temporal: BTreeMap<(String, String), usize>,
    pub statics: BTreeMap<(String, String), usize>,
    pub entities: BTreeSet<String>,
    pub blueprint_msgs: usize,
    /// The 3-D view's eye: position and look target, from the blueprint.
    pub eye: Option<([f32; 3], [f32; 3])>,
    /// Query expressions of the blueprint's views.
    pub view_queries: Vec<String>,
    /// Class identifiers of the blueprint's views (`3D`, `TimeSeries`, …).
    pub view_classes: Vec<String>,
    /// Entities a view hides (blueprint `EntityBehavior:visible` false).
    pub invisible: BTreeSet<String>,
    /// Static labels per entity.
    pub labels: BTreeMap<String, Vec<String>>,
    pub timelines: BTreeSet<String>,
    /// Static mesh vertex positions per entity.
    pub mesh_vertices: BTreeMap<String, Vec<[f32; 3]>>,
    /// Static half sizes of boxes and ellipsoids per entity.
    pub half_sizes: BTreeMap<String, Vec<[f32; 3]>>,
    /// Temporal transforms per entity, in row order: translation and `[x, y, z, w]`.
    pub poses: BTreeMap<String, Vec<Pose>>,
}

impl Contents {
    pub fn rows(&self, entity: &str, component: &str) -> usize {
        self.temporal
            .get(&(entity.to_string(), component.to_string()))
            .copied()
            .unwrap_or(0)
    }
    pub fn has_static(&self, entity: &str, component: &str) -> bool {
        self.statics
            .contains_key(&(entity.to_string(), component.to_string()))
    }
}

pub fn decode(p: &Path) -> Contents {
    let bytes = std::fs::read(p).unwrap();
    assert!(
        bytes.len() > 1000,
        "{}: only {} bytes",
        p.display(),
        bytes.len()
    );
    assert_eq!(&bytes[..4], b"RRF2", "rrd magic");
    let msgs: Vec<LogMsg> = DecoderApp::decode_eager(std::io::BufReader::new(&bytes[..]))
        .unwrap()
        .collect::<Result<_, _>>()
        .unwrap();
    let mut c = Contents::default();
    for m in msgs {
        let LogMsg::ArrowMsg(store, arrow) = m else {
            continue;
        };
        let chunk = Chunk::from_arrow_msg(&arrow).unwrap();
        if store.kind() == StoreKind::Blueprint {
            c.blueprint_msgs += 1;
            let pos = chunk
                .iter_component::<Position3D>("EyeControls3D:position".into())
                .next();
            let target = chunk
                .iter_component::<Position3D>("EyeControls3D:look_target".into())
                .next();
            if let (Some(p), Some(t)) = (pos, target) {
                c.eye = Some((p[0].0 .0, t[0].0 .0));
            }
            for q in chunk.iter_component::<rerun::blueprint::components::QueryExpression>(
                "ViewContents:query".into(),
            ) {
                c.view_queries.extend(q.iter().map(|e| e.0.to_string()));
            }
            for v in chunk.iter_component::<rerun::blueprint::components::ViewClass>(
                "ViewBlueprint:class_identifier".into(),
            ) {
                c.view_classes.extend(v.iter().map(|e| e.0.to_string()));
            }
            // view/<id>/ViewContents/overrides/<entity>/visualizers
            let at = chunk.entity_path().to_string();
            for v in
                chunk.iter_component::<rerun::components::Visible>("EntityBehavior:visible".into())
            {
                if let Some(ent) = at.split("/overrides").nth(1) {
                    if v.iter().any(|b| !b.0 .0) {
                        c.invisible
                            .insert(ent.trim_end_matches("/visualizers").to_string());
                    }
                }
            }
            continue;
        }
        let ent = chunk.entity_path().to_string();
        c.entities.insert(ent.clone());
        for tl in chunk.timelines().keys() {
            c.timelines.insert(tl.as_str().to_string());
        }
        if chunk.is_static() {
            for row in chunk.iter_component::<Position3D>("Mesh3D:vertex_positions".into()) {
                let v = c.mesh_vertices.entry(ent.clone()).or_default();
                v.extend(row.iter().map(|p| p.0 .0));
            }
            for comp in ["Points3D:labels", "Boxes3D:labels"] {
                for row in chunk.iter_component::<rerun::components::Text>(comp.into()) {
                    let v = c.labels.entry(ent.clone()).or_default();
                    v.extend(row.iter().map(|t| t.0.to_string()));
                }
            }
            for comp in ["Boxes3D:half_sizes", "Ellipsoids3D:half_sizes"] {
                for row in chunk.iter_component::<HalfSize3D>(comp.into()) {
                    let v = c.half_sizes.entry(ent.clone()).or_default();
                    v.extend(row.iter().map(|h| h.0 .0));
                }
            }
        } else {
            let tr = chunk.iter_component::<Translation3D>("Transform3D:translation".into());
            let qs = chunk.iter_component::<RotationQuat>("Transform3D:quaternion".into());
            for (t, q) in tr.zip(qs) {
                c.poses
                    .entry(ent.clone())
                    .or_default()
                    .push((t[0].0 .0, q[0].0 .0));
            }
        }
        for d in chunk.component_descriptors() {
            let key = (ent.clone(), d.component.as_str().to_string());
            if chunk.is_static() {
                *c.statics.entry(key).or_default() += chunk.num_rows();
            } else {
                *c.temporal.entry(key).or_default() += chunk.num_rows();
            }
        }
    }
    c
}
