//! Planning on the robot a user brings (issue 26, part 1): the bundled URDFs plan with no
//! SRDF through the computed allowed-collision matrix; the matrix is checked against the
//! exact geometry on samples of its own; a rejected start names the pair it touches; a
//! planner built once gives the same path as a fresh one; the stop flag (Ctrl-C) ends a
//! long search at once.

use armsim::collision::{CollisionData, CollisionModel, CollisionOptions, Obstacle};
use armsim::model::Model;
use armsim::planning::acm::{self, AcmOptions, Reason};
use armsim::planning::sampler::{bounds, Rng};
use armsim::planning::{PairSource, PlanOptions, PlanStatus, Planner, PlanningRobot};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

mod plan_common;

fn robot(file: &str) -> Model {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("robots")
        .join(file);
    Model::load(&p).unwrap().0
}

fn options(seed: u64) -> PlanOptions {
    PlanOptions {
        seed,
        time_limit: Some(Duration::from_secs(10)),
        ..Default::default()
    }
}

/// The UR5 home pose of the issue.
const UR5_HOME: [f64; 6] = [0.0, -1.57, 1.57, 0.0, 1.57, 0.0];

#[test]
fn ur5_home_pose_plans_without_an_srdf() {
    let model = robot("ur5.urdf");
    let mut p = Planner::new(&model, &[], None, options(0)).unwrap();
    let goal = [1.2, -1.0, 1.0, -1.5, -1.2, 0.5];
    let r = p.plan(&UR5_HOME, &goal);
    assert_eq!(r.status, PlanStatus::Solved, "{:?}", r.reason);
    // Among a box in the straight path too.
    let wall = Obstacle::cuboid("wall", [0.3, 0.05, 0.5], [0.45, 0.45, 0.25]);
    p.set_obstacles(&[wall]).unwrap();
    let r = p.plan(&UR5_HOME, &goal);
    assert_eq!(r.status, PlanStatus::Solved, "{:?}", r.reason);
}

/// Random start/goal pairs of the joint box, free on the sphere model. (The UR5's joints
/// all span ±2π, and its random pairs can lie in pockets that the sphere model separates:
/// it is tried from its home pose in `ur5_home_pose_plans_without_an_srdf`.)
#[test]
fn bundled_panda_and_iiwa_plan_random_problems_without_an_srdf() {
    for file in ["panda.urdf", "iiwa14.urdf"] {
        let model = robot(file);
        let robot = Arc::new(PlanningRobot::new(&model, None, &options(0)).unwrap());
        let mut p = Planner::for_robot(robot, options(0));
        // Random valid start/goal pairs of the joint box.
        let mut rng = Rng::new(7);
        let mut solved = 0;
        let mut tried = 0;
        let mut draw = |p: &mut Planner| loop {
            let q: Vec<f64> = (0..model.nv)
                .map(|k| {
                    let (lo, hi) = bounds(&model, k);
                    lo + (hi - lo) * rng.next_f64()
                })
                .collect();
            if p.is_free(&q) {
                return q;
            }
        };
        for _ in 0..5 {
            let (a, b) = (draw(&mut p), draw(&mut p));
            tried += 1;
            let r = p.plan(&a, &b);
            solved += (r.status == PlanStatus::Solved) as usize;
        }
        assert_eq!(solved, tried, "{file}");
    }
}

