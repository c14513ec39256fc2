//! The `[counterweight]` part of a linkage report: the slider-crank's crank counterweight
//! (two-mass rod), full static balancing with a second counterweight on the rod, and the
//! gear balancers' force left, each checked by solving the balanced linkage's
//! kinetostatics again along the sweep.

use crate::machines::balancing::{self, add_point_mass, SliderCrankMasses};
use crate::machines::linkage::description::{PlanarJoint, GROUND};
use crate::machines::linkage::kinetostatics::{self, Loads};
use crate::machines::linkage::Vec2;
use crate::scenarios::linkage::linkage_scenario::{CounterweightScenario, MechanismScenario};
use crate::scenarios::linkage::report::sweep_rows::{v2, ReportCtx, Row};
use serde_json::{json, Map, Value};
use std::fmt::Write;

/// The counterweight's JSON and text (docs/mechanism.md).
pub(super) fn counterweight(
    m: &MechanismScenario,
    ctx: &ReportCtx,
    cw: &CounterweightScenario,
    rows: &[Row],
    json: &mut Map<String, Value>,
    text: &mut String,
) {
    let l = ctx.l;
    let crank = &l.links[cw.crank];
    let rod = &l.links[cw.rod];
    // The crank's ground pivot, the crank pin (crank–rod) and the piston pin (rod–slider).
    let pin = |a: usize, b: usize| {
        l.joints.iter().find_map(|j| match j {
            PlanarJoint::Revolute {
                a: x, pa, b: y, pb, ..
            } if (*x == a && *y == b) => Some((*pa, *pb)),
            PlanarJoint::Revolute {
                a: x, pa, b: y, pb, ..
            } if (*x == b && *y == a) => Some((*pb, *pa)),
            _ => None,
        })
    };
    let (Some((pivot, _)), Some((crank_pin, rod_b)), Some((rod_c, _))) = (
        pin(cw.crank, GROUND),
        pin(cw.crank, cw.rod),
        pin(cw.rod, cw.slider),
    ) else {
        json.insert("counterweight".into(), json!({"error": "counterweight: the crank, rod and slider must be pinned ground–crank–rod–slider"}));
        return;
    };
    let r = (crank_pin - pivot).norm();
    let u = (crank_pin - pivot) / r;
    let rod_len = (rod_c - rod_b).norm();
    let masses = SliderCrankMasses {
        crank_radius: r,
        crank_mass: crank.mass,
        crank_com: (crank.com - pivot).dot(&u),
        rod_length: rod_len,
        rod_mass: rod.mass,
        rod_com: (rod.com - rod_b).dot(&((rod_c - rod_b) / rod_len)),
        slider_mass: l.links[cw.slider].mass,
    };
    let c = balancing::slider_crank_counterweight(&masses, cw.fraction, cw.radius);
    let mut balanced = l.clone();
    let full = cw.rod_radius.map(|e| {
        let fb = balancing::slider_crank_full_balance(
            (crank.mass, crank.com - pivot, crank_pin - pivot),
            (rod.mass, rod.com - rod_b, rod_c - rod_b),
            masses.slider_mass,
            e,
            cw.radius,
        );
        let [rx, ry] = fb.rod_position;
        add_point_mass(
            &mut balanced.links[cw.rod],
            fb.rod_mass,
            rod_b + Vec2::new(rx, ry),
        );
        let [cx, cy] = fb.crank_position;
        add_point_mass(
            &mut balanced.links[cw.crank],
            fb.crank_mass,
            pivot + Vec2::new(cx, cy),
        );
        fb
    });
    if full.is_none() {
        add_point_mass(&mut balanced.links[cw.crank], c.mass, pivot - u * cw.radius);
    }
    let loads = Loads {
        gravity: Vec2::zeros(),
        ..Default::default()
    };
    let (sd, sdd) = (m.speed, m.acceleration);
    let mut before: f64 = 0.0;
    let mut after: f64 = 0.0;
    let mut formula_dev: f64 = 0.0;
    let mut series = Vec::new();
    // Gear balancers (rotating masses balanced, fraction 0): the slide line's direction,
    // toward the slider, and the largest force left with each set of pairs.
    let slide = l.joints.iter().find_map(|j| match j {
        PlanarJoint::Slider(sl) if sl.link == cw.slider && sl.guide == GROUND => Some(sl.dir),
        _ => None,
    });
    let gear_line = (cw.fraction == 0.0 && full.is_none())
        .then_some(slide)
        .flatten();
    let mut gear_left = [0.0_f64; 3];
    for row in rows {
        let st = &row.st;
        let f0 = kinetostatics::solve(l, &st.q, &row.qdd, &loads).shaking_force;
        let (q1, _, qdd1) = l.transfer_motion(&balanced, &st.q, &row.qd, &row.qdd);
        let f1 = kinetostatics::solve(&balanced, &q1, &qdd1, &loads).shaking_force;
        before = before.max(f0.norm());
        after = after.max(f1.norm());
        // Exact residual with the two-mass rod: −m_rec a_C − k m_rec r ω² (cos φ, sin φ).
        let a_c = l.point_acceleration(&st.q, &row.qd, &row.qdd, cw.rod, &rod_c);
        let phi = st.q[3 * cw.crank + 2];
        let dir = crate::machines::linkage::rotate(phi, &u.clone());
        // Fully balanced (counterweights on the rod and the crank): no shaking force.
        let formula = if full.is_some() {
            Vec2::zeros()
        } else {
            -a_c * c.reciprocating_mass - dir * (cw.fraction * c.reciprocating_mass * r * sd * sd)
        };
        if sdd == 0.0 {
            formula_dev = formula_dev.max((formula - f1).norm());
        }
        if let Some(line) = gear_line {
            let to_c =
                l.point_position(&st.q, cw.rod, &rod_c) - l.point_position(&st.q, cw.crank, &pivot);
            let s_hat = if to_c.dot(&line) < 0.0 { -line } else { line };
            let ph = dir.dot(&s_hat).clamp(-1.0, 1.0).acos();
            let (m_rec, rl) = (c.reciprocating_mass, masses.rod_length);
            for (k, pairs) in [[true, false], [false, true], [true, true]]
                .iter()
                .enumerate()
            {
                let fb = balancing::gear_balancer_force(m_rec, r, rl, sd, ph, *pairs);
                gear_left[k] = gear_left[k].max((f1 + s_hat * fb).norm());
            }
        }
        series.push(json!({ctx.input_key(): ctx.input(st.s), "before": v2(&f0), "after": v2(&f1)}));
    }
    json.insert(
        "counterweight".into(),
        json!({
            "masses": masses,
            "counterweight": c,
            "position_on_crank": v2(&(pivot - u * cw.radius)),
            "max_shaking_force_before": before,
            "max_shaking_force_after": after,
            "primary_reciprocating_amplitude": c.reciprocating_mass * r * sd * sd,
            "deviation_from_two_mass_formula": if sdd == 0.0 { json!(formula_dev) } else { Value::Null },
            "shaking_force": series,
        }),
    );
    if let (Some(fb), Some(Value::Object(o))) = (full, json.get_mut("counterweight")) {
        o.insert("full_balance".into(), json!(fb));
    }
    if let (Some(_), Some(Value::Object(o))) = (gear_line, json.get_mut("counterweight")) {
        let [p, s] = balancing::gear_balancers(c.reciprocating_mass, r, masses.rod_length);
        let a = c.reciprocating_mass * r * sd * sd;
        o.insert(
            "gear_balancers".into(),
            json!({"primary_mass_radius_per_gear": p, "secondary_mass_radius_per_gear": s,
                "primary_amplitude_N": a, "secondary_amplitude_N": a * r / masses.rod_length,
                "max_force_left_primary": gear_left[0], "max_force_left_secondary": gear_left[1],
                "max_force_left_both": gear_left[2]}),
        );
    }
    summary(&c, cw, full.as_ref(), r, (before, after, formula_dev), text);
}

