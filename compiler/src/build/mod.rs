//! The `build.rs` API: compile mechanism files into plan modules, as
//! prost-build does for protobuf files.
//!
//! ```no_run
//! // build.rs
//! fn main() -> Result<(), Box<dyn std::error::Error>> {
//!     dofplan::build::Config::new().compile_dir("mechanisms")?;
//!     Ok(())
//! }
//! ```
//! and in the crate: `include!(concat!(env!("OUT_DIR"), "/mechanisms.rs"));`
//!
//! Planar and spatial (`dimension = 3`) files compile side by side into
//! the same `mechanisms.rs`: each is a module, and the index picks one by
//! name at run time (`driver` for planar mechanisms, `spatial_driver` for
//! spatial ones; `source` for either).

use std::fmt;
use std::path::{Path, PathBuf};

use crate::analysis::{analyse, PlanError};
use crate::conflict::{load_any, load_file};
use crate::emit::{emit, emit_spatial, ident_for, spatial_cluster_fits};
use crate::model::spatial::Mechanism as SpatialMechanism;
use crate::model::{is_spatial_file, Mechanism, Model, ModelError};
use crate::numeric::planar::drag::carriage;

/// Why a build failed.
///
/// Its `Debug` form is its `Display` form: a `build.rs` written as
/// `fn main() -> Result<(), Box<dyn Error>>` prints the error with `{:?}`,
/// and must show the same `file:line:col` diagnostic as the CLI, not the
/// error's fields (which hold the whole file's text).
pub enum BuildError {
    /// A file is invalid.
    Model(ModelError),
    /// A file has no plan.
    Plan {
        /// The file.
        file: PathBuf,
        /// Why.
        error: PlanError,
    },
    /// A spatial file has no plan.
    SpatialPlan {
        /// The file.
        file: PathBuf,
        /// Why.
        error: crate::analysis::spatial::PlanError,
    },
    /// A spatial plan's numeric cluster is too large for the fixed-size
    /// matrices of generated code (see
    /// [`spatial_cluster_fits`]).
    ClusterTooLarge {
        /// The file.
        file: PathBuf,
        /// The cluster's step (1-based, as `dofplan plan` numbers it).
        step: usize,
        /// Its unknowns.
        unknowns: usize,
        /// Its equations.
        equations: usize,
    },
    /// Reading a directory or writing output failed.
    Io {
        /// The path involved.
        path: PathBuf,
        /// The error.
        error: std::io::Error,
    },
    /// Two files give the same module name.
    DuplicateModule {
        /// The module name.
        module: String,
        /// The two files.
        files: [PathBuf; 2],
    },
    /// `OUT_DIR` is not set and no output directory was given.
    NoOutDir,
    /// A design module cannot be compiled for a file (see
    /// [`Config::design`]).
    Design {
        /// The file.
        file: PathBuf,
        /// Why.
        why: String,
    },
    /// A forces module cannot be compiled for a file (see
    /// [`Config::forces`]).
    Forces {
        /// The file.
        file: PathBuf,
        /// Why.
        why: String,
    },
    /// A drag names a marker the file does not have, or one on a fixed
    /// body.
    Drag {
        /// The file.
        file: PathBuf,
        /// The marker as given.
        marker: String,
        /// Why.
        why: String,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BuildError::Model(e) => write!(f, "{}", e.render(false)),
            BuildError::Plan { file, error } => write!(f, "{}: {error}", file.display()),
            BuildError::SpatialPlan { file, error } => write!(f, "{}: {error}", file.display()),
            BuildError::ClusterTooLarge {
                file,
                step,
                unknowns,
                equations,
            } => write!(
                f,
                "{}: step {step} is a numeric cluster of {unknowns} unknowns and {equations} equations; \
                 compiled spatial clusters hold at most {} of each (`dofplan plan` shows the step; \
                 run the file with the interpreter instead)",
                file.display(),
                crate::emit::FIXED_LIMIT
            ),
            BuildError::Io { path, error } => write!(f, "{}: {error}", path.display()),
            BuildError::DuplicateModule { module, files } => write!(
                f,
                "{} and {} both give the module name `{module}`; rename one mechanism",
                files[0].display(),
                files[1].display()
            ),
            BuildError::Drag { file, marker, why } => {
                write!(
                    f,
                    "{}: cannot compile a drag of `{marker}`: {why}",
                    file.display()
                )
            }
            BuildError::NoOutDir => {
                write!(f, "OUT_DIR is not set: call Config::out_dir or run from build.rs")
            }
            BuildError::Design { file, why } => {
                write!(f, "{}: cannot compile its design module: {why}", file.display())
            }
            BuildError::Forces { file, why } => {
                write!(f, "{}: cannot compile its forces module: {why}", file.display())
            }
        }
    }
}

