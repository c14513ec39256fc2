//! Axis ticks a person can read: "nice" tick positions (1, 2 or 5 × 10^k apart) over a
//! data range, and their labels with one common power of ten chosen from the range.
//!
//! A tracking error of a few 1e-8 rad used to be labelled `0.0` at every tick; here its
//! ticks read `-20`, `0`, `20`, `40` and the axis title carries `×10⁻⁹`. The common power
//! is a multiple of 3 (engineering notation: the SI prefixes), used when the largest tick
//! is below 0.01 or at least 10 000 in magnitude; otherwise labels are plain decimals.
//! Every label has the same number of decimals, just enough to tell neighbouring ticks
//! apart. Pure functions, no drawing: the plots (`trajectory::plot`, `arm::plots`) pass
//! [`AxisTicks::values`] to plotters as the key points and [`AxisTicks::label`] as the
//! label formatter.

/// Ticks of one axis: the range drawn, the tick values and their labels.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisTicks {
    /// Lower end of the axis.
    pub lo: f64,
    /// Upper end of the axis.
    pub hi: f64,
    /// Tick positions, increasing, within `[lo, hi]` (to 1e-9 of a step).
    pub values: Vec<f64>,
    /// One label per tick, in units of `10^exponent`.
    pub labels: Vec<String>,
    /// Common power of ten of the labels (a multiple of 3; 0: plain numbers).
    pub exponent: i32,
    /// Decimals of every label.
    pub decimals: usize,
}

/// Largest tick magnitude shown without a common power of ten (exclusive).
const PLAIN_MAX: f64 = 1e4;
/// Smallest tick magnitude shown without a common power of ten.
const PLAIN_MIN: f64 = 1e-2;

impl AxisTicks {
    /// Ticks for an axis over `[lo, hi]`: at least 2 and at most `max_ticks` of them
    /// (`max_ticks` below 5 counts as 5, which guarantees the 2). A non-finite range becomes `[0,
    /// 1]`; an empty one (`lo == hi`) is widened by 10 % of `|lo|` on each side, or to `[-1, 1]`
    /// around zero; reversed ends are swapped.
    pub fn new(lo: f64, hi: f64, max_ticks: usize) -> Self {
        let (lo, hi) = usable_range(lo, hi);
        let max_ticks = max_ticks.max(5);
        let (step_mantissa, step_power) = nice_step(lo, hi, max_ticks);
        let step = step_mantissa as f64 * 10f64.powi(step_power);
        let (first, last) = tick_indices(lo, hi, step);
        let values: Vec<f64> = (first..=last).map(|i| i as f64 * step).collect();
        let biggest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let exponent = if biggest == 0.0 || (PLAIN_MIN..PLAIN_MAX).contains(&biggest) {
            0
        } else {
            3 * (biggest.log10().floor() as i32).div_euclid(3)
        };
        let decimals = usize::try_from(exponent - step_power).unwrap_or(0);
        let mut axis = AxisTicks {
            lo,
            hi,
            values,
            labels: Vec::new(),
            exponent,
            decimals,
        };
        axis.labels = axis.values.iter().map(|&v| axis.label(v)).collect();
        axis
    }

    /// The label of `v` in this axis's units (`v / 10^exponent` with the axis's decimals;
    /// never `-0`).
    pub fn label(&self, v: f64) -> String {
        let scaled = v / 10f64.powi(self.exponent);
        let s = format!("{:.*}", self.decimals, scaled);
        match s.strip_prefix('-') {
            Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
            _ => s,
        }
    }

    /// The factor the labels are in, for the axis title: `""` or e.g. `"×10⁻⁹"`.
    pub fn factor(&self) -> String {
        if self.exponent == 0 {
            String::new()
        } else {
            format!("×10{}", superscript(self.exponent))
        }
    }

    /// `title` with the factor appended (`"rad ×10⁻⁹"`), or `title` alone.
    pub fn title(&self, title: &str) -> String {
        match self.factor() {
            f if f.is_empty() => title.to_string(),
            f if title.is_empty() => f,
            f => format!("{title}  {f}"),
        }
    }
}

/// A finite, non-empty, ordered range from what the data gave.
fn usable_range(lo: f64, hi: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let span = hi - lo;
    let size = lo.abs().max(hi.abs());
    if span > size * 1e-12 && span > 0.0 {
        (lo, hi)
    } else if size > 0.0 {
        (lo - 0.1 * size, hi + 0.1 * size)
    } else {
        (-1.0, 1.0)
    }
}

/// The first and last multiples of `step` in `[lo, hi]` (ends within 1e-9 step count as
/// in, so that `-3e-8 / 1e-8 = -2.9999999999999996` still puts a tick at -3e-8).
fn tick_indices(lo: f64, hi: f64, step: f64) -> (i64, i64) {
    (
        (lo / step - 1e-9).ceil() as i64,
        (hi / step + 1e-9).floor() as i64,
    )
}

/// The smallest step `m × 10^p` (`m` in 1, 2, 5) that puts at most `max_ticks` ticks in
/// `[lo, hi]`, as `(m, p)`.
fn nice_step(lo: f64, hi: f64, max_ticks: usize) -> (i64, i32) {
    let span = hi - lo;
    let mut p = span.log10().floor() as i32 - 2;
    loop {
        for m in [1i64, 2, 5] {
            let step = m as f64 * 10f64.powi(p);
            let (first, last) = tick_indices(lo, hi, step);
            if last - first < max_ticks as i64 {
                return (m, p);
            }
        }
        p += 1;
    }
}

