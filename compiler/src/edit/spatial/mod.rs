//! Spatial (`dimension = 3`) files in `dofplan edit`: shown, not edited.
//! The page draws them in a view it orbits, pans and zooms itself; the
//! server sends the document (markers in 3D, the panels' texts, the sweep's
//! traces) and runs the plan at the sliders' values. Dragging and editing
//! stay planar-only.

mod document;
mod session;
#[cfg(test)]
mod tests;

pub use document::{Document, READ_ONLY};
pub use session::Session;
