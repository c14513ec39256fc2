//! Plot of the torque check: `τ_j(t)` against `±τ_max,j`, one panel per joint (at most
//! 24: beyond, the joints with the smallest margins), under a title naming the scenario,
//! with the legend in a column right of the charts and axis ticks from
//! [`crate::io::plots::ticks`]; and the pieces the other charts share (title, legend, font,
//! palette, PNG encoding). Drawn with
//! plotters (bitmap backend into memory, encoded to PNG with the `png` crate; or SVG into
//! a string). Text is drawn with the bundled DejaVu Sans Mono (`assets/fonts/`, Bitstream
//! Vera license, see `assets/fonts/LICENSE-DejaVu.txt`) through plotters' `ab_glyph`
//! renderer, so no system font is needed.

use crate::io::plots::plot_error::PlotError;
use crate::io::plots::ticks::AxisTicks;
use crate::motion::torque_check::TorqueReport;
use crate::motion::TrajectoryError;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::sync::Once;

/// The bundled font (also used by the trade-offs report's charts).
static FONT: &[u8] = include_bytes!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/assets/fonts/DejaVuSansMono.ttf"
));
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
/// Height of the two title lines above the panels (pixels).
pub(crate) const HEADER_HEIGHT: u32 = 40;
/// Width of the legend column right of the charts (pixels).
pub(crate) const LEGEND_WIDTH: u32 = 180;
/// At most this many ticks on an axis.
pub(crate) const MAX_TICKS: usize = 7;
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

/// Renders the report to bytes in `format`; the title names `scenario` when given.
pub(crate) fn render(
    report: &TorqueReport,
    format: PlotFormat,
    scenario: Option<&str>,
) -> Result<Vec<u8>, PlotError> {
    register_font();
    let n = panel_joints(report).len().max(1) as u32;
    let size = (WIDTH, PANEL_HEIGHT * n + HEADER_HEIGHT);
    match format {
        PlotFormat::Png => {
            let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
                draw(report, scenario, &root)?;
                root.present().map_err(PlotError::draw)?;
            }
            encode_png(&buf, size)
        }
        PlotFormat::Svg => {
            let mut s = String::new();
            {
                let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
                draw(report, scenario, &root)?;
                root.present().map_err(PlotError::draw)?;
            }
            Ok(s.into_bytes())
        }
    }
}

pub(crate) fn encode_png(rgb: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>, PlotError> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header().map_err(PlotError::png)?;
        writer.write_image_data(rgb).map_err(PlotError::png)?;
    }
    Ok(out)
}

/// An f64 axis over `[lo, hi]` whose tick marks are exactly an [`AxisTicks`]'s values
/// (plotters' own `with_key_points` over f64 cannot take a label formatter).
pub(crate) struct TickedRange {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
}

impl TickedRange {
    /// The axis of `ticks`, over its range.
    pub(crate) fn of(ticks: &AxisTicks) -> Self {
        TickedRange {
            lo: ticks.lo,
            hi: ticks.hi,
            ticks: ticks.values.clone(),
        }
    }
}

impl Ranged for TickedRange {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        RangedCoordf64::from(self.lo..self.hi).map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// One legend entry: a series name and how its line is drawn.
pub(crate) struct LegendEntry {
    pub name: String,
    pub color: RGBColor,
    pub dashed: bool,
}

/// Longest legend name drawn in full (longer ones are cut with `…`).
const LEGEND_CHARS: usize = 20;

/// Draws `entries` as a column at the top of `area` (beside the charts, never on the
/// data): a line sample and the name per row, from `top` pixels down.
pub(crate) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    top: i32,
) -> Result<(), PlotError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::draw(e);
    let font = ("sans-serif", 12).into_font().color(&BLACK);
    for (k, e) in entries.iter().enumerate() {
        let y = top + 16 * k as i32;
        let style = e.color.stroke_width(2);
        if e.dashed {
            for x in [8, 17] {
                area.draw(&PathElement::new([(x, y), (x + 6, y)], style))
                    .map_err(err)?;
            }
        } else {
            area.draw(&PathElement::new([(8, y), (30, y)], style))
                .map_err(err)?;
        }
        let name = if e.name.chars().count() > LEGEND_CHARS {
            let cut: String = e.name.chars().take(LEGEND_CHARS - 1).collect();
            format!("{cut}…")
        } else {
            e.name.clone()
        };
        area.draw(&Text::new(name, (36, y - 7), font.clone()))
            .map_err(err)?;
    }
    Ok(())
}

