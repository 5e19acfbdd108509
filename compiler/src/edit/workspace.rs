//! Construction, undo, saving and opening in `dofplan edit`: the document
//! the server shares between its pages, edited with [`crate::edit`].
//!
//! Every change is made by the library's [`Editor`], which loads the result
//! as `dofplan check` does and refuses an invalid one with check's message;
//! this module chooses what to edit (the pose on screen is redrawn first,
//! so constraints are added in a solved state and what the user sees is
//! what gets edited), rebuilds the document the pages are sent, and keeps
//! reads and writes inside the directory the server was started in.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::Deserialize;
use serde_json::{json, Value};

use super::{save, Edit, Editor, EMPTY};
use crate::conflict::{load_any_str, load_str};
use crate::model::{Format, Location, Model, ModelError};
use dofplan_runtime::planar::{Pose, Rot};

use super::planar::document::{Document, Watch, UNTITLED};
use super::spatial::{self, READ_ONLY};

/// A message from the page that changes the document (the others, for
/// the pose on screen, are [`super::planar::session::Request`]s).
#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum Request {
    /// Make `edits` in order, at the pose on screen, as one undoable edit.
    Edit {
        /// Echoed in the reply.
        id: u64,
        /// What to do, as [`Edit`] reads it.
        edits: Vec<Edit>,
    },
    /// Take the last edit back.
    Undo {
        /// Echoed in the reply.
        id: u64,
    },
    /// Make the last undone edit again.
    Redo {
        /// Echoed in the reply.
        id: u64,
    },
    /// Write the document to its file, or to `name` in the directory the
    /// server was started in (a new document has no file yet).
    Save {
        /// Echoed in the reply.
        id: u64,
        /// A plain `.toml` file name.
        #[serde(default)]
        name: Option<String>,
    },
    /// Replace the file's text with `text` (typed in the page's File tab):
    /// checked as any edit is; for a file that does not load, its fix so
    /// far.
    Text {
        /// Echoed in the reply.
        id: u64,
        /// The whole text.
        text: String,
    },
    /// Open `name`, a file of the directory the server was started in.
    Open {
        /// Echoed in the reply.
        id: u64,
        /// A `.toml` file's path relative to that directory.
        name: String,
        /// Open even though the document has unsaved changes.
        #[serde(default)]
        discard: bool,
    },
}

impl Request {
    /// The request's id, for the reply.
    pub fn id(&self) -> u64 {
        match self {
            Request::Edit { id, .. }
            | Request::Undo { id }
            | Request::Redo { id }
            | Request::Text { id, .. }
            | Request::Save { id, .. }
            | Request::Open { id, .. } => *id,
        }
    }
}

/// Whether the JSON text `message` is one of [`Request`]'s types (which
/// then must parse as one), rather than a session's request.
pub fn is_editing(message: &str) -> bool {
    let kind = serde_json::from_str::<Value>(message)
        .ok()
        .and_then(|v| v.get("type").and_then(Value::as_str).map(str::to_string));
    matches!(
        kind.as_deref(),
        Some("edit" | "text" | "undo" | "redo" | "save" | "open")
    )
}

/// The document every page of the server shows, and what edits it.
pub struct Workspace {
    /// The editor of the document, or why it cannot be edited (a JSON
    /// file is shown, not edited: the editor writes TOML; a file that does
    /// not load is fixed as text first).
    editor: Result<Editor, String>,
    /// The file's text and diagnostics when it does not load (`dofplan edit
    /// typo.toml`): the page shows them to be fixed there.
    broken: Option<Broken>,
    /// Where Save writes: the file opened or last saved (`None`: a new
    /// document, which asks for a name).
    path: Option<PathBuf>,
    /// The directory the server was started in: the only one (with its
    /// folders) files are opened from and saved to by name.
    dir: PathBuf,
    /// The text last read or written: the document has unsaved changes
    /// when the editor's differs.
    saved: String,
    /// What the pages are sent, rebuilt after every change.
    view: View,
    /// How a document's analysis shows its progress.
    watch: Option<Watch>,
}

