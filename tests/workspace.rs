//! Workspace sampling against closed forms: the planar 2R disc and annulus areas, the
//! spherical R-R-P shell volume, the 2R's manipulability and condition number per pixel,
//! the Sobol' sequence against SciPy's, Owen scrambling's net property, the error bars'
//! 1/√N law, Sobol' against random at equal N, determinism across seeds and thread
//! counts, and the CSV output. Sized for `cargo test --release` (what CI runs).

mod common;

use armsim::core::spatial::Vec3;
use armsim::kinematics;
use armsim::model::data::Data;
use armsim::model::parse::dh_table as dh;
use armsim::model::{chain, Model};
use armsim::workspace::sobol::{owen_scramble, Sobol};
use armsim::workspace::{
    sample_workspace, IntervalKind, Sampling, WorkspaceOptions, WorkspaceResult,
};
use nalgebra::Matrix2;
use std::f64::consts::PI;

fn planar_2r() -> Model {
    common::load("robots/planar_2r.toml")
}

/// The planar 2R of `robots/planar_2r.toml` with link lengths `l1`, `l2`.
fn planar_2r_lengths(l1: f64, l2: f64) -> Model {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/planar_2r.toml");
    let text = std::fs::read_to_string(path).expect("readable");
    let text = text.replacen("a = 0.5", &format!("a = {l1}"), 1).replacen(
        "a = 0.5",
        &format!("a = {l2}"),
        1,
    );
    Model::build(dh::parse(&text, "planar_2r_lengths.toml").expect("parses"))
        .expect("builds")
        .0
}

fn opts(samples: u64, replicates: usize, sampling: Sampling, voxel: f64) -> WorkspaceOptions {
    WorkspaceOptions {
        samples,
        replicates,
        sampling,
        voxel,
        extras: false,
        quiet: true,
        ..Default::default()
    }
}

/// Prints the figures and checks that the reported 95 % interval is two-sided, contains
/// `truth`, holds the headline, and is no wider than `max_rel` of the truth either side
/// (so that a ballooning interval fails).
fn assert_within_uncertainty(r: &WorkspaceResult, truth: f64, max_rel: f64, what: &str) {
    let e = &r.estimate;
    eprintln!(
        "{what} [{:?}, {} × {}, h = {}]: headline {:.5} (err {:+.5}), interval {:?}, corrected {:.5}, \
         richardson {:.5}, remaining ≤ {:?}, spread {:.5}, pooled raw {:.5}, first-order bias {:.5}",
        r.sampling,
        r.replicates,
        r.samples_per_replicate,
        r.voxel,
        r.measure(),
        r.measure() - truth,
        e.interval,
        e.corrected,
        e.richardson,
        e.remaining,
        e.stderr,
        e.raw,
        e.voxel_bias
    );
    assert_eq!(r.interval_kind, IntervalKind::Interval, "{what}: two-sided");
    let [Some(lo), Some(hi)] = r.measure_interval() else {
        panic!("{what}: two-sided interval expected");
    };
    assert!(
        lo <= truth && truth <= hi,
        "{what}: truth {truth} outside the reported interval [{lo}, {hi}]"
    );
    assert!(lo <= r.measure() && r.measure() <= hi);
    assert!(
        e.rel_half_width() <= max_rel,
        "{what}: the interval's half-width {} is wider than {} % of the estimate",
        e.rel_half_width(),
        100.0 * max_rel
    );
    assert_eq!(r.bias.interval, [lo, hi]);
}

// ---------------------------------------------------------------------------------------
// Sobol' sequence and scrambling.

