use dofplan_runtime::{BranchPolicy, Ctx, Driver, Options};
use std::hint::black_box;
use std::time::Instant;
fn main() {
    let n = 36_100_000;
    let inputs: Vec<f64> = (0..361).map(|i| i as f64).collect();
    for _ in 0..3 {
        let mut s = dofplan_generated::fourbar::State::DRAWN;
        let t = Instant::now();
        for k in 0..n {
            let mut ctx = Ctx::new(BranchPolicy::Keep, false);
            let _ = black_box(dofplan_generated::fourbar::solve(
                &mut s,
                &[inputs[k % 361]],
                &mut ctx,
            ));
        }
        println!("raw solve {:.1} ns", t.elapsed().as_secs_f64() * 1e9 / n as f64);
        let mut d = Driver::new(dofplan_generated::fourbar::Plan, Options::default());
        let t = Instant::now();
        for k in 0..n {
            black_box(d.frame(&[inputs[k % 361]]));
        }
        println!(
            "typed driver {:.1} ns",
            t.elapsed().as_secs_f64() * 1e9 / n as f64
        );
    }
}
