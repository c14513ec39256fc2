//! The report of a `kind = "gear_pair"` scenario: per pair the radii, thicknesses,
//! shifts, working pressure angle, centre distance, contact ratios and checks (undercut,
//! pointed teeth, interference), or the crossed/worm/bevel quantities, and one tooth
//! profile per gear (involute flanks). JSON keys are listed in `docs/machines.md`.

use crate::io::report::Report;
use crate::machines::gearing::crossed_axes::{bevel, crossed, crossed_rack, worm, Worm};
use crate::machines::gearing::involute::{
    flank_points, internal_thickness_at, involute_at, thickness_at,
};
use crate::machines::gearing::pair::{
    pair, withdrawal_for, GearGeometry, PairGeometry, PairKind, PairSpec,
};
use crate::machines::gearing::pair_design::Design;
use serde_json::{json, Value};
use std::fmt::Write;

/// A non-parallel pair's data.
#[derive(Clone, Debug, PartialEq)]
pub enum SpatialCase {
    /// Crossed helical.
    Crossed {
        /// Normal module.
        mn: f64,
        /// Teeth.
        z: [u32; 2],
        /// Helix angles (rad).
        beta: [f64; 2],
        /// Speed of gear 1 (rad/s), for the sliding speed.
        omega1: Option<f64>,
    },
    /// Helical gear on a crossed rack.
    CrossedRack {
        /// Normal module.
        mn: f64,
        /// Gear teeth.
        z: u32,
        /// Helix angles of the gear and of the rack teeth (rad).
        beta: [f64; 2],
        /// Gear speed (rad/s), for the rack and sliding speeds.
        omega1: Option<f64>,
    },
    /// Worm drive.
    Worm {
        /// Axial module.
        m: f64,
        /// Worm starts.
        starts: u32,
        /// Diameter factor.
        q: f64,
        /// Wheel teeth.
        z2: u32,
        /// Pressure angle (rad).
        alpha: f64,
        /// Worm speed (rpm).
        n1: Option<f64>,
        /// Flank friction coefficient.
        f: Option<f64>,
    },
    /// A pair designed for a centre distance (BANHRANG).
    Design {
        /// Centre distance (mm).
        a: f64,
        /// Module.
        m: f64,
        /// Pressure angle (rad).
        alpha: f64,
        /// Ratio `z₂/z₁`.
        i: f64,
        /// Addendum coefficient.
        ha: f64,
        /// Clearance coefficient.
        c: f64,
    },
    /// Bevel pair.
    Bevel {
        /// Module.
        m: f64,
        /// Teeth.
        z: [u32; 2],
        /// Shaft angle (rad).
        sigma: f64,
        /// Pressure angle (rad).
        alpha: f64,
        /// Addendum coefficient.
        ha: f64,
        /// Clearance coefficient.
        c: f64,
    },
}

/// One `[[pair]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct PairCase {
    /// Label.
    pub label: String,
    /// Type as written.
    pub kind: String,
    /// Planar pair.
    pub spec: Option<PairSpec>,
    /// Non-parallel pair.
    pub spatial: Option<SpatialCase>,
    /// Points per flank in the profiles.
    pub points: usize,
    /// Radii (mm) per gear at which the involute's quantities are listed.
    pub at_radii: Vec<Vec<f64>>,
    /// A cycloidal, pin or Roots pair.
    pub profile: Option<crate::scenarios::gear_pair_profiles::ProfileCase>,
}

/// A parsed gear-pair scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct PairScenario {
    /// Name.
    pub name: String,
    /// The pairs.
    pub cases: Vec<PairCase>,
    /// The `[[query]]` answers.
    pub queries: Vec<crate::scenarios::gear_pair_query::QueryCase>,
}

fn deg(x: f64) -> f64 {
    x.to_degrees()
}

fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// One tooth (left flank reversed, then the right flank) from `max(r_f, r_b)` to `r_a`.
fn tooth_profile(g: &GearGeometry, n: usize) -> Vec<[f64; 2]> {
    if g.internal || g.ra <= g.rb || !g.s_tip.is_finite() {
        return Vec::new();
    }
    crate::scenarios::gear_pair_profiles::tooth(&flank_points(g.s, g.r, g.rb, g.rf, g.ra, n))
}

fn gear_json(g: &GearGeometry, n: usize) -> Value {
    json!({
        "teeth": g.teeth,
        "shift": g.shift,
        "pitch_radius": g.r,
        "base_radius": g.rb,
        "tip_radius": g.ra,
        "root_radius": g.rf,
        "thickness_pitch": g.s,
        "thickness_tip": num(g.s_tip),
        "virtual_teeth": g.zv,
        "z_min": g.z_min,
        "x_min": g.x_min,
        "undercut": g.undercut,
        "undercut_exact": g.undercut_exact,
        "pointed_shift_fixed_tip": g.pointed_shift_fixed_tip,
        "pointed_shift_growing_tip": g.pointed_shift_growing_tip,
        "root_inside_base": g.root_inside_base,
        "max_tip_radius": g.max_tip_radius,
        "tooth_profile": tooth_profile(g, n),
    })
}

/// The involute's quantities at the radii `radii` of gear `k` (checked ≥ r_b at parse):
/// pressure angle, `inv α_y`, roll angle, radius of curvature, tooth thickness and space
/// width (arcs; an internal gear's tooth is the space of the external involute).
fn involute_rows(g: &GearGeometry, radii: &[f64], k: usize, text: &mut String) -> Value {
    let rows = radii.iter().filter_map(|&ry| {
        let i = involute_at(g.rb, ry)?;
        let s = if g.internal {
            internal_thickness_at(g.s, g.r, g.rb, ry)
        } else {
            thickness_at(g.s, g.r, g.rb, ry)
        };
        let pitch = 2.0 * std::f64::consts::PI * ry / g.teeth as f64;
        let _ = writeln!(
            text,
            "  gear {} at r = {ry:.4}: α = {:.4}°, inv α = {:.6}, ρ = {:.4}, s = {:.4}, e = {:.4}{}",
            k + 1,
            deg(i.pressure_angle),
            i.involute,
            i.curvature_radius,
            s,
            pitch - s,
            if s <= 0.0 { " (beyond the tooth's point)" } else { "" }
        );
        Some(json!({
            "radius": ry,
            "pressure_angle_deg": deg(i.pressure_angle),
            "involute": i.involute,
            "roll_angle_deg": deg(i.roll_angle),
            "curvature_radius": i.curvature_radius,
            "thickness": s,
            "space_width": pitch - s,
            "pointed": s <= 0.0,
        }))
    });
    Value::Array(rows.collect())
}

/// The warning of a pair whose total contact ratio is below 1.
const CONTACT_BELOW_ONE: &str = "the contact ratio is below 1: one pair of teeth leaves \
    contact before the next engages, so the drive is not continuous";

