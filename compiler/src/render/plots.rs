//! Plots of a sweep's kinematics (`dofplan analyze --svg`), drawn with
//! plotters' SVG backend: the traced markers' paths (coupler curves), their
//! position, velocity and acceleration against the input, and each
//! four-bar loop's transmission angle with its extremes marked; for a
//! spatial sweep ([`draw_spatial`]), the traced markers' position, speed
//! and acceleration magnitude against the input.
//!
//! Plotters draws the frame of each panel (caption, axes, grid, tick
//! labels); the data are drawn here, as SVG added after plotters' output:
//! plotters rounds every coordinate to a whole pixel, which turns a smooth
//! curve into steps, while these paths keep two decimals. Each panel's
//! legend sits in a column right of its plot, off the curves, and lists at
//! most [`MAX_SERIES`] series (the others are counted, not drawn, so a
//! sweep of thousands of loops still gives a small file). A panel whose
//! values have a few far outliers (the frames next to a dead point) is
//! drawn over a robust range ([`robust_range`]); the curve is cut where it
//! leaves the range, the cuts are marked with triangles (class `clipped`)
//! and the legend gives the full range.
//!
//! Behind the `plots` feature: plotters is a dependency of the CLI, not of
//! `build.rs` users.

use std::fmt::Write as _;

use crate::format::thousands;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// One frame of a traced marker.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// The swept input's value.
    pub input: f64,
    /// The marker's position.
    pub at: [f64; 2],
    /// Its velocity and acceleration; `None` at a dead point (a gap in the
    /// plot, not a spike).
    pub rates: Option<([f64; 2], [f64; 2])>,
}

/// A traced marker's series.
pub struct Traced<'a> {
    /// "coupler.P".
    pub name: &'a str,
    /// One sample a frame.
    pub points: &'a [Sample],
}

/// A four-bar loop's transmission angle (input, degrees) over the sweep.
pub struct Loop<'a> {
    /// "ground–crank–coupler–rocker".
    pub name: String,
    /// One entry a frame.
    pub angles: &'a [(f64, f64)],
}

/// The most series a panel draws and lists in its legend; the others are
/// counted in one more legend line ("… 4,988 more loops not drawn"), as the
/// mechanism picture caps its legend.
pub const MAX_SERIES: usize = 12;

const WIDTH: u32 = 900;
const PANEL: u32 = 300;
/// The legend column right of each panel's plot.
const LEGEND_W: u32 = 210;
const LEGEND_FONT: f64 = 12.0;
const LEGEND_ROW: f64 = 17.0;
const COLOURS: [&str; 6] = ["#2563eb", "#dc2626", "#059669", "#d97706", "#7c3aed", "#0891b2"];

/// The SVG text: the paths panel, then position, velocity and acceleration
/// against `axis` (the swept input, moving at `rate`, e.g. "1 rad/s"),
/// then one transmission-angle panel.
pub fn draw(
    title: &str,
    axis: &str,
    rate: &str,
    traced: &[Traced],
    loops: &[Loop],
) -> Result<String, String> {
    let panels = if traced.is_empty() { 0 } else { 4 } + usize::from(!loops.is_empty());
    if panels == 0 {
        return Err("nothing to plot: the sweep traces no marker and has no four-bar loop".into());
    }
    let names: Vec<&str> = traced.iter().map(|t| t.name).collect();
    let of = |pick: &dyn Fn(&Sample) -> Option<Vec<f64>>| -> Vec<Vec<Point>> {
        (traced.iter())
            .map(|t| t.points.iter().map(|p| (p.input, pick(p))).collect())
            .collect()
    };
    let mut svg = String::new();
    let mut overlay = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, PANEL * panels as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let areas = root.split_evenly((panels, 1));
        let mut next = areas.iter();
        if !traced.is_empty() {
            paths(next.next().expect("a panel"), &mut overlay, title, traced)?;
            components(
                next.next().expect("a panel"),
                &mut overlay,
                ("position (solid x, thin y)", axis),
                (&names, "markers"),
                &of(&|p| Some(p.at.to_vec())),
            )?;
            components(
                next.next().expect("a panel"),
                &mut overlay,
                (
                    &format!("velocity (solid vx, thin vy), the input at {rate}"),
                    axis,
                ),
                (&names, "markers"),
                &of(&|p| p.rates.map(|(v, _)| v.to_vec())),
            )?;
            components(
                next.next().expect("a panel"),
                &mut overlay,
                (
                    &format!("acceleration (solid ax, thin ay), the input at {rate}"),
                    axis,
                ),
                (&names, "markers"),
                &of(&|p| p.rates.map(|(_, a)| a.to_vec())),
            )?;
        }
        if !loops.is_empty() {
            transmission(next.next().expect("a panel"), &mut overlay, axis, loops)?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(with_overlay(svg, &overlay))
}

/// A named series against the swept input: `None` where the frame has no
/// value (not solved, a dead point): a gap.
pub type Series<'a> = (&'a str, Vec<(f64, Option<f64>)>);

