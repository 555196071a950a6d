//! The viewer's HTTP server: tiny_http on [`WORKERS`] threads, a fixed table of routes (no file
//! is served by its path, so no request reaches outside what the viewer holds), GET for the
//! page and its data, POST for an export, 4xx for anything else, request bodies and URLs
//! bounded. The data the viewer holds (tables, the last frame) is shared with the replies,
//! never copied for one.
//!
//! Whom it answers (docs/reliability.md, "The viewer's server"): only requests whose `Host`
//! names this machine as a browser on it does (`localhost`, a loopback address), the name or
//! address it was started on, or (when it listens on every interface) an IP address; any
//! other name is what a page of another site sends after DNS rebinding, and is refused (403).
//! A request whose `Origin` is another site's is refused; a request that changes something
//! (the export) must also carry the page's `Origin` and the session token the served page
//! holds ([`SESSION_HEADER`]), which no other site's page can read.
//!
//! | route | answer |
//! |---|---|
//! | `GET /`, `/viewer.js`, `/viewer.css` | the page |
//! | `GET /api/scene` | the scene JSON: size, planes, frames, colour, table layout, products |
//! | `GET /api/frame/N` | frame N's JSON: glass pixels per id |
//! | `GET /api/frame/N/passes`, `/api/frame/N/mask` | frame N's binary data ([`crate::data`]) |
//! | `GET /api/frame/N/parts` | frame N's light parts' passes ([`crate::relight`]; empty without) |
//! | `GET /api/product/N/lut` | product N's lookup table |
//! | `GET /api/view/N` | `.cube` view N's tables ([`crate::data::view_bytes`]) |
//! | `GET /api/luts` | every product's table, one after the other (the page's one request) |
//! | `POST /api/export` | `{"glass": "1:NAME,…", "ev": 0, "units": […]}`: writes the export folder given at start (with the units built on the page it names); answers its path, files and bytes |
//! | `POST /api/unit` | `{"elements": [{"glass": 6}, {"gap_mm": 12.7, "gas": "argon"}, {"glass": 2}]}`: the unit built ([`crate::units`]) |

use std::io::{Cursor, Read};
use std::net::{IpAddr, SocketAddr, ToSocketAddrs};
use std::ops::Range;
use std::sync::Arc;

use glassdb_io::{ErrorChain, quoted};
use serde_json::{Value, json};
use tiny_http::{Header, Method, Request, Response, Server, StatusCode};

use base64::Engine;
use base64::engine::general_purpose::STANDARD;

use crate::export::ExportFolder;
use crate::page::{PAGE_FORMAT, PageBuiltUnit, PageProduct};
use crate::scene::FrameData;
use crate::{ViewError, Viewer, assets, export};

/// Longest request URL accepted (path and query).
pub const MAX_URL_BYTES: usize = 8 * 1024;
/// Threads answering requests.
pub const WORKERS: usize = 4;
/// Largest request body accepted (an export request is a few hundred bytes).
pub const MAX_BODY_BYTES: usize = 64 * 1024;
/// The request header that carries the page's session token on a request that changes
/// something (`POST /api/export`).
pub const SESSION_HEADER: &str = "X-Glassdb-Session";
/// The `name` of the `<meta>` element that carries the session token in the served page.
pub const SESSION_META: &str = "glassdb-session";

/// A listening viewer.
pub struct ViewServer {
    server: Server,
    viewer: Viewer,
    export: Option<ExportFolder>,
    audience: Audience,
    token: String,
    /// The page's HTML with the session token.
    page: Arc<[u8]>,
}

impl ViewServer {
    /// Listens on `host:port` (port 0: a free port chosen by the system; `host` an IP address
    /// or a name of this machine). `export` is where the page's "export" button writes (none:
    /// the button says how to enable it).
    pub fn bind(
        viewer: Viewer,
        host: &str,
        port: u16,
        export: Option<ExportFolder>,
    ) -> Result<ViewServer, ViewError> {
        let addresses = resolve(host, port)?;
        let server = Server::http(addresses.as_slice()).map_err(|e| ViewError::Bind {
            address: match addresses.as_slice() {
                [one] => one.to_string(),
                _ => format!("{host}:{port}"),
            },
            source: match e.downcast::<std::io::Error>() {
                Ok(io) => *io,
                Err(other) => std::io::Error::other(other.to_string()),
            },
        })?;
        let listening = server.server_addr().to_ip();
        let audience = Audience::new(host, listening.map(|a| a.ip()));
        let token = session_token()?;
        let page = assets::INDEX_HTML
            .replacen(
                "</head>",
                &format!("<meta name=\"{SESSION_META}\" content=\"{token}\">\n</head>"),
                1,
            )
            .into_bytes()
            .into();
        Ok(ViewServer {
            server,
            viewer,
            export,
            audience,
            token,
            page,
        })
    }

