//! Where documents come from besides the files a user opens: the bundled demos and the
//! wavefunctions computed with PySCF, and saved sessions.

pub mod compute;
pub mod demo;
pub mod session;