/// The plots of `analyze --forces --svg`: each input's force or torque
/// against `axis` (the swept input; `how` says held still or at which
/// rate), then the magnitude of each joint's reaction (the first
/// [`MAX_SERIES`] given: the caller puts the most loaded first).
pub fn draw_forces(
    title: &str,
    (axis, how): (&str, &str),
    inputs: &[Series],
    joints: &[Series],
    polar: Option<Polar>,
) -> Result<String, String> {
    let panels = 1 + usize::from(!joints.is_empty()) + usize::from(polar.is_some());
    let points = |s: &[Series]| -> Vec<Vec<Point>> {
        (s.iter())
            .map(|(_, p)| p.iter().map(|(x, v)| (*x, v.map(|v| vec![v]))).collect())
            .collect()
    };
    let names = |s: &[Series]| -> Vec<String> { s.iter().map(|(n, _)| n.to_string()).collect() };
    let mut svg = String::new();
    let mut overlay = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, PANEL * panels as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let areas = root.split_evenly((panels, 1));
        let input_names = names(inputs);
        let input_names: Vec<&str> = input_names.iter().map(String::as_str).collect();
        components(
            &areas[0],
            &mut overlay,
            (&format!("{title}: each input's force or torque, {how}"), axis),
            (&input_names, "inputs"),
            &points(inputs),
        )?;
        if !joints.is_empty() {
            let joint_names = names(joints);
            let joint_names: Vec<&str> = joint_names.iter().map(String::as_str).collect();
            components(
                &areas[1],
                &mut overlay,
                ("each joint's reaction, its magnitude", axis),
                (&joint_names, "joints"),
                &points(joints),
            )?;
        }
        if let Some(polar) = &polar {
            polar_panel(&areas[panels - 1], &mut overlay, polar)?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(with_overlay(svg, &overlay))
}

/// One joint's reaction over a sweep, for its polar diagram.
pub struct Polar<'a> {
    /// The joint's name.
    pub joint: &'a str,
    /// What the two components are along ("fx", "fy").
    pub axes: (&'a str, &'a str),
    /// Its two components at each frame (`None`: none there).
    pub points: Vec<Option<[f64; 2]>>,
}

/// A joint's polar load diagram: the tip of its reaction vector over the
/// sweep, drawn from the origin at one scale on both axes, with the
/// largest marked by a line from the origin and the first frame by a dot.
fn polar_panel(area: &Area, overlay: &mut String, polar: &Polar) -> Result<(), String> {
    let reach = (polar.points.iter().flatten())
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0f64, f64::max);
    let r = if reach > 0.0 { 1.1 * reach } else { 1.0 };
    let aspect = (WIDTH - LEGEND_W - 90) as f64 / (PANEL - 70) as f64;
    let caption = format!("joint {}'s reaction, polar", polar.joint);
    let chart = chart(
        area,
        &caption,
        16,
        -r * aspect..r * aspect,
        -r..r,
        polar.axes.0,
        Some(polar.axes.1),
        60,
    )?;
    let page = Page::of(&chart);
    let mut runs = vec![Vec::new()];
    for p in &polar.points {
        match p {
            Some(p) if p.iter().all(|v| v.is_finite()) => {
                runs.last_mut().expect("a run").push(page.at(p[0], p[1]))
            }
            _ => runs.push(Vec::new()),
        }
    }
    let colour = COLOURS[0];
    let (ox, oy) = page.at(0.0, 0.0);
    let peak = (polar.points.iter().flatten()).max_by(|a, b| a[0].hypot(a[1]).total_cmp(&b[0].hypot(b[1])));
    if let Some(p) = peak {
        let (px_, py_) = page.at(p[0], p[1]);
        curve(overlay, &[vec![(ox, oy), (px_, py_)]], COLOURS[1], 1.5);
    }
    curve(overlay, &runs, colour, 2.0);
    let _ = writeln!(
        overlay,
        r#"<circle class="origin" cx="{}" cy="{}" r="3" fill="black"/>"#,
        px(ox),
        px(oy)
    );
    if let Some(first) = polar.points.iter().flatten().next() {
        let (fx, fy) = page.at(first[0], first[1]);
        let _ = writeln!(
            overlay,
            r#"<circle class="start" cx="{}" cy="{}" r="4" fill="{colour}"/>"#,
            px(fx),
            px(fy)
        );
    }
    let entries = vec![
        (Key::Line(colour), format!("{}'s force, tip", polar.joint)),
        (Key::Line(COLOURS[1]), format!("largest, {}", short(reach))),
        (Key::None, "dot: the first frame".to_string()),
    ];
    legend(overlay, &page, &entries);
    Ok(())
}

