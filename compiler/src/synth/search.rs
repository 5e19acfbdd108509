//! The search, for either dimension: differential evolution over the box
//! of the varied parameters (metaheuristics-nature's `De`, seeded, its
//! population evaluated on all cores), whose best candidates are polished
//! by Levenberg–Marquardt with the exact Jacobian. The constraints are
//! kept as penalties in the global search (a candidate that breaks one
//! ranks behind every one that keeps them all) and as a condition on every
//! step the polish takes.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use metaheuristics_nature as mh;
use nalgebra::{DMatrix, DVector};

/// A synthesis problem as the search sees it.
pub trait Objective: Sync {
    /// The box of the varied parameters: the global search's variables.
    fn bounds(&self) -> &[[f64; 2]];
    /// The global search's fitness of the varied parameters `x`: the error
    /// plus penalties (see [`penalised`]). By default (no constraints, no
    /// unknowns but the parameters) the residuals' sum of squares.
    fn fitness(&self, x: &[f64]) -> f64 {
        self.residuals(x, false).map_or(FAILED, |(r, _)| r.norm_squared())
    }
    /// The polish's unknowns for `x`: the parameters, then any further
    /// unknowns of the problem (free timing's input values), started from
    /// where `x` puts them; `None` for a candidate that fails. By default
    /// the parameters alone.
    fn start(&self, x: &[f64]) -> Option<Vec<f64>> {
        Some(x.to_vec())
    }
    /// The residuals at the polish's unknowns `z` (the error is their sum
    /// of squares) and, when asked, their exact Jacobian; `None` for a
    /// candidate that fails.
    fn residuals(&self, z: &[f64], jacobian: bool) -> Option<(DVector<f64>, Option<DMatrix<f64>>)>;
    /// Whether the constraints hold at `z` (by default there are none).
    fn feasible(&self, _z: &[f64]) -> bool {
        true
    }
}

/// A fitness that keeps every candidate meeting the constraints ahead of
/// every one that does not: `error` when `violation` is 0, else a
/// constant far above any error plus the violation.
pub fn penalised(error: f64, violation: f64) -> f64 {
    if violation > 0.0 {
        PENALTY * (1.0 + violation)
    } else {
        error
    }
}

/// The fitness of a candidate that cannot be planned or breaks at a target.
pub const FAILED: f64 = PENALTY * 1e6;

const PENALTY: f64 = 1e12;

/// How the search runs and when it stops.
#[derive(Clone, Debug)]
pub struct Options {
    /// The seed: the same seed, problem and options give the same result
    /// (with the same number of threads).
    pub seed: u64,
    /// Stop after this long.
    pub time_limit: Duration,
    /// Stop after this many evaluations (the global search's and the
    /// polish's): a budget that, unlike the time limit, gives the same
    /// result on any machine.
    pub evaluations: Option<usize>,
    /// Stop once a polished candidate's sum of squares is at most this.
    pub target: f64,
    /// The population (default: ten per variable, 40 to 200).
    pub population: Option<usize>,
    /// Restart from a new population when the best fitness has not
    /// improved by a relative 1e-6 for this many generations.
    pub stagnation: u64,
    /// Polish the best candidate every this many generations.
    pub polish_every: u64,
    /// How many distinct solutions to return.
    pub keep: usize,
    /// Set from another thread to stop the search at the next generation.
    pub cancel: Option<Arc<AtomicBool>>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            seed: 1,
            time_limit: Duration::from_secs(10),
            evaluations: None,
            target: 0.0,
            population: None,
            stagnation: 100,
            polish_every: 10,
            keep: 5,
            cancel: None,
        }
    }
}

/// Why the search stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// A polished candidate reached the target error.
    Target,
    /// The time limit.
    Time,
    /// No progress for [`Options::stagnation`] generations (the last
    /// restart's; the search restarts until the time limit, so this is
    /// only reported when nothing else stopped it).
    Stagnation,
    /// Cancelled through [`Options::cancel`].
    Cancelled,
    /// The evaluation budget ([`Options::evaluations`]).
    Budget,
}

/// A polished solution: the polish's unknowns and its sum of squares.
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    /// The unknowns (the varied parameters first).
    pub z: Vec<f64>,
    /// The sum of squared residuals.
    pub sum_sq: f64,
}

