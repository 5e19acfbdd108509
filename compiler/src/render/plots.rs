//! Plots of a sweep's kinematics (`dofplan analyze --svg`), drawn with
//! plotters' SVG backend: the traced markers' paths (coupler curves), their
//! position, velocity and acceleration against the input, and each
//! four-bar loop's transmission angle with its extremes marked; for a
//! spatial sweep ([`draw_spatial`]), the traced markers' position, speed
//! and acceleration magnitude against the input.
//!
//! Behind the `plots` feature: plotters is a dependency of the CLI, not of
//! `build.rs` users.

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

const WIDTH: u32 = 900;
const PANEL: u32 = 300;
const COLOURS: [RGBColor; 6] = [
    RGBColor(37, 99, 235),
    RGBColor(220, 38, 38),
    RGBColor(5, 150, 105),
    RGBColor(217, 119, 6),
    RGBColor(124, 58, 237),
    RGBColor(8, 145, 178),
];

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
    let mut svg = String::new();
    if panels == 0 {
        return Err("nothing to plot: the sweep traces no marker and has no four-bar loop".into());
    }
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, PANEL * panels as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let areas = root.split_evenly((panels, 1));
        let mut next = areas.iter();
        if !traced.is_empty() {
            paths(next.next().expect("a panel"), title, traced)?;
            against(
                next.next().expect("a panel"),
                "position (solid x, thin y)",
                axis,
                traced,
                &|p| Some((p.at[0], p.at[1])),
            )?;
            against(
                next.next().expect("a panel"),
                &format!("velocity (solid vx, thin vy), the input at {rate}"),
                axis,
                traced,
                &|p| p.rates.map(|(v, _)| (v[0], v[1])),
            )?;
            against(
                next.next().expect("a panel"),
                &format!("acceleration (solid ax, thin ay), the input at {rate}"),
                axis,
                traced,
                &|p| p.rates.map(|(_, a)| (a[0], a[1])),
            )?;
        }
        if !loops.is_empty() {
            transmission(next.next().expect("a panel"), axis, loops)?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(svg)
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
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5_f64.max(lo.abs() * 0.05)
    };
    (lo - pad, hi + pad)
}

type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// A panel's chart with its caption (`caption_size` points), axes over `x`
/// and `y`, and its mesh with the axes' descriptions drawn; `y_labels` is
/// the width left for the y labels.
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

/// The series' legend, on a pale box.
fn legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>) -> Result<(), String> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())
}

