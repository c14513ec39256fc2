//! The volume pass's hot loop: eight samples at a time are drawn
//! ([`QStream::next_lanes`]), placed by the batched FK of the tool origin
//! ([`crate::kinematics::fk_lanes::ToolChain::positions_lanes`]), located on the replicate's
//! three grids ([`Grid::locate_lanes`]) and marked (a bit on the common grid, a two-bit
//! saturating counter on the estimation grid and on the replicate's own grid,
//! [`Counts`]). No allocation per sample.
//!
//! The whole loop is one `#[inline(always)]` function compiled three times: for baseline
//! x86-64, and inside `#[target_feature]` entries for AVX2 + FMA and for AVX-512 (F, VL,
//! DQ), the entry chosen at run time from [`Isa::detected`] (at most
//! [`crate::workspace::WorkspaceOptions::max_isa`]); the binary stays baseline x86-64. Integer
//! arithmetic is exact and the floating-point operations are the same, in the same order,
//! without fused multiply-adds, on every instruction set: the samples, the positions, the
//! cells and therefore the estimate are bitwise the same on each.

use crate::core::spatial::Vec3;
use crate::kinematics::fk_lanes::{lanes_in_range, Isa, Lanes, LANES};
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::workspace::counts::Counts;
use crate::workspace::grid::Grid;
use crate::workspace::sample_stream::{QStream, RandomStream, SobolStream};
use crate::workspace::volume_context::{shifted_grid, Ctx};
use crate::workspace::workspace_options::Sampling;
use indicatif::ProgressBar;

/// Samples between progress-bar updates.
const PROGRESS_BLOCK: u64 = 1 << 16;

/// A replicate's stream (the Sobol' one, 5 KiB of direction numbers, boxed).
pub(super) enum Stream {
    Random(RandomStream),
    Sobol(Box<SobolStream>),
}

/// One replicate between stages.
pub(crate) struct Replicate {
    pub(super) stream: Stream,
    /// Samples drawn so far.
    pub(super) done: u64,
    pub marks: Marks,
}

impl Replicate {
    /// Replicate `r` of `ctx`, before its first sample.
    pub fn new(ctx: &Ctx, r: usize) -> Self {
        let d = ctx.model.nv;
        let stream = match ctx.sampling {
            Sampling::Random => Stream::Random(RandomStream::new(ctx.seed, r as u64, d, 0)),
            Sampling::Sobol => Stream::Sobol(Box::new(SobolStream::new(ctx.seed, r as u64, d, 0))),
        };
        let grid = shifted_grid(
            &ctx.grid,
            &ctx.center,
            ctx.radius,
            ctx.seed,
            r as u64,
            ctx.shift,
        );
        Replicate {
            stream,
            done: 0,
            marks: Marks::new(grid, &ctx.est, &ctx.grid),
        }
    }
}

/// What a replicate's samples leave: its marks on the three grids and the extent of its
/// tool points.
pub(crate) struct Marks {
    /// The replicate's own shifted grid and its hit counts.
    pub grid: Grid,
    pub counts: Counts,
    /// Its hits on the pooled estimation grid.
    pub est_counts: Counts,
    /// Its samples on the common grid.
    pub common_bits: Vec<u64>,
    /// Per lane, the smallest and largest coordinates so far (reduced by
    /// [`Self::bounds`]).
    lo: [Lanes; 3],
    hi: [Lanes; 3],
    /// Samples outside the common grid.
    pub outside: u64,
    /// Largest distance of a tool point to the plane (planar grids).
    pub max_off_plane: f64,
}

impl Marks {
    /// No marks on `grid` (the replicate's own), `est` and `common`.
    pub fn new(grid: Grid, est: &Grid, common: &Grid) -> Marks {
        Marks {
            counts: Counts::new(&grid),
            grid,
            est_counts: Counts::new(est),
            common_bits: common.empty(),
            lo: [[f64::INFINITY; LANES]; 3],
            hi: [[f64::NEG_INFINITY; LANES]; 3],
            outside: 0,
            max_off_plane: 0.0,
        }
    }

    /// The box of the tool points so far: smallest and largest coordinates.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let fold = |v: &Lanes, f: fn(f64, f64) -> f64, init: f64| v.iter().copied().fold(init, f);
        let lo = self.lo.each_ref().map(|v| fold(v, f64::min, f64::INFINITY));
        let hi = self
            .hi
            .each_ref()
            .map(|v| fold(v, f64::max, f64::NEG_INFINITY));
        (Vec3::from(lo), Vec3::from(hi))
    }

    /// Marks the tool points `p[axis][lane]` of lanes `0..n` (the spare lanes repeat
    /// lane `n − 1`, so they may join the box).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // the box: three lane arrays by axis and lane
    fn mark_lanes<const AVX2: bool>(&mut self, ctx: &Ctx, p: &[Lanes; 3], n: usize) {
        for a in 0..3 {
            for l in 0..LANES {
                self.lo[a][l] = self.lo[a][l].min(p[a][l]);
                self.hi[a][l] = self.hi[a][l].max(p[a][l]);
            }
        }
        let c = match ctx.grid.plane {
            None => *p,
            Some(_) => self.plane_coords(ctx, p),
        };
        // SAFETY: `AVX2` is set only in the entries compiled with AVX2 (see `advance`).
        let (common, est, own) = unsafe {
            (
                ctx.grid.locate_lanes_with::<AVX2>(&c),
                ctx.est.locate_lanes_with::<AVX2>(&c),
                self.grid.locate_lanes_with::<AVX2>(&c),
            )
        };
        for l in 0..n {
            match common[l] {
                u32::MAX => self.outside += 1,
                i => {
                    Grid::set(&mut self.common_bits, i as usize);
                }
            }
            if est[l] != u32::MAX {
                self.est_counts.hit(est[l] as usize);
            }
            if own[l] != u32::MAX {
                self.counts.hit(own[l] as usize);
            }
        }
    }

    /// In-plane coordinates of the points (planar grids), with the largest distance to
    /// the plane recorded: [`Grid::coords`] lane by lane.
    fn plane_coords(&mut self, ctx: &Ctx, p: &[Lanes; 3]) -> [Lanes; 3] {
        let mut c = [[0.0; LANES]; 3];
        for l in 0..LANES {
            let (cl, d) = ctx.grid.coords(&Vec3::new(p[0][l], p[1][l], p[2][l]));
            for a in 0..3 {
                c[a][l] = cl[a];
            }
            self.max_off_plane = self.max_off_plane.max(d.abs());
        }
        c
    }
}

