//! orbcloud: molecular orbitals and electron densities as GPU-rendered clouds.
//!
//! Layers, each using only those before it (see ARCHITECTURE.md): `model` ← `formats`, `scene`
//! ← `gpu` ← `evaluate` ← `sources`, `layers` ← `pictures` ← `plane` ← `app`, `cli` ← `main.rs`.

pub mod app;
pub mod cli;
pub mod evaluate;
pub mod formats;
pub mod gpu;
pub mod layers;
pub mod model;
pub mod pictures;
pub mod plane;
pub mod scene;
pub mod sources;
