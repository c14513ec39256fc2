//! Time-series plots of an arm scenario's simulation: the panels a run draws
//! ([`simulation_panels`]: tracking error and applied torques per joint) and their
//! rendering ([`write`]): a two-line title naming the scenario, one chart per panel with
//! its legend in a column to the right (never on the data), axis ticks from
//! [`crate::io::plots::ticks`] (a common power of ten in the axis title when the values
//! are tiny or huge), drawn with plotters like the torque check's plot and written
//! atomically.

use crate::io::plots::plot_error::PlotError;
use crate::io::plots::ticks::AxisTicks;
use crate::io::plots::torque_chart::PlotFormat;
use crate::io::plots::torque_chart::{
    draw_legend, draw_title, encode_png, register_font, LegendEntry, TickedRange, HEADER_HEIGHT,
    LEGEND_WIDTH, MAX_TICKS, PALETTE,
};
use crate::scenarios::arm::run::SimSample;
use crate::scenarios::arm::scene::Scene;
use plotters::prelude::*;

/// One panel: a caption, a y label and named curves `(t, y)`.
pub struct SimPanel {
    /// The panel caption.
    pub caption: String,
    /// The y-axis label.
    pub y_label: String,
    /// Named curves of `(t, y)` points.
    pub curves: Vec<(String, Vec<(f64, f64)>)>,
}

/// Image width and height of one panel (pixels).
const WIDTH: u32 = 960;
const PANEL_HEIGHT: u32 = 240;

/// The panels of a run's simulation plot: the tracking error `q − q_ref` and the applied
/// (motor, for elastic joints) torques, one curve per joint in the palette's order.
pub fn simulation_panels(scene: &Scene, samples: &[SimSample]) -> Vec<SimPanel> {
    let names = scene.model.dof_names();
    let per_joint = |f: &dyn Fn(&SimSample, usize) -> f64| {
        names
            .iter()
            .enumerate()
            .map(|(k, name)| {
                (
                    name.clone(),
                    samples.iter().map(|s| (s.t, f(s, k))).collect(),
                )
            })
            .collect()
    };
    vec![
        SimPanel {
            caption: "tracking error q - q_ref".into(),
            y_label: "rad or m".into(),
            curves: per_joint(&|s, k| s.q[k] - s.q_ref[k]),
        },
        SimPanel {
            caption: if scene.effects.elasticity.is_some() {
                "motor torques".into()
            } else {
                "applied joint torques".into()
            },
            y_label: "N m or N".into(),
            curves: per_joint(&|s, k| s.tau[k]),
        },
    ]
}

/// The time range of a panel's finite points (`[0, 1]` without any).
fn time_range(p: &SimPanel) -> (f64, f64) {
    let (mut t0, mut t1) = (f64::MAX, f64::MIN);
    for &(t, y) in p.curves.iter().flat_map(|c| c.1.iter()) {
        if t.is_finite() && y.is_finite() {
            t0 = t0.min(t);
            t1 = t1.max(t);
        }
    }
    if t0 > t1 {
        (0.0, 1.0)
    } else {
        (t0, t1.max(t0 + 1e-9))
    }
}

/// The y axis of a panel as drawn: its finite values padded by 5 % of their span, with
/// the ticks and labels of [`AxisTicks`].
pub fn y_axis(p: &SimPanel) -> AxisTicks {
    let (mut y0, mut y1) = (f64::MAX, f64::MIN);
    for &(t, y) in p.curves.iter().flat_map(|c| c.1.iter()) {
        if t.is_finite() && y.is_finite() {
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if y0 > y1 {
        return AxisTicks::new(-1.0, 1.0, MAX_TICKS);
    }
    let pad = 0.05 * (y1 - y0);
    AxisTicks::new(y0 - pad, y1 + pad, MAX_TICKS)
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    p: &SimPanel,
) -> Result<(), PlotError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::draw(e);
    let (chart_area, legend_area) = area.split_horizontally(WIDTH - LEGEND_WIDTH);
    let (t0, t1) = time_range(p);
    let x = AxisTicks::new(t0, t1, MAX_TICKS + 4);
    let y = y_axis(p);
    let x_fmt = |v: &f64| x.label(*v);
    let y_fmt = |v: &f64| y.label(*v);
    let mut chart = ChartBuilder::on(&chart_area)
        .caption(&p.caption, ("sans-serif", 14))
        .margin(6)
        .x_label_area_size(30)
        .y_label_area_size(72)
        .build_cartesian_2d(TickedRange::of(&x), TickedRange::of(&y))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x.title("t (s)"))
        .y_desc(y.title(&p.y_label))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 12))
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()
        .map_err(err)?;
    let mut legend = Vec::new();
    for (i, (name, c)) in p.curves.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        chart
            .draw_series(LineSeries::new(c.iter().copied(), color.stroke_width(2)))
            .map_err(err)?;
        legend.push(LegendEntry {
            name: name.clone(),
            color,
            dashed: false,
        });
    }
    if !p.curves.is_empty() {
        draw_legend(&legend_area, &legend, 36)?;
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    subtitle: &str,
    panels: &[SimPanel],
) -> Result<(), PlotError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::draw(e);
    root.fill(&WHITE).map_err(err)?;
    let (header, body) = root.split_vertically(HEADER_HEIGHT);
    draw_title(&header, title, subtitle)?;
    let areas = body.split_evenly((panels.len().max(1), 1));
    for (p, area) in panels.iter().zip(areas.iter()) {
        draw_panel(area, p)?;
    }
    Ok(())
}

/// Renders the panels under `title` (large) and `subtitle` and writes them atomically to
/// `path`.
pub fn write(
    path: &std::path::Path,
    title: &str,
    subtitle: &str,
    panels: &[SimPanel],
    format: PlotFormat,
) -> Result<(), String> {
    let bytes = render(title, subtitle, panels, format).map_err(|e| e.to_string())?;
    crate::core::files::write_atomic(path, &bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The panels under `title` (large) and `subtitle`, as bytes in `format`.
fn render(
    title: &str,
    subtitle: &str,
    panels: &[SimPanel],
    format: PlotFormat,
) -> Result<Vec<u8>, PlotError> {
    register_font();
    let size = (
        WIDTH,
        PANEL_HEIGHT * panels.len().max(1) as u32 + HEADER_HEIGHT,
    );
    let bytes = match format {
        PlotFormat::Png => {
            let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
                draw(&root, title, subtitle, panels)?;
                root.present().map_err(PlotError::draw)?;
            }
            encode_png(&buf, size)?
        }
        PlotFormat::Svg => {
            let mut s = String::new();
            {
                let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
                draw(&root, title, subtitle, panels)?;
                root.present().map_err(PlotError::draw)?;
            }
            s.into_bytes()
        }
    };
    Ok(bytes)
}