impl fmt::Debug for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl std::error::Error for BuildError {}

/// Compiles mechanism files into Rust plan modules.
#[derive(Clone, Debug, Default)]
pub struct Config {
    out_dir: Option<PathBuf>,
    drags: Vec<(PathBuf, String)>,
    designs: Vec<PathBuf>,
    forces: Vec<PathBuf>,
}

impl Config {
    /// Output into `$OUT_DIR`.
    pub fn new() -> Config {
        Config::default()
    }

    /// Output into `dir` instead of `$OUT_DIR`.
    pub fn out_dir(&mut self, dir: impl Into<PathBuf>) -> &mut Config {
        self.out_dir = Some(dir.into());
        self
    }

    /// Also compiles a drag of `marker` ("body.marker") of the mechanism in
    /// `file`, planned like an input (see
    /// [`carriage`]): a module
    /// `<name>_drag_<body>_<marker>` whose two slide inputs are the
    /// target's offsets from the marker's drawn position. Meant for
    /// mechanisms with DOF to spare (an open chain); a target the plan
    /// cannot reach exactly breaks (use the limit or search policy; the
    /// library's `Drag` falls back to the closest approach instead).
    pub fn drag(&mut self, file: impl Into<PathBuf>, marker: impl Into<String>) -> &mut Config {
        self.drags.push((file.into(), marker.into()));
        self
    }

    /// Also writes, into the module of the planar mechanism in `file` (one
    /// of the files compiled), `pub mod design`: its design parameters
    /// (`Params`, with `Params::DRAWN`), `prepare(&Params)`, which makes a
    /// candidate drawing's `Geometry` once, and `solve_with(&Geometry, …)`,
    /// which runs the candidate's frames as `solve` runs the drawing's —
    /// for an optimisation loop of one's own (see the synthesis guide).
    /// Closed-form plans only.
    pub fn design(&mut self, file: impl Into<PathBuf>) -> &mut Config {
        self.designs.push(file.into());
        self
    }

    /// Also writes, into the module of the planar mechanism in `file` (one
    /// of the files compiled, with masses, gravity or loads), `pub mod
    /// forces`: `solve_forces`, a frame's positions, rates and forces in
    /// one pass without allocating (each joint's reaction, each input's
    /// force or torque, each slot's and gear pair's force, the force and
    /// moment on the ground, as `dofplan analyze --forces` gives them),
    /// and its `TABLE`. A
    /// mechanism whose reactions need least squares (redundant joints) is
    /// an error naming why.
    pub fn forces(&mut self, file: impl Into<PathBuf>) -> &mut Config {
        self.forces.push(file.into());
        self
    }

