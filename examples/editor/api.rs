//! The editor's HTTP API without sockets: a request (method, URL, body bytes) in, a
//! reply (status, type, body) out. Every request is judged here before anything touches
//! the city: the route and method, the body size, the JSON against a closed schema
//! (unknown fields refused), every number finite and in range, every id known. A bad
//! request gets a 4xx with a message; nothing the page sends can panic the server.
//!
//! | route | what |
//! |---|---|
//! | `GET /`, `/app.js`, `/plan.js`, `/view3d.js`, `/style.css` | the page (compiled in) |
//! | `GET /api/scene` | the whole scene: primary nodes and roads, every city cell's content |
//! | `POST /api/preview` | an [`Edit`] proposed, not committed: red proposed and green corrected geometry |
//! | `POST /api/apply` | an [`Edit`] committed: only the changed nodes, roads, cells and block groups |
//! | `POST /api/undo`, `POST /api/redo` | the same delta for the undone or redone edit |
//! | `GET /api/cell/{id}` | a city cell's pattern and parameters with deviances (the cell inspector) |
//! | `GET /api/export/{glb,obj,mtl,geojson,svg,stats}` | the city as a file |
//! | `GET /api/log` | the output log |

use std::sync::Mutex;

use polis::editor::Edit;
use serde::Deserialize;

use crate::session::{Session, Timing};

/// The largest request body accepted, bytes. Edits are a few hundred bytes.
pub const MAX_BODY_BYTES: usize = 64 * 1024;

/// One request as the socket layer read it.
pub struct Request<'a> {
    /// `GET`, `POST`, …
    pub method: &'a str,
    /// The path with its query.
    pub url: &'a str,
    /// The body (at most [`MAX_BODY_BYTES`]).
    pub body: &'a [u8],
}

/// One reply.
#[derive(Debug)]
pub struct Reply {
    /// HTTP status.
    pub status: u16,
    /// `Content-Type`.
    pub content_type: &'static str,
    /// The body.
    pub body: Vec<u8>,
    /// A file name to offer as a download.
    pub download: Option<&'static str>,
    /// The server's time for an edit (sent as `Server-Timing`).
    pub timing: Option<Timing>,
}

const JSON: &str = "application/json";

impl Reply {
    fn new(status: u16, content_type: &'static str, body: Vec<u8>) -> Reply {
        Reply {
            status,
            content_type,
            body,
            download: None,
            timing: None,
        }
    }

    /// A JSON reply with status 200.
    pub fn json(body: Vec<u8>) -> Reply {
        Reply::new(200, JSON, body)
    }

    /// An error reply: `{"error": message}`.
    pub fn error(status: u16, message: impl Into<String>) -> Reply {
        let body = serde_json::json!({ "error": message.into() }).to_string();
        Reply::new(status, JSON, body.into_bytes())
    }

    /// 400 with a message.
    pub fn bad_request(message: impl Into<String>) -> Reply {
        Reply::error(400, message)
    }

    /// 413: the body is over [`MAX_BODY_BYTES`].
    pub fn too_large() -> Reply {
        Reply::error(
            413,
            format!("the request body is over {MAX_BODY_BYTES} bytes"),
        )
    }
}

/// An error of a request, with its HTTP status.
#[derive(Debug, Clone, PartialEq)]
pub struct ApiError {
    /// 400 malformed, 404 unknown id, 409 nothing to undo/redo, 422 refused by the city,
    /// 500 a failure of ours.
    pub status: u16,
    /// What was wrong, for the page's output log.
    pub message: String,
}

impl ApiError {
    /// 400.
    pub fn bad(message: impl Into<String>) -> ApiError {
        ApiError {
            status: 400,
            message: message.into(),
        }
    }
    /// 404.
    pub fn not_found(message: impl Into<String>) -> ApiError {
        ApiError {
            status: 404,
            message: message.into(),
        }
    }
    /// 409.
    pub fn conflict(message: impl Into<String>) -> ApiError {
        ApiError {
            status: 409,
            message: message.into(),
        }
    }
    /// 422.
    pub fn refused(message: impl Into<String>) -> ApiError {
        ApiError {
            status: 422,
            message: message.into(),
        }
    }
    /// 500.
    pub fn internal(message: impl Into<String>) -> ApiError {
        ApiError {
            status: 500,
            message: message.into(),
        }
    }
}