/// Plotters' SVG with `overlay` (the data, the legends) drawn over it.
fn with_overlay(mut svg: String, overlay: &str) -> String {
    let at = svg.rfind("</svg>").unwrap_or(svg.len());
    svg.insert_str(at, overlay);
    svg
}

/// Bounds of `values` with a margin (a flat series gets a unit span).
fn span(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    padded(lo, hi)
}

/// `lo..hi` widened by 5 % each side (a point gets a unit span).
fn padded(lo: f64, hi: f64) -> (f64, f64) {
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5_f64.max(lo.abs() * 0.05)
    };
    (lo - pad, hi + pad)
}

/// The range a panel shows of `values`: all of them, unless a few lie far
/// outside the bulk. The bulk is the 2nd to 98th percentile; a value more
/// than that spread (or, for a flat bulk, a tenth of its size) beyond it
/// is an outlier — the frames next to a dead point, where a rate grows
/// without bound. The outliers are left out only when showing them would
/// take more than half again the room of the rest (else nothing is cut).
/// Returns the range drawn and, when values were left out of it, the full
/// range of the values.
pub fn robust_range(values: &[f64]) -> ((f64, f64), Option<(f64, f64)>) {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return ((-1.0, 1.0), None);
    }
    v.sort_by(f64::total_cmp);
    let (min, max) = (v[0], v[v.len() - 1]);
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    let (q_lo, q_hi) = (at(0.02), at(0.98));
    let reach = (q_hi - q_lo).max(0.1 * q_lo.abs().max(q_hi.abs()));
    let (lo, hi) = (min.max(q_lo - reach), max.min(q_hi + reach));
    let full = padded(min, max);
    let bulk = padded(lo, hi);
    if full.1 - full.0 > 1.5 * (bulk.1 - bulk.0) {
        (bulk, Some((min, max)))
    } else {
        (full, None)
    }
}

type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A panel's chart with its caption (`caption_size` points), axes over `x`
/// and `y`, and its mesh with the axes' descriptions drawn, on the left of
/// `area` (the legend column is left free on the right); `y_labels` is the
/// width left for the y labels.
#[allow(clippy::too_many_arguments)]
fn chart<'a, 'b>(
    area: &'a Area<'b>,
    caption: &str,
    caption_size: u32,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    x_desc: &str,
    y_desc: Option<&str>,
    y_labels: u32,
) -> Result<Chart<'a, 'b>, String> {
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", caption_size))
        .margin(10)
        .margin_right(10 + LEGEND_W)
        .x_label_area_size(30)
        .y_label_area_size(y_labels)
        .build_cartesian_2d(x, y)
        .map_err(|e| e.to_string())?;
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(x_desc);
    if let Some(d) = y_desc {
        mesh.y_desc(d);
    }
    mesh.draw().map_err(|e| e.to_string())?;
    Ok(chart)
}

/// Data to page coordinates, as plotters maps them but without rounding
/// to whole pixels.
#[derive(Clone, Copy, Debug)]
struct Page {
    x: (f64, f64),
    y: (f64, f64),
    /// The plotting area's left and right pixel columns.
    px: (f64, f64),
    /// Its bottom and top pixel rows (y grows downwards on the page).
    py: (f64, f64),
}

impl Page {
    fn of(chart: &Chart) -> Page {
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        let (x, y) = (chart.x_range(), chart.y_range());
        Page {
            x: (x.start, x.end),
            y: (y.start, y.end),
            px: (xs.start as f64, (xs.end - 1) as f64),
            py: ((ys.end - 1) as f64, ys.start as f64),
        }
    }

    fn at(&self, x: f64, y: f64) -> (f64, f64) {
        let f = |v: f64, (lo, hi): (f64, f64), (a, b): (f64, f64)| a + (b - a) * (v - lo) / (hi - lo);
        (f(x, self.x, self.px), f(y, self.y, self.py))
    }

    /// The right edge of the panel's legend column starts here.
    fn legend_left(&self) -> f64 {
        self.px.1 + 24.0
    }
}