/// The traced markers' paths in the plane, at one scale on both axes.
fn paths(area: &Area, title: &str, traced: &[Traced]) -> Result<(), String> {
    let (x0, x1) = span(traced.iter().flat_map(|t| t.points.iter().map(|p| p.at[0])));
    let (y0, y1) = span(traced.iter().flat_map(|t| t.points.iter().map(|p| p.at[1])));
    // One scale: widen the narrower range to the panel's aspect.
    let aspect = (WIDTH - 80) as f64 / (PANEL - 70) as f64;
    let (w, h) = (x1 - x0, y1 - y0);
    let (x0, x1, y0, y1) = if w / h > aspect {
        let extra = (w / aspect - h) / 2.0;
        (x0, x1, y0 - extra, y1 + extra)
    } else {
        let extra = (h * aspect - w) / 2.0;
        (x0 - extra, x1 + extra, y0, y1)
    };
    let caption = format!("{title}: paths of the traced markers");
    let mut chart = chart(area, &caption, 18, x0..x1, y0..y1, "x", Some("y"), 50)?;
    for (k, t) in traced.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        chart
            .draw_series(LineSeries::new(
                t.points.iter().map(|p| (p.at[0], p.at[1])),
                colour.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?
            .label(t.name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
    }
    legend(&mut chart)
}

/// A pair of components per traced marker against the input: the first
/// solid, the second thin; gaps where `pick` has nothing (dead points).
fn against(
    area: &Area,
    caption: &str,
    axis: &str,
    traced: &[Traced],
    pick: &dyn Fn(&Sample) -> Option<(f64, f64)>,
) -> Result<(), String> {
    let names: Vec<&str> = traced.iter().map(|t| t.name).collect();
    let series: Vec<Vec<Point>> = (traced.iter())
        .map(|t| {
            (t.points.iter())
                .map(|p| (p.input, pick(p).map(|(a, b)| vec![a, b])))
                .collect()
        })
        .collect();
    components(area, caption, axis, &names, &series)
}

/// One frame of a series against the input: the input, and the
/// components, `None` at a dead point.
type Point = (f64, Option<Vec<f64>>);

/// Components of each named series against the input, the first
/// component thickest and each next one thinner; gaps where a point has
/// nothing (dead points).
fn components(
    area: &Area,
    caption: &str,
    axis: &str,
    names: &[&str],
    series: &[Vec<Point>],
) -> Result<(), String> {
    let (x0, x1) = span(series.iter().flat_map(|s| s.iter().map(|p| p.0)));
    let (y0, y1) = span(
        series
            .iter()
            .flat_map(|s| s.iter().filter_map(|p| p.1.as_ref()).flatten().copied()),
    );
    let mut chart = chart(area, caption, 16, x0..x1, y0..y1, axis, None, 60)?;
    for (k, (name, points)) in names.iter().zip(series).enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let count = points
            .iter()
            .filter_map(|p| p.1.as_ref().map(Vec::len))
            .max()
            .unwrap_or(0);
        for component in 0..count {
            let width = (count - component) as u32 + u32::from(count == 1);
            // Runs between gaps, each its own line.
            let mut run: Vec<(f64, f64)> = Vec::new();
            let mut runs = Vec::new();
            for (x, v) in points {
                match v.as_ref().and_then(|v| v.get(component)) {
                    Some(y) => run.push((*x, *y)),
                    None => runs.push(std::mem::take(&mut run)),
                }
            }
            runs.push(run);
            for (r, points) in runs.into_iter().filter(|r| !r.is_empty()).enumerate() {
                let series = chart
                    .draw_series(LineSeries::new(points, colour.stroke_width(width)))
                    .map_err(|e| e.to_string())?;
                if r == 0 && component == 0 {
                    let name = name.to_string();
                    series.label(name).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                    });
                }
            }
        }
    }
    legend(&mut chart)
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
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, PANEL * 3)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let areas = root.split_evenly((3, 1));
        components(
            &areas[0],
            &format!("{title}: position of the traced markers (thick x, medium y, thin z)"),
            axis,
            &names,
            &of(&|p| Some(p.at.to_vec())),
        )?;
        components(
            &areas[1],
            &format!("speed |v|, the input at {rate}"),
            axis,
            &names,
            &of(&|p| p.rates.map(|(v, _)| vec![norm(v)])),
        )?;
        components(
            &areas[2],
            &format!("acceleration |a|, the input at {rate}"),
            axis,
            &names,
            &of(&|p| p.rates.map(|(_, a)| vec![norm(a)])),
        )?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(svg)
}

/// Transmission angles against the input, the extremes of each loop marked
/// and labelled.
fn transmission(area: &Area, axis: &str, loops: &[Loop]) -> Result<(), String> {
    let (x0, x1) = span(loops.iter().flat_map(|l| l.angles.iter().map(|p| p.0)));
    let (lo, hi) = span(loops.iter().flat_map(|l| l.angles.iter().map(|p| p.1)));
    let mut chart = chart(
        area,
        "transmission angle (degrees; 90 is ideal, below 40 or above 140 transmits poorly)",
        16,
        x0..x1,
        lo.min(0.0)..hi.max(180.0),
        axis,
        Some("μ (°)"),
        50,
    )?;
    for (k, l) in loops.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        chart
            .draw_series(LineSeries::new(l.angles.iter().copied(), colour.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label(l.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        let min = l.angles.iter().min_by(|a, b| a.1.total_cmp(&b.1));
        let max = l.angles.iter().max_by(|a, b| a.1.total_cmp(&b.1));
        for (p, what) in [(min, "min"), (max, "max")] {
            if let Some(&(x, y)) = p {
                chart
                    .draw_series(std::iter::once(Circle::new((x, y), 4, colour.filled())))
                    .map_err(|e| e.to_string())?;
                chart
                    .draw_series(std::iter::once(Text::new(
                        format!("{what} {y:.1}° at {x:.1}"),
                        (x, y),
                        ("sans-serif", 13),
                    )))
                    .map_err(|e| e.to_string())?;
            }
        }
    }
    legend(&mut chart)
}
