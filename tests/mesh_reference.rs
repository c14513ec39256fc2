//! Every bundled mesh (`robots/meshes/**`, `tests/data/meshes/*`) read through
//! `armsim::collision::mesh::load_mesh` must give the triangles that armsim's hand-written
//! STL/COLLADA readers and its `tobj` OBJ path gave before the readers moved to
//! `mesh-loader` (issue 27): the same welded vertex and triangle counts, the same bounding
//! box, enclosed volume and closedness. The reference table was printed by
//! `print_census` (ignored) at commit bc097f8, before any reader changed.

use armsim::collision::mesh::{load_mesh, MeshData};
use std::path::{Path, PathBuf};

/// The census of one mesh: vertex, triangle and dropped counts, the bounding box
/// (min x, y, z, max x, y, z), six times the signed volume, and closedness.
struct Census {
    vertices: usize,
    triangles: usize,
    dropped: usize,
    bbox: [f64; 6],
    volume6: f64,
    closed: bool,
}

fn census(m: &MeshData) -> Census {
    let mut bbox = [
        f64::INFINITY,
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for t in &m.triangles {
        for &i in t {
            let p = m.vertices[i as usize];
            for k in 0..3 {
                bbox[k] = bbox[k].min(p[k]);
                bbox[k + 3] = bbox[k + 3].max(p[k]);
            }
        }
    }
    Census {
        vertices: m.vertices.len(),
        triangles: m.triangles.len(),
        dropped: m.dropped,
        bbox,
        volume6: m.signed_volume6(),
        closed: m.is_closed(),
    }
}

/// Bundled mesh files, relative to the crate root, sorted.
fn bundled() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(rd) = std::fs::read_dir(dir) else {
            return;
        };
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if matches!(
                p.extension()
                    .and_then(|e| e.to_str())
                    .map(str::to_ascii_lowercase)
                    .as_deref(),
                Some("stl" | "obj" | "dae")
            ) {
                out.push(p);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    walk(&root.join("robots/meshes"), &mut out);
    walk(&root.join("tests/data/meshes"), &mut out);
    let mut rel: Vec<PathBuf> = out
        .into_iter()
        .map(|p| p.strip_prefix(root).map(Path::to_path_buf).unwrap_or(p))
        .collect();
    rel.sort();
    rel
}

/// (file, vertices, triangles, dropped, bounding box, 6 × volume, closed), as the readers
/// of commit bc097f8 gave them.
type Row = (&'static str, usize, usize, usize, [f64; 6], f64, bool);

#[rustfmt::skip]
const REFERENCE: &[Row] = &[
    ("robots/meshes/iiwa14/collision/link_0.stl", 4732, 9484, 10, [-1.3600000739097595e-1, -1.2138400226831436e-1, -0e0, 1.2124300003051758e-1, 1.2138400226831436e-1, 1.574999988079071e-1], 3.28602712972298e-2, true),
    ("robots/meshes/iiwa14/collision/link_1.stl", 1810, 3616, 0, [-8.549100160598755e-2, -1.1568599939346313e-1, -9.999999776482582e-3, 8.549100160598755e-2, 8.5487000644207e-2, 2.879999876022339e-1], 2.4571013163229474e-2, true),
    ("robots/meshes/iiwa14/collision/link_2.stl", 2200, 4396, 0, [-8.505699783563614e-2, -8.54329988360405e-2, -6.799899786710739e-2, 8.592899888753891e-2, 2.0450100302696228e-1, 1.3210700452327728e-1], 2.3633126135516148e-2, true),
    ("robots/meshes/iiwa14/collision/link_3.stl", 2301, 4598, 18, [-6.800000369548798e-2, -6.800000369548798e-2, -9.999999776482582e-3, 6.800000369548798e-2, 1.1459299921989441e-1, 2.834939956665039e-1], 1.8974530691505908e-2, true),
    ("robots/meshes/iiwa14/collision/link_4.stl", 2106, 4208, 10, [-6.79979994893074e-2, -6.799899786710739e-2, -6.800000369548798e-2, 6.79979994893074e-2, 1.8449999392032623e-1, 1.1447899788618088e-1], 1.6380114584818434e-2, true),
    ("robots/meshes/iiwa14/collision/link_5.stl", 2529, 5054, 10, [-6.800000369548798e-2, -6.800000369548798e-2, -9.999999776482582e-3, 6.82469978928566e-2, 9.901999682188034e-2, 2.670069932937622e-1], 1.0116641514595721e-2, true),
    ("robots/meshes/iiwa14/collision/link_6.stl", 1643, 3282, 2, [-6.612099707126617e-2, -8.636400103569031e-2, -7.069999724626541e-2, 6.612999737262726e-2, 8.089999854564667e-2, 6.691399961709976e-2], 1.0805971270962741e-2, true),
    ("robots/meshes/iiwa14/collision/link_7.stl", 5674, 11340, 42, [-5.185399949550629e-2, -5.1941998302936554e-2, -9.89999994635582e-3, 5.185399949550629e-2, 5.1941998302936554e-2, 4.500000178813934e-2], 1.8412143170898761e-3, true),
    ("robots/meshes/iiwa14/visual/band.obj", 474, 636, 0, [-6.8e-2, -6.8e-2, 0e0, 6.8e-2, 6.8e-2, 3.3e-2], 1.6854247763262462e-3, false),
    ("robots/meshes/iiwa14/visual/kuka.obj", 206, 194, 0, [-4.7981e-2, -6.7936e-2, 8.082e-3, 4.7981e-2, 6.7936e-2, 2.4651e-2], 2.2892928263745495e-4, false),
    ("robots/meshes/iiwa14/visual/link_0.obj", 4732, 9484, 0, [-1.36e-1, -1.21384e-1, 0e0, 1.21243e-1, 1.21384e-1, 1.575e-1], 3.286027099436126e-2, true),
    ("robots/meshes/iiwa14/visual/link_1.obj", 4964, 9924, 0, [-8.5491e-2, -1.15686e-1, -1e-2, 8.5491e-2, 8.5487e-2, 2.87984e-1], 2.4621354631319665e-2, true),
    ("robots/meshes/iiwa14/visual/link_2_grey.obj", 3809, 7375, 0, [-8.5057e-2, -8.55e-2, -6.7999e-2, 8.5929e-2, 2.04501e-1, 8.4283e-2], 1.2778695580305966e-2, false),
    ("robots/meshes/iiwa14/visual/link_2_orange.obj", 1974, 3711, 0, [-7.9803e-2, -8.5295e-2, 2.4745e-2, 8.0247e-2, 1.36902e-1, 1.32107e-1], 1.0901907723070028e-2, false),
    ("robots/meshes/iiwa14/visual/link_3.obj", 4475, 8769, 0, [-6.8e-2, -6.8e-2, -1e-2, 6.8e-2, 1.14593e-1, 2.83466e-1], 1.7108194306454078e-2, false),
    ("robots/meshes/iiwa14/visual/link_4_grey.obj", 3781, 7221, 0, [-6.7998e-2, -6.7993e-2, -6.8e-2, 6.7998e-2, 1.845e-1, 8.1696e-2], 1.0185148429702381e-2, false),
    ("robots/meshes/iiwa14/visual/link_4_orange.obj", 1800, 3259, 0, [-6.2082e-2, -6.6806e-2, 2.97e-2, 6.2099e-2, 1.27247e-1, 1.14579e-1], 6.22947962920448e-3, false),
    ("robots/meshes/iiwa14/visual/link_5.obj", 2179, 4230, 0, [-6.8e-2, -6.8e-2, -1e-2, 6.8247e-2, 9.902e-2, 2.67007e-1], 8.203305072965015e-3, false),
    ("robots/meshes/iiwa14/visual/link_6_grey.obj", 2815, 5421, 0, [-6.617e-2, -5.9355e-2, -7.07e-2, 6.6164e-2, 8.09e-2, 5.3851e-2], 5.681963993125835e-3, false),
    ("robots/meshes/iiwa14/visual/link_6_orange.obj", 1312, 2425, 0, [-6.609e-2, -8.6486e-2, -4.3868e-2, 6.6108e-2, 6.5702e-2, 6.6914e-2], 5.155788808337603e-3, false),
    ("robots/meshes/iiwa14/visual/link_7.obj", 5674, 11340, 0, [-5.1854e-2, -5.1942e-2, -9.9e-3, 5.1854e-2, 5.1942e-2, 4.5e-2], 1.8412142817349276e-3, true),
    ("robots/meshes/panda/collision/finger.stl", 18, 32, 0, [-1.0479453019797802e-2, -1.326427300227806e-4, 1.3169624435249716e-4, 1.0494818910956383e-2, 2.6403382420539856e-2, 5.384903401136398e-2], 1.3185928520887004e-4, true),
    ("robots/meshes/panda/collision/hand.stl", 102, 200, 0, [-3.1635917723178864e-2, -1.0398972034454346e-1, -2.592480182647705e-2, 3.161578252911568e-2, 1.0042587667703629e-1, 6.596215069293976e-2], 4.2531228085487755e-3, true),
    ("robots/meshes/panda/collision/link0.stl", 102, 200, 0, [-1.5407869219779968e-1, -9.461374580860138e-2, -3.249277506256476e-5, 7.156699150800705e-2, 9.467043727636337e-2, 1.4000283181667328e-1], 1.797881662493227e-2, true),
    ("robots/meshes/panda/collision/link1.stl", 152, 300, 0, [-5.498699098825455e-2, -1.2937313318252563e-1, -1.9200406968593597e-1, 5.516122654080391e-2, 5.51922544836998e-2, 5.4973091930150986e-2], 1.785022739657012e-2, true),
    ("robots/meshes/panda/collision/link2.stl", 152, 300, 0, [-5.5153440684080124e-2, -1.9400957226753235e-1, -5.5096644908189774e-2, 5.4984934628009796e-2, 5.522003769874573e-2, 1.2948937714099884e-1], 1.802552455736424e-2, true),
    ("robots/meshes/panda/collision/link3.stl", 152, 300, 0, [-5.4645780473947525e-2, -5.491721257567406e-2, -1.2101753056049347e-1, 1.3756124675273895e-1, 1.1120302975177765e-1, 5.515643209218979e-2], 1.396703394686769e-2, true),
    ("robots/meshes/panda/collision/link4.stl", 152, 300, 0, [-1.3760687410831451e-1, -5.514972284436226e-2, -5.520660802721977e-2, 5.5139537900686264e-2, 1.2400948256254196e-1, 1.1105209589004517e-1], 1.4242841507484866e-2, true),
    ("robots/meshes/panda/collision/link5.stl", 152, 300, 0, [-5.5016547441482544e-2, -5.512791872024536e-2, -2.6455438137054443e-1, 5.508343130350113e-2, 1.2990427017211914e-1, 5.2168332040309906e-2], 2.0514610792506004e-2, true),
    ("robots/meshes/panda/collision/link6.stl", 102, 200, 0, [-4.800514504313469e-2, -5.138847231864929e-2, -4.398505762219429e-2, 1.3220776617527008e-1, 8.168089389801025e-2, 5.630863085389137e-2], 8.60964001501559e-3, true),
    ("robots/meshes/panda/collision/link7.stl", 102, 200, 0, [-4.403458908200264e-2, -4.4029612094163895e-2, 5.1990531384944916e-2, 8.130612969398499e-2, 8.118730783462524e-2, 1.0683722794055939e-1], 2.6761700862532644e-3, true),
    ("robots/meshes/panda/visual/finger.dae", 318, 624, 0, [-1.05009e-2, -8.37643e-5, 1.33332e-4, 1.050156e-2, 2.634549e-2, 5.389988e-2], 6.732593230924567e-5, true),
    ("robots/meshes/panda/visual/hand.dae", 3613, 7078, 0, [-3.151953e-2, -1.039465e-1, -2.594578e-2, 3.152513e-2, 1.005699e-1, 6.599998e-2], 2.932347681403827e-3, false),
    ("robots/meshes/panda/visual/link0.dae", 10482, 20478, 5, [-1.540856e-1, -9.459596e-2, 0e0, 7.154428e-2, 9.457278e-2, 1.400001e-1], 1.4708548669960237e-2, false),
    ("robots/meshes/panda/visual/link1.dae", 6260, 12516, 0, [-5.501461e-2, -1.29392e-1, -1.92e-1, 5.500113e-2, 5.501437e-2, 5.500240000000001e-2], 1.3759507610247029e-2, true),
    ("robots/meshes/panda/visual/link2.dae", 6360, 12716, 0, [-5.502986e-2, -1.940002e-1, -5.500108e-2, 5.500298e-2, 5.502396e-2, 1.29392e-1], 1.3873809944310679e-2, true),
    ("robots/meshes/panda/visual/link3.dae", 7233, 14233, 0, [-5.501335e-2, -5.500596e-2, -1.21e-1, 1.374981e-1, 1.110572e-1, 5.5001700000000014e-2], 1.2409233348038347e-2, false),
    ("robots/meshes/panda/visual/link4.dae", 7422, 14620, 1, [-1.375094e-1, -5.499973e-2, -5.499452e-2, 5.499804e-2, 1.24e-1, 1.110582e-1], 1.2491173200624458e-2, false),
    ("robots/meshes/panda/visual/link5.dae", 9351, 18327, 0, [-5.50071e-2, -5.499523e-2, -2.59e-1, 5.498921e-2, 1.299349e-1, 5.219869999999999e-2], 1.516795032745329e-2, false),
    ("robots/meshes/panda/visual/link6.dae", 11818, 21620, 0, [-4.790425e-2, -5.120003e-2, -4.3989639999999997e-2, 1.320213e-1, 8.166313e-2, 5.625362e-2], 9.090158495784392e-3, false),
    ("robots/meshes/panda/visual/link7.dae", 6362, 12077, 5, [-4.4026212786765e-2, -4.4023257082492995e-2, 5.2e-2, 8.1306827966041e-2, 8.1274111678311e-2, 1.0680002999999999e-1], 2.5703194730959e-3, false),
    ("robots/meshes/ur5/collision/base.stl", 283, 578, 0, [-7.357943803071976e-2, -1.100001111626625e-1, -3.002399345859885e-3, 7.363327592611313e-2, 7.355142384767532e-2, 2.1000295877456665e-2], 2.085279825120292e-3, true),
    ("robots/meshes/ur5/collision/forearm.stl", 537, 1050, 0, [-5.7912249118089676e-2, -5.7176098227500916e-2, -5.798553675413132e-2, 5.853401497006416e-2, 5.4510679095983505e-2, 4.3127942085266113e-1], 1.4943727709141204e-2, true),
    ("robots/meshes/ur5/collision/shoulder.stl", 341, 674, 0, [-5.940401554107666e-2, -5.974636226892471e-2, -6.520015746355057e-2, 5.9500157833099365e-2, 7.050129771232605e-2, 6.845968216657639e-2], 9.289927570811318e-3, true),
    ("robots/meshes/ur5/collision/upperarm.stl", 598, 1176, 0, [-5.9892438352108e-2, -6.519998610019684e-2, -5.9746138751506805e-2, 5.9479936957359314e-2, 6.859733164310455e-2, 4.848988354206085e-1], 3.216606187355683e-2, true),
    ("robots/meshes/ur5/collision/wrist1.stl", 355, 702, 0, [-3.860008716583252e-2, 4.74993996322155e-2, -5.717611685395241e-2, 3.888977691531181e-2, 1.325002759695053e-1, 4.7499947249889374e-2], 3.083216317539409e-3, true),
    ("robots/meshes/ur5/collision/wrist2.stl", 355, 702, 0, [-3.888968005776405e-2, -5.7188112288713455e-2, 4.914984107017517e-2, 3.86943444609642e-2, 4.749998822808266e-2, 1.3338255882263184e-1], 3.0823258135497873e-3, true),
    ("robots/meshes/ur5/collision/wrist3.stl", 233, 446, 0, [-3.7515703588724136e-2, 4.732474312186241e-2, -3.751566633582115e-2, 3.751571848988533e-2, 8.182505518198013e-2, 4.29999865591526e-2], 8.296598034254923e-4, true),
    ("robots/meshes/ur5/visual/base.dae", 960, 1932, 0, [-7.33658e-2, -1.1e-1, -2.999961e-3, 7.336586e-2, 7.33658e-2, 2.099978e-2], 2.0869009455126244e-3, true),
    ("robots/meshes/ur5/visual/forearm.dae", 10523, 21022, 6, [-5.799978e-2, -5.719995e-2, -5.799973e-2, 5.799973e-2, 5.449998e-2, 4.3118e-1], 1.5051472661656124e-2, true),
    ("robots/meshes/ur5/visual/shoulder.dae", 6748, 13488, 4, [-5.94998e-2, -5.94999565e-2, -6.52001265e-2, 5.94998e-2, 7.04997935e-2, 6.85107465e-2], 9.322694144277813e-3, true),
    ("robots/meshes/ur5/visual/upperarm.dae", 14724, 29428, 8, [-5.949974e-2, -6.519997e-2, -5.94998e-2, 5.94998e-2, 6.851094e-2, 4.844999e-1], 3.229709840288295e-2, true),
    ("robots/meshes/ur5/visual/wrist1.dae", 7040, 14072, 2, [-3.874987e-2, 4.750001e-2, -5.719988428001101e-2, 3.874993e-2, 1.323537e-1, 4.7499945250005005e-2], 3.0932321571645713e-3, true),
    ("robots/meshes/ur5/visual/wrist2.dae", 7040, 14072, 2, [-3.874987e-2, -5.719995e-2, 4.914999e-2, 3.874993e-2, 4.749995e-2, 1.333999e-1], 3.0932334406521215e-3, true),
    ("robots/meshes/ur5/visual/wrist3.dae", 839, 1658, 0, [-3.749996e-2, 4.732495e-2, -3.749996e-2, 3.749996e-2, 8.182489e-2, 4.299998e-2], 8.324366388015417e-4, true),
    ("tests/data/meshes/box_node_transform.dae", 8, 12, 0, [0e0, 1.5e0, 2.5e0, 2e0, 2.5e0, 3.5e0], 1.2e1, true),
    ("tests/data/meshes/cube.dae", 8, 12, 0, [-5e-1, -5e-1, -5e-1, 5e-1, 5e-1, 5e-1], 6e0, true),
    ("tests/data/meshes/cube.obj", 8, 12, 0, [-5e-1, -5e-1, -5e-1, 5e-1, 5e-1, 5e-1], 6e0, true),
    ("tests/data/meshes/cube_ascii.stl", 8, 12, 0, [-5e-1, -5e-1, -5e-1, 5e-1, 5e-1, 5e-1], 6e0, true),
    ("tests/data/meshes/cube_binary.stl", 8, 12, 0, [-5e-1, -5e-1, -5e-1, 5e-1, 5e-1, 5e-1], 6e0, true),
];

/// Coordinates are read in f32 by `mesh-loader` (binary STL always was): a bound may move
/// by the f32 rounding of the value written in the file, well under a micrometre here.
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1.0)
}

