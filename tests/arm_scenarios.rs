//! Arm scenarios end to end (`armsim run`), checked against independent references:
//!
//! - the torque check against a recomputation by plain RNEA on a model whose tool link
//!   carries the payload, plus the friction law written out here, at sampled points, and
//!   its violations flagged at exactly the samples where the recomputation exceeds;
//! - a left-out effect is never run (effect counters, the contact pipeline never built);
//! - the time-optimal plan meets every limit and beats the trapezoidal one;
//! - a planted obstacle is hit by the right link: the skeleton capsule at the analytic
//!   time, the real wrist mesh at a contact confirmed triangle by triangle;
//! - the contact scene's sliding force equals Coulomb's μ m g;
//! - every bundled scenario runs, and broken ones give `file:line: key: message` errors.

mod common;

use armsim::core::spatial::{Inertia, Mat3, Vec3};
use armsim::dynamics::rnea;
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::motion::Trajectory;
use armsim::scenarios::arm::{self, RunOptions};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn no_files() -> RunOptions {
    RunOptions {
        write_files: false,
        ..Default::default()
    }
}

/// Runs scenario text as if it were the file `scenarios/<name>.toml`.
fn run_text(name: &str, text: &str) -> arm::Outcome {
    let path = root().join("scenarios").join(format!("{name}.toml"));
    arm::run(&path, text, &no_files()).unwrap_or_else(|e| panic!("{e}"))
}

fn bundled(name: &str) -> String {
    std::fs::read_to_string(root().join("scenarios").join(format!("{name}.toml"))).unwrap()
}

fn cli(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_armsim"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("run armsim")
}

/// The UR5 model with the payload merged into `tool0`'s inertia (an independent route to
/// the payload torques: no `Effects`, no payload code path).
fn ur5_with_payload(mass: f64, com: [f64; 3]) -> Model {
    let mut spec = Model::read_spec(&root().join("robots/ur5.urdf")).unwrap();
    let link = spec.links.iter_mut().find(|l| l.name == "tool0").unwrap();
    let p = Inertia::new(mass, Vec3::new(com[0], com[1], com[2]), Mat3::zeros());
    let a = link.inertial;
    let m = a.mass + p.mass;
    let c = (a.com * a.mass + p.com * p.mass) / m;
    let shift = |i: &Inertia| {
        let d = i.com - c;
        i.inertia_com + i.mass * (Mat3::identity() * d.dot(&d) - d * d.transpose())
    };
    link.inertial = Inertia::new(m, c, shift(&a) + shift(&p));
    Model::build(spec).unwrap().0
}

/// Viscous + Coulomb/Stribeck law as documented (`Friction::torque`), written out.
fn friction(v: f64, b: f64, fc: f64) -> f64 {
    let (fs, vs, eps) = (fc, 0.1, 1e-3);
    let r = v / vs;
    b * v + (fc + (fs - fc) * (-r * r).exp()) * (v / eps).tanh()
}

#[test]
fn torque_check_agrees_with_an_independent_rnea_recomputation() {
    // The bundled pick-and-place carries its 1.5 kg part only between the pick and the
    // place: before and after, the reference is the bare UR5; in between, the UR5 with
    // the part merged into tool0.
    let out = run_text("ur5_pick_and_place", &bundled("ur5_pick_and_place"));
    let (attach, detach) = out.plan.carry.expect("the task grasps a part");
    assert!(attach > 0.5 && detach > attach + 1.0, "{attach} {detach}");
    let loaded = ur5_with_payload(1.5, [0.0, 0.0, 0.06]);
    let bare = Model::build(Model::read_spec(&root().join("robots/ur5.urdf")).unwrap())
        .unwrap()
        .0;
    let mut data = Data::new(&loaded);
    let viscous = [2.0, 2.0, 1.5, 0.5, 0.5, 0.5];
    let coulomb = [3.0, 3.0, 2.0, 1.0, 1.0, 1.0];
    let g = Vec3::new(0.0, 0.0, -9.81);
    assert_eq!((loaded.gravity, bare.gravity), (g, g));
    let traj = &out.plan.trajectory;
    let rep = &out.torque;
    let n = 6;
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    let (mut before, mut during, mut after) = (0, 0, 0);
    for k in (0..rep.t.len()).step_by(23) {
        let t = rep.t[k];
        traj.sample(t, &mut q, &mut qd, &mut qdd);
        let carrying = t >= attach && t <= detach;
        let model = if carrying { &loaded } else { &bare };
        match (t < attach, carrying) {
            (true, _) => before += 1,
            (_, true) => during += 1,
            _ => after += 1,
        }
        let tau = rnea(model, &mut data, &q, &qd, &qdd).to_vec();
        for j in 0..n {
            let expect = tau[j] + friction(qd[j], viscous[j], coulomb[j]);
            worst = worst.max((expect - rep.torque(k, j)).abs());
        }
        checked += 1;
    }
    assert!(
        before > 20 && during > 20 && after > 20,
        "{before} {during} {after}"
    );
    // The part's weight is felt: at a held pose inside the window the shoulder-lift
    // torque differs from the bare arm's by about m g × lever arm (> 1 N m here).
    let k = rep.t.iter().position(|&t| t > attach + 1e-3).unwrap();
    traj.sample(rep.t[k], &mut q, &mut qd, &mut qdd);
    let with = rnea(&loaded, &mut data, &q, &qd, &qdd)[1];
    let without = rnea(&bare, &mut data, &q, &qd, &qdd)[1];
    assert!((with - without).abs() > 1.0, "{with} {without}");
    assert!(checked > 300, "{checked} samples");
    assert!(worst < 1e-9, "largest torque difference {worst:e} N m");
    // The JSON rows carry the same peaks.
    let rows = out.report.json["torque_check"].as_array().unwrap();
    for (r, j) in rows.iter().zip(&rep.joints) {
        assert_eq!(r["joint"], j.joint.as_str());
        assert_eq!(r["peak_torque"].as_f64().unwrap(), j.peak_torque);
        for key in ["rms_torque", "peak_speed", "limit", "margin", "ok"] {
            assert!(!r[key].is_null(), "{key}");
        }
    }
}

