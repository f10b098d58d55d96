//! The project as a whole: the module layers, tools/setup, a dependent crate, the Python package,
//! scale-out on a real Slurm.
//!
//! One test binary (`cargo test --release --test system`); one file per subject.

#[path = "../support/mod.rs"]
mod support;

mod dependent_crate;
mod module_layers;
mod python_package;
mod setup_script;
mod slurm_array;