    /// Compiles every `.toml` and `.json` file of `dir` (sorted by name),
    /// planar or spatial, and the drags asked for.
    pub fn compile_dir(&self, dir: impl AsRef<Path>) -> Result<Vec<String>, BuildError> {
        let dir = dir.as_ref();
        let io = |error| BuildError::Io {
            path: dir.to_path_buf(),
            error,
        };
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(io)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("toml" | "json")))
            .collect();
        files.sort();
        println!("cargo:rerun-if-changed={}", dir.display());
        self.compile(&files)
    }

    /// Compiles the given files: one `<module>.rs` per mechanism and a
    /// `mechanisms.rs` that declares them all, plus `MECHANISMS` (the
    /// planar module names) and `driver(name, options)` to pick one at run
    /// time, and — when any file is spatial (`dimension = 3`) —
    /// `SPATIAL_MECHANISMS` and `spatial_driver(name, options)`; `source`
    /// covers both. Returns the module names (planar, then spatial).
    pub fn compile(&self, files: &[impl AsRef<Path>]) -> Result<Vec<String>, BuildError> {
        let out_dir = match &self.out_dir {
            Some(d) => d.clone(),
            None => std::env::var_os("OUT_DIR")
                .map(PathBuf::from)
                .ok_or(BuildError::NoOutDir)?,
        };
        // Every file read is named to cargo before any is read, so that
        // fixing any of them (not only the first broken one) reruns the
        // build script.
        let read = files
            .iter()
            .map(|f| f.as_ref())
            .chain(self.drags.iter().map(|(f, _)| f.as_path()));
        for file in read {
            println!("cargo:rerun-if-changed={}", file.display());
        }
        let (mut mechanisms, spatial) = load_files(files)?;
        for d in &self.designs {
            if !mechanisms.iter().any(|(f, _)| same_file(f, d)) {
                let why = if spatial.iter().any(|(f, _)| same_file(f, d)) {
                    "design modules are compiled for planar mechanisms only so far"
                } else {
                    "the file is not among the files compiled"
                };
                return Err(BuildError::Design {
                    file: d.clone(),
                    why: why.to_string(),
                });
            }
        }
        for d in &self.forces {
            if !mechanisms.iter().any(|(f, _)| same_file(f, d)) {
                let why = if spatial.iter().any(|(f, _)| same_file(f, d)) {
                    "forces modules are compiled for planar mechanisms only so far (`dofplan analyze --forces` takes spatial files)"
                } else {
                    "the file is not among the files compiled"
                };
                return Err(BuildError::Forces {
                    file: d.clone(),
                    why: why.to_string(),
                });
            }
        }
        self.load_drags(&mut mechanisms)?;
        // Each module's name and source, planar first: the name is checked
        // against every module before it, of either dimension.
        let mut modules = Modules {
            out_dir: &out_dir,
            written: Vec::new(),
            designs: &self.designs,
            forces: &self.forces,
        };
        for (file, m) in &mechanisms {
            modules.add_planar(file, m)?;
        }
        for (file, m) in &spatial {
            modules.add_spatial(file, m)?;
        }
        let all = modules.written;
        write_if_changed(
            &out_dir.join("mechanisms.rs"),
            &index_text(&all, mechanisms.len()),
        )?;
        Ok(all.iter().map(|(m, _, _)| m.clone()).collect())
    }

    /// Loads each drag's file and adds the drag's carriage mechanism (see
    /// [`carriage`]) to `mechanisms`.
    fn load_drags(&self, mechanisms: &mut Loaded<Mechanism>) -> Result<(), BuildError> {
        for (file, marker) in &self.drags {
            let m = load_file(file).map_err(BuildError::Model)?;
            let why = |why: &str| BuildError::Drag {
                file: file.clone(),
                marker: marker.clone(),
                why: why.to_string(),
            };
            let id = m
                .find_marker(marker)
                .ok_or_else(|| why("no such marker (write body.marker)"))?;
            if m.bodies[id.body].fixed {
                return Err(why("the marker is on a fixed body"));
            }
            let c = carriage(&m, id).ok_or_else(|| why("the mechanism has no fixed body"))?;
            mechanisms.push((file.clone(), c));
        }
        Ok(())
    }
}

/// Whether two paths name one file (as written, or once resolved).
fn same_file(a: &Path, b: &Path) -> bool {
    a == b || matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
}

/// A module written: its name, the file it is compiled from, and the
/// `<module>.rs` it is written to.
type Written = (String, PathBuf, PathBuf);

/// Mechanisms with the files they are loaded from.
type Loaded<M> = Vec<(PathBuf, M)>;

/// Loads the files, planar and spatial apart, each in the order given.
fn load_files(
    files: &[impl AsRef<Path>],
) -> Result<(Loaded<Mechanism>, Loaded<SpatialMechanism>), BuildError> {
    let mut mechanisms = Vec::new();
    let mut spatial = Vec::new();
    for file in files {
        let file = file.as_ref();
        // Planar files keep their own loader (and its diagnostics);
        // only a file that says `dimension = 3` goes the spatial way.
        if is_spatial_file(file) {
            match load_any(file).map_err(BuildError::Model)? {
                Model::Spatial(m) => spatial.push((file.to_path_buf(), m)),
                Model::Planar(m) => mechanisms.push((file.to_path_buf(), m)),
            }
        } else {
            mechanisms.push((file.to_path_buf(), load_file(file).map_err(BuildError::Model)?));
        }
    }
    Ok((mechanisms, spatial))
}