#[test]
fn violations_are_flagged_exactly_where_the_recomputation_exceeds() {
    let text = bundled("panda_payload_sweep");
    let out = run_text("panda_payload_sweep", &text);
    // The nominal case is the heaviest payload of the sweep (6 kg) and it violates.
    assert!(!out.torque.ok);
    let mut spec = Model::read_spec(&root().join("robots/panda.urdf")).unwrap();
    let tcp = spec
        .links
        .iter_mut()
        .find(|l| l.name == "panda_hand_tcp")
        .unwrap();
    assert_eq!(tcp.inertial.mass, 0.0, "the TCP frame is massless");
    tcp.inertial = Inertia::new(
        6.0,
        Vec3::new(0.0, 0.0, 0.05),
        Mat3::from_diagonal_element(0.004),
    );
    let model = Model::build(spec).unwrap().0;
    let mut data = Data::new(&model);
    assert_eq!(model.gravity, Vec3::new(0.0, 0.0, -9.81));
    let n = model.nv;
    let rep = &out.torque;
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut first: Vec<Option<usize>> = vec![None; n];
    for (k, &t) in rep.t.iter().enumerate() {
        out.plan.trajectory.sample(t, &mut q, &mut qd, &mut qdd);
        let tau = rnea(&model, &mut data, &q, &qd, &qdd);
        for j in 0..n {
            assert!((tau[j] - rep.torque(k, j)).abs() < 1e-9);
            if first[j].is_none() && tau[j].abs() > model.effort_limit[j] {
                first[j] = Some(k);
            }
        }
    }
    let mut violating = 0;
    for (j, row) in rep.joints.iter().enumerate() {
        match (first[j], row.first_torque_violation_s) {
            (None, None) => {}
            (Some(k), Some(t)) => {
                violating += 1;
                assert!(k > 0, "{}", row.joint);
                assert!(
                    rep.t[k - 1] < t && t <= rep.t[k],
                    "{}: flagged at {t}, recomputation crosses in ({}, {}]",
                    row.joint,
                    rep.t[k - 1],
                    rep.t[k]
                );
            }
            (a, b) => panic!("{}: recomputation {a:?}, check {b:?}", row.joint),
        }
    }
    assert!(violating >= 1);
    // The sweep: every peak torque grows with the payload, and the verdict turns once.
    let sweep = out.report.json["payload_sweep"].as_array().unwrap();
    assert_eq!(sweep.len(), 7);
    let oks: Vec<bool> = sweep.iter().map(|r| r["ok"].as_bool().unwrap()).collect();
    assert!(oks[0] && !oks[6], "{oks:?}");
    let turn = oks.iter().position(|o| !o).unwrap();
    assert!(oks[turn..].iter().all(|o| !o), "{oks:?}");
    let peak = |r: &serde_json::Value, j: &str| r["peak_torque"][j].as_f64().unwrap();
    for w in sweep.windows(2) {
        assert!(peak(&w[1], "panda_joint2") > peak(&w[0], "panda_joint2"));
    }
}

