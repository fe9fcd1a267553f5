//! The simulator's ECS vocabulary and every system, layered bottom-up:
//! `core` ← `world` ← `raycast`/`body` ← `sensors` ← `matching` ← `localization` ←
//! `mapping`/`navigation`/`eval`.
//! Nothing lower imports anything higher (see systems/ARCHITECTURE.md, "Layers of `systems`").
//!
//! Each feature folder exposes one [`core::schedule::SimPlugin`] that adds its systems to the
//! right [`core::schedule::SimSet`]; the `sim` crate composes them from a scenario.

pub mod body;
pub mod core;
pub mod eval;
pub mod localization;
pub mod mapping;
pub mod matching;
pub mod navigation;
pub mod prelude;
pub mod raycast;
pub mod robot;
pub mod sensors;
pub mod world;
