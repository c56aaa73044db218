//! Unit conversions. The model is in bohr; files and users may speak ångström.

/// CODATA 2018 Bohr radius in ångström.
pub const ANGSTROM_PER_BOHR: f64 = 0.529_177_210_903;
pub const BOHR_PER_ANGSTROM: f64 = 1.0 / ANGSTROM_PER_BOHR;
/// Hartree in electronvolt (CODATA 2018).
pub const EV_PER_HARTREE: f64 = 27.211_386_245_988;
