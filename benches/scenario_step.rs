//! What one simulation step of an arm scenario costs, with and without each effect, with the
//! rapier3d contact scene, and with and without MCAP recording.
//!
//! The scenes are the UR5 of `scenarios/ur5_push_box.toml` (computed-torque control, RK4,
//! h = 1 ms, its planned push trajectory as reference), loaded through the scenario
//! loader (`armsim::scenarios::arm::load`) with only the `effects = [...]` line changed and parameter
//! tables added (UR5-typical values, below; tables of effects left out are ignored, as in
//! any scenario). Each row runs the real machinery, `Simulator::run_with_hook`, over a
//! fixed number of steps; the time reported by criterion is **per step** (the time of
//! the run divided by its number of steps, via `iter_custom`).
//!
//! - Rigid rows: the first `STEPS` steps of the scenario from its initial configuration.
//! - The energy audit runs when nothing dissipates (bare, gravity, undamped elastic
//!   joints): the row `bare, audit off` shows its share.
//! - Contact rows (`gravity` + `contact`, the push-box scene as written): `approach` =
//!   the first `STEPS` steps (pusher clear of the box, box resting on the table);
//!   `pushing` = `STEPS` steps from 10 ms before the first pusher–box contact (the arm
//!   starts there at rest on the reference). The rapier world is built outside the
//!   timing.
//! - Recording rows: gravity + friction + payload (the `ur5_pick_and_place` effect set),
//!   `REC_STEPS` steps (1 s); each iteration creates the MCAP file, writes every sample
//!   (`RobotTf::frame_at` + `McapWriter::write_frame`) during the timed run and finishes
//!   it; creating and finishing the file are timed on their own (per file).
//!
//! Run: `cargo bench --bench scenario_step`.

use armsim::dynamics::ExternalWrench;
use armsim::io::record::mcap_out::McapWriter;
use armsim::io::record::Header;
use armsim::model::data::Data;
use armsim::motion::Trajectory;
use armsim::scenarios::arm::contact::ContactSim;
use armsim::scenarios::arm::scene::Scene;
use armsim::sim::{Integrator, NoHook, Reference, SimConfig, Simulator, StepHook};
use criterion::{criterion_group, criterion_main, Criterion};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Steps per timed run (effect and contact rows).
const STEPS: usize = 200;
/// Steps per timed run (recording rows): 1 s at 1 ms.
const REC_STEPS: usize = 1000;

/// Parameter tables appended to the push-box scenario (UR5-typical values; the bundled
/// URDF has no `<dynamics>` and no motor data).
const TABLES: &str = r#"
[friction]
viscous = [2.0, 2.0, 1.5, 0.5, 0.5, 0.5]
coulomb = [3.0, 3.0, 2.0, 1.0, 1.0, 1.0]

[rotor_inertia]
inertia = [5e-5, 5e-5, 5e-5, 1e-5, 1e-5, 1e-5]
gear_ratio = [100.0, 100.0, 100.0, 100.0, 100.0, 100.0]
efficiency = [0.9, 0.9, 0.9, 0.9, 0.9, 0.9]

[joint_elasticity]
stiffness = [8000.0, 8000.0, 5000.0, 1500.0, 1500.0, 1000.0]
damping = 0.0
motor_inertia = [0.5, 0.5, 0.5, 0.1, 0.1, 0.1]

[payload]
mass = 1.5
com = [0.0, 0.0, 0.08]
"#;

fn scenario_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/ur5_push_box.toml")
}

/// The push-box scenario with `effects` named (and the parameter tables above).
fn scene(effects: &[&str]) -> Scene {
    let path = scenario_path();
    let text = std::fs::read_to_string(&path).expect("scenario");
    let list = effects
        .iter()
        .map(|e| format!("\"{e}\""))
        .collect::<Vec<_>>()
        .join(", ");
    let old = "effects = [\"gravity\", \"contact\"]";
    assert!(text.contains(old), "the push-box scenario changed");
    let text = text.replacen(old, &format!("effects = [{list}]"), 1) + TABLES;
    armsim::scenarios::arm::load(&path, &text).unwrap_or_else(|e| panic!("{effects:?}: {e}"))
}

/// The reference shifted in time: `q_d(t) = traj(t0 + t)`.
struct Shifted<'a> {
    traj: &'a dyn Trajectory,
    t0: f64,
}

impl Reference for Shifted<'_> {
    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        self.traj.sample(self.t0 + t, q, qd, qdd);
    }
}

/// A hook that does nothing but declares itself non-conservative: the energy audit is off.
struct NoAudit;

impl StepHook for NoAudit {
    fn before_step(&mut self, _: f64, _: &[f64], _: &[f64], _: &mut Vec<ExternalWrench>) -> bool {
        true
    }
    fn conservative(&self) -> bool {
        false
    }
}

fn never() -> bool {
    false
}

