//! What both dimensions' requests resolve alike: the driving input by
//! name, the varied parameters by name, and the box of every varied
//! point (a point's own box, the common one, or a default around the
//! drawing and the targets).

use super::nodes::Parameters;
use crate::model::{Input, Sweep};

/// `a, b, c`: names for a message.
pub(crate) fn names(it: impl Iterator<Item = String>) -> String {
    let v: Vec<String> = it.collect();
    v.join(", ")
}

/// The input that drives the synthesis: the one named, or the sweep's, or
/// the only one.
pub(crate) fn driving_input(
    inputs: &[Input],
    sweep: Option<&Sweep>,
    name: Option<&str>,
) -> Result<usize, String> {
    let all = || names(inputs.iter().map(|i| i.name.clone()));
    match name {
        Some(n) => (inputs.iter().position(|i| i.name == n))
            .ok_or_else(|| format!("no input '{n}': one of {}", all())),
        None => match (sweep, inputs.len()) {
            (Some(s), _) => Ok(s.primary().input),
            (None, 1) => Ok(0),
            (None, 0) => Err("the mechanism has no input to drive".into()),
            _ => Err(format!(
                "the mechanism has several inputs: choose one with --input ({})",
                all()
            )),
        },
    }
}

/// The indices of the parameters `vary` names — a parameter (`D.x`) or a
/// point (`D`, all its coordinates) — or all of them when `None`.
pub(crate) fn varied<const N: usize>(
    params: &Parameters<N>,
    vary: Option<&[String]>,
) -> Result<Vec<usize>, String> {
    let Some(vary) = vary else {
        return Ok((0..params.names().len()).collect());
    };
    let mut out = Vec::new();
    for v in vary {
        let found: Vec<usize> = match params.index(v) {
            Ok(k) => vec![k],
            Err(e) => match params.nodes().iter().position(|n| &n.name == v) {
                Some(n) => (N * n..N * n + N).collect(),
                None => return Err(e.to_string()),
            },
        };
        for k in found {
            if !out.contains(&k) {
                out.push(k);
            }
        }
    }
    if out.is_empty() {
        return Err("--vary names no parameter".into());
    }
    Ok(out)
}

/// A box: its lowest and highest corner.
pub(crate) type Corners<const N: usize> = ([f64; N], [f64; N]);

/// The box of every varied parameter: a point's own box (`point_bounds`,
/// by point name), or the common one (`bounds`), or by default the box
/// around the drawing and `targets`, widened by half its larger side on
/// every side.
pub(crate) fn boxes<const N: usize>(
    params: &Parameters<N>,
    targets: impl Iterator<Item = [f64; N]>,
    vary: &[usize],
    bounds: Option<Corners<N>>,
    point_bounds: &[(String, Corners<N>)],
) -> Result<Vec<[f64; 2]>, String> {
    let nodes = params.nodes();
    for (n, _) in point_bounds {
        if !nodes.iter().any(|x| &x.name == n) {
            return Err(format!(
                "--bounds {n}=…: no point '{n}': one of {}",
                names(nodes.iter().map(|x| x.name.clone()))
            ));
        }
    }
    let default = bounds.unwrap_or_else(|| {
        let (mut lo, mut hi) = ([f64::INFINITY; N], [f64::NEG_INFINITY; N]);
        for p in nodes.iter().map(|n| n.at).chain(targets) {
            for k in 0..N {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let side = (0..N).map(|k| hi[k] - lo[k]).fold(1e-9, f64::max);
        (lo.map(|x| x - 0.5 * side), hi.map(|x| x + 0.5 * side))
    });
    Ok(vary
        .iter()
        .map(|&k| {
            let node = &nodes[k / N].name;
            let (lo, hi) = (point_bounds.iter().find(|(n, _)| n == node)).map_or(default, |(_, b)| *b);
            [lo[k % N], hi[k % N]]
        })
        .collect())
}
