//! [`Header::for_model`]: the recording header of a model — joint names, effort limits,
//! static transforms and robot description — with the [`RobotTf`] that makes its frames.

use super::tf::RobotTf;
use super::urdf_out::robot_description;
use super::Header;
use crate::model::{Model, ModelSpec};
use std::path::Path;

impl Header {
    /// The header for recording `model` (built from `spec`, read from `model_path`), named
    /// `name`, without metadata; and the [`RobotTf`] whose
    /// [`frame_at`](RobotTf::frame_at) makes the frames.
    pub fn for_model(
        name: impl Into<String>,
        model_path: &Path,
        model: &Model,
        spec: &ModelSpec,
    ) -> (Header, RobotTf) {
        let robot_tf = RobotTf::new(model, spec);
        let header = Header {
            name: name.into(),
            joint_names: model.dof_names(),
            effort_limits: model
                .effort_limit
                .iter()
                .map(|&e| e.is_finite().then_some(e))
                .collect(),
            static_tf: robot_tf.static_transforms(),
            robot_description: Some(robot_description(model_path, spec)),
            metadata: Vec::new(),
            epoch_ns: None,
        };
        (header, robot_tf)
    }
}