/// Points of SciPy 1.17 `qmc.Sobol(d, scramble=False, bits=32)` (Joe–Kuo
/// `new-joe-kuo-6.21201`) times 2³²: an independent implementation of the same table.
#[test]
fn sobol_matches_scipy() {
    let first10: [(u64, [u32; 10]); 6] = [
        (
            2,
            [
                3221225472, 1073741824, 1073741824, 1073741824, 3221225472, 3221225472, 1073741824,
                3221225472, 3221225472, 3221225472,
            ],
        ),
        (
            5,
            [
                3758096384, 3758096384, 536870912, 1610612736, 3758096384, 2684354560, 3758096384,
                1610612736, 1610612736, 536870912,
            ],
        ),
        (
            13,
            [
                3489660928, 2952790016, 3489660928, 268435456, 1879048192, 4026531840, 2415919104,
                2415919104, 2415919104, 1879048192,
            ],
        ),
        (
            100,
            [
                1778384896, 1107296256, 3321888768, 3120562176, 3791650816, 3187671040, 100663296,
                2046820352, 2717908992, 2986344448,
            ],
        ),
        (
            511,
            [
                8388608, 2155872256, 1753219072, 3632267264, 1518338048, 3766484992, 3196059648,
                1988100096, 947912704, 864026624,
            ],
        ),
        (
            1023,
            [
                4194304, 3233808384, 2629828608, 624951296, 801112064, 1883242496, 599785472,
                2654994432, 1480589312, 3653238784,
            ],
        ),
    ];
    let mut seq = Sobol::new(10, 0);
    let mut out = [0u32; 10];
    let mut seen = Vec::new();
    for i in 0..1024u64 {
        seq.next_u32(&mut out);
        if let Some((_, want)) = first10.iter().find(|(k, _)| *k == i) {
            assert_eq!(&out, want, "point {i}");
            seen.push(i);
        }
    }
    assert_eq!(seen.len(), first10.len());
    // All 31 dimensions, deep into the sequence, started directly at the index.
    let deep: [(u64, [u32; 31]); 2] = [
        (
            123456,
            [
                113803264, 784891904, 1319665664, 1934065664, 726630400, 872972288, 3074457600,
                1993113600, 3034218496, 1069711360, 2143649792, 3355148288, 2370732032, 1204518912,
                3278536704, 2840559616, 2453766144, 1596227584, 3788210176, 674988032, 507215872,
                2589556736, 2003468288, 2134409216, 3200286720, 2252505088, 3701637120, 1927512064,
                3150020608, 1396932608, 2896199680,
            ],
        ),
        (
            1048575,
            [
                4096, 4026593280, 3314585600, 1977167872, 3719483392, 3405787136, 1416089600,
                3816001536, 3178434560, 1778348032, 3254300672, 3192164352, 1278513152, 155856896,
                3318927360, 1001721856, 856436736, 2484047872, 875622400, 2097213440, 97579008,
                1118973952, 385191936, 1318989824, 380686336, 1409519616, 3255291904, 3224645632,
                155676672, 3704524800, 3864023040,
            ],
        ),
    ];
    for (i, want) in deep {
        let mut out = [0u32; 31];
        Sobol::new(31, i).next_u32(&mut out);
        assert_eq!(out, want, "point {i}");
    }
    // Starting anywhere continues the same sequence.
    let mut a = Sobol::new(7, 0);
    let mut b = Sobol::new(7, 1000);
    let (mut x, mut y) = ([0u32; 7], [0u32; 7]);
    for _ in 0..1000 {
        a.next_u32(&mut x);
    }
    for _ in 0..100 {
        a.next_u32(&mut x);
        b.next_u32(&mut y);
        assert_eq!(x, y);
    }
}

