//! Design synthesis: parameters, candidates and the derivatives with
//! respect to the dimensions, checked against hand derivations and central
//! differences.

mod gradients;
mod recovery;
mod spatial_gradients;
mod spatial_recovery;
mod tolerance;