/// Parses an edit: a JSON object whose `op` names one of polis' [`Edit`]s, with exactly
/// that edit's fields (a closed schema: unknown fields and ops are refused). Numbers are
/// then checked by the editor (finite, in range, inside the map, known ids).
///
/// # Errors
/// 400 naming what is wrong.
pub fn parse_edit(body: &[u8]) -> Result<Edit, ApiError> {
    let value: serde_json::Value = parse(body)?;
    let op = value
        .as_object()
        .ok_or_else(|| ApiError::bad("an edit is a JSON object with an \"op\""))?
        .get("op")
        .and_then(|o| o.as_str())
        .ok_or_else(|| ApiError::bad("an edit needs an \"op\" string (e.g. \"move_node\")"))?
        .to_string();
    check_numbers(&value, 0)?;
    let mut value = value;
    if let Some(o) = value.as_object_mut() {
        // 64-bit ids travel as decimal strings (see `wire`).
        for key in ["cell", "lot"] {
            if let Some(serde_json::Value::String(t)) = o.get(key) {
                let n: u64 = t
                    .parse()
                    .map_err(|_| ApiError::bad(format!("{key}: {t:?} is not an id")))?;
                o.insert(key.to_string(), serde_json::Value::from(n));
            }
        }
    }
    serde_json::from_value(value).map_err(|e| ApiError::bad(format!("bad {op} edit: {e}")))
}

/// Refuses texts over [`MAX_TEXT_BYTES`] and numbers JSON can carry but no edit means: beyond ±[`MAX_NUMBER`] (a float
/// that overflowed to infinity on the page is sent as `null` by `JSON.stringify`, and
/// serde refuses that where a number is due).
fn check_numbers(v: &serde_json::Value, depth: usize) -> Result<(), ApiError> {
    if depth > 16 {
        return Err(ApiError::bad("the edit is nested too deeply"));
    }
    match v {
        serde_json::Value::Number(n) => match n.as_f64() {
            Some(x) if x.is_finite() && (n.is_u64() || x.abs() <= MAX_NUMBER) => Ok(()),
            _ => Err(ApiError::bad(format!(
                "{n}: numbers must be finite and within ±{MAX_NUMBER:e}"
            ))),
        },
        serde_json::Value::String(t) if t.len() > MAX_TEXT_BYTES => Err(ApiError::bad(format!(
            "a text of {} bytes: at most {MAX_TEXT_BYTES}",
            t.len()
        ))),
        serde_json::Value::Array(a) => a.iter().try_for_each(|x| check_numbers(x, depth + 1)),
        serde_json::Value::Object(o) => o.values().try_for_each(|x| check_numbers(x, depth + 1)),
        _ => Ok(()),
    }
}

/// The longest text in an edit (a label, a style name), bytes.
pub const MAX_TEXT_BYTES: usize = 1024;

/// The largest magnitude of a non-id number in an edit (ids and seeds are unsigned
/// integers and may be larger). Coordinates are checked against the map by the editor.
pub const MAX_NUMBER: f64 = 1e12;

/// Parses and checks a JSON body into `T`.
///
/// # Errors
/// 400 with serde's message (line, column, what was expected).
pub fn parse<'a, T: Deserialize<'a>>(body: &'a [u8]) -> Result<T, ApiError> {
    if body.is_empty() {
        return Err(ApiError::bad("the request needs a JSON body"));
    }
    serde_json::from_slice(body).map_err(|e| ApiError::bad(format!("malformed request: {e}")))
}

/// The API: the session behind a lock (edits are applied one at a time).
pub struct Api {
    session: Mutex<Session>,
}

