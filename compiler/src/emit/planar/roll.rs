//! Runs of repeated steps as one loop over a table of their numbers.
//!
//! A large plan is usually a pattern repeated: a chain of four-bar loops is
//! the same three steps (a circle intersection, two placements) two
//! thousand times, with other numbers and other bodies. Written out, every
//! repetition is its own machine code (about 560 bytes a step), so a frame
//! of the 2,000-loop chain ran through 3.4 MB of instructions, more than
//! the processor's caches hold, and the compiled plan was slower than the
//! interpreter, whose few kilobytes of code stay cached. Rolled, the
//! repeated steps are written once, as the body of a loop over a table
//! (`ROWS`) with one row of numbers (`row.f`: coordinates, radii) and
//! indices (`row.i`: bodies, branch slots, step numbers) per repetition:
//! the same runtime calls on the same numbers as the steps written out,
//! in the same order, so the frames are the same to the last bit.
//!
//! A run is found from the code itself: each step is written once more
//! with its constants taken out ([`Recording`]), and a run is a stretch of
//! groups of one to [`MAX_PERIOD`] steps whose code is the same group for
//! group, at least [`MIN_ROWS`] times. A group may hand the points it
//! computes only to its own later steps (each repetition's points are the
//! loop body's locals), and it may read only its own; poses are read and
//! written in the state itself. Only the split form of large plans is
//! rolled (see [`chunk`](super::chunk)): a plan that fits one function is
//! already faster compiled than interpreted.

use std::ops::Range;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use std::fmt::Write;

use super::uses::{param, Uses};
use super::{lit, Emitter, Sink};
use crate::plan::StepKind;

/// The fewest repetitions rolled into a loop: fewer are written out.
pub const MIN_ROWS: usize = 4;

/// The most steps one repetition of a run has.
pub const MAX_PERIOD: usize = 16;

/// A stretch of steps that repeat with a period.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Run {
    /// The steps, `period` times the number of rows.
    pub steps: Range<usize>,
    /// Steps per repetition.
    pub period: usize,
}

impl Run {
    /// The number of repetitions (rows of the table).
    pub fn rows(&self) -> usize {
        self.steps.len() / self.period
    }
}

/// How the points computed by steps are named while a step is recorded.
#[derive(Clone, Copy, Debug)]
enum TempNames {
    /// By how many steps before the step at hand they are computed: a
    /// step's code then reads the same wherever it stands.
    Back(usize),
    /// By their step's place in the repetition starting at this step.
    From(usize),
}

/// A step's code being written with its constants taken out into a row.
#[derive(Clone, Debug)]
pub(super) struct Recording {
    /// The numbers, in the order the code names them.
    f: Vec<f64>,
    /// The indices (bodies, branch slots, step numbers), in order.
    i: Vec<u32>,
    temps: TempNames,
    /// Whether steps are marked for their comments.
    markers: bool,
    /// The points the code names (computed or read).
    named: Vec<usize>,
}

impl Recording {
    fn new(temps: TempNames, markers: bool) -> Recording {
        Recording {
            f: Vec::new(),
            i: Vec::new(),
            temps,
            markers,
            named: Vec::new(),
        }
    }
}

/// One row of a run's table: the numbers and indices of one repetition.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Row {
    f: Vec<f64>,
    i: Vec<u32>,
}

