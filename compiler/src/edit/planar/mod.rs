//! Planar files in `dofplan edit`: the mechanism open with its panels'
//! texts (`document`), and one page's pose, sliders and drag (`session`).

pub mod document;
pub mod session;