/// Owen scrambling keeps the first two dimensions a (0, m, 2)-net — every elementary
/// box `2^-a × 2^-(m-a)` holds exactly one of the first 2^m points — changes the points,
/// and gives an unbiased randomised-QMC integral whose spread is far below Monte Carlo's.
#[test]
fn owen_scrambling_keeps_the_net_and_is_unbiased() {
    let m = 10u32;
    let n = 1usize << m;
    for seeds in [[0u32, 0], [12345, 678], [0xdead_beef, 0x0bad_cafe]] {
        let mut s = Sobol::scrambled(&seeds, 0);
        let mut pts = vec![[0u32; 2]; n];
        for p in pts.iter_mut() {
            s.next_u32(p);
        }
        for a in 0..=m {
            let mut count = vec![0u32; n];
            for p in &pts {
                // The first `a` digits of x and the first `m − a` digits of y.
                let i = ((p[0] as u64) >> (32 - a)) as usize;
                let j = ((p[1] as u64) >> (32 - (m - a))) as usize;
                count[(i << (m - a)) | j] += 1;
            }
            assert!(count.iter().all(|&c| c == 1), "seeds {seeds:?}, a = {a}");
        }
    }
    // Scrambling is a bijection that keeps prefixes: equal leading digits stay equal.
    assert_ne!(owen_scramble(0x8000_0000, 1), owen_scramble(0x8000_0000, 2));
    let (x, y) = (0xabcd_0000u32, 0xabcd_ffffu32);
    assert_eq!(owen_scramble(x, 99) >> 16, owen_scramble(y, 99) >> 16);

    // ∫ Π x_j over [0, 1]^6 = 1/64 with 64 replicates of 1024 points.
    let d = 6;
    let est: Vec<f64> = (0..64u32)
        .map(|r| {
            let seeds: Vec<u32> = (0..d as u32).map(|j| r * 7919 + j * 104_729 + 1).collect();
            let mut s = Sobol::scrambled(&seeds, 0);
            let mut u = [0.0f64; 6];
            (0..1024)
                .map(|_| {
                    s.next_f64(&mut u);
                    u.iter().map(|x| x + 0.5 / 4_294_967_296.0).product::<f64>()
                })
                .sum::<f64>()
                / 1024.0
        })
        .collect();
    let mean = est.iter().sum::<f64>() / 64.0;
    let sd = (est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / 63.0).sqrt();
    // Monte Carlo: sd of Π x_j is sqrt(3^-6 − 4^-6) ≈ 0.0358, over √1024.
    let mc_sd = ((1.0f64 / 729.0) - 1.0 / 4096.0).sqrt() / 32.0;
    eprintln!("RQMC ∫Πx: mean {mean:.6} (1/64 = 0.015625), sd {sd:.2e}, MC sd {mc_sd:.2e}");
    assert!((mean - 1.0 / 64.0).abs() < 4.0 * sd / 8.0);
    assert!(sd < 0.25 * mc_sd, "RQMC sd {sd} not well below MC {mc_sd}");
}

// ---------------------------------------------------------------------------------------
// Closed forms.

/// The planar 2R (l1 = l2 = 0.5) reaches the disc of radius 1: area π. The cloud is
/// planar (world x–z), the first-order bias at full coverage is `4 h R` (`(h/2) ∮ ‖n‖₁`
/// for a circle of radius R), and the raw occupancy on a randomly shifted grid tends to
/// `|disc ⊕ pixel| = π R² + 4 h R + h²`.
#[test]
fn planar_2r_disc_area_random_and_sobol() {
    let model = planar_2r();
    let h = 0.02;
    for sampling in [Sampling::Random, Sampling::Sobol] {
        let r = sample_workspace(&model, &opts(1 << 22, 16, sampling, h)).expect("runs");
        assert!(r.planar);
        assert_eq!(r.cloud_dimension, 2);
        assert_eq!(r.volume_m3, 0.0);
        let pl = r.plane.as_ref().expect("plane");
        assert_eq!(pl.normal[1].abs(), 1.0);
        assert_eq!((pl.u, pl.v), ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]));
        assert_eq!(r.bias.unit, "m2");
        assert_within_uncertainty(&r, PI, 0.005, "2R disc");
        let first_order = 4.0 * h;
        assert!(
            (r.bias.bias - first_order).abs() < 0.05 * first_order,
            "bias {} against 4hR = {first_order}",
            r.bias.bias
        );
        // The pooled raw occupancy (one randomly shifted grid, all samples) is about
        // |disc ⊕ pixel|, within the lattice noise (the replicates' spread).
        let full = PI + 4.0 * h + h * h;
        assert!(r.pooled <= full + 3.0 * r.measure_stderr());
        assert!(r.pooled >= full - 3.0 * r.measure_stderr() - 0.002);
        // The bounding box is the disc's.
        for k in [0, 2] {
            assert!(r.bbox[0][k] > -1.0 - 1e-12 && r.bbox[0][k] < -0.999);
            assert!(r.bbox[1][k] < 1.0 + 1e-12 && r.bbox[1][k] > 0.999);
        }
        assert_eq!(r.bbox[0][1], 0.0);
        assert_eq!(r.outside_grid, 0);
    }
}

