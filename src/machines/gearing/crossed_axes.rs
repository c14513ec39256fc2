//! Gears on non-parallel axes (docs/reference_data.md §M2, ch. 9): crossed helical pairs,
//! a helical gear on a crossed rack,
//! worm drives (lead angle, sliding speed, efficiency, self-locking) and bevel pairs
//! (pitch-cone angles, Tredgold's virtual spur gears, undercut and the contact ratio of
//! the virtual pair).

use crate::machines::gearing::pair::{pair, PairGeometry, PairKind, PairSpec};

/// A crossed helical pair (angles in radians, lengths in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct Crossed {
    /// Shaft angle `Σ = β₁ + β₂`.
    pub shaft_angle: f64,
    /// Transverse modules `m_n / cos β`.
    pub mt: [f64; 2],
    /// Pitch radii.
    pub r: [f64; 2],
    /// Centre distance `(m_n/2)(z₁/cos β₁ + z₂/cos β₂)`.
    pub centre_distance: f64,
    /// Speed ratio `ω₁/ω₂ = z₂/z₁`.
    pub ratio: f64,
    /// Sliding speed at the pitch point for `ω₁` (rad/s): `v₁ sin Σ / cos β₂` (m/s).
    pub sliding_speed: Option<f64>,
}

/// Crossed helical pair with normal module `mn`, teeth `z`, helix angles `beta`.
pub fn crossed(mn: f64, z: [u32; 2], beta: [f64; 2], omega1: Option<f64>) -> Crossed {
    let mt = [mn / beta[0].cos(), mn / beta[1].cos()];
    let r = [mt[0] * z[0] as f64 / 2.0, mt[1] * z[1] as f64 / 2.0];
    let sum = beta[0] + beta[1];
    Crossed {
        shaft_angle: sum,
        mt,
        r,
        centre_distance: r[0] + r[1],
        ratio: z[1] as f64 / z[0] as f64,
        sliding_speed: omega1.map(|w| (w * r[0] / 1000.0 * sum.sin() / beta[1].cos()).abs()),
    }
}

/// A helical gear meshing with a rack whose teeth are crossed: the rack moves at the
/// shaft angle `Σ = β₁ + β₂` to the gear's plane of rotation (angles in radians, lengths
/// in mm, speeds in m/s). At the pitch point the velocities normal to the common tooth
/// line are equal, `v₁ cos β₁ = v₂ cos β₂`, so
///
/// `v₂ = v₁ cos β₁/cos β₂`,  sliding along the teeth `v_s = v₁ sin Σ/cos β₂`,
/// `m_t1 = m_n/cos β₁` (gear), `m_2 = m_n/cos β₂` (rack, along its motion),
/// travel per gear revolution `π m_n z/cos β₂`.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossedRack {
    /// Shaft angle `Σ = β₁ + β₂` between the rack's motion and the gear's plane.
    pub shaft_angle: f64,
    /// Gear transverse module `m_n/cos β₁`.
    pub gear_transverse_module: f64,
    /// Rack module along its motion `m_n/cos β₂`.
    pub rack_module: f64,
    /// Gear pitch radius `m_n z/(2 cos β₁)`.
    pub pitch_radius: f64,
    /// Rack travel per gear revolution `π m_n z/cos β₂` (mm).
    pub travel_per_revolution: f64,
    /// For a gear speed `ω₁` (rad/s): pitch-line speed `v₁`, rack speed `v₂`, sliding
    /// speed `v_s` (m/s).
    pub speeds: Option<[f64; 3]>,
}

/// A crossed gear–rack pair: normal module `mn`, gear teeth `z`, helix angles
/// `[β₁ (gear), β₂ (rack teeth to the normal of the rack's motion)]`.
pub fn crossed_rack(mn: f64, z: u32, beta: [f64; 2], omega1: Option<f64>) -> CrossedRack {
    let r = mn * z as f64 / (2.0 * beta[0].cos());
    let sum = beta[0] + beta[1];
    CrossedRack {
        shaft_angle: sum,
        gear_transverse_module: mn / beta[0].cos(),
        rack_module: mn / beta[1].cos(),
        pitch_radius: r,
        travel_per_revolution: std::f64::consts::PI * mn * z as f64 / beta[1].cos(),
        speeds: omega1.map(|w| {
            let v1 = (w * r / 1000.0).abs();
            [
                v1,
                v1 * beta[0].cos() / beta[1].cos(),
                v1 * sum.sin().abs() / beta[1].cos(),
            ]
        }),
    }
}