/// `pub mod forces` of the planar mechanism `m` (from `file`), planned as
/// `plan`: its force table, as the interpreter solves it, emitted.
fn forces_module(file: &Path, m: &Mechanism, plan: &crate::plan::Plan) -> Result<String, BuildError> {
    use crate::forces::planar::{describe, force_plan, runtime_blocks};
    let why = |why: &str| BuildError::Forces {
        file: file.to_path_buf(),
        why: why.to_string(),
    };
    if m.loads.is_empty() {
        return Err(why(
            "the file gives no masses, gravity or loads, so every force is 0",
        ));
    }
    let forces = force_plan(m).ok_or_else(|| why("its primitive constraints carry no reactions yet"))?;
    let described = describe(m);
    let blocks = runtime_blocks(&forces);
    crate::emit::emit_forces(plan, &described.table(&blocks), m.slots.len()).map_err(|e| why(&e))
}

/// The modules written so far into `out_dir`.
struct Modules<'a> {
    out_dir: &'a Path,
    written: Vec<Written>,
    /// The files whose modules get a design module.
    designs: &'a [PathBuf],
    /// The files whose modules get a forces module.
    forces: &'a [PathBuf],
}

impl Modules<'_> {
    /// Plans and emits a planar mechanism.
    fn add_planar(&mut self, file: &Path, m: &Mechanism) -> Result<(), BuildError> {
        let plan = analyse(m).plan.map_err(|error| BuildError::Plan {
            file: file.to_path_buf(),
            error,
        })?;
        let mut source = emit(&plan);
        if self.designs.iter().any(|d| same_file(d, file)) {
            let why = |why: String| BuildError::Design {
                file: file.to_path_buf(),
                why,
            };
            let design = crate::synth::planar::Design::new(m).map_err(|e| why(e.to_string()))?;
            source.push_str(&crate::emit::emit_design(&plan, &design.table()).map_err(why)?);
        }
        if self.forces.iter().any(|d| same_file(d, file)) {
            source.push_str(&forces_module(file, m, &plan)?);
        }
        self.add(ident_for(&m.name), file, source)
    }

    /// Plans and emits a spatial mechanism, whose numeric clusters must fit
    /// the fixed-size matrices of generated code.
    fn add_spatial(&mut self, file: &Path, m: &SpatialMechanism) -> Result<(), BuildError> {
        let plan = crate::analysis::spatial::analyse(m).map_err(|error| BuildError::SpatialPlan {
            file: file.to_path_buf(),
            error,
        })?;
        if let Err((step, unknowns, equations)) = spatial_cluster_fits(&plan) {
            return Err(BuildError::ClusterTooLarge {
                file: file.to_path_buf(),
                step,
                unknowns,
                equations,
            });
        }
        self.add(ident_for(&m.name), file, emit_spatial(&plan))
    }

    /// Writes a module's source, unless a module before it, of either
    /// dimension, has its name.
    fn add(&mut self, module: String, file: &Path, source: String) -> Result<(), BuildError> {
        if let Some((_, other, _)) = self.written.iter().find(|(n, _, _)| *n == module) {
            return Err(BuildError::DuplicateModule {
                module,
                files: [other.clone(), file.to_path_buf()],
            });
        }
        let out = self.out_dir.join(format!("{module}.rs"));
        write_if_changed(&out, &source)?;
        self.written.push((module, file.to_path_buf(), out));
        Ok(())
    }
}