/// l1 = 0.6, l2 = 0.3: the annulus between radii 0.3 and 0.9, area π(0.9² − 0.3²).
#[test]
fn planar_2r_annulus_area_random_and_sobol() {
    let (l1, l2) = (0.6, 0.3);
    let model = planar_2r_lengths(l1, l2);
    let truth = PI * ((l1 + l2) * (l1 + l2) - (l1 - l2) * (l1 - l2));
    let h = 0.02;
    for sampling in [Sampling::Random, Sampling::Sobol] {
        let r = sample_workspace(&model, &opts(1 << 22, 16, sampling, h)).expect("runs");
        assert!(r.planar);
        assert_within_uncertainty(&r, truth, 0.006, "2R annulus");
        // First-order bias: (h/2) · 8 (R_out + R_in).
        let first_order = 4.0 * h * (l1 + l2 + l1 - l2);
        assert!(
            (r.bias.bias - first_order).abs() < 0.05 * first_order,
            "bias {} against {first_order}",
            r.bias.bias
        );
        // The hole is empty and the ring is full.
        assert!(!r.is_occupied(&Vec3::new(0.0, 0.0, 0.0)));
        assert!(!r.is_occupied(&Vec3::new(0.25, 0.0, 0.0)));
        assert!(r.is_occupied(&Vec3::new(0.0, 0.0, 0.6)));
        assert!(!r.is_occupied(&Vec3::new(-0.95, 0.0, 0.0)));
    }
}

/// The spherical R-R-P reaches the shell sector r ∈ [0.6, 1.5], elevation
/// b ∈ [−45°, 60°], azimuth g ∈ [−170°, 170°]:
/// `V = (r2³ − r1³)/3 · (sin 60° − sin(−45°)) · 340°`.
#[test]
fn spherical_rrp_shell_volume_random_and_sobol() {
    let model = common::load("robots/textbook_spherical_rrp.toml");
    let truth = (1.5f64.powi(3) - 0.6f64.powi(3)) / 3.0
        * (60f64.to_radians().sin() + 45f64.to_radians().sin())
        * 340f64.to_radians();
    for sampling in [Sampling::Random, Sampling::Sobol] {
        let r = sample_workspace(&model, &opts(1 << 23, 8, sampling, 0.1)).expect("runs");
        assert!(!r.planar);
        assert_eq!(r.cloud_dimension, 3);
        assert!(r.area_m2.is_none());
        assert_eq!(r.bias.unit, "m3");
        assert_within_uncertainty(&r, truth, 0.10, "R-R-P shell");
        // Radii: the bounding box reaches r = 1.5 along +x (g = 0, b = 0) and
        // z = 1.5 sin 60°, z = −1.5 sin 45°.
        assert!(r.bbox[1][0] > 1.49 && r.bbox[1][0] <= 1.5 + 1e-12);
        assert!(r.bbox[1][2] > 1.5 * 60f64.to_radians().sin() - 0.01);
        assert!(r.bbox[0][2] < -1.5 * 45f64.to_radians().sin() + 0.01);
        assert!(r.is_occupied(&Vec3::new(1.0, 0.0, 0.0)));
        assert!(!r.is_occupied(&Vec3::new(0.3, 0.0, 0.0)));
        assert!(
            !r.is_occupied(&Vec3::new(-1.0, 0.0, 0.0)),
            "the 20° gap at g = 180°"
        );
        assert!(!r.is_occupied(&Vec3::new(0.0, 0.0, 1.0)), "above b = 60°");
    }
}

// ---------------------------------------------------------------------------------------
// Error bars.

/// The reported noise scale is honest: over 12 independent runs (seeds) the spread of
/// the headline is no larger than 1.5 × the reported `stderr` (the spread of the
/// replicates, each on its own shifted grid with 1/R of the samples, bounds the noise of
/// the pooled estimate), and not absurdly smaller than it either.
#[test]
fn stderr_bounds_the_spread_over_seeds() {
    let model = planar_2r();
    for sampling in [Sampling::Random, Sampling::Sobol] {
        let (est, se): (Vec<f64>, Vec<f64>) = (0..12u64)
            .map(|seed| {
                let o = WorkspaceOptions {
                    seed: 100 + seed,
                    ..opts(1 << 18, 8, sampling, 0.02)
                };
                let res = sample_workspace(&model, &o).expect("runs");
                (res.measure(), res.measure_stderr())
            })
            .unzip();
        let mean = est.iter().sum::<f64>() / 12.0;
        let spread = (est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / 11.0).sqrt();
        let reported = (se.iter().map(|s| s * s).sum::<f64>() / 12.0).sqrt();
        eprintln!(
            "{sampling:?}: reported stderr {reported:.5}, spread over seeds {spread:.5}, mean {mean:.5} (π)"
        );
        assert!(
            spread <= 1.5 * reported,
            "spread {spread} against stderr {reported}"
        );
        assert!(
            spread >= 0.05 * reported,
            "spread {spread} against stderr {reported}"
        );
    }
}

