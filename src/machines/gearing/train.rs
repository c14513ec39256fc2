//! The gear-train description (docs/reference_data.md §M1): gears with tooth counts, the
//! bodies they sit on (a compound block `2/2'` is two gears on one body), carriers that
//! hold planet axes, and the meshes between gears (external/internal spur, bevel, worm or
//! crossed, with a sign for the non-parallel ones). This file owns the structure: the
//! checks that make a train well formed, the mesh geometry (`A = m (z₁ ± z₂)/2`), the
//! mobility count `W = 3n − 2p₅ − p₄` and the classification.
//!
//! Errors name the element ([`Element`]) so that a scenario reader can locate them.

/// Which element of the description an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Element {
    /// The train as a whole.
    Train,
    /// `gears[i]`.
    Gear(usize),
    /// `carriers[i]`.
    Carrier(usize),
    /// `meshes[i]`.
    Mesh(usize),
    /// `inputs[i]`.
    Input(usize),
    /// `torques[i]`.
    Torque(usize),
}

/// A structural or numerical problem with a train.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct TrainError {
    /// Where.
    pub element: Element,
    /// The key of that element (`teeth`, `gears`, `sign`, …).
    pub field: &'static str,
    /// What is wrong.
    pub message: String,
}

impl TrainError {
    /// Builds an error.
    pub fn new(element: Element, field: &'static str, message: impl Into<String>) -> Self {
        Self {
            element,
            field,
            message: message.into(),
        }
    }
}

/// The kind of a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshKind {
    /// Parallel axes (external, or internal when one gear is internal).
    Spur,
    /// Intersecting axes.
    Bevel,
    /// Worm and wheel (the worm's `teeth` are its starts).
    Worm,
    /// Crossed helical.
    Crossed,
}

impl MeshKind {
    /// The TOML spelling.
    pub fn name(self) -> &'static str {
        match self {
            MeshKind::Spur => "spur",
            MeshKind::Bevel => "bevel",
            MeshKind::Worm => "worm",
            MeshKind::Crossed => "crossed",
        }
    }
}

/// One gear.
#[derive(Clone, Debug, PartialEq)]
pub struct Gear {
    /// Name (unique among gears).
    pub name: String,
    /// Tooth count (starts for a worm); `None` = to be found from coaxiality or a given
    /// centre distance.
    pub teeth: Option<u32>,
    /// Internal (ring) gear.
    pub internal: bool,
    /// Module (mm); needed for centre distances, radii and forces.
    pub module: Option<f64>,
    /// The body it turns with.
    pub body: usize,
    /// Moment of inertia about its own axis (kg m²).
    pub inertia: f64,
    /// Mass (kg): a planet's mass also orbits with the carrier.
    pub mass: f64,
}

/// A rigid rotating body: a gear block or a carrier.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainBody {
    /// Name (a gear's body name, or the carrier's name).
    pub name: String,
    /// The carrier (body index) whose arm holds this body's axis; `None` = the frame.
    pub carrier: Option<usize>,
    /// Held fixed to the frame.
    pub fixed: bool,
    /// A carrier (holds planet axes).
    pub is_carrier: bool,
    /// Equally spaced planets on a carrier (their loads share the carrier torque).
    pub planets: u32,
    /// Inertia of a carrier (kg m²); gear bodies sum their gears'.
    pub inertia: f64,
    /// The element that declared it (for errors).
    pub element: Element,
}

/// One mesh between two gears.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// The two gears (indices).
    pub gears: [usize; 2],
    /// Kind.
    pub kind: MeshKind,
    /// Sign of `(ω_a − ω_H)/(ω_b − ω_H)` for a non-parallel mesh (arrow rule); spur
    /// meshes take it from internal/external.
    pub sign: Option<i8>,
    /// Mesh efficiency (1 = ideal).
    pub efficiency: f64,
    /// A centre distance (mm) stated for the mesh: it fixes a missing tooth count or is
    /// checked.
    pub centre_distance: Option<f64>,
}

/// A gear train.
#[derive(Clone, Debug, PartialEq)]
pub struct GearTrain {
    /// Gears.
    pub gears: Vec<Gear>,
    /// Bodies: gear blocks in order of first appearance, then carriers (a carrier that
    /// gears are rigid with is their gear block, marked `is_carrier`).
    pub bodies: Vec<TrainBody>,
    /// Meshes.
    pub meshes: Vec<Mesh>,
    /// Groups of bodies stated to be coaxial (besides carriers and their central gears).
    pub coaxial: Vec<Vec<usize>>,
    /// Profile-shifted (non-standard) gears: coaxiality by `m (z₁ ± z₂)/2` is not checked.
    pub profile_shifted: bool,
}

/// What a mesh relates, after [`GearTrain::mesh_frame`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshFrame {
    /// Bodies of the two gears.
    pub bodies: [usize; 2],
    /// The carrier the mesh is seen from (`None` = the frame).
    pub carrier: Option<usize>,
    /// `+1` internal, `−1` external, the given sign, or `None` for an unsigned
    /// non-parallel mesh.
    pub sign: Option<i8>,
}

impl GearTrain {
    /// Index of the body named `name`.
    pub fn body(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The gears on body `b`.
    pub fn gears_on(&self, b: usize) -> impl Iterator<Item = usize> + '_ {
        (0..self.gears.len()).filter(move |&g| self.gears[g].body == b)
    }