/// The text of `mechanisms.rs`: every module declared (the first `planar`
/// of `all` planar, the others spatial) and the index items that pick one
/// by name.
fn index_text(all: &[Written], planar: usize) -> String {
    let mut index = String::from("// @generated by dofplan — do not edit.\n\n");
    for (module, file, out) in all {
        index.push_str(&format!(
            "/// Compiled from `{}`.\n#[allow(clippy::approx_constant, clippy::excessive_precision, clippy::unreadable_literal, clippy::large_const_arrays)]\npub mod {module} {{\n    include!({:?});\n\n    /// The generated source of this module (for review and drift tests).\n    pub const SOURCE: &str = include_str!({:?});\n}}\n\n",
            file.file_name().map_or_else(|| file.display().to_string(), |f| f.to_string_lossy().into_owned()),
            out.display().to_string(),
            out.display().to_string()
        ));
    }
    // Spatial modules come after every planar one. The planar index
    // items name planar modules only (their drivers animate planar
    // poses), so a build without spatial files writes what it always
    // did.
    let (modules, spatial_modules) = all.split_at(planar);
    let names: Vec<String> = modules.iter().map(|(m, _, _)| format!("{m:?}")).collect();
    index.push_str(&format!(
        "/// The names of the compiled mechanisms.\npub const MECHANISMS: &[&str] = &[{}];\n\n",
        names.join(", ")
    ));
    index.push_str(
        "/// A driver for the compiled mechanism `name`, behind a trait object.\npub fn driver(name: &str, options: dofplan_runtime::Options) -> Option<Box<dyn dofplan_runtime::Animate>> {\n    match name {\n",
    );
    for (module, _, _) in modules {
        index.push_str(&format!(
            "        {module:?} => Some(Box::new(dofplan_runtime::Driver::new({module}::Plan, options))),\n"
        ));
    }
    index.push_str("        _ => None,\n    }\n}\n\n");
    index.push_str("/// The generated source of the compiled mechanism `name`.\npub fn source(name: &str) -> Option<&'static str> {\n    match name {\n");
    for (module, _, _) in all {
        index.push_str(&format!("        {module:?} => Some({module}::SOURCE),\n"));
    }
    index.push_str("        _ => None,\n    }\n}\n\n");
    index.push_str(
        "/// Evaluates `$body` with `$plan` bound to the compiled plan of the mechanism\n/// named `$name`, monomorphised per mechanism (no trait object): `Some(value)`,\n/// or `None` for an unknown name.\n#[macro_export]\nmacro_rules! with_plan {\n    ($name:expr, |$plan:ident| $body:expr) => {\n        match $name {\n",
    );
    for (module, _, _) in modules {
        index.push_str(&format!(
            "            {module:?} => {{\n                let $plan = $crate::{module}::Plan;\n                Some($body)\n            }}\n"
        ));
    }
    index.push_str("            _ => None,\n        }\n    };\n}\n");
    if !spatial_modules.is_empty() {
        spatial_index(&mut index, spatial_modules);
    }
    index
}

/// The index items of spatial modules: `SPATIAL_MECHANISMS`,
/// `spatial_driver` and `with_spatial_plan!`, as the planar ones.
fn spatial_index(index: &mut String, modules: &[(String, PathBuf, PathBuf)]) {
    let names: Vec<String> = modules.iter().map(|(m, _, _)| format!("{m:?}")).collect();
    index.push_str(&format!(
        "\n/// The names of the compiled spatial mechanisms.\npub const SPATIAL_MECHANISMS: &[&str] = &[{}];\n\n",
        names.join(", ")
    ));
    index.push_str(
        "/// A driver for the compiled spatial mechanism `name`, behind a trait object.\npub fn spatial_driver(name: &str, options: dofplan_runtime::Options) -> Option<Box<dyn dofplan_runtime::Animate<dofplan_runtime::spatial::Pose3>>> {\n    match name {\n",
    );
    for (module, _, _) in modules {
        index.push_str(&format!(
            "        {module:?} => Some(Box::new(dofplan_runtime::Driver::new({module}::Plan, options))),\n"
        ));
    }
    index.push_str("        _ => None,\n    }\n}\n\n");
    index.push_str(
        "/// Evaluates `$body` with `$plan` bound to the compiled plan of the spatial\n/// mechanism named `$name`, monomorphised per mechanism (no trait object):\n/// `Some(value)`, or `None` for an unknown name.\n#[macro_export]\nmacro_rules! with_spatial_plan {\n    ($name:expr, |$plan:ident| $body:expr) => {\n        match $name {\n",
    );
    for (module, _, _) in modules {
        index.push_str(&format!(
            "            {module:?} => {{\n                let $plan = $crate::{module}::Plan;\n                Some($body)\n            }}\n"
        ));
    }
    index.push_str("            _ => None,\n        }\n    };\n}\n");
}

/// Leaves an unchanged file alone so dependants are not rebuilt.
fn write_if_changed(path: &Path, text: &str) -> Result<(), BuildError> {
    if std::fs::read_to_string(path).is_ok_and(|old| old == text) {
        return Ok(());
    }
    std::fs::write(path, text).map_err(|error| BuildError::Io {
        path: path.to_path_buf(),
        error,
    })
}
