//! orbcloud: molecular orbitals and electron densities as GPU-rendered clouds.
//!
//! Layers (see ARCHITECTURE.md): `model` ← `formats`, `scene` ← `gpu` ← `headless` ← `app` ← `main`.

pub mod app;
pub mod demo;
pub mod formats;
pub mod gpu;
pub mod headless;
pub mod info;
pub mod model;
pub mod scene;