#[test]
fn left_out_effects_are_never_run_and_contact_is_built_only_when_named() {
    let out = run_text("ur5_pick_and_place", &bundled("ur5_pick_and_place"));
    let runs = out.effect_runs.unwrap();
    assert!(runs.gravity > 0 && runs.friction > 0 && runs.payload > 0);
    assert_eq!((runs.rotor, runs.elasticity, runs.external), (0, 0, 0));
    assert!(!out.contact_built);
    assert_eq!(out.report.json["contact_pipeline_built"], false);
    assert!(out.report.json["contact"].is_null());
    // The same scene without friction: friction code never runs.
    let text = bundled("ur5_pick_and_place").replace(
        "effects = [\"gravity\", \"friction\", \"payload\"]",
        "effects = [\"gravity\", \"payload\"]",
    );
    let out = run_text("ur5_pick_and_place", &text);
    let runs = out.effect_runs.unwrap();
    assert_eq!(runs.friction, 0);
    assert!(out.report.json["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("[friction] is given")));
    // Naming contact builds it, and its wrenches reach the plant.
    let out = run_text("ur5_push_box", &bundled("ur5_push_box"));
    assert!(out.contact_built);
    assert!(out.effect_runs.unwrap().external > 0);
}

#[test]
fn pushed_box_slides_with_the_coulomb_force() {
    let out = run_text("ur5_push_box", &bundled("ur5_push_box"));
    let c = out.contact.unwrap();
    // mu = 0.4 (table and box), m = 1 kg, g = 9.81.
    assert!((c.coulomb_force_n - 0.4 * 9.81).abs() < 1e-12);
    let f = c.sliding_force_n.expect("steady sliding phase");
    assert!(
        (f - c.coulomb_force_n).abs() < 0.05 * c.coulomb_force_n,
        "sliding push {f} N vs mu m g {} N",
        c.coulomb_force_n
    );
    // The pusher (r = 3 cm) goes from x = 0.32 to 0.62; the box face starts at 0.45:
    // pushed 0.62 + 0.03 - 0.45 = 0.20 m, less what it falls behind while decelerating.
    assert!(
        c.box_displacement_m > 0.17 && c.box_displacement_m < 0.205,
        "{}",
        c.box_displacement_m
    );
    assert!(
        (c.box_end[2] - 0.05).abs() < 2e-3,
        "the box stays on the table"
    );
    assert!(c.box_end[0] > c.box_start[0], "pushed along +x");
}

#[test]
fn time_optimal_plan_meets_the_limits_and_beats_the_trapezoid() {
    let text = bundled("planar_2r");
    let topp = run_text("planar_2r", &text);
    let trap = run_text(
        "planar_2r",
        &text.replace("type = \"time_optimal\"", "type = \"trapezoidal\""),
    );
    let (vel, eff) = (3.0, [30.0, 10.0]);
    for (j, row) in topp.torque.joints.iter().enumerate() {
        assert!(row.peak_speed <= vel * (1.0 + 1e-6), "{}", row.peak_speed);
        assert!(
            row.peak_torque <= eff[j] * (1.0 + 1e-6),
            "{}",
            row.peak_torque
        );
    }
    let (t1, t2) = (
        topp.plan.trajectory.duration(),
        trap.plan.trajectory.duration(),
    );
    assert!(t1 < t2, "time-optimal {t1} s vs trapezoidal {t2} s");
}

/// The planted-obstacle scenario on the UR5 model file `model` (absolute or relative to
/// `scenarios/`): the tool (pointing down) moves along x from 0.3 to 0.6 m at z = 0.3,
/// toward a sphere of radius 0.03 at x = 0.5.
fn planted_text(model: &str) -> String {
    format!(
        r#"
name = "planted"
effects = []
[model]
file = "{model}"
tool = "tool0"
[initial]
q = [0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0]
[[obstacles]]
name = "ball"
shape = "sphere"
radius = 0.03
xyz = [0.5, 0.1, 0.3]
[collision]
skeleton_radius = 0.04
[task]
type = "sequence"
steps = [
  {{ line = {{ xyz = [0.3, 0.1, 0.3], rpy = [3.14159265358979, 0.0, -1.5707963267949] }} }},
  {{ line = {{ xyz = [0.6, 0.1, 0.3], rpy = [3.14159265358979, 0.0, -1.5707963267949] }} }},
]
[trajectory]
line_samples = 201
[simulation]
enabled = false
"#
    )
}

#[test]
fn planted_obstacle_is_hit_by_the_wrist_capsule_at_the_analytic_time() {
    // The skeleton fallback: a copy of the UR5 whose meshes cannot be found. In this URDF
    // wrist_3_link and tool0 share their origin, so the skeleton capsule ending at the tool
    // point is wrist_2_link's (radius r = 0.04, rising vertically from it). The sphere is
    // first touched when x_tool = 0.5 − 0.07.
    let dir = std::env::temp_dir().join(format!("armsim-planted-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let urdf = dir.join("ur5_without_meshes.urdf");
    let text = std::fs::read_to_string(root().join("robots/ur5.urdf")).unwrap();
    std::fs::write(&urdf, text.replace("\"meshes/ur5/", "\"no_such_dir/ur5/")).unwrap();
    let out = run_text("planted", &planted_text(&urdf.display().to_string()));
    let _ = std::fs::remove_dir_all(&dir);
    let first = &out.report.json["collisions"]["first"];
    assert_eq!(first["pair"][0], "wrist_2_link", "{first}");
    assert_eq!(first["pair"][1], "ball");
    let line = &out.plan.pieces[1];
    assert_eq!(line.kind, "line");
    // x_tool(t) = 0.3 + 0.3 σ(u), σ(u) = 10u³ − 15u⁴ + 6u⁵: solve σ(u) = 0.13 / 0.3.
    let target = 0.13 / 0.3;
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..100 {
        let u = 0.5 * (lo + hi);
        let s = u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
        if s < target {
            lo = u;
        } else {
            hi = u;
        }
    }
    let t = line.start_s + lo * line.duration_s;
    let found = first["time"].as_f64().unwrap();
    assert!((found - t).abs() < 2e-3, "found {found} s, analytic {t} s");
    assert_eq!(out.report.json["ok"], false);
}

/// Closest point of triangle `abc` to `p` (Ericson, Real-Time Collision Detection 5.1.5).
fn closest_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

#[test]
fn planted_obstacle_is_hit_by_the_wrist_3_mesh_at_a_true_contact() {
    // The same motion with the UR5's real collision meshes: the wrist_3 casing (a
    // cylinder of radius ~0.038 around the tool axis) reaches the ball first. At the
    // reported configuration the ball's distance to the mesh, computed here triangle by
    // triangle from the STL file, equals the reported depth.
    let out = run_text("planted", &planted_text("../robots/ur5.urdf"));
    let first = &out.report.json["collisions"]["first"];
    assert_eq!(first["pair"][0], "wrist_3_link", "{first}");
    assert_eq!(first["pair"][1], "ball");
    let model = &out.scene.model;
    let q: Vec<f64> = model
        .dof_names()
        .iter()
        .map(|n| first["q"][n].as_f64().unwrap())
        .collect();
    let mut d = Data::new(model);
    armsim::kinematics::forward_kinematics(model, &mut d, &q);
    let li = model.link_id("wrist_3_link").unwrap();
    let link = &model.links[li];
    let base = &out.scene.base;
    let pose = base
        .mul(&d.o_m_i[link.body])
        .mul(&link.offset)
        .mul(&link.collisions[0].origin);
    let b = std::fs::read(root().join("robots/meshes/ur5/collision/wrist3.stl")).unwrap();
    let n = u32::from_le_bytes(b[80..84].try_into().unwrap()) as usize;
    assert_eq!(b.len(), 84 + 50 * n);
    let f = |at: usize| f32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as f64;
    let vertex = |t: usize, k: usize| {
        let at = 84 + 50 * t + 12 + 12 * k;
        pose.act_point(&Vec3::new(f(at), f(at + 4), f(at + 8)))
    };
    let centre = Vec3::new(0.5, 0.1, 0.3);
    let dist = (0..n)
        .map(|t| {
            (closest_on_triangle(centre, vertex(t, 0), vertex(t, 1), vertex(t, 2)) - centre).norm()
        })
        .fold(f64::INFINITY, f64::min);
    let depth = first["depth"].as_f64().unwrap();
    assert!((0.0..1e-3).contains(&depth), "{first}");
    assert!(
        ((dist - 0.03) + depth).abs() < 1e-7,
        "ball centre to mesh {dist}, reported depth {depth}"
    );
    assert_eq!(out.report.json["ok"], false);
}

/// The `<mesh filename>` values of URDF text.
fn mesh_uris(urdf: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(urdf).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("mesh"))
        .map(|n| n.attribute("filename").unwrap().to_string())
        .collect()
}

/// The run's warnings about `package://ur5/` meshes.
fn mesh_warnings(out: &arm::Outcome) -> Vec<String> {
    out.report.json["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap().to_string())
        .filter(|w| w.contains("package://ur5/"))
        .collect()
}

/// How many meshes the scene's links name, each checked to be an absolute existing file.
fn absolute_mesh_files(out: &arm::Outcome, how: &str) -> usize {
    let mut n = 0;
    for l in &out.scene.spec.links {
        for g in l.visuals.iter().chain(&l.collisions) {
            if let armsim::model::Shape::Mesh { uri, .. } = &g.shape {
                let p = Path::new(uri);
                assert!(p.is_absolute() && p.is_file(), "{how}: {uri}");
                n += 1;
            }
        }
    }
    n
}

#[test]
fn package_uris_resolve_through_package_paths_and_the_mcap_names_absolute_files() {
    // The UR5 with its meshes named package://ur5/... : robots/meshes is a directory
    // containing the "package" ur5.
    let dir = std::env::temp_dir().join(format!("armsim_pkg_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let urdf = dir.join("arm.urdf");
    let text = std::fs::read_to_string(root().join("robots/ur5.urdf")).unwrap();
    std::fs::write(&urdf, text.replace("\"meshes/ur5/", "\"package://ur5/")).unwrap();
    let scenario = dir.join("arm.toml");
    let meshes = root().join("robots/meshes");
    let plain = planted_text(&urdf.display().to_string());
    let with_key = |p: &str| {
        plain.replace(
            "tool = \"tool0\"",
            &format!("tool = \"tool0\"\npackage_path = [\"{p}\"]"),
        )
    };

    // Nowhere to find the package: one warning per visual mesh, naming its URI; the
    // collision meshes fall back to skeleton capsules (and are named too).
    let out = arm::run(&scenario, &plain, &no_files()).unwrap();
    let w = mesh_warnings(&out);
    assert_eq!(w.len(), 14, "{w:#?}");
    assert!(w
        .iter()
        .any(|m| m.contains("visual mesh 'package://ur5/visual/forearm.dae' not found")));

    // From the scenario key (relative to the scenario file, here absolute) and from the
    // command line: every mesh resolves to an absolute existing file.
    let key = with_key(meshes.to_str().unwrap());
    let cli = RunOptions {
        package_path: vec![meshes.clone()],
        ..no_files()
    };
    for (out, how) in [
        (
            arm::run(&scenario, &key, &no_files()).unwrap(),
            "model.package_path",
        ),
        (arm::run(&scenario, &plain, &cli).unwrap(), "--package-path"),
    ] {
        assert!(
            mesh_warnings(&out).is_empty(),
            "{how}: {:?}",
            mesh_warnings(&out)
        );
        assert_eq!(absolute_mesh_files(&out, how), 14, "{how}");
        assert_eq!(
            out.report.json["collisions"]["first"]["pair"][0],
            "wrist_3_link"
        );
    }

    // A package_path that is not a directory: file, line and key.
    let e = arm::run(&scenario, &with_key("no_such_dir"), &no_files())
        .err()
        .expect("error")
        .to_string();
    assert!(
        e.contains("arm.toml:7") && e.contains("model.package_path") && e.contains("no_such_dir"),
        "{e}"
    );

    // The recording's robot_description names every mesh by an absolute file:// URI of
    // an existing file.
    let opts = RunOptions {
        out_dir: Some(dir.join("out")),
        package_path: vec![meshes.clone()],
        ..Default::default()
    };
    arm::run(&scenario, &plain, &opts).unwrap();
    let rec = armsim::io::record::mcap_in::read_mcap(&dir.join("out/planted.mcap")).unwrap();
    let desc = rec.header.robot_description.expect("robot_description");
    let uris = mesh_uris(&desc);
    assert_eq!(uris.len(), 14);
    for u in &uris {
        let p = u
            .strip_prefix("file://")
            .unwrap_or_else(|| panic!("not file://: {u}"));
        assert!(Path::new(p).is_absolute() && Path::new(p).is_file(), "{u}");
        assert!(
            p.starts_with(meshes.canonicalize().unwrap().to_str().unwrap()),
            "{u}"
        );
    }
    // --keep-mesh-uris: the URIs as the URDF writes them.
    let keep = RunOptions {
        keep_mesh_uris: true,
        ..opts
    };
    arm::run(&scenario, &plain, &keep).unwrap();
    let rec = armsim::io::record::mcap_in::read_mcap(&dir.join("out/planted.mcap")).unwrap();
    let uris = mesh_uris(&rec.header.robot_description.unwrap());
    assert_eq!(uris.len(), 14);
    assert!(
        uris.iter().all(|u| u.starts_with("package://ur5/")),
        "{uris:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bundled_scenario_recording_names_existing_mesh_files() {
    // The bundled UR5 scenario's MCAP: relative mesh paths became absolute file:// URIs.
    let dir = std::env::temp_dir().join(format!("armsim_meshrec_{}", std::process::id()));
    let path = root().join("scenarios/ur5_pick_and_place.toml");
    // Only the recording matters here: no collision check (seconds with meshes).
    let text =
        bundled("ur5_pick_and_place").replace("[collision]\n", "[collision]\nenabled = false\n");
    let opts = RunOptions {
        out_dir: Some(dir.clone()),
        ..Default::default()
    };
    arm::run(&path, &text, &opts).unwrap();
    let rec = armsim::io::record::mcap_in::read_mcap(&dir.join("ur5_pick_and_place.mcap")).unwrap();
    let uris = mesh_uris(&rec.header.robot_description.unwrap());
    assert_eq!(uris.len(), 14);
    for u in &uris {
        let p = u.strip_prefix("file:///").map(|p| format!("/{p}"));
        let p = p.unwrap_or_else(|| panic!("not an absolute file:// URI: {u}"));
        assert!(Path::new(&p).is_file(), "{u}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn elastic_joints_ring_after_the_motion_and_the_energy_balances() {
    let out = run_text("iiwa_elastic_joints", &bundled("iiwa_elastic_joints"));
    let sim = &out.report.json["simulation"];
    let f = sim["residual_vibration_hz"].as_f64().expect("vibration");
    assert!(f > 0.5 && f < 50.0, "{f} Hz");
    assert!(sim["residual_tool_error_m"].as_f64().unwrap() > 1e-4);
    // No damping, no friction: the energy audit applies and holds.
    let e = sim["energy_audit"]["max_relative_drift"].as_f64().unwrap();
    assert!(e < 1e-2, "{e}");
    // With the motor reference q_d + K⁻¹ τ_ff there is no static sag: the arm ends on
    // its target within the ringing amplitude (the sag K⁻¹ g would be ~2 cm).
    assert!(sim["residual_tool_error_m"].as_f64().unwrap() < 1e-2);
}

#[test]
fn every_bundled_arm_scenario_runs_and_names_its_joints() {
    let mut n = 0;
    for e in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().and_then(|x| x.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap();
        if text.lines().any(|l| l.trim_start().starts_with("kind =")) {
            continue;
        }
        let out = arm::run(&p, &text, &no_files()).unwrap_or_else(|e| panic!("{e}"));
        let j = &out.report.json;
        let joints = j["model"]["joints"].as_array().unwrap();
        assert_eq!(joints.len(), out.scene.model.nv);
        for (row, name) in j["torque_check"].as_array().unwrap().iter().zip(joints) {
            assert_eq!(&row["joint"], name);
        }
        for key in [
            "scenario",
            "effects",
            "torque_check",
            "collisions",
            "outputs",
        ] {
            assert!(j.get(key).is_some(), "{}: {key}", p.display());
        }
        n += 1;
    }
    assert!(n >= 5, "{n} arm scenarios");
}

#[test]
fn cli_run_writes_outputs_atomically_and_prints_json() {
    let dir = std::env::temp_dir().join(format!("armsim_run_{}", std::process::id()));
    let d = dir.to_str().unwrap();
    let o = cli(&["run", "scenarios/planar_2r.toml", "--out", d, "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let outputs = j["outputs"].as_array().unwrap();
    assert!(outputs.len() >= 3);
    for p in outputs {
        let p = Path::new(p.as_str().unwrap());
        assert!(p.starts_with(&dir) && p.exists(), "{}", p.display());
    }
    let png = std::fs::read(dir.join("planar_2r_torques.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left");
    // --check exits 2 on a violation; the text names the verdict.
    let o = cli(&[
        "run",
        "scenarios/panda_payload_sweep.toml",
        "--out",
        d,
        "--check",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stdout).contains("LIMITS EXCEEDED"));
    std::fs::remove_dir_all(&dir).ok();
}

/// `(file, line, key, message fragment)` of every broken arm scenario.
const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "arm_bad_integrator.toml",
        12,
        "simulation.integrator",
        "unknown integrator 'euler'",
    ),
    (
        "arm_bad_obstacle.toml",
        7,
        "obstacles[0] (ball)",
        "a sphere takes radius",
    ),
    (
        "arm_contact_without_gravity.toml",
        2,
        "effects",
        "needs 'gravity'",
    ),
    (
        "arm_contradictory_limits.toml",
        8,
        "limits.lower",
        "is not below the upper limit",
    ),
    (
        "arm_elastic_without_table.toml",
        2,
        "effects",
        "[joint_elasticity]",
    ),
    ("arm_empty.toml", 1, "file", "the file is empty"),
    (
        "arm_dt_over_budget.toml",
        15,
        "simulation.dt",
        "at least 5e11 steps (0.5 s at simulation.dt = 1e-12 s), more than the budget of 5e7",
    ),
    (
        "arm_dwell_over_budget.toml",
        15,
        "task.steps[1]",
        "this step lasts 1e12 s: the torque and limit checks would take 1.0000000000004905e15 samples",
    ),
    (
        "arm_check_dt_over_budget.toml",
        16,
        "trajectory.check_dt",
        "samples of trajectory.check_dt = 1e-12 s over the 0.408248290463863 s motion, more than the budget of 1e7",
    ),
    (
        "arm_collision_max_step.toml",
        15,
        "collision.max_step",
        "does not apply: the collision check no longer steps",
    ),
    (
        "arm_initial_outside_limits.toml",
        8,
        "initial.q",
        "outside the limits",
    ),
    (
        "arm_limit_above_model.toml",
        8,
        "limits.velocity",
        "exceeds the model's velocity limit",
    ),
    ("arm_missing_model.toml", 4, "model.file", "not found"),
    ("arm_missing_task.toml", 1, "task", "missing field `task`"),
    (
        "arm_misspelt_joint.toml",
        8,
        "initial.q.shoulder_pan_jiont",
        "did you mean 'shoulder_pan_joint'",
    ),
    (
        "arm_misspelt_joint_limits.toml",
        8,
        "limits.acceleration.elbow",
        "unknown joint 'elbow'",
    ),
    (
        "arm_negative_payload.toml",
        8,
        "payload.mass",
        "finite and >= 0",
    ),
    ("arm_truncated.toml", 6, "task.type", "invalid basic string"),
    (
        "arm_gear_train_unknown_joint.toml",
        8,
        "rotor_inertia.gear_train.shoulder",
        "no joint 'shoulder' in the model (joints: joint1, joint2)",
    ),
    (
        "arm_gear_train_without_output.toml",
        8,
        "rotor_inertia.gear_train.joint1",
        "must name its output member",
    ),
    (
        "arm_unknown_effect.toml",
        3,
        "effects",
        "unknown effect 'wind'",
    ),
    (
        "arm_unknown_key.toml",
        4,
        "effect",
        "unknown field `effect`",
    ),
    (
        "arm_unknown_key_in_table.toml",
        12,
        "simulation.integrater",
        "unknown field `integrater`",
    ),
    (
        "arm_unknown_link.toml",
        5,
        "model.tool",
        "did you mean 'tool0'",
    ),
    (
        "arm_unknown_task_type.toml",
        8,
        "task.type",
        "unknown task type 'wave'",
    ),
    (
        "arm_unreachable_pose.toml",
        9,
        "task.pick (approach)",
        "out of reach",
    ),
    (
        "arm_waypoint_count.toml",
        10,
        "task.waypoints[1]",
        "5 values for 6 joints",
    ),
    (
        "arm_wrong_type.toml",
        12,
        "simulation.dt",
        "invalid type: string \"fast\"",
    ),
    (
        "arm_wrong_type_array.toml",
        5,
        "model.base_xyz",
        "invalid length 2",
    ),
    (
        "arm_task_key_not_for_type.toml",
        10,
        "task.pick",
        "does not apply to a 'joint_waypoints' task (it reads waypoints, degrees)",
    ),
    (
        "arm_disabled_pair_three_names.toml",
        8,
        "collision.disabled_pairs",
        "a pair names two links or obstacles, got 3",
    ),
    (
        "arm_obstacle_too_large.toml",
        7,
        "obstacles[0] (wall)",
        "box size[0] of 1e308 m is larger than the 1e9 m accepted for collision geometry",
    ),
    (
        "arm_acceleration_too_large.toml",
        9,
        "limits.acceleration",
        "joint shoulder_pan_joint: at most 1000 rad/s²",
    ),
    (
        "arm_overshoot_out_of_range.toml",
        8,
        "planner.max_overshoot",
        "must lie in 0.0001 … 0.1 m, got 1e-300",
    ),
    (
        "arm_time_limit_too_large.toml",
        8,
        "planner.time_limit_ms",
        "at most 1e9 ms, got 1e308",
    ),
    (
        "arm_pusher_offset_nan.toml",
        7,
        "contact.pusher_offset",
        "must be finite",
    ),
];

#[test]
fn broken_arm_scenarios_give_located_errors_and_no_panic() {
    let listed: Vec<&str> = BROKEN.iter().map(|b| b.0).collect();
    common::assert_lists_every_broken_scenario("arm_", &listed);
    let out = std::env::temp_dir().join(format!("armsim_broken_{}", std::process::id()));
    for &(file, line, key, msg) in BROKEN {
        let rel = format!("tests/broken_scenarios/{file}");
        let e = armsim::scenarios::run_file_with(&root().join(&rel), &no_files())
            .err()
            .unwrap_or_else(|| panic!("{file} ran"));
        assert_eq!(e.line, Some(line), "{file}: {e}");
        assert_eq!(e.key, key, "{file}: {e}");
        assert!(e.message.contains(msg), "{file}: {e}");
        let o = cli(&["run", &rel, "--out", out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && o.stdout.is_empty(), "{file}");
        assert!(
            err.contains(&format!("{rel}:{line}: {key}: ")),
            "{file}: {err}"
        );
        assert!(!err.contains("panicked"), "{file}: {err}");
    }
    // Nothing was written for a scenario that failed to load.
    assert!(!out.exists() || std::fs::read_dir(&out).unwrap().next().is_none());
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn scenario_recording_round_trips_through_mcap() {
    let dir = std::env::temp_dir().join(format!("armsim_rec_{}", std::process::id()));
    let opts = RunOptions {
        out_dir: Some(dir.clone()),
        ..Default::default()
    };
    let path = root().join("scenarios/planar_2r.toml");
    let out = arm::run(&path, &bundled("planar_2r"), &opts).unwrap();
    let file = dir.join("planar_2r.mcap");
    let rec = armsim::io::record::mcap_in::read_mcap(&file).unwrap();
    assert_eq!(rec.header.joint_names, vec!["joint1", "joint2"]);
    assert_eq!(rec.frames.len(), out.samples.len());
    for (f, s) in rec.frames.iter().zip(&out.samples) {
        assert!((f.t - s.t).abs() < 1e-9);
        assert_eq!(f.q, s.q, "decoded joint values equal the simulated ones");
        assert_eq!(f.tau, s.tau);
    }
    assert!(rec.frames.windows(2).all(|w| w[1].t > w[0].t));
    assert_eq!(rec.torque_check.len(), 2);
    assert_eq!(rec.torque_check[0].joint, "joint1");
    assert!(rec.header.static_tf.iter().any(|t| t.parent == "world"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sigint_in_the_middle_of_a_run_leaves_a_valid_mcap() {
    let dir = std::env::temp_dir().join(format!("armsim_sigint_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let robot = root().join("robots/planar_2r.toml");
    let text = bundled("planar_2r")
        .replace("../robots/planar_2r.toml", robot.to_str().unwrap())
        .replace("dt = 0.001", "dt = 0.0002\nduration = 5000.0");
    let scenario = dir.join("long.toml");
    std::fs::write(&scenario, text).unwrap();
    let out = dir.join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_armsim"))
        .args([
            "run",
            scenario.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let ok = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
    let status = child.wait().unwrap();
    assert_eq!(
        status.code(),
        Some(130),
        "exits 130 after finishing its files"
    );
    let rec = armsim::io::record::mcap_in::read_mcap(&out.join("planar_2r.mcap")).unwrap();
    let last = rec
        .frames
        .last()
        .expect("frames recorded before the interrupt")
        .t;
    assert!(last > 0.0 && last < 5000.0, "{last}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("planar_2r.json")).unwrap()).unwrap();
    assert_eq!(report["simulation"]["interrupted"], true);
    let leftovers = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .count();
    assert_eq!(leftovers, 0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn workspace_writes_its_cloud_as_pointcloud2_in_mcap() {
    let dir = std::env::temp_dir().join(format!("armsim_ws_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("ws.mcap");
    let o = cli(&[
        "workspace",
        "robots/planar_2r.toml",
        "--samples",
        "4000",
        "--out",
        p.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rec = armsim::io::record::mcap_in::read_mcap(&p).unwrap();
    assert_eq!(rec.clouds.len(), 1);
    let c = &rec.clouds[0];
    assert!(c.points.len() >= 1000, "{}", c.points.len());
    assert_eq!(c.values.len(), c.points.len());
    // The 2R tip (l1 = l2 = 0.5 m) stays within 1 m of the shoulder.
    for q in &c.points {
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        assert!(r <= 1.0 + 1e-5, "{r}");
    }
    assert!(rec.header.robot_description.unwrap().contains("<robot"));
    std::fs::remove_dir_all(&dir).ok();
}

/// The bundled pick-and-place with the planner switched off: joint-space moves to the IK
/// solutions of the approach poses.
fn pick_and_place_unplanned() -> String {
    let text = bundled("ur5_pick_and_place");
    let i = text.find("[planner]").unwrap();
    let j = text[i..].find("\n\n").unwrap() + i + 2;
    let text = format!("{}{}", &text[..i], &text[j..]);
    assert!(text.contains("planner = \"rrt-connect\""));
    text.replace("planner = \"rrt-connect\"", "planner = \"none\"")
}

#[test]
fn bundled_pick_and_place_direct_path_hits_the_crate_and_the_planned_one_does_not() {
    // Direct: the parry trajectory check finds the crate in the way.
    let out = run_text("ur5_pick_and_place", &pick_and_place_unplanned());
    let c = &out.report.json["collisions"];
    assert_eq!(c["checked"], true);
    assert_eq!(c["collision_free"], false, "{c}");
    let pair = c["first"]["pair"].as_array().unwrap();
    assert!(pair.iter().any(|p| p == "crate"), "{pair:?}");
    assert!(out.plan.planned_paths.is_empty());
    // Planned: the same check (continuous between samples, the part on the tool from
    // the pick to the place) finds nothing.
    let out = run_text("ur5_pick_and_place", &bundled("ur5_pick_and_place"));
    let c = &out.report.json["collisions"];
    assert_eq!(c["collision_free"], true, "{c}");
    let (a, b) = out.plan.carry.unwrap();
    assert_eq!(c["part_checked_s"], serde_json::json!([a, b]));
    assert_eq!(
        out.plan.planned_paths.len(),
        3,
        "approach, transfer, return"
    );
    let planner = &out.report.json["plan"]["planner"];
    assert_eq!(planner["algorithm"], "rrt-connect");
    assert_eq!(planner["segments"], 3);
}

#[test]
fn planned_transfer_goes_through_its_via_points_without_stopping() {
    let out = run_text("ur5_pick_and_place", &bundled("ur5_pick_and_place"));
    let traj = &out.plan.trajectory;
    let planned: Vec<_> = out
        .plan
        .pieces
        .iter()
        .filter(|p| p.kind == "planned")
        .collect();
    assert_eq!(planned.len(), 3);
    // The transfer (from the pick's retreat to the place's approach) goes around the
    // crate: more than two via points.
    let transfer = &out.plan.planned_paths[1];
    assert!(transfer.len() > 2, "{} via points", transfer.len());
    let n = 6;
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for p in planned {
        // Rest at both ends, moving everywhere in between (sampled every 2 ms away from
        // the ends): no stop at the via points.
        let k = (p.duration_s / 0.002) as usize;
        let mut slowest = f64::INFINITY;
        for i in 1..k {
            let t = p.start_s + p.duration_s * i as f64 / k as f64;
            let u = (t - p.start_s).min(p.start_s + p.duration_s - t);
            traj.sample(t, &mut q, &mut qd, &mut qdd);
            let speed = qd.iter().map(|x| x * x).sum::<f64>().sqrt();
            if u > 0.1 {
                slowest = slowest.min(speed);
            }
        }
        assert!(slowest > 0.05, "{}: slowest {slowest} rad/s", p.from);
        traj.sample(p.start_s + 1e-9, &mut q, &mut qd, &mut qdd);
        assert!(qd.iter().all(|x| x.abs() < 1e-3), "{qd:?}");
    }
}

#[test]
fn plan_task_reaches_joint_and_pose_goals_around_the_crate() {
    let base = bundled("ur5_pick_and_place");
    let i = base.find("[task]").unwrap();
    let j = base.find("[trajectory]").unwrap();
    let head = &base[..i];
    let tail = &base[j..];
    // Joint goal on the far side of the crate.
    let h = std::f64::consts::FRAC_PI_2;
    let goal = [1.0, -h, h, -h, -h, 0.0];
    let text = format!("{head}[task]\ntype = \"plan\"\ngoal_q = {goal:?}\n\n{tail}");
    let out = run_text("ur5_pick_and_place", &text);
    assert_eq!(out.report.json["collisions"]["collision_free"], true);
    assert_eq!(out.plan.planned_paths.len(), 1);
    let path = &out.plan.planned_paths[0];
    assert!(path.len() > 2, "the straight move crosses the crate");
    let traj = &out.plan.trajectory;
    let (mut q, mut qd, mut qdd) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
    traj.sample(traj.duration(), &mut q, &mut qd, &mut qdd);
    for k in 0..6 {
        assert!((q[k] - goal[k]).abs() < 1e-9, "{q:?}");
    }
    // The same seed gives the same path.
    let again = run_text("ur5_pick_and_place", &text);
    assert_eq!(again.plan.planned_paths, out.plan.planned_paths);
    // Tool pose goal through IK: the motion ends at the pose.
    let text = format!(
        "{head}[task]\ntype = \"plan\"\ngoal = {{ xyz = [0.45, 0.3, 0.35], rpy = [3.14159265, 0.0, -1.5707963] }}\n\n{tail}"
    );
    let out = run_text("ur5_pick_and_place", &text);
    assert_eq!(out.report.json["collisions"]["collision_free"], true);
    let traj = &out.plan.trajectory;
    traj.sample(traj.duration(), &mut q, &mut qd, &mut qdd);
    let model = Model::build(Model::read_spec(&root().join("robots/ur5.urdf")).unwrap())
        .unwrap()
        .0;
    let mut data = Data::new(&model);
    armsim::kinematics::forward_kinematics(&model, &mut data, &q);
    let tool = model.link_id("tool0").unwrap();
    let p = armsim::kinematics::frame_placement(&model, &data, tool).trans;
    assert!((p - Vec3::new(0.45, 0.3, 0.35)).norm() < 1e-6, "{p:?}");
}

#[test]
fn planner_table_without_a_planned_task_is_refused_with_its_line() {
    let text = pick_and_place_unplanned().replace("[task]", "[planner]\nseed = 3\n\n[task]");
    let path = root().join("scenarios/ur5_pick_and_place.toml");
    let e = arm::load(&path, &text).err().expect("refused").to_string();
    assert!(e.contains("planner") && e.contains("plans nothing"), "{e}");
    let line = text.lines().position(|l| l == "[planner]").unwrap() + 1;
    assert!(e.contains(&format!(":{line}:")), "{e}");
}

/// A failure of the run itself (here: the output folder cannot be made, its parent is a
/// file) is located at the header of the table it comes from, not only named by its key.
#[test]
fn run_time_errors_give_the_line_of_their_table() {
    let dir = std::env::temp_dir().join(format!("armsim_run_error_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("blocker"), "a file, not a folder").unwrap();
    let robot = common::root().join("robots/ur5.urdf");
    let text = format!(
        "effects = [\"gravity\"]\n[model]\nfile = \"{}\"\ntool = \"tool0\"\n\n\
         [task]\ntype = \"joint_waypoints\"\nwaypoints = [[0.5, -1.2, 1.2, -1.5, -1.57, 0.0]]\n\n\
         [outputs]\ndir = \"{}\"\n",
        robot.display(),
        dir.join("blocker").join("out").display()
    );
    let f = dir.join("blocked.toml");
    std::fs::write(&f, text).unwrap();
    let e = armsim::scenarios::run_file(&f).expect_err("the output folder cannot be made");
    assert!(e.key.starts_with("outputs"), "{e}");
    assert_eq!(e.line, Some(10), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 28: a task of more than 10 000 waypoints is refused when read (10⁵ took 22 s to
/// reach the step budget, whose message then named every waypoint).
#[test]
fn a_task_of_too_many_waypoints_is_refused_when_read() {
    let dir = std::env::temp_dir().join(format!("armsim_waypoints_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rows = vec!["[0.5, -1.2, 1.2, -1.5, -1.57, 0.0]"; 10_001].join(", ");
    let text = format!(
        "effects = [\"gravity\"]\n[model]\nfile = \"{}\"\ntool = \"tool0\"\n\n[task]\ntype = \"joint_waypoints\"\nwaypoints = [{rows}]\n",
        common::root().join("robots/ur5.urdf").display()
    );
    let path = dir.join("many.toml");
    std::fs::write(&path, text).unwrap();
    let t = std::time::Instant::now();
    let e = armsim::scenarios::run_file(&path).expect_err("refused");
    assert_eq!(e.key, "task.waypoints", "{e}");
    assert!(
        e.message
            .contains("entry 10001: more than the 10000 entries one task accepts"),
        "{e}"
    );
    eprintln!("refused in {:.2} s", t.elapsed().as_secs_f64());
    std::fs::remove_dir_all(&dir).ok();
}
