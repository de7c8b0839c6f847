//! The paper's accumulator study: the selection method of Section 4.3
//! ([`accumulator_design`]); the precharge sweep of Section 5.2 joins it.

pub mod accumulator_design;
