//! The trade-offs report (`armsim tradeoffs`): the eight studies run at their smoke-test
//! sizes (`StudyMode::Tiny`, seconds) through the library, and the figures they produce are
//! checked for structure and for the physics and numerics they should show (a tighter
//! IK tolerance gives a smaller residual, RK4's energy error falls with the step, ABA
//! and CRBA agree, Sobol' beats random sampling once the grid is covered, finite
//! differences of the dynamics follow their O(h) and O(h²) truncation and stay far from
//! the analytical derivatives, …). The report files are checked (eight sections, at least
//! four image links that exist as PNGs),
//! and the hidden `--tiny` flag runs the command end to end. Nothing here asserts on a
//! time: the machines are shared.

use armsim::studies::tradeoffs::derivatives_report;
use armsim::studies::tradeoffs::difference_quotients::{Kernel, Scheme};
use armsim::studies::tradeoffs::ik_study as ik;
use armsim::studies::tradeoffs::integrators::IntegratorOutcome;
use armsim::studies::tradeoffs::markdown as report;
use armsim::studies::tradeoffs::{self, Options, StudyMode, TradeoffsReport};
use armsim::workspace::Sampling;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The tiny report, measured once for all tests.
fn tiny() -> &'static TradeoffsReport {
    static REPORT: OnceLock<TradeoffsReport> = OnceLock::new();
    REPORT.get_or_init(|| tradeoffs::run(&Options::new(StudyMode::Tiny)).expect("the studies run"))
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("armsim-tradeoffs-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn finite_positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

#[test]
fn ik_rows_cover_every_method_and_tolerance_and_tighter_tolerances_give_smaller_residuals() {
    let st = &tiny().ik;
    let tols = ik::IkConfig::for_mode(StudyMode::Tiny).tolerances;
    assert_eq!(st.robot, "ur5");
    assert_eq!(st.analytic_kind.as_deref(), Some("ur"));
    for m in [ik::NUMERIC, ik::QP, ik::ANALYTIC] {
        let rows = st.method(m);
        assert_eq!(
            rows.iter().map(|r| r.tol).collect::<Vec<_>>(),
            tols,
            "{m}: one row per tolerance, loosest first"
        );
        for r in &rows {
            assert_eq!(r.targets, st.targets);
            assert!((0.0..=1.0).contains(&r.success_rate));
            assert!(finite_positive(r.time_us.median) && r.time_us.p99 >= r.time_us.median);
            // Every successful residual is within its tolerance.
            if r.residual.count > 0 {
                assert!(
                    r.residual.max <= r.tol,
                    "{m} at {}: {}",
                    r.tol,
                    r.residual.max
                );
            }
        }
    }
    // The numeric solver converges on every reachable target at every tolerance, and the
    // residual it stops at shrinks with the tolerance.
    let num = st.method(ik::NUMERIC);
    assert!(num.iter().all(|r| r.success_rate == 1.0));
    for w in num.windows(2) {
        assert!(
            w[1].residual.max < w[0].residual.max,
            "residual at {} ({}) not below that at {} ({})",
            w[1].tol,
            w[1].residual.max,
            w[0].tol,
            w[0].residual.max
        );
    }
    // The closed form is exact to rounding, whatever the tolerance.
    for r in st.method(ik::ANALYTIC) {
        assert_eq!(r.success_rate, 1.0);
        assert!(r.residual.max < 1e-12);
    }
}

#[test]
fn integrators_show_rk4_order_symplectic_first_order_and_explicit_blow_up_on_springs() {
    let st = &tiny().integrators;
    let dts = tradeoffs::integrators::IntegratorConfig::for_mode(StudyMode::Tiny).dts;
    assert_eq!(st.cases.len(), 2);
    assert_eq!(st.cells.len(), 2 * 3 * dts.len());
    let energy = |case: &str, m: &str| -> Vec<f64> {
        st.series(case, m)
            .iter()
            .map(|c| c.energy.value().expect("finished"))
            .collect()
    };
    // Rigid arm: every method finishes; the steps halve, RK4's energy error falls by well
    // over 4× per halving (fourth order: ≈16×), semi-implicit Euler's by about 2×.
    let rk4 = energy("rigid", "rk4");
    let se = energy("rigid", "semi_implicit_euler");
    for w in dts.windows(2) {
        assert!((w[1] / w[0] - 0.5).abs() < 1e-12, "the tiny steps halve");
    }
    for w in rk4.windows(2) {
        assert!(w[1] < w[0] / 4.0, "RK4 energy error {} → {}", w[0], w[1]);
    }
    for w in se.windows(2) {
        assert!(
            w[1] < w[0] && w[1] > w[0] / 4.0,
            "semi-implicit Euler {} → {}",
            w[0],
            w[1]
        );
    }
    assert!(rk4.iter().zip(&se).all(|(a, b)| a < b));
    // Computed torque with the exact model: the rigid tracking error is integration error.
    for c in st.series("rigid", "rk4") {
        assert!(c.tracking.value().expect("finished") < 1e-6);
        assert!(c.wall_s.is_some_and(finite_positive));
    }
    // Elastic arm: at these steps (h·ω > 2.8) both explicit methods diverge and say so;
    // the implicit one finishes with a bounded energy error.
    let w = st.cases[1]
        .fastest_mode
        .expect("elastic case has a fastest mode");
    assert!(dts.iter().all(|dt| dt * w > 2.83));
    for m in ["semi_implicit_euler", "rk4"] {
        for c in st.series("elastic", m) {
            assert!(
                matches!(c.energy, IntegratorOutcome::Diverged { .. }),
                "{m} {}",
                c.dt
            );
            assert!(c.tracking.diverged() && c.wall_s.is_none());
        }
        assert_eq!(st.largest_stable_dt("elastic", m), None);
    }
    for c in st.series("elastic", "implicit") {
        let e = c.energy.value().expect("the implicit method finishes");
        assert!(e < 0.1, "implicit energy error {e}");
    }
}

#[test]
fn dynamics_formulations_agree_and_are_timed_up_to_their_caps() {
    let st = &tiny().formulations;
    let cfg = tradeoffs::formulations::FormulationConfig::for_mode(StudyMode::Tiny);
    assert_eq!(st.rows.iter().map(|r| r.dof).collect::<Vec<_>>(), cfg.dofs);
    for r in &st.rows {
        for k in 0..3 {
            assert!(
                r.ns[k].is_some_and(|t| finite_positive(t.median)),
                "{} DOF",
                r.dof
            );
        }
        assert_eq!(r.ns[3].is_some(), r.dof <= cfg.max_dof_trace);
        assert_eq!(r.ns[4].is_some(), r.dof <= cfg.max_dof_energy);
        assert!(
            r.aba_vs_crba_abs < 1e-9,
            "{} DOF: {}",
            r.dof,
            r.aba_vs_crba_abs
        );
        assert!(r.roundtrip_rel < 1e-9);
        if let Some(e) = r.rnea_vs_trace_rel {
            assert!(e < 1e-9);
        }
        if let Some(e) = r.rnea_vs_energy_rel {
            assert!(e < 1e-9);
        }
    }
}

#[test]
fn workspace_sobol_beats_random_once_covered_and_its_band_holds_the_truth() {
    let st = &tiny().workspace;
    assert_eq!(st.cases.len(), 1);
    let case = &st.cases[0];
    assert!((case.truth - std::f64::consts::PI * (0.81 - 0.09)).abs() < 1e-12);
    let rand = st.series(&case.name, Sampling::Random);
    let sob = st.series(&case.name, Sampling::Sobol);
    assert_eq!(rand.len(), sob.len());
    assert!(rand.windows(2).all(|w| w[1].samples > w[0].samples));
    let (r, s) = (rand.last().unwrap(), sob.last().unwrap());
    assert_eq!(r.samples, s.samples);
    // At the largest N the grid is covered: finite bands that contain the truth, and the
    // Sobol' estimate about as good as the random one.
    for row in [r, s] {
        assert_eq!(row.converged_fraction, 1.0, "{:?}", row.sampling);
        assert_eq!(row.covered_fraction, Some(1.0), "{:?}", row.sampling);
        assert!(row.median_band.is_finite() && row.mean_abs_error <= row.median_band);
        assert!(row.mean_rel_error < 0.2);
    }
    // Once covered, the closed-occupancy estimator fills random sampling's gaps, and both
    // schemes' errors are the lattice noise of one grid: Sobol' within 10 % of random
    // (measured over the smoke seeds: 0.01335 against 0.01309).
    assert!(
        s.mean_abs_error <= 1.1 * r.mean_abs_error,
        "Sobol' {} vs random {}",
        s.mean_abs_error,
        r.mean_abs_error
    );
    // Under-covered estimates report an infinite band rather than a false one.
    assert!(rand[0].converged_fraction == 0.0 && rand[0].median_band.is_infinite());
}

#[test]
fn effects_are_all_measured_against_the_bare_model() {
    let st = &tiny().effects;
    let names: Vec<&str> = st.rows.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "bare",
            "gravity",
            "friction",
            "rotor",
            "elasticity",
            "payload",
            "external",
            "all"
        ]
    );
    assert_eq!(st.rows[0].inverse_ratio, 1.0);
    assert_eq!(st.rows[0].step_ratio, 1.0);
    for r in &st.rows {
        assert!(finite_positive(r.inverse_ns.median) && finite_positive(r.step_ns.median));
        assert!(finite_positive(r.inverse_ratio) && finite_positive(r.step_ratio));
    }
}