#[test]
fn bundled_meshes_give_the_reference_triangles() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let files = bundled();
    let names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
    let listed: Vec<&str> = REFERENCE.iter().map(|r| r.0).collect();
    assert_eq!(
        names, listed,
        "the bundled meshes changed: reprint the reference table"
    );
    let mut bad = Vec::new();
    for &(file, nv, nt, nd, bbox, vol6, closed) in REFERENCE {
        let m = load_mesh(&root.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        let c = census(&m);
        let bbox_ok = (0..6).all(|k| close(c.bbox[k], bbox[k], 1e-7));
        let vol_ok = (c.volume6 - vol6).abs() <= 1e-6 * vol6.abs();
        if (c.vertices, c.triangles, c.dropped, c.closed) != (nv, nt, nd, closed)
            || !bbox_ok
            || !vol_ok
        {
            bad.push(format!(
                "{file}: vertices {} (was {nv}), triangles {} (was {nt}), dropped {} (was {nd}), \
                 closed {} (was {closed}), bbox {:?} (was {bbox:?}), 6V {:e} (was {vol6:e})",
                c.vertices, c.triangles, c.dropped, c.closed, c.bbox, c.volume6
            ));
        }
    }
    assert!(
        bad.is_empty(),
        "{} of {} meshes differ:\n{}",
        bad.len(),
        REFERENCE.len(),
        bad.join("\n")
    );
}

