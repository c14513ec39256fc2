//! The Rerun blueprint (viewer layout) of a recording, written as blueprint entities by
//! hand: the rerun 0.36 Rust SDK's `Spatial3DView` builder cannot carry view properties,
//! and the 3-D view needs one, its eye ([`EyeControls3D`](bp::EyeControls3D): position and
//! look target), so that the robot and its scene are framed from outside.
//!
//! Layout: the 3-D view (origin `world`) on the left, 3/5 of the width; on the right, tabs:
//! a grid with one time series per joint torque, the joint positions, the text log and the
//! reports (the plots only when the recording has them). A workspace picture has its own
//! layout ([`send_workspace`]): the 3-D view beside the workspace report, and entities
//! that are present but hidden (blueprint visibility, `EntityBehavior`).

use crate::io::record::rerun::rerun_entities::path;
use crate::io::record::rerun::rerun_sink::{RerunError, APP_ID};
use crate::io::record::Recording;
use rerun::external::re_log_types::{BlueprintActivationCommand, LogMsg, RecordingId};
use rerun::external::re_sdk_types::blueprint::{archetypes as bp, components as bc};
use rerun::external::re_sdk_types::components::Name;
use rerun::external::uuid::Uuid;
use rerun::{RecordingStream, RecordingStreamBuilder};

/// Where the 3-D view's camera is and what it looks at (world coordinates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eye {
    /// Camera position.
    pub position: [f32; 3],
    /// The point looked at (and orbited around).
    pub look_target: [f32; 3],
}

impl Eye {
    /// A camera in front of, to the right of and above the box `(lo, hi)`, looking at its
    /// centre from far enough that the whole box is in view.
    pub fn framing(lo: [f64; 3], hi: [f64; 3]) -> Eye {
        // From the right (-y) of a robot facing +x, a little in front of it, above.
        Eye::framing_from(lo, hi, [0.7, -1.0, 0.6], 0.85)
    }

    /// A camera looking at the centre of the box `(lo, hi)` from direction `dir`, at
    /// `distance` times the box's diagonal (at least 0.5 m of it).
    pub fn framing_from(lo: [f64; 3], hi: [f64; 3], dir: [f64; 3], distance: f64) -> Eye {
        let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
        let d = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let n = dir.iter().map(|x: &f64| x * x).sum::<f64>().sqrt();
        let dist = distance * d.max(0.5);
        Eye {
            position: [0, 1, 2].map(|k| (c[k] + dir[k] / n * dist) as f32),
            look_target: c.map(|x| x as f32),
        }
    }
}

/// A view or a container of the layout.
enum Node {
    View {
        class: &'static str,
        name: String,
        origin: String,
        contents: Vec<String>,
        eye: Option<Eye>,
        /// Entities in the view but hidden (blueprint visibility, switchable in the viewer).
        invisible: Vec<String>,
    },
    Container {
        kind: bc::ContainerKind,
        name: Option<String>,
        children: Vec<Node>,
        shares: Vec<f32>,
    },
}

fn view(class: &'static str, name: impl Into<String>, origin: impl Into<String>) -> Node {
    Node::View {
        class,
        name: name.into(),
        origin: origin.into(),
        contents: vec!["+ $origin/**".to_string()],
        eye: None,
        invisible: Vec::new(),
    }
}

fn sdk(e: impl std::fmt::Display) -> RerunError {
    RerunError::Sdk(e.to_string())
}

/// Logs `node` (children first) into the blueprint stream; returns its blueprint path and
/// id.
fn log_node(s: &RecordingStream, node: &Node) -> Result<(String, Uuid), RerunError> {
    let id = Uuid::new_v4();
    match node {
        Node::View {
            class,
            name,
            origin,
            contents,
            eye,
            invisible,
        } => {
            let p = format!("view/{id}");
            for e in invisible {
                let ent = rerun::EntityPath::from(e.as_str());
                s.log(
                    bp::ViewContents::blueprint_base_visualizer_path_for_entity(id, &ent),
                    &bp::EntityBehavior::new().with_visible(false),
                )
                .map_err(sdk)?;
            }
            let queries: Vec<bc::QueryExpression> = contents
                .iter()
                .map(|q| bc::QueryExpression(q.as_str().into()))
                .collect();
            s.log(format!("{p}/ViewContents"), &bp::ViewContents::new(queries))
                .map_err(sdk)?;
            let arch = bp::ViewBlueprint::new(bc::ViewClass((*class).into()))
                .with_display_name(Name(name.as_str().into()))
                .with_space_origin(origin.as_str());
            s.log(p.as_str(), &arch).map_err(sdk)?;
            if let Some(e) = eye {
                let controls = bp::EyeControls3D::new()
                    .with_kind(bc::Eye3DKind::Orbital)
                    .with_position(e.position)
                    .with_look_target(e.look_target)
                    .with_eye_up([0.0f32, 0.0, 1.0]);
                s.log(format!("{p}/EyeControls3D"), &controls)
                    .map_err(sdk)?;
            }
            Ok((p, id))
        }
        Node::Container {
            kind,
            name,
            children,
            shares,
        } => {
            let mut paths = Vec::with_capacity(children.len());
            for c in children {
                paths.push(log_node(s, c)?.0);
            }
            let mut arch = bp::ContainerBlueprint::new(*kind)
                .with_contents(paths.iter().map(|p| bc::IncludedContent(p.as_str().into())));
            if let Some(n) = name {
                arch = arch.with_display_name(Name(n.as_str().into()));
            }
            if !shares.is_empty() {
                arch = arch.with_col_shares(shares.iter().map(|&x| bc::ColumnShare(x.into())));
            }
            let p = format!("container/{id}");
            s.log(p.as_str(), &arch).map_err(sdk)?;
            Ok((p, id))
        }
    }
}

