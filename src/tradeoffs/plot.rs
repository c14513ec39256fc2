//! The trade-offs report's charts: line panels and grouped bars from
//! [`crate::trajectory::panels`] (shared with the machine scenarios' pictures, which
//! import them from there so that `tradeoffs` may use the machine libraries).

pub use crate::trajectory::panels::*;