    /// The page's URL.
    pub fn url(&self) -> String {
        match self.server.server_addr().to_ip() {
            Some(addr) => format!("http://{addr}/"),
            None => "http://127.0.0.1/".to_string(),
        }
    }

    /// Whether the server listens on an address other machines may reach (anything but a
    /// loopback address): whoever reaches it sees the frames and the input paths, so the
    /// binary warns.
    pub fn reachable_from_other_machines(&self) -> bool {
        self.server
            .server_addr()
            .to_ip()
            .is_none_or(|addr| !addr.ip().is_loopback())
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
        let reply = match self.refusal(&request) {
            Some(refused) => refused,
            None if request.url().len() > MAX_URL_BYTES => Reply::error(414, "the URL is too long"),
            None => {
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
                        Ok(body) if path == "/api/unit" => self.unit(&body),
                        Ok(_) => Reply::error(404, "no such resource"),
                        Err(reply) => reply,
                    },
                    _ => Reply::error(405, "only GET and POST are answered"),
                }
            }
        };
        // A client that went away is not the server's failure.
        let _ = request.respond(reply.into_response());
    }

    /// Why `request` is not answered, if it is not: a `Host` that is not this machine's, an
    /// `Origin` of another site, or a request that changes something without the page's
    /// `Origin` and session token.
    fn refusal(&self, request: &Request) -> Option<Reply> {
        let Some(host) = header(request, "Host") else {
            return Some(Reply::error(400, "the request names no Host"));
        };
        if !self.audience.allows_host(host) {
            return Some(Reply::error(
                403,
                &format!(
                    "this viewer answers requests for localhost, 127.0.0.1, [::1] or the \
                     address it was started on, not for Host {}",
                    quoted(host)
                ),
            ));
        }
        let origin = header(request, "Origin");
        if let Some(origin) = origin
            && !same_origin(origin, host)
        {
            return Some(Reply::error(
                403,
                &format!(
                    "requests from pages of another site are refused (Origin {})",
                    quoted(origin)
                ),
            ));
        }
        // The requests that change something or cost the machine work (the export, a unit
        // built); other methods are answered 405.
        if *request.method() == Method::Post {
            if origin.is_none() {
                return Some(Reply::error(
                    403,
                    "a request that changes something must come from the viewer's page (it has no Origin)",
                ));
            }
            let token = header(request, SESSION_HEADER).unwrap_or("");
            if !same_secret(token.as_bytes(), self.token.as_bytes()) {
                return Some(Reply::error(
                    403,
                    "a request that changes something must carry the session token of the viewer's page",
                ));
            }
        }
        None
    }

    fn get(&self, path: &str) -> Reply {
        let v = &self.viewer;
        match path {
            "/" | "/index.html" => Reply::text(
                Body::Shared(self.page.clone(), 0..self.page.len()),
                "text/html; charset=utf-8",
            ),
            "/viewer.js" => Reply::text(
                Body::Static(assets::VIEWER_JS.as_bytes()),
                "text/javascript; charset=utf-8",
            ),
            "/viewer.css" => Reply::text(
                Body::Static(assets::VIEWER_CSS.as_bytes()),
                "text/css; charset=utf-8",
            ),
            "/api/scene" => {
                let mut scene = v.scene().clone();
                scene.export_available = self.export.is_some();
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
            ["parts"] => Reply::binary(Body::Frame(data, FramePart::Parts)),
            _ => Reply::error(404, "no such resource"),
        }
    }

    fn export(&self, body: &[u8]) -> Reply {
        let Some(folder) = &self.export else {
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
        // The units built on the page that the choices use: built again here (the server
        // keeps none).
        let unit_requests = match request.get("units") {
            None | Some(Value::Null) => &[][..],
            Some(Value::Array(units)) => units.as_slice(),
            Some(_) => return Reply::error(400, "units must be an array of unit requests"),
        };
        let mut units = Vec::with_capacity(unit_requests.len());
        for u in unit_requests {
            let Some(workshop) = self.viewer.units() else {
                return Reply::error(
                    409,
                    "this viewer was started without a catalog to build units from",
                );
            };
            match workshop.build(u) {
                Ok(built) => units.push(built),
                Err(e @ ViewError::UnitRequest { .. }) => {
                    return Reply::error(400, &ErrorChain(&e).to_string());
                }
                Err(e) => return Reply::error(e.http_status(), &ErrorChain(&e).to_string()),
            }
        }
        let choices = match self.viewer.parse_choices_among(glass, &units) {
            Ok(c) => c,
            Err(e) => return Reply::error(400, &ErrorChain(&e).to_string()),
        };
        match export::write_export(&self.viewer, folder, &choices, ev, &units) {
            Ok(summary) => Reply::json(&json!({
                "path": folder.dir.display().to_string(),
                "files": summary.files,
                "bytes": summary.bytes,
            })),
            Err(e) => Reply::error(500, &ErrorChain(&e).to_string()),
        }
    }
}

impl ViewServer {
    /// `POST /api/unit`: builds the unit the page asks for (400 for a malformed request, 422
    /// for one the stack engine refuses, 409 without a catalog to build from).
    fn unit(&self, body: &[u8]) -> Reply {
        let Some(units) = self.viewer.units() else {
            return Reply::error(
                409,
                "this viewer was started without a catalog to build units from",
            );
        };
        let Ok(request) = serde_json::from_slice::<Value>(body) else {
            return Reply::error(400, "the unit request must be JSON");
        };
        let start = std::time::Instant::now();
        match units.build(&request) {
            Ok(built) => Reply::json(&json!(PageBuiltUnit {
                format: PAGE_FORMAT,
                product: PageProduct::of(0, &built.record),
                lut: STANDARD.encode(&built.lut),
                build_ms: start.elapsed().as_secs_f64() * 1e3,
            })),
            Err(e @ ViewError::UnitRequest { .. }) => {
                Reply::error(400, &ErrorChain(&e).to_string())
            }
            Err(e) => Reply::error(e.http_status(), &ErrorChain(&e).to_string()),
        }
    }
}

/// The addresses `host` names for listening on `port`: an IP address as it is (also `[::1]`),
/// a name as the system resolves it.
fn resolve(host: &str, port: u16) -> Result<Vec<SocketAddr>, ViewError> {
    let bare = host
        .strip_prefix('[')
        .and_then(|h| h.strip_suffix(']'))
        .unwrap_or(host);
    if let Ok(ip) = bare.parse::<IpAddr>() {
        return Ok(vec![SocketAddr::new(ip, port)]);
    }
    let found = (bare, port)
        .to_socket_addrs()
        .map_err(|source| ViewError::Resolve {
            host: host.to_string(),
            source,
        })?;
    Ok(found.collect())
}

/// A fresh session token: 128 random bits in hex.
fn session_token() -> Result<String, ViewError> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|source| ViewError::SessionToken { source })?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// Whether two secrets are equal, in a time that does not depend on where they differ.
fn same_secret(given: &[u8], expected: &[u8]) -> bool {
    given.len() == expected.len()
        && given
            .iter()
            .zip(expected)
            .fold(0u8, |diff, (a, b)| diff | (a ^ b))
            == 0
}

