//! Bodies joined by ropes (docs/reference_data.md §M4, problem book ch. 5): a chain of
//! blocks or carts, each on its own plane (or hanging), the rope between neighbours led
//! over a pulley of efficiency `η`; sliding or rolling resistance per body, static and
//! kinetic. Newton's second law along each body's path gives the acceleration, the rope
//! tensions, which way it moves (or that static friction holds it) and the force that
//! starts it or keeps it moving uniformly.
//!
//! Bodies `0 … n−1`; the system moves *forward* when every body moves toward the next
//! one's side (body 0 at the back). Body `k` moves along a path at `s_k` below the
//! horizontal when the system moves forward (90° a falling weight, −30° pulled up a 30°
//! incline, 0 level). Along that path it has the driving force
//! `G_k = m_k g sin s_k + P_k` (`P_k` an applied force), the normal force
//! `N_k = m_k g cos s_k` and the resistance `R_k = w_k N_k` (`w` a sliding coefficient
//! `f`, or a rolling equivalent such as `(k + f r)/R`), opposite the motion.
//! Rope `k` (bodies `k`, `k + 1`) passes a pulley whose tension ratio is
//! `c_k = T_behind/T_ahead = η_k` moving forward (the side the rope runs to pulls harder)
//! and `1/η_k` backward. Each body: `μ_k a = G_k ∓ R_k + T_k^ahead − T_{k−1}^behind`
//! (`μ_k = m_k + m_k^rot`, the translational mass of what turns with it, `J/ρ²`); the
//! tension ratios chain the equations into
//!
//! `a = Σ q_k (G_k ∓ R_k) / Σ q_k μ_k`, with `q_0 = 1`, `q_{k+1} = q_k c_k`,
//!
//! and a force `P` on body `p` enters as `q_p P`. At rest the chain starts forward when
//! `Σ q_k (G_k − R_k^s) > 0` (static coefficients), backward when `Σ q_k (G_k + R_k^s) < 0`
//! (with the backward `q`), and otherwise static friction holds it.

/// One body of the chain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RopedBody {
    /// Mass `m` (kg).
    pub mass: f64,
    /// Angle of its path below the horizontal when the chain moves forward, `s` (rad).
    pub slope: f64,
    /// Kinetic resistance coefficient `w` (sliding `f`, or a rolling equivalent).
    pub friction: f64,
    /// Static coefficient (≥ the kinetic one).
    pub static_friction: f64,
    /// Translational mass of the parts turning with it, `J/ρ²` (kg): inertia only.
    pub rotating_mass: f64,
    /// Applied force along its forward path (N).
    pub force: f64,
}

/// Which way the chain goes from rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChainMotion {
    /// Every body toward the next one's side.
    Forward,
    /// The other way.
    Backward,
    /// Static friction holds it.
    Rest,
}

/// A chain of bodies on its planes: see the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    /// The bodies, back to front.
    pub bodies: Vec<RopedBody>,
    /// Pulley efficiency of each rope (`n − 1` values, 1 for an ideal pulley).
    pub pulley_efficiency: Vec<f64>,
    /// `g` (m/s²).
    pub gravity: f64,
}

/// The chain moving one way with kinetic friction.
#[derive(Clone, Debug, PartialEq)]
pub struct Moving {
    /// Acceleration along the forward direction (m/s²; negative: decelerating forward,
    /// or speeding up backward).
    pub acceleration: f64,
    /// Each rope's tension at its back end (body `k`) and its front end (body `k + 1`).
    pub tensions: Vec<[f64; 2]>,
    /// Each body's resistance `w N` (N, opposite the motion).
    pub resistances: Vec<f64>,
}

impl Chain {
    /// Driving force along each body's forward path, `m g sin s + P`.
    pub fn driving(&self) -> Vec<f64> {
        let g = self.gravity;
        self.bodies
            .iter()
            .map(|b| b.mass * g * b.slope.sin() + b.force)
            .collect()
    }

    /// Normal force of each body on its plane, `m g cos s` (0 for a hanging weight).
    pub fn normals(&self) -> Vec<f64> {
        self.bodies
            .iter()
            .map(|b| {
                // A hanging weight (±90°) presses on nothing (cos 90° is not exactly 0).
                let hanging = (b.slope.abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-12;
                if hanging {
                    0.0
                } else {
                    (b.mass * self.gravity * b.slope.cos()).max(0.0)
                }
            })
            .collect()
    }

    /// The tension weights `q_k` (`q_0 = 1`, `q_{k+1} = q_k c_k`) moving forward
    /// (`dir = 1`) or backward (`dir = −1`).
    pub fn weights(&self, dir: f64) -> Vec<f64> {
        let mut q = vec![1.0];
        for &eta in &self.pulley_efficiency {
            let c = if dir > 0.0 { eta } else { 1.0 / eta };
            q.push(q[q.len() - 1] * c);
        }
        q
    }

    /// `Σ q_k (G_k − dir w_k N_k)`: the net force (in the front body's terms) moving
    /// `dir` with coefficients `w` (kinetic or static).
    fn net(&self, dir: f64, stat: bool) -> f64 {
        let q = self.weights(dir);
        let (g, n) = (self.driving(), self.normals());
        self.bodies
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let w = if stat { b.static_friction } else { b.friction };
                q[k] * (g[k] - dir * w * n[k])
            })
            .sum()
    }

    /// Which way it goes from rest (static coefficients).
    pub fn motion_from_rest(&self) -> ChainMotion {
        if self.net(1.0, true) > 0.0 {
            ChainMotion::Forward
        } else if self.net(-1.0, true) < 0.0 {
            ChainMotion::Backward
        } else {
            ChainMotion::Rest
        }
    }

    /// The force along body `p`'s forward path that holds the chain on the point of
    /// moving `dir` (static: starting it; kinetic: keeping it moving uniformly):
    /// `P = −Σ q_k (G_k − dir w_k N_k) / q_p`. Forward, the push needed (≤ 0: it goes by
    /// itself); backward, the pull needed backward (≤ 0: it goes by itself).
    pub fn force_to_move(&self, p: usize, dir: f64, stat: bool) -> f64 {
        let q = self.weights(dir);
        -dir * self.net(dir, stat) / q[p]
    }

    /// The chain moving `dir` (kinetic coefficients): acceleration, tensions and
    /// resistances, from the body equations written out back to front.
    pub fn moving(&self, dir: f64) -> Moving {
        let q = self.weights(dir);
        let mu: f64 = self
            .bodies
            .iter()
            .zip(&q)
            .map(|(b, q)| q * (b.mass + b.rotating_mass))
            .sum();
        let a = self.net(dir, false) / mu;
        let (g, n) = (self.driving(), self.normals());
        let res: Vec<f64> = self
            .bodies
            .iter()
            .zip(&n)
            .map(|(b, n)| b.friction * n)
            .collect();
        let mut tensions = Vec::new();
        let mut pulled_back = 0.0; // the front end of the rope behind body k
        for (k, b) in self.bodies.iter().enumerate().take(self.bodies.len() - 1) {
            // μ a = G − dir R + T_ahead − T_behind, for rope k's back end T_ahead.
            let back = pulled_back + (b.mass + b.rotating_mass) * a - g[k] + dir * res[k];
            // Its front end: T_back/c_k, c_k = q_{k+1}/q_k.
            pulled_back = back * q[k] / q[k + 1];
            tensions.push([back, pulled_back]);
        }
        Moving {
            acceleration: a,
            tensions,
            resistances: res,
        }
    }
}
