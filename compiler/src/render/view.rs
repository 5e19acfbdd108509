//! The frame of the picture: the world box to show, the world-to-page
//! transform and the scale bar that gives the page its unit.

use dofplan_runtime::planar::Point;
use svg::node::element::{Group, Path, Text};

use super::style::{line, num, GREY, INK};

/// The smallest height of the plot area in pixels (a flat mechanism still
/// gets room for its pivots and labels).
const MIN_PLOT_HEIGHT: f64 = 150.0;

/// True when both coordinates are finite.
pub(super) fn finite(p: Point) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

/// The distance between two points.
pub(super) fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// An axis-aligned box grown point by point (non-finite points ignored).
pub(super) struct BBox {
    pub lo: Point,
    pub hi: Point,
}

impl BBox {
    pub fn new() -> BBox {
        BBox {
            lo: [f64::INFINITY; 2],
            hi: [f64::NEG_INFINITY; 2],
        }
    }

    pub fn add(&mut self, p: Point) {
        if !finite(p) {
            return;
        }
        for (k, v) in p.into_iter().enumerate() {
            self.lo[k] = self.lo[k].min(v);
            self.hi[k] = self.hi[k].max(v);
        }
    }
}

/// World to page coordinates: uniform scale, y flipped (world y is up, page
/// y is down), so text stays upright and pixel lengths do not depend on the
/// mechanism's size.
pub(super) struct View {
    /// Pixels per world unit.
    pub scale: f64,
    x0: f64,
    y1: f64,
    ox: f64,
    oy: f64,
    /// The plot area: left, top, width, height in pixels.
    pub left: f64,
    pub top: f64,
    pub plot_w: f64,
    pub plot_h: f64,
}

impl View {
    /// Fits `bbox` (with a margin) into a plot `plot_w` wide whose top-left
    /// corner is at (`left`, `top`), keeping the aspect ratio.
    pub fn fit(bbox: &BBox, size: f64, plot_w: f64, left: f64, top: f64) -> View {
        let (mut lo, mut hi) = if bbox.lo[0] <= bbox.hi[0] {
            (bbox.lo, bbox.hi)
        } else {
            ([0.0, 0.0], [0.0, 0.0])
        };
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let extent = if extent.is_finite() && extent > 0.0 {
            extent
        } else {
            size
        };
        let margin = 0.08 * extent;
        for k in 0..2 {
            lo[k] -= margin;
            hi[k] += margin;
            // A flat box still gets some height (or width).
            let min = 0.3 * extent;
            if hi[k] - lo[k] < min {
                let c = 0.5 * (hi[k] + lo[k]);
                lo[k] = c - 0.5 * min;
                hi[k] = c + 0.5 * min;
            }
        }
        let ww = hi[0] - lo[0];
        let wh = hi[1] - lo[1];
        let plot_h = (plot_w * wh / ww).clamp(MIN_PLOT_HEIGHT, 1.25 * plot_w);
        let plot_h = if plot_h.is_finite() { plot_h } else { plot_w };
        let scale = (plot_w / ww).min(plot_h / wh);
        let scale = if scale.is_finite() && scale > 0.0 {
            scale
        } else {
            1.0
        };
        View {
            scale,
            x0: lo[0],
            y1: hi[1],
            ox: left + 0.5 * (plot_w - ww * scale),
            oy: top + 0.5 * (plot_h - wh * scale),
            left,
            top,
            plot_w,
            plot_h,
        }
    }

    /// A view of `scale` pixels per world unit whose plot area is `plot_w`
    /// by `plot_h` with its top-left corner at (`left`, `top`), with the
    /// world point `centre` at the middle of the plot (several views of one
    /// scale side by side).
    pub fn centred(centre: Point, scale: f64, left: f64, top: f64, plot_w: f64, plot_h: f64) -> View {
        View {
            scale,
            x0: centre[0] - 0.5 * plot_w / scale,
            y1: centre[1] + 0.5 * plot_h / scale,
            ox: left,
            oy: top,
            left,
            top,
            plot_w,
            plot_h,
        }
    }

    /// The page position of a world point.
    pub fn px(&self, p: Point) -> Point {
        [
            self.ox + (p[0] - self.x0) * self.scale,
            self.oy + (self.y1 - p[1]) * self.scale,
        ]
    }

    /// True when a page point lies in the plot area.
    pub fn contains(&self, q: Point) -> bool {
        q[0] >= self.left
            && q[0] <= self.left + self.plot_w
            && q[1] >= self.top
            && q[1] <= self.top + self.plot_h
    }
}

