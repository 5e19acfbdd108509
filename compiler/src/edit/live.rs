//! What one page's live loop does with its messages, apart from the
//! socket that carries them: messages are read, a run of session requests
//! that queued up is coalesced and solved, and a change of the document is
//! made in the workspace every page shares.

use std::sync::{Arc, Mutex, MutexGuard};

use serde_json::Value;

use super::planar::document::Document;
use super::planar::session::{self, Session};
use super::spatial::{self, READ_ONLY};
use super::workspace::{self, Workspace};

/// The workspace the pages share, even if a page's handler panicked
/// holding it (each change to it is made whole or not at all).
pub fn lock(shared: &Mutex<Workspace>) -> MutexGuard<'_, Workspace> {
    shared.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// What a page sent, read: a request for its session (the pose on
/// screen) or a change of the document; one that does not parse is the
/// error to answer it with.
pub enum Incoming {
    /// A request for the page's session.
    Live(Result<session::Request, Value>),
    /// A change of the document every page shows.
    Editing(Result<workspace::Request, Value>),
}

/// Reads a text message of a page.
pub fn read(text: &str) -> Incoming {
    let bad = |e: serde_json::Error| session::error(0, &format!("bad message: {e}"));
    if workspace::is_editing(text) {
        Incoming::Editing(serde_json::from_str(text).map_err(bad))
    } else {
        Incoming::Live(serde_json::from_str(text).map_err(bad))
    }
}

/// The reply to one session request: a frame, or an error.
pub fn solve(session: &mut Session, doc: &Arc<Document>, request: Result<session::Request, Value>) -> Value {
    let started = std::time::Instant::now();
    let mut reply = match request {
        Ok(request) => {
            let solved = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| session.handle(request)));
            solved.unwrap_or_else(|_| {
                // A bug, not the user's input: start the page over from
                // the drawing rather than lose the server.
                *session = Session::new(doc.clone());
                session::error(
                    0,
                    "internal error while solving: the pose was reset to the drawing",
                )
            })
        }
        Err(reply) => reply,
    };
    // How long the server took, for the page's latency figures.
    reply["server_ms"] = serde_json::json!(started.elapsed().as_secs_f64() * 1e3);
    reply
}

/// The reply of a page showing a spatial document to a text message:
/// sliders and the sweep run its plan; edits are refused (planar-only).
pub fn reply_spatial(session: &mut spatial::Session, text: &str) -> Value {
    if workspace::is_editing(text) {
        let id = serde_json::from_str::<Value>(text)
            .ok()
            .and_then(|v| v["id"].as_u64())
            .unwrap_or(0);
        return session::error(id, READ_ONLY);
    }
    match serde_json::from_str::<session::Request>(text) {
        Ok(request) => {
            let started = std::time::Instant::now();
            let solved = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| session.handle(request)));
            let mut reply =
                solved.unwrap_or_else(|_| session::error(0, "internal error while solving: reload the page"));
            reply["server_ms"] = serde_json::json!(started.elapsed().as_secs_f64() * 1e3);
            reply
        }
        Err(e) => session::error(0, &format!("bad message: {e}")),
    }
}

/// Makes the change `request` asks for at the pose on screen, and the
/// replies: the new document and its drawn pose (the frame answering the
/// request, with what changed in `edited`), or an error, nothing changed.
/// The page's document `doc` and `session` start over from the new one.
pub fn change(
    shared: &Mutex<Workspace>,
    doc: &mut Arc<Document>,
    session: &mut Session,
    request: workspace::Request,
) -> Vec<Value> {
    let id = request.id();
    let mut w = lock(shared);
    if !w.planar().is_some_and(|now| Arc::ptr_eq(doc, &now)) {
        // Another page changed the document: this one's pose is of an
        // older drawing, and an edit made at it would be of a file no
        // longer there.
        return vec![session::error(
            id,
            "the document was changed in another page: reload this one to edit it",
        )];
    }
    let poses = workspace::poses_of(&session.current(0));
    let changed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| w.handle(request, &poses)));
    match changed {
        Ok(Ok(summary)) => {
            let Some(now) = w.planar() else {
                return vec![session::error(
                    id,
                    "the document is no longer planar: reload the page",
                )];
            };
            *doc = now;
            *session = Session::new(doc.clone());
            let mut frame = session.current(id);
            frame["edited"] = Value::String(summary);
            vec![w.describe(), frame]
        }
        Ok(Err(message)) => vec![session::error(id, &message)],
        Err(_) => vec![session::error(
            id,
            "internal error while editing: the document was left as it was",
        )],
    }
}

