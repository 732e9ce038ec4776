//! fretsim (crate docs to be completed).
#![warn(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod analytical;
pub mod app;
pub mod cli;
pub mod contact;
pub mod error;
pub mod halfplane;
pub mod material;
pub mod output;
pub mod quadrature;
pub mod scenario;
