//! Studies that measure armsim itself: the trade-offs report ([`tradeoffs`]: what
//! accuracy costs in time) and the micro-benchmarks behind `armsim bench` ([`bench`]).
pub mod bench;
pub mod tradeoffs;
