//! Runs four-bar-rs's own path synthesis (differential evolution on its
//! elliptical-Fourier-descriptor objective, `syn::FbSyn`, closed mode) on a
//! target CSV and prints its final four-bar as one JSON line: the objective it
//! reports, the wall time, the linkage's parameters and the pose of its five
//! points at one crank angle on the branch the synthesis chose, so that
//! dofplan can draw and re-check the same mechanism.
//!
//! Usage: four-bar-peer TARGET.csv [--seed N] [--pop N] [--gen N] [--res N]
use four_bar::mech::{CurveGen, Statable};
use four_bar::{mh, syn, FourBar};
use std::time::Instant;

fn read_targets(path: &str) -> Vec<[f64; 2]> {
    let text = std::fs::read_to_string(path).expect("cannot read the target file");
    let mut pts = Vec::new();
    for line in text.lines() {
        let line = line.split('#').next().unwrap().trim();
        if line.is_empty() {
            continue;
        }
        let nums: Vec<f64> = line.split(',').filter_map(|s| s.trim().parse().ok()).collect();
        if nums.len() >= 2 {
            // x,y (free timing); a leading input column is ignored.
            let n = nums.len();
            pts.push([nums[n - 2], nums[n - 1]]);
        }
    }
    pts
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut path = None;
    let (mut seed, mut pop, mut gen, mut res) = (1u64, 400usize, 200u64, 180usize);
    let mut i = 1;
    while i < args.len() {
        let val = || args.get(i + 1).expect("missing value").clone();
        match args[i].as_str() {
            "--seed" => { seed = val().parse().unwrap(); i += 1; }
            "--pop" => { pop = val().parse().unwrap(); i += 1; }
            "--gen" => { gen = val().parse().unwrap(); i += 1; }
            "--res" => { res = val().parse().unwrap(); i += 1; }
            p => path = Some(p.to_string()),
        }
        i += 1;
    }
    let targets = read_targets(&path.expect("usage: four-bar-peer TARGET.csv [--seed N]"));
    let t0 = Instant::now();
    let func = syn::FbSyn::from_curve(targets.clone(), syn::Mode::Closed).res(res);
    let harmonic = func.harmonic();
    let s = mh::Solver::build(mh::De::default(), func)
        .seed(seed)
        .pop_num(pop)
        .task(|ctx| ctx.gen == gen)
        .solve();
    let (err, fb): (f64, FourBar) = s.into_err_result();
    let seconds = t0.elapsed().as_secs_f64();
    // The pose to draw: crank angle 0 if the crank turns fully (Closed mode
    // only accepts those), else the middle of its range; on the branch the
    // synthesis chose (fb.inv()).
    let bound = fb.angle_bound();
    let full = matches!(bound, four_bar::mech::AngleBound::Closed);
    let t = match bound.to_value() {
        Some([a, b]) if !full => 0.5 * (a + b),
        _ => 0.0,
    };
    let pose = fb.pos(t);
    let pts = |p: Option<[[f64; 2]; 5]>| match p {
        Some(js) => format!(
            "[{}]",
            js.iter().map(|q| format!("[{:e},{:e}]", q[0], q[1])).collect::<Vec<_>>().join(",")
        ),
        None => "null".to_string(),
    };
    println!(
        "{{\"tool\":\"four-bar-rs 7.0.5\",\"seed\":{seed},\"pop\":{pop},\"gen\":{gen},\"res\":{res},\
         \"harmonic\":{harmonic},\"objective\":{err:e},\"seconds\":{seconds},\
         \"type\":\"{}\",\"stat\":\"{}\",\"inv\":{},\"angle_bound\":\"{:?}\",\"pose_angle\":{t:e},\
         \"params\":{{\"p1x\":{:e},\"p1y\":{:e},\"a\":{:e},\"l1\":{:e},\"l2\":{:e},\"l3\":{:e},\"l4\":{:e},\"l5\":{:e},\"g\":{:e}}},\
         \"pose\":{}}}",
        fb.ty().name(),
        fb.stat(),
        fb.inv(),
        bound,
        fb.unnorm.p1x, fb.unnorm.p1y, fb.unnorm.a, fb.l1, fb.unnorm.l2, fb.l3, fb.l4, fb.l5, fb.g,
        pts(pose),
    );
}