/// An independent look at the matrix: on samples it did not draw, no pair it calls
/// *Never* touches on the exact geometry; every *Default* pair touches at the default
/// configuration; every *Always* pair touches in at least 80 % of fresh samples; every
/// *Adjacent* pair is on one body or on bodies one joint apart (through links without
/// geometry).
#[test]
fn acm_reasons_hold_on_the_exact_geometry_at_fresh_samples() {
    for file in ["ur5.urdf", "panda.urdf", "iiwa14.urdf"] {
        let model = robot(file);
        let opts = options(0);
        let r = PlanningRobot::new(&model, None, &opts).unwrap();
        let PairSource::Computed(acm) = &r.pair_source else {
            panic!("{file}: no matrix")
        };
        assert!(acm.exact, "{file}: the exact geometry was not built");
        let cm = CollisionModel::new(&model, Vec::new(), &CollisionOptions::default()).unwrap();
        let mut cd = CollisionData::new(&model, &cm);
        let id = |n: &str| model.link_id(n).unwrap();
        let mut rng = Rng::new(12345);
        let fresh: Vec<Vec<f64>> = (0..3000)
            .map(|_| {
                (0..model.nv)
                    .map(|k| {
                        let (lo, hi) = bounds(&model, k);
                        lo + (hi - lo) * rng.next_f64()
                    })
                    .collect()
            })
            .collect();
        let q0 = acm::default_configuration(&model);
        for p in &acm.disabled {
            let (a, b) = (id(&p.link1), id(&p.link2));
            match p.reason {
                Reason::Never => {
                    for q in &fresh {
                        cm.update(&model, &mut cd, q);
                        assert!(
                            !cm.links_collide(&cd, a, b),
                            "{file}: '{}'–'{}' disabled as never colliding, collides at {q:?}",
                            p.link1,
                            p.link2
                        );
                    }
                }
                Reason::Default => {
                    cm.update(&model, &mut cd, &q0);
                    assert!(cm.links_collide(&cd, a, b), "{file}: {p:?}");
                }
                Reason::Always => {
                    let hits = fresh
                        .iter()
                        .filter(|q| {
                            cm.update(&model, &mut cd, q);
                            cm.links_collide(&cd, a, b)
                        })
                        .count();
                    assert!(hits * 5 >= fresh.len() * 4, "{file}: {p:?}: {hits}");
                }
                Reason::Adjacent => {
                    let (ba, bb) = (model.links[a].body, model.links[b].body);
                    let up = |x: usize| {
                        // Nearest ancestor that carries geometry.
                        let mut p = model.parent[x];
                        while p != armsim::model::WORLD
                            && !model
                                .links
                                .iter()
                                .any(|l| l.body == p && !l.collisions.is_empty())
                        {
                            p = model.parent[p];
                        }
                        p
                    };
                    let ok = ba == bb
                        || (bb != armsim::model::WORLD && up(bb) == ba)
                        || (ba != armsim::model::WORLD && up(ba) == bb);
                    assert!(ok, "{file}: {p:?}");
                }
            }
        }
    }
}

#[test]
fn acm_is_the_same_for_the_same_seed_whatever_the_thread_count() {
    let model = robot("panda.urdf");
    let r = PlanningRobot::new(&model, None, &options(3)).unwrap();
    let sm = &r.spheres;
    let stop = AtomicBool::new(false);
    let opts = AcmOptions {
        seed: 3,
        ..Default::default()
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| acm::compute(&model, sm, r.exact.as_ref(), &opts, &stop).unwrap());
    let many = acm::compute(&model, sm, r.exact.as_ref(), &opts, &stop).unwrap();
    assert_eq!(one.disabled, many.disabled);
    assert_eq!(one.checked, many.checked);
}

#[test]
fn invalid_start_names_the_colliding_pair_and_its_depth() {
    let model = robot("ur5.urdf");
    // A ball around the wrist at the home pose.
    let mut data = armsim::model::data::Data::new(&model);
    armsim::kinematics::forward_kinematics(&model, &mut data, &UR5_HOME);
    let wrist = model.link_id("wrist_2_link").unwrap();
    let c = armsim::kinematics::frame_placement(&model, &data, wrist).trans;
    let ball = Obstacle::sphere("ball", 0.05, [c.x, c.y, c.z]);
    let mut p = Planner::new(&model, &[ball], None, options(0)).unwrap();
    let r = p.plan(&UR5_HOME, &[0.5, -1.0, 1.0, 0.0, 1.0, 0.0]);
    assert_eq!(r.status, PlanStatus::InvalidStart);
    let why = r.reason.unwrap();
    assert!(why.contains("'ball'") && why.contains(" mm"), "{why}");
    assert!(why.contains("wrist"), "{why}");
    // A value outside its limits names the joint.
    let r = p.plan(&[9.0, -1.57, 1.57, 0.0, 1.57, 0.0], &UR5_HOME);
    assert_eq!(r.status, PlanStatus::InvalidStart);
    assert!(r.reason.unwrap().contains("shoulder_pan_joint"));
}

#[test]
fn reused_planner_gives_the_same_path_as_a_fresh_one() {
    let model = robot("ur5.urdf");
    let wall = Obstacle::cuboid("wall", [0.3, 0.05, 0.5], [0.45, 0.45, 0.25]);
    let goal = [1.2, -1.0, 1.0, -1.5, -1.2, 0.5];
    let robot = Arc::new(PlanningRobot::new(&model, None, &options(5)).unwrap());
    let mut reused = Planner::for_robot(robot, options(5));
    // A query in another scene first.
    let other = Obstacle::sphere("other", 0.1, [-0.4, -0.4, 0.3]);
    reused.plan_among(&[other], &UR5_HOME, &goal).unwrap();
    let a = reused
        .plan_among(std::slice::from_ref(&wall), &UR5_HOME, &goal)
        .unwrap();
    let mut fresh = Planner::new(&model, &[wall], None, options(5)).unwrap();
    let b = fresh.plan(&UR5_HOME, &goal);
    assert_eq!(a.status, PlanStatus::Solved);
    assert_eq!(a.path, b.path);
}

