//! Colours, number formatting and small element builders shared by every
//! part of the picture.

use dofplan_runtime::planar::Point;
use svg::node::element::Line;

use crate::model::Body;

/// Colours of the mobile bodies, in order (a colour-blind-friendly
/// categorical palette without its grey, kept for the ground).
pub(super) const BODY_COLOURS: [&str; 9] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf",
];
/// Colour of fixed bodies.
pub(super) const GROUND_COLOUR: &str = "#7f7f7f";
/// Colours of the traces: darker and more saturated than the bodies'.
const TRACE_COLOURS: [&str; 6] = ["#c2185b", "#00695c", "#4527a0", "#e65100", "#1b5e20", "#283593"];
/// Dark ink for outlines and text.
pub(super) const INK: &str = "#222222";
/// Softer ink for secondary text and the ground.
pub(super) const GREY: &str = "#555555";
/// The drag target: a red that none of the bodies or traces use.
pub(super) const TARGET_COLOUR: &str = "#d50000";

/// The colour of the `k`-th trace.
pub(super) fn trace_colour(k: usize) -> &'static str {
    TRACE_COLOURS[k % TRACE_COLOURS.len()]
}

/// A number with at most two decimals, no trailing zeros.
pub(super) fn num(x: f64) -> String {
    if !x.is_finite() {
        return "0".to_string();
    }
    let mut s = format!("{x:.2}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".to_string();
    }
    s
}

/// A rough width of a text in pixels (no font metrics without a font).
pub(super) fn text_width(text: &str, font_size: f64) -> f64 {
    text.chars().count() as f64 * font_size * 0.6
}

/// A line between two page points.
pub(super) fn line(a: Point, b: Point) -> Line {
    Line::new()
        .set("x1", num(a[0]))
        .set("y1", num(a[1]))
        .set("x2", num(b[0]))
        .set("y2", num(b[1]))
}

/// Page points as an SVG `points` attribute.
pub(super) fn points(ps: &[Point]) -> String {
    let mut out = String::with_capacity(ps.len() * 12);
    for (i, p) in ps.iter().enumerate() {
        if i > 0 {
            out.push(' ');
        }
        out.push_str(&num(p[0]));
        out.push(',');
        out.push_str(&num(p[1]));
    }
    out
}

/// Dashes `node` (whose line is `width` wide) when `on`: the mark of
/// whatever did not meet its input exactly (stretched trace segments and
/// poses). Dashes scale with the line so a thick bar still reads as dashed.
pub(super) fn dashed<N: svg::Node>(mut node: N, width: f64, on: bool) -> N {
    if on {
        node.assign(
            "stroke-dasharray",
            format!("{} {}", num(2.0 * width.max(2.0)), num(1.5 * width.max(2.0))),
        );
    }
    node
}

/// The colour of body `b` in either dimension: the ground grey, the mobile
/// bodies by rank.
pub(crate) fn colour_of<M>(bodies: &[Body<M>], b: usize) -> &'static str {
    if bodies.get(b).is_none_or(|body| body.fixed) {
        return GROUND_COLOUR;
    }
    let rank = bodies[..b].iter().filter(|body| !body.fixed).count();
    BODY_COLOURS[rank % BODY_COLOURS.len()]
}

/// The dash pattern of the stitch on stretched poses.
pub(crate) const STITCH_DASH: &str = "4 3";

/// A residual in three significant figures at most ("0.0567", "2.1e-7").
pub(crate) fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return num(x);
    }
    if x.abs() >= 1e-3 {
        let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.1e}")
    }
}
