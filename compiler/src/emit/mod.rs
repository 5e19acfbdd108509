//! The Rust back end: a plan IR becomes one straight-line module per
//! mechanism (tokens by `quote`, checked by `syn`, laid out by
//! `prettyplease`).
//!
//! Every step becomes one block calling the same runtime function the
//! interpreter calls, under a comment holding the step's number,
//! explanation, the joints it serves and the lines they are written on
//! (`fourbar.toml:28`). Planar plans are written by `planar`, spatial
//! ones by `spatial`, with the same files for the same roles (`step`,
//! `rates`, `cluster`); what every module has whatever its dimension (the
//! constants, `State`, the `body` and `marker` modules, `Plan` and its
//! trait impls, the rates API) is written once, by `scaffold`, and
//! constant arithmetic is folded by `fold`. This module holds what both
//! use: the entry points, identifiers and literals, the step comments,
//! and the `Sink` the module's items are laid out into, one at a time.

use std::collections::HashMap;
use std::fmt::Write;

use proc_macro2::{Ident, Literal, TokenStream};
use quote::quote;

mod constants;
mod fold;
mod names;
mod planar;
mod scaffold;
mod spatial;
mod uses;

pub use planar::{CHUNK_WEIGHT, FIXED_LIMIT};
pub use spatial::spatial_cluster_fits;

use crate::plan::Plan;

/// A Rust identifier made from a user's name ("coupler.C" → `coupler_c`).
pub fn ident_for(name: &str) -> String {
    let mut s = names::word(name, false);
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert_str(0, "m_");
    }
    if syn::parse_str::<Ident>(&s).is_err() {
        s.push('_'); // a keyword
    }
    s
}

fn lit(x: f64) -> Literal {
    Literal::f64_unsuffixed(x)
}

fn index(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

/// Rust source of the compiled plan module of `plan`.
///
/// ```
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../mechanisms/fourbar.toml");
/// let m = dofplan::load_file(std::path::Path::new(path))?;
/// let plan = dofplan::analysis::analyse(&m).plan?;
/// let code = dofplan::emit::emit(&plan);
/// // One module: its constants, its state and the straight-line `solve`,
/// // each step's comment citing the joint and the file line it serves.
/// assert!(code.contains("pub fn solve("));
/// assert!(code.contains("[joint C]  (fourbar.toml:"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn emit(plan: &Plan) -> String {
    emit_chunked(plan, CHUNK_WEIGHT)
}

/// [`emit`] with functions of at most `chunk_weight` tokens of steps
/// instead of [`CHUNK_WEIGHT`] (1 puts every step in a function of its
/// own: tests use it to check the split form on small mechanisms).
pub fn emit_chunked(plan: &Plan, chunk_weight: usize) -> String {
    planar::module(plan, chunk_weight)
}

/// Rust source of `pub mod design` for the module [`emit`] writes of
/// `plan`, to be appended to it: `Params` (with `Params::DRAWN`),
/// `prepare(&Params) -> Result<Geometry, PrepareError>` and
/// `solve_with(&Geometry, …)`, the plan's numbers computed from the design
/// parameters of `table` (see [`crate::plan::design`]).
///
/// # Errors
/// A plan with a numeric cluster (compiled for closed-form plans only), or
/// one whose numbers the table does not describe: the reason.
pub fn emit_design(plan: &Plan, table: &crate::plan::design::DesignTable<2>) -> Result<String, String> {
    planar::design_module(plan, table)
}

/// Rust source of `pub mod forces` for the module [`emit`] writes of
/// `plan`, to be appended to it: the force table `table` (the runtime's,
/// as `forces::planar::describe` and the force plan make it) as constants
/// and `solve_forces`; `slots` is the mechanism's number of pins in slots,
/// whose unknowns follow the inputs' in the table (then one per gear pair,
/// as many as the table's `leaning`).
///
/// # Errors
/// A table without blocks (reactions by least squares): the reason.
pub fn emit_forces(
    plan: &Plan,
    table: &dofplan_runtime::planar::forces::Table,
    slots: usize,
) -> Result<String, String> {
    planar::forces_module(plan, table, slots)
}

/// Rust source of the compiled plan module of the spatial plan `plan`.
///
/// A numeric cluster is written over fixed-size matrices whatever its
/// size; see [`spatial_cluster_fits`] for the sizes that compile well.
///
/// # Panics
/// On a drag's plan (`numeric::spatial::drag_plan`): its cluster is solved
/// by task priority, which only the interpreter has. The analysis never
/// makes one.
pub fn emit_spatial(plan: &crate::plan::spatial::Plan) -> String {
    emit_spatial_chunked(plan, CHUNK_WEIGHT)
}

/// [`emit_spatial`] with functions of at most `chunk_weight` tokens of
/// steps (1 puts every step in a function of its own: tests use it to
/// check the split form on small mechanisms).
///
/// # Panics
/// As [`emit_spatial`].
pub fn emit_spatial_chunked(plan: &crate::plan::spatial::Plan, chunk_weight: usize) -> String {
    spatial::module(plan, chunk_weight)
}

/// Every step's comment (see [`step_comment`]), from each step's serves
/// and explanation. The joints' lines are indexed by name once, so a plan
/// of n steps over m joints costs n + m lookups, not n × m comparisons
/// (a 20,000-loop chain has 60,000 of each).
fn step_comments<'a>(
    steps: impl Iterator<Item = (&'a [String], String)>,
    source: &str,
    joint_lines: &[(String, usize)],
) -> Vec<String> {
    // A later entry of the same origin wins, as the scan it replaces did.
    let origins: HashMap<&str, usize> = joint_lines.iter().map(|(o, l)| (o.as_str(), *l)).collect();
    steps
        .enumerate()
        .map(|(i, (serves, text))| step_comment(i, &text, serves, source, &origins))
        .collect()
}