/// A file that does not load, as the page shows it: its text, check's
/// report of it, and where each error is.
struct Broken {
    text: String,
    /// `dofplan check`'s message, without colour.
    message: String,
    /// `{line, column, end_line, end_column, message}` (1-based) of each
    /// error with a place in the text.
    errors: Vec<Value>,
}

impl Broken {
    fn of(text: &str, error: &ModelError) -> Broken {
        let errors = error
            .diagnostics
            .iter()
            .filter_map(|d| {
                let (start, end) = match &d.location {
                    Location::Span(span) => (d.file.line_col(span.start), d.file.line_col(span.end)),
                    Location::LineCol(line, col) => ((*line, *col), (*line, *col + 1)),
                    _ => return None,
                };
                Some(json!({
                    "line": start.0,
                    "column": start.1,
                    "end_line": end.0,
                    "end_column": end.1,
                    "message": d.message,
                }))
            })
            .collect();
        Broken {
            text: text.to_string(),
            message: error.render(false),
            errors,
        }
    }
}

/// Why a file that does not load cannot be edited by mouse.
const BROKEN: &str = "the file does not load: fix its text in the File tab";

/// The document the pages show.
#[derive(Clone)]
pub enum View {
    /// A planar mechanism: dragged and edited. (A file that does not load
    /// is shown as the empty drawing, its text and diagnostics beside it.)
    Planar(Arc<Document>),
    /// A spatial one: shown with its sliders and sweep only.
    Spatial(Arc<spatial::Document>),
}

impl Workspace {
    /// Opens `file` (or a new document) for a server started in `dir`: a
    /// file that does not exist yet is a new document saved under its name;
    /// one that does not load is shown with its diagnostics, to be fixed in
    /// the page. An error is the text to print (a file that cannot be read,
    /// a new file in a folder that does not exist).
    pub fn open(file: Option<&Path>, dir: PathBuf) -> Result<Workspace, String> {
        Workspace::open_watched(file, dir, None)
    }

    /// [`Workspace::open`], the analysis of each document showing its
    /// progress through `watch`.
    pub fn open_watched(
        file: Option<&Path>,
        dir: PathBuf,
        watch: Option<Watch>,
    ) -> Result<Workspace, String> {
        let Some(path) = file else {
            let editor = Editor::empty(UNTITLED);
            return Ok(Workspace {
                saved: editor.text(),
                view: View::Planar(Arc::new(Document::watched(
                    None,
                    editor.mechanism().clone(),
                    watch,
                ))),
                editor: Ok(editor),
                broken: None,
                path: None,
                dir,
                watch,
            });
        };
        let name = path.display().to_string();
        if std::fs::symlink_metadata(path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound) {
            return Workspace::new_file(path, dir, watch);
        }
        let text =
            std::fs::read_to_string(path).map_err(|e| format!("{name}: error: cannot read it: {e}"))?;
        let mut w = Workspace {
            editor: Err(BROKEN.to_string()),
            broken: None,
            path: Some(path.to_path_buf()),
            dir,
            saved: text.clone(),
            view: View::Planar(Arc::new(placeholder(Some(path)))),
            watch,
        };
        match load_any_str(&name, &text, Format::of_path(path)) {
            Ok(Model::Planar(m)) => {
                w.editor = editor_of(path, &text);
                w.view = View::Planar(Arc::new(Document::watched(Some(path), m, watch)));
            }
            Ok(Model::Spatial(m)) => {
                w.editor = Err(READ_ONLY.to_string());
                w.view = View::Spatial(Arc::new(spatial::Document::new(path, m)));
            }
            Err(e) => w.broken = Some(Broken::of(&text, &e)),
        }
        Ok(w)
    }

