//! Time-series plots of an arm scenario's simulation (tracking error, spring vibration,
//! the contact box), one panel per series group, drawn with plotters like the torque
//! check's plot and written atomically.

use crate::trajectory::plot::{encode_png, register_font, PALETTE};
use crate::trajectory::PlotFormat;
use plotters::prelude::*;

/// One panel: a caption, a y label and named curves `(t, y)`.
pub struct Panel {
    pub caption: String,
    pub y_label: String,
    pub curves: Vec<(String, Vec<(f64, f64)>)>,
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    panels: &[Panel],
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("plot: {e}");
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 18)).map_err(err)?;
    let areas = root.split_evenly((panels.len().max(1), 1));
    for (p, area) in panels.iter().zip(areas.iter()) {
        let pts = p.curves.iter().flat_map(|c| c.1.iter());
        let (mut t0, mut t1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for &(t, y) in pts {
            if t.is_finite() && y.is_finite() {
                t0 = t0.min(t);
                t1 = t1.max(t);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
        if t0 > t1 {
            (t0, t1, y0, y1) = (0.0, 1.0, -1.0, 1.0);
        }
        let pad = 0.05 * (y1 - y0).abs().max(1e-12);
        let mut chart = ChartBuilder::on(area)
            .caption(&p.caption, ("sans-serif", 14))
            .margin(6)
            .x_label_area_size(28)
            .y_label_area_size(72)
            .build_cartesian_2d(t0..t1.max(t0 + 1e-9), (y0 - pad)..(y1 + pad))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc(p.y_label.as_str())
            .label_style(("sans-serif", 11))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(err)?;
        for (i, (name, c)) in p.curves.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            chart
                .draw_series(LineSeries::new(c.iter().copied(), color.stroke_width(2)))
                .map_err(err)?
                .label(name.as_str())
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 16, y)], color.stroke_width(2))
                });
        }
        if p.curves.len() > 1 {
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 11))
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(err)?;
        }
    }
    Ok(())
}

/// Renders the panels and writes them atomically to `path`.
pub fn write(
    path: &std::path::Path,
    title: &str,
    panels: &[Panel],
    format: PlotFormat,
) -> Result<(), String> {
    register_font();
    let size = (960u32, 240 * panels.len().max(1) as u32 + 40);
    let bytes = match format {
        PlotFormat::Png => {
            let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
                draw(&root, title, panels)?;
                root.present().map_err(|e| format!("plot: {e}"))?;
            }
            encode_png(&buf, size)?
        }
        PlotFormat::Svg => {
            let mut s = String::new();
            {
                let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
                draw(&root, title, panels)?;
                root.present().map_err(|e| format!("plot: {e}"))?;
            }
            s.into_bytes()
        }
    };
    crate::io::write_atomic(path, &bytes).map_err(|e| format!("{}: {e}", path.display()))
}