#[test]
fn derivative_differences_show_truncation_orders_and_round_off_and_stay_above_the_analytical_error()
{
    let r = tiny();
    let st = &r.derivatives;
    let names: Vec<&str> = st.cases.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["ur5", "panda", "iiwa14", "chain 8"]);
    assert!(
        st.cases[1].mimic && !st.cases[0].mimic,
        "the Panda's finger is a mimic joint"
    );
    for c in &st.cases {
        let kernels: Vec<Kernel> = c.kernels.iter().map(|k| k.kernel).collect();
        assert_eq!(kernels, Kernel::ALL, "{}", c.name);
        for k in &c.kernels {
            let what = format!("{} {}", c.name, k.kernel.as_str());
            assert_eq!(k.forward_error.len(), st.steps.len());
            assert_eq!(k.central_error.len(), st.steps.len());
            // The analytical Jacobians agree with the extrapolated reference to rounding.
            assert!(k.analytical_error < 1e-11, "{what}: {}", k.analytical_error);
            assert!(
                k.reference_estimate < 1e-11,
                "{what}: {}",
                k.reference_estimate
            );
            // Central differences at h = 1e-5 are good to 1e-7, but not as good as the
            // analytical matrices (by at least 10×).
            let c5 = st.error_at(k, Scheme::Central, 1e-5);
            assert!(
                c5 < 1e-7 && c5 > 10.0 * k.analytical_error,
                "{what}: {c5:e}"
            );
            // Truncation: forward O(h) (10× per decade), central O(h²) (100× per decade).
            let ratio = |s, a, b| st.error_at(k, s, a) / st.error_at(k, s, b);
            let f = ratio(Scheme::Forward, 1e-3, 1e-4);
            assert!((8.0..12.5).contains(&f), "{what}: forward 1e-3/1e-4 = {f}");
            let cc = ratio(Scheme::Central, 1e-2, 1e-3);
            assert!(
                (70.0..140.0).contains(&cc),
                "{what}: central 1e-2/1e-3 = {cc}"
            );
            // Round-off: the best steps sit near ε^½ and ε^⅓, and below them the error
            // grows again by orders of magnitude.
            let (hf, ef) = st.best(k, Scheme::Forward);
            let (hc, ec) = st.best(k, Scheme::Central);
            assert!((1e-9..=1e-6).contains(&hf), "{what}: forward best at {hf}");
            assert!((1e-7..=1e-4).contains(&hc), "{what}: central best at {hc}");
            assert!(ef < 1e-6, "{what}: forward at best {ef:e}");
            assert!(ec < ef / 10.0, "{what}: central {ec:e} vs forward {ef:e}");
            for s in Scheme::ALL {
                let (_, best) = st.best(k, s);
                assert!(st.error_at(k, s, 1e-12) > 1e3 * best, "{what} {s:?}");
            }
            for t in [k.analytical_ns, k.forward_ns, k.central_ns, k.reference_ns] {
                assert!(finite_positive(t.median));
            }
        }
    }
    // The report has a table per robot with every scheme, and the reading quotes the
    // measured figures.
    let md = report::markdown(r);
    for c in &st.cases {
        assert!(
            md.contains(&format!("**{}** ({} DOF", c.name, c.nv)),
            "{}",
            c.name
        );
    }
    for kernel in ["RNEA", "ABA"] {
        for scheme in ["analytical", "forward", "central", "Ridders reference"] {
            let row = format!("| {kernel} | {scheme} |");
            assert_eq!(md.matches(&row).count(), st.cases.len(), "{row}");
        }
    }
    let reading = derivatives_report::reading(st);
    // It quotes the range of the best central errors of RNEA over the robots.
    let best: Vec<f64> = st
        .cases
        .iter()
        .map(|c| st.best(&c.kernels[0], Scheme::Central).1)
        .collect();
    let lo = best.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = best.iter().copied().fold(0.0, f64::max);
    let quoted = format!("{}–{}", report::sci(lo), report::sci(hi));
    assert!(reading.contains(&quoted), "{quoted} not in {reading}");
    assert!(md.contains("Complex step") && md.contains("f64"));
}

