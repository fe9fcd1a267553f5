//! The `sim` command line, run as a user runs it: exit codes, error messages, flags, default
//! file names and printed output, one module per command (what the commands compute is tested
//! in the tests crate's end-to-end tests, through the library).

mod batch;
mod bench;
mod carmen;
mod common;
mod experiment;
mod faults;
mod interrupt;
mod matching;
mod replay;
mod report;
mod run;
mod schedule;
mod threads;