/// Drops every drag (or input) request directly followed by another of the
/// same kind: only the latest target or slider values matter, so the reply
/// to the last one of a run answers them all.
pub fn coalesce(requests: Vec<Result<session::Request, Value>>) -> Vec<Result<session::Request, Value>> {
    let kind = |r: &Result<session::Request, Value>| match r {
        Ok(session::Request::Drag { .. }) => 1,
        Ok(session::Request::Inputs { .. }) => 2,
        _ => 0,
    };
    let mut kept: Vec<Result<session::Request, Value>> = Vec::with_capacity(requests.len());
    for r in requests {
        if let Some(last) = kept.last() {
            if kind(last) != 0 && kind(last) == kind(&r) {
                kept.pop();
            }
        }
        kept.push(r);
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use session::Request as R;

    fn ids(requests: &[Result<R, Value>]) -> Vec<u64> {
        requests.iter().map(|r| r.as_ref().map_or(0, R::id)).collect()
    }

    #[test]
    fn a_run_of_drags_or_inputs_is_solved_once_at_its_latest() {
        let drag = |id| Ok(R::Drag { id, to: [0.0, 0.0] });
        let inputs = |id| {
            Ok(R::Inputs {
                id,
                values: vec![1.0],
                policy: None,
            })
        };
        let queued = vec![
            Ok(R::Grab {
                id: 1,
                body: "b".into(),
                at: [0.0, 0.0],
            }),
            drag(2),
            drag(3),
            drag(4),
            Ok(R::Release { id: 5 }),
            inputs(6),
            inputs(7),
            drag(8),
        ];
        assert_eq!(ids(&coalesce(queued)), [1, 4, 5, 7, 8]);
    }

    #[test]
    fn an_edit_from_a_page_showing_an_older_document_is_refused() {
        let dir = std::env::temp_dir();
        let shared = Mutex::new(Workspace::open(None, dir).expect("a new document"));
        let first = lock(&shared).planar().expect("planar");
        let (mut doc, mut stale) = (first.clone(), first);
        let mut session = Session::new(doc.clone());
        let mut stale_session = Session::new(stale.clone());
        let add = || {
            serde_json::from_str::<workspace::Request>(
                r#"{"type":"edit","id":1,"edits":[{"op":"add_marker","body":"ground","at":[1,0]}]}"#,
            )
            .unwrap()
        };
        let replies = change(&shared, &mut doc, &mut session, add());
        assert_eq!(replies.len(), 2, "{replies:?}");
        assert_eq!(
            (replies[0]["type"].as_str(), replies[1]["type"].as_str()),
            (Some("document"), Some("frame"))
        );
        assert_eq!(replies[1]["edited"], "added marker ground.A at (1, 0)");
        assert_eq!(
            doc.mechanism.bodies[0].markers.len(),
            2,
            "the page's document is the new one"
        );
        // The other page still shows the ground alone.
        let refused = change(&shared, &mut stale, &mut stale_session, add());
        assert_eq!(refused[0]["type"], "error");
        assert!(
            refused[0]["message"].as_str().unwrap().contains("reload"),
            "{refused:?}"
        );
        assert_eq!(
            lock(&shared).planar().unwrap().mechanism.bodies[0].markers.len(),
            2
        );
    }
}
