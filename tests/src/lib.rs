//! Independent reference implementations the tests compare `subtess` against.
//!
//! Nothing here calls the code under test: the expected numbers come from closed forms
//! (truncated-power B-splines), classical recurrences (Cox–de Boor, the box-spline recurrence) or brute-force
//! subdivision, each written from its textbook definition.

pub mod box_spline;
pub mod bspline;
pub mod butterfly_fan;
pub mod sqrt3_fan;
