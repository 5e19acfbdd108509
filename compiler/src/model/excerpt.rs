//! The lines of a mechanism file that a diagnostic shows, cut to size.
//!
//! codespan-reporting, left to itself, indexes the start of every line of
//! the file, walks every line a label spans, and prints each shown line
//! whole: a 50 MB file written on one line came back as a 100 MB error,
//! and a label over a whole file of short lines built an entry per line. An
//! [`Excerpt`] holds only the lines a diagnostic shows — the lines its
//! labels start and end on, with the context lines codespan adds — each
//! long line cut to a window around its labels, `...` marking what is left
//! out (as rustc does). codespan renders the excerpt and gets the real line
//! numbers and columns from it, so the carets and `file:line:col` point where
//! they did.

use std::collections::BTreeMap;
use std::ops::Range;

use codespan_reporting::files::{Error, Files};

/// Lines up to this many bytes are shown whole; longer ones as a window.
pub const LONG_LINE: usize = 160;
/// How much of a long line a window shows before its first label (bytes).
const BEFORE: usize = 40;
/// How much of a long line a window shows from its first label on (bytes).
const AFTER: usize = 80;
/// What stands for the text a window leaves out.
const ELLIPSIS: &str = "...";

/// One line of the excerpt (or a stand-in for lines left out between two).
#[derive(Debug)]
struct Shown {
    /// Where the line's text is in [`Excerpt::text`] (ellipses included);
    /// empty for a stand-in.
    range: Range<usize>,
    /// The 1-based line number in the file (a stand-in's is the line's
    /// before it: codespan counts its digits, never prints it).
    number: usize,
    /// Whether this is a stand-in for lines left out.
    stand_in: bool,
    /// The whole line in the file (byte offsets, its `\n` left out).
    line: Range<usize>,
    /// The part of the line shown.
    window: Range<usize>,
    /// The 0-based column (in characters) where the window starts.
    column: usize,
}

impl Shown {
    /// Where the window's text starts in the excerpt (past an ellipsis).
    fn inner(&self) -> usize {
        self.range.start
            + if self.window.start > self.line.start {
                ELLIPSIS.len()
            } else {
                0
            }
    }
}

/// A diagnostic's lines of a file, for codespan-reporting (one file, id
/// `()`), with the labels' spans moved into it by [`Excerpt::map`].
#[derive(Debug)]
pub struct Excerpt<'a> {
    name: &'a str,
    text: String,
    lines: Vec<Shown>,
}

/// A line to show: where it starts in the file and the label ends on it.
struct Wanted {
    start: usize,
    marks: Vec<usize>,
}

impl<'a> Excerpt<'a> {
    /// The excerpt of `text` that shows `spans` (byte ranges in `text`),
    /// with codespan's `start_context` lines after the first line of a
    /// label over several lines and `end_context` lines before its last.
    pub fn new(
        name: &'a str,
        text: &str,
        spans: &[Range<usize>],
        start_context: usize,
        end_context: usize,
    ) -> Self {
        // Every label end with its line (index and start): one pass over
        // the file, up to the last of them.
        let mut ends: Vec<usize> = spans
            .iter()
            .flat_map(|s| [clamp(text, s.start), clamp(text, s.end.max(s.start))])
            .collect();
        ends.sort_unstable();
        ends.dedup();
        let mut line_of = BTreeMap::new();
        let (mut line, mut line_start, mut scanned) = (0usize, 0usize, 0usize);
        for &p in &ends {
            let segment = &text.as_bytes()[scanned..p];
            let newlines = segment.iter().filter(|&&b| b == b'\n').count();
            if newlines > 0 {
                line += newlines;
                line_start = scanned + segment.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            }
            scanned = p;
            line_of.insert(p, (line, line_start));
        }

        let mut wanted: BTreeMap<usize, Wanted> = BTreeMap::new();
        let want = |wanted: &mut BTreeMap<usize, Wanted>, index: usize, start: usize, mark: Option<usize>| {
            let w = wanted.entry(index).or_insert(Wanted { start, marks: vec![] });
            w.marks.extend(mark);
        };
        for s in spans {
            let (a, b) = (clamp(text, s.start), clamp(text, s.end.max(s.start)));
            let (first, first_start) = line_of[&a];
            let (last, last_start) = line_of[&b];
            want(&mut wanted, first, first_start, Some(a));
            want(&mut wanted, last, last_start, Some(b));
            // codespan shows these lines of a label over several.
            let mut start = first_start;
            for index in first + 1..(first + 1 + start_context).min(last) {
                start = line_end(text, start) + 1;
                want(&mut wanted, index, start, None);
            }
            let mut start = last_start;
            for index in (last.saturating_sub(end_context)..last).rev() {
                if index <= first {
                    break;
                }
                start = line_start_before(text, start);
                want(&mut wanted, index, start, None);
            }
        }
        // codespan shows a single line left out between two shown ones
        // rather than a break: so does the excerpt.
        let gaps: Vec<(usize, usize)> = wanted
            .iter()
            .zip(wanted.iter().skip(1))
            .filter(|((a, _), (b, _))| *b - *a == 2)
            .map(|((a, w), _)| (a + 1, line_end(text, w.start) + 1))
            .collect();
        for (index, start) in gaps {
            want(&mut wanted, index, start, None);
        }

        let mut excerpt = Excerpt {
            name,
            text: String::new(),
            lines: Vec::new(),
        };
        let mut previous = None;
        for (index, w) in wanted {
            if let Some(p) = previous {
                if index > p + 1 {
                    // Two stand-ins: codespan draws a break (`·`) where
                    // shown lines are more than two apart, and the stand-ins
                    // are never within a label's context lines, so they are
                    // never printed.
                    excerpt.stand_in();
                    excerpt.stand_in();
                }
                excerpt.text.push('\n');
            }
            previous = Some(index);
            excerpt.push(text, index + 1, w.start, &w.marks);
        }
        excerpt
    }

