//! [`Robot`]: the common path in one object. A robot owns its immutable
//! [`Model`](crate::model::Model), one reusable [`Data`](crate::model::data::Data) workspace and
//! an IK solver, checks its inputs (lengths, finiteness, frame names) and returns errors
//! instead of panicking, takes gravity from the model, and allocates nothing per call
//! once built (IK excepted: it returns a new configuration).
//!
//! ```
//! use armsim::{Expressed, IkOptions, Robot};
//! # fn main() -> Result<(), armsim::RobotError> {
//! let mut robot = Robot::from_file(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf"))?;
//! let tool = robot.frame("tool0")?;
//! let q = [0.1, -1.2, 1.4, -0.3, 1.5, 0.2];
//! let pose = robot.fk(&q)?.pose(tool);
//! let j = robot.jacobian(&q, tool, Expressed::WorldAligned)?.clone();
//! let tau = robot.rnea(&q, &[0.0; 6], &[0.0; 6])?.to_vec();
//! let sol = robot.ik(tool, &pose, &IkOptions::default())?;
//! assert!(sol.converged() && sol.position_error < 1e-6);
//! assert_eq!((j.nrows(), j.ncols(), tau.len()), (6, 6, 6));
//! # Ok(())
//! # }
//! ```
//!
//! The functions underneath ([`crate::kinematics`], [`crate::dynamics`]) stay the API for
//! hot loops: `Robot::model` and `Robot::data` hand them out.

use crate::core::spatial::{Force, Se3, Vec3};
use crate::dynamics::{self, SingularMassMatrix};
use crate::kinematics::ik::{IkOptions, IkSolver, IkStatus};
use crate::kinematics::{self, Expressed};
use crate::model::data::Data;
use crate::model::{FrameId, LoadOptions, Model, ModelError, ModelWarning};
use nalgebra::DMatrix;
use std::path::Path;

/// Why a [`Robot`] call was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RobotError {
    /// The model file could not be loaded.
    #[error("{0}")]
    Model(#[from] ModelError),
    /// No link frame has that name.
    #[error("no frame '{name}'; the frames are: {known}")]
    UnknownFrame {
        /// The name asked for.
        name: String,
        /// The frames there are, comma-separated.
        known: String,
    },
    /// A vector has the wrong length.
    #[error("{what}: {got} values for {expected} coordinates")]
    Length {
        /// Which argument (`q`, `v`, `a`, `tau`, `f_ext`).
        what: &'static str,
        /// The model's count.
        expected: usize,
        /// What was passed.
        got: usize,
    },
    /// A value is NaN or infinite.
    #[error("{what}[{index}] is not finite")]
    NotFinite {
        /// Which argument.
        what: &'static str,
        /// The first bad entry.
        index: usize,
    },
    /// The frame index is not one of this model's frames.
    #[error("frame index {0} does not exist")]
    BadFrame(usize),
    /// Forward dynamics met a mass matrix that is not positive definite.
    #[error("{0}")]
    Singular(#[from] SingularMassMatrix),
    /// The model is too large for the dense algorithms (CRBA, CRBA + Cholesky).
    #[error("{0}")]
    TooLargeForDense(#[from] crate::model::data::TooManyDof),
}

/// The answer of [`Robot::ik`]: the configuration, how it ended, the residual and a
/// sentence saying why.
#[derive(Clone, Debug, PartialEq)]
pub struct IkSolution {
    /// Joint values (inside the limits when the options respect them).
    pub q: Vec<f64>,
    /// Converged, best effort (budget ran out while improving) or unreachable.
    pub status: IkStatus,
    /// Position error of `q`'s pose (m).
    pub position_error: f64,
    /// Rotation error of `q`'s pose (rad; 0 for position-only solves).
    pub rotation_error: f64,
    /// Iterations over all attempts.
    pub iterations: usize,
    /// Why it ended, in words.
    pub reason: String,
}

impl IkSolution {
    /// Whether both errors are within the tolerances.
    pub fn converged(&self) -> bool {
        self.status == IkStatus::Converged
    }
}

/// The placements computed by [`Robot::fk`], read by frame.
pub struct Placements<'a> {
    model: &'a Model,
    data: &'a Data,
}

impl Placements<'_> {
    /// The world placement of a frame.
    pub fn pose(&self, frame: FrameId) -> Se3 {
        kinematics::frame_placement(self.model, self.data, frame.0)
    }

    /// The world position of a frame's origin.
    pub fn translation(&self, frame: FrameId) -> Vec3 {
        self.pose(frame).trans
    }
}