/// At equal N Sobol' covers faster. On the grid anchored at the origin (sampling effects
/// alone) its shortfall from full coverage is well below random sampling's; on shifted
/// grids both intervals cover π.
#[test]
fn sobol_beats_random_at_equal_n() {
    let model = planar_2r();
    let h = 0.02;
    // Two replicates: the pooled occupancy is the union of two scrambled nets (a union
    // of many independent nets loses most of the stratification).
    let n = 1u64 << 15;
    let run = |sampling, shift_grid| {
        let o = WorkspaceOptions {
            shift_grid,
            ..opts(2 * n, 2, sampling, h)
        };
        sample_workspace(&model, &o).expect("runs")
    };
    let (rnd, sob) = (run(Sampling::Random, false), run(Sampling::Sobol, false));
    // Full coverage of the grid anchored at the origin: the pixels that meet the disc,
    // counted in closed form (the nearest point of pixel (i, j) lies inside radius 1).
    let k = (1.0 / h).round() as i64 + 1;
    let mut full = 0u64;
    for i in -k..k {
        for j in -k..k {
            let near = |a: i64| {
                if a > 0 {
                    a as f64 * h
                } else if a + 1 < 0 {
                    -(a + 1) as f64 * h
                } else {
                    0.0
                }
            };
            if near(i).hypot(near(j)) < 1.0 {
                full += 1;
            }
        }
    }
    let full = full as f64 * h * h;
    assert!(rnd.pooled <= full && sob.pooled <= full);
    let (d_rnd, d_sob) = (full - rnd.pooled, full - sob.pooled);
    eprintln!(
        "n = {n}/replicate, fixed grid: stderr random {:.5} Sobol' {:.5}; shortfall from full coverage {full:.4}: random {d_rnd:.5} Sobol' {d_sob:.5}",
        rnd.measure_stderr(),
        sob.measure_stderr()
    );
    // Measured: 0.0060 against 0.0100.
    assert!(d_sob >= 0.0 && d_sob < 0.7 * d_rnd);
    // (The replicates' spread no longer shows it: each replicate's estimate is measured
    // on its closed occupancy, which fills the sampling gaps that made random sampling's
    // replicates disagree; the shortfall above is the sampling effect itself.)
    let (rnd, sob) = (run(Sampling::Random, true), run(Sampling::Sobol, true));
    let (e_rnd, e_sob) = (rnd.measure() - PI, sob.measure() - PI);
    eprintln!("shifted grids: headline − π: random {e_rnd:+.5}, Sobol' {e_sob:+.5}");
    for r in [&rnd, &sob] {
        eprintln!(
            "{:?}: {:?} {:?} {:?}",
            r.sampling, r.estimate.interval, r.estimate.corrected, r.estimate.remaining_bounds
        );
    }
    assert!(rnd.interval_covers(PI) && sob.interval_covers(PI));
}

// ---------------------------------------------------------------------------------------
// Extras.