    /// A new document to be saved as `path`, which does not exist yet:
    /// the ground alone, called after the file.
    fn new_file(path: &Path, dir: PathBuf, watch: Option<Watch>) -> Result<Workspace, String> {
        let name = path.display().to_string();
        if !matches!(Format::of_path(path), Format::Toml) || path.extension().is_none() {
            return Err(format!(
                "{name}: error: there is no such file, and a new one must be a .toml file (the editor writes TOML)\n  help: start `dofplan edit NAME.toml`"
            ));
        }
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        if !folder.is_dir() {
            return Err(format!(
                "{name}: error: there is no such file, and no folder {} to make it in\n  help: create the folder first, or name a file of an existing one",
                folder.display()
            ));
        }
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("untitled");
        let editor = Editor::new_named(&name, stem).map_err(|e| e.to_string())?;
        Ok(Workspace {
            view: View::Planar(Arc::new(Document::watched(
                Some(path),
                editor.mechanism().clone(),
                watch,
            ))),
            editor: Ok(editor),
            broken: None,
            path: Some(path.to_path_buf()),
            dir,
            watch,
            // Nothing is on disk yet: the document has unsaved changes.
            saved: String::new(),
        })
    }

    /// The document as it is now.
    pub fn view(&self) -> View {
        self.view.clone()
    }

    /// The planar document as it is now, if it is planar.
    pub fn planar(&self) -> Option<Arc<Document>> {
        match &self.view {
            View::Planar(doc) => Some(doc.clone()),
            View::Spatial(_) => None,
        }
    }

    /// The `document` message: the document's description and what the
    /// page's editing controls need (whether it can be edited, undone,
    /// redone, whether it has a file and unsaved changes, the files that
    /// can be opened, the file's text); for a file that does not load, its
    /// text and diagnostics (`broken`) and nothing to draw.
    pub fn describe(&self) -> Value {
        let mut d = match &self.view {
            View::Planar(doc) => doc.description.clone(),
            View::Spatial(doc) => doc.description.clone(),
        };
        let (undo, redo) = self.editor.as_ref().map_or((false, false), Editor::can);
        let text = match (&self.broken, &self.editor) {
            (Some(b), _) => Some(b.text.clone()),
            (None, Ok(e)) => Some(e.text()),
            (None, Err(_)) => None,
        };
        d["editing"] = json!({
            "editable": self.editor.is_ok(),
            "why": self.editor.as_ref().err(),
            "undo": undo,
            "redo": redo,
            "dirty": self.dirty(),
            "named": self.path.is_some(),
            "files": save::files(&self.dir).unwrap_or_default(),
            "text": text,
        });
        if let Some(b) = &self.broken {
            d["broken"] = json!({
                "message": b.message,
                "errors": b.errors,
            });
            // The placeholder's name is not the file's: the file's own
            // name cannot be read, so the page is named by the file.
            let stem = self.path.as_deref().and_then(Path::file_stem);
            d["name"] = json!(stem.map(|s| s.to_string_lossy()));
            d["plan"] = Value::Null;
            d["plan_error"] = json!(BROKEN);
            d["check"] = json!(b.message);
            d["rust"] = Value::Null;
        }
        d
    }

    fn dirty(&self) -> bool {
        match (&self.broken, &self.editor) {
            (Some(b), _) => b.text != self.saved,
            (None, Ok(e)) => e.text() != self.saved,
            (None, Err(_)) => false,
        }
    }

    /// Makes the change `request` asks for, the pose on screen being
    /// `poses` (relative to the drawing, one per body), and rebuilds the
    /// document; returns what changed, or why nothing did.
    pub fn handle(&mut self, request: Request, poses: &[Pose]) -> Result<String, String> {
        let moved = poses.iter().any(|p| *p != Pose::IDENTITY).then_some(poses);
        let summary = match request {
            Request::Edit { edits, .. } => {
                if edits.is_empty() {
                    return Err("no edit to make".into());
                }
                let editor = self.editor_mut()?;
                let summaries = editor.apply_at(moved, &edits).map_err(|e| e.to_string())?;
                // The redraw's own summary says only that the pose on
                // screen became the drawing: the edits' say what changed.
                let skip = usize::from(moved.is_some());
                summaries[skip..].join("; ")
            }
            Request::Text { text, .. } => {
                if self.broken.is_some() {
                    self.fix(&text)
                } else {
                    self.editor_mut()?.set_text(&text).map_err(|e| e.to_string())?
                }
            }
            Request::Undo { .. } => {
                if !self.editor_mut()?.undo() {
                    return Err("nothing to undo".into());
                }
                "undone".into()
            }
            Request::Redo { .. } => {
                if !self.editor_mut()?.redo() {
                    return Err("nothing to redo".into());
                }
                "redone".into()
            }
            Request::Save { name, .. } => self.save(name.as_deref(), moved)?,
            Request::Open { name, discard, .. } => return self.open_named(&name, discard),
        };
        self.rebuild();
        Ok(summary)
    }

