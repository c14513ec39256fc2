//! Follower motion laws and dwell–rise–dwell–return timing (docs/reference_data.md §M3,
//! program CAMLAN). A law gives the lift fraction and its derivatives in `u = φ/Φ`;
//! [`MotionLaw`] turns them into `s(φ)` and the geometric derivatives `s' = ds/dφ`, `s''`,
//! `s'''` over the whole turn (the return is `h − law`, with the signs flipped).

use std::f64::consts::PI;

/// A follower displacement over the turn: a law with its timing ([`MotionLaw`]) or a
/// table or diagram ([`crate::machines::cams::motion_table::MotionTable`]).
pub trait Displacement {
    /// `[s, s', s'', s''']` at `φ` (geometric derivatives, per radian of cam angle).
    fn eval(&self, phi: f64) -> [f64; 4];
    /// The lift `max s − min s`.
    fn stroke(&self) -> f64;
    /// Cam angles (rad, in `[0, 2π)`) where a derivative may jump: segment ends.
    fn breakpoints(&self) -> Vec<f64>;
    /// The size of the `order`-th derivative, against which a jump is judged.
    fn derivative_scale(&self, order: usize) -> f64;
}

/// A rise (or return) law.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Law {
    /// Constant velocity `s = h u` (Archimedean spiral); infinite acceleration at the ends.
    Uniform,
    /// Constant acceleration then deceleration, `2hu²` / `h(−2u² + 4u − 1)`.
    Parabolic,
    /// Cosine acceleration `h(1 − cos πu)/2`.
    Harmonic,
    /// Sine acceleration `h(u − sin 2πu/(2π))`.
    Cycloidal,
    /// Linear acceleration `h u²(3 − 2u)`.
    Cubic,
    /// The 3-4-5 polynomial `h(10u³ − 15u⁴ + 6u⁵)`.
    Polynomial345,
}

impl Law {
    /// From its TOML name.
    pub fn parse(s: &str) -> Option<Law> {
        Some(match s {
            "uniform" => Law::Uniform,
            "parabolic" => Law::Parabolic,
            "harmonic" => Law::Harmonic,
            "cycloidal" => Law::Cycloidal,
            "cubic" => Law::Cubic,
            "polynomial" | "polynomial_345" => Law::Polynomial345,
            _ => return None,
        })
    }

    /// `(f, f', f'', f''')` with `f(0) = 0`, `f(1) = 1`, derivatives in `u`. At the switch
    /// point of the parabolic law (`u = 1/2`) the deceleration branch is taken.
    pub fn eval(self, u: f64) -> [f64; 4] {
        match self {
            Law::Uniform => [u, 1.0, 0.0, 0.0],
            Law::Parabolic => {
                if u < 0.5 {
                    [2.0 * u * u, 4.0 * u, 4.0, 0.0]
                } else {
                    [-2.0 * u * u + 4.0 * u - 1.0, -4.0 * u + 4.0, -4.0, 0.0]
                }
            }
            Law::Harmonic => {
                let (s, c) = (PI * u).sin_cos();
                [
                    (1.0 - c) / 2.0,
                    PI * s / 2.0,
                    PI * PI * c / 2.0,
                    -PI.powi(3) * s / 2.0,
                ]
            }
            Law::Cycloidal => {
                let (s, c) = (2.0 * PI * u).sin_cos();
                [u - s / (2.0 * PI), 1.0 - c, 2.0 * PI * s, 4.0 * PI * PI * c]
            }
            Law::Cubic => [
                u * u * (3.0 - 2.0 * u),
                6.0 * (u - u * u),
                6.0 * (1.0 - 2.0 * u),
                -12.0,
            ],
            Law::Polynomial345 => {
                let (u2, u3) = (u * u, u * u * u);
                [
                    10.0 * u3 - 15.0 * u3 * u + 6.0 * u3 * u2,
                    30.0 * u2 - 60.0 * u3 + 30.0 * u2 * u2,
                    60.0 * u - 180.0 * u2 + 120.0 * u3,
                    60.0 - 360.0 * u + 360.0 * u2,
                ]
            }
        }
    }
}

/// Dwell–rise–dwell–return timing with a lift `h` (mm, or radians of swing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionLaw {
    /// Lift.
    pub stroke: f64,
    /// Rise angle, top dwell, return angle (rad); the bottom dwell is the rest of the turn.
    pub rise: f64,
    /// Top dwell (rad).
    pub dwell_top: f64,
    /// Return (rad).
    pub ret: f64,
    /// Rise law.
    pub rise_law: Law,
    /// Return law.
    pub return_law: Law,
}

/// Which part of the cycle an angle falls in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Rising.
    Rise,
    /// Top dwell.
    DwellTop,
    /// Returning.
    Return,
    /// Bottom dwell.
    DwellBottom,
}

impl MotionLaw {
    /// The bottom dwell `2π − (rise + dwell + return)`.
    pub fn dwell_bottom(&self) -> f64 {
        2.0 * PI - self.rise - self.dwell_top - self.ret
    }

    /// Phase at `φ` (rad, wrapped to one turn).
    pub fn phase(&self, phi: f64) -> Phase {
        let p = phi.rem_euclid(2.0 * PI);
        if p < self.rise {
            Phase::Rise
        } else if p < self.rise + self.dwell_top {
            Phase::DwellTop
        } else if p < self.rise + self.dwell_top + self.ret {
            Phase::Return
        } else {
            Phase::DwellBottom
        }
    }

    /// `[s, s', s'', s''']` at `φ` (geometric derivatives, per radian of cam angle).
    pub fn eval(&self, phi: f64) -> [f64; 4] {
        let p = phi.rem_euclid(2.0 * PI);
        let h = self.stroke;
        match self.phase(p) {
            Phase::Rise => {
                let f = self.rise_law.eval(p / self.rise);
                let k = self.rise;
                [
                    h * f[0],
                    h * f[1] / k,
                    h * f[2] / (k * k),
                    h * f[3] / (k * k * k),
                ]
            }
            Phase::DwellTop => [h, 0.0, 0.0, 0.0],
            Phase::Return => {
                let k = self.ret;
                let f = self.return_law.eval((p - self.rise - self.dwell_top) / k);
                [
                    h * (1.0 - f[0]),
                    -h * f[1] / k,
                    -h * f[2] / (k * k),
                    -h * f[3] / (k * k * k),
                ]
            }
            Phase::DwellBottom => [0.0; 4],
        }
    }
}

impl Displacement for MotionLaw {
    fn eval(&self, phi: f64) -> [f64; 4] {
        MotionLaw::eval(self, phi)
    }

    fn stroke(&self) -> f64 {
        self.stroke
    }

    fn breakpoints(&self) -> Vec<f64> {
        let (r, d, t) = (self.rise, self.dwell_top, self.ret);
        vec![0.0, r / 2.0, r, r + d, r + d + t / 2.0, r + d + t]
    }

    fn derivative_scale(&self, order: usize) -> f64 {
        self.stroke / self.rise.min(self.ret).powi(order as i32)
    }
}
