//! `dofplan edit`: the interactive editor, a page served on the loopback
//! interface with a WebSocket for the live loop.
//!
//! The page ([`compiler/web/`](../../../web)) is embedded in the binary, so
//! the editor needs no network beyond 127.0.0.1. Every request must carry
//! the random token printed with the address (as a query parameter, or the
//! cookie the page is served with), its Host must be this server's own
//! address (a DNS-rebinding page's Host is its own name), and the
//! WebSocket's Origin must be the page's.

use std::io::{self, Read, Write};
use std::net::{Ipv4Addr, SocketAddr};
use std::path::Path;
use std::process::ExitCode;
use std::sync::{Arc, Mutex, MutexGuard};

use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use futures_util::FutureExt;
use serde_json::Value;

use dofplan::edit::live::{self, Incoming};
use dofplan::edit::planar::session::{self, Session};
use dofplan::edit::spatial as spatial_edit;
use dofplan::edit::workspace::{self, View, Workspace};

/// The page and its script and style, embedded at compile time.
const INDEX_HTML: &str = include_str!("../../../web/index.html");
const APP_JS: &str = include_str!("../../../web/app.js");
const STYLE_CSS: &str = include_str!("../../../web/style.css");

/// The largest WebSocket message accepted: a message is a few numbers.
const MAX_MESSAGE: usize = 64 * 1024;

/// Queued messages read at once before solving (see [`coalesce`]).
const MAX_BATCH: usize = 256;

/// What every request handler shares.
struct Server {
    /// The document every page shows and edits.
    workspace: Mutex<Workspace>,
    token: String,
    port: u16,
}

impl Server {
    /// The workspace, even if a page's handler panicked holding it (each
    /// change to it is made whole or not at all).
    fn workspace(&self) -> MutexGuard<'_, Workspace> {
        live::lock(&self.workspace)
    }
}

/// Runs `dofplan edit`: prints the page's address as the first line of
/// `out`, then serves until the process is stopped.
pub fn run(file: Option<&Path>, port: Option<u16>, open: bool, out: &mut dyn Write) -> io::Result<ExitCode> {
    // Files are opened and saved by name in the directory the server is
    // started in, nothing outside it.
    let dir = match std::env::current_dir() {
        Ok(d) => d,
        Err(e) => {
            crate::report(&format!("error: cannot read the current directory: {e}"));
            return Ok(ExitCode::FAILURE);
        }
    };
    let workspace = match Workspace::open_watched(file, dir, Some(watch)) {
        Ok(w) => w,
        Err(text) => {
            crate::report(&text);
            return Ok(ExitCode::FAILURE);
        }
    };
    let description = workspace.describe();
    let token = match token() {
        Ok(t) => t,
        Err(e) => {
            crate::report(&format!(
                "error: cannot read random bytes for the access token: {e}"
            ));
            return Ok(ExitCode::FAILURE);
        }
    };
    // Bound before the runtime starts so that a taken port is reported
    // plainly; port 0 lets the system choose a free one.
    let address = SocketAddr::from((Ipv4Addr::LOCALHOST, port.unwrap_or(0)));
    let listener = match std::net::TcpListener::bind(address)
        .and_then(|l| l.set_nonblocking(true).map(|()| l))
    {
        Ok(l) => l,
        Err(e) => {
            crate::report(&format!(
                "error: cannot listen on {address}: {e}\n  help: choose another port with --port N, or leave it out for a free one"
            ));
            return Ok(ExitCode::FAILURE);
        }
    };
    let port = listener.local_addr()?.port();
    let url = format!("http://127.0.0.1:{port}/?token={token}");
    writeln!(out, "{url}")?;
    out.flush()?;
    let shown = description["file"].as_str().unwrap_or("a new document");
    crate::report(&format!(
        "dofplan edit: serving {shown} at the address above (127.0.0.1 only); Ctrl+C stops"
    ));
    if let Some(message) = description["broken"]["message"].as_str() {
        // Said here too: a terminal is where `check` would have said it.
        crate::report(&format!(
            "dofplan edit: {shown} does not load; the page shows its text with these errors, to be fixed there:\n{message}"
        ));
    } else if file.is_some_and(|f| !f.exists()) {
        crate::report(&format!(
            "dofplan edit: {shown} does not exist yet: a new document, written there when saved"
        ));
    }
    if open {
        open_browser(&url);
    }
    let server = Arc::new(Server {
        workspace: Mutex::new(workspace),
        token,
        port,
    });
    let runtime = match tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
    {
        Ok(r) => r,
        Err(e) => {
            crate::report(&format!("error: cannot start the server's runtime: {e}"));
            return Ok(ExitCode::FAILURE);
        }
    };
    let served = runtime.block_on(async move {
        let listener = tokio::net::TcpListener::from_std(listener)?;
        axum::serve(listener, router(server)).await
    });
    match served {
        Ok(()) => Ok(ExitCode::SUCCESS),
        Err(e) => {
            crate::report(&format!("error: the server stopped: {e}"));
            Ok(ExitCode::FAILURE)
        }
    }
}

