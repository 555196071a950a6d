//! The viewer's HTTP server: tiny_http on [`WORKERS`] threads, a fixed table of routes (no file
//! is served by its path, so no request reaches outside what the viewer holds), GET for the
//! page and its data, POST for an export, 4xx for anything else, request bodies and URLs
//! bounded. The data the viewer holds (tables, the last frame) is shared with the replies,
//! never copied for one.
//!
//! | route | answer |
//! |---|---|
//! | `GET /`, `/viewer.js`, `/viewer.css` | the page |
//! | `GET /api/scene` | the scene JSON: size, planes, frames, colour, table layout, products |
//! | `GET /api/frame/N` | frame N's JSON: glass pixels per id |
//! | `GET /api/frame/N/passes`, `/api/frame/N/mask` | frame N's binary data ([`crate::data`]) |
//! | `GET /api/product/N/lut` | product N's lookup table |
//! | `GET /api/view/N` | `.cube` view N's tables ([`crate::data::view_bytes`]) |
//! | `GET /api/luts` | every product's table, one after the other (the page's one request) |
//! | `POST /api/export` | `{"glass": "1:NAME,…", "ev": 0}`: writes the export folder given at start |

use std::io::{Cursor, Read};
use std::ops::Range;
use std::path::PathBuf;
use std::sync::Arc;

use glassdb_io::ErrorChain;
use serde_json::{Value, json};
use tiny_http::{Header, Method, Request, Response, Server, StatusCode};

use crate::scene::FrameData;
use crate::{ViewError, Viewer, assets, export};

/// Longest request URL accepted (path and query).
pub const MAX_URL_BYTES: usize = 8 * 1024;
/// Threads answering requests.
pub const WORKERS: usize = 4;
/// Largest request body accepted (an export request is a few hundred bytes).
pub const MAX_BODY_BYTES: usize = 64 * 1024;

/// A listening viewer.
pub struct ViewServer {
    server: Server,
    viewer: Viewer,
    export_dir: Option<PathBuf>,
}

impl ViewServer {
    /// Listens on `host:port` (port 0: a free port chosen by the system). `export_dir` is where
    /// the page's "export" button writes (none: the button says how to enable it).
    pub fn bind(
        viewer: Viewer,
        host: &str,
        port: u16,
        export_dir: Option<PathBuf>,
    ) -> Result<ViewServer, ViewError> {
        let address = format!("{host}:{port}");
        let server =
            Server::http(&address).map_err(|source| ViewError::Bind { address, source })?;
        Ok(ViewServer {
            server,
            viewer,
            export_dir,
        })
    }

    /// The page's URL.
    pub fn url(&self) -> String {
        match self.server.server_addr().to_ip() {
            Some(addr) => format!("http://{addr}/"),
            None => "http://127.0.0.1/".to_string(),
        }
    }

    /// Answers requests until the process ends, on [`WORKERS`] threads (a frame being
    /// decoded does not hold up the page's other requests).
    pub fn run(&self) {
        std::thread::scope(|scope| {
            for _ in 0..WORKERS {
                scope.spawn(|| {
                    while let Ok(request) = self.server.recv() {
                        self.answer(request);
                    }
                });
            }
        });
    }

    fn answer(&self, mut request: Request) {
        let reply = if request.url().len() > MAX_URL_BYTES {
            Reply::error(414, "the URL is too long")
        } else {
            let method = request.method().clone();
            let path = request
                .url()
                .split(['?', '#'])
                .next()
                .unwrap_or("")
                .to_string();
            match method {
                Method::Get | Method::Head => self.get(&path),
                Method::Post => match read_body(&mut request) {
                    Ok(body) if path == "/api/export" => self.export(&body),
                    Ok(_) => Reply::error(404, "no such resource"),
                    Err(reply) => reply,
                },
                _ => Reply::error(405, "only GET and POST are answered"),
            }
        };
        // A client that went away is not the server's failure.
        let _ = request.respond(reply.into_response());
    }

    fn get(&self, path: &str) -> Reply {
        let v = &self.viewer;
        match path {
            "/" | "/index.html" => Reply::text(assets::INDEX_HTML, "text/html; charset=utf-8"),
            "/viewer.js" => Reply::text(assets::VIEWER_JS, "text/javascript; charset=utf-8"),
            "/viewer.css" => Reply::text(assets::VIEWER_CSS, "text/css; charset=utf-8"),
            "/api/scene" => {
                let mut scene = v.scene().clone();
                scene.export_available = self.export_dir.is_some();
                Reply::json(&json!(scene))
            }
            _ => {
                let parts: Vec<&str> = path.trim_start_matches('/').split('/').collect();
                match parts.as_slice() {
                    ["api", "frame", n, rest @ ..] => self.frame(n, rest),
                    ["api", "luts"] => {
                        let all = v.all_product_luts();
                        Reply::binary(Body::Shared(all.clone(), 0..all.len()))
                    }
                    ["api", "view", n] => match index(n, v.view_count())
                        .and_then(|i| v.view_data(i))
                    {
                        Some(bytes) => Reply::binary(Body::Shared(bytes.clone(), 0..bytes.len())),
                        None => Reply::error(404, "no such view"),
                    },
                    ["api", "product", n, "lut"] => {
                        match index(n, v.products().len()).and_then(|i| v.product_lut_range(i)) {
                            Some(range) => {
                                Reply::binary(Body::Shared(v.all_product_luts().clone(), range))
                            }
                            None => Reply::error(404, "no such product"),
                        }
                    }
                    _ => Reply::error(404, "no such resource"),
                }
            }
        }
    }

