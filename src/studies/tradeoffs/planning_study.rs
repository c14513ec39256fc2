//! Study 8, planning: what path quality costs in planning time. On bundled
//! MotionBenchMaker problems (the first twelve of `table_pick` for the spherized Panda
//! and UR5, `assets/planning/mbm/`, embedded at build time), RRT-Connect's simplified
//! first path, then the optimising mode (AORRTC, [`crate::planning::improve`]) at
//! growing iteration budgets: median and 95th-percentile planning time against the
//! median path cost (joint-space length), over problems × seeds.
//!
//! VAMP's AORRTC cannot run here (it is a C++/Python build outside this crate); its
//! figures are the ones `tools/planning_tradeoff_vamp.sh` recorded on the whole
//! `table_pick` scene (`assets/planning/vamp_tradeoff.csv`, armsim's figures of that same
//! run beside them), shown with the date and machine they were measured on.

use crate::planning::moveit::{parse_request, parse_scene};
use crate::planning::plan_options::{OptimiseBudget, PlanOptions, PlannerKind};
use crate::planning::planner::{PlanStatus, Planner};
use crate::planning::setup::PlanningRobot;
use crate::planning::srdf::parse_srdf;
use crate::studies::tradeoffs::bundled_robots::model_from_text;
use crate::studies::tradeoffs::study_options::{Options, StudyMode};
use serde::Serialize;
use std::sync::Arc;

/// One bundled problem: its robot, number, scene and request texts.
struct Problem {
    robot: &'static str,
    id: &'static str,
    scene: &'static str,
    request: &'static str,
}

macro_rules! problems {
    ($robot:literal: $($id:literal)*) => {
        [$(Problem {
            robot: $robot,
            id: $id,
            scene: include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"), "/assets/planning/mbm/", $robot,
                "/table_pick/scene", $id, ".yaml"
            )),
            request: include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"), "/assets/planning/mbm/", $robot,
                "/table_pick/request", $id, ".yaml"
            )),
        }),*]
    };
}

const PANDA: [Problem; 12] = problems!("panda": "0001" "0002" "0003" "0004" "0005" "0006"
    "0007" "0008" "0009" "0010" "0011" "0012");
const UR5: [Problem; 12] = problems!("ur5": "0001" "0002" "0003" "0004" "0005" "0006"
    "0007" "0008" "0009" "0010" "0011" "0012");

/// The spherized robots (URDF, SRDF) and VAMP's RRT-Connect range for each.
const ROBOTS: [(&str, &str, &str, f32); 2] = [
    (
        "panda",
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/spherized/panda_spherized.urdf"
        )),
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/spherized/panda.srdf"
        )),
        1.0,
    ),
    (
        "ur5",
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/spherized/ur5_spherized.urdf"
        )),
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/spherized/ur5.srdf"
        )),
        1.5,
    ),
];

/// The figures VAMP's AORRTC reached on these problems, recorded with armsim's of the same
/// run by `tools/planning_tradeoff_vamp.sh`.
pub const VAMP_RECORD: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/assets/planning/vamp_tradeoff.csv"
));

/// Sizes of the planning study.
#[derive(Clone, Debug)]
pub struct PlanningConfig {
    /// Problems per robot (of the twelve bundled).
    pub problems: usize,
    /// Seeds per problem (0, 1, …).
    pub seeds: u64,
    /// The optimising mode's iteration budgets, smallest first.
    pub budgets: Vec<usize>,
}

impl PlanningConfig {
    /// The sizes of `mode`.
    pub fn for_mode(mode: StudyMode) -> Self {
        match mode {
            StudyMode::Tiny => PlanningConfig {
                problems: 3,
                seeds: 1,
                budgets: vec![250, 1000],
            },
            StudyMode::Quick => PlanningConfig {
                problems: 12,
                seeds: 2,
                budgets: vec![250, 500, 1000, 2000, 4000],
            },
            StudyMode::Full => PlanningConfig {
                problems: 12,
                seeds: 5,
                budgets: vec![250, 500, 1000, 2000, 4000, 8000],
            },
        }
    }
}

