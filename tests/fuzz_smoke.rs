//! The fuzz targets at CI size (stable toolchain, `cargo test --release`): replays every
//! committed corpus and regression input of `fuzz/`, and feeds proptest-mutated seed
//! files (byte flips, truncations, insertions of dictionary tokens and odd numbers,
//! duplicated and deleted ranges) to the same entry points as the cargo-fuzz targets
//! (`tests/fuzz_harness/mod.rs`). A panic fails the test; every refusal must render
//! with the file name. The long campaigns are in `RELIABILITY.md` (## Fuzzing).

mod fuzz_harness;

use fuzz_harness as h;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRng, TestRunner};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Files directly in `dir` (sorted; none if it does not exist), at most `max_len` bytes.
fn files(dir: &Path, ext: Option<&str>, max_len: usize) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .filter(|p| ext.is_none_or(|x| p.extension().and_then(|e| e.to_str()) == Some(x)))
        .filter(|p| p.file_name().and_then(|n| n.to_str()) != Some("EXPECTED.toml"))
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() as usize <= max_len))
        .collect();
    v.sort();
    v
}

struct Target {
    name: &'static str,
    run: fn(&[u8]),
    max_len: usize,
    /// Seed directories and the extension of their files.
    seeds: &'static [(&'static str, &'static str)],
    dict: &'static str,
}

const TARGETS: [Target; 9] = [
    Target {
        name: "urdf_loader",
        run: h::urdf,
        max_len: h::URDF_MAX_LEN,
        seeds: &[
            ("robots", "urdf"),
            ("tests/broken", "urdf"),
            ("tests/data", "urdf"),
        ],
        dict: "urdf.dict",
    },
    Target {
        name: "dh_loader",
        run: h::dh,
        max_len: h::TOML_MAX_LEN,
        seeds: &[("robots", "toml"), ("tests/broken", "toml")],
        dict: "dh.dict",
    },
    Target {
        name: "scenario_loader",
        run: h::scenario,
        max_len: h::TOML_MAX_LEN,
        seeds: &[("scenarios", "toml"), ("tests/broken_scenarios", "toml")],
        dict: "scenario.dict",
    },
    Target {
        name: "mcap_reader",
        run: h::mcap,
        max_len: h::MCAP_MAX_LEN,
        seeds: &[("tests/data/recordings", "mcap")],
        dict: "mcap.dict",
    },
    Target {
        name: "stl_reader",
        run: h::stl,
        max_len: h::MESH_MAX_LEN,
        seeds: &[
            ("tests/data/meshes", "stl"),
            ("robots/meshes/ur5/collision", "stl"),
            ("tests/broken/readers", "stl"),
        ],
        dict: "stl.dict",
    },
    Target {
        name: "obj_reader",
        run: h::obj,
        max_len: h::MESH_MAX_LEN,
        seeds: &[
            ("tests/data/meshes", "obj"),
            ("robots/meshes/iiwa14/visual", "obj"),
        ],
        dict: "obj.dict",
    },
    Target {
        name: "dae_reader",
        run: h::dae,
        max_len: h::MESH_MAX_LEN,
        seeds: &[
            ("tests/data/meshes", "dae"),
            ("tests/broken/readers", "dae"),
        ],
        dict: "dae.dict",
    },
    Target {
        name: "srdf_reader",
        run: h::srdf,
        max_len: h::MESH_MAX_LEN,
        seeds: &[
            ("robots/spherized", "srdf"),
            ("tests/broken/readers", "srdf"),
        ],
        dict: "srdf.dict",
    },
    Target {
        name: "moveit_yaml",
        run: h::moveit,
        max_len: h::MESH_MAX_LEN,
        seeds: &[("tests/data/moveit", "yaml")],
        dict: "yaml.dict",
    },
];