/// A number with two decimals at most (page coordinates).
fn px(v: f64) -> String {
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// `text` with the characters XML reserves escaped.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// One curve: runs of page points, joined within a run.
fn curve(out: &mut String, runs: &[Vec<(f64, f64)>], colour: &str, width: f64) {
    let mut d = String::new();
    for run in runs.iter().filter(|r| !r.is_empty()) {
        for (i, &(x, y)) in run.iter().enumerate() {
            let _ = write!(d, "{}{} {}", if i == 0 { 'M' } else { 'L' }, px(x), px(y));
        }
    }
    if !d.is_empty() {
        let _ = writeln!(
            out,
            r#"<path class="curve" d="{d}" fill="none" stroke="{colour}" stroke-width="{}" stroke-linejoin="round"/>"#,
            px(width)
        );
    }
}

/// Runs of `points` (input, value; `None` a gap) on the page, cut where a
/// value leaves `lo..=hi` (at the crossing), and the crossings: where a
/// run stops or starts at the range's edge, and whether above it.
#[allow(clippy::type_complexity)]
fn clip_runs(
    page: &Page,
    points: &[(f64, Option<f64>)],
    (lo, hi): (f64, f64),
) -> (Vec<Vec<(f64, f64)>>, Vec<((f64, f64), bool)>) {
    let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    let mut cuts = Vec::new();
    let inside = |y: f64| (lo..=hi).contains(&y);
    let mut prev: Option<(f64, f64)> = None;
    for &(x, v) in points {
        let Some(y) = v.filter(|y| y.is_finite() && x.is_finite()) else {
            runs.push(Vec::new());
            prev = None;
            continue;
        };
        match prev {
            None => {
                if inside(y) {
                    runs.last_mut().expect("a run").push(page.at(x, y));
                }
            }
            Some((x0, y0)) => {
                // The segment's part inside the range (Liang–Barsky on y).
                let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
                let dy = y - y0;
                for (edge, below) in [(lo, true), (hi, false)] {
                    if dy == 0.0 {
                        if (below && y0 < edge) || (!below && y0 > edge) {
                            t0 = 1.0;
                            t1 = 0.0;
                        }
                        continue;
                    }
                    let t = (edge - y0) / dy;
                    let entering = if below { dy > 0.0 } else { dy < 0.0 };
                    if entering {
                        t0 = t0.max(t);
                    } else {
                        t1 = t1.min(t);
                    }
                }
                if t0 <= t1 {
                    let at = |t: f64| (x0 + t * (x - x0), (y0 + t * dy).clamp(lo, hi));
                    let (a, b) = (at(t0), at(t1));
                    if t0 > 0.0 {
                        // Comes in from beyond an edge: a new run.
                        runs.push(vec![page.at(a.0, a.1)]);
                        cuts.push((page.at(a.0, a.1), y0 > hi));
                    } else if runs.last().is_some_and(Vec::is_empty) {
                        runs.last_mut().expect("a run").push(page.at(a.0, a.1));
                    }
                    runs.last_mut().expect("a run").push(page.at(b.0, b.1));
                    if t1 < 1.0 {
                        cuts.push((page.at(b.0, b.1), y > hi));
                        runs.push(Vec::new());
                    }
                }
            }
        }
        prev = Some((x, y));
    }
    runs.retain(|r| r.len() > 1);
    (runs, cuts)
}

/// A triangle at a cut, pointing the way the curve went off the range.
fn cut_mark(out: &mut String, (x, y): (f64, f64), up: bool, colour: &str) {
    let (tip, base) = if up {
        (y - 7.0, y + 1.0)
    } else {
        (y + 7.0, y - 1.0)
    };
    let _ = writeln!(
        out,
        r#"<path class="clipped" d="M{} {}L{} {}L{} {}Z" fill="{colour}" stroke="none"/>"#,
        px(x),
        px(tip),
        px(x - 4.5),
        px(base),
        px(x + 4.5),
        px(base)
    );
}

/// A legend line: a key and a text, possibly cut to fit the column.
enum Key {
    Line(&'static str),
    Clipped,
    None,
}

/// The legend of a panel: `entries` down the column right of the plot.
fn legend(out: &mut String, page: &Page, entries: &[(Key, String)]) {
    let left = page.legend_left();
    let top = page.py.1 + 4.0;
    let _ = writeln!(
        out,
        r##"<g class="legend" font-family="sans-serif" font-size="{LEGEND_FONT}" fill="#222222">"##
    );
    for (i, (key, text)) in entries.iter().enumerate() {
        let y = top + i as f64 * LEGEND_ROW;
        let mid = y + 8.0;
        let text_x = match key {
            Key::Line(colour) => {
                let _ = writeln!(
                    out,
                    r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{colour}" stroke-width="2"/>"#,
                    px(left),
                    px(mid),
                    px(left + 20.0),
                    px(mid)
                );
                left + 26.0
            }
            Key::Clipped => {
                cut_mark(out, (left + 6.0, mid + 3.0), true, "#555555");
                cut_mark(out, (left + 16.0, mid - 3.0), false, "#555555");
                left + 26.0
            }
            Key::None => left,
        };
        // Characters that fit before the page's edge (no font metrics:
        // an average sans-serif glyph is about 0.52 of the font size).
        let room = ((left + LEGEND_W as f64 - 14.0 - text_x) / (LEGEND_FONT * 0.52)) as usize;
        let shown: String = if text.chars().count() > room {
            text.chars().take(room.saturating_sub(1)).chain(['…']).collect()
        } else {
            text.clone()
        };
        let title = if shown == *text {
            String::new()
        } else {
            format!("<title>{}</title>", escape(text))
        };
        let _ = writeln!(
            out,
            r#"<text class="legend-entry" x="{}" y="{}">{title}{}</text>"#,
            px(text_x),
            px(mid + 4.0),
            escape(&shown)
        );
    }
    let _ = writeln!(out, "</g>");
}

/// The legend entries of `names` (the first [`MAX_SERIES`] drawn), with
/// one more line counting those not drawn.
fn series_entries(names: &[&str], what: &str) -> Vec<(Key, String)> {
    let mut entries: Vec<(Key, String)> = (names.iter().take(MAX_SERIES).enumerate())
        .map(|(k, n)| (Key::Line(COLOURS[k % COLOURS.len()]), n.to_string()))
        .collect();
    if names.len() > MAX_SERIES {
        entries.push((
            Key::None,
            format!("… {} more {what} not drawn", thousands(names.len() - MAX_SERIES)),
        ));
    }
    entries
}

/// The traced markers' paths in the plane, at one scale on both axes.
fn paths(area: &Area, overlay: &mut String, title: &str, traced: &[Traced]) -> Result<(), String> {
    let drawn = &traced[..traced.len().min(MAX_SERIES)];
    let (x0, x1) = span(drawn.iter().flat_map(|t| t.points.iter().map(|p| p.at[0])));
    let (y0, y1) = span(drawn.iter().flat_map(|t| t.points.iter().map(|p| p.at[1])));
    // One scale: widen the narrower range to the plot's aspect.
    let aspect = (WIDTH - LEGEND_W - 90) as f64 / (PANEL - 70) as f64;
    let (w, h) = (x1 - x0, y1 - y0);
    let (x0, x1, y0, y1) = if w / h > aspect {
        let extra = (w / aspect - h) / 2.0;
        (x0, x1, y0 - extra, y1 + extra)
    } else {
        let extra = (h * aspect - w) / 2.0;
        (x0 - extra, x1 + extra, y0, y1)
    };
    let caption = format!("{title}: paths of the traced markers");
    let chart = chart(area, &caption, 18, x0..x1, y0..y1, "x", Some("y"), 50)?;
    let page = Page::of(&chart);
    for (k, t) in drawn.iter().enumerate() {
        let mut runs = vec![Vec::new()];
        for p in t.points {
            if p.at.iter().all(|v| v.is_finite()) {
                runs.last_mut().expect("a run").push(page.at(p.at[0], p.at[1]));
            } else {
                runs.push(Vec::new());
            }
        }
        curve(overlay, &runs, COLOURS[k % COLOURS.len()], 2.0);
    }
    let names: Vec<&str> = traced.iter().map(|t| t.name).collect();
    legend(overlay, &page, &series_entries(&names, "markers"));
    Ok(())
}

/// One frame of a series against the input: the input, and the
/// components, `None` at a dead point.
type Point = (f64, Option<Vec<f64>>);

/// Components of each named series against the input, the first
/// component thickest and each next one thinner; gaps where a point has
/// nothing (dead points). Over a robust range: far outliers are cut off
/// and marked.
fn components(
    area: &Area,
    overlay: &mut String,
    (caption, axis): (&str, &str),
    (names, what): (&[&str], &str),
    series: &[Vec<Point>],
) -> Result<(), String> {
    let drawn = &series[..series.len().min(MAX_SERIES)];
    let (x0, x1) = span(drawn.iter().flat_map(|s| s.iter().map(|p| p.0)));
    let values: Vec<f64> = (drawn.iter())
        .flat_map(|s| s.iter().filter_map(|p| p.1.as_ref()).flatten().copied())
        .collect();
    let ((y0, y1), full) = robust_range(&values);
    let chart = chart(area, caption, 16, x0..x1, y0..y1, axis, None, 60)?;
    let page = Page::of(&chart);
    let mut cuts = Vec::new();
    for (k, points) in drawn.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let count = points
            .iter()
            .filter_map(|p| p.1.as_ref().map(Vec::len))
            .max()
            .unwrap_or(0);
        for component in 0..count {
            let width = (count - component) as f64 + f64::from(u8::from(count == 1));
            let values: Vec<(f64, Option<f64>)> = (points.iter())
                .map(|(x, v)| (*x, v.as_ref().and_then(|v| v.get(component)).copied()))
                .collect();
            let (runs, c) = clip_runs(&page, &values, (y0, y1));
            curve(overlay, &runs, colour, width);
            cuts.extend(c.into_iter().map(|c| (c, colour)));
        }
    }
    for ((at, up), colour) in cuts {
        cut_mark(overlay, at, up, colour);
    }
    let mut entries = series_entries(names, what);
    if let Some((lo, hi)) = full {
        entries.push((Key::Clipped, "cut off at the axis:".into()));
        entries.push((Key::None, format!("values run from {}", short(lo))));
        entries.push((Key::None, format!("to {}", short(hi))));
    }
    legend(overlay, &page, &entries);
    Ok(())
}

/// A value in four significant figures at most, for the legend
/// ("-6012", "0.03142", "1.2e-7").
fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    if !(-4..6).contains(&magnitude) {
        return format!("{x:.3e}");
    }
    let decimals = (3 - magnitude).max(0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// One frame of a traced marker of a spatial sweep.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample3 {
    /// The swept input's value.
    pub input: f64,
    /// The marker's position.
    pub at: [f64; 3],
    /// Its velocity and acceleration; `None` where they are not known (a
    /// dead point, or a plan whose rates are not computed): a gap.
    pub rates: Option<([f64; 3], [f64; 3])>,
}

/// A traced marker's series of a spatial sweep.
pub struct Traced3<'a> {
    /// "coupler.M".
    pub name: &'a str,
    /// One sample a frame.
    pub points: &'a [Sample3],
}

