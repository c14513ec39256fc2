//! The optimising planner (AORRTC, issue 30):
//! - on a planar two-link arm around a disc, its cost approaches the optimum found by an
//!   independent Dijkstra search on a fine 16-connected grid of the joint plane, and is
//!   never below what the grid allows;
//! - on MotionBenchMaker problems it never returns a costlier path than RRT-Connect (its
//!   first path is RRT-Connect's), every improvement is cheaper than the one before, and
//!   every returned path passes the independent dense re-check;
//! - the same seed gives the same path, bit for bit;
//! - the informed sampler draws uniformly from the prolate hyperspheroid: its second
//!   moments equal the closed form `(d/2)²/(n + 2)` along each semi-axis.

mod plan_common;

use armsim::collision::Obstacle;
use armsim::model::{LoadOptions, Model};
use armsim::planning::informed::InformedSampler;
use armsim::planning::plan_options::{OptimiseBudget, PlannerKind};
use armsim::planning::sampler::Rng;
use armsim::planning::{PlanOptions, PlanResult, PlanStatus, Planner};
use plan_common::{path_length, problems, Recheck, Robot};
use std::collections::BinaryHeap;

/// Two links in the horizontal plane, each a row of spheres, both joints about z.
fn planar_arm() -> Robot {
    let spheres = |n: usize, step: f64| -> String {
        (1..=n)
            .map(|i| {
                format!(
                    "<collision><origin xyz=\"{} 0 0\"/><geometry><sphere radius=\"0.04\"/>\
                     </geometry></collision>",
                    i as f64 * step
                )
            })
            .collect()
    };
    let urdf = format!(
        r#"<robot name="planar2">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>{}</link>
  <link name="l2"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>{}</link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
</robot>"#,
        spheres(5, 0.1),
        spheres(4, 0.1)
    );
    let model = Model::load_str(&urdf, "planar2.urdf", &LoadOptions::default())
        .unwrap()
        .0;
    Robot {
        name: "planar2".into(),
        model,
        disabled: Vec::new(),
        root: "base".into(),
    }
}

/// The length of the shortest grid path from `start` to `goal` over the free cells of a
/// `(2·half + 1)²` grid on `[−3, 3]²` (each cell's centre checked), 16-connected, a move
/// allowed when the cells under seven points along it are free too (Dijkstra).
fn grid_optimum(free: &mut dyn FnMut(&[f64]) -> bool, start: [f64; 2], goal: [f64; 2]) -> f64 {
    let half = 240i64;
    let h = 3.0 / half as f64;
    let side = (2 * half + 1) as usize;
    let at = |i: i64| i as f64 * h;
    let mut occ = vec![false; side * side];
    for i in -half..=half {
        for j in -half..=half {
            occ[((i + half) as usize) * side + (j + half) as usize] = !free(&[at(i), at(j)]);
        }
    }
    let cell = |q: [f64; 2]| [(q[0] / h).round() as i64, (q[1] / h).round() as i64];
    let (s, g) = (cell(start), cell(goal));
    let idx = |c: [i64; 2]| ((c[0] + half) as usize) * side + (c[1] + half) as usize;
    let moves: Vec<[i64; 2]> = (-2i64..=2)
        .flat_map(|a| (-2i64..=2).map(move |b| [a, b]))
        .filter(|m| {
            let (a, b) = (m[0].abs(), m[1].abs());
            (a, b) != (0, 0) && !(a == 2 && b != 1) && !(b == 2 && a != 1)
        })
        .collect();
    assert_eq!(moves.len(), 16);
    let mut dist = vec![f64::INFINITY; side * side];
    let mut heap = BinaryHeap::new();
    dist[idx(s)] = 0.0;
    heap.push((std::cmp::Reverse(0u64), s));
    while let Some((std::cmp::Reverse(dk), c)) = heap.pop() {
        let d = f64::from_bits(dk);
        if d > dist[idx(c)] {
            continue;
        }
        if c == g {
            break;
        }
        for m in &moves {
            let n = [c[0] + m[0], c[1] + m[1]];
            if n.iter().any(|v| v.abs() > half) || occ[idx(n)] {
                continue;
            }
            // The cells the move passes through (at eight points along it) are free.
            let clear = (1..8).all(|k| {
                let t = f64::from(k) / 8.0;
                let p = [
                    (c[0] as f64 + t * m[0] as f64).round() as i64,
                    (c[1] as f64 + t * m[1] as f64).round() as i64,
                ];
                !occ[idx(p)]
            });
            let nd = d + h * ((m[0] * m[0] + m[1] * m[1]) as f64).sqrt();
            if clear && nd < dist[idx(n)] {
                dist[idx(n)] = nd;
                heap.push((std::cmp::Reverse(nd.to_bits()), n));
            }
        }
    }
    // The ends snapped to the grid: add the offsets.
    let off = |q: [f64; 2], c: [i64; 2]| (q[0] - at(c[0])).hypot(q[1] - at(c[1]));
    dist[idx(g)] + off(start, s) + off(goal, g)
}