impl Emitter<'_> {
    /// `f` run with the constants of the code it writes recorded in `rec`.
    fn recorded<T>(&self, rec: Recording, f: impl FnOnce(&Self) -> T) -> (T, Recording) {
        *self.row.borrow_mut() = Some(rec);
        let out = f(self);
        let rec = self
            .row
            .borrow_mut()
            .take()
            .expect("the recording is still there");
        (out, rec)
    }

    /// A number of the code: a literal, or the next number of the row.
    pub(super) fn lit(&self, x: f64) -> TokenStream {
        match self.row.borrow_mut().as_mut() {
            Some(rec) => {
                let n = Literal::usize_unsuffixed(rec.f.len());
                rec.f.push(x);
                quote!(row.f[#n])
            }
            None => {
                let l = lit(x);
                quote!(#l)
            }
        }
    }

    /// A point of the code (`[x, y]`), each coordinate as [`Self::lit`].
    pub(super) fn point_lit(&self, p: [f64; 2]) -> TokenStream {
        let (x, y) = (self.lit(p[0]), self.lit(p[1]));
        quote!([#x, #y])
    }

    /// An index of the code (a body, a branch slot): a literal, or the
    /// next index of the row.
    pub(super) fn index(&self, i: usize) -> TokenStream {
        match self.row.borrow_mut().as_mut() {
            Some(rec) => {
                let n = Literal::usize_unsuffixed(rec.i.len());
                rec.i
                    .push(u32::try_from(i).expect("fewer than 2^32 bodies and branch slots"));
                quote!(row.i[#n] as usize)
            }
            None => {
                let l = Literal::usize_unsuffixed(i);
                quote!(#l)
            }
        }
    }

    /// A step's number, as the runtime's calls take it (`StepId`).
    pub(super) fn step_id(&self, i: usize) -> TokenStream {
        match self.row.borrow_mut().as_mut() {
            Some(rec) => {
                let n = Literal::usize_unsuffixed(rec.i.len());
                rec.i.push(u32::try_from(i).expect("fewer than 2^32 steps"));
                quote!(row.i[#n])
            }
            None => {
                let l = Literal::u32_unsuffixed(i as u32);
                quote!(#l)
            }
        }
    }

    /// The mark a step's comment replaces (see `Sink::push`).
    pub(super) fn step_marker(&self, i: usize) -> TokenStream {
        if self.row.borrow().as_ref().is_some_and(|rec| !rec.markers) {
            return quote!();
        }
        let l = Literal::u32_unsuffixed(i as u32);
        quote!(__dofplan_step!(#l);)
    }

    /// The local holding the point a step computes.
    pub(super) fn temp(&self, t: usize) -> Ident {
        match self.row.borrow_mut().as_mut() {
            Some(rec) => {
                rec.named.push(t);
                let at = self.temp_steps[t];
                match rec.temps {
                    TempNames::Back(step) => format_ident!("point_back_{}", step - at),
                    TempNames::From(first) => format_ident!("point_{}", at - first),
                }
            }
            None => self.temp_idents[t].clone(),
        }
    }

    /// The local a step binds a marker's world point to (`prelude` holds
    /// the step's earlier ones): named after the marker, or by its place
    /// when recorded, where the marker changes from row to row.
    pub(super) fn local_point(&self, name: &str, prelude: &[TokenStream]) -> Ident {
        if self.row.borrow().is_some() {
            format_ident!("p{}", prelude.len())
        } else {
            format_ident!("{}", super::point_ident(name))
        }
    }

    /// A body's pose while recorded: the state's entry (the working poses
    /// on jets), by the row's index.
    pub(super) fn rolled_pose(&self, body: usize) -> Option<TokenStream> {
        self.row.borrow().as_ref()?;
        let b = self.index(body);
        Some(match (self.jets, self.plan.bodies[body].fixed) {
            (false, _) => quote!(s.poses[#b]),
            (true, true) => {
                let t = self.num();
                quote!(Pose::<#t>::cst(s.poses[#b]))
            }
            (true, false) => quote!(w.poses[#b]),
        })
    }

    /// The runs of the plan's steps worth rolling, in order, disjoint.
    pub(super) fn runs(&self) -> Vec<Run> {
        let plan = self.plan;
        let n = plan.steps.len();
        // Each step's code with its constants out, and the points it names.
        let mut keys: Vec<Option<String>> = Vec::with_capacity(n);
        let mut named: Vec<Vec<usize>> = Vec::with_capacity(n);
        for (i, step) in plan.steps.iter().enumerate() {
            if matches!(step.kind, StepKind::Cluster { .. }) {
                // A cluster's rows and parameters are code, not numbers.
                keys.push(None);
                named.push(Vec::new());
                continue;
            }
            let (code, rec) = self.recorded(Recording::new(TempNames::Back(i), false), |e| e.step(i));
            keys.push(Some(code.to_string()));
            named.push(rec.named);
        }
        let mut last_use = vec![0; plan.temps.len()];
        for (i, ts) in named.iter().enumerate() {
            for &t in ts {
                last_use[t] = last_use[t].max(i);
            }
        }
        // Whether the group of `p` steps from `g` reads and hands on its own
        // points only.
        let closed = |g: usize, p: usize| {
            (g..g + p).all(|i| {
                keys[i].is_some()
                    && named[i]
                        .iter()
                        .all(|&t| self.temp_steps[t] >= g && last_use[t] < g + p)
            })
        };
        let same = |a: usize, b: usize, p: usize| (0..p).all(|j| keys[a + j] == keys[b + j]);
        let mut runs = Vec::new();
        let mut start = 0;
        while start < n {
            let mut best: Option<Run> = None;
            for p in 1..=MAX_PERIOD.min(n - start) {
                if !closed(start, p) {
                    continue;
                }
                let mut rows = 1;
                while start + (rows + 1) * p <= n
                    && same(start, start + rows * p, p)
                    && closed(start + rows * p, p)
                {
                    rows += 1;
                }
                let covers = rows * p;
                if rows >= MIN_ROWS && best.as_ref().is_none_or(|b| covers > b.steps.len()) {
                    best = Some(Run {
                        steps: start..start + covers,
                        period: p,
                    });
                }
            }
            match best {
                Some(run) => {
                    start = run.steps.end;
                    runs.push(run);
                }
                None => start += 1,
            }
        }
        runs
    }

    /// The code of one repetition of `run` and the table's rows.
    fn rolled_body(&self, run: &Run) -> (TokenStream, Vec<Row>) {
        let p = run.period;
        let group = |first: usize, markers: bool| {
            self.recorded(Recording::new(TempNames::From(first), markers), |e| {
                let code: Vec<TokenStream> = (first..first + p).map(|i| e.step(i)).collect();
                quote!(#(#code)*)
            })
        };
        let (marked, _) = group(run.steps.start, true);
        let mut body = None;
        let mut rows = Vec::with_capacity(run.rows());
        for first in run.steps.clone().step_by(p) {
            let (code, rec) = group(first, false);
            let code = code.to_string();
            match &body {
                None => body = Some(code),
                Some(b) => assert_eq!(
                    b, &code,
                    "the steps of a rolled run are the same code in every row"
                ),
            }
            rows.push(Row { f: rec.f, i: rec.i });
        }
        (marked, rows)
    }

    /// The module `name` of a rolled run, into `sink`: its table `ROWS`
    /// and its function `run`, called by `solve` (or on jets by
    /// `solve_rates`) as a chunk. The jets' function reads the values'
    /// table when the rows are the same (they are for every kind of step
    /// so far: both write the same constants in the same order).
    pub(super) fn rolled_chunk(&self, run: &Run, name: &Ident, doc: &str, sink: &mut Sink) {
        let (body, rows) = self.rolled_body(run);
        let uses = Uses::of(&body);
        let mut take = Vec::new();
        for field in ["branches", "last"] {
            if uses.has(field) {
                let f = format_ident!("{}", field);
                take.push(if self.jets {
                    quote!(let #f = &mut w.#f;)
                } else {
                    quote!(let #f = &mut s.#f;)
                });
            }
        }
        let mut reads_inputs = uses.has("inputs");
        for k in 0..self.plan.inputs.len() {
            if uses.has(&self.input_idents[k].to_string()) {
                take.push(self.bind_input(k));
                reads_inputs = true;
            }
        }
        let inputs = param("inputs", reads_inputs);
        let ctx = param("ctx", uses.has("ctx"));
        let (first, last, period) = (run.steps.start, run.steps.end - 1, run.period);
        let run_doc = format!(
            " Steps {first} to {last}: the {period} steps of the loop {} times, with the numbers (`row.f`) and \
             indices (`row.i`: bodies, branch slots, step numbers) of one row of [`ROWS`] each. The comments \
             in the loop are those of the first row's steps.",
            crate::format::thousands(run.rows())
        );
        let signature = if self.jets {
            let w = param("w", uses.has("w") || take.iter().any(|t| Uses::of(t).has("w")));
            let s = param("s", uses.has("s"));
            quote!(pub(super) fn run(#s: &State, #w: &mut JetWorking<'_>, #inputs: &[Jet2], #ctx: &mut Ctx) -> Result<(), RateError>)
        } else {
            quote!(pub(super) fn run(s: &mut State, _w: &mut Working, #inputs: &[f64], #ctx: &mut Ctx) -> Result<(), Break>)
        };
        let function = quote! {
            #[doc = #run_doc]
            #[inline(never)]
            #signature {
                #(#take)*
                // Opaque to the optimiser: it knows a static's rows, and
                // unrolled a loop of a few dozen of them fully, constants
                // folded in, which took LLVM 40 s for one 24-row loop.
                for row in core::hint::black_box(&ROWS) {
                    #body
                }
                Ok(())
            }
        };
        let shared = self.jets
            && self
                .tables
                .borrow()
                .get(&first)
                .is_some_and(|(_, values)| *values == rows);
        if shared {
            let values = &self.tables.borrow()[&first].0;
            return sink.push(quote! {
                #[doc = #doc]
                mod #name {
                    use super::*;
                    use super::#values::ROWS;

                    #function
                }
            });
        }
        let (nf, ni, nr) = (
            Literal::usize_unsuffixed(rows[0].f.len()),
            Literal::usize_unsuffixed(rows[0].i.len()),
            Literal::usize_unsuffixed(rows.len()),
        );
        let table_doc = format!(" One row per repetition of steps {first} to {last}, in order.");
        let module = quote! {
            #[doc = #doc]
            mod #name {
                use super::*;

                /// The numbers and indices of one repetition.
                pub(super) struct Row {
                    pub(super) f: [f64; #nf],
                    pub(super) i: [u32; #ni],
                }

                #[doc = #table_doc]
                pub(super) static ROWS: [Row; #nr] = __dofplan_rows!();

                #function
            }
        };
        // The table as text, a row a line: through `syn` and `prettyplease`
        // a 20,000-row table took more time and memory than the rest of
        // the module (a line per number).
        let mut table = String::with_capacity(rows.len() * (24 * rows[0].f.len() + 8 * rows[0].i.len() + 24));
        for r in &rows {
            table.push_str("Row { f: [");
            for (k, x) in r.f.iter().enumerate() {
                if k > 0 {
                    table.push_str(", ");
                }
                let _ = write!(table, "{}", lit(*x));
            }
            table.push_str("], i: [");
            for (k, x) in r.i.iter().enumerate() {
                if k > 0 {
                    table.push_str(", ");
                }
                let _ = write!(table, "{x}");
            }
            table.push_str("] },\n");
        }
        sink.push_with_rows(module, &table);
        if !self.jets {
            self.tables.borrow_mut().insert(first, (name.clone(), rows));
        }
    }
}