/// Translational manipulability of the 2R (l1 = l2 = l) is `l² |sin q2|`, a function of
/// the radius ρ = 2l |cos(q2/2)| alone: `w(ρ) = ρ √(4l² − ρ²) / 2`; the condition number
/// is that of the 2 × 2 Jacobian at the same q2. Every pixel's min/mean/max must lie in
/// the range of the closed form over the pixel's radii; w → 0 at the stretched-arm
/// boundary and is positive inside.
#[test]
fn manipulability_and_condition_per_pixel_of_the_2r() {
    let model = planar_2r();
    let h = 0.05;
    let o = WorkspaceOptions {
        extras: true,
        extras_samples: Some(1 << 20),
        ..opts(1 << 20, 8, Sampling::Sobol, h)
    };
    let r = sample_workspace(&model, &o).expect("runs");
    let ex = r.extras.as_ref().expect("extras");
    assert_eq!(ex.samples, 1 << 20);
    assert_eq!(ex.voxels as usize, r.voxels.len());
    assert_eq!(
        ex.voxels, r.occupied_voxels,
        "every pooled pixel got samples"
    );
    let l = 0.5;
    let w_of = |rho: f64| 0.5 * rho * (4.0 * l * l - rho * rho).max(0.0).sqrt();
    let kappa_of = |rho: f64| {
        let q2 = 2.0 * (rho / (2.0 * l)).min(1.0).acos();
        // Planar Jacobian at q1 = 0 (the singular values do not depend on q1).
        let j = Matrix2::new(-l * q2.sin(), -l * q2.sin(), l + l * q2.cos(), l * q2.cos());
        let s = j.singular_values();
        s.max() / s.min()
    };
    let (mut outer, mut inner, mut outer_min) = (0, 0, 0.0f64);
    for v in &r.voxels {
        let [lo, hi] = r.voxel_bounds(v.index);
        // Radii covered by the pixel [lo0, hi0] × [lo1, hi1] in the x–z plane.
        let near = |a: f64, b: f64| {
            if a > 0.0 {
                a
            } else if b < 0.0 {
                -b
            } else {
                0.0
            }
        };
        let far = |a: f64, b: f64| a.abs().max(b.abs());
        let rmin = near(lo[0], hi[0]).hypot(near(lo[1], hi[1]));
        let rmax = far(lo[0], hi[0]).hypot(far(lo[1], hi[1])).min(2.0 * l);
        let grid: Vec<f64> = (0..=400)
            .map(|i| rmin + (rmax - rmin) * i as f64 / 400.0)
            .collect();
        let wmin = grid.iter().map(|&x| w_of(x)).fold(f64::INFINITY, f64::min);
        let wmax = grid.iter().map(|&x| w_of(x)).fold(0.0, f64::max);
        let tol = 1e-9 + 0.002 * (wmax - wmin);
        assert!(
            v.manipulability_min >= wmin - tol && v.manipulability_max <= wmax + tol,
            "pixel {:?} radii [{rmin:.4}, {rmax:.4}]: w in [{}, {}], closed form [{wmin}, {wmax}]",
            v.index,
            v.manipulability_min,
            v.manipulability_max
        );
        assert!(
            v.manipulability_mean >= v.manipulability_min
                && v.manipulability_mean <= v.manipulability_max
        );
        let far_corner = far(lo[0], hi[0]).hypot(far(lo[1], hi[1]));
        if far_corner > 2.0 * l + 0.01 && v.samples >= 50 {
            // The circle crosses the pixel: samples near the stretched arm, w → 0.
            assert!(
                v.manipulability_min < 0.005,
                "outer pixel {:?}: min w {}",
                v.index,
                v.manipulability_min
            );
            outer_min = outer_min.max(v.manipulability_min);
            outer += 1;
        }
        if rmax < 0.95 && rmin > 0.05 {
            assert!(v.manipulability_min > 0.0);
            let kmin = grid
                .iter()
                .map(|&x| kappa_of(x))
                .fold(f64::INFINITY, f64::min);
            let kmax = grid.iter().map(|&x| kappa_of(x)).fold(0.0, f64::max);
            assert!(
                v.condition_min >= kmin * (1.0 - 1e-6) && v.condition_max <= kmax * (1.0 + 1e-3),
                "pixel {:?}: κ in [{}, {}], closed form [{kmin}, {kmax}]",
                v.index,
                v.condition_min,
                v.condition_max
            );
            inner += 1;
        }
    }
    eprintln!(
        "2R pixels checked: {} ({outer} on the outer rim, largest min w there {outer_min:.4}; {inner} inside)",
        r.voxels.len()
    );
    assert!(outer > 20 && inner > 500);
    // Mean over all samples: l² E|sin q2| = l² · 2/π; the largest is l² (q2 = ±π/2).
    assert!((ex.manipulability_mean - l * l * 2.0 / PI).abs() < 2e-3);
    assert!((ex.manipulability_max - l * l).abs() < 1e-6);
    // The disc has boundary pixels only on its rim.
    let rim = r.voxels.iter().filter(|v| v.boundary).count() as u64;
    assert_eq!(rim, r.boundary_voxels);
    for v in r.voxels.iter().filter(|v| v.boundary) {
        let c = Vec3::from(v.center);
        assert!(
            c.norm() > 1.0 - 2.0 * h,
            "boundary pixel at radius {}",
            c.norm()
        );
    }
}