fn aorrtc(iterations: usize, seed: u64) -> PlanOptions {
    PlanOptions {
        seed,
        planner: PlannerKind::Aorrtc,
        budget: OptimiseBudget {
            iterations,
            time: None,
        },
        ..Default::default()
    }
}

/// The improvements are cheaper one after the other, in time order, and end at the cost.
fn assert_improvements(r: &PlanResult, what: &str) {
    let imp = &r.improvements;
    assert!(!imp.is_empty(), "{what}: no improvement logged");
    for w in imp.windows(2) {
        assert!(w[1].cost < w[0].cost, "{what}: {:?} after {:?}", w[1], w[0]);
        assert!(w[1].time_us >= w[0].time_us && w[1].iterations >= w[0].iterations);
    }
    let last = imp.last().unwrap();
    assert!(
        (last.cost - r.cost).abs() <= 1e-9 * r.cost.max(1.0),
        "{what}"
    );
    assert!(last.time_us <= r.plan_time_us + 1.0, "{what}");
}

#[test]
fn aorrtc_approaches_the_grid_optimum_of_a_planar_arm_around_a_disc() {
    let robot = planar_arm();
    // A disc the forearm must clear: the straight joint-space line sweeps through it.
    let disc = vec![Obstacle::sphere("disc", 0.12, [0.55, 0.45, 0.0])];
    let (start, goal) = ([-0.6, 1.2], [1.6, -0.3]);
    let mut probe = Planner::new(&robot.model, &disc, Some(&[]), PlanOptions::default()).unwrap();
    assert!(
        !probe.edge_free(&start, &goal),
        "the straight line must be blocked"
    );
    let optimum = grid_optimum(&mut |q| probe.is_free(q), start, goal);
    assert!(optimum.is_finite() && optimum > 1.05 * 2.2f64.hypot(1.5));
    let mut check = Recheck::new(&robot, &disc);
    let mut rrtc_excess = Vec::new();
    for seed in 0..6 {
        let mut first = Planner::new(
            &robot.model,
            &disc,
            Some(&[]),
            PlanOptions {
                seed,
                ..Default::default()
            },
        )
        .unwrap();
        let rc = first.plan(&start, &goal);
        let mut pl = Planner::new(&robot.model, &disc, Some(&[]), aorrtc(20_000, seed)).unwrap();
        let r = pl.plan(&start, &goal);
        let what = format!("seed {seed}");
        assert_eq!(r.status, PlanStatus::Solved, "{what}: {:?}", r.reason);
        assert_improvements(&r, &what);
        assert!(check.path(&r.path).max_penetration <= 1e-4, "{what}");
        // The grid's moves are 16 directions: its optimum is above the true one by at
        // most 1/cos(13.3°) − 1 = 2.8 %, and below by at most the half cell it cuts.
        assert!(
            r.cost <= 1.01 * optimum,
            "{what}: cost {} against the grid optimum {optimum}",
            r.cost
        );
        assert!(
            r.cost >= optimum / 1.03 - 0.02,
            "{what}: {} < {optimum}",
            r.cost
        );
        assert!(r.cost <= rc.cost + 1e-9, "{what}");
        rrtc_excess.push(rc.cost / optimum - 1.0);
    }
    eprintln!("RRT-Connect (simplified) above the grid optimum {optimum:.4}: {rrtc_excess:.3?}");
}