/// One planner setting on one robot, over problems × seeds.
#[derive(Clone, Debug, Serialize)]
pub struct PlanningRow {
    /// `rrt-connect` or `aorrtc`.
    pub planner: String,
    /// Iteration budget (`None` for RRT-Connect, which stops at its first path).
    pub budget: Option<usize>,
    /// Queries solved, of those run on valid problems.
    pub solved: usize,
    /// Queries run.
    pub queries: usize,
    /// Median planning time of the solved queries (µs), search and simplification.
    pub time_median_us: f64,
    /// Their 95th percentile (nearest rank, µs).
    pub time_p95_us: f64,
    /// Median path cost (joint-space L2 length) of the solved queries.
    pub cost_median: f64,
    /// Per query (problem-major, then seed), the cost; `None` when not solved.
    pub costs: Vec<Option<f64>>,
}

/// One robot's rows.
#[derive(Clone, Debug, Serialize)]
pub struct RobotPlanning {
    /// `panda` or `ur5`.
    pub robot: String,
    /// The problems (`table_pick` numbers).
    pub problems: Vec<String>,
    /// RRT-Connect first, then AORRTC by growing budget.
    pub rows: Vec<PlanningRow>,
}

/// The study's result.
#[derive(Clone, Debug, Serialize)]
pub struct PlanningStudy {
    /// Per robot.
    pub robots: Vec<RobotPlanning>,
    /// Seeds per problem.
    pub seeds: u64,
    /// VAMP's recorded figures (and armsim's of the same run).
    pub vamp: Vec<VampRecord>,
}

/// One line of `assets/planning/vamp_tradeoff.csv`.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct VampRecord {
    /// `panda` or `ur5`.
    pub robot: String,
    /// `rrtc` or `aorrtc`.
    pub planner: String,
    /// Iteration budget (0 for RRT-Connect).
    pub budget: usize,
    /// VAMP: median and 95th-percentile planning time (µs), median simplified cost.
    pub vamp: [f64; 3],
    /// armsim in the same run: the same three.
    pub armsim: [f64; 3],
    /// Valid problems of the scene.
    pub valid: usize,
    /// Problems solved by VAMP, then by armsim (the medians are over these).
    pub solved: [usize; 2],
    /// When and where (`date host`).
    pub measured: String,
}

/// Parses the recorded CSV (header `robot,planner,budget,valid,vamp_solved,vamp_med_us,
/// vamp_p95_us,vamp_cost,armsim_solved,armsim_med_us,armsim_p95_us,armsim_cost,measured`).
pub fn parse_vamp_record(text: &str) -> Result<Vec<VampRecord>, String> {
    let file = "assets/planning/vamp_tradeoff.csv";
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 13 {
            return Err(format!(
                "{file}:{}: expected 13 fields, got {}",
                i + 1,
                f.len()
            ));
        }
        let num = |k: usize| -> Result<f64, String> {
            f[k].trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    format!(
                        "{file}:{}: field {}: '{}' is not a number",
                        i + 1,
                        k + 1,
                        f[k]
                    )
                })
        };
        out.push(VampRecord {
            robot: f[0].to_string(),
            planner: f[1].to_string(),
            budget: num(2)? as usize,
            valid: num(3)? as usize,
            vamp: [num(5)?, num(6)?, num(7)?],
            armsim: [num(9)?, num(10)?, num(11)?],
            solved: [num(4)? as usize, num(8)? as usize],
            measured: f[12].trim().to_string(),
        });
    }
    Ok(out)
}

