//! Generated serial chains for scale tests and benchmarks.
//!
//! `chain N`: links `link0` … `linkN`, revolute joints `joint1` … `jointN`; joint `i` sits
//! 0.1 m above its parent along z (joint 1 at the origin) and turns about z, y, x in turn
//! (`i % 3 == 1, 2, 0`); limits ±3.14159 rad, 100 N m, 2 rad/s; every moving link has
//! 1 kg at (0, 0, 0.05) with inertia diag(0.01, 0.01, 0.005). The same chain is written as
//! URDF by [`chain_urdf`] (and by `tools/pinocchio/gen_chain.py` for the Pinocchio
//! baseline), so both libraries time the same mechanism.

use crate::core::spatial::{Inertia, Mat3, Se3, Vec3};
use crate::model::spec::*;
use std::fmt::Write;

fn axis(i: usize) -> [f64; 3] {
    match i % 3 {
        1 => [0.0, 0.0, 1.0],
        2 => [0.0, 1.0, 0.0],
        _ => [1.0, 0.0, 0.0],
    }
}

fn z_offset(i: usize) -> f64 {
    if i == 1 {
        0.0
    } else {
        0.1
    }
}

/// The chain as a [`ModelSpec`] (no XML round trip).
#[allow(clippy::approx_constant)] // ±3.14159 is the chain's spec (as written in its URDF), not π
pub fn chain_spec(n: usize) -> ModelSpec {
    let mut links = Vec::with_capacity(n + 1);
    let mut joints = Vec::with_capacity(n);
    links.push(LinkSpec::new("link0"));
    for i in 1..=n {
        let mut l = LinkSpec::new(format!("link{i}"));
        l.inertial = Inertia::new(
            1.0,
            Vec3::new(0.0, 0.0, 0.05),
            Mat3::from_diagonal(&Vec3::new(0.01, 0.01, 0.005)),
        );
        links.push(l);
        let mut j = JointSpec::new(
            format!("joint{i}"),
            JointType::Revolute,
            format!("link{}", i - 1),
            format!("link{i}"),
        );
        j.origin = Se3::from_translation(Vec3::new(0.0, 0.0, z_offset(i)));
        j.axis = Vec3::from(axis(i));
        j.limits = Limits {
            lower: -3.14159,
            upper: 3.14159,
            velocity: 2.0,
            effort: 100.0,
        };
        joints.push(j);
    }
    ModelSpec {
        name: format!("chain_{n}"),
        source: format!("<generated chain_{n}>"),
        root_offset: Se3::identity(),
        links,
        joints,
        urdf_text: None,
        gravity: None,
        warnings: Vec::new(),
    }
}

/// The chain as URDF text.
pub fn chain_urdf(n: usize) -> String {
    let mut s = String::with_capacity(400 * n + 100);
    let _ = writeln!(s, "<?xml version=\"1.0\"?>\n<robot name=\"chain_{n}\">");
    s.push_str("  <link name=\"link0\"/>\n");
    for i in 1..=n {
        let _ = writeln!(
            s,
            "  <link name=\"link{i}\">\n    <inertial>\n      <origin xyz=\"0 0 0.05\" rpy=\"0 0 0\"/>\n      <mass value=\"1.0\"/>\n      <inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.005\"/>\n    </inertial>\n  </link>"
        );
        let a = axis(i);
        let _ = writeln!(
            s,
            "  <joint name=\"joint{i}\" type=\"revolute\">\n    <parent link=\"link{}\"/>\n    <child link=\"link{i}\"/>\n    <origin xyz=\"0 0 {}\" rpy=\"0 0 0\"/>\n    <axis xyz=\"{} {} {}\"/>\n    <limit lower=\"-3.14159\" upper=\"3.14159\" effort=\"100\" velocity=\"2\"/>\n  </joint>",
            i - 1,
            if i == 1 { "0" } else { "0.1" },
            a[0],
            a[1],
            a[2]
        );
    }
    s.push_str("</robot>\n");
    s
}
