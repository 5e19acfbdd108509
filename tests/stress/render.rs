//! Pictures of long stress chains stay readable: the legend is capped, the
//! poses do not pile up into a blur, and the file stays small. The SVG is
//! parsed back with the `svg` crate's reader and its elements counted.

use dofplan::analysis::analyse;
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::Format;
use dofplan::render::{render, SvgOptions};
use dofplan::simulate::{run, sweep_inputs};
use dofplan_runtime::Options;
use dofplan_tests::stress::stress_chain;
use svg::node::element::tag::Type;
use svg::parser::Event;

/// Every start or empty tag's name, class and the text right after it.
fn elements(svg: &str) -> Vec<(String, String, String)> {
    let mut out: Vec<(String, String, String)> = Vec::new();
    let mut depth = 0i64;
    for event in svg::read(svg).expect("readable") {
        match event {
            Event::Error(e) => panic!("parse error: {e}"),
            Event::Tag(name, kind, attrs) => {
                match kind {
                    Type::Start => depth += 1,
                    Type::End => {
                        depth -= 1;
                        continue;
                    }
                    Type::Empty => {}
                }
                let class = attrs.get("class").map(|v| v.to_string()).unwrap_or_default();
                out.push((name.to_string(), class, String::new()));
            }
            Event::Text(t) => {
                if let Some(last) = out.last_mut() {
                    last.2.push_str(t);
                }
            }
            _ => {}
        }
    }
    assert_eq!(depth, 0, "unbalanced tags");
    out
}

#[test]
fn a_chain_of_a_thousand_loops_gets_a_readable_picture() {
    let loops = 1000;
    let m = load_str("chain.toml", &stress_chain(loops), Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.bodies.len(), 2 * loops + 2);
    let plan = analyse(&m).plan.unwrap_or_else(|e| panic!("{e}"));
    let frames = run(
        Interpreter::new(plan),
        Options::default(),
        &sweep_inputs(&m, Some(5)),
    );
    let trace = m.sweep.as_ref().unwrap().trace.clone();
    assert_eq!(trace.len(), 1);
    let svg = render(&m, &frames, &trace, &SvgOptions::default());
    let els = elements(&svg);

    // The legend: the trace and 11 bodies, then a count of the other
    // 2,002 − 11 bodies.
    let entries: Vec<&str> = els
        .iter()
        .filter(|(_, class, _)| class == "legend-entry")
        .map(|(_, _, text)| text.as_str())
        .collect();
    assert_eq!(entries.len(), 13, "{entries:?}");
    assert_eq!(entries[0], "trace coupler_1000.P");
    assert_eq!(entries[12], "\u{2026} and 1,991 more bodies");

    // One pose: 2,001 mobile bodies leave no room for more.
    assert_eq!(els.iter().filter(|(_, class, _)| class == "pose").count(), 1);
    let circles: Vec<&str> = els
        .iter()
        .filter(|(name, _, _)| name == "circle")
        .map(|(_, c, _)| c.as_str())
        .collect();
    // Pins would hide links 3 px long: the only circles are the traced
    // marker and its trace, which moves less than the half pixel thinning
    // keeps at this scale (4,000 units in 770 px).
    assert_eq!(circles, ["trace-point", "traced"]);
    // The trace, its label and a scale bar are there.
    assert_eq!(
        els.iter().filter(|(_, class, _)| class == "trace-label").count(),
        1
    );
    assert_eq!(els.iter().filter(|(_, class, _)| class == "scale-bar").count(), 1);

    // A picture of ordinary height, in a file of modest size.
    let height: f64 = svg
        .split("height=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!(height < 400.0, "{height} px high");
    assert!(svg.len() < 400_000, "{} bytes", svg.len());
}