/// Runs the study at `cfg`'s sizes.
pub fn run(opts: &Options, cfg: &PlanningConfig) -> Result<PlanningStudy, String> {
    let mut robots = Vec::new();
    for (name, urdf, srdf, range) in ROBOTS {
        let problems: &[Problem] = if name == "panda" { &PANDA } else { &UR5 };
        let problems = &problems[..cfg.problems.min(problems.len())];
        opts.say(format!("planning: {name}, {} problems", problems.len()));
        robots.push(run_robot(name, urdf, srdf, range, problems, cfg)?);
    }
    Ok(PlanningStudy {
        robots,
        seeds: cfg.seeds,
        vamp: parse_vamp_record(VAMP_RECORD)?,
    })
}

/// One robot: RRT-Connect, then AORRTC at each budget, on every problem and seed.
fn run_robot(
    name: &str,
    urdf: &str,
    srdf: &str,
    range: f32,
    problems: &[Problem],
    cfg: &PlanningConfig,
) -> Result<RobotPlanning, String> {
    let file = format!("robots/spherized/{name}_spherized.urdf");
    let model = model_from_text(urdf, &file)?;
    let srdf_file = format!("robots/spherized/{name}.srdf");
    let (pairs, _) = parse_srdf(srdf, &srdf_file)
        .map_err(|e| e.to_string())?
        .disabled_pairs(&model);
    let mut base = PlanOptions::default();
    base.rrt.range = range;
    let robot =
        Arc::new(PlanningRobot::new(&model, Some(&pairs), &base).map_err(|e| e.to_string())?);
    let root = model
        .links
        .iter()
        .find(|l| l.parent_joint.is_none())
        .map(|l| l.name.clone());
    let frames: Vec<&str> = root.iter().map(String::as_str).collect();
    let mut inputs = Vec::new();
    for p in problems {
        debug_assert_eq!(p.robot, name);
        let at = |kind: &str| format!("assets/planning/mbm/{name}/table_pick/{kind}{}.yaml", p.id);
        let obstacles = parse_scene(p.scene, &at("scene"), &frames).map_err(|e| e.to_string())?;
        let (req, _) =
            parse_request(p.request, &at("request"), &model).map_err(|e| e.to_string())?;
        inputs.push((obstacles, req.start, req.goal));
    }
    let settings = std::iter::once(None).chain(cfg.budgets.iter().map(|&b| Some(b)));
    let mut rows = Vec::new();
    for budget in settings {
        let mut opts = base.clone();
        if let Some(b) = budget {
            opts.planner = PlannerKind::Aorrtc;
            opts.budget = OptimiseBudget {
                iterations: b,
                time: None,
            };
        }
        let (mut times, mut costs, mut solved) = (Vec::new(), Vec::new(), 0);
        for (obstacles, start, goal) in &inputs {
            for seed in 0..cfg.seeds {
                let mut o = opts.clone();
                o.seed = seed;
                let mut planner = Planner::for_robot(robot.clone(), o);
                planner
                    .set_obstacles(obstacles)
                    .map_err(|e| e.to_string())?;
                let r = planner.plan(start, goal);
                if r.status == PlanStatus::Solved {
                    solved += 1;
                    times.push(r.plan_time_us + r.simplify_time_us);
                    costs.push(Some(r.cost));
                } else {
                    costs.push(None);
                }
            }
        }
        let mut ok: Vec<f64> = costs.iter().flatten().copied().collect();
        ok.sort_by(f64::total_cmp);
        times.sort_by(f64::total_cmp);
        rows.push(PlanningRow {
            planner: if budget.is_some() {
                "aorrtc"
            } else {
                "rrt-connect"
            }
            .into(),
            budget,
            solved,
            queries: costs.len(),
            time_median_us: median_sorted(&times),
            time_p95_us: p95_sorted(&times),
            cost_median: median_sorted(&ok),
            costs,
        });
    }
    Ok(RobotPlanning {
        robot: name.into(),
        problems: problems.iter().map(|p| p.id.to_string()).collect(),
        rows,
    })
}

/// The median of sorted values (`NaN` when empty).
fn median_sorted(v: &[f64]) -> f64 {
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The 95th percentile of sorted values, nearest rank (`NaN` when empty).
fn p95_sorted(v: &[f64]) -> f64 {
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    v[((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1]
}
