//! End-to-end tests: scenario in, metrics and files out. One test binary (every binary links
//! rerun, so few binaries keep builds short).

mod ackermann;
mod batch;
mod blocked_by_person;
mod carmen;
mod common;
mod determinism;
mod events;
mod layout;
mod localization;
mod mcap;
mod navigation;
mod park;
mod park_scenarios;
mod people;
mod physics;
mod recording;
mod replay;
mod scenarios;
mod sensors;
mod slam;
mod sonar;
