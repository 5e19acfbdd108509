//! Editing a planar mechanism file the way MechEdit's user does — adding
//! bodies and markers, joining markers, toggling a joint between revolute
//! and prismatic, marking inputs, deleting — with every edit checked and
//! undoable, and the file's comments and key order kept.
//!
//! An [`Editor`] holds the file's text as a `toml_edit` document. Each
//! [`Edit`] changes the document, and the result is loaded exactly as
//! `dofplan check` loads a file: an edit that would make the file invalid
//! (a joint whose markers do not coincide, a name used twice, …) is refused
//! with the message `check` would print, and the document is left as it
//! was. Edits that remove more than they name (deleting a body deletes its
//! joints, the inputs on them, the sweep that drove them and the traces of
//! its markers) say so in their summary: nothing is dropped silently.
//!
//! Constraints are added in a solved state (MechEdit §5.1): after a drag
//! the caller redraws the file at the pose on screen ([`Editor::redraw`]),
//! so the next edit starts from what the user sees.

mod forces;
pub mod live;
mod names;
mod ops;
pub mod planar;
pub mod save;
pub mod spatial;
pub mod workspace;

use dofplan_runtime::planar::Pose;
use toml_edit::DocumentMut;

use crate::conflict::load_str;
use crate::model::{Format, Mechanism};

pub use ops::Edit;

/// The ground alone, with one marker at the origin to build on: a new
/// document.
pub const EMPTY: &str = "name = \"untitled\"\n\n[bodies.ground]\nfixed = true\nmarkers = { O = [0, 0] }\n";

/// How many edits [`Editor::undo`] can take back.
const HISTORY: usize = 1000;

/// A mechanism file being edited.
#[derive(Clone, Debug)]
pub struct Editor {
    /// The name diagnostics give the file.
    file_name: String,
    doc: DocumentMut,
    mechanism: Mechanism,
    /// Earlier texts, the last one the most recent.
    undo: Vec<String>,
    /// Texts undone, the last one the next to redo.
    redo: Vec<String>,
}

/// Why an edit was not made. The document is as it was.
#[derive(Clone, Debug, PartialEq)]
pub enum EditError {
    /// The edit names something that is not there, or asks for something
    /// no file can say (deleting the only fixed body, …).
    Refused(String),
    /// The edited file would not load: `dofplan check`'s message.
    Invalid(String),
}

impl std::fmt::Display for EditError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EditError::Refused(why) | EditError::Invalid(why) => f.write_str(why),
        }
    }
}

impl std::error::Error for EditError {}

impl Editor {
    /// Opens `text`, a planar TOML mechanism file called `file_name` in
    /// diagnostics. The error is `dofplan check`'s message.
    pub fn new(file_name: &str, text: &str) -> Result<Editor, EditError> {
        let doc: DocumentMut = text
            .parse()
            .map_err(|_| EditError::Invalid(invalid(file_name, text)))?;
        let mechanism =
            load_str(file_name, text, Format::Toml).map_err(|e| EditError::Invalid(e.render(false)))?;
        Ok(Editor {
            file_name: file_name.to_string(),
            doc,
            mechanism,
            undo: Vec::new(),
            redo: Vec::new(),
        })
    }

    /// A new document: the ground alone ([`EMPTY`]).
    pub fn empty(file_name: &str) -> Editor {
        Editor::new(file_name, EMPTY).expect("the empty document is valid")
    }

    /// A new document called `name` (the ground alone, as [`EMPTY`]): a
    /// file named on the command line that does not exist yet.
    pub fn new_named(file_name: &str, name: &str) -> Result<Editor, EditError> {
        let mut doc: DocumentMut = EMPTY.parse().expect("the empty document parses");
        doc.insert("name", toml_edit::value(name));
        Editor::new(file_name, &doc.to_string())
    }

    /// The mechanism as the file now draws it.
    pub fn mechanism(&self) -> &Mechanism {
        &self.mechanism
    }

    /// The file's text, comments and key order as they were read.
    pub fn text(&self) -> String {
        self.doc.to_string()
    }

    /// Makes `edit`, or refuses it and changes nothing. The summary says
    /// what changed, including what the edit removed besides what it names.
    pub fn apply(&mut self, edit: &Edit) -> Result<String, EditError> {
        let mut doc = self.doc.clone();
        let summary = ops::apply(&mut doc, &self.mechanism, edit)?;
        self.commit(doc)?;
        Ok(summary)
    }

    /// Redraws the file at `poses` (one per body, in file order): every
    /// marker, and its direction, where the body's pose puts it, so the
    /// pose on screen becomes the drawn pose. Inputs then start from 0 at
    /// this pose. One undoable edit.
    pub fn redraw(&mut self, poses: &[Pose]) -> Result<String, EditError> {
        let mut doc = self.doc.clone();
        let summary = ops::redraw(&mut doc, &self.mechanism, poses)?;
        self.commit(doc)?;
        Ok(summary)
    }

