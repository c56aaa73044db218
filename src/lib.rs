//! orbcloud: molecular orbitals and electron densities as GPU-rendered clouds.
//!
//! Layers (see ARCHITECTURE.md): `model` ← `formats`, `scene` ← `gpu` ← `meshes`, `evaluate` ←
//! `layers` ← `headless`, `key_volumes` ← `app` ← `main`.

pub mod app;
pub mod arithmetic;
pub mod compute;
pub mod demo;
pub mod evaluate;
pub mod figure;
pub mod formats;
pub mod gpu;
pub mod headless;
pub mod info;
pub mod key_volumes;
pub mod layers;
pub mod meshes;
pub mod model;
pub mod movie;
pub mod plane;
pub mod scene;
pub mod shots;