/// The progress of a document's analysis, on a terminal for a large file.
fn watch(file: &Path) -> Box<dyn FnMut(dofplan::analysis::Progress)> {
    let bar = crate::progress::Bar::for_file(file);
    Box::new(move |p| bar.report(p))
}

/// The routes, every one behind [`guard`].
fn router(server: Arc<Server>) -> Router {
    Router::new()
        .route("/", get(index))
        .route(
            "/app.js",
            get(|| async { asset(APP_JS, "text/javascript; charset=utf-8") }),
        )
        .route(
            "/style.css",
            get(|| async { asset(STYLE_CSS, "text/css; charset=utf-8") }),
        )
        .route("/ws", get(socket))
        .layer(middleware::from_fn_with_state(server.clone(), guard))
        .with_state(server)
}

/// 128 random bits from the system, in hex.
fn token() -> io::Result<String> {
    let mut bytes = [0u8; 16];
    std::fs::File::open("/dev/urandom")?.read_exact(&mut bytes)?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// Asks the desktop to open `url`; only reports when it cannot. The opener
/// is waited for on its own thread: some run the browser until it closes.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else {
        "xdg-open"
    };
    let child = std::process::Command::new(opener)
        .arg(url)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => {
            crate::report(&format!(
                "dofplan edit: could not open a browser ({opener}: {e}); open the address above by hand"
            ));
            return;
        }
    };
    std::thread::spawn(move || match child.wait() {
        Ok(status) if status.success() => {}
        Ok(status) => crate::report(&format!(
            "dofplan edit: could not open a browser ({opener} {status}); open the address above by hand"
        )),
        Err(e) => crate::report(&format!("dofplan edit: could not open a browser ({opener}: {e})")),
    });
}

/// The name of the cookie that carries the token, one per port so that
/// two editors on one machine do not overwrite each other's.
fn cookie_name(port: u16) -> String {
    format!("dofplan_token_{port}")
}

/// Compares in time independent of where the strings differ.
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len() && a.bytes().zip(b.bytes()).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

/// Refuses (403) a request whose Host is not this server's address, or
/// that carries no valid token (query `token=` or the cookie), or a
/// WebSocket whose Origin is not the page's.
async fn guard(State(s): State<Arc<Server>>, request: Request, next: Next) -> Response {
    let headers = request.headers();
    let Some(host) = own_host(headers, s.port) else {
        return refuse("the Host header is not this server's address (127.0.0.1 or localhost with its port)");
    };
    let query_token = request
        .uri()
        .query()
        .into_iter()
        .flat_map(|q| q.split('&'))
        .find_map(|kv| kv.strip_prefix("token="));
    let cookie = cookie_name(s.port);
    let cookie_token = headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .find_map(|kv| kv.trim().strip_prefix(cookie.as_str())?.strip_prefix('='));
    let valid =
        query_token.is_some_and(|t| same(t, &s.token)) || cookie_token.is_some_and(|t| same(t, &s.token));
    if !valid {
        return refuse("a valid access token is needed: open the address `dofplan edit` printed");
    }
    if request.uri().path() == "/ws" {
        let origin = headers.get(header::ORIGIN).and_then(|v| v.to_str().ok());
        if origin != Some(format!("http://{host}").as_str()) {
            return refuse("the WebSocket's Origin is not this page's");
        }
    }
    next.run(request).await
}