#[test]
fn stop_flag_ends_a_long_search_promptly() {
    // An impossible problem (plan_common::panda_wall_problem): the search would run to
    // its 60 s limit unless stopped.
    let robot = plan_common::Robot::load("panda");
    let (obstacles, start, goal) = plan_common::panda_wall_problem();
    let stop = Arc::new(AtomicBool::new(false));
    let opts = PlanOptions {
        time_limit: Some(Duration::from_secs(60)),
        stop: Some(stop.clone()),
        ..Default::default()
    };
    let mut p = Planner::new(&robot.model, &obstacles, Some(&robot.disabled), opts).unwrap();
    let flag = stop.clone();
    let raiser = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(300));
        flag.store(true, Ordering::SeqCst);
        Instant::now()
    });
    let r = p.plan(&start, &goal);
    let ended = Instant::now();
    let raised = raiser.join().unwrap();
    assert_eq!(r.status, PlanStatus::Failed, "{:?}", r.reason);
    assert_eq!(r.reason.as_deref(), Some("interrupted"));
    let late = ended.duration_since(raised);
    assert!(late < Duration::from_secs(1), "{late:?} after the flag");
}

/// Whether any checked self pair of `robot` touches on the exact geometry at one of 400
/// points per unit of joint-space length along the path.
fn exact_contact_on_path(robot: &PlanningRobot, path: &[Vec<f64>]) -> Option<Vec<f64>> {
    let (model, cm) = (&*robot.model, robot.exact.as_ref().unwrap());
    let mut cd = CollisionData::new(model, cm);
    let links: Vec<(usize, usize)> = robot
        .self_pairs
        .iter()
        .map(|&(a, b)| (robot.spheres.links[a].link, robot.spheres.links[b].link))
        .collect();
    for w in path.windows(2) {
        let len: f64 = w[0].iter().zip(&w[1]).map(|(a, b)| (b - a).powi(2)).sum();
        let n = (len.sqrt() * 400.0).ceil() as usize;
        for i in 0..=n {
            let t = i as f64 / n.max(1) as f64;
            let q: Vec<f64> = w[0]
                .iter()
                .zip(&w[1])
                .map(|(a, b)| a + t * (b - a))
                .collect();
            cm.update(model, &mut cd, &q);
            if links.iter().any(|&(a, b)| cm.links_collide(&cd, a, b)) {
                return Some(q);
            }
        }
    }
    None
}

/// The UR5's upper arm pointing down passes its base 7 mm away: the sphere covers touch
/// there, so the pair is decided on the exact geometry, and the shoulder can swing
/// through the band (before, every configuration in it was "in collision" and the
/// shoulder angles on either side could not be joined).
#[test]
fn ur5_upper_arm_passes_its_base_on_the_exact_geometry() {
    let model = robot("ur5.urdf");
    let robot = Arc::new(PlanningRobot::new(&model, None, &options(0)).unwrap());
    let name = |g: usize| model.links[robot.spheres.links[g].link].name.as_str();
    let exact: Vec<(&str, &str)> = robot
        .exact_pairs
        .iter()
        .map(|&(a, b)| (name(a), name(b)))
        .collect();
    assert!(
        exact.contains(&("base_link_inertia", "upper_arm_link")),
        "{exact:?}"
    );
    let mut p = Planner::for_robot(robot.clone(), options(0));
    let down = [1.0, std::f64::consts::FRAC_PI_2, -0.29, 0.3, 0.5, 0.2];
    assert!(p.is_free(&down));
    let (a, b) = (
        [1.07, 1.07, -0.29, 0.3, 0.5, 0.2],
        [1.07, 3.13, 1.81, 0.3, 0.5, 0.2],
    );
    let r = p.plan(&a, &b);
    assert_eq!(r.status, PlanStatus::Solved, "{:?}", r.reason);
    assert_eq!(exact_contact_on_path(&robot, &r.path), None);
}