fn cfg(
    scene: &Scene,
    integrator: Option<Integrator>,
    steps: usize,
    record_every: usize,
) -> SimConfig {
    let ss = scene.simulation.as_ref().expect("[simulation]");
    SimConfig {
        dt: ss.dt,
        duration: steps as f64 * ss.dt,
        integrator: integrator.unwrap_or(ss.integrator),
        controller: ss.controller.clone(),
        record_every,
    }
}

fn gravity_in_scene(scene: &Scene) -> [f64; 3] {
    let g = scene
        .effects
        .gravity
        .map(|g| scene.base.rot * g)
        .unwrap_or_default();
    [g.x, g.y, g.z]
}

fn bench(c: &mut Criterion) {
    // The push trajectory, planned once from the contact scene (the task is the same in
    // every row).
    let contact_scene = scene(&["gravity", "contact"]);
    let plan = armsim::scenarios::arm::task_motion::plan(&contact_scene).expect("plan");
    let traj = &plan.trajectory;
    let start = Shifted { traj, t0: 0.0 };
    let h = contact_scene.simulation.as_ref().unwrap().dt;
    let t_push = first_contact(&contact_scene, &start, traj.duration()) - 0.01;
    let push = Shifted { traj, t0: t_push };
    let mut q_push = vec![0.0; contact_scene.model.nv];
    let (mut a, mut b) = (q_push.clone(), q_push.clone());
    traj.sample(t_push, &mut q_push, &mut a, &mut b);

    let mut g = c.benchmark_group("ur5_step");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    effect_rows(&mut g, &start);
    contact_rows(
        &mut g,
        &contact_scene,
        h,
        [(&contact_scene.q0, &start), (&q_push, &push)],
    );
    // Recording rows (1000-step runs: more time per sample).
    g.measurement_time(Duration::from_secs(6));
    recording_rows(&mut g, &start);
    g.finish();
}

type Group<'a> = criterion::BenchmarkGroup<'a, criterion::measurement::WallTime>;

/// The time of the first pusher–box contact of the full scenario run.
fn first_contact(contact_scene: &Scene, start: &Shifted, duration: f64) -> f64 {
    let h = contact_scene.simulation.as_ref().unwrap().dt;
    let model = &contact_scene.model;
    let stop: &dyn Fn() -> bool = &never;
    let cs = contact_scene.contact.as_ref().unwrap();
    let mut hook = ContactSim::new(
        model,
        contact_scene.base,
        cs,
        gravity_in_scene(contact_scene),
        h,
        stop,
    );
    hook.place(&contact_scene.q0);
    let mut sim = Simulator::new(model, contact_scene.effects.clone()).unwrap();
    let steps = (duration / h).round() as usize;
    sim.run_with_hook(
        &contact_scene.q0,
        &cfg(contact_scene, None, steps, 1),
        start,
        &mut hook,
        |_| {},
    )
    .unwrap();
    hook.report()
        .first_contact_s
        .expect("the pusher reaches the box")
}

/// The rigid and elastic rows, one per effect set (and integrator, and audit off).
fn effect_rows(g: &mut Group, start: &Shifted) {
    // Rigid and elastic rows: (label, effects named, integrator override, audit off).
    let rows: Vec<(&str, Vec<&str>, Option<Integrator>, bool)> = vec![
        ("bare", vec![], None, false),
        ("bare, audit off", vec![], None, true),
        ("bare, implicit", vec![], Some(Integrator::Implicit), false),
        ("gravity", vec!["gravity"], None, false),
        ("friction", vec!["friction"], None, false),
        ("rotor_inertia", vec!["rotor_inertia"], None, false),
        ("joint_elasticity", vec!["joint_elasticity"], None, false),
        (
            "joint_elasticity, implicit",
            vec!["joint_elasticity"],
            Some(Integrator::Implicit),
            false,
        ),
        ("payload", vec!["payload"], None, false),
        (
            "all rigid (gravity friction rotor payload)",
            vec!["gravity", "friction", "rotor_inertia", "payload"],
            None,
            false,
        ),
    ];
    for (label, names, integrator, audit_off) in rows {
        let sc = scene(&names);
        let model = &sc.model;
        let mut sim = Simulator::new(model, sc.effects.clone()).unwrap();
        let config = cfg(&sc, integrator, STEPS, usize::MAX);
        // One run outside the timing: it must not diverge, and the effect-run counters show
        // which effects' code ran (a left-out effect stays at 0).
        sim.run_with_hook(&sc.q0, &config, start, &mut NoHook, |_| {})
            .unwrap_or_else(|e| panic!("{label}: {e}"));
        eprintln!(
            "{label}: effect-run counters after one {STEPS}-step run {:?}",
            sim.effect_runs()
        );
        g.bench_function(label, |bch| {
            bch.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let t = Instant::now();
                    let r = if audit_off {
                        sim.run_with_hook(&sc.q0, &config, start, &mut NoAudit, |_| {})
                    } else {
                        sim.run_with_hook(&sc.q0, &config, start, &mut NoHook, |_| {})
                    };
                    total += t.elapsed();
                    assert_eq!(r.unwrap().steps, STEPS);
                }
                total / STEPS as u32
            })
        });
    }
}

