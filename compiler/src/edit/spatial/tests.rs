//! The spatial document and session as a page drives them.

use std::path::Path;
use std::sync::Arc;

use serde_json::Value;

use super::*;

fn rssr() -> Session {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/spatial/rssr.toml");
    let Ok(crate::model::Model::Spatial(m)) = crate::load_any(&path) else {
        panic!("rssr is a spatial file");
    };
    Session::new(Arc::new(Document::new(&path, m)))
}

fn reply(s: &mut Session, message: &str) -> Value {
    s.handle(serde_json::from_str(message).expect("a well-formed request"))
}

#[test]
fn sliders_run_the_spatial_plan_and_drags_are_refused() {
    let mut s = rssr();
    let drawn = s.current(0)["markers"].clone();
    assert_eq!(
        drawn[0].as_array().map(Vec::len),
        Some(3),
        "points in 3D: {drawn}"
    );
    let frame = reply(&mut s, r#"{"type":"inputs","id":1,"values":[30]}"#);
    assert_eq!(
        (frame["type"].as_str(), frame["status"].as_str()),
        (Some("frame"), Some("solved")),
        "{frame}"
    );
    assert_ne!(frame["markers"], drawn, "the slider moved it");
    for bad in [
        r#"{"type":"grab","id":2,"body":"crank","at":[0,0]}"#,
        r#"{"type":"inputs","id":3,"values":[1,2,3]}"#,
        r#"{"type":"inputs","id":4,"values":[1],"policy":"stretch"}"#,
    ] {
        assert_eq!(reply(&mut s, bad)["type"], "error", "{bad}");
    }
}