/// The image links `![…](file)` of a Markdown text.
#[test]
fn rotor_elements_converge_at_fourth_order_to_the_closed_form_and_the_transfer_matrices() {
    let st = &tiny().rotor;
    assert_eq!(st.cases.len(), 2);
    // The closed form of FX-3: ω1 = 283.6 rad/s, ω_n = n² ω1.
    let u = &st.cases[0];
    assert!((u.reference[0] - 283.6).abs() < 0.1, "{}", u.reference[0]);
    assert!((u.reference[2] / u.reference[0] - 9.0).abs() < 1e-12);
    for c in &st.cases {
        for k in 0..3 {
            let errs: Vec<f64> = c.rows.iter().map(|r| r.relative_error[k]).collect();
            assert!(
                errs.windows(2).all(|w| w[1] < w[0] || w[1] < 1e-10),
                "{} mode {}: errors do not fall: {errs:?}",
                c.name,
                k + 1
            );
            // Finite elements are stiff: they over-estimate, and reach 1e-4 by 16.
            let last = c.rows.last().unwrap();
            assert!(last.omega[k] > c.reference[k] * (1.0 - 1e-10));
            assert!(errs[errs.len() - 1] < 1e-3, "{}: {errs:?}", c.name);
        }
    }
    // h⁴: the fitted slope of mode 1's error against elements is −4 on the uniform shaft;
    // the stepped rotor's few tiny-mode meshes are still pre-asymptotic (steeper).
    let s_uniform = st.cases[0].slope[0].expect("a slope");
    assert!((s_uniform + 4.0).abs() < 0.3, "uniform slope {s_uniform}");
    let s_stepped = st.cases[1].slope[0].expect("a slope");
    assert!(s_stepped < -3.5, "stepped slope {s_stepped}");
    let md = armsim::studies::tradeoffs::rotor_report::reading(st);
    assert!(md.contains("h⁴"), "{md}");
}