/// The text lines: the full balance's two counterweights, or the crank counterweight of
/// the two-mass model; with the largest shaking forces before and after.
fn summary(
    c: &balancing::Counterweight,
    cw: &CounterweightScenario,
    full: Option<&balancing::FullBalance>,
    r: f64,
    (before, after, formula_dev): (f64, f64, f64),
    text: &mut String,
) {
    if let Some(fb) = full {
        let _ = writeln!(
            text,
            "\ncounterweight: full static balancing: on the rod {:.6} kg at {} m beyond the crank pin (rod frame ({:.6}, {:.6}) m from it), on the crank {:.6} kg at {} m beyond the pivot (crank frame ({:.6}, {:.6}) m from it)\n  max shaking force {:.3} N → {:.3} N (total centre of mass fixed)",
            fb.rod_mass,
            cw.rod_radius.unwrap_or(0.0),
            fb.rod_position[0],
            fb.rod_position[1],
            fb.crank_mass,
            cw.radius,
            fb.crank_position[0],
            fb.crank_position[1],
            before,
            after
        );
        return;
    }
    let _ = writeln!(
        text,
        "\ncounterweight: rotating mass {:.4} kg, reciprocating {:.4} kg at r = {r} m; with {:.0}% of the reciprocating mass: m_cw r_cw = {:.6} kg m → {:.4} kg at {} m\n  max shaking force {:.3} N → {:.3} N (deviation from the two-mass formula {:.2e} N)",
        c.rotating_mass,
        c.reciprocating_mass,
        cw.fraction * 100.0,
        c.mass_radius,
        c.mass,
        cw.radius,
        before,
        after,
        formula_dev
    );
}