/// What the search found.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The best distinct solutions, best first (empty if no candidate
    /// could be polished).
    pub found: Vec<Found>,
    /// Fitness evaluations of the global search, plus residual
    /// evaluations of the polish.
    pub evaluations: usize,
    /// Generations of the global search, over every restart.
    pub generations: u64,
    /// Why it stopped.
    pub stop: Stop,
}

/// The search's progress, reported once a generation.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Generations done.
    pub generation: u64,
    /// The best sum of squares polished so far (infinite before one).
    pub best: f64,
    /// Time since the start.
    pub elapsed: Duration,
}

/// The global search's view of an [`Objective`].
struct Func<'a, O: ?Sized> {
    objective: &'a O,
    evaluations: &'a AtomicUsize,
}

impl<O: Objective + ?Sized> mh::Bounded for Func<'_, O> {
    fn bound(&self) -> &[[f64; 2]] {
        self.objective.bounds()
    }
}

impl<O: Objective + ?Sized> mh::ObjFunc for Func<'_, O> {
    type Ys = f64;
    fn fitness(&self, x: &[f64]) -> f64 {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        self.objective.fitness(x)
    }
}

/// Runs the search on `objective`: differential evolution until the
/// target, the time limit or a cancel; a run that stagnates has its best
/// candidates polished and the search restarts from a new population (the
/// next seed of a sequence the seed fixes).
pub fn run<O: Objective + ?Sized>(
    objective: &O,
    options: &Options,
    progress: &mut (dyn FnMut(Progress) + Send),
) -> Outcome {
    let clock = Clock {
        start: Instant::now(),
        deadline: Instant::now() + options.time_limit,
    };
    let evaluations = AtomicUsize::new(0);
    let polished: Mutex<Vec<Found>> = Mutex::new(Vec::new());
    let (mut generations, mut stop) = (0, Stop::Stagnation);
    for restart in 0u64.. {
        let seed = options
            .seed
            .wrapping_add(restart.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let (why, gens, pool) = one_run(
            objective,
            options,
            seed,
            &clock,
            &evaluations,
            &polished,
            progress,
        );
        generations += gens;
        stop = why;
        if why == Stop::Target || why == Stop::Cancelled {
            break;
        }
        // The run's final population: its best few polished too (a tenth
        // of the time limit past it at most: they are worth it).
        let mut ranked: Vec<(f64, &Vec<f64>)> = pool.iter().map(|x| (objective.fitness(x), x)).collect();
        ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
        let grace = clock.deadline + options.time_limit / 10;
        let mut found = polished.lock().expect("no panic holds it");
        for (_, x) in ranked.iter().take(3 * options.keep) {
            if let Some(f) = polish(objective, x, options.target, &evaluations, grace) {
                found.push(f);
            }
        }
        if why == Stop::Time || why == Stop::Budget || found.iter().any(|f| f.sum_sq <= options.target) {
            break;
        }
    }
    let found = distinct(
        polished.into_inner().expect("no panic holds it"),
        objective.bounds(),
        options.keep,
    );
    Outcome {
        found,
        evaluations: evaluations.into_inner(),
        generations,
        stop,
    }
}

/// When the search started and must stop.
struct Clock {
    start: Instant,
    deadline: Instant,
}

/// One run of differential evolution from a population seeded by `seed`,
/// polishing as it goes into `polished`: why it stopped, its generations
/// and its final population.
fn one_run<O: Objective + ?Sized>(
    objective: &O,
    options: &Options,
    seed: u64,
    clock: &Clock,
    evaluations: &AtomicUsize,
    polished: &Mutex<Vec<Found>>,
    progress: &mut (dyn FnMut(Progress) + Send),
) -> (Stop, u64, Vec<Vec<f64>>) {
    let dim = objective.bounds().len();
    let population = options.population.unwrap_or((10 * dim).clamp(40, 200));
    let mut stop = Stop::Stagnation;
    let mut last = (f64::INFINITY, 0u64);
    let mut generations = 0;
    let func = Func {
        objective,
        evaluations,
    };
    let solver = mh::Solver::build(mh::De::default(), func)
        .seed(seed)
        .pop_num(population)
        .task(|ctx| {
            generations = ctx.gen;
            let best = ctx.best.get_eval();
            if best < last.0 * (1.0 - 1e-6) {
                last = (best, ctx.gen);
            }
            let mut found = polished.lock().expect("no panic holds it");
            if ctx.gen % options.polish_every == 0 {
                // Besides the best, one other member in turn: the best
                // may sit in a basin whose floor is not the target's.
                let k = (ctx.gen / options.polish_every) as usize % ctx.pool.len();
                for x in [&ctx.pool[k][..], ctx.best.get_xs()] {
                    if let Some(f) = polish(objective, x, options.target, evaluations, clock.deadline) {
                        found.push(f);
                    }
                }
            }
            let best_polished = found.iter().map(|f| f.sum_sq).fold(f64::INFINITY, f64::min);
            progress(Progress {
                generation: ctx.gen,
                best: best_polished,
                elapsed: clock.start.elapsed(),
            });
            let cancelled = options.cancel.as_ref().is_some_and(|c| c.load(Ordering::Relaxed));
            let reason = if best_polished <= options.target {
                Some(Stop::Target)
            } else if cancelled {
                Some(Stop::Cancelled)
            } else if Instant::now() >= clock.deadline {
                Some(Stop::Time)
            } else if options
                .evaluations
                .is_some_and(|n| evaluations.load(Ordering::Relaxed) >= n)
            {
                Some(Stop::Budget)
            } else if ctx.gen - last.1 >= options.stagnation {
                Some(Stop::Stagnation)
            } else {
                None
            };
            if let Some(r) = reason {
                stop = r;
            }
            reason.is_some()
        })
        .solve();
    (stop, generations, solver.pool().to_vec())
}

/// The best `keep` of `found` that differ: two solutions whose varied
/// parameters are within 1e-3 of the box's width of each other are one.
fn distinct(mut found: Vec<Found>, bounds: &[[f64; 2]], keep: usize) -> Vec<Found> {
    found.sort_by(|a, b| a.sum_sq.total_cmp(&b.sum_sq));
    let mut out: Vec<Found> = Vec::new();
    for f in found {
        let same = out.iter().any(|o| {
            bounds
                .iter()
                .enumerate()
                .all(|(k, [lo, hi])| (o.z[k] - f.z[k]).abs() <= 1e-3 * (hi - lo).max(f64::MIN_POSITIVE))
        });
        if !same && out.len() < keep {
            out.push(f);
        }
    }
    out
}

/// Levenberg–Marquardt from the varied parameters `x`: steps on the
/// polish's unknowns with the exact Jacobian, each kept only if it lowers
/// the sum of squares and keeps the constraints, the parameters held in
/// their box, until `deadline`. `None` when the start itself fails.
pub fn polish<O: Objective + ?Sized>(
    objective: &O,
    x: &[f64],
    target: f64,
    evaluations: &AtomicUsize,
    deadline: Instant,
) -> Option<Found> {
    let mut z = objective.start(x)?;
    let bounds = objective.bounds();
    let (mut r, j) = objective.residuals(&z, true)?;
    let mut j = j?;
    evaluations.fetch_add(1, Ordering::Relaxed);
    let mut cost = r.norm_squared();
    if !objective.feasible(&z) {
        return None;
    }
    let mut lambda = 1e-3;
    for _ in 0..200 {
        if cost <= target || Instant::now() >= deadline {
            break;
        }
        let jt = j.transpose();
        let a = &jt * &j;
        let g = &jt * &r;
        let mut improved = false;
        while lambda < 1e14 {
            let mut m = a.clone();
            for i in 0..m.nrows() {
                m[(i, i)] += lambda * a[(i, i)].max(1e-12);
            }
            let Some(step) = m.cholesky().map(|c| c.solve(&(-&g))) else {
                lambda *= 10.0;
                continue;
            };
            let mut next = z.clone();
            for (k, v) in next.iter_mut().enumerate() {
                *v += step[k];
                if let Some([lo, hi]) = bounds.get(k) {
                    *v = v.clamp(*lo, *hi);
                }
            }
            evaluations.fetch_add(1, Ordering::Relaxed);
            match objective.residuals(&next, true) {
                Some((r2, Some(j2))) if r2.norm_squared() < cost && objective.feasible(&next) => {
                    let new_cost = r2.norm_squared();
                    let gain = cost - new_cost;
                    (z, r, j, cost) = (next, r2, j2, new_cost);
                    lambda = (lambda / 3.0).max(1e-12);
                    improved = gain > 1e-15 * cost.max(f64::MIN_POSITIVE) || cost <= target;
                    break;
                }
                _ => lambda *= 4.0,
            }
        }
        if !improved {
            break;
        }
    }
    Some(Found { z, sum_sq: cost })
}
