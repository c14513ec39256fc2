//! Flexible rotors (docs/reference_data.md §M7; textbook vol. 2 ch. 16): a shaft of uniform
//! segments (Euler–Bernoulli, no shear, no gyroscopics) carrying point discs on rigid or
//! elastic bearings, in one plane of whirl. Critical speeds and mode shapes by finite
//! elements (this file; Hermite cubic elements with the consistent mass matrix,
//! `K x = ω² M x` by Cholesky and the symmetric eigen-solver), checked by the exact
//! transfer matrices of [`crate::machines::vibration::rotor_transfer`].
//!
//! A uniform pinned–pinned shaft has `ω_n = n² π² sqrt(EI/(μ l⁴))` and modes
//! `sin(nπx/l)`; the finite elements converge to them as `h⁴`. The rotor counts as rigid
//! while its top speed stays below `0.8 ω_1`.

use nalgebra::{Cholesky, DMatrix, DVector, SymmetricEigen};

/// A uniform shaft segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Length (m).
    pub length: f64,
    /// Bending stiffness `EI` (N m²).
    pub ei: f64,
    /// Mass per length `μ` (kg/m).
    pub mu: f64,
}

impl Segment {
    /// A solid or hollow circular segment of material `(E, ρ)`.
    pub fn circular(length: f64, d: f64, d_inner: f64, e: f64, rho: f64) -> Self {
        let i = std::f64::consts::PI * (d.powi(4) - d_inner.powi(4)) / 64.0;
        let a = std::f64::consts::PI * (d * d - d_inner * d_inner) / 4.0;
        Self {
            length,
            ei: e * i,
            mu: rho * a,
        }
    }
}

/// A point disc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    /// Axial position (m).
    pub at: f64,
    /// Mass (kg).
    pub mass: f64,
    /// Unbalance `m e` (kg m).
    pub unbalance: f64,
    /// Its angle (rad).
    pub phase: f64,
}

/// A bearing: rigid (`None`) or a radial spring (N/m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bearing {
    /// Axial position (m).
    pub at: f64,
    /// Stiffness; `None` = rigid.
    pub stiffness: Option<f64>,
}

/// A rotor.
#[derive(Clone, Debug, PartialEq)]
pub struct FlexibleRotor {
    /// Segments from `x = 0`.
    pub segments: Vec<Segment>,
    /// Discs.
    pub discs: Vec<Disc>,
    /// Bearings.
    pub bearings: Vec<Bearing>,
}

/// A mode.
#[derive(Clone, Debug, PartialEq)]
pub struct RotorMode {
    /// Critical speed (rad/s).
    pub omega: f64,
    /// Node positions (m).
    pub x: Vec<f64>,
    /// Deflection at the nodes, largest magnitude 1, first clear value positive.
    pub y: Vec<f64>,
    /// Slopes at the nodes (same scale).
    pub slope: Vec<f64>,
    /// Generalised mass `φᵀ M φ` of this scaling (kg).
    pub modal_mass: f64,
}

impl RotorMode {
    /// The deflection at `x` by Hermite interpolation in the element holding it.
    pub fn at(&self, x: f64) -> f64 {
        let k = self
            .x
            .partition_point(|&n| n <= x)
            .clamp(1, self.x.len() - 1);
        let (x0, x1) = (self.x[k - 1], self.x[k]);
        let h = x1 - x0;
        let s = ((x - x0) / h).clamp(0.0, 1.0);
        let (h1, h2) = (
            1.0 - 3.0 * s * s + 2.0 * s.powi(3),
            h * (s - 2.0 * s * s + s.powi(3)),
        );
        let (h3, h4) = (3.0 * s * s - 2.0 * s.powi(3), h * (-s * s + s.powi(3)));
        h1 * self.y[k - 1] + h2 * self.slope[k - 1] + h3 * self.y[k] + h4 * self.slope[k]
    }
}

