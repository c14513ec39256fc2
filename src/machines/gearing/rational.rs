//! Exact rational numbers (`i128 / i128`, always reduced, positive denominator) and the
//! exact null space of a rational matrix: gear-train ratios are ratios of tooth-count
//! products, and high-ratio differentials cancel nearly equal terms (`2/(−69/68 + 68/67)
//! = 9112`), so the speeds are solved without rounding. Every operation is checked: an
//! overflow is an error, never a wrong answer.

use std::fmt;

/// A reduced fraction `num / den` with `den > 0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Ratio {
    num: i128,
    den: i128,
}

/// The numbers grew beyond 128 bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("exact arithmetic overflowed 128-bit integers (tooth-count products too large)")]
pub struct Overflow;

fn gcd(mut a: i128, mut b: i128) -> i128 {
    a = a.abs();
    b = b.abs();
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

impl Ratio {
    /// Zero.
    pub const ZERO: Ratio = Ratio { num: 0, den: 1 };
    /// One.
    pub const ONE: Ratio = Ratio { num: 1, den: 1 };

    /// `n / d`, reduced; `None` when `d = 0`.
    pub fn new(n: i128, d: i128) -> Option<Ratio> {
        if d == 0 {
            return None;
        }
        let g = gcd(n, d).max(1);
        let s = if d < 0 { -1 } else { 1 };
        Some(Ratio {
            num: s * n / g,
            den: s * d / g,
        })
    }

    /// The integer `n`.
    pub fn int(n: i128) -> Ratio {
        Ratio { num: n, den: 1 }
    }

    /// Numerator (sign carrier).
    pub fn numer(self) -> i128 {
        self.num
    }

    /// Denominator (> 0).
    pub fn denom(self) -> i128 {
        self.den
    }

    /// Whether this is zero.
    pub fn is_zero(self) -> bool {
        self.num == 0
    }

    /// The nearest `f64`.
    pub fn to_f64(self) -> f64 {
        self.num as f64 / self.den as f64
    }

    /// `self + o`.
    pub fn plus(self, o: Ratio) -> Result<Ratio, Overflow> {
        let g = gcd(self.den, o.den).max(1);
        let a = self.num.checked_mul(o.den / g).ok_or(Overflow)?;
        let b = o.num.checked_mul(self.den / g).ok_or(Overflow)?;
        let d = (self.den / g).checked_mul(o.den).ok_or(Overflow)?;
        Ratio::new(a.checked_add(b).ok_or(Overflow)?, d).ok_or(Overflow)
    }

    /// `self − o`.
    pub fn minus(self, o: Ratio) -> Result<Ratio, Overflow> {
        self.plus(o.negated())
    }

    /// `−self`.
    pub fn negated(self) -> Ratio {
        Ratio {
            num: -self.num,
            den: self.den,
        }
    }

    /// `self × o`.
    pub fn times(self, o: Ratio) -> Result<Ratio, Overflow> {
        let g1 = gcd(self.num, o.den).max(1);
        let g2 = gcd(o.num, self.den).max(1);
        let n = (self.num / g1).checked_mul(o.num / g2).ok_or(Overflow)?;
        let d = (self.den / g2).checked_mul(o.den / g1).ok_or(Overflow)?;
        Ratio::new(n, d).ok_or(Overflow)
    }

    /// `self / o`; `None` when `o = 0`.
    pub fn over(self, o: Ratio) -> Result<Option<Ratio>, Overflow> {
        if o.is_zero() {
            return Ok(None);
        }
        self.times(Ratio {
            num: o.den * o.num.signum(),
            den: o.num.abs(),
        })
        .map(Some)
    }
}

impl fmt::Display for Ratio {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

/// A basis of the null space of `rows` (each `ncols` long) by exact Gauss–Jordan
/// elimination: one vector per free column, with a 1 in that column. Also returns the
/// rank.
pub fn null_space(rows: &[Vec<Ratio>], ncols: usize) -> Result<(Vec<Vec<Ratio>>, usize), Overflow> {
    let mut m: Vec<Vec<Ratio>> = rows.to_vec();
    let mut pivots: Vec<usize> = Vec::new();
    let mut r = 0;
    for c in 0..ncols {
        let Some(p) = (r..m.len()).find(|&i| !m[i][c].is_zero()) else {
            continue;
        };
        m.swap(r, p);
        let inv = Ratio::ONE.over(m[r][c])?.ok_or(Overflow)?;
        for x in m[r].iter_mut() {
            *x = x.times(inv)?;
        }
        let pivot = m[r].clone();
        for (i, row) in m.iter_mut().enumerate() {
            if i != r && !row[c].is_zero() {
                let f = row[c];
                for (x, p) in row.iter_mut().zip(&pivot) {
                    *x = x.minus(f.times(*p)?)?;
                }
            }
        }
        pivots.push(c);
        r += 1;
        if r == m.len() {
            break;
        }
    }
    let mut basis = Vec::new();
    for free in (0..ncols).filter(|c| !pivots.contains(c)) {
        let mut v = vec![Ratio::ZERO; ncols];
        v[free] = Ratio::ONE;
        for (row, &pc) in pivots.iter().enumerate() {
            v[pc] = m[row][free].negated();
        }
        basis.push(v);
    }
    Ok((basis, pivots.len()))
}

/// Solves the square system `a x = b` exactly; `None` when `a` is singular.
pub fn solve(a: &[Vec<Ratio>], b: &[Ratio]) -> Result<Option<Vec<Ratio>>, Overflow> {
    let n = b.len();
    let mut m: Vec<Vec<Ratio>> = a
        .iter()
        .zip(b)
        .map(|(row, &bi)| {
            let mut r = row.clone();
            r.push(bi);
            r
        })
        .collect();
    for c in 0..n {
        let Some(p) = (c..n).find(|&i| !m[i][c].is_zero()) else {
            return Ok(None);
        };
        m.swap(c, p);
        let inv = Ratio::ONE.over(m[c][c])?.ok_or(Overflow)?;
        for x in m[c][c..].iter_mut() {
            *x = x.times(inv)?;
        }
        let pivot = m[c].clone();
        for (i, row) in m.iter_mut().enumerate() {
            if i != c && !row[c].is_zero() {
                let f = row[c];
                for (x, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                    *x = x.minus(f.times(*p)?)?;
                }
            }
        }
    }
    Ok(Some(m.into_iter().map(|r| r[n]).collect()))
}
