//! Producing pictures: rendering without a window, the frames of movies, figures that stand
//! alone (captions, supersampling, transparency) and the files movies are written to.

pub mod figure;
pub mod headless;
pub mod movie;
pub mod shots;