#[test]
#[ignore = "prints the reference table (run before changing a reader)"]
fn print_census() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for p in bundled() {
        let m = load_mesh(&root.join(&p)).expect("bundled mesh reads");
        let c = census(&m);
        println!(
            "    (\"{}\", {}, {}, {}, [{:e}, {:e}, {:e}, {:e}, {:e}, {:e}], {:e}, {}),",
            p.display(),
            c.vertices,
            c.triangles,
            c.dropped,
            c.bbox[0],
            c.bbox[1],
            c.bbox[2],
            c.bbox[3],
            c.bbox[4],
            c.bbox[5],
            c.volume6,
            c.closed
        );
    }
}

#[test]
#[ignore = "timing loop: cargo test --release --test mesh_reference -- --ignored time_bundled --nocapture"]
fn time_bundled() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let files = bundled();
    let mut by_ext: std::collections::BTreeMap<String, (usize, f64)> = Default::default();
    let rounds = 5;
    for p in &files {
        let path = root.join(p);
        let mut best = f64::INFINITY;
        for _ in 0..rounds {
            let t = std::time::Instant::now();
            let m = load_mesh(&path).expect("bundled mesh reads");
            std::hint::black_box(&m);
            best = best.min(t.elapsed().as_secs_f64());
        }
        let ext = p
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let e = by_ext.entry(ext).or_default();
        e.0 += 1;
        e.1 += best;
    }
    for (ext, (n, s)) in &by_ext {
        println!(
            "{ext}: {n} files, {:.2} ms (sum of best-of-{rounds})",
            s * 1e3
        );
    }
}

