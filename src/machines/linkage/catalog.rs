//! Standard linkages built in code, with the problem book's point names (crank pivot `A`,
//! crank pin `B`, then `C`, `D`), and starting guesses for a chosen assembly mode. The
//! scenario files describe the same linkages in TOML; these are for tests and library
//! users.
//!
//! Guesses come from the closed forms (circle intersections); the solver then closes the
//! loop exactly, so a guess only has to pick the branch.

use crate::machines::linkage::description::{Driver, Linkage, PlanarLink, Slider, GROUND};
use crate::machines::linkage::fourbar;
use crate::machines::linkage::Vec2;
use nalgebra::DVector;
use std::collections::HashMap;

fn pts(v: &[(&str, Vec2)]) -> HashMap<String, Vec2> {
    v.iter().map(|(n, p)| (n.to_string(), *p)).collect()
}

/// Slider-crank: crank `AB` (length `r`) about ground `A = (0, 0)`, rod `BC` (length `l`),
/// block `slider` with pin `C` sliding along the x axis at height `e` (the offset).
/// Massless; add masses with [`PlanarLink::with_mass`] on `links`. The driver is the crank
/// angle.
pub fn slider_crank(r: f64, l: f64, e: f64) -> Linkage {
    Linkage::with_shared_pins(
        format!("slider-crank r={r} l={l} e={e}"),
        vec![("A".into(), Vec2::zeros())],
        vec![
            PlanarLink::binary("AB", "A", "B", r),
            PlanarLink::binary("BC", "B", "C", l),
            PlanarLink::new("slider", vec![("C".into(), Vec2::zeros())]),
        ],
        vec![Slider {
            name: "C".into(),
            link: 2,
            p: Vec2::zeros(),
            guide: GROUND,
            through: Vec2::new(0.0, e),
            dir: Vec2::new(1.0, 0.0),
            prismatic: Some(0.0),
        }],
        Driver::Angle {
            link: 0,
            relative_to: GROUND,
        },
    )
}

/// A guess for [`slider_crank`] at crank angle `phi`, with the slider on the side
/// `side = ±1` of the crank pivot (+1: `x_C > x_B`).
pub fn slider_crank_guess(
    l: &Linkage,
    r: f64,
    rod: f64,
    e: f64,
    phi: f64,
    side: f64,
) -> DVector<f64> {
    let b = Vec2::new(r * phi.cos(), r * phi.sin());
    let dy = e - b.y;
    let dx = (rod * rod - dy * dy).max(0.0).sqrt() * side.signum();
    let c = Vec2::new(b.x + dx, e);
    l.coordinates_from_points(&pts(&[("B", b), ("C", c)]), &[])
        .expect("every link has a guessed point")
}

/// Four-bar: ground pivots `A = (0, 0)` and `D = (g, 0)`, crank `AB` (length `a`),
/// coupler `BC` (`b`), rocker `DC` (`c`, angle measured from `D` toward `C`).
pub fn four_bar(g: f64, a: f64, b: f64, c: f64) -> Linkage {
    Linkage::with_shared_pins(
        format!("four-bar {g}/{a}/{b}/{c}"),
        vec![("A".into(), Vec2::zeros()), ("D".into(), Vec2::new(g, 0.0))],
        vec![
            PlanarLink::binary("AB", "A", "B", a),
            PlanarLink::binary("BC", "B", "C", b),
            PlanarLink::binary("DC", "D", "C", c),
        ],
        Vec::new(),
        Driver::Angle {
            link: 0,
            relative_to: GROUND,
        },
    )
}

/// A guess for [`four_bar`] at crank angle `phi` in assembly `mode` (±1, see
/// [`fourbar::position`]); `None` where it cannot close.
pub fn four_bar_guess(
    l: &Linkage,
    (g, a, b, c): (f64, f64, f64, f64),
    phi: f64,
    mode: f64,
) -> Option<DVector<f64>> {
    let (pb, pc) = fourbar::position(g, a, b, c, phi, mode)?;
    l.coordinates_from_points(&pts(&[("B", pb), ("C", pc)]), &[])
        .ok()
}