    /// A stand-in for lines left out: empty, at the end of the text so far.
    fn stand_in(&mut self) {
        let end = self.text.len();
        let number = self.lines.last().map_or(1, |l| l.number);
        self.lines.push(Shown {
            range: end..end,
            number,
            stand_in: true,
            line: 0..0,
            window: 0..0,
            column: 0,
        });
    }

    /// The file's line `number` (starting at byte `start`), cut to a window
    /// from a little before the first of `marks` when it is long.
    fn push(&mut self, text: &str, number: usize, start: usize, marks: &[usize]) {
        let end = line_end(text, start);
        let window = if end - start <= LONG_LINE {
            start..end
        } else {
            let focus = marks.iter().copied().min().unwrap_or(start).clamp(start, end);
            let mut from = floor_boundary(text, focus.saturating_sub(BEFORE).max(start));
            // Cutting off no more than the ellipsis takes shows nothing.
            if from - start <= ELLIPSIS.len() {
                from = start;
            }
            let mut to = floor_boundary(text, (focus + AFTER).min(end));
            if end - to <= ELLIPSIS.len() {
                to = end;
            }
            from..to
        };
        let begin = self.text.len();
        if window.start > start {
            self.text.push_str(ELLIPSIS);
        }
        self.text.push_str(&text[window.clone()]);
        if window.end < end {
            self.text.push_str(ELLIPSIS);
        }
        self.lines.push(Shown {
            range: begin..self.text.len(),
            number,
            stand_in: false,
            line: start..end,
            column: text[start..window.start].chars().count(),
            window,
        });
    }

    /// A span of `text` (the file the excerpt was made from, the span one
    /// of those it was made for) moved into the excerpt: each end onto its
    /// line's window, an end the window leaves out onto its ellipsis.
    pub fn map(&self, span: &Range<usize>, text: &str) -> Range<usize> {
        let start = self.offset(clamp(text, span.start));
        let end = self.offset(clamp(text, span.end.max(span.start)));
        start..end.max(start)
    }

    /// Where file offset `p` (on a shown line) is in the excerpt.
    fn offset(&self, p: usize) -> usize {
        let Some(l) = self
            .lines
            .iter()
            .find(|l| !l.stand_in && l.line.start <= p && p <= l.line.end)
        else {
            return 0;
        };
        if p < l.window.start {
            l.range.start
        } else if p > l.window.end {
            l.range.end
        } else {
            l.inner() + (p - l.window.start)
        }
    }

    fn shown(&self, line_index: usize) -> Result<&Shown, Error> {
        self.lines.get(line_index).ok_or(Error::LineTooLarge {
            given: line_index,
            max: self.lines.len().saturating_sub(1),
        })
    }
}

