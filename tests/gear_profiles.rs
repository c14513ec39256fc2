//! Non-involute profiles of `kind = "gear_pair"` (cycloidal, pin and Roots pairs), each
//! checked by a route independent of the code's formulas: the path of contact recovered
//! from the reported tooth profiles by Willis' law (the normal at the contact point passes
//! through the pitch point), the pin gear's flank as the locus at the pin radius from the
//! epicycloid, the pointed tip of a pin gear with thin pins from the epicycloid alone, and
//! the Roots rotors' area by the shoelace formula and their meshing at every angle.

use serde_json::Value;
use std::f64::consts::{PI, TAU};

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

/// Runs a gear-pair file given as text and returns its JSON.
fn run_text(name: &str, text: &str) -> Value {
    let dir = std::env::temp_dir().join(format!("armsim_gprof_{}_{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    let r = armsim::scenarios::run_file(&p).unwrap_or_else(|e| panic!("{e}"));
    std::fs::remove_dir_all(&dir).ok();
    r.json
}

fn points(v: &Value) -> Vec<[f64; 2]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()])
        .collect()
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn rot(p: [f64; 2], a: f64) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The right flank (second half of a `tooth_profile`), root to tip.
fn right_flank(gear: &Value) -> Vec<[f64; 2]> {
    let t = points(&gear["tooth_profile"]);
    t[t.len() / 2..].to_vec()
}

/// Willis' law applied to a profile point `q` (neighbours `a`, `b` give its normal) of a
/// gear of pitch radius `r` centred at the origin: the turn that brings the normal's foot
/// on the pitch circle to the pitch point `(0, r)`, and the contact point there.
fn contact_of(q: [f64; 2], a: [f64; 2], b: [f64; 2], r: f64) -> (f64, [f64; 2]) {
    let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
    let l = tx.hypot(ty);
    let n = [-ty / l, tx / l];
    // |q + t n|² = r²: t² + 2 (q·n) t + |q|² − r² = 0, the root nearer q.
    let qn = q[0] * n[0] + q[1] * n[1];
    let disc = (qn * qn - (q[0] * q[0] + q[1] * q[1] - r * r)).max(0.0);
    let t = [-qn + disc.sqrt(), -qn - disc.sqrt()]
        .into_iter()
        .min_by(|x, y| x.abs().total_cmp(&y.abs()))
        .unwrap();
    let foot = [q[0] + t * n[0], q[1] + t * n[1]];
    let turn = PI / 2.0 - foot[1].atan2(foot[0]);
    (turn, rot(q, turn))
}

const CYCLOIDAL: &str = r#"kind = "gear_pair"
module = 4

[[pair]]
type = "cycloidal"
teeth = [14, 30]
rolling_radii = [11.0, 16.0]
profile_points = 600
"#;

/// The contact points that the reported profiles imply (Willis) lie on the two rolling
/// circles: gear 1's flank on `ρ₁` inside its pitch circle, its face on `ρ₂` outside; and
/// gear 1's turn over the contacts inside the mate's tip circle, divided by the angular
/// pitch, is the reported contact ratio.
#[test]
fn cycloidal_path_of_contact_lies_on_the_rolling_circles() {
    let v = run_text("cyc", CYCLOIDAL);
    let pair = &v["pairs"][0];
    let g1 = &pair["gears"][0];
    let (r1, r2) = (
        num(&g1["pitch_radius"]),
        num(&pair["gears"][1]["pitch_radius"]),
    );
    close(r1, 28.0, 1e-12, "r1");
    close(r2, 60.0, 1e-12, "r2");
    let (rho1, rho2) = (11.0, 16.0);
    let ra2 = num(&pair["gears"][1]["tip_radius"]);
    let o2 = [0.0, r1 + r2];
    let flank = right_flank(g1);
    let (mut flank_turns, mut face_turns) = (Vec::new(), Vec::new());
    for i in 1..flank.len() - 1 {
        let q = flank[i];
        let radius = q[0].hypot(q[1]);
        if (radius - r1).abs() < 0.05 || radius < num(&g1["root_radius"]) + 0.05 {
            continue;
        }
        let (turn, k) = contact_of(q, flank[i - 1], flank[i + 1], r1);
        if radius < r1 {
            close(dist(k, [0.0, r1 - rho1]), rho1, 2e-4, "flank contact on ρ1");
            if dist(k, o2) <= ra2 {
                flank_turns.push(turn);
            }
        } else {
            close(dist(k, [0.0, r1 + rho2]), rho2, 2e-4, "face contact on ρ2");
            face_turns.push(turn);
        }
    }
    // At the pitch point (polar angle π/2 − s/(2r₁), s = p/2) the turn is s/(2r₁); each
    // range runs from there to its farthest contact.
    let at_pitch = PI * 4.0 / 4.0 / r1;
    let pitch_turn = |t: &[f64]| t.iter().map(|x| (x - at_pitch).abs()).fold(0.0, f64::max);
    let eps = (pitch_turn(&flank_turns) + pitch_turn(&face_turns)) / (TAU / 14.0);
    close(
        eps,
        num(&pair["contact_ratio"]),
        3e-3,
        "ε from the profiles",
    );
    // The closed form: cos θ₁ = ((r₂ + ρ₁)² + ρ₁² − r_a2²)/(2ρ₁(r₂ + ρ₁)), ε = Σρθ/p.
    let th = |r: f64, rho: f64, ra: f64| {
        (((r + rho).powi(2) + rho * rho - ra * ra) / (2.0 * rho * (r + rho))).acos()
    };
    let e = (rho1 * th(r2, rho1, r2 + 4.0) + rho2 * th(r1, rho2, r1 + 4.0)) / (PI * 4.0);
    close(num(&pair["contact_ratio"]), e, 1e-12, "ε closed form");
    close(
        num(&pair["max_pressure_angles_deg"][0]),
        th(r2, rho1, r2 + 4.0).to_degrees() / 2.0,
        1e-12,
        "α max = θ/2",
    );
}