fn image_links(md: &str) -> Vec<String> {
    md.match_indices("![")
        .filter_map(|(i, _)| {
            let rest = &md[i..];
            let open = rest.find("](")?;
            let close = rest[open..].find(')')?;
            Some(rest[open + 2..open + close].to_string())
        })
        .collect()
}

fn check_report_dir(dir: &Path) {
    let md = std::fs::read_to_string(dir.join(report::MARKDOWN)).expect("tradeoffs.md");
    for (i, title) in [
        "Inverse kinematics",
        "Integrators",
        "Dynamics formulations",
        "Workspace sampling",
        "Effects",
        "Flexible rotor",
        "Dynamics derivatives",
        "Planning",
    ]
    .iter()
    .enumerate()
    {
        assert!(
            md.contains(&format!("## {}. {title}", i + 1)),
            "section {} '{title}' missing",
            i + 1
        );
    }
    assert_eq!(
        md.matches("\n## ").count(),
        8,
        "exactly eight study sections"
    );
    assert_eq!(md.matches("**Reading.**").count(), 8, "a reading per study");
    for key in [
        "| CPU |",
        "| cores |",
        "| date |",
        "| armsim |",
        "tiny mode",
    ] {
        assert!(md.contains(key), "header lacks {key}");
    }
    let links = image_links(&md);
    assert!(links.len() >= 4, "{links:?}");
    for l in &links {
        let bytes = std::fs::read(dir.join(l)).unwrap_or_else(|e| panic!("{l}: {e}"));
        assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "{l} is not a PNG");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join(report::JSON)).expect("json"))
            .expect("parses");
    assert_eq!(json["mode"], "tiny");
    for k in [
        "ik",
        "integrators",
        "formulations",
        "workspace",
        "effects",
        "rotor",
        "derivatives",
        "planning",
        "machine",
    ] {
        assert!(json.get(k).is_some(), "json lacks {k}");
    }
}

