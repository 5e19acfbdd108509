//! The legend under the plot: traces and the marks of the picture first,
//! then the bodies, capped so that a mechanism of thousands of bodies still
//! gets a short legend.

use svg::node::element::{Circle, Group, Line, Path, Rectangle, Text};

use super::spatial::symbol::{symbol, HATCH_ID};
use super::style::STITCH_DASH;
use super::style::{num, text_width, GREY, GROUND_COLOUR, INK, TARGET_COLOUR};
use crate::format::thousands;
use crate::model::spatial::JointKind;

/// At most this many entries are listed; the rest are counted in one more
/// line ("… and 1,990 more bodies").
pub(super) const MAX_ENTRIES: usize = 12;
/// Height of a legend row in pixels.
pub(super) const ROW: f64 = 18.0;
const FONT: f64 = 12.0;

/// The key drawn before an entry's text.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Key {
    /// A trace: a line in its colour.
    Trace(&'static str),
    /// Stretched frames: a stitched box (their traces are dashed, their
    /// poses stitched).
    Stretched,
    /// Stretched frames whose joints all hold (an input or a drag target
    /// missed): a dashed line, as their traces are drawn.
    Dashed,
    /// Searched frames: a ring.
    Searched,
    /// The drag target and its path.
    Target,
    /// A body: a filled box in its colour.
    Body(&'static str),
    /// The ground of a spatial drawing: a hatched box.
    Ground,
    /// A spatial joint kind: its symbol.
    Joint(JointKind),
    /// The count of entries left out: no key.
    More,
}

/// One line of the legend.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Entry {
    pub key: Key,
    pub label: String,
}

/// Caps `entries` at `MAX_ENTRIES`: when there are more, the first
/// `MAX_ENTRIES` stay and one line counts the others.
pub(super) fn cap(entries: Vec<Entry>) -> Vec<Entry> {
    cap_at(entries, MAX_ENTRIES)
}

/// [`cap`] at `most` entries.
pub(super) fn cap_at(mut entries: Vec<Entry>, most: usize) -> Vec<Entry> {
    if entries.len() <= most + 1 {
        // One more line would take the room of the count anyway.
        return entries;
    }
    let hidden = entries.split_off(most);
    let bodies = hidden.iter().filter(|e| matches!(e.key, Key::Body(_))).count();
    let what = if bodies == hidden.len() {
        if bodies == 1 {
            "body"
        } else {
            "bodies"
        }
    } else {
        "entries"
    };
    entries.push(Entry {
        key: Key::More,
        label: format!("\u{2026} and {} more {what}", thousands(hidden.len())),
    });
    entries
}

/// The legend's grid: entries read down the columns.
pub(super) struct Layout {
    col_w: f64,
    pub rows: usize,
}

impl Layout {
    /// Columns as wide as the longest label, as many as fit in `width`.
    pub fn new(entries: &[Entry], width: f64) -> Layout {
        let label_w = entries
            .iter()
            .map(|e| text_width(&e.label, FONT))
            .fold(0.0, f64::max);
        let col_w = (label_w + 34.0).min(width);
        let cols = ((width / col_w).floor() as usize).max(1);
        Layout {
            col_w,
            rows: entries.len().div_ceil(cols),
        }
    }

    /// The height in pixels.
    pub fn height(&self) -> f64 {
        self.rows as f64 * ROW
    }
}