/// The request's Host, if it names this server.
fn own_host(headers: &HeaderMap, port: u16) -> Option<String> {
    let host = headers.get(header::HOST)?.to_str().ok()?;
    [format!("127.0.0.1:{port}"), format!("localhost:{port}")]
        .into_iter()
        .find(|h| h == host)
}

fn refuse(why: &str) -> Response {
    (StatusCode::FORBIDDEN, format!("403 forbidden: {why}\n")).into_response()
}

fn asset(body: &'static str, kind: &'static str) -> Response {
    (
        [(header::CONTENT_TYPE, kind), (header::CACHE_CONTROL, "no-store")],
        body,
    )
        .into_response()
}

/// The page, with the cookie that lets its script, style and WebSocket in
/// (HttpOnly: scripts never read it; SameSite: other sites never send it).
async fn index(State(s): State<Arc<Server>>) -> Response {
    let mut response = asset(INDEX_HTML, "text/html; charset=utf-8");
    let cookie = format!(
        "{}={}; Path=/; HttpOnly; SameSite=Strict",
        cookie_name(s.port),
        s.token
    );
    if let Ok(value) = HeaderValue::from_str(&cookie) {
        response.headers_mut().insert(header::SET_COOKIE, value);
    }
    response
}

async fn socket(State(s): State<Arc<Server>>, upgrade: WebSocketUpgrade) -> Response {
    upgrade
        .max_message_size(MAX_MESSAGE)
        .max_frame_size(MAX_MESSAGE)
        .on_upgrade(move |socket| live(socket, s))
}

/// Messages of the page, read: a run of requests for the session (the
/// pose on screen), or a change of the document.
enum Run {
    Live(Vec<Result<session::Request, Value>>),
    Editing(Result<workspace::Request, Value>),
}

/// The live loop of one page: the document and the drawn pose first, then
/// one reply per request, in order. Requests that queued up while a frame
/// was being solved are coalesced first. A change of the document (an
/// edit, undo, save, open) is answered with the new document and its
/// drawn pose.
async fn live(mut socket: WebSocket, server: Arc<Server>) {
    let (view, greeting) = {
        let w = server.workspace();
        (w.view(), w.describe())
    };
    let mut doc = match view {
        View::Planar(doc) => doc,
        View::Spatial(doc) => return live_spatial(socket, doc, greeting).await,
    };
    let mut session = Session::new(doc.clone());
    for greeting in [greeting, session.current(0)] {
        if send(&mut socket, &greeting).await.is_err() {
            return;
        }
    }
    loop {
        let Some(Ok(first)) = socket.recv().await else {
            return;
        };
        let mut batch = vec![first];
        // Whatever else has already arrived, without waiting: dropping a
        // pending `recv` loses nothing (the stream keeps its messages).
        while batch.len() < MAX_BATCH {
            match socket.recv().now_or_never() {
                Some(Some(Ok(next))) => batch.push(next),
                Some(None | Some(Err(_))) => return,
                None => break,
            }
        }
        // Runs of session requests are coalesced; a change of the document
        // is made where it came, between them.
        let mut runs: Vec<Run> = Vec::new();
        for message in batch {
            let live = match message {
                Message::Text(text) => match live::read(text.as_str()) {
                    Incoming::Live(live) => live,
                    Incoming::Editing(change) => {
                        runs.push(Run::Editing(change));
                        continue;
                    }
                },
                Message::Binary(_) => Err(session::error(0, "bad message: expected JSON text")),
                Message::Close(_) => return,
                Message::Ping(_) | Message::Pong(_) => continue,
            };
            match runs.last_mut() {
                Some(Run::Live(run)) => run.push(live),
                _ => runs.push(Run::Live(vec![live])),
            }
        }
        for run in runs {
            let replies = match run {
                Run::Editing(Err(reply)) => vec![reply],
                Run::Editing(Ok(request)) => {
                    let started = std::time::Instant::now();
                    let mut replies = tokio::task::block_in_place(|| {
                        live::change(&server.workspace, &mut doc, &mut session, request)
                    });
                    for r in &mut replies {
                        r["server_ms"] = serde_json::json!(started.elapsed().as_secs_f64() * 1e3);
                    }
                    replies
                }
                Run::Live(requests) => live::coalesce(requests)
                    .into_iter()
                    // Solving is CPU work: let the runtime move other
                    // tasks off this thread meanwhile.
                    .map(|request| tokio::task::block_in_place(|| live::solve(&mut session, &doc, request)))
                    .collect(),
            };
            for reply in replies {
                if send(&mut socket, &reply).await.is_err() {
                    return;
                }
            }
        }
    }
}