impl Target {
    /// Seed files, then the committed corpus and regression inputs.
    fn inputs(&self) -> Vec<PathBuf> {
        let mut v = Vec::new();
        for (dir, ext) in self.seeds {
            v.extend(files(&root().join(dir), Some(ext), self.max_len));
        }
        for dir in ["fuzz/corpus", "fuzz/regressions"] {
            v.extend(files(&root().join(dir).join(self.name), None, usize::MAX));
        }
        v
    }

    /// The libFuzzer dictionary's tokens (`"…"` lines; `\"`, `\\` and `\xNN` escapes).
    fn tokens(&self) -> Vec<Vec<u8>> {
        let p = root().join("fuzz/dict").join(self.dict);
        let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        text.lines()
            .filter_map(|l| l.trim().strip_prefix('"')?.strip_suffix('"'))
            .map(unescape)
            .collect()
    }
}

/// A seed, corpus or regression input. Scenario inputs are run as
/// `<repo>/scenarios/fuzz_scenario.toml` (see [`h::scenario_file`]), so the model paths of
/// the broken scenarios (`../../robots/…`, written for `tests/broken_scenarios/`) are
/// rewritten to `../robots/…` as the committed fuzz corpus has them.
/// A dictionary token's bytes: `\\`, `\"` and `\xNN` escapes as libFuzzer reads them.
fn unescape(t: &str) -> Vec<u8> {
    let b = t.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'\\' && i + 1 < b.len() {
            if b[i + 1] == b'x' && i + 3 < b.len() {
                let hex = std::str::from_utf8(&b[i + 2..i + 4]).unwrap_or("");
                let v = u8::from_str_radix(hex, 16)
                    .unwrap_or_else(|_| panic!("bad escape in dictionary token {t}"));
                out.push(v);
                i += 4;
            } else {
                out.push(b[i + 1]);
                i += 2;
            }
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    out
}

fn read(p: &Path) -> Vec<u8> {
    let bytes = std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    if p.starts_with(root().join("tests/broken_scenarios")) {
        let text = String::from_utf8(bytes).expect("UTF-8 scenario");
        return text.replace("\"../../robots/", "\"../robots/").into_bytes();
    }
    bytes
}

/// Seconds one replayed input may take (in release; the campaigns ran at -timeout=10
/// under AddressSanitizer).
const REPLAY_TIMEOUT_S: u64 = 60;

/// Runs one input on a thread, naming it if the target panics or takes longer than
/// [`REPLAY_TIMEOUT_S`] (a regression of a hang fails instead of hanging the test).
fn run_named(t: &Target, what: &str, data: &[u8]) {
    let (tx, rx) = std::sync::mpsc::channel();
    let (run, data) = (t.run, data.to_vec());
    let worker = std::thread::spawn(move || {
        run(&data);
        let _ = tx.send(());
    });
    match rx.recv_timeout(std::time::Duration::from_secs(REPLAY_TIMEOUT_S)) {
        Ok(()) => {
            let _ = worker.join();
        }
        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
            panic!(
                "{}: {what} still running after {REPLAY_TIMEOUT_S} s",
                t.name
            )
        }
        Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
            panic!("{}: panicked on {what}", t.name)
        }
    }
}

#[test]
fn replay_seeds_corpus_and_regressions() {
    for t in &TARGETS {
        let inputs = t.inputs();
        assert!(
            inputs.len() >= 10,
            "{}: only {} inputs",
            t.name,
            inputs.len()
        );
        for p in &inputs {
            run_named(t, &p.display().to_string(), &read(p));
        }
    }
}