    fn editor_mut(&mut self) -> Result<&mut Editor, String> {
        self.editor
            .as_mut()
            .map_err(|why| format!("this document cannot be edited: {why}"))
    }

    /// The text of a file that does not load, as fixed so far in the page:
    /// the document once it loads, else its new diagnostics.
    fn fix(&mut self, text: &str) -> String {
        let path = self.path.clone().unwrap_or_else(|| PathBuf::from(UNTITLED));
        let file = self.shown(&path).display().to_string();
        let format = Format::of_path(&path);
        match load_any_str(&file, text, format) {
            Ok(Model::Planar(_)) if matches!(format, Format::Toml) => match Editor::new(&file, text) {
                Ok(editor) => {
                    self.editor = Ok(editor);
                    self.broken = None;
                    format!("{file} loads now: save it to keep the fix")
                }
                Err(e) => {
                    self.broken = Some(Broken {
                        text: text.to_string(),
                        message: e.to_string(),
                        errors: Vec::new(),
                    });
                    format!("{file} still does not load")
                }
            },
            Ok(_) => {
                // Shown, not edited, here: kept as text until saved.
                let kind = if matches!(format, Format::Json) {
                    "a JSON file"
                } else {
                    "a spatial (dimension = 3) file"
                };
                self.broken = Some(Broken {
                    text: text.to_string(),
                    message: format!(
                        "{file} loads now, as {kind}, which the editor shows but does not edit: Save it, then start `dofplan edit {file}` to view it"
                    ),
                    errors: Vec::new(),
                });
                format!("{file} loads now: save it, then start `dofplan edit {file}` to view it")
            }
            Err(e) => {
                let broken = Broken::of(text, &e);
                let n = e.diagnostics.len();
                self.broken = Some(broken);
                format!(
                    "{file} still does not load ({n} error{}): see the File tab",
                    if n == 1 { "" } else { "s" }
                )
            }
        }
    }

    /// Writes the document (redrawn at the pose on screen, so the file's
    /// drawing is what the user sees) to its file or to `name`; a file
    /// that does not load is written as its text stands. Saved under a new
    /// name, a mechanism called after its old file (or a new document's
    /// `untitled`) is called after the new one.
    fn save(&mut self, name: Option<&str>, moved: Option<&[Pose]>) -> Result<String, String> {
        let path = match name {
            Some(name) => save::file_in(&self.dir, name)?,
            None => self
                .path
                .clone()
                .ok_or("this document has no file yet: give it a name to save it under")?,
        };
        let shown = self.shown(&path);
        let mut renamed = String::new();
        let text = match &self.broken {
            Some(b) => b.text.clone(),
            None => {
                let editor = self.editor_mut()?;
                let stem = |p: &Path| p.file_stem().and_then(|s| s.to_str()).map(str::to_string);
                let old = stem(Path::new(editor.file_name()));
                let new = stem(&path).filter(|new| {
                    name.is_some()
                        && Some(new) != old.as_ref()
                        && old.as_deref() == Some(&editor.mechanism().name)
                });
                let mut edits = Vec::new();
                if let Some(new) = &new {
                    edits.push(Edit::Rename { name: new.clone() });
                    renamed = format!(" (the mechanism is called {new} now)");
                }
                if moved.is_some() || !edits.is_empty() {
                    editor.apply_at(moved, &edits).map_err(|e| e.to_string())?;
                }
                editor.text()
            }
        };
        save::write(&path, &text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        if let Ok(editor) = &mut self.editor {
            editor.set_file_name(&shown.display().to_string());
        }
        self.path = Some(path);
        self.saved = text;
        Ok(format!("saved {}{renamed}", shown.display()))
    }

    /// Opens `name` of the start directory (or its folders) in place of the
    /// document; a file that does not load is opened to be fixed.
    fn open_named(&mut self, name: &str, discard: bool) -> Result<String, String> {
        if self.dirty() && !discard {
            return Err("the document has unsaved changes: save them, or open again to discard them".into());
        }
        let path = save::file_in(&self.dir, name)?;
        let file = self.shown(&path).display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| format!("cannot read {file}: {e}"))?;
        let summary = match load_any_str(&file, &text, Format::Toml) {
            Ok(Model::Planar(mechanism)) => {
                let editor = editor_of(Path::new(&file), &text)?;
                self.editor = Ok(editor);
                self.broken = None;
                self.view = View::Planar(Arc::new(Document::watched(
                    Some(Path::new(&file)),
                    mechanism,
                    self.watch,
                )));
                format!("opened {file}")
            }
            Ok(Model::Spatial(_)) => {
                return Err(format!(
                    "{file}: spatial (dimension = 3) files are not opened from here: start `dofplan edit {file}` to view one"
                ))
            }
            Err(e) => {
                self.editor = Err(BROKEN.to_string());
                self.broken = Some(Broken::of(&text, &e));
                self.view = View::Planar(Arc::new(placeholder(Some(Path::new(&file)))));
                format!("opened {file}: it does not load; fix it in the File tab")
            }
        };
        self.saved = text;
        self.path = Some(path);
        Ok(summary)
    }