/// The live loop of a page showing a spatial document: sliders and the
/// sweep run its plan; drags and edits are refused (planar-only).
async fn live_spatial(mut socket: WebSocket, doc: Arc<spatial_edit::Document>, greeting: Value) {
    let mut session = spatial_edit::Session::new(doc);
    for greeting in [greeting, session.current(0)] {
        if send(&mut socket, &greeting).await.is_err() {
            return;
        }
    }
    while let Some(Ok(message)) = socket.recv().await {
        let reply = match message {
            Message::Text(text) => {
                tokio::task::block_in_place(|| live::reply_spatial(&mut session, text.as_str()))
            }
            Message::Binary(_) => session::error(0, "bad message: expected JSON text"),
            Message::Close(_) => return,
            Message::Ping(_) | Message::Pong(_) => continue,
        };
        if send(&mut socket, &reply).await.is_err() {
            return;
        }
    }
}

async fn send(socket: &mut WebSocket, value: &Value) -> Result<(), axum::Error> {
    socket.send(Message::Text(value.to_string().into())).await
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_this_servers_host_is_let_in() {
        let with_host = |host: &str| {
            let mut h = HeaderMap::new();
            h.insert(header::HOST, HeaderValue::from_str(host).unwrap());
            own_host(&h, 8123)
        };
        assert_eq!(with_host("127.0.0.1:8123").as_deref(), Some("127.0.0.1:8123"));
        assert_eq!(with_host("localhost:8123").as_deref(), Some("localhost:8123"));
        assert_eq!(with_host("evil.example:8123"), None, "a rebound name");
        assert_eq!(with_host("127.0.0.1:8124"), None, "another port");
        assert_eq!(own_host(&HeaderMap::new(), 8123), None, "no Host at all");
    }

    /// Serves fourbar on a free port from a thread of its own; the port and
    /// the token.
    fn serve_fourbar() -> (u16, String) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/fourbar.toml");
        let workspace = Workspace::open(Some(&path), std::env::temp_dir()).expect("fourbar opens");
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        listener.set_nonblocking(true).unwrap();
        let port = listener.local_addr().unwrap().port();
        let token = "0123456789abcdef".repeat(2);
        let server = Arc::new(Server {
            workspace: Mutex::new(workspace),
            token: token.clone(),
            port,
        });
        std::thread::spawn(move || {
            let runtime = tokio::runtime::Builder::new_multi_thread()
                .worker_threads(1)
                .enable_all()
                .build()
                .unwrap();
            runtime.block_on(async move {
                let listener = tokio::net::TcpListener::from_std(listener).unwrap();
                axum::serve(listener, router(server)).await.unwrap();
            });
        });
        (port, token)
    }

    /// The status code and head of a GET with these extra header lines.
    fn get(port: u16, target: &str, headers: &[String]) -> (u16, String) {
        use std::io::{Read, Write};
        let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
        let mut request = format!("GET {target} HTTP/1.1\r\n");
        if !headers.iter().any(|h| h.starts_with("Connection:")) {
            request.push_str("Connection: close\r\n");
        }
        for h in headers {
            request.push_str(h);
            request.push_str("\r\n");
        }
        request.push_str("\r\n");
        stream.write_all(request.as_bytes()).unwrap();
        stream
            .set_read_timeout(Some(std::time::Duration::from_secs(5)))
            .unwrap();
        let mut response = Vec::new();
        let mut buf = [0u8; 4096];
        while let Ok(n) = stream.read(&mut buf) {
            if n == 0 {
                break;
            }
            response.extend_from_slice(&buf[..n]);
            // A connection kept open (an upgrade, refused or not) is done
            // when its head and body are in.
            let text = String::from_utf8_lossy(&response).to_lowercase();
            if let Some(end) = text.find("\r\n\r\n") {
                let length = text
                    .lines()
                    .find_map(|l| l.strip_prefix("content-length: "))
                    .and_then(|n| n.trim().parse::<usize>().ok())
                    .unwrap_or(0);
                if response.len() >= end + 4 + length {
                    break;
                }
            }
        }
        let text = String::from_utf8_lossy(&response).into_owned();
        let code = text.split(' ').nth(1).and_then(|c| c.parse().ok()).unwrap_or(0);
        (code, text)
    }

    #[test]
    fn the_server_wants_its_token_its_host_and_its_origin() {
        let (port, token) = serve_fourbar();
        let host = format!("Host: 127.0.0.1:{port}");
        let with = |extra: &[&str]| {
            let mut h = vec![host.clone()];
            h.extend(extra.iter().map(|s| s.to_string()));
            h
        };
        assert_eq!(get(port, "/", &with(&[])).0, 403, "no token");
        assert_eq!(get(port, "/?token=0000", &with(&[])).0, 403, "a wrong token");
        let (code, page) = get(port, &format!("/?token={token}"), &with(&[]));
        assert_eq!(code, 200);
        let cookie = format!("dofplan_token_{port}={token}");
        assert!(page.contains(&format!("set-cookie: {cookie}")), "{page}");
        assert!(page.contains("<svg id=\"canvas\""), "the embedded page");
        let by_cookie = format!("Cookie: other=1; {cookie}");
        assert_eq!(
            get(port, "/app.js", &with(&[&by_cookie])).0,
            200,
            "the cookie lets the script in"
        );
        let evil = [format!("Host: evil.example:{port}")];
        assert_eq!(
            get(port, &format!("/?token={token}"), &evil).0,
            403,
            "DNS rebinding"
        );
        let upgrade = [
            "Connection: Upgrade",
            "Upgrade: websocket",
            "Sec-WebSocket-Version: 13",
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
        ];
        let ws = format!("/ws?token={token}");
        let mut foreign = with(&upgrade);
        foreign.push("Origin: http://evil.example".into());
        assert_eq!(get(port, &ws, &foreign).0, 403, "another site's WebSocket");
        let mut none = with(&upgrade);
        assert_eq!(get(port, &ws, &none).0, 403, "a WebSocket without Origin");
        none.push(format!("Origin: http://127.0.0.1:{port}"));
        assert_eq!(get(port, &ws, &none).0, 101, "the page's own WebSocket");
    }

    #[test]
    fn tokens_compare_whole() {
        assert!(same("00ff", "00ff"));
        assert!(!same("00ff", "00fe"));
        assert!(!same("00ff", "00ff0"));
        assert!(!same("", "00ff"));
    }
}
