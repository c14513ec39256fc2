//! Vibration absorbers on a disk `J_r` excited at `ν = j w` (order `j`, shaft speed `w`)
//! (docs/reference_data.md §S3, textbook extras). Both replace the disk and its attachment by
//! an equivalent disk for the forced response.
//!
//! - **Tuned (spring) absorber**: a disk `J_a` on a spring `c_a` to `J_r`, tuned to
//!   `a = sqrt(c_a / J_a)`. From `(c_a − ν² J_a) φ_a = c_a φ_r` the spring torque on
//!   `J_r` is `−ν² J_a a²/(a² − ν²) φ_r`, so the disk acts with the effective inertia
//!   `I_r = J_r + J_a a² / (a² − j² w²)` — infinite (the disk stands still) when
//!   `a = j w`.
//! - **Viscous (Lanchester) damper**: `J_a` coupled to `J_r` only by a viscous damper `b`.
//!   The reaction on `J_r` is `(−ν² ΔI + iν b_r) φ_r` with
//!   `ΔI = J_a b² / (b² + ν² J_a²)`, `b_r = b ν² J_a² / (b² + ν² J_a²)`.
//!   `b_r` is largest at `b = ν J_a = j w J_a`, where `I_r = J_r + J_a/2`, `b_r = b/2`.

/// Effective inertia of a disk `j_r` carrying a tuned absorber `j_a` with natural
/// frequency `a` (rad/s), excited at `nu = j w` (rad/s).
pub fn tuned_absorber_inertia(j_r: f64, j_a: f64, a: f64, nu: f64) -> f64 {
    j_r + j_a * a * a / (a * a - nu * nu)
}

/// Effective inertia and damping `(I_r, b_r)` of a disk `j_r` carrying a viscous
/// (Lanchester) damper `j_a` with damping `b`, excited at `nu` (rad/s).
pub fn lanchester_damper(j_r: f64, j_a: f64, b: f64, nu: f64) -> (f64, f64) {
    let q = b * b + nu * nu * j_a * j_a;
    (j_r + j_a * b * b / q, b * nu * nu * j_a * j_a / q)
}

/// The damping `b = ν J_a` that maximises the Lanchester damper's effective damping.
pub fn lanchester_optimum_damping(j_a: f64, nu: f64) -> f64 {
    nu * j_a
}
