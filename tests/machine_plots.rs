//! The pictures of the textbook-machine kinds (`armsim run FILE --out DIR`): every kind
//! that has something to look at writes one PNG, named after the scenario and the kind,
//! atomically (no temporary file left), says so in its text summary, and draws its data
//! (pixels in the plot palette's first colours, not only axes). The cam and gear-pair
//! pictures are also checked against the numbers: the cam's profile panel and each
//! gear's outline span what the JSON reports.

use armsim::scenarios::arm::RunOptions;
use std::path::{Path, PathBuf};

mod common;

/// RGB pixels of a PNG and its size.
fn pixels(path: &Path) -> (Vec<u8>, u32, u32) {
    let file = std::fs::File::open(path).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (buf, info.width, info.height)
}

/// Runs `scenarios/<file>` with `--out` a fresh directory; its report and the directory.
fn run_with_out(file: &str) -> (armsim::io::report::Report, PathBuf) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("mplots_{file}"));
    let _ = std::fs::remove_dir_all(&dir);
    let opts = RunOptions {
        out_dir: Some(dir.clone()),
        ..Default::default()
    };
    let r = armsim::scenarios::run_file_with(&common::root().join("scenarios").join(file), &opts)
        .unwrap_or_else(|e| panic!("{file}: {e}"));
    (r, dir)
}

/// Pixels close to one of the plot palette's first three colours (the data lines).
fn data_pixels(buf: &[u8]) -> usize {
    const COLOURS: [[u8; 3]; 3] = [[31, 119, 180], [255, 127, 14], [44, 160, 44]];
    buf.chunks(3)
        .filter(|p| {
            COLOURS.iter().any(|c| {
                p.iter()
                    .zip(c)
                    .all(|(a, b)| (*a as i32 - *b as i32).abs() < 30)
            })
        })
        .count()
}

#[test]
fn every_machine_kind_with_a_picture_writes_it() {
    for (file, suffix) in [
        ("cam_roller_cycloidal_design.toml", "_cam.png"),
        ("cam_cm1_eccentric_knife.toml", "_cam.png"),
        ("gear_pair_gg4_218_tooth_thickness.toml", "_gears.png"),
        ("flywheel_139.toml", "_flywheel.png"),
        ("flexible_rotor_uniform_shaft.toml", "_rotor.png"),
        ("isolation_transmissibility.toml", "_isolation.png"),
        (
            "centrodes_isosceles_slotted_lever_274.toml",
            "_centrodes.png",
        ),
        ("synthesis_function_log10.toml", ".png"),
    ] {
        let (r, dir) = run_with_out(file);
        let files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{file}: no output directory: {e}"))
            .map(|e| e.unwrap().path())
            .collect();
        assert_eq!(
            files.len(),
            1,
            "{file}: {files:?} (one picture, no temporary file)"
        );
        let png = &files[0];
        let name = png.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.ends_with(suffix), "{file}: {name}");
        assert!(
            r.text.contains(&format!("plot: {}", png.display())),
            "{file}: the summary names the picture"
        );
        let (buf, w, h) = pixels(png);
        assert!(w >= 600 && h >= 400, "{file}: {w}x{h}");
        let n = data_pixels(&buf);
        assert!(n > 800, "{file}: only {n} data pixels");
    }
}

#[test]
fn cam_and_gear_panels_draw_the_reported_numbers() {
    use armsim::io::plots::machine_plots::{cam_panels, pair_panels};
    let cam = common::run_json("scenarios/cam_roller_cycloidal_design.toml");
    let panels = cam_panels(&cam);
    let titles: Vec<&str> = panels.iter().map(|p| p.title.as_str()).collect();
    assert_eq!(
        titles,
        [
            "profile (cam frame)",
            "displacement s",
            "velocity v",
            "acceleration a",
            "jerk",
            "pressure angle"
        ]
    );
    // The displacement panel spans 0 … stroke, the profile the pitch curve's radii.
    let s = &panels[1].series[0].points;
    let top = s.iter().map(|p| p.1).fold(f64::MIN, f64::max);
    let stroke = cam["summary"]["stroke"].as_f64().unwrap();
    assert!(
        (top - stroke).abs() < 1e-9 * stroke.max(1.0),
        "{top} vs {stroke}"
    );
    assert_eq!(s.len(), cam["samples"]["s"].as_array().unwrap().len());
    let gp = common::run_json("scenarios/gear_pair_gg4_218_tooth_thickness.toml");
    let panels = pair_panels(&gp);
    assert!(!panels.is_empty());
    let g = &gp["pairs"][0]["gears"][0];
    let (ra, z) = (
        g["tip_radius"].as_f64().unwrap(),
        g["teeth"].as_u64().unwrap() as usize,
    );
    let outline = &panels[0].series[0].points;
    let far = outline.iter().map(|p| p.0.hypot(p.1)).fold(0.0, f64::max);
    assert!(
        (far - ra).abs() < 1e-9 * ra,
        "outline reaches the tip circle: {far} vs {ra}"
    );
    // z teeth: the outline's points at the tip radius come in z groups.
    let tooth_len = g["tooth_profile"].as_array().unwrap().len();
    assert_eq!(outline.len(), z * tooth_len + 1);
}