fn planar_json(c: &PairCase, spec: &PairSpec, g: &PairGeometry, text: &mut String) -> Value {
    let _ = writeln!(
        text,
        "\n[{}] {} pair, m = {}, z = {:?}, α = {:.4}°, β = {:.4}°, x = {:?}",
        c.label,
        c.kind,
        spec.module,
        &spec.teeth[..g.gears.len()],
        deg(spec.pressure_angle),
        deg(spec.helix),
        &spec.shift[..g.gears.len()]
    );
    let _ = writeln!(
        text,
        "  working pressure angle {:.4}°, centre distance {:.4} mm (standard {:.4}, y = {:.4}, tip reduction {:.4})",
        deg(g.alpha_w),
        g.centre_distance,
        g.a0,
        g.y,
        g.tip_reduction
    );
    let _ = writeln!(
        text,
        "  contact ratio ε_α = {:.4}, ε_β = {:.4}, ε = {:.4}{}",
        g.eps_alpha,
        g.eps_beta,
        g.eps(),
        if g.interference {
            "; TIP INTERFERENCE"
        } else {
            ""
        }
    );
    let below_one = g.eps() < 1.0;
    if below_one {
        let _ = writeln!(text, "  warning: {CONTACT_BELOW_ONE}");
    }
    for (k, gg) in g.gears.iter().enumerate() {
        let _ = writeln!(
            text,
            "  gear {}: z = {}, r = {:.4}, rb = {:.4}, ra = {:.4}, rf = {:.4}, s = {:.4}, s_a = {}, x_min = {:.4}{}{}",
            k + 1,
            gg.teeth,
            gg.r,
            gg.rb,
            gg.ra,
            gg.rf,
            gg.s,
            if gg.s_tip.is_finite() { format!("{:.4}", gg.s_tip) } else { "– (tip inside the base circle)".into() },
            gg.x_min,
            if gg.undercut { ", UNDERCUT" } else { "" },
            if gg.s_tip.is_finite() && gg.s_tip < 0.4 * spec.module { ", tip thinner than 0.4 m" } else { "" }
        );
    }
    let mut v = json!({
        "label": c.label,
        "type": c.kind,
        "module": spec.module,
        "transverse_module": g.mt,
        "teeth": spec.teeth,
        "pressure_angle_deg": deg(spec.pressure_angle),
        "transverse_pressure_angle_deg": deg(g.alpha_t),
        "helix_angle_deg": deg(spec.helix),
        "shift": spec.shift,
        "working_pressure_angle_deg": deg(g.alpha_w),
        "standard_centre_distance": g.a0,
        "centre_distance": g.centre_distance,
        "centre_distance_factor": g.y,
        "tip_reduction": g.tip_reduction,
        "pitch": g.pitch,
        "base_pitch": g.base_pitch,
        "line_of_action": g.line_of_action,
        "arc_of_action": g.line_of_action.map(|l| l / g.alpha_w.cos()),
        "contact_ratio": { "transverse": g.eps_alpha, "overlap": g.eps_beta, "total": g.eps() },
        "interference": g.interference,
        "gears": g.gears.iter().map(|gg| gear_json(gg, c.points)).collect::<Vec<_>>(),
    });
    for (k, radii) in c.at_radii.iter().enumerate() {
        v["gears"][k]["at_radii"] = involute_rows(&g.gears[k], radii, k, text);
    }
    if below_one {
        v["warnings"] = json!([CONTACT_BELOW_ONE]);
    }
    if spec.kind == PairKind::Rack {
        v["rack_withdrawal"] = json!(spec.shift[1] * spec.module);
        v["withdrawal_for_unit_contact_ratio"] =
            json!(withdrawal_for(g, 1.0) + spec.shift[1] * spec.module);
    }
    if let (Some(o), Some((exact, book))) = (g.o2n1, g.internal_min_pinion) {
        v["o2n1"] = json!(o);
        v["internal_min_pinion_teeth"] = json!({ "exact": exact, "book_rule": book });
        let _ = writeln!(
            text,
            "  internal: O2N1 = {o:.4} vs ra2 = {:.4}; smallest pinion without tip interference {exact:.3} (book's rule {book:.3})",
            g.gears[1].ra
        );
    }
    v
}

