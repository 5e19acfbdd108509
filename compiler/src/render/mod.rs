//! Pictures of a mechanism's motion, as standalone SVG.
//!
//! [`render`] draws a simulated sweep or a drag: the mechanism at a few
//! poses, the path of every traced marker through every frame (split at
//! breaks, thinned to what the page shows, with an arrow of motion and the
//! marker's name), stretched poses dashed, the drag target, a scale bar, a
//! title and a legend.
//!
//! The parts, by concern:
//! - `view`: the world box, the world-to-page transform, the scale bar;
//! - [`planar`]: the ground, the bodies and pins of one pose (`mechanism`), the
//!   drag target and its path (`target`), and the whole picture;
//! - `trace`: runs between breaks, thinning, arrows, labels;
//! - `legend`: the capped legend;
//! - `marks`: marked points (a synthesis's targets), in either dimension;
//! - `caption`: which poses to draw, the title and subtitle;
//! - `style`: colours and number formatting;
//! - [`spatial`]: spatial (3D) mechanisms in four views of one scale (front,
//!   side, top, isometric), built from the same parts.
//!
//! The drawing stands on its own (no scripts, no external styles). World
//! coordinates have y up; points are transformed here (y flipped) so that
//! text stays upright and every length given in pixels (line widths, pivot
//! symbols) is independent of the mechanism's scale. The output is
//! deterministic and numbers carry at most two decimals. Elements carry a
//! `class` (`trace`, `arrow`, `trace-label`, `scale-bar`, `target`,
//! `pose stretched`, `legend`, ...) so that tests and style sheets can find
//! them.

mod caption;
mod legend;
mod marks;
pub mod planar;
#[cfg(feature = "plots")]
pub mod plots;
pub mod spatial;
mod style;
mod trace;
mod view;

#[cfg(test)]
mod tests;

pub use planar::{render, SvgOptions};
pub use spatial::{render_spatial, render_spatial_with, SpatialFrame};
