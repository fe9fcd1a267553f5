//! End-to-end tests live in tests/tests/; the architecture rules (tests/tests/architecture.rs)
//! use the module graph built here.

pub mod module_graph;
