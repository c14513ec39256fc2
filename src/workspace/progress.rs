//! The progress bar: `indicatif` on standard error, drawn only when standard error is a
//! terminal, and never when the caller asks for quiet. The volume pass writes the current
//! estimate and interval into the bar's message after every doubling.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar over `len` samples labelled `label` (hidden when `quiet`).
pub(crate) fn bar(len: u64, quiet: bool, label: &'static str) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(
        "{prefix:>10} [{bar:30}] {percent:>3}% {human_pos}/{human_len} samples, {per_sec:0}, eta {eta} {msg}",
    ) {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_prefix(label);
    pb
}