/// The value of `request`'s header `name` (the first, if repeated).
fn header<'r>(request: &'r Request, name: &str) -> Option<&'r str> {
    request
        .headers()
        .iter()
        .find(|h| h.field.as_str().as_str().eq_ignore_ascii_case(name))
        .map(|h| h.value.as_str())
}

/// Whether `origin` is the origin of a page served under `host` (`http://` and the same
/// host and port).
fn same_origin(origin: &str, host: &str) -> bool {
    origin
        .strip_prefix("http://")
        .is_some_and(|rest| rest.eq_ignore_ascii_case(host))
}

/// Whom the server answers: the `Host` names a browser on this machine uses for it, the name
/// or address it was started on, and, when it listens on every interface, IP addresses (a
/// browser that reached the machine by its address). A page that reached the server by DNS
/// rebinding sends its own site's name, which none of these is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Audience {
    /// The `--bind` name, in lower case, without brackets.
    bound_name: String,
    /// The address listened on.
    bound_ip: Option<IpAddr>,
}

impl Audience {
    /// The audience of a server started on `host` (as given), listening on `ip`.
    pub fn new(host: &str, ip: Option<IpAddr>) -> Audience {
        let bare = host
            .strip_prefix('[')
            .and_then(|h| h.strip_suffix(']'))
            .unwrap_or(host);
        Audience {
            bound_name: bare.to_ascii_lowercase(),
            bound_ip: ip,
        }
    }

