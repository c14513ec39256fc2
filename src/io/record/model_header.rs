//! [`Header::for_model`]: the recording header of a model — joint names, effort limits,
//! static transforms and robot description — with the [`RobotTf`] that makes its frames.
//! The robot description names every mesh that resolves on this machine by its absolute
//! `file://` URI ([`absolute_mesh_uris`]).

use crate::collision::resolve::PackagePaths;
use crate::io::record::tf::RobotTf;
use crate::io::record::urdf_out::{absolute_mesh_uris, robot_description};
use crate::io::record::Header;
use crate::model::{Model, ModelSpec};
use std::path::Path;

impl Header {
    /// The header for recording `model` (built from `spec`, read from `model_path`), named
    /// `name`, without metadata; and the [`RobotTf`] whose
    /// [`frame_at`](RobotTf::frame_at) makes the frames. `package://` mesh URIs are
    /// searched with the environment's package paths only.
    pub fn for_model(
        name: impl Into<String>,
        model_path: &Path,
        model: &Model,
        spec: &ModelSpec,
    ) -> (Header, RobotTf) {
        let pkgs = PackagePaths::from_env(Vec::new());
        Self::for_model_with(name, model_path, model, spec, Some(&pkgs))
    }

    /// [`Header::for_model`] with the package paths `pkgs` for `package://` mesh URIs;
    /// `None` keeps the description's mesh URIs as written (for viewers that resolve
    /// `package://` themselves, e.g. with `ROS_PACKAGE_PATH`).
    pub fn for_model_with(
        name: impl Into<String>,
        model_path: &Path,
        model: &Model,
        spec: &ModelSpec,
        pkgs: Option<&PackagePaths>,
    ) -> (Header, RobotTf) {
        let robot_tf = RobotTf::new(model, spec);
        let mut text = robot_description(model_path, spec);
        if let Some(pkgs) = pkgs {
            text = absolute_mesh_uris(&text, model_path.parent(), pkgs).0;
        }
        let header = Header {
            name: name.into(),
            joint_names: model.dof_names(),
            effort_limits: model
                .effort_limit
                .iter()
                .map(|&e| e.is_finite().then_some(e))
                .collect(),
            static_tf: robot_tf.static_transforms(),
            robot_description: Some(text),
            metadata: Vec::new(),
            epoch_ns: None,
        };
        (header, robot_tf)
    }
}