/// One geometry (the ±1 cube of `tests/data/meshes/cube.dae`) placed by two nodes: one
/// translated, one nested under a translated parent and rotated and scaled, all in
/// half-metre units. `mesh-loader` 0.1.13 keys node transforms by geometry URL (one mesh
/// per geometry, at the last transform walked); armsim must give both copies.
const TWICE_INSTANCED: &str = r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="half-metre" meter="0.5"/></asset>
  <library_geometries>
    <geometry id="cube-mesh">
      <mesh>
        <source id="cube-positions">
          <float_array id="cube-positions-array" count="24">-1 -1 -1 1 -1 -1 1 1 -1 -1 1 -1 -1 -1 1 1 -1 1 1 1 1 -1 1 1</float_array>
          <technique_common>
            <accessor source="#cube-positions-array" count="8" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="cube-vertices"><input semantic="POSITION" source="#cube-positions"/></vertices>
        <polylist count="6">
          <input semantic="VERTEX" source="#cube-vertices" offset="0"/>
          <vcount>4 4 4 4 4 4</vcount>
          <p>0 3 2 1 4 5 6 7 0 1 5 4 2 3 7 6 1 2 6 5 0 4 7 3</p>
        </polylist>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene">
      <node id="first"><translate>2 0 0</translate><instance_geometry url="#cube-mesh"/></node>
      <node id="parent"><translate>0 0 6</translate>
        <node id="second"><rotate>0 0 1 90</rotate><scale>0.5 0.5 0.5</scale>
          <instance_geometry url="#cube-mesh"/>
        </node>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"##;