/// A worm pair's text line and JSON.
fn worm_json(c: &PairCase, w: &Worm, text: &mut String) -> Value {
    let _ = writeln!(
        text,
        "\n[{}] worm: λ = {:.4}°, d = {:.3}/{:.3} mm, A = {:.3}, i = {}{}{}",
        c.label,
        deg(w.lead_angle),
        w.diameters[0],
        w.diameters[1],
        w.centre_distance,
        w.ratio,
        w.speeds.map_or(String::new(), |(v1, vs)| format!(
            ", v1 = {v1:.4} m/s, sliding {vs:.4} m/s"
        )),
        w.efficiency.map_or(String::new(), |e| format!(
            ", efficiency {e:.4}, reverse {:.4}{}",
            w.reverse_efficiency.unwrap_or(0.0),
            if w.self_locking() == Some(true) {
                " (self-locking)"
            } else {
                ""
            }
        ))
    );
    json!({
        "label": c.label, "type": "worm",
        "lead_angle_deg": deg(w.lead_angle), "diameters": w.diameters, "centre_distance": w.centre_distance,
        "ratio": w.ratio, "pitch_line_speed": w.speeds.map(|s| s.0), "sliding_speed": w.speeds.map(|s| s.1),
        "friction_angle_deg": w.friction_angle.map(deg), "efficiency": w.efficiency,
        "reverse_efficiency": w.reverse_efficiency, "self_locking": w.self_locking(),
    })
}

/// A designed pair's (centre distance `a`, module `m`, ratio `i`) text line and JSON.
fn design_json(c: &PairCase, d: &Design, (a, m, i): (f64, f64, f64), text: &mut String) -> Value {
    let g = &d.pair;
    let _ = writeln!(
        text,
        "\n[{}] design for A = {a} mm, m = {m}, i = {i}: z = {:?}, αw = {:.4}°, x_t = {:.4} (λ = {:.4}, ν = {:.4}){}; balanced shifts x = [{:.4}, {:.4}] (specific sliding {:.3}/{:.3}), ε = {:.4}, s_a = {:.3}/{:.3} mm{}",
        c.label, d.teeth, deg(d.alpha_w), d.total_shift, d.centre_factor, d.tip_reduction,
        if d.feasible { "" } else { " (z1 + z2 < 34 − 17 x_t: infeasible)" },
        d.shift[0], d.shift[1], d.sliding[0], d.sliding[1], g.eps_alpha, g.gears[0].s_tip, g.gears[1].s_tip,
        if d.constraints_met { "" } else { "; CONSTRAINTS NOT MET (undercut, s_a ≥ 0.4 m, ε ≥ 1.1)" }
    );
    json!({
        "label": c.label, "type": "design",
        "teeth": d.teeth, "working_pressure_angle_deg": deg(d.alpha_w), "total_shift": d.total_shift,
        "centre_factor": d.centre_factor, "tip_reduction": d.tip_reduction, "feasible": d.feasible,
        "shift": d.shift, "specific_sliding": d.sliding, "constraints_met": d.constraints_met,
        "centre_distance": g.centre_distance,
        "contact_ratio": g.eps_alpha,
        "gears": g.gears.iter().map(|gg| gear_json(gg, c.points)).collect::<Vec<_>>(),
    })
}

