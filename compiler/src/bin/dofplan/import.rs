//! `dofplan import`: a mechanism from another tool's file, written as a
//! dofplan mechanism file (the import itself is the library's,
//! `dofplan::import`).

use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;

/// The options of `dofplan import`.
#[derive(Args)]
pub struct ImportArgs {
    /// A file holding a Pyslvs (PMKS) expression, `M[J[...], ...]`,
    /// optionally followed by its input pairs in Pyslvs's tuple form:
    /// `((0, 1),)`, `((0, 1), (0, 2))`, `[(0, 1)]` or `(0, 1)`, with or
    /// without a comma after the expression.
    pub file: PathBuf,
    /// An input pair B,D: turn the link that carries points PB and PD about
    /// PB; B,B slides the P or RP point PB along its slot. Repeat the
    /// option for more inputs; given, they replace the pairs in FILE.
    #[arg(long = "input", value_name = "B,D", value_parser = parse_pair)]
    inputs: Vec<(usize, usize)>,
    /// The mechanism's name (default: FILE's name without its extension,
    /// with every character but letters, digits, `_` and `-` made `_`).
    #[arg(long)]
    name: Option<String>,
    /// Write the mechanism file here instead of standard output.
    #[arg(long, value_name = "OUT.toml")]
    out: Option<PathBuf>,
}

/// Parses "B,D" into an input pair.
fn parse_pair(text: &str) -> Result<(usize, usize), String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [b, d] = parts.as_slice() else {
        return Err(format!("expected B,D (two point indices), got `{text}`"));
    };
    let index = |s: &str| {
        s.parse::<usize>()
            .map_err(|_| format!("`{s}` is not a point's index (0, 1, 2, …)"))
    };
    Ok((index(b)?, index(d)?))
}

/// The default name: the file's stem, as a name every output of dofplan
/// takes (a generated module's name, a file name).
fn default_name(file: &Path) -> String {
    let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned());
    let name: String = (stem.unwrap_or_default().chars())
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if name.is_empty() {
        "imported".into()
    } else {
        name
    }
}

/// Runs `dofplan import`.
pub fn run(args: ImportArgs, out: &mut dyn Write) -> io::Result<ExitCode> {
    let place = args.file.display().to_string();
    let text = match std::fs::read_to_string(&args.file) {
        Ok(t) => t,
        Err(e) => {
            super::error(
                &place,
                &format!("cannot read it: {e}"),
                "give a file holding a Pyslvs expression `M[...]`",
            );
            return Ok(ExitCode::FAILURE);
        }
    };
    let name = args.name.clone().unwrap_or_else(|| default_name(&args.file));
    let inputs = (!args.inputs.is_empty()).then_some(args.inputs.as_slice());
    let imported = match dofplan::import::import_pmks(&place, &text, inputs, &name) {
        Ok(i) => i,
        Err(e) => {
            super::report(&e.render(super::colour()));
            return Ok(ExitCode::FAILURE);
        }
    };
    for note in &imported.notes {
        super::report(&format!("{place}: note: {note}"));
    }
    let Some(path) = &args.out else {
        write!(out, "{}", imported.toml)?;
        return Ok(ExitCode::SUCCESS);
    };
    if let Err(e) = std::fs::write(path, &imported.toml) {
        super::report(&format!("{}: error: cannot write the file: {e}", path.display()));
        return Ok(ExitCode::FAILURE);
    }
    let m = &imported.mechanism;
    writeln!(
        out,
        "wrote {}: {} bodies, {} joints, {} input(s)",
        path.display(),
        m.bodies.len(),
        m.joints.len(),
        m.inputs.len()
    )?;
    Ok(ExitCode::SUCCESS)
}
