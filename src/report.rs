//! What a scenario runner returns: the JSON document and the human summary. A leaf
//! module, so the runners ([`crate::arm`], [`crate::mechanism`], [`crate::drivetrain`])
//! do not import the dispatcher ([`crate::scenario`]) that calls them.

/// What a scenario run produced.
#[derive(Debug, Clone)]
pub struct Report {
    /// The JSON document `armsim run --json` prints.
    pub json: serde_json::Value,
    /// The human-readable summary.
    pub text: String,
}