    fn frame(&self, n: &str, rest: &[&str]) -> Reply {
        let Some(i) = index(n, self.viewer.frame_count()) else {
            return Reply::error(404, "no such frame");
        };
        let data = match self.viewer.frame(i) {
            Ok(d) => d,
            Err(e) => return Reply::error(e.http_status(), &ErrorChain(&e).to_string()),
        };
        match rest {
            [] => Reply::json(&json!(data.info)),
            ["passes"] => Reply::binary(Body::Frame(data, FramePart::Passes)),
            ["mask"] => Reply::binary(Body::Frame(data, FramePart::Mask)),
            _ => Reply::error(404, "no such resource"),
        }
    }

    fn export(&self, body: &[u8]) -> Reply {
        let Some(dir) = &self.export_dir else {
            return Reply::error(
                409,
                "this viewer was started without an export folder; restart it with one",
            );
        };
        let Ok(request) = serde_json::from_slice::<Value>(body) else {
            return Reply::error(400, "the export request must be JSON");
        };
        let glass = request.get("glass").and_then(Value::as_str).unwrap_or("");
        let ev = request.get("ev").and_then(Value::as_f64).unwrap_or(0.0);
        if !ev.is_finite() {
            return Reply::error(400, "ev must be a finite number");
        }
        let choices = match self.viewer.parse_choices(glass) {
            Ok(c) => c,
            Err(e) => return Reply::error(400, &ErrorChain(&e).to_string()),
        };
        match export::write_export(&self.viewer, dir, &choices, ev) {
            Ok(()) => Reply::json(&json!({ "path": dir.display().to_string() })),
            Err(e) => Reply::error(500, &ErrorChain(&e).to_string()),
        }
    }
}

/// A path segment as an index below `len` (digits only).
fn index(text: &str, len: usize) -> Option<usize> {
    if text.is_empty() || text.len() > 9 || !text.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    text.parse().ok().filter(|&i| i < len)
}

/// The body, refused (413) beyond [`MAX_BODY_BYTES`]. A refused body is still read (up to
/// [`DRAIN_BYTES`]) so that closing the connection does not reset it before the client has
/// the reply.
fn read_body(request: &mut Request) -> Result<Vec<u8>, Reply> {
    let mut body = Vec::new();
    let read = request
        .as_reader()
        .take(MAX_BODY_BYTES as u64 + 1)
        .read_to_end(&mut body);
    match read {
        Err(_) => Err(Reply::error(400, "cannot read the request body")),
        Ok(_) if body.len() > MAX_BODY_BYTES => {
            let _ = std::io::copy(
                &mut request.as_reader().take(DRAIN_BYTES),
                &mut std::io::sink(),
            );
            Err(Reply::error(413, "the request body is too large"))
        }
        Ok(_) => Ok(body),
    }
}

/// How much of a refused body is read and dropped.
const DRAIN_BYTES: u64 = 16 * 1024 * 1024;

/// A reply's body: the bytes the viewer holds are shared with the reply, not copied.
enum Body {
    Static(&'static [u8]),
    Owned(Vec<u8>),
    /// A range of bytes held once (the products' tables, a view's tables).
    Shared(Arc<[u8]>, Range<usize>),
    /// A part of a decoded frame.
    Frame(Arc<FrameData>, FramePart),
}

#[derive(Clone, Copy)]
enum FramePart {
    Passes,
    Mask,
}

impl AsRef<[u8]> for Body {
    fn as_ref(&self) -> &[u8] {
        match self {
            Body::Static(bytes) => bytes,
            Body::Owned(bytes) => bytes,
            // The ranges are made in bounds (`Viewer::product_lut_range`, a whole slice).
            Body::Shared(bytes, range) => bytes.get(range.clone()).unwrap_or_default(),
            Body::Frame(data, FramePart::Passes) => &data.passes,
            Body::Frame(data, FramePart::Mask) => &data.mask,
        }
    }
}

/// A reply before it becomes a tiny_http response.
struct Reply {
    status: u16,
    content_type: &'static str,
    body: Body,
}

impl Reply {
    fn text(body: &'static str, content_type: &'static str) -> Reply {
        Reply {
            status: 200,
            content_type,
            body: Body::Static(body.as_bytes()),
        }
    }

    fn json(value: &Value) -> Reply {
        Reply {
            status: 200,
            content_type: "application/json",
            body: Body::Owned(value.to_string().into_bytes()),
        }
    }

    fn binary(body: Body) -> Reply {
        Reply {
            status: 200,
            content_type: "application/octet-stream",
            body,
        }
    }

    fn error(status: u16, message: &str) -> Reply {
        Reply {
            status,
            content_type: "application/json",
            body: Body::Owned(json!({ "error": message }).to_string().into_bytes()),
        }
    }

    fn into_response(self) -> Response<Cursor<Body>> {
        let headers = [
            ("Content-Type", self.content_type),
            ("Cache-Control", "no-store"),
            ("X-Content-Type-Options", "nosniff"),
        ]
        .into_iter()
        .filter_map(|(name, value)| Header::from_bytes(name.as_bytes(), value.as_bytes()).ok())
        .collect();
        let len = self.body.as_ref().len();
        Response::new(
            StatusCode(self.status),
            headers,
            Cursor::new(self.body),
            Some(len),
            None,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_are_digits_below_the_length() {
        assert_eq!(index("0", 3), Some(0));
        assert_eq!(index("2", 3), Some(2));
        for bad in ["3", "-1", "", "1e2", "..", "01x", "99999999999999999999"] {
            assert_eq!(index(bad, 3), None, "{bad}");
        }
    }
}
