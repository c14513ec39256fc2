//! Analytic inverse kinematics (being written).
