//! Errors about a mechanism file: each names the file, the position
//! (`file:line:column`) where the parser knows it, the names involved and
//! what to do.

use std::fmt;
use std::sync::Arc;

use super::excerpt::Excerpt;
use super::source::Span;

/// The text of a mechanism file, kept so errors can point into it.
#[derive(Clone, Debug)]
pub struct SourceFile {
    /// The file name as given by the user.
    pub name: String,
    /// The whole text.
    pub text: Arc<str>,
}

impl SourceFile {
    /// 1-based line and column of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let col = before[line_start..].chars().count() + 1;
        (line, col)
    }
}

/// Where an error points.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// A byte range in the file.
    Span(Span),
    /// A line and column, where there is no text to span (a byte that is
    /// not UTF-8).
    LineCol(usize, usize),
    /// A path in the document (JSON, whose parser keeps no positions).
    Path(String),
    /// The file as a whole.
    File,
}

/// A secondary position: another place involved in the error.
#[derive(Clone, Debug)]
pub struct Note {
    /// Where.
    pub location: Location,
    /// What is there.
    pub message: String,
}

/// One error in a mechanism file.
#[derive(Clone, Debug)]
pub struct Diagnostic {
    /// The file it is about.
    pub file: SourceFile,
    /// The main position.
    pub location: Location,
    /// What is wrong, naming the bodies, markers and joints involved.
    pub message: String,
    /// Other places involved (e.g. the first definition of a duplicate).
    pub notes: Vec<Note>,
    /// What to do about it.
    pub help: Option<String>,
}

impl Diagnostic {
    /// `file:line:col` (or `file (at path)`) of a location.
    pub fn position(&self, location: &Location) -> String {
        match location {
            Location::Span(span) => {
                let (line, col) = self.file.line_col(span.start);
                format!("{}:{}:{}", self.file.name, line, col)
            }
            Location::LineCol(line, col) => format!("{}:{}:{}", self.file.name, line, col),
            Location::Path(path) => format!("{} (at {})", self.file.name, path),
            Location::File => self.file.name.clone(),
        }
    }
}

impl Diagnostic {
    /// The diagnostic as a person reads it: `error: message`, its
    /// `file:line:col`, the lines of the file it points at with every place
    /// involved labelled, then the notes and the help. The CLI prints this
    /// and so does a failing `build.rs` (`dofplan::build`), so a user sees
    /// one form of every error. `colour` adds ANSI colour codes: for a
    /// terminal only.
    ///
    /// A diagnostic with no span in the file (JSON paths, a JSON syntax
    /// error's line and column, the file as a whole) has no lines to show
    /// and renders as its one-line [`Display`](fmt::Display) form.
    pub fn render(&self, colour: bool) -> String {
        use codespan_reporting::diagnostic::{Diagnostic as Snippet, Label};
        use codespan_reporting::term::{self, termcolor};

        let Location::Span(span) = &self.location else {
            return self.to_string();
        };
        let config = term::Config::default();
        let text = &*self.file.text;
        let mut spans = vec![span.clone()];
        spans.extend(self.notes.iter().filter_map(|n| match &n.location {
            Location::Span(s) => Some(s.clone()),
            _ => None,
        }));
        // Only the lines shown, long ones cut to a window: the file may be
        // one 50 MB line.
        let file = Excerpt::new(
            self.file.name.as_str(),
            text,
            &spans,
            config.start_context_lines,
            config.end_context_lines,
        );
        let mut labels = vec![Label::primary((), file.map(span, text))];
        let mut notes = Vec::new();
        for n in &self.notes {
            match &n.location {
                Location::Span(s) => {
                    labels.push(Label::secondary((), file.map(s, text)).with_message(n.message.clone()))
                }
                // A note elsewhere still reaches the user, as text.
                other => notes.push(format!("note: {}: {}", self.position(other), n.message)),
            }
        }
        if let Some(help) = &self.help {
            notes.push(format!("help: {help}"));
        }
        let snippet = Snippet::error()
            .with_message(self.message.clone())
            .with_labels(labels)
            .with_notes(notes);
        let rendered = if colour {
            let mut buffer = termcolor::Buffer::ansi();
            term::emit_to_write_style(&mut buffer, &config, &file, &snippet)
                .ok()
                .and_then(|()| String::from_utf8(buffer.into_inner()).ok())
        } else {
            term::emit_into_string(&config, &file, &snippet).ok()
        };
        // The span comes from this file's own parser, so rendering cannot
        // fail; if it ever did, the plain form still says everything.
        rendered.unwrap_or_else(|| self.to_string())
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: error: {}", self.position(&self.location), self.message)?;
        for note in &self.notes {
            write!(f, "\n  {}: note: {}", self.position(&note.location), note.message)?;
        }
        if let Some(help) = &self.help {
            write!(f, "\n  help: {help}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostic {}

/// All the errors found in one file (validation goes on past the first).
#[derive(Clone, Debug)]
pub struct ModelError {
    /// The errors, in file order of discovery.
    pub diagnostics: Vec<Diagnostic>,
}

/// The most diagnostics [`ModelError::render`] shows; it counts the rest.
pub const MAX_RENDERED: usize = 100;

impl ModelError {
    /// The diagnostics rendered as [`Diagnostic::render`] does, one after
    /// the other with a blank line between, and no newline at the end: the
    /// first `MAX_RENDERED`, then how many more there are. (Each one
    /// reads the file up to its position: a large file with errors
    /// everywhere would take minutes to show them all, and no one reads
    /// past the first hundred.)
    pub fn render(&self, colour: bool) -> String {
        let mut shown: Vec<String> = self
            .diagnostics
            .iter()
            .take(MAX_RENDERED)
            // A snippet ends in a blank line, a one-line form in nothing.
            .map(|d| d.render(colour).trim_end().to_string())
            .collect();
        let more = self.diagnostics.len().saturating_sub(MAX_RENDERED);
        if more > 0 {
            shown.push(format!(
                "error: {more} more error{} in {}, not shown: fix the {MAX_RENDERED} above and check again",
                if more == 1 { "" } else { "s" },
                self.diagnostics[0].file.name
            ));
        }
        shown.join("\n\n")
    }
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.diagnostics.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for ModelError {}