#[test]
fn a_geometry_instanced_twice_gives_both_copies_in_place() {
    let m = armsim::collision::mesh::read_dae(TWICE_INSTANCED).expect("reads");
    // Worked by hand: first copy [1, 3] × [-1, 1]² → ×0.5 → [0.5, 1.5] × [-0.5, 0.5]²
    // (side 1, 6V = 6); second copy scaled to [-0.5, 0.5]³, turned a quarter about z (the
    // same box), lifted to z ∈ [5.5, 6.5] → ×0.5 → [-0.25, 0.25]² × [2.75, 3.25]
    // (side 0.5, 6V = 0.75).
    assert_eq!(
        (m.vertices.len(), m.triangles.len(), m.dropped),
        (16, 24, 0)
    );
    let c = census(&m);
    let want = [-0.25, -0.5, -0.5, 1.5, 0.5, 3.25];
    for (got, want) in c.bbox.iter().zip(want) {
        assert!((got - want).abs() < 1e-12, "bbox {:?}", c.bbox);
    }
    assert!((c.volume6 - 6.75).abs() < 1e-12, "6V {}", c.volume6);
    assert!(c.closed);
    // Each copy on its own: the vertices with z above 1 m are the second copy's 8.
    let high: Vec<&[f64; 3]> = m.vertices.iter().filter(|p| p[2] > 1.0).collect();
    assert_eq!(high.len(), 8);
    for p in high {
        assert!((p[0].abs() - 0.25).abs() < 1e-12 && (p[1].abs() - 0.25).abs() < 1e-12);
        assert!(
            (p[2] - 2.75).abs() < 1e-12 || (p[2] - 3.25).abs() < 1e-12,
            "{p:?}"
        );
    }
}