/// Random problems of the UR5's joint box within ±π (the elbow folded at ±π separates
/// the wider box into pockets no path joins), free on the checker: all solve, and no path
/// touches on the exact geometry at 400 points per unit.
#[test]
fn ur5_random_problems_solve_and_their_paths_are_exactly_free() {
    let model = robot("ur5.urdf");
    let robot = Arc::new(PlanningRobot::new(&model, None, &options(0)).unwrap());
    let mut p = Planner::for_robot(robot.clone(), options(0));
    let mut rng = Rng::new(11);
    let mut draw = |p: &mut Planner| loop {
        let q: Vec<f64> = (0..model.nv)
            .map(|_| std::f64::consts::PI * (2.0 * rng.next_f64() - 1.0))
            .collect();
        if p.is_free(&q) {
            return q;
        }
    };
    for _ in 0..6 {
        let (a, b) = (draw(&mut p), draw(&mut p));
        let r = p.plan(&a, &b);
        assert_eq!(
            r.status,
            PlanStatus::Solved,
            "{a:?} → {b:?}: {:?}",
            r.reason
        );
        assert_eq!(
            exact_contact_on_path(&robot, &r.path),
            None,
            "{a:?} → {b:?}"
        );
    }
}

/// Soundness of the two-stage check on random edges of the UR5: an edge the checker
/// calls free has no exact contact at 400 points per unit, and a configuration it calls
/// free has none either.
#[test]
fn edges_the_checker_frees_have_no_exact_contact() {
    let model = robot("ur5.urdf");
    let robot = Arc::new(PlanningRobot::new(&model, None, &options(0)).unwrap());
    let mut p = Planner::for_robot(robot.clone(), options(0));
    let mut rng = Rng::new(99);
    let (mut free_edges, mut exact_checked) = (0, 0);
    for _ in 0..300 {
        let a: Vec<f64> = (0..model.nv)
            .map(|_| std::f64::consts::PI * (2.0 * rng.next_f64() - 1.0))
            .collect();
        let b: Vec<f64> = a.iter().map(|x| x + 0.8 * (rng.next_f64() - 0.5)).collect();
        if !(p.is_free(&a) && p.is_free(&b)) {
            continue;
        }
        if p.edge_free(&a, &b) {
            free_edges += 1;
            let path = [a.clone(), b.clone()];
            assert_eq!(exact_contact_on_path(&robot, &path), None, "{a:?} → {b:?}");
        }
        exact_checked = p.exact_checks();
    }
    assert!(free_edges > 50, "{free_edges}");
    assert!(exact_checked > 0, "the exact stage never ran");
}

/// With the elbow spanning ±2π, the UR5's elbow folded at ±π always collides (checked here
/// on the exact geometry): a query from elbow 2 rad to 4 rad has no path, and its failure
/// names the elbow's blocked band instead of only the time limit.
#[test]
fn ur5_failure_names_the_folded_elbow_band() {
    let model = robot("ur5.urdf");
    let robot = Arc::new(PlanningRobot::new(&model, None, &options(0)).unwrap());
    let (cm, mut rng) = (robot.exact.as_ref().unwrap(), Rng::new(5));
    let mut cd = CollisionData::new(&model, cm);
    let links: Vec<(usize, usize)> = robot
        .self_pairs
        .iter()
        .map(|&(a, b)| (robot.spheres.links[a].link, robot.spheres.links[b].link))
        .collect();
    for _ in 0..200 {
        let mut q: Vec<f64> = (0..model.nv)
            .map(|k| {
                let (lo, hi) = bounds(&model, k);
                lo + (hi - lo) * rng.next_f64()
            })
            .collect();
        q[2] = std::f64::consts::PI;
        cm.update(&model, &mut cd, &q);
        assert!(
            links.iter().any(|&(a, b)| cm.links_collide(&cd, a, b)),
            "{q:?}"
        );
    }
    let opts = PlanOptions {
        time_limit: Some(Duration::from_millis(500)),
        ..options(0)
    };
    let mut p = Planner::for_robot(robot, opts);
    let (a, b) = (
        [0.0, -1.2, 2.0, -0.8, 1.57, 0.0],
        [0.0, -1.2, 4.0, -0.8, 1.57, 0.0],
    );
    assert!(p.is_free(&a) && p.is_free(&b));
    let r = p.plan(&a, &b);
    assert_eq!(r.status, PlanStatus::Failed);
    let why = r.reason.unwrap();
    assert!(why.contains("'elbow_joint'"), "{why}");
    assert!(why.contains("probably no path"), "{why}");
}
