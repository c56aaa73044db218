//! Plane maps: a quantity on a square of points in any plane through a molecule, evaluated
//! exactly from its wavefunction (a cube file's values interpolated), with contour lines, drawn
//! as a PNG or SVG figure beside its numbers.
//!
//! geometry.rs: the plane and its points; values.rs: the quantity at them; levels.rs: which
//! contours; contour.rs: marching squares; colors.rs: colour scales; drawing.rs: the figure
//! laid out on a canvas, which raster.rs (PNG) and svg.rs (SVG) draw.

mod caption;
mod colors;
mod contour;
mod drawing;
mod geometry;
mod gradient;
mod levels;
mod raster;
mod svg;
mod values;

pub use caption::{potential_scale, scale_for, unit, where_text};
pub use colors::ColorScale;
pub use contour::{Polyline, contour};
pub use drawing::{MapPicture, NEAR_PLANE};
pub use geometry::{Frame, MAX_POINTS, Plane, atom_position};
pub use gradient::gradient_lines;
pub use levels::{Levels, auto_levels};
pub use raster::png;
pub use svg::svg;
pub use values::{PlaneMap, Sampling, VANISHING, evaluate};

/// Why a map cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum PlaneError {
    #[error("atom {index} does not exist: the molecule has {atoms} atoms, numbered from 1")]
    Atom { index: usize, atoms: usize },
    #[error("{0}: they span no plane")]
    Collinear(String),
    #[error("the plane's normal is zero (or not a number)")]
    ZeroNormal,
    #[error("{0} points per side: a map takes 2 to {MAX_POINTS}")]
    Points(usize),
    #[error("the extent must be positive, got {0:?} Å")]
    Extent([f64; 2]),
    #[error("{0}: its grid does not reach the plane (no point of the map lies inside it)")]
    OutsideGrid(String),
    #[error("the file holds no {0}")]
    Missing(String),
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::model::{Atom, Molecule};

    /// A map of x·y (both signs, a saddle at the centre) over a plane through three atoms.
    fn saddle() -> (Molecule, PlaneMap) {
        let atoms = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 6.0]]
            .iter()
            .zip([8, 1, 1, 6])
            .map(|(p, z)| Atom { z, charge: z as f64, position: DVec3::from_array(*p), ghost: false })
            .collect();
        let molecule = Molecule::new(atoms);
        let plane = Frame::through_atoms(&molecule, [1, 2, 3]).unwrap().rectangle(&molecule, None, 81, false).unwrap();
        let values = plane.points().iter().map(|p| p.x * p.y * 0.01).collect();
        (molecule, PlaneMap { plane, values, signed: true, sampling: Sampling::Exact })
    }

    #[test]
    fn the_svg_holds_each_contour_as_a_polyline_negative_ones_dashed() {
        let (molecule, map) = saddle();
        let levels = Levels::Auto.resolve(map.max_abs(), true);
        assert!(levels.contains(&0.0) && levels.iter().any(|&l| l < 0.0));
        let picture = MapPicture {
            map: &map,
            molecule: &molecule,
            levels: &levels,
            caption: vec!["x·y".into()],
            unit: "f".into(),
            scale: None,
            gradient_lines: false,
            bohr: false,
        };
        let text = svg(&picture);
        assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
        let contours: Vec<&str> = text.lines().filter(|l| l.contains(r#"class="contour""#)).collect();
        let expected: usize = levels.iter().map(|&l| contour(&map.values, 81, 81, l, 0.0).len()).sum();
        assert_eq!(contours.len(), expected);
        assert!(contours.len() > 10, "{} lines", contours.len());
        assert!(contours.iter().any(|l| l.contains("stroke-dasharray")), "negative levels dashed");
        assert!(contours.iter().any(|l| !l.contains("stroke-dasharray")));
        // The three atoms in the plane are marked and labelled; the one 6 bohr away is not.
        assert_eq!(text.matches(r#"class="atom""#).count(), 3);
        assert!(text.contains(">O1<") && text.contains(">H3<") && !text.contains(">C4<"));
        assert!(text.contains("data:image/png;base64,"));
    }

    #[test]
    fn a_nodal_plane_draws_no_contours_of_its_rounding_noise() {
        let (molecule, mut map) = saddle();
        let noise: Vec<f64> = (0..map.values.len()).map(|k| if k % 3 == 0 { 1e-17 } else { -1e-17 }).collect();
        map.values = noise;
        assert!(map.vanishes());
        let levels = Levels::Auto.resolve(map.max_abs(), true);
        assert!(!contour(&map.values, 81, 81, 0.0, 0.0).is_empty(), "noise alone would be contoured");
        let picture = MapPicture {
            map: &map,
            molecule: &molecule,
            levels: &levels,
            caption: vec![],
            unit: "f".into(),
            scale: None,
            gradient_lines: false,
            bohr: false,
        };
        let text = svg(&picture);
        assert!(!text.contains(r#"class="contour""#));
        assert!(text.contains("nodal plane"));
    }

    #[test]
    fn the_png_is_coloured_by_sign_with_dark_contours() {
        let (molecule, map) = saddle();
        let levels = [-0.01, 0.0, 0.01];
        let picture = MapPicture {
            map: &map,
            molecule: &molecule,
            levels: &levels,
            caption: vec!["x·y".into()],
            unit: "f".into(),
            scale: None,
            gradient_lines: false,
            bohr: false,
        };
        let img = png(&picture);
        let layout = picture.layout();
        assert_eq!(img.dimensions(), (layout.size[0], layout.size[1]));
        let [x0, y0, w, h] = layout.plot;
        // The saddle x·y is positive in the first quadrant of the plane (red) and negative in
        // the second (blue); u runs along x here and v along y.
        let ([cu, cv], _) = map.plane.project(DVec3::ZERO);
        let at = |u: f64, v: f64| {
            let [su, sv] = map.plane.size;
            let px = x0 + ((cu + u) / su + 0.5) * w;
            let py = y0 + (0.5 - (cv + v) / sv) * h;
            img.get_pixel(px as u32, py as u32).0
        };
        let red = at(3.5, 3.5);
        let blue = at(-3.5, 3.5);
        assert!(red[0] > red[2] + 60, "{red:?}");
        assert!(blue[2] > blue[0] + 60, "{blue:?}");
        let dark = img.pixels().filter(|p| p.0[0] < 80 && p.0[1] < 80 && p.0[2] < 80).count();
        assert!(dark > 500, "contours and text drawn: {dark} dark pixels");
    }
}
