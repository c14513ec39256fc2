//! Criterion benchmarks of the motion planner on fixed MotionBenchMaker problems (Panda,
//! `table_pick` 0001–0010 and `box` 0001–0010, from `../shared/benchmarks/motion-planning`
//! beside the clone): per scene, the ten queries end to end (start/goal checks, search,
//! simplification) on planners built beforehand, the same without simplification, and
//! the scene set-up plus the queries (planner construction from parsed obstacles).
//! Run: `cargo bench --bench planning`. The anchor-style table over whole folders comes
//! from `armsim plan … --moveit-dir DIR --passes 5` (see BENCHMARKS.md).

use armsim::collision::Obstacle;
use armsim::model::Model;
use armsim::planning::srdf;
use armsim::planning::{moveit, PlanOptions, PlanStatus, Planner};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::PathBuf;

/// The model, its SRDF's disabled pairs, and the problems per scene.
type Setup = (
    Model,
    Vec<(String, String)>,
    Vec<(&'static str, Vec<Problem>)>,
);

struct Problem {
    obstacles: Vec<Obstacle>,
    start: Vec<f64>,
    goal: Vec<f64>,
}

fn setup() -> Setup {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let bench = root.join("../shared/benchmarks/motion-planning/panda");
    assert!(
        bench.is_dir(),
        "the benchmark data is expected at {}",
        bench.display()
    );
    let model = Model::load(root.join("robots/spherized/panda_spherized.urdf"))
        .unwrap()
        .0;
    let (disabled, _) =
        srdf::load_disabled_pairs(root.join("robots/spherized/panda.srdf"), &model).unwrap();
    let scenes = ["table_pick", "box"]
        .map(|scene| {
            let problems = (1..=10)
                .map(|k| {
                    let dir = bench.join(scene);
                    let obstacles = moveit::load_scene_in(
                        dir.join(format!("scene{k:04}.yaml")),
                        &["panda_link0"],
                    )
                    .unwrap();
                    let (req, _) =
                        moveit::load_request(dir.join(format!("request{k:04}.yaml")), &model)
                            .unwrap();
                    Problem {
                        obstacles,
                        start: req.start,
                        goal: req.goal,
                    }
                })
                .collect();
            (scene, problems)
        })
        .into();
    (model, disabled, scenes)
}

fn planning(c: &mut Criterion) {
    let (model, disabled, scenes) = setup();
    let mut g = c.benchmark_group("plan_panda");
    for (scene, problems) in &scenes {
        for simplify in [true, false] {
            let opts = PlanOptions {
                simplify,
                ..Default::default()
            };
            let mut planners: Vec<Planner> = problems
                .iter()
                .map(|p| Planner::new(&model, &p.obstacles, Some(&disabled), opts.clone()).unwrap())
                .collect();
            for (pl, p) in planners.iter_mut().zip(problems) {
                assert_eq!(pl.plan(&p.start, &p.goal).status, PlanStatus::Solved);
            }
            let name = if simplify {
                "query"
            } else {
                "query_no_simplify"
            };
            g.bench_function(format!("{scene}_0001-0010_{name}"), |b| {
                b.iter(|| {
                    for (pl, p) in planners.iter_mut().zip(problems) {
                        black_box(pl.plan(black_box(&p.start), black_box(&p.goal)));
                    }
                })
            });
        }
        g.bench_function(format!("{scene}_0001-0010_setup_and_query"), |b| {
            b.iter(|| {
                for p in problems {
                    let mut pl = Planner::new(
                        &model,
                        &p.obstacles,
                        Some(&disabled),
                        PlanOptions::default(),
                    )
                    .unwrap();
                    black_box(pl.plan(&p.start, &p.goal));
                }
            })
        });
    }
    g.finish();
}

criterion_group!(benches, planning);
criterion_main!(benches);