impl Api {
    /// Serves `session`.
    pub fn new(session: Session) -> Api {
        Api {
            session: Mutex::new(session),
        }
    }

    fn with_session<T>(&self, f: impl FnOnce(&mut Session) -> T) -> T {
        // A panic while holding the lock cannot leave a half-applied edit behind (edits
        // are applied or refused whole), so a poisoned lock is taken over.
        let mut guard = match self.session.lock() {
            Ok(g) => g,
            Err(poisoned) => poisoned.into_inner(),
        };
        f(&mut guard)
    }

    /// Answers one request.
    pub fn handle(&self, req: &Request<'_>) -> Reply {
        let path = req.url.split(['?', '#']).next().unwrap_or("");
        if let Some(reply) = static_file(req.method, path) {
            return reply;
        }
        let result = match (req.method, path) {
            ("GET", "/api/scene") => self.with_session(|s| s.scene()).map(Reply::json),
            ("POST", "/api/preview") => parse_edit(req.body)
                .and_then(|e| self.with_session(|s| s.preview(&e)))
                .map(Reply::json),
            ("POST", "/api/apply") => parse_edit(req.body)
                .and_then(|e| self.with_session(|s| s.apply(&e)))
                .map(timed),
            ("POST", "/api/undo") => self.with_session(|s| s.undo()).map(timed),
            ("POST", "/api/redo") => self.with_session(|s| s.redo()).map(timed),
            ("GET", "/api/log") => self.with_session(|s| s.log_json()).map(Reply::json),
            ("GET", p) if p.starts_with("/api/cell/") => parse_id(&p["/api/cell/".len()..])
                .and_then(|id| self.with_session(|s| s.cell_info(id)))
                .map(Reply::json),
            ("GET", p) if p.starts_with("/api/export/") => {
                let format = &p["/api/export/".len()..];
                self.with_session(|s| s.export(format)).map(|e| Reply {
                    status: 200,
                    content_type: e.content_type,
                    body: e.body,
                    download: Some(e.file_name),
                    timing: None,
                })
            }
            (_, p) if known_path(p) => Err(ApiError {
                status: 405,
                message: format!("{} is not allowed on {p}", req.method),
            }),
            _ => Err(ApiError::not_found(format!("no such page: {path}"))),
        };
        result.unwrap_or_else(|e| Reply::error(e.status, e.message))
    }
}

/// A committed edit's reply with the server's time in `Server-Timing`.
fn timed((body, timing): (Vec<u8>, Timing)) -> Reply {
    let mut r = Reply::json(body);
    r.timing = Some(timing);
    r
}

fn parse_id(text: &str) -> Result<u64, ApiError> {
    text.parse()
        .map_err(|_| ApiError::bad(format!("not an id: {text:?}")))
}

fn known_path(p: &str) -> bool {
    matches!(
        p,
        "/" | "/index.html"
            | "/app.js"
            | "/plan.js"
            | "/view3d.js"
            | "/style.css"
            | "/api/scene"
            | "/api/preview"
            | "/api/apply"
            | "/api/undo"
            | "/api/redo"
            | "/api/log"
    ) || p.starts_with("/api/cell/")
        || p.starts_with("/api/export/")
}

/// The page's files, compiled into the binary.
fn static_file(method: &str, path: &str) -> Option<Reply> {
    if method != "GET" {
        return None;
    }
    let (body, kind): (&'static str, &'static str) = match path {
        "/" | "/index.html" => (
            include_str!("static/index.html"),
            "text/html; charset=utf-8",
        ),
        "/app.js" => (include_str!("static/app.js"), "text/javascript"),
        "/plan.js" => (include_str!("static/plan.js"), "text/javascript"),
        "/view3d.js" => (include_str!("static/view3d.js"), "text/javascript"),
        "/style.css" => (include_str!("static/style.css"), "text/css"),
        _ => return None,
    };
    Some(Reply::new(200, kind, body.as_bytes().to_vec()))
}
