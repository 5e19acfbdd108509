//! What the picture tests of both dimensions share: the SVG parsed back
//! into elements, found by class and text.

use std::collections::HashMap;

use dofplan_runtime::planar::Point;
use svg::node::element::tag::Type;
use svg::parser::Event;

/// One element of a parsed picture.
#[derive(Debug)]
pub(crate) struct El {
    pub name: String,
    pub attrs: HashMap<String, String>,
    /// The text directly inside it.
    pub text: String,
    /// The `class` of every enclosing element, outermost first.
    pub within: Vec<String>,
}

impl El {
    pub fn attr(&self, k: &str) -> &str {
        self.attrs.get(k).map(String::as_str).unwrap_or("")
    }

    pub fn f(&self, k: &str) -> f64 {
        self.attr(k)
            .parse()
            .unwrap_or_else(|_| panic!("{k}={:?} of {self:?}", self.attr(k)))
    }

    pub fn class(&self) -> &str {
        self.attr("class")
    }

    pub fn inside(&self, class: &str) -> bool {
        self.within.iter().any(|c| c == class)
    }

    /// The `points` attribute.
    pub fn points(&self) -> Vec<Point> {
        self.attr("points")
            .split_whitespace()
            .map(|xy| {
                let (x, y) = xy.split_once(',').expect("x,y");
                [x.parse().unwrap(), y.parse().unwrap()]
            })
            .collect()
    }
}

/// Parses a picture into its elements in document order, checking that it
/// is well formed: one `<svg>` root, tags nested, no parse error, no
/// non-finite number.
pub(crate) fn parse(svg: &str) -> Vec<El> {
    assert!(
        !svg.contains("NaN") && !svg.contains("inf"),
        "non-finite number in the SVG"
    );
    let mut out: Vec<El> = Vec::new();
    // (name, class, index in out) of the open elements.
    let mut open: Vec<(String, String, usize)> = Vec::new();
    let mut roots = 0;
    for event in svg::read(svg).expect("readable") {
        match event {
            Event::Error(e) => panic!("parse error: {e}"),
            Event::Tag(name, kind, attrs) => {
                if kind == Type::End {
                    let (open_name, _, _) = open.pop().expect("a closing tag closes something");
                    assert_eq!(open_name, name, "mismatched </{name}>");
                    continue;
                }
                if open.is_empty() {
                    roots += 1;
                    assert_eq!(name, "svg");
                }
                let attrs: HashMap<String, String> =
                    attrs.iter().map(|(k, v)| (k.clone(), v.to_string())).collect();
                let class = attrs.get("class").cloned().unwrap_or_default();
                out.push(El {
                    name: name.to_string(),
                    attrs,
                    text: String::new(),
                    within: open.iter().map(|(_, c, _)| c.clone()).collect(),
                });
                if kind == Type::Start {
                    open.push((name.to_string(), class, out.len() - 1));
                }
            }
            Event::Text(t) => {
                if let Some((_, _, i)) = open.last() {
                    out[*i].text.push_str(t);
                }
            }
            Event::Comment(_) | Event::Declaration(_) | Event::Instruction(_) => {
                panic!("unexpected markup")
            }
        }
    }
    assert!(open.is_empty(), "unclosed tags");
    assert_eq!(roots, 1);
    out
}

pub(crate) fn with_class<'a>(els: &'a [El], class: &str) -> Vec<&'a El> {
    els.iter().filter(|e| e.class() == class).collect()
}

pub(crate) fn texts(els: &[El]) -> Vec<&str> {
    els.iter()
        .filter(|e| e.name == "text")
        .map(|e| e.text.as_str())
        .collect()
}