/// Draws replicate `rep`'s samples until it has `to`, eight at a time, on the best
/// instruction set `ctx` allows.
pub(crate) fn advance(rep: &mut Replicate, ctx: &Ctx, to: u64, pb: &ProgressBar) {
    #[cfg(target_arch = "x86_64")]
    match ctx.isa {
        // SAFETY: `ctx.isa` is at most `Isa::detected()`: the CPU has the features.
        Isa::Avx512 => return unsafe { advance_avx512(rep, ctx, to, pb) },
        Isa::Avx2 => return unsafe { advance_avx2(rep, ctx, to, pb) },
        Isa::Baseline => {}
    }
    advance_lanes::<false>(rep, ctx, to, pb)
}

/// [`advance_lanes`] compiled for one instruction set (with the AVX2 intrinsics).
macro_rules! isa_entry_point {
    ($features:literal, $name:ident) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        unsafe fn $name(rep: &mut Replicate, ctx: &Ctx, to: u64, pb: &ProgressBar) {
            advance_lanes::<true>(rep, ctx, to, pb)
        }
    };
}

isa_entry_point!("avx2,fma", advance_avx2);
isa_entry_point!("avx2,fma,avx512f,avx512vl,avx512dq", advance_avx512);

/// The loop, for the replicate's kind of stream; `AVX2`: the CPU has AVX2 and the caller
/// is compiled for it.
#[inline(always)]
fn advance_lanes<const AVX2: bool>(rep: &mut Replicate, ctx: &Ctx, to: u64, pb: &ProgressBar) {
    let Replicate {
        stream,
        done,
        marks,
    } = rep;
    match stream {
        Stream::Random(s) => run::<_, AVX2>(s, done, marks, ctx, to, pb),
        Stream::Sobol(s) => run::<_, AVX2>(&mut **s, done, marks, ctx, to, pb),
    }
}

/// Draws, places and marks samples `done .. to` of `stream`.
#[inline(always)]
fn run<S: QStream, const AVX2: bool>(
    stream: &mut S,
    done: &mut u64,
    marks: &mut Marks,
    ctx: &Ctx,
    to: u64,
    pb: &ProgressBar,
) {
    let mut q = vec![[0.0; LANES]; ctx.model.nv];
    let mut out: [Lanes; 3] = [[0.0; LANES]; 3];
    let mut scalar: Option<ScalarFk> = None;
    let mut since = 0u64;
    while *done < to {
        let n = (to - *done).min(LANES as u64) as usize;
        // SAFETY: `AVX2` only in the entries compiled with AVX2 (see `advance`).
        unsafe { stream.next_lanes::<AVX2>(&ctx.jb, &mut q, n) };
        if ctx.batched && lanes_in_range(&q) {
            ctx.chain.positions_lanes(&q, &mut out);
        } else {
            scalar
                .get_or_insert_with(|| ScalarFk::new(ctx))
                .positions(ctx, &q, n, &mut out);
        }
        marks.mark_lanes::<AVX2>(ctx, &out, n);
        *done += n as u64;
        since += n as u64;
        if since >= PROGRESS_BLOCK {
            pb.inc(since);
            since = 0;
            if ctx.stopped() {
                break;
            }
        }
    }
    pb.inc(since);
}

/// The scalar FK, one configuration at a time (the reference the batched FK reproduces;
/// also for joint values beyond the batched `sin`/`cos` range).
struct ScalarFk {
    data: Data,
    row: Vec<f64>,
}

impl ScalarFk {
    fn new(ctx: &Ctx) -> ScalarFk {
        ScalarFk {
            data: Data::new(ctx.model),
            row: vec![0.0; ctx.model.nv],
        }
    }

    /// Tool positions of lanes `0..n` of `q`; the spare lanes repeat lane `n − 1`.
    #[inline(never)]
    fn positions(&mut self, ctx: &Ctx, q: &[Lanes], n: usize, out: &mut [Lanes; 3]) {
        for l in 0..n {
            for (v, lanes) in self.row.iter_mut().zip(q) {
                *v = lanes[l];
            }
            forward_kinematics(ctx.model, &mut self.data, &self.row);
            let p = frame_placement(ctx.model, &self.data, ctx.tool).trans;
            for a in 0..3 {
                out[a][l] = p[a];
            }
        }
        for o in out.iter_mut() {
            let last = o[n - 1];
            o[n..].fill(last);
        }
    }
}