/// A worm drive.
#[derive(Clone, Debug, PartialEq)]
pub struct Worm {
    /// Lead angle `λ = atan(z₁/q)`.
    pub lead_angle: f64,
    /// Worm pitch diameter `q m` and wheel `m z₂` (mm).
    pub diameters: [f64; 2],
    /// Centre distance (mm).
    pub centre_distance: f64,
    /// Ratio `z₂/z₁`.
    pub ratio: f64,
    /// Worm pitch-line speed and sliding speed `v₁/cos λ` (m/s), for a worm speed.
    pub speeds: Option<(f64, f64)>,
    /// Friction angle `φ' = atan(f/cos α)` of the thread flank.
    pub friction_angle: Option<f64>,
    /// `tan λ / tan(λ + φ')`.
    pub efficiency: Option<f64>,
    /// `tan(λ − φ')/tan λ` (≤ 0: self-locking).
    pub reverse_efficiency: Option<f64>,
}

impl Worm {
    /// The wheel cannot drive the worm: `λ ≤ φ'`.
    pub fn self_locking(&self) -> Option<bool> {
        self.friction_angle.map(|p| self.lead_angle <= p)
    }
}

/// Worm of `starts` and diameter factor `q` with a wheel of `z2` teeth, axial module `m`;
/// worm speed `n1` (rpm) and flank friction `f` optional.
pub fn worm(
    m: f64,
    starts: u32,
    q: f64,
    z2: u32,
    alpha: f64,
    n1: Option<f64>,
    f: Option<f64>,
) -> Worm {
    let lambda = (starts as f64 / q).atan();
    let d = [q * m, m * z2 as f64];
    let phi = f.map(|f| (f / alpha.cos()).atan());
    Worm {
        lead_angle: lambda,
        diameters: d,
        centre_distance: (d[0] + d[1]) / 2.0,
        ratio: z2 as f64 / starts as f64,
        speeds: n1.map(|n| {
            let v1 = std::f64::consts::PI * d[0] / 1000.0 * n / 60.0;
            (v1, v1 / lambda.cos())
        }),
        friction_angle: phi,
        efficiency: phi.map(|p| lambda.tan() / (lambda + p).tan()),
        reverse_efficiency: phi.map(|p| (lambda - p).tan() / lambda.tan()),
    }
}

/// A bevel pair.
#[derive(Clone, Debug, PartialEq)]
pub struct Bevel {
    /// Pitch-cone angles `tan δ₁ = sin Σ/(i + cos Σ)`, `δ₂ = Σ − δ₁`.
    pub cone: [f64; 2],
    /// Outer pitch radii `m z/2`.
    pub r: [f64; 2],
    /// Virtual (Tredgold) tooth counts `z / cos δ`.
    pub zv: [f64; 2],
    /// Virtual ratio `z_v2/z_v1`.
    pub virtual_ratio: f64,
    /// Smallest pinion without undercut `z_min cos δ₁` (book 17 cos δ₁).
    pub z_min: f64,
    /// Shift of the pinion for no undercut `(17 − z_v1)/17` (≤ 0: none needed); the
    /// wheel takes the opposite shift.
    pub pinion_shift: f64,
    /// The virtual spur pair (contact ratio, radii).
    pub virtual_pair: PairGeometry,
}

/// Bevel pair of module `m`, teeth `z`, shaft angle `sigma`, standard tooth data.
pub fn bevel(m: f64, z: [u32; 2], sigma: f64, alpha: f64, ha: f64, c: f64) -> Bevel {
    let i = z[1] as f64 / z[0] as f64;
    let d1 = (sigma.sin() / (i + sigma.cos())).atan();
    let cone = [d1, sigma - d1];
    let zv = [z[0] as f64 / cone[0].cos(), z[1] as f64 / cone[1].cos()];
    let zmin = crate::machines::gearing::pair::z_min_book(ha, alpha, 0.0);
    // The virtual pair: spur gears of radii r/cos δ (non-integer teeth scale the module).
    let spec = PairSpec {
        kind: PairKind::External,
        module: m,
        teeth: [z[0], z[1]],
        pressure_angle: alpha,
        addendum: ha,
        clearance: c,
        shift: [0.0, 0.0],
        helix: 0.0,
        face_width: None,
        centre_distance: None,
    };
    let mut vp = pair(&spec);
    for (k, g) in vp.gears.iter_mut().enumerate() {
        let scale = 1.0 / cone[k].cos();
        g.r *= scale;
        g.rb *= scale;
        g.ra = g.r + ha * m;
        g.rf = g.r - (ha + c) * m;
        g.zv = zv[k];
    }
    let a = vp.gears[0].r + vp.gears[1].r;
    let n1n2 = a * alpha.sin();
    let l = |g: &crate::machines::gearing::pair::GearGeometry| (g.ra * g.ra - g.rb * g.rb).sqrt();
    vp.eps_alpha = (l(&vp.gears[0]) + l(&vp.gears[1]) - n1n2) / vp.base_pitch;
    vp.centre_distance = a;
    vp.a0 = a;
    vp.line_of_action = Some(n1n2);
    Bevel {
        cone,
        r: [m * z[0] as f64 / 2.0, m * z[1] as f64 / 2.0],
        zv,
        virtual_ratio: zv[1] / zv[0],
        z_min: zmin * d1.cos(),
        pinion_shift: (zmin - zv[0]) / zmin,
        virtual_pair: vp,
    }
}
