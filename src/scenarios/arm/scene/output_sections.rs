//! The `[outputs]` section: where the files go and which are written (torque plot
//! format, report, CSV files, MCAP recording).

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::plots::torque_chart::PlotFormat;
use crate::scenarios::arm::scene::arm_scene::Outputs;
use crate::scenarios::arm::scene::section_reader::Sections;
use std::path::PathBuf;

/// The torque plot format (`None`: no plot).
pub(super) fn torque_plot(sx: &Sections) -> Result<Option<PlotFormat>, ScenarioError> {
    let cx = &sx.cx;
    let osec = sx.file.outputs.as_ref().map(|o| o.get_ref());
    let torque_plot = match osec.and_then(|o| o.torque_plot.as_ref()) {
        None => Some(crate::io::plots::torque_chart::PlotFormat::Png),
        Some(p) => match p.get_ref().as_str() {
            "png" => Some(crate::io::plots::torque_chart::PlotFormat::Png),
            "svg" => Some(crate::io::plots::torque_chart::PlotFormat::Svg),
            "none" => None,
            other => {
                return Err(cx.at(
                    p.span(),
                    "outputs.torque_plot",
                    format!("expected png, svg or none (got '{other}')"),
                ))
            }
        },
    };
    Ok(torque_plot)
}

/// The output settings.
pub(super) fn outputs(sx: &Sections, torque_plot: Option<PlotFormat>) -> Outputs {
    let osec = sx.file.outputs.as_ref().map(|o| o.get_ref());
    Outputs {
        dir: osec.and_then(|o| o.dir.clone()).map(PathBuf::from),
        torque_plot,
        report: osec.and_then(|o| o.report).unwrap_or(true),
        trajectory_csv: osec.and_then(|o| o.trajectory_csv).unwrap_or(false),
        simulation_csv: osec.and_then(|o| o.simulation_csv).unwrap_or(false),
        mcap: osec.and_then(|o| o.mcap).unwrap_or(true),
    }
}