/// Dexterity (in-plane tool angle, 36 bins, at least half of them): only the folded
/// arm of the equal-link 2R at the origin reaches every orientation; the unequal-link
/// 2R reaches none (two orientations per point).
#[test]
fn dexterous_area_of_the_2r() {
    let o = WorkspaceOptions {
        extras: true,
        ..opts(1 << 20, 8, Sampling::Sobol, 0.02)
    };
    let r = sample_workspace(&planar_2r(), &o).expect("runs");
    let ex = r.extras.as_ref().expect("extras");
    assert_eq!((ex.orientation_bins, ex.dexterous_min_bins), (36, 18));
    let dex: Vec<_> = r.voxels.iter().filter(|v| v.dexterous).collect();
    assert!(!dex.is_empty());
    for v in &dex {
        assert!(
            Vec3::from(v.center).norm() < 0.1,
            "dexterous pixel at {:?}",
            v.center
        );
    }
    assert_eq!(r.dexterous_area_m2, Some(dex.len() as f64 * 0.02 * 0.02));
    let r = sample_workspace(&planar_2r_lengths(0.6, 0.3), &o).expect("runs");
    assert_eq!(r.dexterous_area_m2, Some(0.0));
    assert!(r.voxels.iter().all(|v| v.orientations <= 8));
}

// ---------------------------------------------------------------------------------------
// Determinism, options, output.

fn fingerprint(r: &WorkspaceResult) -> String {
    let mut v = serde_json::to_value(r).expect("serializes");
    v.as_object_mut().expect("object").remove("time_s");
    v.as_object_mut().expect("object").remove("threads");
    let voxels: Vec<_> = r
        .voxels
        .iter()
        .map(|x| {
            (
                x.index,
                x.samples,
                x.manipulability_mean,
                x.condition_max,
                x.orientations,
            )
        })
        .collect();
    format!("{v}{voxels:?}")
}

#[test]
fn same_seed_same_result_whatever_the_thread_count() {
    let model = common::load("robots/ur5.urdf");
    for sampling in [Sampling::Random, Sampling::Sobol] {
        let o = WorkspaceOptions {
            extras: true,
            extras_samples: Some(50_000),
            seed: 42,
            ..opts(1 << 18, 4, sampling, 0.05)
        };
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let r = pool.install(|| sample_workspace(&model, &o).expect("runs"));
            assert_eq!(r.threads, threads);
            fingerprint(&r)
        };
        let one = run(1);
        assert_eq!(one, run(1), "same seed, same result");
        assert_eq!(one, run(3), "1 thread against 3");
        let other = WorkspaceOptions {
            seed: 43,
            ..o.clone()
        };
        let r = sample_workspace(&model, &other).expect("runs");
        assert_ne!(one, fingerprint(&r), "another seed differs");
    }
}

/// Every robot in `robots/`: the reach bound holds (no sample outside the grid), the
/// bounding box lies inside it, and the tool is the deepest link.
#[test]
fn every_robot_stays_inside_its_grid() {
    for path in common::robot_files() {
        let model = common::load(
            path.strip_prefix(env!("CARGO_MANIFEST_DIR"))
                .unwrap()
                .to_str()
                .unwrap(),
        );
        let sampling = if model.nv <= 31 {
            Sampling::Sobol
        } else {
            Sampling::Random
        };
        let r = sample_workspace(&model, &opts(1 << 14, 2, sampling, 0.05))
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(r.outside_grid, 0, "{}", path.display());
        assert!(r.pooled > 0.0);
        assert!(r.interval_covers(r.measure()) || r.interval_kind == IntervalKind::LowerBound);
        assert_eq!(r.joint_names, model.dof_names());
    }
}

#[test]
fn bad_options_are_errors() {
    let model = planar_2r();
    let bad = |o: WorkspaceOptions| sample_workspace(&model, &o).unwrap_err().to_string();
    assert!(bad(opts(1000, 1, Sampling::Random, 0.02)).contains("2 replicates"));
    assert!(bad(opts(1000, 4, Sampling::Random, 0.0)).contains("voxel"));
    assert!(bad(WorkspaceOptions {
        tool: Some("nope".into()),
        ..opts(1000, 4, Sampling::Random, 0.02)
    })
    .contains("nope"));
    assert!(bad(WorkspaceOptions {
        tool: Some("base_link".into()),
        ..opts(1000, 4, Sampling::Random, 0.02)
    })
    .contains("fixed to the world"));
    assert!(bad(opts(1000, 4, Sampling::Random, 1e-5)).contains("too large"));
    let long = Model::build(chain::chain_spec(40)).expect("chain").0;
    let e = sample_workspace(&long, &opts(1000, 2, Sampling::Sobol, 0.05)).unwrap_err();
    assert!(e.to_string().contains("random"), "{e}");
    assert!(sample_workspace(&long, &opts(1000, 2, Sampling::Random, 0.05)).is_ok());
}