/// A model with its workspace: kinematics, dynamics and IK by frame name (see the module
/// docs for an example).
pub struct Robot {
    model: Model,
    data: Data,
    jac: DMatrix<f64>,
    ik: IkSolver,
    warnings: Vec<ModelWarning>,
}

impl Robot {
    /// Loads a URDF or DH-table (`.toml`) file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Robot, RobotError> {
        Self::from_file_with(path, &LoadOptions::default())
    }

    /// Loads a model file with options (strict warnings, mimic joints as coordinates).
    pub fn from_file_with(path: impl AsRef<Path>, opts: &LoadOptions) -> Result<Robot, RobotError> {
        let (model, warnings) = Model::load_with(path, opts)?;
        Ok(Self::with_warnings(model, warnings))
    }

    /// Loads model text; `file` names it in messages and its extension (`.urdf`, `.xml`,
    /// `.toml`) picks the reader.
    pub fn load_str(text: &str, file: &str) -> Result<Robot, RobotError> {
        let (model, warnings) = Model::load_str(text, file, &LoadOptions::default())?;
        Ok(Self::with_warnings(model, warnings))
    }

    /// Wraps a model already built.
    pub fn from_model(model: Model) -> Robot {
        Self::with_warnings(model, Vec::new())
    }

    fn with_warnings(model: Model, warnings: Vec<ModelWarning>) -> Robot {
        let data = Data::new(&model);
        let jac = DMatrix::zeros(6, model.nv);
        let ik = IkSolver::new(&model);
        Robot {
            model,
            data,
            jac,
            ik,
            warnings,
        }
    }

    /// The model (for the low-level functions).
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The model and the workspace, for the low-level functions in hot loops.
    pub fn model_data(&mut self) -> (&Model, &mut Data) {
        (&self.model, &mut self.data)
    }

    /// The workspace as the last call left it.
    pub fn data(&self) -> &Data {
        &self.data
    }

    /// The loader's warnings.
    pub fn warnings(&self) -> &[ModelWarning] {
        &self.warnings
    }

    /// Number of coordinates (length of `q`, `v`, `a`, `tau`).
    pub fn nv(&self) -> usize {
        self.model.nv
    }

    /// The coordinates' joint names, in order.
    pub fn joint_names(&self) -> Vec<String> {
        self.model.dof_names()
    }

    /// The link frame names, in tree order.
    pub fn frame_names(&self) -> Vec<String> {
        self.model.links.iter().map(|l| l.name.clone()).collect()
    }

    /// The middle of the joint limits (0 for unbounded joints).
    pub fn neutral(&self) -> Vec<f64> {
        self.model.neutral()
    }

    /// The world gravity vector the dynamics use (from the model file; default
    /// `(0, 0, −9.81)`).
    pub fn gravity(&self) -> Vec3 {
        self.model.gravity
    }

    /// Changes the gravity the dynamics use.
    pub fn set_gravity(&mut self, g: Vec3) {
        self.model.gravity = g;
    }

    /// The frame called `name`.
    pub fn frame(&self, name: &str) -> Result<FrameId, RobotError> {
        self.model
            .frame(name)
            .ok_or_else(|| RobotError::UnknownFrame {
                name: name.to_string(),
                known: self.frame_names().join(", "),
            })
    }

    fn check(&self, what: &'static str, x: &[f64]) -> Result<(), RobotError> {
        if x.len() != self.model.nv {
            return Err(RobotError::Length {
                what,
                expected: self.model.nv,
                got: x.len(),
            });
        }
        match x.iter().position(|v| !v.is_finite()) {
            Some(index) => Err(RobotError::NotFinite { what, index }),
            None => Ok(()),
        }
    }

    fn check_frame(&self, f: FrameId) -> Result<(), RobotError> {
        if f.0 < self.model.links.len() {
            Ok(())
        } else {
            Err(RobotError::BadFrame(f.0))
        }
    }

    /// Forward kinematics at `q`; read the frames from the result.
    pub fn fk(&mut self, q: &[f64]) -> Result<Placements<'_>, RobotError> {
        self.check("q", q)?;
        kinematics::forward_kinematics(&self.model, &mut self.data, q);
        Ok(Placements {
            model: &self.model,
            data: &self.data,
        })
    }

    /// The world placement of one frame at `q`.
    pub fn pose(&mut self, q: &[f64], frame: FrameId) -> Result<Se3, RobotError> {
        self.check_frame(frame)?;
        Ok(self.fk(q)?.pose(frame))
    }

    /// The 6 × nv geometric Jacobian of `frame` at `q` (rows: linear, then angular) in
    /// the chosen expression.
    pub fn jacobian(
        &mut self,
        q: &[f64],
        frame: FrameId,
        expressed: Expressed,
    ) -> Result<&DMatrix<f64>, RobotError> {
        self.check("q", q)?;
        self.check_frame(frame)?;
        kinematics::compute_joint_jacobians(&self.model, &mut self.data, q);
        kinematics::frame_jacobian(&self.model, &self.data, frame.0, expressed, &mut self.jac);
        Ok(&self.jac)
    }

    /// Inverse dynamics `τ = M(q) a + C(q, v) v + g(q)` with the model's gravity.
    pub fn rnea(&mut self, q: &[f64], v: &[f64], a: &[f64]) -> Result<&[f64], RobotError> {
        self.check("q", q)?;
        self.check("v", v)?;
        self.check("a", a)?;
        Ok(dynamics::rnea(&self.model, &mut self.data, q, v, a))
    }

    /// [`Robot::rnea`] with external wrenches, one per body in the body frame.
    pub fn rnea_with_forces(
        &mut self,
        q: &[f64],
        v: &[f64],
        a: &[f64],
        f_ext: &[Force],
    ) -> Result<&[f64], RobotError> {
        self.check("q", q)?;
        self.check("v", v)?;
        self.check("a", a)?;
        if f_ext.len() != self.model.nbodies() {
            return Err(RobotError::Length {
                what: "f_ext",
                expected: self.model.nbodies(),
                got: f_ext.len(),
            });
        }
        Ok(dynamics::rnea_with_forces(
            &self.model,
            &mut self.data,
            q,
            v,
            a,
            f_ext,
        ))
    }

    /// The gravity torques `g(q)`.
    pub fn gravity_torque(&mut self, q: &[f64]) -> Result<&[f64], RobotError> {
        self.check("q", q)?;
        Ok(dynamics::gravity_torque(&self.model, &mut self.data, q))
    }

    /// The joint-space mass matrix `M(q)` (CRBA).
    pub fn crba(&mut self, q: &[f64]) -> Result<&DMatrix<f64>, RobotError> {
        self.check("q", q)?;
        crate::model::data::dense_fits(&self.model)?;
        Ok(dynamics::crba(&self.model, &mut self.data, q))
    }

    /// Forward dynamics `q̈` with the model's gravity: ABA, or CRBA + Cholesky when the
    /// model has mimic joints.
    pub fn aba(&mut self, q: &[f64], v: &[f64], tau: &[f64]) -> Result<&[f64], RobotError> {
        self.check("q", q)?;
        self.check("v", v)?;
        self.check("tau", tau)?;
        if self.model.has_mimic {
            crate::model::data::dense_fits(&self.model)?;
        }
        Ok(dynamics::forward_dynamics(
            &self.model,
            &mut self.data,
            q,
            v,
            tau,
        )?)
    }

    /// Kinetic energy `½ vᵀ M(q) v`.
    pub fn kinetic_energy(&mut self, q: &[f64], v: &[f64]) -> Result<f64, RobotError> {
        self.check("q", q)?;
        self.check("v", v)?;
        Ok(dynamics::kinetic_energy(&self.model, &mut self.data, q, v))
    }

    /// IK for `frame` reaching `target`, starting from the middle of the limits and then
    /// from random configurations (deterministic for `opts.seed`).
    pub fn ik(
        &mut self,
        frame: FrameId,
        target: &Se3,
        opts: &IkOptions,
    ) -> Result<IkSolution, RobotError> {
        self.ik_from(frame, target, None, opts)
    }

    /// [`Robot::ik`] starting from `seed` first.
    pub fn ik_from(
        &mut self,
        frame: FrameId,
        target: &Se3,
        seed: Option<&[f64]>,
        opts: &IkOptions,
    ) -> Result<IkSolution, RobotError> {
        self.check_frame(frame)?;
        if let Some(s) = seed {
            self.check("seed", s)?;
        }
        crate::model::data::dense_fits(&self.model)?;
        let r = self.ik.solve(&self.model, frame.0, target, seed, opts);
        let reason = match r.status {
            IkStatus::Converged => format!(
                "within {:e} m and {:e} rad after {} iterations and {} restarts",
                opts.tol_position, opts.tol_rotation, r.iterations, r.restarts
            ),
            IkStatus::BestEffort => format!(
                "the time budget ({:?}) ran out while improving: {:.3e} m, {:.3e} rad off",
                opts.time_budget, r.position_error, r.rotation_error
            ),
            IkStatus::Unreachable => format!(
                "every attempt stalled {:.3e} m and {:.3e} rad from the target: out of reach",
                r.position_error, r.rotation_error
            ),
        };
        Ok(IkSolution {
            q: r.q,
            status: r.status,
            position_error: r.position_error,
            rotation_error: r.rotation_error,
            iterations: r.iterations,
            reason,
        })
    }
}
