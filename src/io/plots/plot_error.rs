//! Why a picture could not be made ([`PlotError`]): plotters refused to draw, or the PNG
//! encoder failed. The messages are the ones the plot writers always gave (`plot: …`,
//! `png: …`).

/// A failed drawing or PNG encoding.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlotError {
    /// plotters refused to draw (the backend's message).
    #[error("plot: {0}")]
    Draw(String),
    /// The PNG encoder failed (its message).
    #[error("png: {0}")]
    Png(String),
}

impl PlotError {
    /// A drawing error from plotters' error `e`.
    pub fn draw(e: impl std::fmt::Display) -> Self {
        PlotError::Draw(e.to_string())
    }

    /// A PNG encoding error from the encoder's error `e`.
    pub fn png(e: impl std::fmt::Display) -> Self {
        PlotError::Png(e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use crate::io::plots::plot_error::PlotError;

    #[test]
    fn messages_keep_their_prefix() {
        assert_eq!(PlotError::draw("no room").to_string(), "plot: no room");
        assert_eq!(PlotError::png("bad size").to_string(), "png: bad size");
    }
}