#[test]
fn aorrtc_never_costs_more_than_rrt_connect_and_its_paths_recheck() {
    for (name, scene) in [("panda", "table_pick"), ("ur5", "box")] {
        let robot = Robot::load(name);
        for p in problems(&robot, scene).iter().filter(|p| p.valid).take(8) {
            let what = format!("{name}/{scene} {}", p.id);
            let mut rc = Planner::new(&robot.model, &p.obstacles, Some(&robot.disabled), {
                PlanOptions::default()
            })
            .unwrap();
            let first = rc.plan(&p.start, &p.goal);
            let mut ao = Planner::new(
                &robot.model,
                &p.obstacles,
                Some(&robot.disabled),
                aorrtc(2000, 0),
            )
            .unwrap();
            let r = ao.plan(&p.start, &p.goal);
            assert_eq!(r.status, PlanStatus::Solved, "{what}: {:?}", r.reason);
            assert_eq!(r.planner, PlannerKind::Aorrtc);
            assert_improvements(&r, &what);
            // Its first path is RRT-Connect's, simplified alike.
            assert_eq!(
                r.improvements[0].cost.to_bits(),
                first.cost.to_bits(),
                "{what}"
            );
            assert!(r.cost <= first.cost, "{what}");
            assert!((r.cost - path_length(&r.path)).abs() <= 1e-5 * r.cost.max(1.0));
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&r.path[0]), bits(&p.start));
            assert_eq!(bits(r.path.last().unwrap()), bits(&p.goal));
            let rep = Recheck::new(&robot, &p.obstacles).path(&r.path);
            assert!(rep.max_penetration <= 1e-4, "{what}: {rep:?}");
            assert!(
                r.iterations >= 2000 || r.path.len() == 2,
                "{what}: budget unspent"
            );
        }
    }
}

#[test]
fn same_seed_gives_the_same_optimised_path() {
    let robot = Robot::load("panda");
    for p in problems(&robot, "bookshelf_small")
        .iter()
        .filter(|p| p.valid)
        .take(4)
    {
        let opts = aorrtc(1500, 3);
        let mut a = Planner::new(
            &robot.model,
            &p.obstacles,
            Some(&robot.disabled),
            opts.clone(),
        )
        .unwrap();
        let mut b = Planner::new(&robot.model, &p.obstacles, Some(&robot.disabled), opts).unwrap();
        let (ra, rb, ra2) = (
            a.plan(&p.start, &p.goal),
            b.plan(&p.start, &p.goal),
            a.plan(&p.start, &p.goal),
        );
        for r in [&rb, &ra2] {
            assert_eq!(r.path, ra.path, "bookshelf_small {}", p.id);
            assert_eq!(r.iterations, ra.iterations);
            let costs = |r: &PlanResult| r.improvements.iter().map(|i| i.cost).collect::<Vec<_>>();
            assert_eq!(costs(r), costs(&ra));
        }
    }
}

#[test]
fn informed_samples_have_the_second_moments_of_a_uniform_hyperspheroid() {
    // Foci 2 apart in 5-D, transverse diameter 3: semi-axes 1.5 and √(9 − 4)/2.
    let n = 5;
    let start = [0.1, -0.2, 0.3, 0.0, 0.5];
    let dir = [0.6, 0.0, 0.8, 0.0, 0.0];
    let goal: Vec<f32> = start.iter().zip(dir).map(|(s, d)| s + 2.0 * d).collect();
    let (lo, hi) = (vec![-50.0; n], vec![50.0; n]);
    let mut s = InformedSampler::new(&start, &goal, &lo, &hi);
    s.set_cost_bound(3.0);
    let centre: Vec<f64> = start
        .iter()
        .zip(&goal)
        .map(|(a, b)| 0.5 * f64::from(a + b))
        .collect();
    let mut rng = Rng::new(11);
    let (samples, mut x) = (200_000, vec![0.0f32; n]);
    let (mut along2, mut across2, mut mean) = (0.0, 0.0, vec![0.0; n]);
    for _ in 0..samples {
        s.sample(&mut rng, &mut x);
        assert!(
            s.heuristic(&x) <= 3.0 + 1e-5,
            "{x:?} outside the hyperspheroid"
        );
        let d: Vec<f64> = x
            .iter()
            .zip(&centre)
            .map(|(v, c)| f64::from(*v) - c)
            .collect();
        let a: f64 = d.iter().zip(dir).map(|(v, u)| v * f64::from(u)).sum();
        along2 += a * a;
        across2 += d.iter().map(|v| v * v).sum::<f64>() - a * a;
        for k in 0..n {
            mean[k] += d[k];
        }
    }
    let m = samples as f64;
    // E[u_i²] = r_i²/(n + 2) for u uniform in an ellipsoid of semi-axes r_i.
    let (ra, rc2) = (1.5f64, (9.0 - 4.0) / 4.0);
    let want_along = ra * ra / (n as f64 + 2.0);
    let want_across = (n as f64 - 1.0) * rc2 / (n as f64 + 2.0);
    assert!(
        (along2 / m / want_along - 1.0).abs() < 0.01,
        "{}",
        along2 / m
    );
    assert!(
        (across2 / m / want_across - 1.0).abs() < 0.01,
        "{}",
        across2 / m
    );
    assert!(mean.iter().all(|v| (v / m).abs() < 0.005), "{mean:?}");
}