/// What each committed regression input must now give: (target directory, file, a
/// substring of the error; `""` for an input that must load).
const REGRESSIONS: &[(&str, &str, &str)] = &[
    (
        "scenario_loader",
        "empty_links_table.toml",
        "[links] is empty: a linkage needs links",
    ),
    (
        "scenario_loader",
        "sweep_start_far_from_assembly.toml",
        "more than a million tracking steps",
    ),
    (
        "scenario_loader",
        "slow_limit_position_newton.toml",
        "locked here (limit position)",
    ),
    (
        "mcap_reader",
        "uncompressed_chunk_record_overruns_chunk.mcap",
        "bytes of content, more than the",
    ),
    (
        "obj_reader",
        "relative_index_before_first.obj",
        "OBJ: line 5: index -11 of a texture coordinate is out of range (1 before it)",
    ),
    (
        "obj_reader",
        "relative_normal_index_before_invalid_utf8.obj",
        "OBJ: line 5: index -11 of a normal is out of range (1 before it)",
    ),
];

#[test]
fn regressions_give_their_errors() {
    let dir = root().join("fuzz/regressions");
    for (target, file, expect) in REGRESSIONS {
        let path = dir.join(target).join(file);
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let text = String::from_utf8_lossy(&bytes);
        let err = match *target {
            "urdf_loader" => armsim::model::Model::spec_from_str(&text, h::URDF_FILE)
                .and_then(armsim::model::Model::build)
                .err()
                .map(|e| e.to_string()),
            "dh_loader" => armsim::model::Model::spec_from_str(&text, h::DH_FILE)
                .and_then(armsim::model::Model::build)
                .err()
                .map(|e| e.to_string()),
            "mcap_reader" => {
                armsim::io::record::mcap_in::read_mcap_bytes(&bytes, Path::new(h::MCAP_FILE))
                    .err()
                    .map(|e| e.to_string())
            }
            "stl_reader" => armsim::collision::mesh::read_stl(&bytes)
                .err()
                .map(|e| e.to_string()),
            "obj_reader" => armsim::collision::mesh::read_obj_bytes(&bytes)
                .err()
                .map(|e| e.to_string()),
            "dae_reader" => armsim::collision::mesh::read_dae(&text)
                .err()
                .map(|e| e.to_string()),
            "srdf_reader" => armsim::planning::srdf::parse_srdf(&text, h::SRDF_FILE)
                .err()
                .map(|e| e.to_string()),
            _ => armsim::scenarios::check(h::scenario_file(), &text)
                .err()
                .map(|e| e.to_string()),
        };
        match err {
            None => assert!(expect.is_empty(), "{file}: loaded, expected '{expect}'"),
            Some(e) => assert!(
                !expect.is_empty() && e.contains(expect),
                "{file}: '{e}', expected '{expect}'"
            ),
        }
    }
    // Every regression input is listed.
    for t in &TARGETS {
        for p in files(&dir.join(t.name), None, usize::MAX) {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            assert!(
                REGRESSIONS.iter().any(|r| r.0 == t.name && r.1 == name),
                "{}: not listed in REGRESSIONS",
                p.display()
            );
        }
    }
}

#[test]
fn regression_inputs_are_named_for_their_target() {
    // Every file under fuzz/regressions/ sits in a directory named after a target.
    let dir = root().join("fuzz/regressions");
    let Ok(rd) = std::fs::read_dir(&dir) else {
        return;
    };
    for e in rd.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if e.path().is_dir() {
            assert!(
                TARGETS.iter().any(|t| t.name == name),
                "fuzz/regressions/{name}: not a target name"
            );
        }
    }
}

/// One edit of an input.
#[derive(Clone, Debug)]
enum Edit {
    /// XOR the byte at (position fraction) with a non-zero mask.
    Flip(f64, u8),
    /// Keep the first (fraction) of the input.
    Truncate(f64),
    /// Insert dictionary token `k` (modulo their number).
    Token(f64, usize),
    /// Insert an odd number.
    Number(f64, String),
    /// Delete `n` bytes.
    Delete(f64, usize),
    /// Repeat the `n` bytes from the position `times` times.
    Repeat(f64, usize, usize),
}

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e308".to_string()),
        Just("-1e308".to_string()),
        Just("5e-324".to_string()),
        Just("-0".to_string()),
        Just("18446744073709551615".to_string()),
        Just("99999999999999999999999".to_string()),
        any::<i64>().prop_map(|i| i.to_string()),
        any::<f64>().prop_map(|x| format!("{x:e}")),
        (-1e3f64..1e3).prop_map(|x| x.to_string()),
    ]
}

