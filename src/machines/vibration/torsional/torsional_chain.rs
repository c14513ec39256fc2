//! The torsional chain: rigid disks `J_k` on one axis joined by massless linear shafts
//! `c_k`, with absolute damping `a_k` (disk to ground) and relative damping `b_k` (across
//! shaft `k`). In absolute disk angles `φ` the equations of motion are
//!
//! `J φ̈ + B φ̇ + K φ = M(t)`,
//!
//! `J_k φ̈_k + (a_k + b_{k−1} + b_k) φ̇_k − b_{k−1} φ̇_{k−1} − b_k φ̇_{k+1}
//!  + (c_{k−1} + c_k) φ_k − c_{k−1} φ_{k−1} − c_k φ_{k+1} = M_k(t)`
//!
//! (docs/reference_data.md §S3; shafts `k` join disks `k` and `k+1`, 0-based, so `K` and the
//! relative part of `B` are tridiagonal and `J` is diagonal). The chain is free at both
//! ends (no stiffness to ground): `K` has the rigid-body null vector `(1, …, 1)`.
//!
//! The same chain is a serial chain of coaxial revolute joints whose coordinates are the
//! relative twists `q_0 = φ_0`, `q_k = φ_k − φ_{k−1}`: [`TorsionalChain::to_model`] builds
//! it as an armsim [`Model`], so the rigid-body engine (CRBA, ABA) sees the same inertia:
//! with `φ = L q` (`L` lower-triangular ones) the engine's mass matrix is `M = Lᵀ J L`,
//! the shafts are the diagonal joint stiffness `diag(0, c_0, …)` and the relative dampers
//! are the joints' viscous damping.

use crate::core::spatial::{Inertia, Mat3, Se3, Vec3};
use crate::model::{JointSpec, JointType, LinkSpec, Model, ModelError, ModelSpec};
use nalgebra::DMatrix;

/// An invalid chain parameter: which array, which entry, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}{}: {message}", index.map(|i| format!("[{i}]")).unwrap_or_default())]
pub struct ChainError {
    /// The parameter array, e.g. `inertia`, `stiffness`.
    pub field: String,
    /// The 0-based entry, where one entry is at fault.
    pub index: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl ChainError {
    pub(crate) fn new(field: &str, index: Option<usize>, message: impl Into<String>) -> Self {
        Self {
            field: field.into(),
            index,
            message: message.into(),
        }
    }
}

/// A free–free torsional chain of `n` disks and `n − 1` shafts (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct TorsionalChain {
    /// Disk names (unique), in chain order.
    pub names: Vec<String>,
    /// Disk inertias `J_k` (kg m²), > 0.
    pub inertia: Vec<f64>,
    /// Shaft stiffnesses `c_k` (N m/rad) between disks `k` and `k+1`, ≥ 0.
    pub stiffness: Vec<f64>,
    /// Absolute dampers `a_k` (N m s/rad), disk to ground, ≥ 0.
    pub absolute_damping: Vec<f64>,
    /// Relative dampers `b_k` (N m s/rad) across shaft `k`, ≥ 0.
    pub relative_damping: Vec<f64>,
}

fn check_values(field: &str, v: &[f64], len: usize, positive: bool) -> Result<(), ChainError> {
    if v.len() != len {
        return Err(ChainError::new(
            field,
            None,
            format!("{} values, expected {len}", v.len()),
        ));
    }
    for (i, &x) in v.iter().enumerate() {
        if !x.is_finite() {
            return Err(ChainError::new(field, Some(i), "not a finite number"));
        }
        if positive && x <= 0.0 {
            return Err(ChainError::new(
                field,
                Some(i),
                format!("must be positive, got {x}"),
            ));
        }
        if !positive && x < 0.0 {
            return Err(ChainError::new(
                field,
                Some(i),
                format!("must not be negative, got {x}"),
            ));
        }
    }
    Ok(())
}

