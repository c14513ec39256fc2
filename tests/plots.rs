//! The PNG plots of an arm run, read as a person reads them: the main scenario's
//! tracking-error axis (values of a few 1e-8) gets distinct tick labels with a common
//! power of ten instead of `0.0` at every tick, the titles name the scenario, and the
//! legends sit in a column right of the charts, off the data (checked on the pixels).

use armsim::scenarios::arm::sim_plots as plots;
use armsim::scenarios::arm::{self, RunOptions};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `scenarios/<name>.toml`, writing its files to a fresh directory named after `tag`.
fn run_bundled(name: &str, tag: &str) -> (arm::Outcome, PathBuf) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("plots_{tag}"));
    let _ = std::fs::remove_dir_all(&dir);
    let path = root().join("scenarios").join(format!("{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap();
    let opts = RunOptions {
        out_dir: Some(dir.clone()),
        ..Default::default()
    };
    (arm::run(&path, &text, &opts).unwrap(), dir)
}

/// RGB pixels of a PNG and its size.
fn pixels(path: &std::path::Path) -> (Vec<u8>, u32, u32) {
    let file = std::fs::File::open(path).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (buf, info.width, info.height)
}

#[test]
fn ur5_tracking_error_ticks_are_distinct_and_scaled() {
    let (out, dir) = run_bundled("ur5_pick_and_place", "ticks");
    // The case that used to read "0.0" everywhere: errors far below the 0.1 a one-decimal
    // label resolves (a few 1e-8 before the planner; a few 1e-5 now that the planned path is
    // timed by TOPP, whose accelerations switch at once).
    let max_err = out
        .samples
        .iter()
        .flat_map(|s| s.q.iter().zip(&s.q_ref).map(|(q, r)| (q - r).abs()))
        .fold(0.0f64, f64::max);
    assert!(
        max_err > 1e-10 && max_err < 1e-3,
        "max tracking error {max_err}"
    );
    let panels = plots::simulation_panels(&out.scene, &out.samples);
    assert_eq!(panels[0].caption, "tracking error q - q_ref");
    let axis = plots::y_axis(&panels[0]);
    assert!(axis.labels.len() >= 3, "{axis:?}");
    let distinct: std::collections::BTreeSet<&String> = axis.labels.iter().collect();
    assert_eq!(distinct.len(), axis.labels.len(), "{:?}", axis.labels);
    assert!(axis.labels.iter().any(|l| l != "0" && l != "0.0"));
    // A common power of ten, in the axis title, that brings the ticks to 1 … 999.
    assert!(axis.exponent <= -6 && axis.exponent % 3 == 0, "{axis:?}");
    assert_eq!(
        axis.title("rad or m"),
        format!("rad or m  {}", axis.factor())
    );
    assert!(axis.factor().starts_with("×10⁻"));
    let biggest = axis.labels.iter().map(|l| l.parse::<f64>().unwrap().abs());
    let biggest = biggest.fold(0.0, f64::max);
    assert!((1.0..1000.0).contains(&biggest), "{axis:?}");
    // The ticks cover the data: the largest error lies within the axis.
    assert!(axis.lo <= -max_err || axis.hi >= max_err);
    assert!(axis.hi - axis.lo >= max_err);
    // The torque panel in N m needs no factor.
    assert_eq!(plots::y_axis(&panels[1]).exponent, 0);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn legends_sit_right_of_the_charts_and_titles_name_the_scenario() {
    let (out, dir) = run_bundled("ur5_pick_and_place", "legends");
    let n = out.scene.model.nv;
    // The simulation plot: 2 panels of 240 px under a 40 px title, legend column from
    // x = 780 (960 − 180) holding one 16 px row per joint from 36 px into each panel.
    let (px, w, h) = pixels(&dir.join("ur5_pick_and_place_simulation.png"));
    assert_eq!((w, h), (960, 2 * 240 + 40));
    let at = |x: u32, y: u32| {
        let i = 3 * (y * w + x) as usize;
        [px[i], px[i + 1], px[i + 2]]
    };
    let mut legend_ink = 0;
    for y in 40..h {
        let in_panel = (y - 40) % 240;
        let in_legend_rows = (36 - 10..36 + 16 * n as u32).contains(&in_panel);
        for x in 780..w {
            if at(x, y) != [255, 255, 255] {
                assert!(in_legend_rows, "ink at ({x}, {y}) outside the legend rows");
                legend_ink += 1;
            }
        }
    }
    assert!(legend_ink > 500, "legend ink {legend_ink}");
    // The legend's first line sample is the palette's first colour (shoulder_pan_joint).
    assert!((788..808).any(|x| at(x, 40 + 36) == [31, 119, 180]));
    // The torque plot: same layout, one legend at the top of the column.
    let (_, w, h) = pixels(&dir.join("ur5_pick_and_place_torques.png"));
    assert_eq!((w, h), (960, 220 * n as u32 + 40));
    // Titles: the SVG of the same plots carries the text.
    let svg_dir = dir.join("svg");
    std::fs::create_dir_all(&svg_dir).unwrap();
    let svg = svg_dir.join("t.svg");
    armsim::io::plots::torque_chart::write_torque_plot(
        &out.torque,
        &svg,
        armsim::io::plots::torque_chart::PlotFormat::Svg,
        Some("ur5_pick_and_place"),
    )
    .unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("ur5_pick_and_place: joint torques vs effort limits"));
    assert!(text.contains("\n± effort limit\n") && text.contains("\ntorque\n"));
    let panels = plots::simulation_panels(&out.scene, &out.samples);
    let svg = svg_dir.join("s.svg");
    plots::write(
        &svg,
        "ur5_pick_and_place: simulation",
        "subtitle",
        &panels,
        armsim::io::plots::torque_chart::PlotFormat::Svg,
    )
    .unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("ur5_pick_and_place: simulation"));
    let factor = plots::y_axis(&panels[0]).factor();
    assert!(text.contains(&factor), "no {factor} in the SVG");
    std::fs::remove_dir_all(&dir).ok();
}