/// A step's comment: its number (as the plan lists it, from 0), its
/// explanation, what it serves and, for a plan read from a file, the
/// lines of the joints it serves (`fourbar.toml:14, 23`).
fn step_comment(
    i: usize,
    text: &str,
    serves: &[String],
    source: &str,
    origins: &HashMap<&str, usize>,
) -> String {
    let mut out = format!("{i}: {text}");
    if !serves.is_empty() {
        let _ = write!(out, "  [{}]", serves.join(", "));
    }
    let mut lines: Vec<usize> = Vec::new();
    for s in serves {
        if let Some(line) = joint_line(s, origins).filter(|l| !lines.contains(l)) {
            lines.push(line);
        }
    }
    if !lines.is_empty() {
        let lines: Vec<String> = lines.iter().map(usize::to_string).collect();
        let _ = write!(out, "  ({source}:{})", lines.join(", "));
    }
    out
}

/// The line of the joint a serve names ("joint B coincident" names the
/// origin "joint B"): the longest origin the serve starts with, ending at
/// a space or at the serve's end.
fn joint_line(serve: &str, origins: &HashMap<&str, usize>) -> Option<usize> {
    let ends = serve.match_indices(' ').map(|(k, _)| k).chain([serve.len()]);
    let ends: Vec<usize> = ends.collect();
    ends.into_iter()
        .rev()
        .find_map(|end| origins.get(&serve[..end]).copied())
}

/// The generated module's text, written item by item: each item is parsed
/// by `syn` and laid out by `prettyplease` as soon as it is made, so that
/// only one item's tokens and syntax tree are held at a time.
struct Sink {
    /// Each step's comment, made once (see [`step_comment`]).
    comments: Vec<String>,
    /// Comments inside steps (a cluster's rows), by the index their
    /// placeholder `__dofplan_note!(i)` names.
    notes: Vec<String>,
    out: String,
}

impl Sink {
    /// A module that starts with `header` and whose step `i` is marked by
    /// `comments[i]`.
    fn new(header: String, comments: Vec<String>) -> Sink {
        Sink {
            comments,
            notes: Vec::new(),
            out: header,
        }
    }

    /// The module's text.
    fn finish(self) -> String {
        self.out
    }

    /// Appends the module `head { first items }` (`head`: its attributes,
    /// visibility and name), each of `items` already laid out one level
    /// inside it (see [`constants`]).
    fn push_module(&mut self, head: TokenStream, first: TokenStream, items: impl Iterator<Item = String>) {
        let text = Self::lay_out(quote!(#head { #first __dofplan_items!(); }));
        let (before, after) =
            (text.split_once("    __dofplan_items!();\n")).expect("the module holds its items' mark");
        self.out.push_str(before);
        items.for_each(|item| self.out.push_str(&item));
        self.out.push_str(after);
    }

    /// The items of `tokens` laid out by prettyplease.
    fn lay_out(tokens: TokenStream) -> String {
        let file = syn::parse2::<syn::File>(tokens).expect("the emitter produces valid Rust");
        prettyplease::unparse(&file)
    }

    /// Appends the items of `tokens`, laid out, with `rows` (a rolled
    /// run's table, a row a line) in place of their `__dofplan_rows!()`.
    fn push_with_rows(&mut self, tokens: TokenStream, rows: &str) {
        let pretty = Self::lay_out(tokens);
        let (before, after) = pretty
            .split_once("__dofplan_rows!()")
            .expect("a rolled run's module holds its table");
        let indent = before
            .rsplit('\n')
            .next()
            .map_or(0, |line| line.len() - line.trim_start().len());
        let mut text = String::with_capacity(pretty.len() + rows.len() + rows.len() / 40 * (indent + 4));
        text.push_str(before);
        text.push_str("[\n");
        for row in rows.lines() {
            text.extend(std::iter::repeat_n(' ', indent + 4));
            text.push_str(row);
            text.push('\n');
        }
        text.extend(std::iter::repeat_n(' ', indent));
        text.push(']');
        text.push_str(after);
        self.push_laid_out(&text);
    }

    /// Appends the items of `tokens`, laid out.
    fn push(&mut self, tokens: TokenStream) {
        let pretty = Self::lay_out(tokens);
        self.push_laid_out(&pretty);
    }

    /// Appends laid-out items, each step's mark replaced by its comment.
    fn push_laid_out(&mut self, pretty: &str) {
        // Comments are not tokens: each step (and each note) was marked by
        // a macro call that is replaced here by its comment.
        for line in pretty.lines() {
            let trimmed = line.trim_start();
            let indent = &line[..line.len() - trimmed.len()];
            if let Some(rest) = trimmed.strip_prefix("__dofplan_step!(") {
                let i: usize = rest.trim_end_matches(");").parse().expect("step marker");
                let _ = writeln!(self.out, "{indent}// {}", self.comments[i]);
            } else if let Some(rest) = trimmed.strip_prefix("__dofplan_note!(") {
                let i: usize = rest.trim_end_matches(");").parse().expect("note marker");
                let _ = writeln!(self.out, "{indent}// {}", self.notes[i]);
            } else {
                self.out.push_str(line);
                self.out.push('\n');
            }
        }
    }
}