/// The layout of `rec`: the 3-D view (without the entities in `hidden`, with `eye`) and
/// the tabs.
fn layout(rec: &Recording, hidden: &[&str], eye: Option<Eye>) -> Node {
    let mut contents = vec!["+ $origin/**".to_string()];
    contents.extend(hidden.iter().map(|h| format!("- {h}")));
    let scene = Node::View {
        class: "3D",
        name: "robot".into(),
        origin: "/world".into(),
        contents,
        eye,
        invisible: Vec::new(),
    };
    let mut tabs = Vec::new();
    let plots = rec.frames.len() >= 2;
    if plots && rec.frames.iter().any(|f| !f.tau.is_empty()) {
        let torque = rec
            .header
            .joint_names
            .iter()
            .map(|j| {
                let origin = path(&["plots", "torque", j]).to_string();
                view("TimeSeries", format!("τ {j}"), origin)
            })
            .collect();
        tabs.push(Node::Container {
            kind: bc::ContainerKind::Grid,
            name: Some("torque".into()),
            children: torque,
            shares: Vec::new(),
        });
    }
    if plots && rec.frames.iter().any(|f| !f.q.is_empty()) {
        tabs.push(view("TimeSeries", "joint positions", "/plots/q"));
    }
    tabs.push(view("TextLog", "log", "/log"));
    tabs.push(view("TextDocument", "reports", "/reports"));
    Node::Container {
        kind: bc::ContainerKind::Horizontal,
        name: None,
        children: vec![
            scene,
            Node::Container {
                kind: bc::ContainerKind::Tabs,
                name: None,
                children: tabs,
                shares: Vec::new(),
            },
        ],
        shares: vec![3.0, 2.0],
    }
}

/// Sends the blueprint of `rec` to `stream` and makes it the active and default one.
/// `hidden`: entity paths left out of the 3-D view; `eye`: its camera (default: Rerun's).
pub fn send(
    stream: &RecordingStream,
    rec: &Recording,
    hidden: &[&str],
    eye: Option<Eye>,
) -> Result<(), RerunError> {
    send_layout(stream, &layout(rec, hidden, eye))
}

/// The layout of a workspace picture: the 3-D view named `title` (without the entities
/// in `hidden`, with those in `invisible` present but switched off, camera `eye`) beside
/// the workspace report (`/reports/workspace`) and the text log.
pub fn send_workspace(
    stream: &RecordingStream,
    title: &str,
    hidden: &[&str],
    invisible: &[&str],
    eye: Eye,
) -> Result<(), RerunError> {
    let mut contents = vec!["+ $origin/**".to_string()];
    contents.extend(hidden.iter().map(|h| format!("- {h}")));
    let scene = Node::View {
        class: "3D",
        name: title.to_string(),
        origin: "/world".into(),
        contents,
        eye: Some(eye),
        invisible: invisible.iter().map(|s| s.to_string()).collect(),
    };
    let side = Node::Container {
        kind: bc::ContainerKind::Tabs,
        name: None,
        children: vec![
            view("TextDocument", "workspace", "/reports/workspace"),
            view("TextLog", "log", "/log"),
        ],
        shares: Vec::new(),
    };
    send_layout(
        stream,
        &Node::Container {
            kind: bc::ContainerKind::Horizontal,
            name: None,
            children: vec![scene, side],
            shares: vec![3.0, 1.0],
        },
    )
}

/// Sends the blueprint whose root is `root` and makes it the active and default one.
fn send_layout(stream: &RecordingStream, root: &Node) -> Result<(), RerunError> {
    let (bps, storage) = RecordingStreamBuilder::new(APP_ID)
        .recording_id(RecordingId::random())
        .blueprint()
        .memory()
        .map_err(sdk)?;
    bps.set_time_sequence("blueprint", 0);
    let (_, root) = log_node(&bps, root)?;
    bps.log(
        "viewport",
        &bp::ViewportBlueprint::new()
            .with_root_container(bc::RootContainer(root.into()))
            .with_auto_views(false),
    )
    .map_err(sdk)?;
    bps.flush_blocking().map_err(sdk)?;
    let msgs: Vec<LogMsg> = storage.take();
    let Some(id) = msgs.first().map(|m| m.store_id().clone()) else {
        return Err(RerunError::Sdk("empty blueprint".into()));
    };
    stream.send_blueprint(
        msgs,
        BlueprintActivationCommand {
            blueprint_id: id,
            make_active: true,
            make_default: true,
        },
    );
    Ok(())
}
