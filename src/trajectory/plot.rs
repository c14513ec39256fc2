//! Plot of the torque check: `τ_j(t)` against `±τ_max,j`, one panel per joint (at most
//! 24: beyond, the joints with the smallest margins), with
//! plotters (bitmap backend into memory, encoded to PNG with the `png` crate; or SVG into
//! a string). Text is drawn with the bundled DejaVu Sans Mono (`assets/fonts/`, Bitstream
//! Vera license, see `assets/fonts/LICENSE-DejaVu.txt`) through plotters' `ab_glyph`
//! renderer, so no system font is needed.

use super::torque_check::TorqueReport;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::sync::Once;

/// The bundled font (also used by the trade-offs report's charts).
static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");
static REGISTER: Once = Once::new();

/// Line colours of armsim's multi-series charts (colour-blind-safe Tableau order): the
/// scenario simulation plots and the trade-offs report.
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// Output format of the plot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlotFormat {
    /// PNG image.
    Png,
    /// SVG drawing.
    Svg,
}

impl PlotFormat {
    /// From a file extension (`png` or `svg`, any case).
    pub fn from_path(path: &std::path::Path) -> Option<Self> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "png" => Some(PlotFormat::Png),
            "svg" => Some(PlotFormat::Svg),
            _ => None,
        }
    }
}

/// Panel size (pixels).
const WIDTH: u32 = 960;
const PANEL_HEIGHT: u32 = 220;
/// At most this many panels: beyond, the joints with the smallest torque margins.
pub(crate) const MAX_PANELS: usize = 24;

/// The joints to draw, in order: all of them, or the `MAX_PANELS` with the smallest
/// torque margins.
fn panel_joints(report: &TorqueReport) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..report.dof()).collect();
    if idx.len() > MAX_PANELS {
        idx.sort_by(|&a, &b| report.joints[a].margin.total_cmp(&report.joints[b].margin));
        idx.truncate(MAX_PANELS);
        idx.sort_unstable();
    }
    idx
}

pub(crate) fn register_font() {
    REGISTER.call_once(|| {
        // The font is valid (checked by the tests); a failure would only lose the text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Renders the report to bytes in `format`.
pub(crate) fn render(report: &TorqueReport, format: PlotFormat) -> Result<Vec<u8>, String> {
    register_font();
    let n = panel_joints(report).len().max(1) as u32;
    let size = (WIDTH, PANEL_HEIGHT * n + 40);
    match format {
        PlotFormat::Png => {
            let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
                draw(report, &root)?;
                root.present().map_err(|e| format!("plot: {e}"))?;
            }
            encode_png(&buf, size)
        }
        PlotFormat::Svg => {
            let mut s = String::new();
            {
                let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
                draw(report, &root)?;
                root.present().map_err(|e| format!("plot: {e}"))?;
            }
            Ok(s.into_bytes())
        }
    }
}

pub(crate) fn encode_png(rgb: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(|e| format!("png: {e}"))?;
        writer
            .write_image_data(rgb)
            .map_err(|e| format!("png: {e}"))?;
    }
    Ok(out)
}

fn draw<DB: DrawingBackend>(
    report: &TorqueReport,
    root: &DrawingArea<DB, Shift>,
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plot: {e}");
    root.fill(&WHITE).map_err(err)?;
    let effects = if report.effects.is_empty() {
        "rigid body".to_string()
    } else {
        report.effects.join(", ")
    };
    let shown = panel_joints(report);
    let title = format!(
        "joint torques vs effort limits ({effects}) - {}{}",
        if report.ok {
            "all within limits"
        } else {
            "LIMITS EXCEEDED"
        },
        if shown.len() < report.dof() {
            format!(
                " - the {} joints of {} with the smallest margins",
                shown.len(),
                report.dof()
            )
        } else {
            String::new()
        }
    );
    let root = root.titled(&title, ("sans-serif", 18)).map_err(err)?;
    let panels = root.split_evenly((shown.len().max(1), 1));
    let t_end = report.t.last().copied().unwrap_or(0.0).max(1e-9);
    for (&j, area) in shown.iter().zip(panels.iter()) {
        let row = &report.joints[j];
        let lim = row.limit;
        let top = if lim.is_finite() {
            row.peak_torque.max(lim)
        } else {
            row.peak_torque
        };
        let top = if top > 0.0 { 1.1 * top } else { 1.0 };
        let caption = format!(
            "{}: peak {:.3}, limit {}, margin {:.1} %{}",
            row.joint,
            row.peak_torque,
            if lim.is_finite() {
                format!("{lim:.3}")
            } else {
                "none".into()
            },
            row.margin,
            row.first_torque_violation_s
                .map_or(String::new(), |t| format!(", first violation at {t:.4} s"))
        );
        let mut chart = ChartBuilder::on(area)
            .caption(caption, ("sans-serif", 14))
            .margin(6)
            .x_label_area_size(28)
            .y_label_area_size(64)
            .build_cartesian_2d(0.0..t_end, -top..top)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc("torque (N m)")
            .label_style(("sans-serif", 11))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(err)?;
        let series = report
            .t
            .iter()
            .enumerate()
            .map(|(k, &t)| (t, report.torque(k, j)));
        chart
            .draw_series(LineSeries::new(series, BLUE.stroke_width(2)))
            .map_err(err)?;
        if lim.is_finite() {
            for l in [lim, -lim] {
                chart
                    .draw_series(DashedLineSeries::new(
                        [(0.0, l), (t_end, l)],
                        8,
                        5,
                        RED.stroke_width(2),
                    ))
                    .map_err(err)?;
            }
        }
        if let Some(tv) = row.first_torque_violation_s {
            chart
                .draw_series(LineSeries::new(
                    [(tv, -top), (tv, top)],
                    RGBColor(200, 0, 200).stroke_width(1),
                ))
                .map_err(err)?;
        }
    }
    Ok(())
}