/// The SVG text of a spatial sweep's plots: the traced markers' position
/// (x, y, z), speed and acceleration magnitude against `axis` (the swept
/// input, moving at `rate`). No path panel: `simulate --svg` draws the
/// paths in space, in four views.
pub fn draw_spatial(title: &str, axis: &str, rate: &str, traced: &[Traced3]) -> Result<String, String> {
    if traced.is_empty() {
        return Err("nothing to plot: the sweep traces no marker".into());
    }
    let names: Vec<&str> = traced.iter().map(|t| t.name).collect();
    let of = |pick: &dyn Fn(&Sample3) -> Option<Vec<f64>>| -> Vec<Vec<Point>> {
        (traced.iter())
            .map(|t| t.points.iter().map(|p| (p.input, pick(p))).collect())
            .collect()
    };
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let mut svg = String::new();
    let mut overlay = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, PANEL * 3)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let areas = root.split_evenly((3, 1));
        components(
            &areas[0],
            &mut overlay,
            (
                &format!("{title}: position of the traced markers (thick x, medium y, thin z)"),
                axis,
            ),
            (&names, "markers"),
            &of(&|p| Some(p.at.to_vec())),
        )?;
        components(
            &areas[1],
            &mut overlay,
            (&format!("speed |v|, the input at {rate}"), axis),
            (&names, "markers"),
            &of(&|p| p.rates.map(|(v, _)| vec![norm(v)])),
        )?;
        components(
            &areas[2],
            &mut overlay,
            (&format!("acceleration |a|, the input at {rate}"), axis),
            (&names, "markers"),
            &of(&|p| p.rates.map(|(_, a)| vec![norm(a)])),
        )?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(with_overlay(svg, &overlay))
}