impl FlexibleRotor {
    /// Total length (m).
    pub fn length(&self) -> f64 {
        self.segments.iter().map(|s| s.length).sum()
    }

    /// The segment at `x` (the left one at a joint).
    pub fn segment_at(&self, x: f64) -> Segment {
        let mut acc = 0.0;
        for s in &self.segments {
            acc += s.length;
            if x < acc {
                return *s;
            }
        }
        *self.segments.last().expect("a rotor has segments")
    }

    /// Station positions: segment joints, discs and bearings, sorted and merged.
    pub fn stations(&self) -> Vec<f64> {
        let mut v = vec![0.0];
        let mut acc = 0.0;
        for s in &self.segments {
            acc += s.length;
            v.push(acc);
        }
        v.extend(self.discs.iter().map(|d| d.at));
        v.extend(self.bearings.iter().map(|b| b.at));
        v.sort_by(f64::total_cmp);
        let tol = 1e-12 * acc.max(1.0);
        v.dedup_by(|a, b| (*a - *b).abs() <= tol);
        v
    }

    /// Finite-element nodes: the stations, each interval split into pieces of about
    /// `length / elements`.
    pub fn nodes(&self, elements: usize) -> Vec<f64> {
        let st = self.stations();
        let h = self.length() / elements.max(1) as f64;
        let mut x = vec![st[0]];
        for w in st.windows(2) {
            let n = ((w[1] - w[0]) / h).round().max(1.0) as usize;
            for k in 1..=n {
                x.push(w[0] + (w[1] - w[0]) * k as f64 / n as f64);
            }
        }
        x
    }

    /// Global stiffness and mass matrices over `nodes` (DOFs `y_i, θ_i`), with discs
    /// and spring bearings; and the indices of the rigidly held DOFs.
    pub fn matrices(&self, x: &[f64]) -> (DMatrix<f64>, DMatrix<f64>, Vec<usize>) {
        let n = 2 * x.len();
        let (mut k, mut m) = (DMatrix::zeros(n, n), DMatrix::zeros(n, n));
        for e in 0..x.len() - 1 {
            let h = x[e + 1] - x[e];
            let s = self.segment_at(0.5 * (x[e] + x[e + 1]));
            let ke = [
                [12.0, 6.0 * h, -12.0, 6.0 * h],
                [6.0 * h, 4.0 * h * h, -6.0 * h, 2.0 * h * h],
                [-12.0, -6.0 * h, 12.0, -6.0 * h],
                [6.0 * h, 2.0 * h * h, -6.0 * h, 4.0 * h * h],
            ];
            let me = [
                [156.0, 22.0 * h, 54.0, -13.0 * h],
                [22.0 * h, 4.0 * h * h, 13.0 * h, -3.0 * h * h],
                [54.0, 13.0 * h, 156.0, -22.0 * h],
                [-13.0 * h, -3.0 * h * h, -22.0 * h, 4.0 * h * h],
            ];
            let (kf, mf) = (s.ei / h.powi(3), s.mu * h / 420.0);
            for i in 0..4 {
                for j in 0..4 {
                    k[(2 * e + i, 2 * e + j)] += kf * ke[i][j];
                    m[(2 * e + i, 2 * e + j)] += mf * me[i][j];
                }
            }
        }
        let node = |p: f64| {
            x.iter()
                .enumerate()
                .min_by(|a, b| (a.1 - p).abs().total_cmp(&(b.1 - p).abs()))
                .map(|(i, _)| i)
                .unwrap_or(0)
        };
        for d in &self.discs {
            m[(2 * node(d.at), 2 * node(d.at))] += d.mass;
        }
        let mut held = Vec::new();
        for b in &self.bearings {
            let i = 2 * node(b.at);
            match b.stiffness {
                Some(c) => k[(i, i)] += c,
                None => held.push(i),
            }
        }
        held.sort_unstable();
        held.dedup();
        (k, m, held)
    }
}

