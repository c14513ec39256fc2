//! Line panels and bar charts (plotters, PNG) for the trade-offs report and the machine
//! scenarios' pictures: line panels with optional log axes (drawn in log10 coordinates
//! with `10^k` tick labels) or equal axes, markers for failed points, and grouped bar
//! charts. Text uses the bundled font through the torque-check plot's setup
//! ([`crate::io::plots::torque_chart`]), so no system font is needed.

use crate::io::plots::plot_error::PlotError;
/// The report's colours: armsim's chart palette.
pub use crate::io::plots::torque_chart::PALETTE;
use crate::io::plots::torque_chart::{encode_png, register_font};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One line of a panel.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points `(x, y)` in data units (non-positive values are dropped on log axes).
    pub points: Vec<(f64, f64)>,
    /// Colour.
    pub color: RGBColor,
    /// Dashed line (e.g. a reported error next to a measured one).
    pub dashed: bool,
}

/// A point drawn as a cross at the top edge of a panel (e.g. a diverged run).
#[derive(Clone, Debug)]
pub struct Flag {
    /// Abscissa in data units.
    pub x: f64,
    /// Colour (the series it belongs to).
    pub color: RGBColor,
    /// Row of crosses (one per series, so that coinciding crosses stay visible).
    pub lane: usize,
}

/// One chart.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// Caption.
    pub title: String,
    /// Axis labels.
    pub x_desc: String,
    /// Axis labels.
    pub y_desc: String,
    /// Logarithmic abscissa.
    pub log_x: bool,
    /// Logarithmic ordinate.
    pub log_y: bool,
    /// Lines.
    pub series: Vec<Series>,
    /// Crosses at the top edge, explained by `flag_label` in the legend.
    pub flags: Vec<Flag>,
    /// Legend entry of the crosses.
    pub flag_label: String,
    /// Fixed ordinate range in data units.
    pub y_range: Option<(f64, f64)>,
    /// Where the legend goes (default upper left).
    pub legend: Legend,
    /// Empty space added above the data, as a fraction of its range (room for the
    /// legend).
    pub headroom: f64,
    /// Draw earlier solid lines wider, so that coinciding lines stay visible (a coloured
    /// core inside a coloured rim).
    pub layered: bool,
    /// One data unit is as long on both axes (shapes: profiles, gears, centrodes); the
    /// shorter range is widened about its middle. Linear axes only.
    pub equal_aspect: bool,
}

/// Legend corner.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Legend {
    /// Upper left.
    #[default]
    UpperLeft,
    /// Upper right.
    UpperRight,
    /// Lower left.
    LowerLeft,
    /// Lower right.
    LowerRight,
    /// Middle of the right edge.
    MiddleRight,
}

fn tf(log: bool, v: f64) -> Option<f64> {
    if log {
        (v > 0.0 && v.is_finite()).then(|| v.log10())
    } else {
        v.is_finite().then_some(v)
    }
}

/// A chart axis over `[lo, hi]` in drawing units: data units on a linear axis, `log10` of
/// the data on a logarithmic one. Its ticks sit at round values of the data (1, 2, 5 × 10^k
/// on a log axis, or only the decades when it spans three or more) and are labelled in
/// data units.
#[derive(Clone, Copy, Debug)]
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

/// Tick label of the data value `x`: `1e-6` style outside `[lo, 1e4)`, else up to three
/// decimals.
fn label(x: f64, lo: f64) -> String {
    let a = x.abs();
    if a != 0.0 && !(lo..1e4).contains(&a) {
        let s = format!("{x:.0e}");
        // Keep a second digit when the rounding would change the value (2.5e-3).
        if ((s.parse::<f64>().unwrap_or(x) - x) / x).abs() > 1e-6 {
            format!("{x:.1e}")
        } else {
            s
        }
    } else {
        let s = format!("{x:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.to_string()
        }
    }
}