/// The points CSV holds the kept samples; forward kinematics of each row's q gives its
/// x, y, z. The voxels CSV has one row per pooled voxel.
#[test]
fn csv_output() {
    let model = common::load("robots/ur5_dh.toml");
    let o = WorkspaceOptions {
        keep_points: 300,
        extras: true,
        extras_samples: Some(10_000),
        ..opts(1 << 16, 4, Sampling::Sobol, 0.05)
    };
    let r = sample_workspace(&model, &o).expect("runs");
    let dir = std::env::temp_dir().join(format!("armsim_ws_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    let path = dir.join("points.csv");
    r.write_points_csv(&path).expect("writes");
    let text = std::fs::read_to_string(&path).expect("reads");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    assert_eq!(header.len(), model.nv + 5);
    assert_eq!(
        header[..model.nv],
        model
            .dof_names()
            .iter()
            .map(|s| s.as_str())
            .collect::<Vec<_>>()[..]
    );
    assert_eq!(
        &header[model.nv..],
        ["x", "y", "z", "manipulability", "condition"]
    );
    let tool = model.link_id(&r.tool).expect("tool");
    let mut data = Data::new(&model);
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect();
    assert_eq!(rows.len(), 300);
    for row in &rows {
        kinematics::forward_kinematics(&model, &mut data, &row[..model.nv]);
        let p = kinematics::frame_placement(&model, &data, tool).trans;
        for k in 0..3 {
            assert!((p[k] - row[model.nv + k]).abs() < 1e-12);
        }
        assert!(row[model.nv + 3] >= 0.0 && row[model.nv + 4] >= 1.0);
    }
    let vpath = dir.join("voxels.csv");
    r.write_voxels_csv(&vpath).expect("writes");
    let text = std::fs::read_to_string(&vpath).expect("reads");
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(rows.len() as u64, r.occupied_voxels);
    let boundary = rows
        .iter()
        .filter(|l| l.split(',').nth(6) == Some("1"))
        .count() as u64;
    assert_eq!(boundary, r.boundary_voxels);
    let with_stats = rows
        .iter()
        .filter(|l| !l.split(',').nth(7).unwrap_or("").is_empty())
        .count();
    assert_eq!(with_stats, r.voxels.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_raised_stop_flag_cancels_the_run_within_a_block() {
    use armsim::workspace::WorkspaceError;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let m = Model::load(std::path::Path::new("robots/ur5.urdf"))
        .unwrap()
        .0;
    // Raised before the start: nothing but the pilot runs.
    let stop = Arc::new(AtomicBool::new(true));
    let o = WorkspaceOptions {
        stop: Some(stop),
        ..opts(1 << 22, 4, Sampling::Sobol, 0.05)
    };
    assert!(matches!(
        sample_workspace(&m, &o),
        Err(WorkspaceError::Cancelled)
    ));
    // Raised 50 ms into a run of 2^28 samples (tens of seconds here): it ends within a
    // block of 65 536 samples per replicate.
    let stop = Arc::new(AtomicBool::new(false));
    let o = WorkspaceOptions {
        stop: Some(stop.clone()),
        ..opts(1 << 28, 4, Sampling::Sobol, 0.05)
    };
    let raiser = std::thread::spawn(move || {
        std::thread::sleep(std::time::Duration::from_millis(50));
        stop.store(true, Ordering::Relaxed);
    });
    let t = std::time::Instant::now();
    let r = sample_workspace(&m, &o);
    raiser.join().unwrap();
    assert!(
        matches!(r, Err(WorkspaceError::Cancelled)),
        "{:?}",
        r.map(|r| r.estimate.measure)
    );
    assert!(t.elapsed().as_secs_f64() < 5.0, "took {:?}", t.elapsed());
}
