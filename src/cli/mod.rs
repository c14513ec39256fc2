//! Commands of the `armsim` binary that live in their own modules (src/main.rs parses the
//! command line and dispatches here).

pub mod plan;
pub mod plan_report;
pub mod plan_scenario;
