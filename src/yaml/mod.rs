//! The located-YAML base every input format is read with: a YAML value tree in which every node
//! remembers its file, line and column ([`value`]); typed deserialization from it with located
//! errors ([`de`]); diagnostics in rustc's style ([`diag`]); did-you-mean suggestions
//! ([`suggest`]); the keys a section takes, read from the struct that declares it
//! ([`field_names`]); range-checked unit parsers for metres, seconds and `deg(..)` angles
//! ([`units`]); and reading input files with hard limits ([`read_limited`]).
//!
//! Tree files ([`crate::spec`]), scene files ([`crate::scene`]) and scenario files
//! (`crate::suite`) are all read through it; it depends on nothing else in the crate but the
//! robot's constants in [`crate::motion`] (for the reach and joint-limit checks).

pub mod bounds;
pub mod de;
pub mod diag;
mod fields;
mod ident;
mod read;
pub mod suggest;
mod table_pose;
pub mod units;
pub mod value;

pub use bounds::Bounds;
pub use diag::{Diagnostic, Issue, Loc, MAX_FIELD_CHARS, Sources, cut_text, short_number};
pub use fields::field_names;
pub use ident::is_identifier;
pub use read::read_limited;
pub use table_pose::TablePose;