/// The contact rows: approaching the box, and pushing it.
fn contact_rows(g: &mut Group, sc: &Scene, h: f64, runs: [(&Vec<f64>, &Shifted); 2]) {
    let model = &sc.model;
    let stop: &dyn Fn() -> bool = &never;
    let grav = gravity_in_scene(sc);
    let cs = sc.contact.as_ref().unwrap();
    let mut sim = Simulator::new(model, sc.effects.clone()).unwrap();
    let config = cfg(sc, None, STEPS, usize::MAX);
    for (label, (q0, reference)) in ["contact, approach", "contact, pushing"]
        .into_iter()
        .zip(runs)
    {
        let mut hook = ContactSim::new(model, sc.base, cs, grav, h, stop);
        hook.place(q0);
        sim.run_with_hook(q0, &config, reference, &mut hook, |_| {})
            .unwrap();
        let r = hook.report();
        eprintln!(
            "{label}: {} steps in contact of {STEPS}, box moved {:.4} m, max force {:.2} N",
            (r.contact_time_s / h).round(),
            r.box_displacement_m,
            r.max_contact_force_n
        );
        g.bench_function(label, |bch| {
            bch.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let mut hook = ContactSim::new(model, sc.base, cs, grav, h, stop);
                    hook.trace.reserve(STEPS + 2);
                    hook.place(q0);
                    let t = Instant::now();
                    let r = sim.run_with_hook(q0, &config, reference, &mut hook, |_| {});
                    total += t.elapsed();
                    assert_eq!(r.unwrap().steps, STEPS);
                }
                total / STEPS as u32
            })
        });
    }
}

/// The recording rows: none, every step, every 10th step, one frame alone, and the fixed
/// cost of a file.
fn recording_rows(g: &mut Group, start: &Shifted) {
    let sc = scene(&["gravity", "friction", "payload"]);
    let model = &sc.model;
    let mut sim = Simulator::new(model, sc.effects.clone()).unwrap();
    let (header, robot_tf) = Header::for_model(&sc.name, &sc.model_path, model, &sc.spec);
    let dir = std::env::temp_dir().join(format!("armsim-bench-rec-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("ur5.mcap");
    let mut data = Data::new(model);
    for (label, every) in [
        ("record: none", None),
        ("record: every step (1 kHz)", Some(1)),
        ("record: 100 Hz (every 10th step)", Some(10)),
    ] {
        let config = cfg(&sc, None, REC_STEPS, every.unwrap_or(usize::MAX));
        g.bench_function(label, |bch| {
            bch.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let r = if every.is_some() {
                        // Creating and finishing the file are a fixed cost per run,
                        // timed separately below.
                        let mut w = McapWriter::create(&file, &header).unwrap();
                        let t = Instant::now();
                        let r = sim.run_with_hook(&sc.q0, &config, start, &mut NoHook, |s| {
                            let frame = robot_tf.frame_at(model, &mut data, s.t, s.q, s.qd, s.tau);
                            w.write_frame(&frame).unwrap();
                        });
                        total += t.elapsed();
                        w.finish().unwrap();
                        r
                    } else {
                        let t = Instant::now();
                        let r = sim.run_with_hook(&sc.q0, &config, start, &mut NoHook, |_| {});
                        total += t.elapsed();
                        r
                    };
                    assert_eq!(r.unwrap().steps, REC_STEPS);
                }
                total / REC_STEPS as u32
            })
        });
    }
    // One frame on its own (forward kinematics, tf, CDR encoding, chunk writing and
    // compression as chunks fill): the marginal cost of a recorded sample, in a tight
    // loop, so it does not depend on how the scheduler treats the file I/O of a run.
    let qd0 = vec![0.1; model.nv];
    let tau0 = vec![1.0; model.nv];
    g.bench_function("record: one frame (frame_at + write_frame)", |bch| {
        bch.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut left = iters;
            while left > 0 {
                let k = left.min(10_000);
                let mut w = McapWriter::create(&file, &header).unwrap();
                let t = Instant::now();
                for i in 0..k {
                    let frame =
                        robot_tf.frame_at(model, &mut data, i as f64 * 1e-3, &sc.q0, &qd0, &tau0);
                    w.write_frame(&frame).unwrap();
                }
                total += t.elapsed();
                w.finish().unwrap();
                left -= k;
            }
            total
        })
    });
    // The fixed cost per recorded run: create the file (metadata, robot description,
    // static tf) and finish it (last chunk, summary, rename), no frames. Per file, not
    // per step.
    g.bench_function("record: file create + finish (per file)", |bch| {
        bch.iter(|| {
            let w = McapWriter::create(&file, &header).unwrap();
            w.finish().unwrap()
        })
    });
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, bench);
criterion_main!(benches);
