//! Pictures as PNG bytes (plotters): the shared line panels and bar charts
//! ([`panels`]), readable axis ticks ([`ticks`]), the torque-check chart
//! ([`torque_chart`]), the cam and gear-pair pictures ([`machine_plots`]), and why a
//! picture failed ([`plot_error`]).
pub mod machine_plots;
pub mod panels;
pub mod plot_error;
pub mod ticks;
pub mod torque_chart;