/// Draws a two-line title: `title` large, `subtitle` below it, left-aligned in `area`.
pub(crate) fn draw_title<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    subtitle: &str,
) -> Result<(), PlotError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::draw(e);
    let big = ("sans-serif", 17).into_font().color(&BLACK);
    let small = ("sans-serif", 12).into_font().color(&RGBColor(60, 60, 60));
    area.draw(&Text::new(title.to_string(), (10, 3), big))
        .map_err(err)?;
    area.draw(&Text::new(subtitle.to_string(), (10, 23), small))
        .map_err(err)?;
    Ok(())
}

fn draw<DB: DrawingBackend>(
    report: &TorqueReport,
    scenario: Option<&str>,
    root: &DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::draw(e);
    root.fill(&WHITE).map_err(err)?;
    let effects = if report.effects.is_empty() {
        "rigid body".to_string()
    } else {
        report.effects.join(", ")
    };
    let shown = panel_joints(report);
    let title = match scenario {
        Some(name) => format!("{name}: joint torques vs effort limits"),
        None => "joint torques vs effort limits".to_string(),
    };
    let subtitle = format!(
        "effects: {effects} - {}{}",
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
    let (header, body) = root.split_vertically(HEADER_HEIGHT);
    draw_title(&header, &title, &subtitle)?;
    let (charts, legend) = body.split_horizontally(WIDTH - LEGEND_WIDTH);
    let mut entries = vec![LegendEntry {
        name: "torque".into(),
        color: BLUE,
        dashed: false,
    }];
    if report.joints.iter().any(|r| r.limit.is_finite()) {
        entries.push(LegendEntry {
            name: "± effort limit".into(),
            color: RED,
            dashed: true,
        });
    }
    if report
        .joints
        .iter()
        .any(|r| r.first_torque_violation_s.is_some())
    {
        entries.push(LegendEntry {
            name: "first violation".into(),
            color: VIOLATION,
            dashed: false,
        });
    }
    draw_legend(&legend, &entries, 36)?;
    let panels = charts.split_evenly((shown.len().max(1), 1));
    let t_end = report.t.last().copied().unwrap_or(0.0).max(1e-9);
    for (&j, area) in shown.iter().zip(panels.iter()) {
        draw_joint(report, j, t_end, area)?;
    }
    Ok(())
}

/// Colour of the first-violation marker.
const VIOLATION: RGBColor = RGBColor(200, 0, 200);

/// One joint's panel: its torque, the ± limit and the first violation.
fn draw_joint<DB: DrawingBackend>(
    report: &TorqueReport,
    j: usize,
    t_end: f64,
    area: &DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::draw(e);
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
    let x = AxisTicks::new(0.0, t_end, MAX_TICKS + 4);
    let y = AxisTicks::new(-top, top, MAX_TICKS);
    let x_fmt = |v: &f64| x.label(*v);
    let y_fmt = |v: &f64| y.label(*v);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 14))
        .margin(6)
        .x_label_area_size(30)
        .y_label_area_size(64)
        .build_cartesian_2d(TickedRange::of(&x), TickedRange::of(&y))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x.title("t (s)"))
        .y_desc(y.title("torque (N m)"))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 12))
        .bold_line_style(RGBColor(225, 225, 225))
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
                VIOLATION.stroke_width(1),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// Renders `τ(t)` against the limits, one panel per joint, and writes it atomically
/// (rendered in memory, then [`crate::core::files::write_atomic`]); `scenario` names the
/// scenario in the title.
pub fn write_torque_plot(
    report: &TorqueReport,
    path: &std::path::Path,
    format: PlotFormat,
    scenario: Option<&str>,
) -> Result<(), TrajectoryError> {
    if report.t.is_empty() {
        return Err(TrajectoryError::Output(
            "plot: the report kept no samples (CheckOptions::keep_series)".into(),
        ));
    }
    let bytes =
        render(report, format, scenario).map_err(|e| TrajectoryError::Output(e.to_string()))?;
    crate::core::files::write_atomic(path, &bytes)
        .map_err(|e| TrajectoryError::Output(format!("{}: {e}", path.display())))
}