    /// Makes `edits` in order as one undoable edit, after redrawing the
    /// file at `poses` when given (the pose on screen, as
    /// [`Editor::redraw`]): what the user did to what they saw is taken
    /// back by one undo. Each edit sees the file the previous one left, and
    /// every step must load as `check` loads a file; if one is refused,
    /// nothing changes. The summaries, one per edit (and the redraw's
    /// first).
    pub fn apply_at(&mut self, poses: Option<&[Pose]>, edits: &[Edit]) -> Result<Vec<String>, EditError> {
        let mut doc = self.doc.clone();
        let mut mechanism = self.mechanism.clone();
        let mut summaries = Vec::with_capacity(edits.len() + 1);
        if let Some(poses) = poses {
            summaries.push(ops::redraw(&mut doc, &mechanism, poses)?);
            mechanism = self.load(&doc)?;
        }
        for edit in edits {
            summaries.push(ops::apply(&mut doc, &mechanism, edit)?);
            mechanism = self.load(&doc)?;
        }
        self.commit(doc)?;
        Ok(summaries)
    }

    /// Replaces the whole text (typed in the editor's File tab), or refuses
    /// it with check's message and changes nothing. One undoable edit.
    pub fn set_text(&mut self, text: &str) -> Result<String, EditError> {
        let doc: DocumentMut = text
            .parse()
            .map_err(|_| EditError::Invalid(invalid(&self.file_name, text)))?;
        if doc.to_string() == self.doc.to_string() {
            return Err(EditError::Refused(
                "the text is as it was: nothing to change".into(),
            ));
        }
        self.commit(doc)?;
        Ok(format!(
            "the file's text replaced ({} lines)",
            text.lines().count()
        ))
    }

    /// The name diagnostics give the file.
    pub fn file_name(&self) -> &str {
        &self.file_name
    }

    /// Calls the file `file_name` in diagnostics from now on (after it is
    /// saved under a new name); the history is kept.
    pub fn set_file_name(&mut self, file_name: &str) {
        self.file_name = file_name.to_string();
        if let Ok(m) = load_str(file_name, &self.doc.to_string(), Format::Toml) {
            self.mechanism = m;
        }
    }

    /// Takes the last edit back; false when there is none.
    pub fn undo(&mut self) -> bool {
        self.travel(true)
    }

    /// Makes the last undone edit again; false when there is none.
    pub fn redo(&mut self) -> bool {
        self.travel(false)
    }

    /// Whether [`Editor::undo`] and [`Editor::redo`] have something to do.
    pub fn can(&self) -> (bool, bool) {
        (!self.undo.is_empty(), !self.redo.is_empty())
    }

    /// Loads `doc` as `check` would and makes it the document, the old one
    /// kept for undo.
    fn commit(&mut self, doc: DocumentMut) -> Result<(), EditError> {
        let text = doc.to_string();
        let mechanism = load_str(&self.file_name, &text, Format::Toml)
            .map_err(|e| EditError::Invalid(e.render(false)))?;
        let old = std::mem::replace(&mut self.doc, doc).to_string();
        self.mechanism = mechanism;
        self.undo.push(old);
        if self.undo.len() > HISTORY {
            self.undo.remove(0);
        }
        self.redo.clear();
        Ok(())
    }

    /// `doc` loaded as `check` would load it.
    fn load(&self, doc: &DocumentMut) -> Result<Mechanism, EditError> {
        load_str(&self.file_name, &doc.to_string(), Format::Toml)
            .map_err(|e| EditError::Invalid(e.render(false)))
    }

    fn travel(&mut self, back: bool) -> bool {
        let (from, to) = if back {
            (&mut self.undo, &mut self.redo)
        } else {
            (&mut self.redo, &mut self.undo)
        };
        let Some(text) = from.pop() else {
            return false;
        };
        // Every text on either stack loaded when it was current.
        let doc: DocumentMut = text.parse().expect("a text that loaded before parses");
        let mechanism =
            load_str(&self.file_name, &text, Format::Toml).expect("a text that loaded before loads");
        to.push(self.doc.to_string());
        self.doc = doc;
        self.mechanism = mechanism;
        true
    }
}

/// The loader's message for a text that is not TOML.
fn invalid(file_name: &str, text: &str) -> String {
    match load_str(file_name, text, Format::Toml) {
        Err(e) => e.render(false),
        Ok(_) => format!("{file_name}: error: the file cannot be edited as TOML"),
    }
}

#[cfg(test)]
mod tests;