fn reduce(a: &DMatrix<f64>, free: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(free.len(), free.len(), |i, j| a[(free[i], free[j])])
}

/// The lowest `count` modes by finite elements with about `elements` elements; `None`
/// when the mass matrix is not positive definite (no mass) or the rotor floats (fewer
/// than two constraints make rigid-body modes, reported as speed 0).
pub fn fe_modes(rotor: &FlexibleRotor, elements: usize, count: usize) -> Option<Vec<RotorMode>> {
    let x = rotor.nodes(elements);
    let (k, m, held) = rotor.matrices(&x);
    let free: Vec<usize> = (0..k.nrows()).filter(|i| !held.contains(i)).collect();
    let (kr, mr) = (reduce(&k, &free), reduce(&m, &free));
    let l = Cholesky::new(mr.clone())?.l();
    let linv = l.clone().try_inverse()?;
    let a = &linv * kr * linv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eig = SymmetricEigen::new(a);
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let mut out = Vec::new();
    for &i in order.iter().take(count) {
        let v: DVector<f64> = linv.transpose() * eig.eigenvectors.column(i);
        let mut full = DVector::zeros(k.nrows());
        for (r, &f) in free.iter().enumerate() {
            full[f] = v[r];
        }
        let y: Vec<f64> = (0..x.len()).map(|n| full[2 * n]).collect();
        let big = y.iter().fold(0.0f64, |b, v| b.max(v.abs()));
        let first = y
            .iter()
            .find(|v| v.abs() > 1e-6 * big)
            .copied()
            .unwrap_or(1.0);
        let scale = first.signum() / big;
        let full = full * scale;
        let modal_mass = (full.transpose() * &m * &full)[(0, 0)];
        out.push(RotorMode {
            omega: eig.eigenvalues[i].max(0.0).sqrt(),
            y: (0..x.len()).map(|n| full[2 * n]).collect(),
            slope: (0..x.len()).map(|n| full[2 * n + 1]).collect(),
            x: x.clone(),
            modal_mass,
        });
    }
    Some(out)
}

/// `ω_n = n² π² sqrt(EI/(μ l⁴))`: a uniform pinned–pinned shaft.
pub fn pinned_pinned_speed(n: usize, ei: f64, mu: f64, l: f64) -> f64 {
    (n * n) as f64 * std::f64::consts::PI.powi(2) * (ei / (mu * l.powi(4))).sqrt()
}

/// Steady unbalance response at `omega` (rad/s): deflection amplitude at the nodes by a
/// direct solve of `(K − ω² M) y = ω² U` (the in-phase and quadrature parts of the
/// rotating unbalance, no damping); `None` at a critical speed.
pub fn unbalance_response(
    rotor: &FlexibleRotor,
    elements: usize,
    omega: f64,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let x = rotor.nodes(elements);
    let (k, m, held) = rotor.matrices(&x);
    let free: Vec<usize> = (0..k.nrows()).filter(|i| !held.contains(i)).collect();
    let a = reduce(&(k - m * (omega * omega)), &free);
    let lu = a.lu();
    let mut amp = vec![0.0; x.len()];
    for part in [0usize, 1] {
        let mut f = DVector::zeros(free.len());
        for d in &rotor.discs {
            let n = x
                .iter()
                .enumerate()
                .min_by(|a, b| (a.1 - d.at).abs().total_cmp(&(b.1 - d.at).abs()))
                .map(|(i, _)| i)?;
            if let Some(r) = free.iter().position(|&g| g == 2 * n) {
                let c = if part == 0 {
                    d.phase.cos()
                } else {
                    d.phase.sin()
                };
                f[r] += omega * omega * d.unbalance * c;
            }
        }
        let y = lu.solve(&f)?;
        for (r, &g) in free.iter().enumerate() {
            if g % 2 == 0 {
                amp[g / 2] += y[r] * y[r];
            }
        }
    }
    Some((x, amp.into_iter().map(f64::sqrt).collect()))
}