fn edit() -> impl Strategy<Value = Edit> {
    let at = 0.0f64..1.0;
    prop_oneof![
        (at.clone(), 1u8..=255).prop_map(|(p, m)| Edit::Flip(p, m)),
        at.clone().prop_map(Edit::Truncate),
        (at.clone(), any::<usize>()).prop_map(|(p, k)| Edit::Token(p, k)),
        (at.clone(), number()).prop_map(|(p, n)| Edit::Number(p, n)),
        (at.clone(), 1usize..64).prop_map(|(p, n)| Edit::Delete(p, n)),
        (at, 1usize..128, 1usize..20).prop_map(|(p, n, k)| Edit::Repeat(p, n, k)),
    ]
}

fn apply(data: &mut Vec<u8>, edits: &[Edit], tokens: &[Vec<u8>], max_len: usize) {
    for e in edits {
        let pos = |f: f64| ((data.len() as f64 * f) as usize).min(data.len());
        match e {
            Edit::Flip(f, m) => {
                if !data.is_empty() {
                    let i = pos(*f).min(data.len() - 1);
                    data[i] ^= m;
                }
            }
            Edit::Truncate(f) => data.truncate(pos(*f)),
            Edit::Token(f, k) => {
                let i = pos(*f);
                let t = &tokens[k % tokens.len()];
                data.splice(i..i, t.iter().copied());
            }
            Edit::Number(f, n) => {
                let i = pos(*f);
                data.splice(i..i, n.bytes());
            }
            Edit::Delete(f, n) => {
                let i = pos(*f);
                let j = (i + n).min(data.len());
                data.drain(i..j);
            }
            Edit::Repeat(f, n, k) => {
                let i = pos(*f);
                let j = (i + n).min(data.len());
                let chunk: Vec<u8> = data[i..j].to_vec();
                for _ in 0..*k {
                    data.splice(j..j, chunk.iter().copied());
                }
            }
        }
        data.truncate(max_len);
    }
}

/// `cases` mutated seeds per target. The mutations are the same on every run (CI stays
/// reproducible); `FUZZ_SMOKE_RANDOM=1` draws fresh ones, to explore.
fn mutate(t: &Target, cases: u32) {
    let seeds: Vec<Vec<u8>> = t.inputs().iter().map(|p| read(p)).collect();
    let tokens = t.tokens();
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner = if std::env::var_os("FUZZ_SMOKE_RANDOM").is_some() {
        TestRunner::new(config)
    } else {
        let rng = TestRng::deterministic_rng(config.rng_algorithm);
        TestRunner::new_with_rng(config, rng)
    };
    let strategy = (0..seeds.len(), prop::collection::vec(edit(), 1..8));
    let ran = std::cell::Cell::new(0u32);
    runner
        .run(&strategy, |(s, edits)| {
            let mut data = seeds[s].clone();
            apply(&mut data, &edits, &tokens, t.max_len);
            (t.run)(&data);
            ran.set(ran.get() + 1);
            Ok(())
        })
        .unwrap_or_else(|e| panic!("{}: {e}", t.name));
    assert!(ran.get() >= cases, "{}: {} cases ran", t.name, ran.get());
}

#[test]
fn mutated_urdf() {
    mutate(&TARGETS[0], 5000);
}

#[test]
fn mutated_dh_tables() {
    mutate(&TARGETS[1], 20000);
}

#[test]
fn mutated_scenarios() {
    mutate(&TARGETS[2], 10000);
}

#[test]
fn mutated_recordings() {
    mutate(&TARGETS[3], 5000);
}