fn spatial_json(c: &PairCase, s: &SpatialCase, text: &mut String) -> Value {
    match *s {
        SpatialCase::Crossed {
            mn,
            z,
            beta,
            omega1,
        } => {
            let r = crossed(mn, z, beta, omega1);
            let _ = writeln!(
                text,
                "\n[{}] crossed helical: Σ = {:.4}°, m_t = {:.4}/{:.4}, A = {:.4} mm, i = {:.4}{}",
                c.label,
                deg(r.shaft_angle),
                r.mt[0],
                r.mt[1],
                r.centre_distance,
                r.ratio,
                r.sliding_speed
                    .map_or(String::new(), |v| format!(", sliding {v:.4} m/s"))
            );
            json!({
                "label": c.label, "type": "crossed",
                "shaft_angle_deg": deg(r.shaft_angle), "transverse_modules": r.mt, "pitch_radii": r.r,
                "centre_distance": r.centre_distance, "ratio": r.ratio, "sliding_speed": r.sliding_speed,
            })
        }
        SpatialCase::CrossedRack {
            mn,
            z,
            beta,
            omega1,
        } => {
            let r = crossed_rack(mn, z, beta, omega1);
            let _ = writeln!(
                text,
                "\n[{}] crossed rack: Σ = {:.4}°, m_t1 = {:.4}, rack module {:.4}, r1 = {:.4} mm, travel/rev {:.4} mm{}",
                c.label,
                deg(r.shaft_angle),
                r.gear_transverse_module,
                r.rack_module,
                r.pitch_radius,
                r.travel_per_revolution,
                r.speeds.map_or(String::new(), |[v1, v2, vs]| format!(
                    ", v1 = {v1:.5}, rack v2 = {v2:.5}, sliding {vs:.5} m/s"
                ))
            );
            json!({
                "label": c.label, "type": "crossed_rack",
                "shaft_angle_deg": deg(r.shaft_angle), "transverse_module": r.gear_transverse_module,
                "normal_module": mn, "rack_module": r.rack_module, "pitch_radius": r.pitch_radius,
                "travel_per_revolution": r.travel_per_revolution,
                "pitch_line_speed": r.speeds.map(|s| s[0]), "rack_speed": r.speeds.map(|s| s[1]),
                "sliding_speed": r.speeds.map(|s| s[2]),
            })
        }
        SpatialCase::Worm {
            m,
            starts,
            q,
            z2,
            alpha,
            n1,
            f,
        } => worm_json(c, &worm(m, starts, q, z2, alpha, n1, f), text),
        SpatialCase::Design {
            a,
            m,
            alpha,
            i,
            ha,
            c: cl,
        } => {
            let Some(d) = crate::machines::gearing::pair_design::design(a, m, alpha, i, ha, cl)
            else {
                return Value::Null;
            };
            design_json(c, &d, (a, m, i), text)
        }
        SpatialCase::Bevel {
            m,
            z,
            sigma,
            alpha,
            ha,
            c: cl,
        } => {
            let b = bevel(m, z, sigma, alpha, ha, cl);
            let _ = writeln!(
                text,
                "\n[{}] bevel: δ = {:.4}°/{:.4}°, z_v = {:.3}/{:.3}, z_min = {:.3}, pinion shift for no undercut {:.4}, virtual-pair ε = {:.4}",
                c.label,
                deg(b.cone[0]),
                deg(b.cone[1]),
                b.zv[0],
                b.zv[1],
                b.z_min,
                b.pinion_shift,
                b.virtual_pair.eps_alpha
            );
            json!({
                "label": c.label, "type": "bevel",
                "cone_angles_deg": [deg(b.cone[0]), deg(b.cone[1])], "pitch_radii": b.r,
                "virtual_teeth": b.zv, "virtual_ratio": b.virtual_ratio, "z_min": b.z_min,
                "pinion_shift": b.pinion_shift,
                "contact_ratio": b.virtual_pair.eps_alpha,
            })
        }
    }
}

/// The report (see the module docs).
pub fn report(sc: &PairScenario, kind_name: &str) -> Report {
    let mut text = format!("Gear pairs '{}'\n", sc.name);
    let mut pairs = Vec::new();
    for c in &sc.cases {
        let v = match (&c.spec, &c.spatial) {
            (Some(spec), _) => planar_json(c, spec, &pair(spec), &mut text),
            (None, Some(s)) => spatial_json(c, s, &mut text),
            (None, None) => c.profile.as_ref().map_or(Value::Null, |pc| {
                crate::scenarios::gear_pair_profiles::profile_json(
                    &c.label, pc, c.points, &mut text,
                )
            }),
        };
        pairs.push(v);
    }
    let mut queries = Vec::new();
    for q in &sc.queries {
        text.push_str(&crate::scenarios::gear_pair_query::query_line(q));
        text.push('\n');
        queries.push(crate::scenarios::gear_pair_query::query_json(q));
    }
    Report {
        json: json!({ "scenario": sc.name, "kind": kind_name, "pairs": pairs, "queries": queries }),
        text,
    }
}