    /// `path` as reports write it: relative to the start directory when it
    /// is in it (the server's working directory), so `dofplan check` run
    /// there names it the same.
    fn shown(&self, path: &Path) -> PathBuf {
        path.strip_prefix(&self.dir).unwrap_or(path).to_path_buf()
    }

    /// The document of the editor's mechanism, after a change.
    fn rebuild(&mut self) {
        let shown = self.path.as_deref().map(|p| self.shown(p));
        if self.broken.is_some() {
            self.view = View::Planar(Arc::new(placeholder(shown.as_deref())));
        } else if let Ok(editor) = &self.editor {
            let m = editor.mechanism().clone();
            self.view = View::Planar(Arc::new(Document::watched(shown.as_deref(), m, self.watch)));
        }
    }
}

/// What the page draws of a file that does not load: nothing (the
/// description's bodies are emptied by [`Workspace::describe`]); the
/// ground alone keeps the live loop's session well defined.
fn placeholder(path: Option<&Path>) -> Document {
    let m = load_str(UNTITLED, EMPTY, Format::Toml).expect("the empty document loads");
    let mut doc = Document::new(path, m);
    for key in ["bodies", "joints", "inputs"] {
        doc.description[key] = json!([]);
    }
    doc.description["sweep"] = Value::Null;
    doc.description["traces"] = json!({});
    doc
}

/// An editor of `text`, read from `path`; JSON files are shown, not
/// edited.
fn editor_of(path: &Path, text: &str) -> Result<Editor, String> {
    if matches!(Format::of_path(path), Format::Json) {
        return Err("JSON files are shown, not edited (the editor writes TOML)".into());
    }
    Editor::new(&path.display().to_string(), text).map_err(|e| e.to_string())
}

