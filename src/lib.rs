//! orbcloud: molecular orbitals and electron densities as GPU-rendered clouds.
//!
//! Layers (see ARCHITECTURE.md): `model` ← `formats`, `scene` ← `gpu` ← `headless` ← `app` ← `main`.

pub mod formats;
pub mod model;
