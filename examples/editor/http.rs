//! The socket side of the editor's server: tiny_http accepts connections, a few worker
//! threads read each request (body size-limited), hand it to [`Api::handle`] and write
//! the reply. Everything the page sends is judged in [`crate::api`]; this file only
//! moves bytes.

use std::io::Read;
use std::net::SocketAddr;
use std::sync::Arc;
use std::thread::JoinHandle;

use crate::api::{Api, MAX_BODY_BYTES, Reply, Request};

/// Worker threads answering requests. Edits are serialised by the session's lock; the
/// extra workers keep static files and previews answered while an edit runs.
pub const WORKERS: usize = 4;

/// A running server: its address and its worker threads.
pub struct Running {
    /// The bound address (with the port the system chose when asked for port 0).
    pub addr: SocketAddr,
    #[cfg_attr(not(test), allow(dead_code))]
    server: Arc<tiny_http::Server>,
    workers: Vec<JoinHandle<()>>,
}

impl Running {
    /// Stops accepting requests and waits for the workers to finish their current one.
    #[cfg(test)]
    pub fn stop(self) {
        for _ in &self.workers {
            self.server.unblock();
        }
        for w in self.workers {
            // A worker that panicked has nothing left to clean up.
            let _ = w.join();
        }
    }

    /// Blocks until every worker has ended (they end only when the process does).
    pub fn wait(self) {
        for w in self.workers {
            let _ = w.join();
        }
    }
}

/// Binds `addr` and serves `api` on [`WORKERS`] threads.
///
/// # Errors
/// The address cannot be bound (in use, not local, no permission).
pub fn serve(api: Arc<Api>, addr: SocketAddr) -> Result<Running, String> {
    let server = tiny_http::Server::http(addr).map_err(|e| format!("cannot bind {addr}: {e}"))?;
    let addr = server
        .server_addr()
        .to_ip()
        .ok_or_else(|| "the server has no IP address".to_string())?;
    let server = Arc::new(server);
    let workers = (0..WORKERS)
        .map(|_| {
            let server = Arc::clone(&server);
            let api = Arc::clone(&api);
            std::thread::spawn(move || {
                // `recv` fails only when the server is unblocked or its socket is gone.
                while let Ok(request) = server.recv() {
                    answer(&api, request);
                }
            })
        })
        .collect();
    Ok(Running {
        addr,
        server,
        workers,
    })
}

/// Reads one request (at most [`MAX_BODY_BYTES`] of body), asks the API, writes the reply.
fn answer(api: &Api, mut request: tiny_http::Request) {
    let method = request.method().as_str().to_string();
    let url = request.url().to_string();
    let declared = request.body_length();
    let reply = if declared.is_some_and(|n| n > MAX_BODY_BYTES) {
        Reply::too_large()
    } else {
        let mut body = Vec::with_capacity(declared.unwrap_or(0).min(MAX_BODY_BYTES));
        // Chunked bodies have no declared length: read one byte past the limit to know.
        let limit = MAX_BODY_BYTES as u64 + 1;
        match request.as_reader().take(limit).read_to_end(&mut body) {
            Err(e) => Reply::bad_request(format!("cannot read the request body: {e}")),
            Ok(n) if n > MAX_BODY_BYTES => Reply::too_large(),
            Ok(_) => api.handle(&Request {
                method: &method,
                url: &url,
                body: &body,
            }),
        }
    };
    let close = reply.status == 413;
    // The length is known: always a Content-Length, never chunked.
    let mut response = tiny_http::Response::from_data(reply.body)
        .with_status_code(reply.status)
        .with_chunked_threshold(usize::MAX);
    let mut headers = vec![
        ("Content-Type", reply.content_type.to_string()),
        ("Cache-Control", "no-store".to_string()),
        ("X-Content-Type-Options", "nosniff".to_string()),
    ];
    if let Some(name) = reply.download {
        headers.push((
            "Content-Disposition",
            format!("attachment; filename=\"{name}\""),
        ));
    }
    if let Some(t) = reply.timing {
        headers.push((
            "Server-Timing",
            format!("edit;dur={:.3}, total;dur={:.3}", t.edit_ms, t.total_ms),
        ));
    }
    if close {
        // The unread rest of a refused body must not be taken for the next request.
        headers.push(("Connection", "close".to_string()));
    }
    for (k, v) in headers {
        if let Ok(h) = tiny_http::Header::from_bytes(k.as_bytes(), v.as_bytes()) {
            response.add_header(h);
        }
    }
    // The page may have gone away; nothing to do about a failed write.
    let _ = request.respond(response);
}