/// `n` in Unicode superscript digits (`-9` → `⁻⁹`).
fn superscript(n: i32) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::io::plots::ticks::*;

    /// Labels are distinct, there are 2..=max of them, and each reads back as its tick.
    fn assert_readable(a: &AxisTicks, max: usize) {
        let n = a.labels.len();
        assert!((2..=max).contains(&n), "{n} ticks: {a:?}");
        let mut seen = std::collections::HashSet::new();
        for (v, l) in a.values.iter().zip(&a.labels) {
            assert!(seen.insert(l.clone()), "duplicate label {l}: {a:?}");
            let back: f64 = l.parse::<f64>().unwrap() * 10f64.powi(a.exponent);
            let step = a.values[1] - a.values[0];
            assert!((back - v).abs() <= 1e-6 * step, "{l} for {v}: {a:?}");
            assert!(*v >= a.lo - 1e-9 * step && *v <= a.hi + 1e-9 * step);
        }
    }

    #[test]
    fn tracking_error_of_a_few_nanoradians_gets_distinct_labels() {
        let a = AxisTicks::new(-1.2e-8, 3.1e-8, 6);
        assert_eq!(a.exponent, -9);
        assert_eq!(a.labels, ["-10", "0", "10", "20", "30"]);
        assert_eq!(a.factor(), "×10⁻⁹");
        assert_eq!(a.title("rad or m"), "rad or m  ×10⁻⁹");
    }

    #[test]
    fn every_decade_from_1e_minus_9_to_1e3_reads_distinctly() {
        for k in -9..=3 {
            for c in [1.0, 1.7, 3.3, 7.0, 9.99] {
                let hi = c * 10f64.powi(k);
                for max in [5, 6, 10] {
                    assert_readable(&AxisTicks::new(0.0, hi, max), max);
                    assert_readable(&AxisTicks::new(-hi, 0.0, max), max);
                    assert_readable(&AxisTicks::new(-0.4 * hi, hi, max), max);
                    assert_readable(&AxisTicks::new(hi, 1.3 * hi, max), max);
                }
            }
        }
    }

    #[test]
    fn negative_ranges_keep_their_signs() {
        let a = AxisTicks::new(-5e-8, -1e-8, 5);
        assert_eq!(a.exponent, -9);
        assert_eq!(a.labels, ["-50", "-40", "-30", "-20", "-10"]);
        let b = AxisTicks::new(-250.0, -30.0, 6);
        assert_eq!(b.exponent, 0);
        assert_eq!(b.labels, ["-250", "-200", "-150", "-100", "-50"]);
    }

    #[test]
    fn zero_crossing_ranges_label_zero_without_a_sign() {
        let a = AxisTicks::new(-3e-8, 2e-8, 6);
        assert_eq!(a.labels, ["-30", "-20", "-10", "0", "10", "20"]);
        let b = AxisTicks::new(-0.33, 0.52, 6);
        assert_eq!(b.exponent, 0);
        assert_eq!(b.labels, ["-0.2", "0.0", "0.2", "0.4"]);
        let c = AxisTicks::new(-165.0, 165.0, 7);
        assert_eq!(c.labels, ["-150", "-100", "-50", "0", "50", "100", "150"]);
    }

    #[test]
    fn plain_and_scaled_boundaries() {
        assert_eq!(AxisTicks::new(0.0, 0.05, 6).exponent, 0);
        assert_eq!(AxisTicks::new(0.0, 0.05, 6).labels[1], "0.01");
        assert_eq!(AxisTicks::new(0.0, 0.004, 5).exponent, -3);
        assert_eq!(
            AxisTicks::new(0.0, 0.004, 5).labels,
            ["0", "1", "2", "3", "4"]
        );
        let big = AxisTicks::new(0.0, 3.0e5, 5);
        assert_eq!(big.exponent, 3);
        assert_eq!(big.labels, ["0", "100", "200", "300"]);
        assert_eq!(big.factor(), "×10³");
        // A tiny span on a large offset still tells its ticks apart.
        assert_readable(&AxisTicks::new(1000.0, 1000.00001, 6), 6);
    }

    #[test]
    fn degenerate_ranges_still_get_ticks() {
        let zero = AxisTicks::new(0.0, 0.0, 5);
        assert_eq!((zero.lo, zero.hi), (-1.0, 1.0));
        assert_readable(&zero, 5);
        let flat = AxisTicks::new(2.5e-7, 2.5e-7, 5);
        assert!(flat.lo < 2.5e-7 && flat.hi > 2.5e-7);
        assert_readable(&flat, 5);
        let nan = AxisTicks::new(f64::NAN, 1.0, 5);
        assert_eq!((nan.lo, nan.hi), (0.0, 1.0));
        let rev = AxisTicks::new(2.0, -2.0, 5);
        assert_eq!(rev.labels, ["-2", "-1", "0", "1", "2"]);
    }

    #[test]
    fn superscripts() {
        assert_eq!(superscript(-12), "⁻¹²");
        assert_eq!(superscript(3), "³");
        assert_eq!(superscript(0), "⁰");
    }
}