/// The poses of a session's `frame` message (`[cos, sin, x, y]` per body).
pub fn poses_of(frame: &Value) -> Vec<Pose> {
    let number = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    frame["poses"]
        .as_array()
        .map(|poses| {
            poses
                .iter()
                .map(|p| Pose {
                    rot: Rot {
                        c: number(&p[0]),
                        s: number(&p[1]),
                    },
                    at: [number(&p[2]), number(&p[3])],
                })
                .collect()
        })
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("dofplan-editing-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn edits(json: &str) -> Request {
        serde_json::from_str(json).expect("a well-formed request")
    }

    #[test]
    fn a_new_document_is_built_saved_by_name_and_opened_again() {
        let dir = temp_dir("new");
        let mut w = Workspace::open(None, dir.clone()).unwrap();
        let none = vec![Pose::IDENTITY];
        let summary = w
            .handle(
                edits(r#"{"type":"edit","id":1,"edits":[{"op":"add_body","markers":[[0,0],[1,1]]},{"op":"join","a":"ground.O","b":"link1.A","snap":true}]}"#),
                &none,
            )
            .unwrap();
        assert!(summary.contains("link1"), "{summary}");
        assert_eq!(w.describe()["editing"]["dirty"], true);
        let poses = vec![Pose::IDENTITY; 2];
        let unnamed = w.handle(edits(r#"{"type":"save","id":2}"#), &poses);
        assert!(unnamed.unwrap_err().contains("give it a name"));
        let outside = w.handle(edits(r#"{"type":"save","id":3,"name":"../x"}"#), &poses);
        assert!(outside.unwrap_err().contains("not a file name inside"));
        assert!(!dir.parent().unwrap().join("x.toml").exists());
        assert_eq!(
            w.handle(edits(r#"{"type":"save","id":4,"name":"pendulum"}"#), &poses),
            Ok("saved pendulum.toml (the mechanism is called pendulum now)".into())
        );
        let saved = std::fs::read_to_string(dir.join("pendulum.toml")).unwrap();
        assert!(saved.contains("link1"), "{saved}");
        assert_eq!(w.describe()["editing"]["dirty"], false);
        assert_eq!(w.describe()["editing"]["files"], json!(["pendulum.toml"]));
        // Undo, then opening refuses to drop the change unless told to.
        w.handle(edits(r#"{"type":"undo","id":5}"#), &poses).unwrap();
        let kept = w.handle(edits(r#"{"type":"open","id":6,"name":"pendulum.toml"}"#), &none);
        assert!(kept.unwrap_err().contains("unsaved changes"));
        w.handle(
            edits(r#"{"type":"open","id":7,"name":"pendulum.toml","discard":true}"#),
            &none,
        )
        .unwrap();
        assert_eq!(w.planar().unwrap().mechanism.bodies.len(), 2);
        assert_eq!(w.describe()["editing"]["undo"], false);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_refused_edit_changes_nothing_and_says_why() {
        let dir = temp_dir("refused");
        let mut w = Workspace::open(None, dir.clone()).unwrap();
        let before = w.describe();
        let none = vec![Pose::IDENTITY];
        let why = w
            .handle(
                edits(r#"{"type":"edit","id":1,"edits":[{"op":"add_body","markers":[[1,0],[2,0]]},{"op":"join","a":"ground.O","b":"link1.A"}]}"#),
                &none,
            )
            .unwrap_err();
        assert!(why.contains("untitled.toml"), "check's message: {why}");
        assert_eq!(w.describe(), before);
        assert_eq!(
            w.handle(edits(r#"{"type":"undo","id":2}"#), &none),
            Err("nothing to undo".into())
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_spatial_file_is_shown_and_every_change_refused() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/spatial/rssr.toml");
        let mut w = Workspace::open(Some(&path), std::env::temp_dir()).unwrap();
        let d = w.describe();
        assert_eq!(
            (d["dimension"].as_u64(), d["editing"]["editable"].as_bool()),
            (Some(3), Some(false))
        );
        assert!(
            d["plan"].is_string() && d["check"].as_str().is_some_and(|c| c.contains("mobility")),
            "{d}"
        );
        for request in [
            r#"{"type":"edit","id":1,"edits":[{"op":"add_marker","body":"ground","at":[0,0]}]}"#,
            r#"{"type":"save","id":2}"#,
            r#"{"type":"undo","id":3}"#,
        ] {
            let why = w.handle(edits(request), &[]).unwrap_err();
            assert!(why.contains("planar-only"), "{request}: {why}");
        }
        assert!(w.planar().is_none());
    }

    const PENDULUM: &str = "name = \"pendulum\"\n\n[bodies.ground]\nfixed = true\nmarkers = { O = [0, 0] }\n\n[bodies.arm]\nmarkers = { A = [0, 0], B = [1, 0] }\n\n[joints.J1]\nkind = \"revolute\"\nmarkers = [\"ground.O\", \"arm.A\"]\n";

    #[test]
    fn a_file_that_does_not_load_is_opened_with_its_diagnostics_and_fixed_in_the_page() {
        let dir = temp_dir("broken");
        let typo = PENDULUM.replace(
            "markers = [\"ground.O\", \"arm.A\"]",
            "markers = [\"ground.O\", \"arm.Z\"]",
        );
        std::fs::write(dir.join("typo.toml"), &typo).unwrap();
        let path = dir.join("typo.toml");
        let mut w = Workspace::open(Some(&path), dir.clone()).expect("opened, not refused");
        let d = w.describe();
        let message = d["broken"]["message"].as_str().unwrap();
        assert!(message.contains("arm.Z"), "check's message: {message}");
        // The error's place: line 13 (the joint's markers), the column of
        // "arm.Z" in it.
        let line = typo.lines().position(|l| l.contains("arm.Z")).unwrap() + 1;
        let column = typo.lines().nth(line - 1).unwrap().find("\"arm.Z\"").unwrap() + 1;
        let first = &d["broken"]["errors"][0];
        assert_eq!(
            (first["line"].as_u64(), first["column"].as_u64()),
            (Some(line as u64), Some(column as u64)),
            "{first}"
        );
        assert_eq!(d["editing"]["text"], typo.as_str(), "the text to fix");
        assert_eq!(d["editing"]["editable"], false);
        assert_eq!(d["bodies"], json!([]), "nothing drawn");
        assert_eq!(d["check"].as_str(), Some(message));
        let none = vec![Pose::IDENTITY];
        let refused = w.handle(
            edits(r#"{"type":"edit","id":1,"edits":[{"op":"add_marker","body":"ground","at":[1,0]}]}"#),
            &none,
        );
        assert!(refused.unwrap_err().contains("File tab"));
        // Still wrong: new diagnostics, still not editable.
        let worse = typo.replace("[bodies.arm]", "[bodies.arm");
        let s = w
            .handle(
                Request::Text {
                    id: 2,
                    text: worse.clone(),
                },
                &none,
            )
            .unwrap();
        assert!(s.contains("still does not load"), "{s}");
        assert_eq!(w.describe()["editing"]["text"], worse.as_str());
        assert_eq!(w.describe()["editing"]["dirty"], true);
        // Fixed: a planar document, editable, with unsaved changes.
        let s = w
            .handle(
                Request::Text {
                    id: 3,
                    text: PENDULUM.to_string(),
                },
                &none,
            )
            .unwrap();
        assert!(s.contains("loads now"), "{s}");
        let d = w.describe();
        assert_eq!(
            (
                d["editing"]["editable"].as_bool(),
                d["editing"]["dirty"].as_bool()
            ),
            (Some(true), Some(true))
        );
        assert!(d.get("broken").is_none());
        assert_eq!(w.planar().unwrap().mechanism.bodies.len(), 2);
        w.handle(edits(r#"{"type":"save","id":4}"#), &[Pose::IDENTITY; 2])
            .unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), PENDULUM);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_spatial_file_that_does_not_load_is_fixed_as_text_and_saved_to_be_viewed() {
        let dir = temp_dir("broken-spatial");
        let good = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/spatial/rssr.toml"),
        )
        .unwrap();
        let typo = good.replace("kind = \"spherical\"", "kind = \"sferical\"");
        assert_ne!(typo, good);
        let path = dir.join("rssr.toml");
        std::fs::write(&path, &typo).unwrap();
        let mut w = Workspace::open(Some(&path), dir.clone()).unwrap();
        assert!(w.describe()["broken"]["message"]
            .as_str()
            .unwrap()
            .contains("sferical"));
        let none = [Pose::IDENTITY];
        let s = w
            .handle(
                Request::Text {
                    id: 1,
                    text: good.clone(),
                },
                &none,
            )
            .unwrap();
        assert!(s.contains("loads now") && s.contains("dofplan edit"), "{s}");
        // Shown, not edited, by this server: still text, saved as typed.
        let d = w.describe();
        assert_eq!(d["editing"]["editable"], false);
        assert!(
            d["broken"]["message"].as_str().unwrap().contains("spatial"),
            "{d}"
        );
        w.handle(edits(r#"{"type":"save","id":2}"#), &none).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), good);
        assert!(
            Workspace::open(Some(&path), dir.clone())
                .unwrap()
                .planar()
                .is_none(),
            "now a 3D view"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_file_that_does_not_load_opened_from_the_list_is_shown_to_be_fixed() {
        let dir = temp_dir("broken-open");
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        std::fs::write(
            dir.join("sub/typo.toml"),
            PENDULUM.replace("[bodies.arm]", "[bodies.arm"),
        )
        .unwrap();
        std::fs::write(dir.join("Cargo.toml"), "[package]\nname = \"x\"\n").unwrap();
        let mut w = Workspace::open(None, dir.clone()).unwrap();
        assert_eq!(w.describe()["editing"]["files"], json!(["sub/typo.toml"]));
        let s = w
            .handle(
                edits(r#"{"type":"open","id":1,"name":"sub/typo.toml"}"#),
                &[Pose::IDENTITY],
            )
            .unwrap();
        assert!(s.contains("does not load"), "{s}");
        let d = w.describe();
        assert_eq!(d["file"], "sub/typo.toml");
        assert!(
            d["broken"]["message"]
                .as_str()
                .unwrap()
                .contains("sub/typo.toml:"),
            "{d}"
        );
        assert_eq!(d["editing"]["dirty"], false);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_file_that_does_not_exist_is_a_new_document_saved_under_its_name() {
        let dir = temp_dir("new-file");
        let path = dir.join("new.toml");
        let mut w = Workspace::open(Some(&path), dir.clone()).unwrap();
        let d = w.describe();
        assert_eq!(
            (d["name"].as_str(), d["editing"]["named"].as_bool()),
            (Some("new"), Some(true))
        );
        assert_eq!(d["editing"]["dirty"], true, "nothing on disk yet");
        assert!(!path.exists());
        let none = vec![Pose::IDENTITY];
        w.handle(
            edits(r#"{"type":"edit","id":1,"edits":[{"op":"add_marker","body":"ground","at":[2,0]}]}"#),
            &none,
        )
        .unwrap();
        assert_eq!(
            w.handle(edits(r#"{"type":"save","id":2}"#), &none),
            Ok("saved new.toml".into())
        );
        let written = std::fs::read_to_string(&path).unwrap();
        assert!(
            written.starts_with("name = \"new\"") && written.contains("A = [2"),
            "{written}"
        );
        assert_eq!(w.describe()["editing"]["dirty"], false);
        // No folder to make it in, or not TOML: refused at the start.
        let nowhere = Workspace::open(Some(&dir.join("nowhere/new.toml")), dir.clone());
        assert!(nowhere.err().unwrap().contains("no folder"));
        let json = Workspace::open(Some(&dir.join("new.json")), dir.clone());
        assert!(json.err().unwrap().contains(".toml"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn saved_as_a_new_name_the_mechanism_follows_the_file() {
        let dir = temp_dir("follows");
        let mut w = Workspace::open(None, dir.clone()).unwrap();
        let none = vec![Pose::IDENTITY];
        assert_eq!(
            w.handle(edits(r#"{"type":"save","id":1,"name":"crank"}"#), &none),
            Ok("saved crank.toml (the mechanism is called crank now)".into())
        );
        assert_eq!(w.describe()["name"], "crank");
        assert!(std::fs::read_to_string(dir.join("crank.toml"))
            .unwrap()
            .starts_with("name = \"crank\""));
        // A name of the user's own is kept.
        w.handle(
            edits(r#"{"type":"edit","id":2,"edits":[{"op":"rename","name":"mine"}]}"#),
            &none,
        )
        .unwrap();
        assert_eq!(
            w.handle(edits(r#"{"type":"save","id":3,"name":"other"}"#), &none),
            Ok("saved other.toml".into())
        );
        assert_eq!(w.describe()["name"], "mine");
        // Into a folder of the directory, not out of it.
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        assert_eq!(
            w.handle(edits(r#"{"type":"save","id":4,"name":"sub/third"}"#), &none),
            Ok("saved sub/third.toml".into())
        );
        assert_eq!(w.describe()["file"], "sub/third.toml");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn only_editing_types_are_editing_messages() {
        assert!(is_editing(r#"{"type":"save","id":1}"#));
        assert!(is_editing(r#"{"type":"edit","id":1,"edits":"nonsense"}"#));
        assert!(!is_editing(r#"{"type":"drag","id":1,"to":[0,0]}"#));
        assert!(!is_editing("not json"));
    }
}
