//! What real URDF files contain and urdfdom / Pinocchio load, armsim loads: minimal copies
//! of the constructs that armsim used to refuse in example-robot-data (TALOS, Alex, iCub,
//! Romeo, TIAGo) and the other odd cases of docs/urdf.md, in `tests/data/urdf_ecosystem/`.
//!
//! Each file's warnings are checked word for word where they matter (file, line, element,
//! problem), with the numbers loaded (clamped inertias, geometry kept, coordinates), and
//! forward kinematics is compared with Pinocchio 4.1's link placements at random states,
//! written by `tools/urdf_sweep.py --golden` into `pinocchio_fk.json` (no Python here).

use armsim::core::spatial::{rpy_to_matrix, Mat3, Vec3};
use armsim::kinematics::{forward_kinematics, update_frames};
use armsim::model::data::Data;
use armsim::model::{LoadOptions, Model, ModelWarning, Shape};
use serde_json::Value;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/urdf_ecosystem");

fn path(name: &str) -> String {
    format!("{DIR}/{name}")
}

fn load(name: &str) -> (Model, Vec<ModelWarning>) {
    Model::load(path(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Loads `name`, checks that `--strict` refuses it with its first warning, and returns the
/// model and the warnings rendered.
fn load_warned(name: &str) -> (Model, Vec<String>) {
    let (m, w) = load(name);
    assert!(!w.is_empty(), "{name}: no warning");
    let strict = LoadOptions {
        strict: true,
        ..Default::default()
    };
    let e = Model::load_with(path(name), &strict).expect_err("strict refuses a warning");
    assert_eq!(e, w[0], "{name}: strict error is the first warning");
    (m, w.iter().map(|w| w.to_string()).collect())
}

/// Asserts that exactly one warning starts with `FILE:LINE: ELEMENT: ` and contains `msg`.
fn assert_warned(w: &[String], name: &str, line: usize, element: &str, msg: &str) {
    let head = format!("{}:{line}: {element}: ", path(name));
    let hits = w
        .iter()
        .filter(|x| x.starts_with(&head) && x.contains(msg))
        .count();
    assert_eq!(hits, 1, "want one '{head}…{msg}…' in {w:#?}");
}

fn placement(m: &Model, q: &[f64], link: &str) -> (Mat3, Vec3) {
    let mut d = Data::new(m);
    forward_kinematics(m, &mut d, q);
    update_frames(m, &mut d);
    let t = &d.o_m_f[m.link_id(link).unwrap_or_else(|| panic!("link {link}"))];
    (t.rot, t.trans)
}

fn assert_close(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got:e}, want {want:e}"
    );
}

#[test]
fn fk_matches_pinocchio_on_every_construct() {
    let text = std::fs::read_to_string(path("pinocchio_fk.json")).unwrap();
    let g: Value = serde_json::from_str(&text).unwrap();
    let files = g["files"].as_object().unwrap();
    assert!(
        files.len() >= 11,
        "only {} files in the golden data",
        files.len()
    );
    let mut compared = 0;
    for (file, f) in files {
        let (m, _) = load(file);
        for (s, st) in f["states"].as_array().unwrap().iter().enumerate() {
            let qmap = st["q"].as_object().unwrap();
            assert_eq!(qmap.len(), m.nv, "{file}: coordinates");
            let q: Vec<f64> = m
                .dof_names()
                .iter()
                .map(|n| qmap[n].as_f64().unwrap_or_else(|| panic!("{file}: {n}")))
                .collect();
            let mut d = Data::new(&m);
            forward_kinematics(&m, &mut d, &q);
            update_frames(&m, &mut d);
            let links = st["links"].as_object().unwrap();
            assert!(!links.is_empty(), "{file}: no link compared");
            for (link, pose) in links {
                let t = &d.o_m_f[m.link_id(link).unwrap()];
                for i in 0..3 {
                    let what = format!("{file} state {s} {link}");
                    let p = pose["translation"][i].as_f64().unwrap();
                    assert_close(t.trans[i], p, 1e-9, &format!("{what} p[{i}]"));
                    for j in 0..3 {
                        let r = pose["rotation"][i][j].as_f64().unwrap();
                        assert_close(t.rot[(i, j)], r, 1e-9, &format!("{what} R[{i},{j}]"));
                    }
                }
                compared += 1;
            }
        }
    }
    assert!(compared >= 100, "only {compared} link placements compared");
}

#[test]
fn talos_mimic_on_a_fixed_joint_is_ignored_with_a_warning() {
    let name = "talos_mimic_on_fixed.urdf";
    let (m, w) = load_warned(name);
    assert_eq!(w.len(), 1, "{w:#?}");
    assert_warned(
        &w,
        name,
        19,
        "joint 'fingertip_joint'",
        "<mimic joint=\"gripper_joint\"> on a fixed joint: ignored (a fixed joint does not move)",
    );
    assert_eq!(m.dof_names(), ["wrist", "gripper_joint"]);
    // The fingertip stays 0.032, 0.046, -0.066 from the finger whatever the gripper does.
    let q = [0.4, -0.7];
    let (r0, p0) = placement(&m, &q, "inner_double");
    let (_, p1) = placement(&m, &q, "fingertip");
    let want = p0 + r0 * Vec3::new(0.032, 0.046, -0.066);
    assert!((p1 - want).norm() < 1e-15, "{p1} vs {want}");
}

#[test]
fn alex_mimic_of_a_missing_master_is_an_independent_coordinate() {
    let name = "alex_missing_mimic_master.urdf";
    let (m, w) = load_warned(name);
    assert_eq!(w.len(), 1, "{w:#?}");
    assert_warned(
        &w,
        name,
        15,
        "joint 'Left_index_q2'",
        "mimic: master joint 'index_q1' does not exist: the mimic tag is ignored ('Left_index_q2' is an independent coordinate)",
    );
    assert_eq!(m.nv, 2);
    assert_eq!(m.dof_names(), ["Left_index_q1", "Left_index_q2"]);
    let j = &m.joints[m.joint_id("Left_index_q2").unwrap()];
    assert!(j.mimic.is_none());
    assert_eq!((j.limits.lower, j.limits.upper), (0.0, 2.6586));
    assert_eq!((j.damping, j.friction), (0.001, 0.001));
}

#[test]
fn icub_texture_without_filename_loads_without_a_warning() {
    let (m, w) = load("icub_texture_without_filename.urdf");
    assert!(w.is_empty(), "{w:?}");
    assert_eq!(m.dof_names(), ["torso_pitch"]);
    // The visual's own material has only a texture: the named material gives the colour.
    let base = &m.links[m.link_id("root_link").unwrap()];
    assert_eq!(base.visuals.len(), 1);
    assert_eq!(base.visuals[0].rgba, Some([0.9, 0.9, 0.9, 1.0]));
}

#[test]
fn tiago_rounding_negative_inertia_is_clamped_with_a_warning() {
    let name = "tiago_rounding_inertia.urdf";
    let (m, w) = load_warned(name);
    assert_warned(
        &w,
        name,
        8,
        "link 'base_antenna_left_link'",
        "inertial: principal moments 9.087010e-8, -3.534856e-8, 3.500846e-8: the negative one is within 1.0e-6 kg m² of zero (rounding); negative moments are clamped to 0",
    );
    assert_warned(
        &w,
        name,
        15,
        "link 'probe_link'",
        "the negative one is within 1.0e-6 kg m² of zero (rounding); negative moments are clamped to 0",
    );
    // [[1, 1.2, 0], [1.2, 1, 0], [0, 0, 1]] e-7: moments 2.2e-7 along (1, 1, 0)/√2,
    // -2e-8 along (1, -1, 0)/√2, 1e-7 along z. Clamped: 2.2e-7 · ½[[1, 1], [1, 1]] ⊕ 1e-7.
    let i = m.links[m.link_id("probe_link").unwrap()].inertial;
    assert_eq!(i.mass, 0.01);
    let want = Mat3::new(1.1e-7, 1.1e-7, 0.0, 1.1e-7, 1.1e-7, 0.0, 0.0, 0.0, 1e-7);
    for k in 0..9 {
        assert_close(i.inertia_com[k], want[k], 1e-21, &format!("probe I[{k}]"));
    }
    // The antenna: positive semi-definite now, the positive moments kept.
    let a = m.links[m.link_id("base_antenna_left_link").unwrap()].inertial;
    let mut ev: Vec<f64> = a
        .inertia_com
        .symmetric_eigenvalues()
        .iter()
        .copied()
        .collect();
    ev.sort_by(f64::total_cmp);
    assert_close(ev[0], 0.0, 1e-22, "antenna min moment");
    assert_close(ev[1], 3.500846e-8, 1e-13, "antenna mid moment");
    assert_close(ev[2], 9.087010e-8, 1e-13, "antenna max moment");
}

#[test]
fn romeo_inconsistent_inertia_is_replaced_by_the_nearest_positive_one() {
    let name = "romeo_inconsistent_inertia.urdf";
    let (m, w) = load_warned(name);
    assert_warned(
        &w,
        name,
        7,
        "link 'body'",
        "not positive semi-definite by 2.1e-2 kg m², more than rounding (9.9e-5): the products of inertia are inconsistent with the moments; negative moments are clamped to 0",
    );
    let i = m.links[m.link_id("body").unwrap()].inertial;
    let file = Mat3::new(
        0.0564204,
        7.26322e-05,
        -0.0575115,
        7.26322e-05,
        0.0521042,
        -3.39086e-05,
        -0.0575115,
        -3.39086e-05,
        0.021185,
    );
    // Clipping one negative moment λ: the change is -λ v vᵀ, so the trace grows by |λ|
    // and the Frobenius distance is |λ| (the nearest positive semi-definite tensor).
    let lambda = file.symmetric_eigenvalues().min();
    assert!(lambda < -0.02, "{lambda}");
    let delta = i.inertia_com - file;
    assert_close(delta.trace(), -lambda, 1e-15, "trace change");
    assert_close(delta.norm(), -lambda, 1e-15, "distance");
    assert_close(
        0.0564204 + 0.0521042 + 0.021185 - lambda,
        i.inertia_com.trace(),
        1e-15,
        "trace",
    );
    assert!(i.inertia_com.symmetric_eigenvalues().min() >= -1e-17);
    assert_eq!(i.mass, 5.11337);
    assert_eq!(i.com, Vec3::new(0.02825, 0.0, -0.16653));
}

#[test]
fn odd_geometry_is_left_out_with_a_warning_each() {
    let name = "odd_geometry.urdf";
    let (m, w) = load_warned(name);
    assert_eq!(w.len(), 6, "{w:#?}");
    let el = "link 'base'";
    assert_warned(&w, name, 6, el, "<geometry>: no shape (expected <box>, <cylinder>, <sphere>, <capsule> or <mesh>): the <visual> is ignored");
    assert_warned(&w, name, 7, el, "unknown geometry <plane> (expected <box>, <cylinder>, <sphere>, <capsule> or <mesh>): the <visual> is ignored");
    assert_warned(&w, name, 8, el, "unknown geometry <cdf> (expected <box>, <cylinder>, <sphere>, <capsule> or <mesh>): the <collision> is ignored");
    assert_warned(
        &w,
        name,
        9,
        el,
        "<mesh scale=\"0.001\">: one number: taken as a uniform scale",
    );
    assert_warned(
        &w,
        name,
        10,
        el,
        "<mesh scale=\"0.001 0.001\">: expected 3 number(s), found 2: the <collision> is ignored",
    );
    assert_warned(
        &w,
        name,
        11,
        el,
        "<geometry>: more than one shape: the first (<box>) is used",
    );
    let base = &m.links[m.link_id("base").unwrap()];
    assert_eq!(base.visuals.len(), 1);
    assert_eq!(
        base.visuals[0].shape,
        Shape::Mesh {
            uri: "package://arm/base.stl".into(),
            scale: [0.001; 3]
        }
    );
    assert_eq!(base.collisions.len(), 1);
    assert_eq!(
        base.collisions[0].shape,
        Shape::Box {
            size: [0.1, 0.2, 0.3]
        }
    );
    assert_eq!(m.dof_names(), ["shoulder"]);
}

#[test]
fn duplicate_child_tags_use_the_first_with_a_warning() {
    let name = "duplicate_tags.urdf";
    let (m, w) = load_warned(name);
    assert_eq!(w.len(), 4, "{w:#?}");
    let el = "joint 'shoulder'";
    for (line, tag, first) in [
        (11, "child", 10),
        (13, "origin", 12),
        (15, "axis", 14),
        (17, "limit", 16),
    ] {
        let msg =
            format!("<{tag}> given more than once: the first (line {first}) is used, the others are ignored");
        assert_warned(&w, name, line, el, &msg);
    }
    assert_eq!((m.lower[0], m.upper[0]), (-1.0, 1.0));
    // The first axis (z) and origin (0, 0, 0.2): arm = T(0, 0, 0.2) Rz(q).
    let q = 0.5f64;
    let (r, p) = placement(&m, &[q], "arm");
    assert!((p - Vec3::new(0.0, 0.0, 0.2)).norm() < 1e-15);
    assert!((r - rpy_to_matrix([0.0, 0.0, q])).norm() < 1e-15);
    // 'spare' hangs from 'arm' by its own joint, not by the ignored second <child>.
    let (_, ps) = placement(&m, &[q], "spare");
    let want = Vec3::new(0.1 * q.cos(), 0.1 * q.sin(), 0.2);
    assert!((ps - want).norm() < 1e-15, "{ps} vs {want}");
}

#[test]
fn a_late_xml_declaration_is_ignored_with_a_warning() {
    let name = "late_declaration.urdf";
    let (m, w) = load_warned(name);
    assert_eq!(w.len(), 1, "{w:#?}");
    assert_eq!(
        w[0],
        format!(
            "{}:3: XML: XML declaration <?xml …?> not at the start of the file: ignored",
            path(name)
        )
    );
    assert_eq!(m.dof_names(), ["shoulder"]);
}

#[test]
fn extension_tags_are_ignored_anywhere() {
    let name = "extensions.urdf";
    let (m, w) = load_warned(name);
    // The one warning: the undeclared xacro: prefix (the vendor: one is declared).
    assert_eq!(w.len(), 1, "{w:#?}");
    assert_warned(
        &w,
        name,
        6,
        "XML",
        "namespace prefix 'xacro' is not declared: its elements are ignored (as extensions)",
    );
    let base = &m.links[m.link_id("base").unwrap()];
    assert_eq!(base.inertial.mass, 2.0);
    assert_eq!(base.inertial.com, Vec3::new(0.0, 0.0, 0.05));
    assert_eq!(base.visuals.len(), 1);
    assert_eq!(m.dof_names(), ["shoulder"]);
    assert_eq!((m.lower[0], m.upper[0]), (0.0, 0.5));
}

#[test]
fn a_floating_joint_is_six_one_axis_joints() {
    let name = "floating_base.urdf";
    let (m, w) = load_warned(name);
    assert_eq!(w.len(), 1, "{w:#?}");
    assert_warned(&w, name, 13, "joint 'base'", "floating joint: modelled as the one-axis joints base_x, base_y, base_z, base_yaw, base_pitch, base_roll");
    assert_eq!(
        m.dof_names(),
        [
            "base_x",
            "base_y",
            "base_z",
            "base_yaw",
            "base_pitch",
            "base_roll",
            "shoulder"
        ]
    );
    // pelvis = T(0, 0, 1) Rz(0.5) · T(x, y, z) · Rz(yaw) Ry(pitch) Rx(roll).
    let q = [1.0, 2.0, 3.0, 0.1, 0.2, 0.3, 0.0];
    let (r, p) = placement(&m, &q, "pelvis");
    let rz = rpy_to_matrix([0.0, 0.0, 0.5]);
    let want_p = Vec3::new(0.0, 0.0, 1.0) + rz * Vec3::new(1.0, 2.0, 3.0);
    let want_r = rz * rpy_to_matrix([0.3, 0.2, 0.1]);
    assert!((p - want_p).norm() < 1e-14, "{p} vs {want_p}");
    assert!((r - want_r).norm() < 1e-14);
    // The pelvis keeps its mass; the links between are massless.
    assert_eq!(m.links[m.link_id("pelvis").unwrap()].inertial.mass, 3.0);
    assert_eq!(
        m.links[m.link_id("base_x_link").unwrap()].inertial.mass,
        0.0
    );
}

#[test]
fn a_planar_joint_moves_in_the_joint_frame_xy_plane_as_in_pinocchio() {
    let name = "planar_base.urdf";
    let (m, w) = load_warned(name);
    assert_eq!(w.len(), 2, "{w:#?}");
    assert_warned(
        &w,
        name,
        8,
        "joint 'base'",
        "planar joint: modelled as the one-axis joints base_x, base_y, base_yaw",
    );
    assert_warned(
        &w,
        name,
        8,
        "joint 'base'",
        "planar joint: <axis xyz=\"1 0 0\"> is not the joint frame's z: ignored",
    );
    assert_eq!(m.dof_names(), ["base_x", "base_y", "base_yaw", "shoulder"]);
    // cart = T(0, 0, 0.1) Rx(0.2) · T(x, y, 0) Rz(yaw).
    let q = [1.0, -0.5, 0.7, 0.0];
    let (r, p) = placement(&m, &q, "cart");
    let rx = rpy_to_matrix([0.2, 0.0, 0.0]);
    let want_p = Vec3::new(0.0, 0.0, 0.1) + rx * Vec3::new(1.0, -0.5, 0.0);
    assert!((p - want_p).norm() < 1e-15, "{p} vs {want_p}");
    assert!((r - rx * rpy_to_matrix([0.0, 0.0, 0.7])).norm() < 1e-15);
}

#[test]
fn an_inertial_without_inertia_is_a_point_mass() {
    let name = "point_mass_inertial.urdf";
    let (m, w) = load_warned(name);
    assert_eq!(w.len(), 1, "{w:#?}");
    assert_warned(
        &w,
        name,
        7,
        "link 'tip'",
        "<inertial>: missing <inertia>: the tensor is taken as zero (a point mass)",
    );
    let i = m.links[m.link_id("tip").unwrap()].inertial;
    assert_eq!(i.mass, 2.0);
    assert_eq!(i.com, Vec3::new(0.5, 0.0, 0.0));
    assert_eq!(i.inertia_com, Mat3::zeros());
    // About the hinge: m r² = 2 · 0.5² = 0.5 kg m².
    let mut d = Data::new(&m);
    let mass = armsim::dynamics::crba(&m, &mut d, &[0.3]);
    assert_close(mass[(0, 0)], 0.5, 1e-15, "M");
}

fn armsim(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_armsim"))
        .args(args)
        .output()
        .expect("run armsim")
}

#[test]
fn strict_refuses_warned_models_in_plan_and_run_too() {
    let model = path("talos_mimic_on_fixed.urdf");
    let warning = format!(
        "{model}:19: joint 'fingertip_joint': <mimic joint=\"gripper_joint\"> on a fixed joint"
    );
    // plan: the model is loaded first; without --strict the missing folder is the error.
    let dir = std::env::temp_dir().join(format!("armsim_no_such_dir_{}", std::process::id()));
    let dir = dir.to_str().unwrap();
    let o = armsim(&["plan", &model, "--moveit-dir", dir, "--strict"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains(&format!("error: {warning}")),
        "{err}"
    );
    let o = armsim(&["plan", &model, "--moveit-dir", dir]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(
        err.contains(&format!("warning: {warning}")) && err.contains(dir),
        "{err}"
    );
    // run: a scenario on the same model.
    let tmp = std::env::temp_dir().join(format!("armsim_strict_run_{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let scenario = tmp.join("talos.toml");
    std::fs::write(
        &scenario,
        format!(
            "name = \"talos\"\neffects = []\n[model]\nfile = \"{model}\"\n[initial]\nq = [0.0, 0.0]\n\
             [task]\ntype = \"sequence\"\nsteps = [{{ joint = [0.2, -0.3] }}]\n[collision]\nenabled = false\n"
        ),
    )
    .unwrap();
    let o = armsim(&[
        "run",
        scenario.to_str().unwrap(),
        "--strict",
        "--out",
        tmp.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert!(err.contains(&format!("--strict: {warning}")), "{err}");
    let _ = std::fs::remove_dir_all(&tmp);
}
