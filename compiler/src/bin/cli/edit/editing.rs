//! Construction, undo, saving and opening in `dofplan edit`: the document
//! the server shares between its pages, edited with [`dofplan::edit`].
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

use dofplan::edit::{save, Edit, Editor};
use dofplan::model::{load_any_str, Format, Model};
use dofplan_runtime::planar::{Pose, Rot};

use super::document::{Document, UNTITLED};
use super::view3::{Document3, READ_ONLY};

/// A message from the page that changes the document (the others, for
/// the pose on screen, are [`super::session::Request`]s).
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
    /// Open `name`, a file of the directory the server was started in.
    Open {
        /// Echoed in the reply.
        id: u64,
        /// A plain `.toml` file name.
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
    matches!(kind.as_deref(), Some("edit" | "undo" | "redo" | "save" | "open"))
}

/// The document every page of the server shows, and what edits it.
pub struct Workspace {
    /// The editor of the document, or why it cannot be edited (a JSON
    /// file is shown, not edited: the editor writes TOML).
    editor: Result<Editor, String>,
    /// Where Save writes: the file opened or last saved (`None`: a new
    /// document, which asks for a name).
    path: Option<PathBuf>,
    /// The directory the server was started in: the only one files are
    /// opened from and saved to by name.
    dir: PathBuf,
    /// The text last read or written: the document has unsaved changes
    /// when the editor's differs.
    saved: String,
    /// What the pages are sent, rebuilt after every change.
    view: View,
}

/// The document the pages show.
#[derive(Clone)]
pub enum View {
    /// A planar mechanism: dragged and edited.
    Planar(Arc<Document>),
    /// A spatial one: shown with its sliders and sweep only.
    Spatial(Arc<Document3>),
}

impl Workspace {
    /// Opens `file` (or a new document) for a server started in `dir`. An
    /// error is the text to print: the file's diagnostics.
    pub fn open(file: Option<&Path>, dir: PathBuf) -> Result<Workspace, String> {
        if let Some(path) = file.filter(|p| dofplan::model::is_spatial_file(p)) {
            match dofplan::model::load_any(path) {
                Ok(Model::Spatial(m)) => {
                    return Ok(Workspace {
                        editor: Err(READ_ONLY.to_string()),
                        path: Some(path.to_path_buf()),
                        dir,
                        saved: String::new(),
                        view: View::Spatial(Arc::new(Document3::new(path, m))),
                    })
                }
                // Rewritten as a planar file meanwhile: opened as one below.
                Ok(Model::Planar(_)) => {}
                Err(e) => return Err(e.render(crate::colour())),
            }
        }
        let doc = Document::open(file)?;
        let editor = match file {
            None => Ok(Editor::empty(UNTITLED)),
            Some(path) => std::fs::read_to_string(path)
                .map_err(|e| format!("{}: cannot read it: {e}", path.display()))
                .and_then(|text| editor_of(path, &text)),
        };
        Ok(Workspace {
            saved: editor.as_ref().map(Editor::text).unwrap_or_default(),
            editor,
            path: file.map(Path::to_path_buf),
            dir,
            view: View::Planar(Arc::new(doc)),
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
    /// can be opened).
    pub fn describe(&self) -> Value {
        let mut d = match &self.view {
            View::Planar(doc) => doc.description.clone(),
            View::Spatial(doc) => doc.description.clone(),
        };
        let (undo, redo) = self.editor.as_ref().map_or((false, false), Editor::can);
        d["editing"] = json!({
            "editable": self.editor.is_ok(),
            "why": self.editor.as_ref().err(),
            "undo": undo,
            "redo": redo,
            "dirty": self.dirty(),
            "named": self.path.is_some(),
            "files": save::files(&self.dir).unwrap_or_default(),
        });
        d
    }

    fn dirty(&self) -> bool {
        self.editor.as_ref().is_ok_and(|e| e.text() != self.saved)
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

    /// Writes the document (redrawn at the pose on screen, so the file's
    /// drawing is what the user sees) to its file or to `name`.
    fn save(&mut self, name: Option<&str>, moved: Option<&[Pose]>) -> Result<String, String> {
        let path = match name {
            Some(name) => save::file_in(&self.dir, name)?,
            None => self
                .path
                .clone()
                .ok_or("this document has no file yet: give it a name to save it under")?,
        };
        let shown = self.shown(&path);
        let editor = self.editor_mut()?;
        if let Some(poses) = moved {
            editor.redraw(poses).map_err(|e| e.to_string())?;
        }
        let text = editor.text();
        save::write(&path, &text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        editor.set_file_name(&shown.display().to_string());
        self.path = Some(path);
        self.saved = text;
        Ok(format!("saved {}", shown.display()))
    }

    /// Opens `name` of the start directory in place of the document.
    fn open_named(&mut self, name: &str, discard: bool) -> Result<String, String> {
        if self.dirty() && !discard {
            return Err("the document has unsaved changes: save them, or open again to discard them".into());
        }
        let path = save::file_in(&self.dir, name)?;
        let file = self.shown(&path).display().to_string();
        let text = std::fs::read_to_string(&path).map_err(|e| format!("cannot read {file}: {e}"))?;
        let mechanism = match load_any_str(&file, &text, Format::Toml) {
            Ok(Model::Planar(m)) => m,
            Ok(Model::Spatial(_)) => {
                return Err(format!(
                    "{file}: spatial (dimension = 3) files are not opened from here: start `dofplan edit {file}` to view one"
                ))
            }
            Err(e) => return Err(e.render(false)),
        };
        let editor = editor_of(Path::new(&file), &text)?;
        self.saved = editor.text();
        self.editor = Ok(editor);
        self.view = View::Planar(Arc::new(Document::new(Some(Path::new(&file)), mechanism)));
        self.path = Some(path);
        Ok(format!("opened {file}"))
    }

    /// `path` as reports write it: relative to the start directory when it
    /// is in it (the server's working directory), so `dofplan check` run
    /// there names it the same.
    fn shown(&self, path: &Path) -> PathBuf {
        path.strip_prefix(&self.dir).unwrap_or(path).to_path_buf()
    }

    /// The document of the editor's mechanism, after a change.
    fn rebuild(&mut self) {
        if let Ok(editor) = &self.editor {
            let m = editor.mechanism().clone();
            let shown = self.path.as_deref().map(|p| self.shown(p));
            self.view = View::Planar(Arc::new(Document::new(shown.as_deref(), m)));
        }
    }
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
        assert!(outside.unwrap_err().contains("not a plain file name"));
        assert!(!dir.parent().unwrap().join("x.toml").exists());
        assert_eq!(
            w.handle(edits(r#"{"type":"save","id":4,"name":"pendulum"}"#), &poses),
            Ok("saved pendulum.toml".into())
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

    #[test]
    fn only_editing_types_are_editing_messages() {
        assert!(is_editing(r#"{"type":"save","id":1}"#));
        assert!(is_editing(r#"{"type":"edit","id":1,"edits":"nonsense"}"#));
        assert!(!is_editing(r#"{"type":"drag","id":1,"to":[0,0]}"#));
        assert!(!is_editing("not json"));
    }
}
