//! `sim bench …`: every benchmark of the command line, and the machine each ran on
//! ([`machine`]), which their JSON rows name.

pub mod batch;
pub mod facade;
pub mod localization;
pub mod machine;
pub mod matching;
pub mod profile;
pub mod record;
pub mod slam;
pub mod startup;
pub mod swarm;
