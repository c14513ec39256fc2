//! What the Rerun output is asked for and what it reports, independent of whether the
//! `rerun` feature (the Rerun SDK) is built: the sink, the error, the report, the entity
//! naming constants and the point-cloud colormap. `rerun_out` logs through the SDK when
//! the feature is on; without it, every log call returns [`RerunError::NotBuilt`].

use std::path::PathBuf;

/// Whether this build can log to Rerun (the `rerun` cargo feature, on by default).
pub const AVAILABLE: bool = cfg!(feature = "rerun");

/// Where the log goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RerunSink {
    /// Write an `.rrd` file (atomically).
    Save(PathBuf),
    /// Spawn the `rerun` viewer (found on `PATH`) and stream to it.
    Spawn,
}

/// Why logging failed.
#[derive(Debug, thiserror::Error)]
pub enum RerunError {
    /// The output file cannot be written.
    #[error("{}: {msg}", path.display())]
    Output {
        /// The `.rrd` path.
        path: PathBuf,
        /// What went wrong.
        msg: String,
    },
    /// The viewer could not be started or reached.
    #[error("rerun viewer: {0}")]
    Viewer(String),
    /// The Rerun SDK refused the data.
    #[error("rerun: {0}")]
    Sdk(String),
    /// The recording is larger than the viewer's budget (see `rerun_tree`).
    #[error("{0}")]
    TooLarge(TooManyFrames),
    /// armsim was built without the `rerun` feature.
    #[error(
        "this armsim was built without Rerun support (cargo feature `rerun`); rebuild with default features"
    )]
    NotBuilt,
}

/// A recording with more transform frames (children of `/tf` and `/tf_static`
/// transforms, and model links) than the viewer draws.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{frames} transform frames (children of /tf and /tf_static transforms and model links): more than the {limit} the viewer draws"
)]
pub struct TooManyFrames {
    /// The transform frames of the recording.
    pub frames: usize,
    /// The most the viewer draws.
    pub limit: usize,
}

/// The scene around the robot: obstacles drawn as static geometry under
/// `world/obstacles/<name>` (their `origin` is the world pose), included in the framing of
/// the 3-D view.
#[derive(Clone, Debug, Default)]
pub struct SceneExtras {
    /// Obstacles by name.
    pub obstacles: Vec<(String, crate::model::Geometry)>,
    /// Directory relative obstacle mesh paths start from (default: the current one).
    pub obstacle_dir: Option<PathBuf>,
}

/// What was logged.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RerunReport {
    /// Link entities (`world/robot/<link>`), in order.
    pub links: Vec<String>,
    /// Links that received a transform per frame.
    pub moving_links: usize,
    /// Frames logged.
    pub frames: usize,
    /// Visual geometry entities logged.
    pub visuals: usize,
    /// Points logged over all clouds.
    pub points: usize,
    /// Obstacle shapes drawn.
    pub obstacles: usize,
    /// The tool link whose path was drawn.
    pub tool: Option<String>,
    /// Problems that did not stop the log (missing meshes, malformed frames, …).
    pub warnings: Vec<String>,
    /// Size of the written file (save only).
    pub bytes: Option<u64>,
}

/// Application id of the recordings.
pub const APP_ID: &str = "armsim";
/// Name of the timeline.
pub const TIMELINE: &str = "time";

/// Viridis-like colormap: `x` in `[0, 1]` (clamped; NaN gives grey) to RGB, linear
/// interpolation between five stops of matplotlib's viridis.
pub fn colormap(x: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    if x.is_nan() {
        return [128, 128, 128];
    }
    let s = x.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - i as f32;
    let mut out = [0u8; 3];
    for c in 0..3 {
        let v = STOPS[i][c] + f * (STOPS[i + 1][c] - STOPS[i][c]);
        out[c] = v.round().clamp(0.0, 255.0) as u8;
    }
    out
}