    /// Whether a request with this `Host` header (`name`, `name:port`, `[v6]:port`) is
    /// answered; the port is not checked (a forwarded port keeps the name).
    pub fn allows_host(&self, host: &str) -> bool {
        let Some(name) = host_name(host) else {
            return false;
        };
        let name = name.to_ascii_lowercase();
        if name == "localhost" || name == self.bound_name {
            return true;
        }
        match name.parse::<IpAddr>() {
            Ok(ip) => {
                ip.is_loopback()
                    || Some(ip) == self.bound_ip
                    || self.bound_ip.is_some_and(|b| b.is_unspecified())
            }
            Err(_) => false,
        }
    }
}

/// The name or address of a `Host` header, without its port and an IPv6 address's brackets;
/// `None` when it is malformed.
fn host_name(host: &str) -> Option<&str> {
    let (name, port) = match host.strip_prefix('[') {
        Some(rest) => {
            let (v6, after) = rest.split_once(']')?;
            v6.parse::<std::net::Ipv6Addr>().ok()?;
            if after.is_empty() {
                (v6, None)
            } else {
                (v6, Some(after.strip_prefix(':')?))
            }
        }
        None => match host.split_once(':') {
            Some((name, port)) => (name, Some(port)),
            None => (host, None),
        },
    };
    let port_ok =
        port.is_none_or(|p| !p.is_empty() && p.len() <= 5 && p.bytes().all(|b| b.is_ascii_digit()));
    let name_ok = !name.is_empty()
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-._:".contains(&b));
    (port_ok && name_ok).then_some(name)
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
    Parts,
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
            Body::Frame(data, FramePart::Parts) => &data.parts,
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
    fn text(body: Body, content_type: &'static str) -> Reply {
        Reply {
            status: 200,
            content_type,
            body,
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
            // No other site's page may load a reply (as an image or a script) or frame the page.
            ("Cross-Origin-Resource-Policy", "same-origin"),
            ("X-Frame-Options", "DENY"),
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
    fn hosts_of_this_machine_are_answered_and_other_names_refused() {
        let loopback = Audience::new("127.0.0.1", Some("127.0.0.1".parse().unwrap()));
        for host in [
            "127.0.0.1:8000",
            "127.0.0.1",
            "localhost:8000",
            "LOCALHOST",
            "[::1]:8000",
            "[::1]",
            "127.0.0.2:1",
        ] {
            assert!(loopback.allows_host(host), "{host}");
        }
        for host in [
            "evil.example:8000",
            "localhost.evil.example",
            "127.0.0.1.evil.example:8000",
            "10.0.0.5:8000",
            "",
            ":8000",
            "localhost:",
            "localhost:123456",
            "localhost:80:80",
            "[::1",
            "[::1]x",
            "[evil]:80",
            "local host",
        ] {
            assert!(!loopback.allows_host(host), "{host:?}");
        }
        // Started on a name, or on every interface (any address, but still no other name).
        let named = Audience::new("Studio.Local", Some("192.168.1.5".parse().unwrap()));
        assert!(named.allows_host("studio.local:8000"));
        assert!(named.allows_host("192.168.1.5:8000"));
        assert!(!named.allows_host("192.168.1.6:8000"));
        let every = Audience::new("0.0.0.0", Some("0.0.0.0".parse().unwrap()));
        assert!(every.allows_host("192.168.1.6:8000"));
        assert!(every.allows_host("[fe80::1]:8000"));
        assert!(!every.allows_host("evil.example:8000"));
        let v6 = Audience::new("[::]", Some("::".parse().unwrap()));
        assert!(v6.allows_host("10.1.2.3"));
    }

    #[test]
    fn origins_and_tokens_must_match_exactly() {
        assert!(same_origin("http://127.0.0.1:8000", "127.0.0.1:8000"));
        assert!(same_origin("http://LOCALHOST:8000", "localhost:8000"));
        for origin in [
            "https://127.0.0.1:8000",
            "http://127.0.0.1:8001",
            "http://127.0.0.1:8000/",
            "null",
            "",
        ] {
            assert!(!same_origin(origin, "127.0.0.1:8000"), "{origin}");
        }
        assert!(same_secret(b"abcd", b"abcd"));
        assert!(!same_secret(b"abcd", b"abce"));
        assert!(!same_secret(b"abc", b"abcd"));
        assert!(!same_secret(b"", b"abcd"));
        let a = session_token().unwrap();
        assert_eq!(a.len(), 32);
        assert_ne!(a, session_token().unwrap());
    }

    #[test]
    fn indices_are_digits_below_the_length() {
        assert_eq!(index("0", 3), Some(0));
        assert_eq!(index("2", 3), Some(2));
        for bad in ["3", "-1", "", "1e2", "..", "01x", "99999999999999999999"] {
            assert_eq!(index(bad, 3), None, "{bad}");
        }
    }
}