/// Transmission angles against the input, the extremes of each loop marked
/// and labelled (inside the plot: a label near the right edge ends at its
/// point, one near the top or bottom sits on the inner side).
fn transmission(area: &Area, overlay: &mut String, axis: &str, loops: &[Loop]) -> Result<(), String> {
    let drawn = &loops[..loops.len().min(MAX_SERIES)];
    let (x0, x1) = span(drawn.iter().flat_map(|l| l.angles.iter().map(|p| p.0)));
    let (lo, hi) = span(drawn.iter().flat_map(|l| l.angles.iter().map(|p| p.1)));
    let chart = chart(
        area,
        "transmission angle (degrees; 90 is ideal, below 40 or above 140 transmits poorly)",
        16,
        x0..x1,
        lo.min(-5.0)..hi.max(185.0),
        axis,
        Some("μ (°)"),
        50,
    )?;
    let page = Page::of(&chart);
    let mut labels = String::new();
    // Label boxes placed so far (left, top, right, bottom): a label that
    // would overlap one is left out (its point keeps a tooltip).
    let mut placed: Vec<[f64; 4]> = Vec::new();
    for (k, l) in drawn.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let points: Vec<(f64, Option<f64>)> = l.angles.iter().map(|&(x, y)| (x, Some(y))).collect();
        let (runs, _) = clip_runs(&page, &points, (f64::NEG_INFINITY, f64::INFINITY));
        curve(overlay, &runs, colour, 2.0);
        let min = l
            .angles
            .iter()
            .filter(|p| p.1.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let max = l
            .angles
            .iter()
            .filter(|p| p.1.is_finite())
            .max_by(|a, b| a.1.total_cmp(&b.1));
        for (p, what) in [(min, "min"), (max, "max")] {
            let Some(&(x, y)) = p else { continue };
            let (cx, cy) = page.at(x, y);
            let text = format!("{what} {y:.1}° at {x:.1}");
            let _ = writeln!(
                overlay,
                r#"<circle class="extreme" cx="{}" cy="{}" r="4" fill="{colour}"><title>{}: {}</title></circle>"#,
                px(cx),
                px(cy),
                escape(&l.name),
                escape(&text)
            );
            // Ends at the point in the plot's right half, starts there in
            // its left half; below the point in the upper half, above it in
            // the lower half: always inside the plot.
            let right_half = cx > 0.5 * (page.px.0 + page.px.1);
            let (anchor, tx) = if right_half {
                ("end", cx - 7.0)
            } else {
                ("start", cx + 7.0)
            };
            let upper_half = cy < 0.5 * (page.py.0 + page.py.1);
            let ty = if upper_half { cy + 16.0 } else { cy - 8.0 };
            let w = text.chars().count() as f64 * 13.0 * 0.56;
            let left = if right_half { tx - w } else { tx };
            let bbox = [left, ty - 11.0, left + w, ty + 3.0];
            let overlaps =
                |b: &[f64; 4]| b[0] < bbox[2] && bbox[0] < b[2] && b[1] < bbox[3] && bbox[1] < b[3];
            if placed.iter().any(overlaps) {
                continue;
            }
            placed.push(bbox);
            let _ = writeln!(
                labels,
                r##"<text class="extreme-label" x="{}" y="{}" text-anchor="{anchor}" font-family="sans-serif" font-size="13" fill="#222222" stroke="#ffffff" stroke-width="3" paint-order="stroke">{}</text>"##,
                px(tx),
                px(ty),
                escape(&text)
            );
        }
    }
    overlay.push_str(&labels);
    let names: Vec<&str> = loops.iter().map(|l| l.name.as_str()).collect();
    legend(overlay, &page, &series_entries(&names, "loops"));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sine traced over a turn, its rates those of the sine; with
    /// `spike` the acceleration of two frames next to 90° is huge.
    fn samples(spike: bool) -> Vec<Sample> {
        (0..=360)
            .map(|i| {
                let t = f64::from(i).to_radians();
                let mut a = [-t.cos(), -t.sin()];
                if spike && (i == 89 || i == 91) {
                    a[0] = -6000.0;
                }
                Sample {
                    input: f64::from(i),
                    at: [t.cos(), t.sin()],
                    rates: (i != 90).then_some(([-t.sin(), t.cos()], a)),
                }
            })
            .collect()
    }

    fn attribute<'a>(element: &'a str, name: &str) -> &'a str {
        let start = element.find(&format!(" {name}=\"")).expect("the attribute") + name.len() + 3;
        let end = element[start..].find('"').expect("its end");
        &element[start..start + end]
    }

    /// The elements of `svg` whose class is `class`.
    fn elements<'a>(svg: &'a str, class: &str) -> Vec<&'a str> {
        svg.match_indices(&format!("class=\"{class}\""))
            .map(|(i, _)| {
                let start = svg[..i].rfind('<').expect("an element");
                let end = i + svg[i..].find('>').expect("its end");
                &svg[start..=end]
            })
            .collect()
    }

    #[test]
    fn curves_keep_sub_pixel_coordinates() {
        let points = samples(false);
        let traced = [Traced {
            name: "coupler.P",
            points: &points,
        }];
        let svg = draw("sine", "theta (degrees)", "1 rad/s", &traced, &[]).unwrap();
        let curves = elements(&svg, "curve");
        assert!(!curves.is_empty());
        let numbers: Vec<f64> = (curves.iter())
            .flat_map(|c| {
                attribute(c, "d")
                    .split(['M', 'L', ' '])
                    .filter(|s| !s.is_empty())
                    .map(|s| s.parse::<f64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect();
        let whole = numbers.iter().filter(|v| v.fract() == 0.0).count();
        // A smooth curve lands on whole pixels by chance only.
        assert!(
            whole * 10 < numbers.len(),
            "{whole} of {} coordinates are whole pixels",
            numbers.len()
        );
        // The velocity's gap at the dead point (frame 90) stays a gap: the
        // velocity panel's two components each have two runs.
        assert!(curves.iter().any(|c| attribute(c, "d").matches('M').count() == 2));
    }

    #[test]
    fn far_outliers_are_cut_off_and_marked() {
        let points = samples(true);
        let traced = [Traced {
            name: "coupler.P",
            points: &points,
        }];
        let svg = draw("sine", "theta (degrees)", "1 rad/s", &traced, &[]).unwrap();
        // Two frames at -6000 cut: the acceleration's x component leaves the
        // range and comes back twice, each marked.
        assert_eq!(elements(&svg, "clipped").len(), 4, "{svg}");
        assert!(svg.contains("values run from -6000"), "the full range is given");
        let plain = draw(
            "sine",
            "theta (degrees)",
            "1 rad/s",
            &[Traced {
                name: "coupler.P",
                points: &samples(false),
            }],
            &[],
        )
        .unwrap();
        assert!(elements(&plain, "clipped").is_empty());
        assert!(!plain.contains("cut off"));
    }

    #[test]
    fn the_robust_range_leaves_out_only_far_outliers() {
        let mut v: Vec<f64> = (0..361).map(|i| f64::from(i).to_radians().sin()).collect();
        let (range, full) = robust_range(&v);
        assert_eq!(full, None);
        assert!(range.0 < -1.0 && range.1 > 1.0);
        v[100] = -6000.0;
        let (range, full) = robust_range(&v);
        assert_eq!(full, Some((-6000.0, 1.0)));
        assert!(range.0 > -5.0 && range.0 < -1.0, "{range:?}");
        // A steep but steady rise is not cut.
        let steep: Vec<f64> = (0..361).map(|i| f64::from(i).powi(3)).collect();
        assert_eq!(robust_range(&steep).1, None);
    }

    #[test]
    fn legends_are_capped_and_beside_the_plot() {
        let angles: Vec<(f64, f64)> = (0..=36)
            .map(|i| (f64::from(i * 10), 90.0 + f64::from(i)))
            .collect();
        let loops: Vec<Loop> = (0..5000)
            .map(|k| Loop {
                name: format!("loop {k}"),
                angles: &angles,
            })
            .collect();
        let svg = draw("many", "theta (degrees)", "1 rad/s", &[], &loops).unwrap();
        let entries = elements(&svg, "legend-entry");
        assert_eq!(entries.len(), MAX_SERIES + 1);
        assert!(svg.contains("… 4,988 more loops not drawn"), "{svg}");
        assert_eq!(elements(&svg, "curve").len(), MAX_SERIES);
        assert!(svg.len() < 200_000, "{} bytes", svg.len());
        // Every legend entry starts right of the plotting area and ends
        // within the page.
        for e in entries {
            let x: f64 = attribute(e, "x").parse().unwrap();
            assert!(x > f64::from(WIDTH - LEGEND_W), "{e}");
        }
    }

    #[test]
    fn extreme_labels_stay_inside_the_plot() {
        // The largest angle at the right end, the smallest at the left.
        let angles: Vec<(f64, f64)> = (0..=360)
            .map(|i| (f64::from(i), 20.0 + f64::from(i) * 0.45))
            .collect();
        let loops = [Loop {
            name: "ground–crank–coupler–rocker".into(),
            angles: &angles,
        }];
        let svg = draw("edge", "theta (degrees)", "1 rad/s", &[], &loops).unwrap();
        let labels = elements(&svg, "extreme-label");
        assert_eq!(labels.len(), 2);
        for l in labels {
            let x: f64 = attribute(l, "x").parse().unwrap();
            let anchor = attribute(l, "text-anchor");
            let at = svg.find(l).unwrap() + l.len();
            let text = &svg[at..at + svg[at..].find("</text>").unwrap()];
            if text.starts_with("max") {
                assert_eq!(anchor, "end", "a label at the right edge ends at its point");
            } else {
                assert_eq!(anchor, "start");
            }
            assert!(x > 0.0 && x < f64::from(WIDTH - LEGEND_W), "{l}");
        }
    }
}
