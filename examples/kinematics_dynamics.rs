//! The library's common path on the bundled UR5: forward kinematics, a frame Jacobian,
//! inverse and forward dynamics, the mass matrix and IK through the `Robot` facade, then
//! the same RNEA through the Model/Data functions underneath.
//!
//! `cargo run --release --no-default-features --example kinematics_dynamics`

use armsim::{dynamics, Expressed, IkOptions, Robot};

pub fn main() -> Result<(), armsim::RobotError> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf");
    let mut robot = Robot::from_file(path)?;
    println!("{}: joints {:?}", robot.model().name, robot.joint_names());

    let tool = robot.frame("tool0")?;
    let q = [0.0, -1.0, 1.2, -0.4, 1.4, 0.3];
    let v = [0.1, 0.0, -0.2, 0.0, 0.3, 0.0];
    let pose = robot.fk(&q)?.pose(tool);
    println!("tool0 at {:.4?}", pose.trans.as_slice());

    let j = robot.jacobian(&q, tool, Expressed::WorldAligned)?;
    println!(
        "Jacobian {}×{}, first column {:.4?}",
        j.nrows(),
        j.ncols(),
        j.column(0).iter().collect::<Vec<_>>()
    );

    let tau = robot.rnea(&q, &v, &[0.0; 6])?.to_vec();
    println!(
        "tau (gravity {:?}) = {:.4?}",
        robot.gravity().as_slice(),
        tau
    );
    let qdd = robot.aba(&q, &v, &tau)?;
    println!(
        "aba(rnea) = {:.3?} (zero: the accelerations RNEA was given)",
        qdd
    );
    let m = robot.crba(&q)?;
    println!("M[0][0] = {:.4} kg m²", m[(0, 0)]);

    let sol = robot.ik(tool, &pose, &IkOptions::default())?;
    println!(
        "ik: {:?}, {:.1e} m, {}",
        sol.status, sol.position_error, sol.reason
    );

    // The same inverse dynamics through the low-level API (what the facade calls).
    let (model, data) = robot.model_data();
    let low = dynamics::rnea(model, data, &q, &v, &[0.0; 6]);
    assert_eq!(low, tau.as_slice());
    println!("low-level rnea agrees bit for bit");
    Ok(())
}