#[test]
fn report_files_have_eight_sections_readings_and_existing_plots() {
    let r = tiny();
    let dir = temp_dir("lib");
    let written = report::write(r, &dir).expect("writes");
    assert!(written.iter().all(|p| p.exists()));
    assert!(
        written
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "png"))
            .count()
            >= 6
    );
    check_report_dir(&dir);
    // The readings quote the measured numbers.
    let md = std::fs::read_to_string(dir.join(report::MARKDOWN)).unwrap();
    let num = r.ik.method(ik::NUMERIC);
    assert!(md.contains(&report::sci(num[0].tol)));
    assert!(report::integrator_reading(r).contains("diverges"));
    assert!(report::formulation_reading(r).contains("agree"));
    // No temporary files are left behind by the atomic writes.
    for e in std::fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().to_string();
        assert!(!name.ends_with(".tmp"), "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cli_tiny_run_writes_the_report() {
    let dir = temp_dir("cli");
    let out = Command::new(env!("CARGO_BIN_EXE_armsim"))
        .args(["tradeoffs", "--tiny", "--out"])
        .arg(&dir)
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("tradeoffs:"),
        "progress goes to stderr: {stderr}"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("tiny mode") && stdout.contains("tradeoffs.md"),
        "{stdout}"
    );
    check_report_dir(&dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cli_rejects_quick_with_tiny_and_an_unwritable_directory() {
    let bin = env!("CARGO_BIN_EXE_armsim");
    let o = Command::new(bin)
        .args(["tradeoffs", "--tiny", "--quick"])
        .output()
        .expect("runs");
    assert!(!o.status.success());
    let o = Command::new(bin)
        .args(["tradeoffs", "--tiny", "--out", "/dev/null/report"])
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("cannot create") && !err.contains("panicked"),
        "{err}"
    );
}

#[test]
fn planning_aorrtc_never_costs_more_than_its_own_rrt_connect_first_path_per_query() {
    use armsim::studies::tradeoffs::planning_study::{self as ps, PlanningConfig};
    let st = &tiny().planning;
    let cfg = PlanningConfig::for_mode(StudyMode::Tiny);
    assert_eq!(st.robots.len(), 2);
    for rb in &st.robots {
        assert_eq!(rb.rows.len(), 1 + cfg.budgets.len(), "{}", rb.robot);
        let first = &rb.rows[0];
        assert_eq!(
            (first.planner.as_str(), first.budget),
            ("rrt-connect", None)
        );
        // Every bundled problem is valid and solved by RRT-Connect.
        assert_eq!(first.solved, first.queries, "{}", rb.robot);
        for row in &rb.rows[1..] {
            assert_eq!(row.planner, "aorrtc");
            assert_eq!(row.queries, first.queries);
            // With the same seed the optimising mode starts from RRT-Connect's simplified
            // first path and keeps only cheaper ones.
            for (a, r) in row.costs.iter().zip(&first.costs) {
                let (a, r) = (a.expect("solved"), r.expect("solved"));
                assert!(
                    a <= r + 1e-9,
                    "{} budget {:?}: {a} > {r}",
                    rb.robot,
                    row.budget
                );
            }
            assert!(row.cost_median <= first.cost_median + 1e-9);
            assert!(finite_positive(row.time_median_us) && row.time_p95_us >= row.time_median_us);
        }
        // No path is shorter than the straight line between its ends, which is at least
        // half a radian in these problems: costs are real lengths.
        assert!(rb.rows.iter().all(|r| r.cost_median > 0.5), "{}", rb.robot);
    }
    // The recorded VAMP figures cover both robots, RRT-Connect and each recorded budget.
    let rec = ps::parse_vamp_record(ps::VAMP_RECORD).expect("the record parses");
    for robot in ["panda", "ur5"] {
        assert!(rec.iter().any(|v| v.robot == robot && v.planner == "rrtc"));
        assert!(
            rec.iter()
                .filter(|v| v.robot == robot && v.planner == "aorrtc")
                .count()
                >= 4
        );
    }
    assert!(rec.iter().all(|v| v
        .vamp
        .iter()
        .chain(&v.armsim)
        .all(|x| x.is_finite() && *x > 0.0)));
    let bad = "robot,planner\npanda,rrtc,0,99,99,nan,1,1,99,1,1,1,x\n";
    let e = ps::parse_vamp_record(bad).unwrap_err();
    assert!(
        e.contains(":2: field 6") && e.contains("not a number"),
        "{e}"
    );
    let short = "robot,planner\npanda,rrtc,0\n";
    let e = ps::parse_vamp_record(short).unwrap_err();
    assert!(e.contains(":2: expected 13 fields, got 3"), "{e}");
}
