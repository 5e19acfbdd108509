//! Planar files in `dofplan edit`: the mechanism open with its panels'
//! texts (`document`), its gear pairs and slots as the page draws them
//! (`gears`, `slots`), and one page's pose, sliders and drag (`session`).

pub mod document;
mod gears;
pub mod session;
mod slots;