impl<'e> Files<'e> for Excerpt<'_> {
    type FileId = ();
    type Name = &'e str;
    type Source = &'e str;

    fn name(&'e self, (): ()) -> Result<&'e str, Error> {
        Ok(self.name)
    }

    fn source(&'e self, (): ()) -> Result<&'e str, Error> {
        Ok(&self.text)
    }

    fn line_index(&'e self, (): (), byte_index: usize) -> Result<usize, Error> {
        // The last shown line starting at or before the offset.
        Ok(self
            .lines
            .iter()
            .rposition(|l| !l.stand_in && l.range.start <= byte_index)
            .unwrap_or(0))
    }

    fn line_number(&'e self, (): (), line_index: usize) -> Result<usize, Error> {
        Ok(self.shown(line_index)?.number)
    }

    fn column_number(&'e self, (): (), line_index: usize, byte_index: usize) -> Result<usize, Error> {
        // The file's column: the window's own, plus the characters shown
        // before the offset.
        let l = self.shown(line_index)?;
        let inner = l.inner();
        let upto = byte_index.clamp(inner, inner.max(l.range.end));
        let shown = self.text.get(inner..upto).map_or(0, |s| s.chars().count());
        Ok(l.column + shown + 1)
    }

    fn line_range(&'e self, (): (), line_index: usize) -> Result<Range<usize>, Error> {
        Ok(self.shown(line_index)?.range.clone())
    }
}

/// `p` within the text, moved back to the start of the character it falls
/// in.
fn clamp(text: &str, p: usize) -> usize {
    floor_boundary(text, p.min(text.len()))
}

/// The end of the line starting at (or running through) `start`: the
/// offset of its `\n`, or the end of the text.
fn line_end(text: &str, start: usize) -> usize {
    let start = start.min(text.len());
    text.as_bytes()[start..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(text.len(), |i| start + i)
}

/// The start of the line before the one starting at `start` (> 0).
fn line_start_before(text: &str, start: usize) -> usize {
    let before = &text.as_bytes()[..start.saturating_sub(1)];
    before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1)
}

/// `p`, moved back to the start of the character it falls in.
fn floor_boundary(text: &str, mut p: usize) -> usize {
    while !text.is_char_boundary(p) {
        p -= 1;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use codespan_reporting::diagnostic::{Diagnostic, Label};
    use codespan_reporting::files::SimpleFile;
    use codespan_reporting::term::{self, Config};

    /// The labels as codespan renders them over the excerpt.
    fn excerpt(text: &str, spans: &[Range<usize>]) -> String {
        let config = Config::default();
        let file = Excerpt::new(
            "f.toml",
            text,
            spans,
            config.start_context_lines,
            config.end_context_lines,
        );
        let labels = spans
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let s = file.map(s, text);
                if i == 0 {
                    Label::primary((), s)
                } else {
                    Label::secondary((), s).with_message("here")
                }
            })
            .collect();
        let d = Diagnostic::error().with_message("m").with_labels(labels);
        term::emit_into_string(&config, &file, &d).unwrap()
    }

    /// The labels as codespan renders them over the whole file.
    fn whole(text: &str, spans: &[Range<usize>]) -> String {
        let file = SimpleFile::new("f.toml", text);
        let labels = spans
            .iter()
            .enumerate()
            .map(|(i, s)| {
                if i == 0 {
                    Label::primary((), s.clone())
                } else {
                    Label::secondary((), s.clone()).with_message("here")
                }
            })
            .collect();
        let d = Diagnostic::error().with_message("m").with_labels(labels);
        term::emit_into_string(&Config::default(), &file, &d).unwrap()
    }

    #[test]
    fn short_lines_render_as_the_whole_file_does() {
        let text: String = (1..=40).map(|i| format!("line{i} = {i}\n")).collect();
        let at = |line: usize| text.match_indices("line").nth(line - 1).unwrap().0;
        let cases: Vec<Vec<Range<usize>>> = vec![
            vec![at(3)..at(3) + 5],
            vec![at(3)..at(3), at(5)..at(5) + 2],
            vec![at(3)..at(4) + 2, at(7)..at(7) + 1],
            // over many lines: the first three and the last two shown
            vec![at(2)..at(30) + 3],
            vec![0..text.len(), at(20)..at(20) + 5],
            vec![at(40)..text.len()],
            vec![text.len()..text.len()],
        ];
        for spans in cases {
            assert_eq!(excerpt(&text, &spans), whole(&text, &spans), "{spans:?}");
        }
    }

    #[test]
    fn a_long_line_is_cut_around_the_label() {
        // x = [0, 1, 2, ...]: the label on the value 5000, far into the line.
        let values: Vec<String> = (0..20_000).map(|i| i.to_string()).collect();
        let text = format!("# c\nx = [{}]\ny = 1\n", values.join(", "));
        let at = text.find(" 5000,").unwrap() + 1;
        let label = at..at + 4;
        let out = excerpt(&text, std::slice::from_ref(&label));
        // Line and column as in the file; the line cut on both sides.
        let col = text[..at].len() - text.find('x').unwrap() + 1;
        assert!(out.contains(&format!("f.toml:2:{col}")), "{out}");
        assert!(out.lines().all(|l| l.len() < 200), "{out}");
        let source = out.lines().find(|l| l.starts_with("2 │")).unwrap();
        assert!(source.starts_with("2 │ ...") && source.ends_with("..."), "{out}");
        // The caret is under the value.
        let caret = out.lines().find(|l| l.contains('^')).unwrap();
        let column = caret.find('^').unwrap();
        assert_eq!(&source[column..column + 4], "5000", "{out}");
        assert_eq!(caret.matches('^').count(), 4, "{out}");
    }

    #[test]
    fn a_label_over_a_long_line_and_past_it_stays_short() {
        let text = format!(
            "a = \"{}\"\nb = [\n{}]\n",
            "é".repeat(100_000),
            "1,\n".repeat(100_000)
        );
        let spans = [0..text.len(), 3..8];
        let out = excerpt(&text, &spans);
        assert!(out.len() < 2_000, "{out}");
        assert!(out.contains("f.toml:1:1"), "{out}");
        // the last line shown is the file's last (empty) line
        assert!(out.contains(&format!("{} │", 100_003)), "{out}");
    }
}