/// The scenario target reaches the whole arm loader: every bundled scenario, run under the
/// fuzz input's name, validates (its model resolves from `scenarios/`), and each broken
/// arm scenario fails with its model loaded, i.e. not for a missing model file (except the
/// one whose point is a missing model, and the unreachable pose and the budgets of the
/// planned motion, found when planning).
#[test]
fn scenario_inputs_reach_the_arm_loader() {
    let t = &TARGETS[2];
    let bundled = files(&root().join("scenarios"), Some("toml"), t.max_len);
    assert!(bundled.len() >= 8, "{} bundled scenarios", bundled.len());
    for p in &bundled {
        let text = String::from_utf8(read(p)).unwrap();
        if let Err(e) = armsim::scenarios::check(h::scenario_file(), &text) {
            panic!("{}: {e}", p.display());
        }
    }
    let broken = files(
        &root().join("tests/broken_scenarios"),
        Some("toml"),
        t.max_len,
    );
    let arm: Vec<_> = broken
        .iter()
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("arm_"))
        .collect();
    assert!(arm.len() >= 20, "{} broken arm scenarios", arm.len());
    for p in arm {
        let text = String::from_utf8(read(p)).unwrap();
        let checked = armsim::scenarios::check(h::scenario_file(), &text);
        // IK runs when the motion is planned, after `check`: an unreachable pose, and the
        // budgets that need the planned motion's duration, are refused by `armsim run`
        // (tests/arm_scenarios.rs), not here.
        let at_planning = [
            "arm_unreachable_pose.toml",
            "arm_check_dt_over_budget.toml",
            "arm_dwell_over_budget.toml",
        ];
        if at_planning.iter().any(|f| p.ends_with(f)) {
            assert!(checked.is_ok(), "{}: {checked:?}", p.display());
            continue;
        }
        let e = checked.expect_err(&format!("{} validated", p.display()));
        let missing = e.to_string().contains(": model.file: ");
        let expect_missing = p.ends_with("arm_missing_model.toml");
        assert_eq!(missing, expect_missing, "{}: {e}", p.display());
    }
}

#[test]
fn scenario_seeds_and_dictionary_cover_every_scenario_kind() {
    // The kinds as the dispatcher lists them when it refuses an unknown one.
    let e = armsim::scenarios::check(h::scenario_file(), "kind = \"no_such_kind\"\n")
        .expect_err("an unknown kind is refused");
    let kinds: Vec<String> = e
        .message
        .split('"')
        .skip(1)
        .step_by(2)
        .filter(|k| *k != "no_such_kind")
        .map(str::to_string)
        .collect();
    assert!(kinds.len() >= 12, "kinds listed: {kinds:?} in '{e}'");
    let t = TARGETS
        .iter()
        .find(|t| t.name == "scenario_loader")
        .unwrap();
    let tokens = t.tokens();
    let seeds = t.inputs();
    for k in &kinds {
        let token = format!("\"{k}\"").into_bytes();
        assert!(tokens.contains(&token), "dictionary lacks the kind {k}");
        let line = format!("kind = \"{k}\"");
        let (mut valid, mut broken) = (0, 0);
        for p in &seeds {
            let text = String::from_utf8_lossy(&read(p)).into_owned();
            if !text.lines().any(|l| l.trim() == line) {
                continue;
            }
            if p.starts_with(root().join("tests/broken_scenarios")) {
                broken += 1;
            } else if armsim::scenarios::check(h::scenario_file(), &text).is_ok() {
                valid += 1;
            }
        }
        // Arm seeds mostly leave `kind` out (their broken files are counted elsewhere).
        assert!(valid >= 1 || k == "arm", "{k}: no valid seed");
        if k != "arm" {
            assert!(broken >= 10, "{k}: {broken} broken seeds");
        }
    }
}

#[test]
fn mutated_meshes() {
    for t in &TARGETS[4..7] {
        mutate(t, 2000);
    }
}

#[test]
fn mutated_srdf_and_moveit_yaml() {
    mutate(&TARGETS[7], 2000);
    mutate(&TARGETS[8], 2000);
}