/// The checks armsim keeps around mesh-loader's OBJ and STL parsers: an OBJ face index
/// named with its line (0 is no index), an OBJ's triangles counted before mesh-loader
/// allocates them, lines ended by a lone `\r` counted too, and an ASCII STL whose length
/// would fit binary records not read as binary.
#[test]
fn checks_around_mesh_loader() {
    use armsim::collision::mesh::{read_obj_bytes, read_stl, MAX_TRIANGLES};
    let e = read_obj_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 0 1 2\n")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "OBJ: line 5: index 0 of a vertex is out of range (3 in the file, from 1)"
    );
    let e = read_obj_bytes(b"v 0 0 0\nv 1 0 0\nf 1 2 4\n")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "OBJ: line 3: index 4 of a vertex is out of range (2 in the file, from 1)"
    );
    // One polygon of MAX_TRIANGLES + 3 corners: MAX_TRIANGLES + 1 triangles.
    let mut big = b"v 0 0 0\nf".to_vec();
    big.extend(std::iter::repeat_n(&b" 1"[..], MAX_TRIANGLES + 3).flatten());
    let e = read_obj_bytes(&big).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "OBJ: the faces make 5000001 triangles, more than the mesh limit of {MAX_TRIANGLES}"
        )
    );
    // A UTF-8 byte-order mark is skipped; UTF-16 is refused (the pre-scan reads UTF-8).
    let m = read_obj_bytes(b"\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert_eq!((m.vertices.len(), m.triangles.len()), (3, 1));
    let utf16: Vec<u8> = "\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
        .encode_utf16()
        .flat_map(u16::to_le_bytes)
        .collect();
    let e = read_obj_bytes(&utf16).unwrap_err().to_string();
    assert_eq!(e, "OBJ: UTF-16 text is not read (save the file as UTF-8)");
    // Old Mac line ends: the face is read (and was checked).
    let m = read_obj_bytes(b"v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r").unwrap();
    assert_eq!((m.vertices.len(), m.triangles.len()), (3, 1));
    assert_eq!(m.vertices[1], [1.0, 0.0, 0.0]);
    let e = read_obj_bytes(b"v 0 0 0\rv 1 0 0\rf 1 2 3\r")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("OBJ: line 1: index 3 of a vertex"), "{e}");
    // 134 bytes (84 + 50), not a binary STL by its declared count (spaces): ASCII, and
    // without a facet it is refused with mesh-loader's place, not read as a binary record.
    let mut t = b"solid x\nhello".to_vec();
    t.resize(134, b' ');
    let e = read_stl(&t).unwrap_err().to_string();
    assert_eq!(
        e,
        "ASCII STL: line 2, column 1: expected facet normal or endsolid"
    );
    // A solid name that is not ASCII: mesh-loader would try the 134 bytes as binary.
    let mut t = "solid é\n".as_bytes().to_vec();
    t.resize(134, b' ');
    let e = read_stl(&t).unwrap_err().to_string();
    assert!(e.starts_with("ASCII STL: unreadable after 'solid'"), "{e}");
}