impl Axis {
    /// Round data values inside the axis, at most about `max` of them.
    fn ticks(&self, max: usize) -> Vec<f64> {
        let max = max.max(2);
        if !self.log {
            let raw = (self.hi - self.lo) / max as f64;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0]
                .iter()
                .map(|m| m * mag)
                .find(|s| *s >= raw)
                .unwrap_or(10.0 * mag);
            let mut v = (self.lo / step).ceil() * step;
            let mut out = Vec::new();
            while v <= self.hi + 1e-9 * step {
                out.push(if v.abs() < 1e-12 * step { 0.0 } else { v });
                v += step;
            }
            return out;
        }
        let (k0, k1) = (self.lo.floor() as i32, self.hi.ceil() as i32);
        let inside = |v: f64| v >= self.lo - 1e-9 && v <= self.hi + 1e-9;
        for mantissas in [&[1.0, 2.0, 5.0][..], &[1.0, 2.0, 3.0, 5.0, 7.0][..]] {
            let span = self.hi - self.lo;
            if span >= 3.0 && mantissas.len() > 1 {
                break;
            }
            let pts: Vec<f64> = (k0..=k1)
                .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
                .filter(|v| inside(v.log10()))
                .collect();
            if pts.len() >= 3 && pts.len() <= max {
                return pts;
            }
        }
        if self.hi - self.lo < 1.0 {
            // Less than a decade: round values of the data, linearly spaced.
            let lin = Axis {
                lo: 10f64.powf(self.lo),
                hi: 10f64.powf(self.hi),
                log: false,
            };
            return lin
                .ticks(max.min(6))
                .into_iter()
                .filter(|v| *v > 0.0)
                .collect();
        }
        // Decades, thinned to at most `max`.
        let decades: Vec<i32> = (k0..=k1).filter(|k| inside(f64::from(*k))).collect();
        let stride = decades.len().div_ceil(max).max(1);
        decades
            .iter()
            .filter(|k| ((*k - decades[0]) as usize).is_multiple_of(stride))
            .map(|k| 10f64.powi(*k))
            .collect()
    }
}

