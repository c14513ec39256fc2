//! Accuracy of the headline workspace measure on closed-form arms that the calibration
//! test does not use (other sizes and joint ranges of the spherical R-R-P, the
//! cylindrical R-P-P and the planar 2R): at 5 M samples and 2 cm voxels the headline is
//! within 3 % of the closed form, and the interval (or lower bound) covers it at every
//! budget. `WS_TABLE=1` prints the table of `docs/workspace.md`.

use armsim::model::parse::dh_table as dh;
use armsim::model::Model;
use armsim::workspace::{sample_workspace, WorkspaceOptions, WorkspaceResult};
use std::f64::consts::PI;

fn build(text: &str, name: &str) -> Model {
    Model::build(dh::parse(text, name).expect("parses"))
        .expect("builds")
        .0
}

fn robot_text(rel: &str) -> String {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(p).expect("readable")
}

/// Replaces the first `lower… = a` / `upper… = b` pair after `from` in `text`.
fn set_range(text: &str, key: &str, old: (f64, f64), new: (f64, f64)) -> String {
    let pat = format!("lower{key} = {:?}\nupper{key} = {:?}", old.0, old.1);
    assert!(text.contains(&pat), "{pat}");
    text.replacen(
        &pat,
        &format!("lower{key} = {:?}\nupper{key} = {:?}", new.0, new.1),
        1,
    )
}

/// A spherical R-R-P: azimuth `±az`, elevation `[el0, el1]` (degrees), radius `[r0, r1]`.
fn rrp(az: f64, el: (f64, f64), r: (f64, f64)) -> (Model, f64) {
    let t = robot_text("robots/textbook_spherical_rrp.toml");
    let t = set_range(&t, "_deg", (-170.0, 170.0), (-az, az));
    let t = set_range(&t, "_deg", (-45.0, 60.0), el);
    let t = set_range(&t, "", (0.6, 1.5), r);
    let d = |x: f64| x.to_radians();
    let truth = (r.1.powi(3) - r.0.powi(3)) / 3.0 * (d(el.1).sin() - d(el.0).sin()) * d(2.0 * az);
    (build(&t, "rrp.toml"), truth)
}

/// A cylindrical R-P-P: azimuth `±az` (degrees), lift `[z0, z1]`, radius `[r0, r1]`.
fn rpp(az: f64, lift: (f64, f64), r: (f64, f64)) -> (Model, f64) {
    let t = robot_text("robots/textbook_cylindrical_rpp.toml");
    let t = set_range(&t, "_deg", (-170.0, 170.0), (-az, az));
    let t = set_range(&t, "", (0.2, 1.2), lift);
    let t = set_range(&t, "", (0.3, 0.9), r);
    let truth = 0.5 * (r.1 * r.1 - r.0 * r.0) * (2.0 * az).to_radians() * (lift.1 - lift.0);
    (build(&t, "rpp.toml"), truth)
}

/// A planar 2R with continuous joints and link lengths `l1`, `l2`: an annulus.
fn planar_2r(l1: f64, l2: f64) -> (Model, f64) {
    let t = robot_text("robots/planar_2r.toml");
    let t = t.replacen("a = 0.5", &format!("a = {l1:?}"), 1).replacen(
        "a = 0.5",
        &format!("a = {l2:?}"),
        1,
    );
    let truth = PI * ((l1 + l2).powi(2) - (l1 - l2).powi(2));
    (build(&t, "planar_2r.toml"), truth)
}

/// The arms of the table: name, model, closed form.
fn arms() -> Vec<(&'static str, Model, f64)> {
    let mut v = Vec::new();
    let mut add = |n, (m, t)| v.push((n, m, t));
    add(
        "R-R-P r 0.5–1.8, ±150°, el −30..70°",
        rrp(150.0, (-30.0, 70.0), (0.5, 1.8)),
    );
    add(
        "R-R-P r 0.3–0.8, ±180°, el ±90°",
        rrp(180.0, (-90.0, 90.0), (0.3, 0.8)),
    );
    add(
        "R-R-P r 0.2–0.5, ±120°, el ±60°",
        rrp(120.0, (-60.0, 60.0), (0.2, 0.5)),
    );
    add(
        "R-R-P r 1.0–1.6, ±90°, el −10..40°",
        rrp(90.0, (-10.0, 40.0), (1.0, 1.6)),
    );
    add(
        "R-P-P r 0.2–1.4, z 0–1.5, ±175°",
        rpp(175.0, (0.0, 1.5), (0.2, 1.4)),
    );
    add(
        "R-P-P r 0.5–0.7, z 0.1–0.6, ±60°",
        rpp(60.0, (0.1, 0.6), (0.5, 0.7)),
    );
    add("2R l 0.7, 0.4 (annulus)", planar_2r(0.7, 0.4));
    add("2R l 1.2, 1.2 (disc)", planar_2r(1.2, 1.2));
    v
}

fn run(m: &Model, samples: u64, voxel: f64, seed: u64) -> WorkspaceResult {
    let o = WorkspaceOptions {
        samples,
        voxel,
        seed,
        extras: false,
        quiet: true,
        ..Default::default()
    };
    sample_workspace(m, &o).expect("runs")
}

/// At 5 M samples and 2 cm voxels the headline is within 3 % of the closed form on every
/// arm, and at every budget from 1/64 of that to 4 times it the interval covers it.
#[test]
fn headline_within_three_percent_at_5m_samples_and_2cm() {
    let table = std::env::var("WS_TABLE").is_ok();
    let mut bad = Vec::new();
    for (name, m, truth) in arms() {
        let budgets: &[u64] = if table {
            &[78_125, 312_500, 1_250_000, 5_000_000, 20_000_000]
        } else {
            &[78_125, 5_000_000]
        };
        for &n in budgets {
            let r = run(&m, n, 0.02, 0);
            let e = &r.estimate;
            let err = r.measure() / truth - 1.0;
            let [lo, hi] = r.measure_interval();
            eprintln!(
                "| {name} | {} | 0.02 | {:.4} | {truth:.4} | {:+.2} % | [{:.4}, {}] | {:?} | C {:.4}, unhit {:.3} |",
                r.samples,
                r.measure(),
                100.0 * err,
                lo.unwrap_or(0.0),
                hi.map_or("–".into(), |v| format!("{v:.4}")),
                r.interval_kind,
                e.corrected,
                e.unhit_fraction,
            );
            if n == 5_000_000 && err.abs() > 0.03 {
                bad.push(format!("{name}: {:+.2} % at {n}", 100.0 * err));
            }
            if !r.interval_covers(truth) {
                bad.push(format!(
                    "{name}: interval {lo:?}–{hi:?} misses {truth} at {n}"
                ));
            }
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}
