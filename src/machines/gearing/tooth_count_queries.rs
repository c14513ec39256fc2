//! "Which tooth count gives X" (problem book ch. 8, problems 219–220; docs/reference_data.md
//! §M2): the tooth count at which a circle of a standard (or shifted, or helical) gear
//! equals another, from `r = m_t z/2`, `r_b = r cos α_t`, `m_t = m_n/cos β`,
//! `tan α_t = tan α_n/cos β`:
//!
//! ```text
//! root = base (external):  r − (h_a* + c* − x) m_n = r cos α_t
//!                          z = 2 (h_a* + c* − x) cos β/(1 − cos α_t)     (41.45 at 20°, 1, 0.25)
//! tip = base (internal):   r − h_a* m_n = r cos α_t
//!                          z = 2 h_a* cos β/(1 − cos α_t)                (33.16 at 20°)
//! no undercut (rack):      (h_a* − x) m_n = r sin² α_t
//!                          z = 2 (h_a* − x) cos β/sin² α_t               (17.10 at 20°)
//! ```
//!
//! The answer is the smallest whole count past the boundary: the root circle outside the
//! base circle from 42 teeth (inside up to 41), the internal tip circle outside the base
//! circle (the whole tooth flank involute) from 34, no undercut from 18 (the book rounds
//! `2h_a*/sin²α` to 17).

/// What is asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToothCountQuery {
    /// External gear: the root circle equals the base circle.
    RootEqualsBase,
    /// Internal gear: the tip circle equals the base circle.
    InternalTipEqualsBase,
    /// External gear cut by a rack: the limit of undercut.
    NoUndercut,
}

impl ToothCountQuery {
    /// The TOML spelling.
    pub fn name(self) -> &'static str {
        match self {
            ToothCountQuery::RootEqualsBase => "root_equals_base",
            ToothCountQuery::InternalTipEqualsBase => "internal_tip_equals_base",
            ToothCountQuery::NoUndercut => "no_undercut",
        }
    }

    /// From the TOML spelling.
    pub fn from_name(s: &str) -> Option<Self> {
        [
            ToothCountQuery::RootEqualsBase,
            ToothCountQuery::InternalTipEqualsBase,
            ToothCountQuery::NoUndercut,
        ]
        .into_iter()
        .find(|q| q.name() == s)
    }

    /// What the answer means.
    pub fn meaning(self) -> &'static str {
        match self {
            ToothCountQuery::RootEqualsBase => {
                "smallest z whose root circle is not inside the base circle (z ≤ largest_below: root inside base)"
            }
            ToothCountQuery::InternalTipEqualsBase => {
                "smallest z of an internal gear whose tip circle is not inside its base circle"
            }
            ToothCountQuery::NoUndercut => "smallest z cut by the rack without undercut",
        }
    }
}

/// The data of a query (angles in radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToothData {
    /// Normal pressure angle `α_n`.
    pub pressure_angle: f64,
    /// Helix angle `β` (0 for spur).
    pub helix_angle: f64,
    /// `h_a*`.
    pub addendum: f64,
    /// `c*`.
    pub clearance: f64,
    /// Profile shift `x` (external gears).
    pub shift: f64,
}

/// The answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToothCountAnswer {
    /// The tooth count where the two circles are equal (not whole in general).
    pub exact: f64,
    /// `answer − 1`: the largest whole count short of the boundary.
    pub largest_below: i64,
    /// The answer: the smallest whole count on or past the boundary, `⌈exact⌉`.
    pub answer: i64,
}

/// The boundary tooth count of `q` for `d` (see the module docs); `None` when the
/// boundary is not positive (e.g. a shift that puts the root outside the base for any z).
pub fn boundary_teeth(q: ToothCountQuery, d: &ToothData) -> Option<ToothCountAnswer> {
    let cb = d.helix_angle.cos();
    let at = (d.pressure_angle.tan() / cb).atan();
    let exact = match q {
        ToothCountQuery::RootEqualsBase => {
            2.0 * (d.addendum + d.clearance - d.shift) * cb / (1.0 - at.cos())
        }
        ToothCountQuery::InternalTipEqualsBase => 2.0 * d.addendum * cb / (1.0 - at.cos()),
        ToothCountQuery::NoUndercut => 2.0 * (d.addendum - d.shift) * cb / at.sin().powi(2),
    };
    if !(exact.is_finite() && exact > 0.0 && exact < 1e9) {
        return None;
    }
    let answer = (exact - 1e-9).ceil();
    Some(ToothCountAnswer {
        exact,
        largest_below: answer as i64 - 1,
        answer: answer as i64,
    })
}