impl plotters::coord::ranged1d::Ranged for Axis {
    type FormatOption = plotters::coord::ranged1d::NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let t = (v - self.lo) / (self.hi - self.lo);
        limit.0 + (t * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let n = hint.max_num_points();
        if n == 0 {
            return Vec::new();
        }
        let t = self.ticks(n);
        if self.log {
            t.iter().map(|v| v.log10()).collect()
        } else {
            t
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

impl plotters::coord::ranged1d::ValueFormatter<f64> for Axis {
    fn format_ext(&self, v: &f64) -> String {
        if self.log && (v - v.round()).abs() < 1e-9 && *v < -0.5 {
            // Decades below 1 as 1e-k, like the rest of the axis.
            return format!("1e{}", v.round() as i64);
        }
        // Log axes switch to exponents below 0.1, so that 2e-2 sits next to 1e-2.
        if self.log {
            label(10f64.powf(*v), 0.1)
        } else {
            label(*v, 1e-2)
        }
    }
}

/// Padded range of `vals`; a degenerate range is widened.
fn range(vals: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-12 {
        return (lo - 0.5, hi + 0.5);
    }
    let p = pad * (hi - lo);
    (lo - p, hi + p)
}

/// A panel's axis ranges, and where the rows of flag crosses sit above the data.
struct Bounds {
    x: (f64, f64),
    y: (f64, f64),
    flag_base: f64,
    flag_step: f64,
}

/// The axis ranges of panel `p` drawn on `pixels` (width, height): the data padded (or
/// the given y range), equal scales when asked, the headroom, and room for the flags.
fn bounds(pixels: (u32, u32), p: &Panel) -> Bounds {
    let xs = p
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(|q| q.0))
        .chain(p.flags.iter().map(|f| f.x))
        .filter_map(|x| tf(p.log_x, x));
    let (mut x0, mut x1) = range(xs, 0.04);
    let (mut y0, mut y1) = match p.y_range {
        Some((a, b)) => (tf(p.log_y, a).unwrap_or(0.0), tf(p.log_y, b).unwrap_or(1.0)),
        None => range(
            p.series
                .iter()
                .flat_map(|s| s.points.iter().filter_map(|q| tf(p.log_y, q.1))),
            0.06,
        ),
    };
    if p.equal_aspect && !p.log_x && !p.log_y {
        // The plotting area: the panel less margins, label areas and caption.
        let (w, h) = pixels;
        let pw = (w as f64 - 20.0 - 70.0).max(1.0);
        let ph = (h as f64 - 20.0 - 40.0 - 26.0).max(1.0);
        let (sx, sy) = ((x1 - x0) / pw, (y1 - y0) / ph);
        if sx > sy {
            let (c, half) = ((y0 + y1) / 2.0, sx * ph / 2.0);
            (y0, y1) = (c - half, c + half);
        } else {
            let (c, half) = ((x0 + x1) / 2.0, sy * pw / 2.0);
            (x0, x1) = (c - half, c + half);
        }
    }
    y1 += p.headroom * (y1 - y0);
    // Room for the rows of crosses above the data.
    let lanes = p.flags.iter().map(|f| f.lane + 1).max().unwrap_or(0);
    let (base, step) = (y1 + 0.04 * (y1 - y0), 0.05 * (y1 - y0));
    if lanes > 0 {
        y1 += (0.06 + 0.05 * lanes as f64) * (y1 - y0);
    }
    Bounds {
        x: (x0, x1),
        y: (y0, y1),
        flag_base: base,
        flag_step: step,
    }
}

/// A series' points on the panel's (possibly logarithmic) axes; points a log axis
/// cannot show are left out.
fn plotted_points(p: &Panel, s: &Series) -> Vec<(f64, f64)> {
    s.points
        .iter()
        .filter_map(|&(x, y)| Some((tf(p.log_x, x)?, tf(p.log_y, y)?)))
        .collect()
}

/// The flags as crosses in rows above the data (row `lane` at `base + step · lane`).
fn flag_crosses(p: &Panel, base: f64, step: f64) -> Vec<Cross<(f64, f64), i32>> {
    p.flags
        .iter()
        .filter_map(|f| {
            let y = base + step * f.lane as f64;
            Some(Cross::new(
                (tf(p.log_x, f.x)?, y),
                6,
                f.color.stroke_width(2),
            ))
        })
        .collect()
}

fn legend_position(legend: Legend) -> SeriesLabelPosition {
    match legend {
        Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
        Legend::UpperRight => SeriesLabelPosition::UpperRight,
        Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
        Legend::LowerRight => SeriesLabelPosition::LowerRight,
        Legend::MiddleRight => SeriesLabelPosition::MiddleRight,
    }
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
) -> Result<(), PlotError> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotError::draw(e);
    let Bounds {
        x: (x0, x1),
        y: (y0, y1),
        flag_base: base,
        flag_step: step,
    } = bounds(area.dim_in_pixel(), p);
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(
            Axis {
                lo: x0,
                hi: x1,
                log: p.log_x,
            },
            Axis {
                lo: y0,
                hi: y1,
                log: p.log_y,
            },
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(&p.x_desc)
        .y_desc(&p.y_desc)
        .x_labels(10)
        .y_labels(10)
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 13))
        .light_line_style(RGBColor(238, 238, 238))
        .draw()
        .map_err(err)?;
    // With `layered`, solid lines are drawn wider first and narrower later.
    let solid = p.series.iter().filter(|s| !s.dashed).count();
    let mut solid_seen = 0;
    for s in &p.series {
        let width = if s.dashed || !p.layered {
            2
        } else {
            solid_seen += 1;
            2 + 2 * (solid - solid_seen) as u32
        };
        let pts = plotted_points(p, s);
        if pts.is_empty() {
            continue;
        }
        let style = s.color.stroke_width(width);
        let color = s.color;
        let anno = if s.dashed {
            chart
                .draw_series(DashedLineSeries::new(pts.clone(), 7, 5, style))
                .map_err(err)?
        } else {
            chart
                .draw_series(LineSeries::new(pts.clone(), style))
                .map_err(err)?
        };
        let dashed = s.dashed;
        anno.label(&s.label).legend(move |(x, y)| {
            if dashed {
                PathElement::new(vec![(x, y), (x + 8, y)], color.stroke_width(2))
            } else {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            }
        });
        let marker = if s.dashed { 2 } else { 3 };
        chart
            .draw_series(pts.iter().map(|&q| Circle::new(q, marker, color.filled())))
            .map_err(err)?;
    }
    if !p.flags.is_empty() {
        let crosses = flag_crosses(p, base, step);
        chart
            .draw_series(crosses)
            .map_err(err)?
            .label(&p.flag_label)
            .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(legend_position(p.legend))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Renders `panels` in a grid of `cols` columns, each `panel_size` pixels, under `title`,
/// as PNG bytes.
pub fn render_panels(
    title: &str,
    panels: &[Panel],
    cols: usize,
    panel_size: (u32, u32),
) -> Result<Vec<u8>, PlotError> {
    register_font();
    let cols = cols.clamp(1, panels.len().max(1));
    let rows = panels.len().div_ceil(cols).max(1);
    let size = (panel_size.0 * cols as u32, panel_size.1 * rows as u32 + 40);
    let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| PlotError::draw(e);
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
        for (area, p) in root.split_evenly((rows, cols)).iter().zip(panels) {
            draw_panel(area, p)?;
        }
        root.present().map_err(err)?;
    }
    encode_png(&buf, size)
}

/// One group of bars (one colour): a value per category.
#[derive(Clone, Debug)]
pub struct BarGroup {
    /// Legend label.
    pub label: String,
    /// Value per category.
    pub values: Vec<f64>,
    /// Colour.
    pub color: RGBColor,
}

/// A grouped bar chart of `groups` over `categories` (linear ordinate from 0), with an
/// optional dashed reference line, as PNG bytes. Each bar is labelled with its value
/// formatted by `fmt`.
pub fn render_bars(
    title: &str,
    y_desc: &str,
    categories: &[String],
    groups: &[BarGroup],
    reference: Option<f64>,
    fmt: &dyn Fn(f64) -> String,
    size: (u32, u32),
) -> Result<Vec<u8>, PlotError> {
    register_font();
    let mut buf = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| PlotError::draw(e);
        root.fill(&WHITE).map_err(err)?;
        let n = categories.len().max(1);
        let top = groups
            .iter()
            .flat_map(|g| g.values.iter().copied())
            .chain(reference)
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max)
            .max(1e-12)
            * 1.18;
        let names = |x: &f64| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < n {
                categories[i as usize].clone()
            } else {
                String::new()
            }
        };
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), 0.0..top)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n)
            .x_label_formatter(&names)
            .y_desc(y_desc)
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 13))
            .light_line_style(RGBColor(238, 238, 238))
            .draw()
            .map_err(err)?;
        let width = 0.8 / groups.len().max(1) as f64;
        for (gi, g) in groups.iter().enumerate() {
            let color = g.color;
            let bars: Vec<_> = g
                .values
                .iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .map(|(i, &v)| {
                    let x0 = i as f64 - 0.4 + gi as f64 * width;
                    Rectangle::new([(x0, 0.0), (x0 + width * 0.92, v)], color.filled())
                })
                .collect();
            chart
                .draw_series(bars)
                .map_err(err)?
                .label(&g.label)
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 14, y + 5)], color.filled())
                });
            let labels: Vec<_> = g
                .values
                .iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .map(|(i, &v)| {
                    let x0 = i as f64 - 0.4 + gi as f64 * width;
                    Text::new(fmt(v), (x0, v + 0.015 * top), ("sans-serif", 11))
                })
                .collect();
            chart.draw_series(labels).map_err(err)?;
        }
        if let Some(r) = reference {
            chart
                .draw_series(DashedLineSeries::new(
                    [(-0.5, r), (n as f64 - 0.5, r)],
                    7,
                    5,
                    BLACK.stroke_width(1),
                ))
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    encode_png(&buf, size)
}
