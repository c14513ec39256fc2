//! How [`topp`](fn@super::topp) is asked to solve ([`ToppMethod`], [`ToppOptions`]) and
//! the figures it reports ([`ToppStats`]).

/// Which solver [`topp`](fn@super::topp) uses for the discretised problem (the same problem either way).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ToppMethod {
    /// TOPP-RA: controllable sets backward, greedy forward, two-variable LPs.
    #[default]
    Reachability,
    /// The second-order-cone program, solved by clarabel.
    Conic,
}

/// Options of [`topp`](fn@super::topp).
#[derive(Clone, Debug)]
pub struct ToppOptions {
    /// Grid intervals `N` along `s`.
    pub segments: usize,
    /// Dense check points per interval (besides its two ends).
    pub check_points: usize,
    /// Refinement rounds (re-solves that tighten a limit) allowed after the first solve
    /// (default 30: a reachability re-solve costs well under a millisecond, and its
    /// bang–bang optima may move an excess between neighbouring intervals for a few more
    /// rounds than the conic solver's).
    pub max_refinements: usize,
    /// Accepted relative excess in the dense check (`|x| ≤ (1 + tol) limit`).
    pub tolerance: f64,
    /// Extra relative tightening added to each excess found.
    pub margin: f64,
    /// Grid grading `β ∈ [0, 1)`: `s_i = φ(i/N)` with `φ(u) = u − β sin(2πu)/(2π)`, so
    /// intervals at the ends are `1 − β` times the uniform `1/N` (paths that start and
    /// end at rest, like the minimum-jerk spline, have `q' → 0` there and need the
    /// resolution); 0 gives a uniform grid.
    pub end_refinement: f64,
    /// Solver of the discretised problem.
    pub method: ToppMethod,
}

impl Default for ToppOptions {
    fn default() -> Self {
        ToppOptions {
            segments: 400,
            check_points: 8,
            max_refinements: 30,
            tolerance: 1e-9,
            margin: 1e-8,
            end_refinement: 0.75,
            method: ToppMethod::default(),
        }
    }
}

/// Figures of a TOPP solve.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ToppStats {
    /// Duration of the motion (s), jerk smoothing included.
    pub duration: f64,
    /// Duration of the time-optimal motion without the jerk limit (s).
    pub optimal_duration: f64,
    /// Grid intervals.
    pub segments: usize,
    /// Solver used.
    pub method: ToppMethod,
    /// Solves of the discretised problem (1 + refinements + friction rounds).
    pub solves: usize,
    /// Interior-point iterations over all solves (conic), or two-variable LPs solved
    /// (reachability).
    pub solver_iterations: u32,
    /// Time inside the solver over all solves (s).
    pub solve_time_s: f64,
    /// Wall time of the whole [`topp`](fn@super::topp) call (s).
    pub wall_time_s: f64,
    /// Largest `|q̇_j| / v_j` on the dense check grid.
    pub max_velocity_ratio: f64,
    /// Largest `|q̈_j| / a_j` on the dense check grid.
    pub max_acceleration_ratio: f64,
    /// Largest `|τ_j| / τ_max,j` on the dense check grid (0 without torque limits).
    pub max_torque_ratio: f64,
    /// Largest `|q⃛_j| / j_j` on the dense check grid (0 without jerk limits).
    pub max_jerk_ratio: f64,
    /// Jerk smoothing: the window of the moving average of `s(t)` (s; 0 without).
    pub jerk_window_s: f64,
    /// Jerk smoothing: the uniform slow-down factor applied after it (1 without).
    pub jerk_slowdown: f64,
}