impl TorsionalChain {
    /// An undamped chain. `stiffness` has one value fewer than `inertia`.
    pub fn new(
        names: Vec<String>,
        inertia: Vec<f64>,
        stiffness: Vec<f64>,
    ) -> Result<Self, ChainError> {
        let n = inertia.len();
        let chain = Self {
            names,
            absolute_damping: vec![0.0; n],
            relative_damping: vec![0.0; n.saturating_sub(1)],
            inertia,
            stiffness,
        };
        chain.validate()?;
        Ok(chain)
    }

    /// An undamped chain with names `m1`, `m2`, ….
    pub fn unnamed(inertia: Vec<f64>, stiffness: Vec<f64>) -> Result<Self, ChainError> {
        let names = (1..=inertia.len()).map(|k| format!("m{k}")).collect();
        Self::new(names, inertia, stiffness)
    }

    /// The same chain with damping (`absolute`: one per disk, `relative`: one per shaft).
    pub fn with_damping(
        mut self,
        absolute: Vec<f64>,
        relative: Vec<f64>,
    ) -> Result<Self, ChainError> {
        self.absolute_damping = absolute;
        self.relative_damping = relative;
        self.validate()?;
        Ok(self)
    }

    /// Checks sizes, signs and names.
    pub fn validate(&self) -> Result<(), ChainError> {
        let n = self.inertia.len();
        if n == 0 {
            return Err(ChainError::new("inertia", None, "the chain has no disks"));
        }
        check_values("inertia", &self.inertia, n, true)?;
        check_values("stiffness", &self.stiffness, n - 1, false)?;
        check_values("absolute_damping", &self.absolute_damping, n, false)?;
        check_values("relative_damping", &self.relative_damping, n - 1, false)?;
        if self.names.len() != n {
            return Err(ChainError::new(
                "names",
                None,
                format!("{} names for {n} disks", self.names.len()),
            ));
        }
        for (i, name) in self.names.iter().enumerate() {
            if name.trim().is_empty() {
                return Err(ChainError::new("names", Some(i), "empty name"));
            }
            if self.names[..i].contains(name) {
                return Err(ChainError::new(
                    "names",
                    Some(i),
                    format!("duplicate name '{name}'"),
                ));
            }
        }
        Ok(())
    }

    /// Number of disks.
    pub fn len(&self) -> usize {
        self.inertia.len()
    }

    /// Whether the chain has no disks (never, for a validated chain).
    pub fn is_empty(&self) -> bool {
        self.inertia.is_empty()
    }

    /// Shaft names `"a–b"` (disk names joined by an en dash).
    pub fn shaft_names(&self) -> Vec<String> {
        self.names
            .windows(2)
            .map(|w| format!("{}–{}", w[0], w[1]))
            .collect()
    }

