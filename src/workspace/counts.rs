//! Saturating hit counters for the volume pass's hot loop: two bits per cell (0, 1, 2,
//! 3 or more hits), 32 cells per word, so that a hit reads and writes one word (one cache
//! line) and a grid's counters take two bits per cell instead of the three bitsets of the
//! thermometer code [`Hits`] that the estimator reads. [`Counts::hits`] converts between
//! the two after each doubling.

use crate::workspace::grid::{Grid, Hits};

/// Two-bit saturating hit counts over the cells of a grid (cell `i` in bits
/// `2 (i mod 32) …` of word `i / 32`).
#[derive(Clone, Debug)]
pub(crate) struct Counts {
    words: Vec<u64>,
}

/// The even bits of `x` packed into the low 32 bits (bit `2k` → bit `k`).
#[inline(always)]
fn even_bits(x: u64) -> u64 {
    let mut x = x & 0x5555_5555_5555_5555;
    x = (x | (x >> 1)) & 0x3333_3333_3333_3333;
    x = (x | (x >> 2)) & 0x0F0F_0F0F_0F0F_0F0F;
    x = (x | (x >> 4)) & 0x00FF_00FF_00FF_00FF;
    x = (x | (x >> 8)) & 0x0000_FFFF_0000_FFFF;
    (x | (x >> 16)) & 0x0000_0000_FFFF_FFFF
}

impl Counts {
    /// No hits on `grid`.
    pub fn new(grid: &Grid) -> Counts {
        Counts {
            words: vec![0; 2 * grid.words()],
        }
    }

    /// One more hit in cell `i` (saturating at 3).
    #[inline(always)]
    pub fn hit(&mut self, i: usize) {
        let w = &mut self.words[i >> 5];
        let sh = (i & 31) << 1;
        let v = (*w >> sh) & 3;
        *w += u64::from(v != 3) << sh;
    }

    /// The thermometer code of the counts (cells hit at least once, twice, three times).
    pub fn hits(&self) -> Hits {
        let n = self.words.len() / 2;
        let mut at_least = [vec![0u64; n], vec![0u64; n], vec![0u64; n]];
        for (w, pair) in self.words.chunks_exact(2).enumerate() {
            // Per counter: low bit `a`, high bit `b`; ≥ 1 is a | b, ≥ 2 is b, 3 is a & b.
            let planes = |x: u64| {
                let (a, b) = (x, x >> 1);
                [even_bits(a | b), even_bits(b), even_bits(a & b)]
            };
            let lo = planes(pair[0]);
            let hi = planes(pair[1]);
            for k in 0..3 {
                at_least[k][w] = lo[k] | (hi[k] << 32);
            }
        }
        Hits { at_least }
    }
}

#[cfg(test)]
mod tests {
    use crate::core::spatial::Vec3;
    use crate::workspace::counts::*;

    /// Counts and the thermometer code agree with `Hits::hit`, cell by cell, across the
    /// halves of a word and across words.
    #[test]
    fn counts_give_the_thermometer_code_of_hits() {
        let g = Grid::new(1.0, &Vec3::zeros(), 4.0, None, [0.0; 3]).expect("small");
        let mut c = Counts::new(&g);
        let mut h = Hits::new(&g);
        // Cell i hit (i * 7) % 5 times: 0 to 4, so saturation is exercised.
        let cells = [0usize, 1, 31, 32, 33, 63, 64, 95, 127, 500, 777];
        for (n, &i) in cells.iter().enumerate() {
            for _ in 0..(n * 7) % 5 {
                c.hit(i);
                h.hit(i);
            }
        }
        let got = c.hits();
        for k in 0..3 {
            assert_eq!(got.at_least[k], h.at_least[k], "level {k}");
        }
        assert_eq!(got.singles_doubles(), h.singles_doubles());
        assert!(crate::workspace::grid::count_bits(&got.at_least[2]) >= 2);
    }
}
