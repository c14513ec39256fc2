//! The `.rrd` of every bundled arm scenario (`armsim run SCENARIO --rerun FILE`), read back
//! with armsim's test reader of `.rrd` files (tests/common/rrd.rs): a mesh or primitive
//! archetype for every link that has a visual (the skeleton for a DH table, which has
//! none), an entity for every obstacle of the scenario file, drawn once and labelled with
//! its name, and a blueprint with a 3-D view framed from outside the robot. Needs the
//! `rerun` feature (on by default).
#![cfg(feature = "rerun")]

mod common;

use armsim::io::record::rerun::rerun_out::{link_entity, path, RerunSink};
use armsim::scenarios::arm::{self, RunOptions};
use common::rrd::decode;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The archetypes a visual can be drawn with.
const GEOMETRY: [&str; 5] = [
    "Mesh3D:vertex_positions",
    "Boxes3D:half_sizes",
    "Cylinders3D:lengths",
    "Capsules3D:lengths",
    "Ellipsoids3D:half_sizes",
];

/// The `name = "…"` of every `[[obstacles]]` table of a scenario file, read line by line
/// (independently of armsim's scenario reader).
fn obstacle_names(text: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut inside = false;
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            inside = line.starts_with("[[obstacles]]");
            continue;
        }
        if let Some(v) = line.strip_prefix("name").map(str::trim) {
            if inside {
                if let Some(v) = v.strip_prefix('=') {
                    let v = v.split('#').next().unwrap().trim().trim_matches('"');
                    names.push(v.to_string());
                }
            }
        }
    }
    names
}

#[test]
fn every_bundled_arm_scenario_rrd_draws_its_links_obstacles_and_a_3d_view() {
    let dir = std::env::temp_dir().join(format!("armsim_rrd_scenarios_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut n = 0;
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().and_then(|x| x.to_str()) == Some("toml"))
        .collect();
    files.sort();
    for p in files {
        let text = std::fs::read_to_string(&p).unwrap();
        if text.lines().any(|l| l.trim_start().starts_with("kind =")) {
            continue;
        }
        let name = p.file_stem().unwrap().to_string_lossy().into_owned();
        let rrd = dir.join(format!("{name}.rrd"));
        let opts = RunOptions {
            write_files: false,
            rerun: Some(RerunSink::Save(rrd.clone())),
            ..Default::default()
        };
        let out = arm::run(&p, &text, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        let c = decode(&rrd);
        let drawn = |ent: &str| GEOMETRY.iter().any(|comp| c.has_static(ent, comp));
        // Every link with a visual has its geometry under `world/robot/<link>/visual_0`.
        let mut with_visual = 0;
        for l in out
            .scene
            .spec
            .links
            .iter()
            .filter(|l| !l.visuals.is_empty())
        {
            let e = format!("{}/visual_0", link_entity(&l.name));
            assert!(drawn(&e), "{name}: {e} not drawn");
            with_visual += 1;
        }
        if with_visual == 0 {
            // A DH table has no visuals: the robot is its skeleton, per frame.
            assert!(
                c.rows("/world/robot/skeleton", "LineStrips3D:strips") > 1,
                "{name}: nothing draws the robot"
            );
        } else {
            assert!(
                with_visual >= 3,
                "{name}: {with_visual} links with a visual"
            );
        }
        // Meshes where the model names meshes (the bundled robots all do).
        let meshes = c
            .mesh_vertices
            .keys()
            .filter(|e| e.starts_with("/world/robot/"))
            .count();
        assert!(meshes >= with_visual, "{name}: {meshes} robot meshes");
        // Every obstacle of the file is an entity with geometry.
        let obstacles = obstacle_names(&text);
        assert_eq!(obstacles.len(), out.scene.obstacles.len(), "{name}");
        // Each once, labelled with its name: from the recording's obstacle markers
        // (`world/obstacles/<name>/shape_<k>`), not a second time from the scene.
        for o in &obstacles {
            let e = path(&["world", "obstacles", o]).to_string();
            let shapes: Vec<&String> = c
                .entities
                .iter()
                .filter(|x| x.starts_with(&format!("{e}/shape_")) && drawn(x))
                .collect();
            assert!(!shapes.is_empty(), "{name}: obstacle {e} not drawn");
            assert!(!drawn(&e), "{name}: obstacle {e} drawn twice");
            let labelled = shapes
                .iter()
                .any(|x| c.labels.get(*x).is_some_and(|l| l.contains(o)));
            assert!(labelled, "{name}: obstacle {e} without its name");
        }
        // A blueprint with a 3-D view on `/world`, its eye outside the link origins' box.
        assert!(
            c.view_classes.iter().any(|v| v == "3D"),
            "{name}: {:?}",
            c.view_classes
        );
        let (eye, target) = c.eye.unwrap_or_else(|| panic!("{name}: no eye"));
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for (t, _) in c.poses.values().flatten() {
            for k in 0..3 {
                lo[k] = lo[k].min(t[k]);
                hi[k] = hi[k].max(t[k]);
            }
        }
        assert!(
            (0..3).any(|k| eye[k] < lo[k] - 0.2 || eye[k] > hi[k] + 0.2),
            "{name}: eye {eye:?} inside {lo:?}–{hi:?}"
        );
        assert!(
            (0..3).all(|k| target[k] > lo[k] - 0.5 && target[k] < hi[k] + 0.5),
            "{name}: target {target:?} off {lo:?}–{hi:?}"
        );
        n += 1;
    }
    assert!(n >= 4, "{n} arm scenarios");
    let _ = std::fs::remove_dir_all(&dir);
}