/// The epicycloid of the pin centre relative to the gear (pin wheel `r1` rolling on `r2`).
fn pin_path(r1: f64, r2: f64, phi: f64) -> [f64; 2] {
    let k = (r2 + r1) / r1 * phi;
    [
        (r2 + r1) * phi.cos() - r1 * k.cos(),
        (r2 + r1) * phi.sin() - r1 * k.sin(),
    ]
}

/// The nearest point of the pin path (the branch from the cusp toward the tooth and its
/// mirror) to `q`, in the frame where the cusp is at polar angle `c0`: `(distance, φ)`.
fn nearest_pin(q: [f64; 2], r1: f64, r2: f64, c0: f64) -> (f64, f64) {
    let q = rot(q, -c0);
    let hi = PI * r1 / r2;
    let n = 200_000;
    (0..=n)
        .flat_map(|i| {
            let phi = hi * i as f64 / n as f64;
            let e = pin_path(r1, r2, phi);
            [(dist(q, e), phi), (dist(q, [e[0], -e[1]]), -phi)]
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap()
}

fn pin_file(rc: f64) -> String {
    format!(
        "kind = \"gear_pair\"\nmodule = 4\n\n[[pair]]\ntype = \"pin\"\nteeth = [10, 20]\n\
         pin_radius = {rc}\nprofile_points = 600\n"
    )
}

/// Every point of the reported gear flank is exactly one pin radius from the pin centre's
/// path (the tooth is what the pins leave), and the contact ratio follows from the pin
/// positions nearest to the first working point and to the tip.
#[test]
fn pin_gear_flank_is_one_pin_radius_from_the_pin_path() {
    let rc = 2.0;
    let v = run_text("pin", &pin_file(rc));
    let pair = &v["pairs"][0];
    let g2 = &pair["gears"][1];
    let (r1, r2) = (20.0, 40.0);
    close(num(&pair["centre_distance"]), 60.0, 1e-12, "A");
    let c0 = PI / 2.0 - PI / 20.0;
    let flank = right_flank(g2);
    for q in flank.iter().step_by(7) {
        let (d, _) = nearest_pin(*q, r1, r2, c0);
        close(d, rc, 1e-5, "distance to the pin path");
    }
    let start = num(&g2["working_start_radius"]);
    let first = flank
        .iter()
        .find(|q| q[0].hypot(q[1]) > start + 1e-3)
        .unwrap();
    let (_, phi0) = nearest_pin(*first, r1, r2, c0);
    let (_, phi1) = nearest_pin(*flank.last().unwrap(), r1, r2, c0);
    let eps = (phi1 - phi0) * 20.0 / TAU;
    close(
        num(&pair["contact_ratio"]),
        eps,
        0.02,
        "ε from the pin positions",
    );
    close(
        num(&pair["pressure_angles_deg"][1]),
        (r2 * phi1 / r1 / 2.0).to_degrees(),
        0.05,
        "α at the tip = θ/2",
    );
    close(num(&g2["root_radius"]), r2 - rc, 1e-12, "root");
    close(
        num(&g2["tip_radius"]),
        num(&g2["pointed_tip_radius"]),
        1e-12,
        "pointed by default",
    );
}

/// With very thin pins the gear tooth is the epicycloid itself: it is pointed where the
/// epicycloid's polar angle is half the angular pitch, `ψ(φ) = π/z₂`, and the contact
/// runs from the line of centres to there, `ε = φ z₂/(2π)`.
#[test]
fn pin_gear_with_thin_pins_is_pointed_where_the_epicycloid_reaches_half_a_pitch() {
    let v = run_text("thin", &pin_file(1e-3));
    let pair = &v["pairs"][0];
    let (r1, r2) = (20.0, 40.0);
    let (mut lo, mut hi) = (0.0, PI * r1 / r2);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        let e = pin_path(r1, r2, mid);
        if e[1].atan2(e[0]) < PI / 20.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let e = pin_path(r1, r2, lo);
    close(
        num(&pair["gears"][1]["pointed_tip_radius"]),
        e[0].hypot(e[1]),
        0.02,
        "pointed tip",
    );
    close(num(&pair["contact_ratio"]), lo * 20.0 / TAU, 2e-3, "ε");
    close(
        num(&pair["pressure_angles_deg"][1]),
        (r2 * lo / r1 / 2.0).to_degrees(),
        0.05,
        "α end",
    );
}

/// A whole Roots rotor from its reported lobe, counter-clockwise.
fn rotor(g: &Value, lobes: usize) -> Vec<[f64; 2]> {
    let t = points(&g["tooth_profile"]);
    let half = t.len() / 2;
    let lobe: Vec<[f64; 2]> = t[half..].iter().chain(t[..half].iter()).copied().collect();
    (0..lobes)
        .flat_map(|k| {
            let a = TAU * k as f64 / lobes as f64;
            lobe[..lobe.len() - 1].iter().map(move |&p| rot(p, a))
        })
        .collect()
}

fn shoelace(p: &[[f64; 2]]) -> f64 {
    (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

fn seg_dist(q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    dist(q, [a[0] + t * dx, a[1] + t * dy])
}

fn inside(q: [f64; 2], poly: &[[f64; 2]]) -> bool {
    let mut c = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a[1] > q[1]) != (b[1] > q[1])
            && q[0] < a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
        {
            c = !c;
        }
    }
    c
}

/// The rotor's area by the shoelace formula on its outline is the closed form
/// `π R² (1 + 1/(2n²))`; the displacement is `2 (π R_a² − A_r) L` (`2.25 π R² L` for two
/// lobes); and two rotors turned by `±a` touch without overlapping at every angle.
#[test]
fn roots_rotors_have_the_closed_form_area_and_mesh_at_every_angle() {
    for (n, speed) in [(2usize, 1450.0), (3, 1000.0)] {
        let v = run_text(
            &format!("roots{n}"),
            &format!(
                "kind = \"gear_pair\"\n\n[[pair]]\ntype = \"roots\"\nlobes = {n}\n\
                 centre_distance = 200\nface_width = 300\nspeed_rpm = {speed}\n\
                 profile_points = 300\n"
            ),
        );
        let pair = &v["pairs"][0];
        let big_r = 100.0;
        let nf = n as f64;
        let area = PI * big_r * big_r * (1.0 + 1.0 / (2.0 * nf * nf));
        close(
            num(&pair["rotor_area"]),
            area,
            1e-9 * area,
            "A_r closed form",
        );
        let outline = rotor(&pair["gears"][0], n);
        close(shoelace(&outline), area, 1e-4 * area, "A_r shoelace");
        let ra = big_r * (1.0 + 1.0 / nf);
        close(num(&pair["tip_radius"]), ra, 1e-12, "R_a");
        let v_rev = 2.0 * (PI * ra * ra - area) * 300.0;
        close(num(&pair["displacement"]), v_rev, 1e-9 * v_rev, "V");
        if n == 2 {
            close(
                v_rev,
                2.25 * PI * big_r * big_r * 300.0,
                1e-6,
                "2.25 π R² L",
            );
        }
        close(
            num(&pair["flow_m3_per_min"]),
            v_rev * 1e-9 * speed,
            1e-12,
            "Q",
        );
        // Rotor 2 above rotor 1, a gap facing down toward rotor 1's upward lobe.
        let o2 = [0.0, 200.0];
        for step in 0..24 {
            let a = TAU / nf * step as f64 / 24.0;
            let p1: Vec<[f64; 2]> = outline.iter().map(|&p| rot(p, a)).collect();
            let p2: Vec<[f64; 2]> = outline
                .iter()
                .map(|&p| {
                    let q = rot(p, PI + PI / nf - a);
                    [q[0] + o2[0], q[1] + o2[1]]
                })
                .collect();
            let boundary = |q: [f64; 2], poly: &[[f64; 2]]| {
                (0..poly.len())
                    .map(|i| seg_dist(q, poly[i], poly[(i + 1) % poly.len()]))
                    .fold(f64::MAX, f64::min)
            };
            let mut gap = f64::MAX;
            for &q in &p2 {
                if q[1] > 160.0 {
                    continue; // far from the mesh
                }
                let d = boundary(q, &p1);
                assert!(
                    !inside(q, &p1) || d < 2e-3,
                    "n = {n}, a = {a}: rotor 2 enters rotor 1 by {d} mm"
                );
                gap = gap.min(d);
            }
            assert!(
                gap < 0.05,
                "n = {n}, a = {a}: the rotors are {gap} mm apart"
            );
        }
    }
}