/// Scotch yoke: crank `AB` (length `r`) about `A = (0, 0)`; the yoke (point `Y` at its
/// origin) slides along the x axis, and the crank pin `B` slides in the yoke's slot along
/// the yoke's y axis through `Y`. The yoke's position is `x_Y = r cos φ`.
pub fn scotch_yoke(r: f64) -> Linkage {
    Linkage::with_shared_pins(
        format!("Scotch yoke r={r}"),
        vec![("A".into(), Vec2::zeros())],
        vec![
            PlanarLink::binary("AB", "A", "B", r),
            PlanarLink::new("yoke", vec![("Y".into(), Vec2::zeros())]),
        ],
        vec![
            Slider {
                name: "yoke".into(),
                link: 1,
                p: Vec2::zeros(),
                guide: GROUND,
                through: Vec2::zeros(),
                dir: Vec2::new(1.0, 0.0),
                prismatic: Some(0.0),
            },
            Slider {
                name: "B".into(),
                link: 0,
                p: Vec2::new(r, 0.0),
                guide: 1,
                through: Vec2::zeros(),
                dir: Vec2::new(0.0, 1.0),
                prismatic: None,
            },
        ],
        Driver::Angle {
            link: 0,
            relative_to: GROUND,
        },
    )
}

/// A guess for [`scotch_yoke`] at crank angle `phi`.
pub fn scotch_yoke_guess(l: &Linkage, r: f64, phi: f64) -> DVector<f64> {
    let b = Vec2::new(r * phi.cos(), r * phi.sin());
    l.coordinates_from_points(&pts(&[("B", b), ("Y", Vec2::new(b.x, 0.0))]), &[])
        .expect("every link has a guessed point")
}

/// Crank and slotted lever (oscillating slider): crank `AB` (length `r`) about
/// `A = (0, 0)`; the lever pivots at ground `C = (g, 0)` and its slot is the lever's x
/// axis through `C`; the block (point `B` at its origin) turns on the crank pin `B` and
/// slides in the slot (a prismatic joint: it turns with the lever). `r < g`: the lever
/// swings (quick return); `r > g`: it turns (Whitworth); `r = g`: the isosceles case,
/// the lever turning at half the crank's speed.
pub fn slotted_lever(g: f64, r: f64) -> Linkage {
    Linkage::with_shared_pins(
        format!("slotted lever AB={r} AC={g}"),
        vec![("A".into(), Vec2::zeros()), ("C".into(), Vec2::new(g, 0.0))],
        vec![
            PlanarLink::binary("AB", "A", "B", r),
            PlanarLink::new("block", vec![("B".into(), Vec2::zeros())]),
            PlanarLink::new("lever", vec![("C".into(), Vec2::zeros())]),
        ],
        vec![Slider {
            name: "B".into(),
            link: 1,
            p: Vec2::zeros(),
            guide: 2,
            through: Vec2::zeros(),
            dir: Vec2::new(1.0, 0.0),
            prismatic: Some(0.0),
        }],
        Driver::Angle {
            link: 0,
            relative_to: GROUND,
        },
    )
}

/// A guess for [`slotted_lever`] at crank angle `phi` (`None` where the pin is on the
/// lever pivot and the slot's direction is not defined).
pub fn slotted_lever_guess(l: &Linkage, g: f64, r: f64, phi: f64) -> Option<DVector<f64>> {
    let b = Vec2::new(r * phi.cos(), r * phi.sin());
    let d = b - Vec2::new(g, 0.0);
    if d.norm() <= 1e-9 * (g + r) {
        return None;
    }
    let th = d.y.atan2(d.x);
    l.coordinates_from_points(&pts(&[("B", b)]), &[0.0, th, th])
        .ok()
}