    /// `J` as a dense diagonal matrix.
    pub fn inertia_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&self.inertia))
    }

    /// The tridiagonal stiffness matrix `K`.
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        tridiagonal(self.len(), &vec![0.0; self.len()], &self.stiffness)
    }

    /// The damping matrix `B` (absolute on the diagonal, relative tridiagonal).
    pub fn damping_matrix(&self) -> DMatrix<f64> {
        tridiagonal(self.len(), &self.absolute_damping, &self.relative_damping)
    }

    /// `out = K x` in O(n), no allocation.
    #[inline]
    pub fn apply_stiffness(&self, x: &[f64], out: &mut [f64]) {
        apply_tridiagonal(None, &self.stiffness, x, out);
    }

    /// `out = B v` in O(n), no allocation.
    #[inline]
    pub fn apply_damping(&self, v: &[f64], out: &mut [f64]) {
        apply_tridiagonal(Some(&self.absolute_damping), &self.relative_damping, v, out);
    }

    /// Shaft torques `c_k (φ_{k+1} − φ_k)` for absolute angles `phi`.
    pub fn shaft_torques(&self, phi: &[f64]) -> Vec<f64> {
        self.stiffness
            .iter()
            .zip(phi.windows(2))
            .map(|(c, w)| c * (w[1] - w[0]))
            .collect()
    }

    /// `L`: relative twists → absolute angles (`φ = L q`, lower-triangular ones). Its
    /// inverse `T = L⁻¹` maps absolute angles to twists (`q_k = φ_k − φ_{k−1}`).
    pub fn relative_to_absolute(&self) -> DMatrix<f64> {
        let n = self.len();
        DMatrix::from_fn(n, n, |i, j| if j <= i { 1.0 } else { 0.0 })
    }

    /// The chain as an armsim [`Model`]: link `ground` (fixed, massless), then one link per
    /// disk (thin disk of radius 1 m: mass `2J`, inertia `diag(J/2, J/2, J)` about its
    /// centre on the axis), joined by continuous joints about z, 1 m apart along z. Joint 0
    /// (`free`) is the absolute angle of disk 0; joint `k` (named after shaft `k−1`) is
    /// the twist of shaft `k−1` and carries its relative damping `b_{k−1}` as viscous
    /// joint damping. Shaft stiffness and absolute damping have no place in a URDF-like
    /// model; they are `diag(0, c)` in these coordinates and the caller's to add.
    pub fn to_model(&self) -> Result<Model, ModelError> {
        let n = self.len();
        let mut links = Vec::with_capacity(n + 1);
        let mut joints = Vec::with_capacity(n);
        links.push(LinkSpec::new("ground"));
        let shafts = self.shaft_names();
        for k in 0..n {
            let j = self.inertia[k];
            let mut l = LinkSpec::new(self.names[k].clone());
            l.inertial = Inertia::new(
                2.0 * j,
                Vec3::zeros(),
                Mat3::from_diagonal(&Vec3::new(0.5 * j, 0.5 * j, j)),
            );
            links.push(l);
            let (name, parent) = if k == 0 {
                ("free".to_string(), "ground".to_string())
            } else {
                (shafts[k - 1].clone(), self.names[k - 1].clone())
            };
            let mut js = JointSpec::new(name, JointType::Continuous, parent, self.names[k].clone());
            js.origin = Se3::from_translation(Vec3::new(0.0, 0.0, if k == 0 { 0.0 } else { 1.0 }));
            js.axis = Vec3::z();
            js.damping = if k == 0 {
                0.0
            } else {
                self.relative_damping[k - 1]
            };
            joints.push(js);
        }
        let spec = ModelSpec {
            name: "torsional_chain".into(),
            source: "<torsional chain>".into(),
            root_offset: Se3::identity(),
            links,
            joints,
            urdf_text: None,
            gravity: None,
            warnings: Vec::new(),
        };
        Model::build(spec).map(|(m, _)| m)
    }
}

/// `diag(d) + Σ_k c_k (e_k − e_{k+1})(e_k − e_{k+1})ᵀ`.
fn tridiagonal(n: usize, diag: &[f64], c: &[f64]) -> DMatrix<f64> {
    let mut m = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(diag));
    for (k, &ck) in c.iter().enumerate().take(n.saturating_sub(1)) {
        m[(k, k)] += ck;
        m[(k + 1, k + 1)] += ck;
        m[(k, k + 1)] -= ck;
        m[(k + 1, k)] -= ck;
    }
    m
}

/// `out = (diag(d) + tridiag(c)) x` without forming the matrix.
#[inline]
fn apply_tridiagonal(diag: Option<&[f64]>, c: &[f64], x: &[f64], out: &mut [f64]) {
    let n = x.len();
    match diag {
        Some(d) => {
            for k in 0..n {
                out[k] = d[k] * x[k];
            }
        }
        None => out[..n].fill(0.0),
    }
    for k in 0..n.saturating_sub(1) {
        let t = c[k] * (x[k] - x[k + 1]);
        out[k] += t;
        out[k + 1] -= t;
    }
}