    /// Tooth count of gear `g` (after [`GearTrain::resolve_teeth`]).
    pub fn z(&self, g: usize) -> u32 {
        self.gears[g].teeth.unwrap_or(0)
    }

    /// The carrier a mesh is seen from and its sign (see [`MeshFrame`]).
    pub fn mesh_frame(&self, e: usize) -> Result<MeshFrame, TrainError> {
        let m = &self.meshes[e];
        let [ga, gb] = m.gears;
        let (ba, bb) = (self.gears[ga].body, self.gears[gb].body);
        let err = |f, msg: String| TrainError::new(Element::Mesh(e), f, msg);
        if ba == bb {
            return Err(err(
                "gears",
                format!(
                    "'{}' and '{}' are on the same body '{}': a body cannot mesh with itself",
                    self.gears[ga].name, self.gears[gb].name, self.bodies[ba].name
                ),
            ));
        }
        let (ca, cb) = (self.bodies[ba].carrier, self.bodies[bb].carrier);
        let carrier = match (ca, cb) {
            (None, None) => None,
            (Some(c), None) | (None, Some(c)) => Some(c),
            (Some(c), Some(d)) if c == d => Some(c),
            (Some(c), Some(d)) => {
                return Err(err(
                    "gears",
                    format!(
                        "'{}' (on carrier '{}') and '{}' (on carrier '{}') ride on different carriers: nested carriers are not supported",
                        self.gears[ga].name, self.bodies[c].name, self.gears[gb].name, self.bodies[d].name
                    ),
                ))
            }
        };
        for (b, c) in [(ba, cb), (bb, ca)] {
            if Some(b) == c {
                return Err(err(
                    "gears",
                    format!(
                        "a gear on carrier '{}' cannot mesh with the carrier itself",
                        self.bodies[b].name
                    ),
                ));
            }
        }
        let (ia, ib) = (self.gears[ga].internal, self.gears[gb].internal);
        let sign = match m.kind {
            MeshKind::Spur => {
                if ia && ib {
                    return Err(err("gears", "two internal gears cannot mesh".into()));
                }
                if m.sign.is_some() {
                    return Err(err(
                        "sign",
                        "a spur mesh takes its sign from internal/external; `sign` is for bevel, worm and crossed meshes".into(),
                    ));
                }
                Some(if ia || ib { 1 } else { -1 })
            }
            _ => {
                if ia || ib {
                    return Err(err(
                        "kind",
                        format!(
                            "an internal gear can only be in a spur mesh, not a {} mesh",
                            m.kind.name()
                        ),
                    ));
                }
                m.sign
            }
        };
        if sign.is_none() && carrier.is_some() {
            return Err(err(
                "sign",
                format!(
                    "a {} mesh seen from carrier '{}' needs `sign = 1` or `-1` (the arrow rule: the sense of the second gear relative to the first, seen from the carrier)",
                    m.kind.name(),
                    self.bodies[carrier.unwrap_or(0)].name
                ),
            ));
        }
        Ok(MeshFrame {
            bodies: [ba, bb],
            carrier,
            sign,
        })
    }

    /// Pitch radius `m z / 2` of gear `g` (mm), when its module is known.
    pub fn radius(&self, g: usize) -> Option<f64> {
        Some(self.gears[g].module? * self.z(g) as f64 / 2.0)
    }

    /// Standard centre distance of a spur mesh, `m (z₁ + z₂)/2` or `m (z_int − z)/2`
    /// (mm); `None` for other kinds or an unknown module.
    pub fn centre_distance(&self, e: usize) -> Option<f64> {
        let m = &self.meshes[e];
        if m.kind != MeshKind::Spur {
            return None;
        }
        let [a, b] = m.gears;
        let (ra, rb) = (self.radius(a)?, self.radius(b)?);
        Some(if self.gears[a].internal {
            ra - rb
        } else if self.gears[b].internal {
            rb - ra
        } else {
            ra + rb
        })
    }

    /// Moving bodies (not fixed).
    pub fn moving(&self) -> usize {
        self.bodies.iter().filter(|b| !b.fixed).count()
    }

    /// Structural mobility `W = 3n − 2p₅ − p₄`: `n` moving bodies, one revolute pair each
    /// (to the frame or its carrier), `p₄` meshes (a mesh with a fixed gear counts once,
    /// as every mesh does).
    pub fn structural_mobility(&self) -> (i64, usize, usize, usize) {
        let n = self.moving();
        let p5 = n;
        let p4 = self.meshes.len();
        (3 * n as i64 - 2 * p5 as i64 - p4 as i64, n, p5, p4)
    }

    /// `"ordinary"`, `"planetary"`, `"differential"` or `"mixed"` given the kinematic DOF.
    pub fn classify(&self, dof: usize) -> &'static str {
        let carriers: Vec<usize> = (0..self.bodies.len())
            .filter(|&b| self.bodies[b].is_carrier && !self.bodies[b].fixed)
            .collect();
        if carriers.is_empty() {
            return "ordinary";
        }
        if dof >= 2 {
            return "differential";
        }
        // A fixed-axis mesh between two frame-held bodies is an ordinary stage.
        let ordinary_stage = self.meshes.iter().any(|m| {
            let [a, b] = m.gears;
            let (ba, bb) = (self.gears[a].body, self.gears[b].body);
            self.bodies[ba].carrier.is_none() && self.bodies[bb].carrier.is_none()
        });
        if ordinary_stage || carriers.len() > 1 {
            "mixed"
        } else {
            "planetary"
        }
    }
}