/// A round length (1, 2 or 5 times a power of ten, in world units): the
/// longest one at most `max_px` long on the page, as its mantissa and
/// exponent so that it can be printed exactly.
pub(super) fn round_length(scale: f64, max_px: f64) -> Option<(u32, i32)> {
    let most = max_px / scale;
    if !(most.is_finite() && most > 0.0) {
        return None;
    }
    let mut exp = most.log10().floor() as i32;
    // log10 may land a hair off at exact powers of ten.
    if 10f64.powi(exp + 1) <= most {
        exp += 1;
    } else if 10f64.powi(exp) > most {
        exp -= 1;
    }
    let decade = 10f64.powi(exp);
    let mantissa = [5, 2, 1]
        .into_iter()
        .find(|&k| k as f64 * decade <= most)
        .unwrap_or(1);
    Some((mantissa, exp))
}

/// `mantissa · 10^exp` written without floating-point noise ("0.05",
/// "2000").
pub(super) fn format_round(mantissa: u32, exp: i32) -> String {
    if exp >= 0 {
        format!("{mantissa}{}", "0".repeat(exp as usize))
    } else {
        format!("0.{}{mantissa}", "0".repeat((-exp - 1) as usize))
    }
}

/// The height of the strip that holds the scale bar.
pub(super) const SCALE_STRIP: f64 = 24.0;

/// A scale bar in the strip whose top is at `top`, right-aligned to
/// `right`: a round length in model units, its ends ticked and its length
/// written beside it ("2 units").
pub(super) fn scale_bar(view: &View, right: f64, top: f64) -> Option<Group> {
    let (mantissa, exp) = round_length(view.scale, 120.0)?;
    let label = format_round(mantissa, exp);
    let length = mantissa as f64 * 10f64.powi(exp);
    let px = length * view.scale;
    let y = top + 14.0;
    let (x0, x1) = (right - px, right);
    let ticks = format!(
        "M{} {}V{}M{} {}V{}",
        num(x0),
        num(y - 4.0),
        num(y + 4.0),
        num(x1),
        num(y - 4.0),
        num(y + 4.0)
    );
    let unit = if mantissa == 1 && exp == 0 {
        "unit"
    } else {
        "units"
    };
    Some(
        Group::new()
            .set("class", "scale-bar")
            .set("data-length", label.clone())
            .add(line([x0, y], [x1, y]).set("stroke", INK).set("stroke-width", 2))
            .add(
                Path::new()
                    .set("d", ticks)
                    .set("stroke", INK)
                    .set("stroke-width", 1.5),
            )
            .add(
                Text::new(format!("{label} {unit}"))
                    .set("x", num(x0 - 8.0))
                    .set("y", num(y + 4.0))
                    .set("text-anchor", "end")
                    .set("font-size", 12)
                    .set("fill", GREY),
            ),
    )
}

/// Convex hull (monotone chain) of page points, counter-clockwise on the
/// page, collinear points dropped.
pub(crate) fn hull(mut ps: Vec<Point>) -> Vec<Point> {
    ps.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    ps.dedup_by(|a, b| (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
    if ps.len() < 3 {
        return ps;
    }
    let cross = |o: Point, a: Point, b: Point| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    let mut out: Vec<Point> = Vec::with_capacity(2 * ps.len());
    for pass in 0..2 {
        let start = out.len();
        let iter: Box<dyn Iterator<Item = &Point>> = if pass == 0 {
            Box::new(ps.iter())
        } else {
            Box::new(ps.iter().rev())
        };
        for &p in iter {
            while out.len() >= start + 2 && cross(out[out.len() - 2], out[out.len() - 1], p) <= 0.0 {
                out.pop();
            }
            out.push(p);
        }
        out.pop();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_lengths_are_one_two_five() {
        // 100 px per unit, at most 120 px: 1 unit.
        assert_eq!(round_length(100.0, 120.0), Some((1, 0)));
        // 1 px per unit: 100 units (120 fits, 200 does not).
        assert_eq!(round_length(1.0, 120.0), Some((1, 2)));
        assert_eq!(round_length(0.5, 120.0), Some((2, 2)));
        assert_eq!(round_length(0.2, 120.0), Some((5, 2)));
        assert_eq!(round_length(1000.0, 120.0), Some((1, -1)));
        assert_eq!(round_length(2000.0, 120.0), Some((5, -2)));
        // Exactly a power of ten fits.
        assert_eq!(round_length(12.0, 120.0), Some((1, 1)));
        assert_eq!(round_length(0.0, 120.0), None);
        assert_eq!(round_length(f64::NAN, 120.0), None);
        for scale in [0.013, 0.7, 3.3, 47.0, 810.0, 1.0e5] {
            let (k, e) = round_length(scale, 120.0).unwrap();
            let px = k as f64 * 10f64.powi(e) * scale;
            // At most 120 px, and more than 120/2.5 (the widest gap between
            // round lengths).
            assert!(px <= 120.0 + 1e-9 && px > 48.0 - 1e-9, "{scale}: {px}");
        }
    }

    #[test]
    fn round_lengths_print_exactly() {
        assert_eq!(format_round(5, -2), "0.05");
        assert_eq!(format_round(1, -1), "0.1");
        assert_eq!(format_round(2, 0), "2");
        assert_eq!(format_round(2, 3), "2000");
    }
}
