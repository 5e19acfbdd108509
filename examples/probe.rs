use dofplan_runtime::{Driver, Options};
use std::hint::black_box;
fn main() {
    let n: usize = std::env::args().nth(1).map_or(361_000, |a| a.parse().unwrap());
    let inputs: Vec<f64> = (0..361).map(|i| i as f64).collect();
    let mut d = Driver::new(dofplan_generated::stress_50::Plan, Options::default());
    for k in 0..n {
        black_box(d.frame(&[inputs[k % 361]]));
    }
}
