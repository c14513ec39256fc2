//! Gear stages and referral to the input shaft (docs/reference_data.md §S3).
//!
//! A [`GearedChain`] is an input chain followed by stages; stage `s` turns at speed ratio
//! `i_s = n_out/n_in` relative to the segment before it, so its disks turn at the
//! cumulative ratio `r = Π i`. The mesh is rigid: the last disk of the previous segment
//! (pinion) and the first disk of the stage (wheel) satisfy `φ_wheel = i φ_pinion` and
//! carry torques `T_wheel = T_pinion / i` (power balance). Ratios are magnitudes: an
//! external mesh also reverses the sense of rotation, which changes no frequency or
//! amplitude.
//!
//! Referral to the input speed keeps the kinetic and potential energies: a driven-side
//! disk or shaft at cumulative ratio `r` enters the referred chain with `J r²`, `c r²`,
//! `a r²`, `b r²`, and each pinion/wheel pair becomes one referred disk
//! `J_pinion + r² J_wheel`. Mapping results back: a driven-side angle (amplitude) is
//! `r ×` the referred one, a driven-side shaft torque is the referred torque `/ r`.

use crate::machines::vibration::torsional::torsional_chain::{ChainError, TorsionalChain};

/// One gear stage: the speed ratio of its mesh and the chain it drives (its first disk is
/// the wheel).
#[derive(Clone, Debug, PartialEq)]
pub struct GearStage {
    /// `i = n_out / n_in` of the mesh (> 0).
    pub ratio: f64,
    /// The driven chain, in its own (physical) units and speed.
    pub chain: TorsionalChain,
}

/// A drivetrain with gear stages (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct GearedChain {
    /// The input segment (its last disk is the first pinion).
    pub input: TorsionalChain,
    /// The stages in order.
    pub stages: Vec<GearStage>,
}

/// A geared chain referred to the input speed, with the maps back to physical values.
#[derive(Clone, Debug, PartialEq)]
pub struct Referral {
    /// The referred chain (pinion/wheel pairs merged).
    pub chain: TorsionalChain,
    /// Per physical disk (input disks, then each stage's): the referred disk and the
    /// cumulative speed ratio `r` of the disk.
    pub mass_map: Vec<(usize, f64)>,
    /// Per physical shaft: the referred shaft and its cumulative ratio `r`.
    pub shaft_map: Vec<(usize, f64)>,
}

impl Referral {
    /// Physical disk angles (or amplitudes) from referred ones: `φ = r φ_ref`.
    pub fn physical_angles(&self, referred: &[f64]) -> Vec<f64> {
        self.mass_map
            .iter()
            .map(|&(k, r)| r * referred[k])
            .collect()
    }

    /// Physical shaft torques from referred ones: `T = T_ref / r`.
    pub fn physical_shaft_torques(&self, referred: &[f64]) -> Vec<f64> {
        self.shaft_map
            .iter()
            .map(|&(k, r)| referred[k] / r)
            .collect()
    }
}

impl From<TorsionalChain> for GearedChain {
    fn from(input: TorsionalChain) -> Self {
        Self {
            input,
            stages: Vec::new(),
        }
    }
}

impl GearedChain {
    /// Checks the segments and the ratios.
    pub fn new(input: TorsionalChain, stages: Vec<GearStage>) -> Result<Self, ChainError> {
        input.validate()?;
        for (s, st) in stages.iter().enumerate() {
            st.chain.validate()?;
            if !(st.ratio.is_finite() && st.ratio > 0.0) {
                return Err(ChainError::new(
                    "ratio",
                    Some(s),
                    format!("gear ratio must be a positive number, got {}", st.ratio),
                ));
            }
        }
        Ok(Self { input, stages })
    }

    /// The segments in order with their cumulative speed ratios.
    pub fn segments(&self) -> Vec<(&TorsionalChain, f64)> {
        let mut out = vec![(&self.input, 1.0)];
        let mut r = 1.0;
        for st in &self.stages {
            r *= st.ratio;
            out.push((&st.chain, r));
        }
        out
    }

    /// Refers every stage to the input speed (see the module docs).
    pub fn refer(&self) -> Referral {
        let mut names: Vec<String> = Vec::new();
        let (mut j, mut c, mut a, mut b) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let (mut mass_map, mut shaft_map) = (Vec::new(), Vec::new());
        for (s, (seg, r)) in self.segments().into_iter().enumerate() {
            let r2 = r * r;
            for k in 0..seg.len() {
                if s > 0 && k == 0 {
                    // Wheel: merged into the pinion (the last referred disk).
                    let p = j.len() - 1;
                    j[p] += r2 * seg.inertia[0];
                    a[p] += r2 * seg.absolute_damping[0];
                    names[p] = format!("{}+{}", names[p], seg.names[0]);
                    mass_map.push((p, r));
                } else {
                    mass_map.push((j.len(), r));
                    names.push(seg.names[k].clone());
                    j.push(r2 * seg.inertia[k]);
                    a.push(r2 * seg.absolute_damping[k]);
                }
                if k + 1 < seg.len() {
                    shaft_map.push((c.len(), r));
                    c.push(r2 * seg.stiffness[k]);
                    b.push(r2 * seg.relative_damping[k]);
                }
            }
        }
        let chain = TorsionalChain {
            names,
            inertia: j,
            stiffness: c,
            absolute_damping: a,
            relative_damping: b,
        };
        Referral {
            chain,
            mass_map,
            shaft_map,
        }
    }
}