/// Draws the legend with its top-left corner at (`left`, `top`).
pub(super) fn draw(entries: &[Entry], layout: &Layout, left: f64, top: f64) -> Group {
    let mut g = Group::new()
        .set("class", "legend")
        .set("font-size", FONT)
        .set("fill", INK);
    for (i, e) in entries.iter().enumerate() {
        let x = left + (i / layout.rows.max(1)) as f64 * layout.col_w;
        let y = top + (i % layout.rows.max(1)) as f64 * ROW;
        let hline = |colour: &str, width: f64| {
            Line::new()
                .set("x1", num(x))
                .set("y1", num(y + 7.0))
                .set("x2", num(x + 22.0))
                .set("y2", num(y + 7.0))
                .set("stroke", colour.to_string())
                .set("stroke-width", width)
        };
        g = match &e.key {
            Key::Trace(colour) => g.add(hline(colour, 2.5)),
            Key::Stretched => g.add(
                // A stitched body, as stretched poses are drawn.
                Group::new()
                    .add(
                        Rectangle::new()
                            .set("x", num(x + 3.0))
                            .set("y", num(y + 1.0))
                            .set("width", 16)
                            .set("height", 12)
                            .set("fill", GREY),
                    )
                    .add(
                        Rectangle::new()
                            .set("x", num(x + 5.0))
                            .set("y", num(y + 3.0))
                            .set("width", 12)
                            .set("height", 8)
                            .set("fill", "none")
                            .set("stroke", "#ffffff")
                            .set("stroke-width", 1.5)
                            .set("stroke-dasharray", STITCH_DASH),
                    ),
            ),
            Key::Dashed => g.add(super::style::dashed(hline(GREY, 2.0), 2.0, true)),
            Key::Searched => g.add(
                Circle::new()
                    .set("cx", num(x + 11.0))
                    .set("cy", num(y + 7.0))
                    .set("r", 3.5)
                    .set("fill", "#ffffff")
                    .set("stroke", GREY)
                    .set("stroke-width", 1.5),
            ),
            Key::Target => g.add(
                Group::new()
                    .set("fill", "none")
                    .set("stroke", TARGET_COLOUR)
                    .set("stroke-width", 1.5)
                    .add(
                        Circle::new()
                            .set("cx", num(x + 11.0))
                            .set("cy", num(y + 7.0))
                            .set("r", 5),
                    )
                    .add(Path::new().set(
                        "d",
                        format!(
                            "M{} {}H{}M{} {}V{}",
                            num(x + 3.0),
                            num(y + 7.0),
                            num(x + 19.0),
                            num(x + 11.0),
                            num(y - 1.0),
                            num(y + 15.0)
                        ),
                    )),
            ),
            Key::Body(colour) => g.add(
                Rectangle::new()
                    .set("x", num(x + 3.0))
                    .set("y", num(y + 1.0))
                    .set("width", 16)
                    .set("height", 12)
                    .set("fill", *colour)
                    .set("stroke", INK)
                    .set("stroke-width", 0.5),
            ),
            Key::Ground => g.add(
                Rectangle::new()
                    .set("x", num(x + 3.0))
                    .set("y", num(y + 1.0))
                    .set("width", 16)
                    .set("height", 12)
                    .set("fill", format!("url(#{HATCH_ID})"))
                    .set("stroke", GROUND_COLOUR)
                    .set("stroke-width", 1)
                    .set("stroke-dasharray", "3 2"),
            ),
            Key::Joint(kind) => g.add(symbol(*kind, [1.0, 0.0], 1.0).set(
                "transform",
                format!("translate({} {})", num(x + 11.0), num(y + 7.0)),
            )),
            Key::More => g,
        };
        g = g.add(
            Text::new(e.label.clone())
                .set("class", "legend-entry")
                .set("x", num(if e.key == Key::More { x + 3.0 } else { x + 28.0 }))
                .set("y", num(y + 11.5)),
        );
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bodies(n: usize) -> Vec<Entry> {
        (0..n)
            .map(|i| Entry {
                key: Key::Body("#000"),
                label: format!("b{i}"),
            })
            .collect()
    }

    #[test]
    fn caps_long_legends() {
        assert_eq!(cap(bodies(13)).len(), 13);
        let capped = cap(bodies(2002));
        assert_eq!(capped.len(), MAX_ENTRIES + 1);
        assert_eq!(capped[11].label, "b11");
        assert_eq!(capped[12].label, "\u{2026} and 1,990 more bodies");
        assert_eq!(capped[12].key, Key::More);
    }

    #[test]
    fn thousands_separators() {
        assert_eq!(thousands(7), "7");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(1234567), "1,234,567");
    }
}
