//! The one integration-test binary: reference solutions, scenarios and the command line.

mod accelerations;
mod bulk_stress;
mod cli;
mod fatigue;
mod fuzz;
mod hybrid;
mod load_paths;
mod output_safety;
mod reference;
mod resume;
