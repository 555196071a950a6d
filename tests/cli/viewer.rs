//! `glassdb view` in a real browser (headless Chromium through WebDriver,
//! `python_oracle/viewer_driver.py`; WebGL2 on SwiftShader here): a product swapped through the
//! page's controls gives the canvas `compose` writes for the same products (its PNG, standard
//! view, undithered), the exported folder gives the same pixels from `file://`, and the server
//! answers bad requests with 4xx. Chromium missing is a failure, not a skip
//! (`scripts/test-all` installs it).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use crate::util::{
    atrium_planes_file, fails_naming, glassdb, ok, read_png_planes, registry_build, repo_path,
    run_oracle,
};

const SWAP_ID: u16 = 5;
/// The product the tests put on the atrium's tinted glass (id 5).
const SWAP_PRODUCT: &str = "AGC Stopray Titanium 34T on grey 8 mm (NFRC 20748)";

/// The atrium's inputs as `glassdb view` and `compose` take them.
fn atrium_inputs(cmd: &mut Command) -> &mut Command {
    let a = |f: &str| repo_path("fixtures/atrium").join(f);
    cmd.arg("--trans").arg(a("trans.exr"));
    for k in 0..3 {
        cmd.arg("--refl").arg(a(&format!("refl_{k}.exr")));
    }
    cmd.arg("--mask")
        .arg(a("mask.png"))
        .arg("--planes")
        .arg(a("virtual/planes.json"))
}

/// A running viewer, stopped when dropped.
struct Served {
    child: Child,
    url: String,
    /// Kept open: the viewer ends quietly when its standard output is closed, as every
    /// glassdb command does on a closed pipe.
    _stdout: BufReader<std::process::ChildStdout>,
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Serves the atrium with `extra` arguments.
fn serve(extra: &[&std::ffi::OsStr]) -> Served {
    let mut cmd = glassdb();
    cmd.arg("view");
    atrium_inputs(&mut cmd).args(extra);
    spawn_viewer(&mut cmd)
}

/// `glassdb view` of the atrium whose page may export into `dir/from-page` (`--export-dir`),
/// and that folder.
fn serve_exporting_into(dir: &Path) -> (Served, PathBuf) {
    let export = dir.join("from-page");
    let served = serve(&["--export-dir".as_ref(), export.as_os_str()]);
    (served, export)
}

/// Starts `cmd` (a `glassdb view` with its inputs) on a free port and reads its URL.
fn spawn_viewer(cmd: &mut Command) -> Served {
    cmd.args(["--port", "0"])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    let mut child = cmd.spawn().expect("start glassdb view");
    let mut line = String::new();
    let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
    stdout.read_line(&mut line).expect("read the URL");
    let url = line
        .trim()
        .strip_prefix("serving ")
        .unwrap_or_else(|| panic!("no URL in {line:?}"))
        .to_string();
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    Served {
        child,
        url,
        _stdout: stdout,
    }
}

/// The registry `source` with `product`'s record under id `id` in every table: what the page
/// composites after the swap, written independently of the viewer (JSON edited directly).
pub(crate) fn swapped_registry(source: &Path, dir: &Path, id: u16, product: &str) -> PathBuf {
    let text = std::fs::read_to_string(source).unwrap();
    let mut reg: serde_json::Value = serde_json::from_str(&text).unwrap();
    for table in reg["tables"].as_array_mut().unwrap() {
        let glasses = table["glasses"].as_array_mut().unwrap();
        let mut record = glasses
            .iter()
            .find(|g| g["name"] == product)
            .expect("product in the registry")
            .clone();
        record["id"] = id.into();
        let slot = glasses.iter().position(|g| g["id"] == id).unwrap();
        glasses[slot] = record;
    }
    let path = dir.join("swapped.json");
    std::fs::write(&path, reg.to_string()).unwrap();
    path
}

/// compose's 8-bit PNG of the atrium (standard view, no dither) with `registry`, one
/// reflection pass per plane as the page composites it (`--surfaces 1`: a unit's inner panes'
/// reflectance on its plane's pass).
fn compose_png(dir: &Path, registry: Option<&Path>, name: &str) -> Vec<[f64; 3]> {
    let out = dir.join(name);
    let mut cmd = glassdb();
    cmd.arg("compose");
    atrium_inputs(&mut cmd)
        .args(["--surfaces", "1", "--dither", "none", "-o"])
        .arg(&out);
    if let Some(r) = registry {
        cmd.arg("--registry").arg(r);
    }
    ok(&mut cmd);
    png_pixels(&out)
}

/// [`compose_png`] with the bundled registry's `product` on glass [`SWAP_ID`]: the picture the
/// page shows after that swap.
fn compose_png_with_swap(dir: &Path, product: &str, name: &str) -> Vec<[f64; 3]> {
    let registry = swapped_registry(&repo_path("data/registry.json"), dir, SWAP_ID, product);
    compose_png(dir, Some(&registry), name)
}

/// A PNG's RGB per pixel, rows top to bottom.
fn png_pixels(path: &Path) -> Vec<[f64; 3]> {
    let p = read_png_planes(path);
    (0..p.width * p.height)
        .map(|i| [0, 1, 2].map(|c| p.channels[c][i]))
        .collect()
}

/// The canvas after the driver's swaps, as RGB per pixel (the page's RGBA read back).
fn canvas(url: &str, swaps: &[String], out: &Path) -> (Vec<[f64; 3]>, serde_json::Value) {
    let mut args: Vec<std::ffi::OsString> = vec!["check".into(), url.into(), "--out".into()];
    args.push(out.into());
    for s in swaps {
        args.push("--swap".into());
        args.push(s.into());
    }
    let refs: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let report: serde_json::Value =
        serde_json::from_str(run_oracle("viewer_driver.py", &refs).trim()).unwrap();
    (rgba_pixels(out), report)
}

/// The RGB of the RGBA bytes the driver wrote, per pixel.
fn rgba_pixels(path: &Path) -> Vec<[f64; 3]> {
    std::fs::read(path)
        .unwrap()
        .chunks_exact(4)
        .map(|p| [0, 1, 2].map(|c| f64::from(p[c])))
        .collect()
}

/// The atrium exported with `extra` arguments into `dir/export`, opened from `file://`: its
/// canvas and the driver's report.
fn exported_canvas(dir: &Path, extra: &[&str]) -> (Vec<[f64; 3]>, serde_json::Value) {
    let export = dir.join("export");
    let mut cmd = glassdb();
    cmd.arg("view");
    atrium_inputs(&mut cmd)
        .arg("--export")
        .arg(&export)
        .args(extra);
    ok(&mut cmd);
    let url = format!("file://{}", export.join("index.html").display());
    canvas(&url, &[], &dir.join("export.rgba"))
}

fn psnr(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    assert_eq!(a.len(), b.len(), "image sizes differ");
    let se: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).powi(2)))
        .sum();
    let mse = se / (3 * a.len()) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

/// Asserts that the canvas `got` shows compose's pixels `want` (a PSNR of 50 dB or more);
/// `what` names the comparison in the failure message.
fn assert_composes_pixels(got: &[[f64; 3]], want: &[[f64; 3]], what: &str) {
    let db = psnr(got, want);
    assert!(db >= 50.0, "{what}: {db:.1} dB");
}

/// Asserts that the page at `url`, without swaps (its canvas read back into `out`), draws
/// without errors and shows compose's pixels `want` (see [`assert_composes_pixels`]).
fn assert_page_shows(url: &str, out: &Path, want: &[[f64; 3]], what: &str) {
    let (got, report) = canvas(url, &[], out);
    assert_eq!(report["errors"], serde_json::json!([]), "{report}");
    assert_composes_pixels(&got, want, what);
}

#[test]
fn a_product_swapped_on_the_page_gives_composes_pixels_and_the_export_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let want = compose_png_with_swap(dir.path(), SWAP_PRODUCT, "swapped.png");
    let unswapped = compose_png(dir.path(), None, "bundled.png");
    // The swap changes the picture visibly, so matching `want` says the swap happened.
    assert!(psnr(&want, &unswapped) < 40.0);

    let served = serve(&[]);
    let swap = format!("{SWAP_ID}:{SWAP_PRODUCT}");
    let (got, report) = canvas(&served.url, &[swap], &dir.path().join("canvas.rgba"));
    assert_eq!(report["errors"], serde_json::json!([]), "{report}");
    assert_eq!(report["products"]["A"]["5"], SWAP_PRODUCT, "{report}");
    assert_eq!(
        report["marker"], "2",
        "first frame, then the swap: {report}"
    );
    assert_composes_pixels(&got, &want, "page vs compose after the swap");

    // URL parameters choose the same product (by a unique part of its name).
    let by_url = format!("{}?glass=5:Stopray&ev=0", served.url);
    let (got, _) = canvas(&by_url, &[], &dir.path().join("url.rgba"));
    assert_composes_pixels(&got, &want, "page with ?glass= vs compose");

    // A/B split: set A as bundled left of the middle, set B with the swap right of it.
    let split = format!("{}?glassB=5:Stopray&ab=split&split=0.5", served.url);
    let (got, report) = canvas(&split, &[], &dir.path().join("split.rgba"));
    assert_eq!(report["products"]["B"]["5"], SWAP_PRODUCT, "{report}");
    let width = report["width"].as_u64().unwrap() as usize;
    let half = |img: &[[f64; 3]], right: bool| -> Vec<[f64; 3]> {
        img.iter()
            .enumerate()
            .filter(|(i, _)| (i % width >= width / 2) == right)
            .map(|(_, p)| *p)
            .collect()
    };
    for (right, reference, name) in [(false, &unswapped, "A (left)"), (true, &want, "B (right)")] {
        assert_composes_pixels(
            &half(&got, right),
            &half(reference, right),
            &format!("split view, {name}"),
        );
    }
    drop(served);

    // The export, opened from disk, starts with the chosen product.
    let (got, report) = exported_canvas(dir.path(), &["--glass", "5:stopray titanium"]);
    assert_eq!(report["products"]["A"]["5"], SWAP_PRODUCT, "{report}");
    assert_composes_pixels(&got, &want, "exported page vs compose");
}

/// The `host:port` a served URL names.
fn host_of(url: &str) -> &str {
    url.trim_start_matches("http://").trim_end_matches('/')
}

/// One raw HTTP request; the status code and the body.
fn exchange(url: &str, request: &[u8]) -> (u16, String) {
    let mut s = TcpStream::connect(host_of(url)).unwrap();
    s.write_all(request).unwrap();
    let mut reply = Vec::new();
    let _ = s.read_to_end(&mut reply);
    let text = String::from_utf8_lossy(&reply).into_owned();
    let code = text
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("no status in {text:?}"));
    let (head, body) = text.split_once("\r\n\r\n").unwrap_or((&text, ""));
    let chunked = head
        .lines()
        .any(|l| l.eq_ignore_ascii_case("transfer-encoding: chunked"));
    (
        code,
        if chunked {
            dechunk(body)
        } else {
            body.to_string()
        },
    )
}

/// An HTTP/1.1 chunked body, joined (tiny_http chunks large replies).
fn dechunk(mut body: &str) -> String {
    let mut out = String::new();
    while let Some((size, rest)) = body.split_once("\r\n") {
        let n = usize::from_str_radix(size.trim(), 16).unwrap_or(0);
        if n == 0 || rest.len() < n {
            break;
        }
        out.push_str(&rest[..n]);
        body = rest[n..].strip_prefix("\r\n").unwrap_or(&rest[n..]);
    }
    out
}

/// One raw HTTP/1.1 request; the status code.
fn status(url: &str, request: &[u8]) -> u16 {
    exchange(url, request).0
}

/// A GET of `path` with the `Host` a browser on this machine sends.
fn get(url: &str, path: &str) -> u16 {
    get_as(url, path, host_of(url)).0
}

/// A GET of `path` naming `host` in its `Host` header: the status and the body.
fn get_as(url: &str, path: &str, host: &str) -> (u16, String) {
    exchange(
        url,
        format!("GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n").as_bytes(),
    )
}

/// The session token of the page the viewer serves.
fn page_token(url: &str) -> String {
    let (code, page) = get_as(url, "/", host_of(url));
    assert_eq!(code, 200);
    let start = page
        .find("name=\"glassdb-session\" content=\"")
        .unwrap_or_else(|| panic!("no session token in the page:\n{page}"));
    let rest = &page[start + "name=\"glassdb-session\" content=\"".len()..];
    rest[..rest.find('"').unwrap()].to_string()
}

/// A POST as the viewer's own page sends it: its `Origin` and session token; the status.
fn post(url: &str, path: &str, body: &[u8]) -> u16 {
    post_reply(url, path, body).0
}

/// A POST of `body` with the `Host` of `url` and the extra `headers`; the status.
fn post_with(url: &str, path: &str, body: &[u8], headers: &[(&str, &str)]) -> u16 {
    post_with_reply(url, path, body, headers).0
}

#[test]
fn the_server_answers_bad_requests_with_4xx_and_serves_no_files() {
    let dir = tempfile::tempdir().unwrap();
    let (served, export) = serve_exporting_into(dir.path());
    let u = &served.url;
    assert_eq!(get(u, "/"), 200);
    assert_eq!(get(u, "/api/scene"), 200);
    for path in [
        "/../Cargo.toml",
        "/..%2f..%2fetc%2fpasswd",
        "/fixtures/atrium/trans.exr",
        "/api/frame/1/passes",
        "/api/frame/-1",
        "/api/frame/0/../../scene",
        "/api/product/99/lut",
        "/api/product/x/lut",
        "/api/frame/99999999999999999999",
    ] {
        assert_eq!(get(u, path), 404, "{path}");
    }
    let long = format!("/{}", "a".repeat(10_000));
    assert_eq!(get(u, &long), 414);
    let delete = format!(
        "DELETE / HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
        host_of(u)
    );
    assert_eq!(status(u, delete.as_bytes()), 405);
    assert_eq!(post(u, "/api/export", &vec![b' '; 100_000]), 413);
    assert_eq!(post(u, "/api/export", b"not json"), 400);
    assert_eq!(
        post(u, "/api/export", br#"{"glass": "5:no such glass"}"#),
        400
    );
    assert_eq!(post(u, "/api/export", br#"{"glass": "77:Stopray"}"#), 400);
    assert_eq!(post(u, "/api/scene", b"{}"), 404);
    // Nothing was written by the refused exports; a good one writes the folder.
    assert!(!export.exists());
    assert_eq!(
        post(u, "/api/export", br#"{"glass": "5:Stopray", "ev": 1}"#),
        200
    );
    for f in [
        "index.html",
        "viewer.js",
        "viewer.css",
        "data.js",
        "frame-0000.js",
    ] {
        assert!(export.join(f).is_file(), "{f}");
    }
    // Still serving after all that.
    assert_eq!(get(u, "/viewer.js"), 200);
}

/// DNS rebinding and cross-site requests, at the HTTP level: only `Host` names of this machine
/// are answered, and an export needs the page's `Origin` and session token.
#[test]
fn the_server_answers_only_this_machine_and_only_its_page_may_export() {
    let dir = tempfile::tempdir().unwrap();
    let (served, export) = serve_exporting_into(dir.path());
    let u = &served.url;
    let port = u.rsplit(':').next().unwrap().trim_end_matches('/');
    for host in [
        format!("127.0.0.1:{port}"),
        format!("localhost:{port}"),
        "LocalHost".to_string(),
        format!("[::1]:{port}"),
        // A forwarded port (ssh -L) keeps the name.
        "localhost:9".to_string(),
    ] {
        assert_eq!(get_as(u, "/api/scene", &host).0, 200, "Host {host}");
    }
    for host in [
        format!("rebound.example:{port}"),
        "rebound.example".to_string(),
        format!("localhost.rebound.example:{port}"),
        format!("127.0.0.1.rebound.example:{port}"),
        "".to_string(),
        "localhost:80:80".to_string(),
        "[::1".to_string(),
        "x".repeat(5000),
    ] {
        for path in ["/", "/api/scene", "/api/frame/0/passes", "/viewer.js"] {
            let (code, body) = get_as(u, path, &host);
            assert_eq!(code, 403, "Host {host:.40} {path}: {body:.200}");
            assert!(body.len() < 400, "{body}");
        }
    }
    let (code, body) = exchange(u, b"GET /api/scene HTTP/1.0\r\n\r\n");
    assert_eq!(code, 400, "no Host: {body}");

    // A page of another site may not read through the viewer's address either.
    let origin = format!("http://{}", host_of(u));
    let token = page_token(u);
    let foreign = [("Origin", "http://rebound.example")];
    let (code, _) = exchange(
        u,
        format!(
            "GET /api/scene HTTP/1.1\r\nHost: {}\r\nOrigin: http://rebound.example\r\nConnection: close\r\n\r\n",
            host_of(u)
        )
        .as_bytes(),
    );
    assert_eq!(code, 403);

    let request = br#"{"glass": "5:Stopray", "ev": 1}"#;
    let text_plain = ("Content-Type", "text/plain");
    // What any page can send without asking: a cross-site text/plain POST.
    assert_eq!(
        post_with(u, "/api/export", request, &[foreign[0], text_plain]),
        403
    );
    assert_eq!(
        post_with(
            u,
            "/api/export",
            request,
            &[foreign[0], text_plain, ("X-Glassdb-Session", &token)]
        ),
        403
    );
    // The page's own origin, without the token or with another.
    assert_eq!(
        post_with(u, "/api/export", request, &[("Origin", &origin)]),
        403
    );
    let wrong = "0".repeat(token.len());
    assert_eq!(
        post_with(
            u,
            "/api/export",
            request,
            &[("Origin", &origin), ("X-Glassdb-Session", &wrong)]
        ),
        403
    );
    // The token without an Origin, and the "null" origin of a sandboxed or local page.
    assert_eq!(
        post_with(u, "/api/export", request, &[("X-Glassdb-Session", &token)]),
        403
    );
    assert_eq!(
        post_with(
            u,
            "/api/export",
            request,
            &[("Origin", "null"), ("X-Glassdb-Session", &token)]
        ),
        403
    );
    assert!(!export.exists(), "a refused request wrote the export");
    // The page's origin and token: written.
    assert_eq!(
        post_with(
            u,
            "/api/export",
            request,
            &[("Origin", &origin), ("X-Glassdb-Session", &token)]
        ),
        200
    );
    assert!(export.join("index.html").is_file());
    // Each viewer draws its own token.
    let other = serve(&[]);
    assert_ne!(page_token(&other.url), token);
}

/// The same in Chromium: a page of another site whose name resolves to the viewer's address
/// (DNS rebinding) gets nothing, and its cross-site POST writes nothing; the viewer's own
/// page still exports with its button.
#[test]
fn in_chromium_a_rebinding_page_gets_nothing_and_the_real_page_exports() {
    let dir = tempfile::tempdir().unwrap();
    let (served, export) = serve_exporting_into(dir.path());
    let said = run_oracle(
        "viewer_driver.py",
        &[
            "rebind".as_ref(),
            served.url.as_ref(),
            "--name".as_ref(),
            "glassdb-rebound.test".as_ref(),
        ],
    );
    let report: serde_json::Value = serde_json::from_str(said.trim()).unwrap();
    assert_eq!(
        report["origin"],
        format!(
            "http://glassdb-rebound.test:{}",
            served.url.rsplit(':').next().unwrap().trim_end_matches('/')
        ),
        "{report}"
    );
    let page = report["page"].as_str().unwrap();
    assert!(page.contains("not for Host"), "{report}");
    assert!(!page.contains("glassdb view"), "{report}");
    assert_eq!(report["scene_status"], 403, "{report}");
    assert!(
        !export.exists(),
        "the other site's POST wrote the export: {report}"
    );

    let said = run_oracle(
        "viewer_driver.py",
        &["export".as_ref(), served.url.as_ref()],
    );
    let report: serde_json::Value = serde_json::from_str(said.trim()).unwrap();
    assert_eq!(report["errors"], serde_json::json!([]), "{report}");
    let status = report["status"].as_str().unwrap();
    assert!(status.starts_with("exported to "), "{report}");
    for f in [
        "index.html",
        "data.js",
        "frame-0000.js",
        "glassdb-export.json",
    ] {
        assert!(export.join(f).is_file(), "{f}");
    }
}

/// A viewer listening on every interface says so on its standard error; one on 127.0.0.1
/// does not.
#[test]
fn a_viewer_other_machines_can_reach_warns() {
    for (bind, warns) in [
        ("0.0.0.0", true),
        ("127.0.0.1", false),
        ("localhost", false),
    ] {
        let mut cmd = glassdb();
        cmd.arg("view");
        atrium_inputs(&mut cmd)
            .args(["--bind", bind, "--port", "0"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        let mut child = cmd.spawn().unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        assert!(line.starts_with("serving http://"), "{line}");
        let _ = child.kill();
        let _ = child.wait();
        let stderr = std::io::read_to_string(child.stderr.take().unwrap()).unwrap();
        assert_eq!(
            stderr.contains("warning: --bind") && stderr.contains("other machines"),
            warns,
            "--bind {bind}: {stderr:?}"
        );
    }
}

#[test]
fn without_an_export_folder_the_page_export_is_refused() {
    let served = serve(&[]);
    assert_eq!(post(&served.url, "/api/export", b"{}"), 409);
}

#[test]
fn bad_choices_and_export_paths_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let view = |extra: &[&std::ffi::OsStr]| {
        let mut cmd = glassdb();
        cmd.arg("view");
        atrium_inputs(&mut cmd).args(extra);
        cmd
    };
    let out = dir.path().join("out");
    fails_naming(
        &mut view(&[
            "--export".as_ref(),
            out.as_os_str(),
            "--glass".as_ref(),
            "5:no such glass".as_ref(),
        ]),
        &["no such glass", "Stopray"],
    );
    fails_naming(
        &mut view(&[
            "--export".as_ref(),
            out.as_os_str(),
            "--glass".as_ref(),
            "5:clear".as_ref(),
        ]),
        &["clear", "several products"],
    );
    let said = fails_naming(
        &mut view(&["--export".as_ref(), file.as_os_str()]),
        &["a-file", "it is a regular file, not a folder"],
    );
    assert!(!said.contains("os error"), "{said}");
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
    assert!(!out.exists());
    // A port another program holds: refused, with the way out, the cause said once.
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let said = fails_naming(
        &mut view(&["--port".as_ref(), port.as_ref()]),
        &["cannot listen", &port, "another program", "--port 0"],
    );
    assert_eq!(said.matches("in use").count(), 1, "{said}");
    // A name that does not resolve: said so, without the hint about another program.
    let said = fails_naming(
        &mut view(&["--bind".as_ref(), "no-such-host.invalid".as_ref()]),
        &[
            "no-such-host.invalid",
            "--bind takes an IP address or a name",
        ],
    );
    assert!(!said.contains("another program"), "{said}");
    assert_eq!(said.matches("lookup").count(), 1, "{said}");
}

/// What `--export` does to a folder that exists (docs/reliability.md): links in it are
/// replaced, never followed; a folder that holds other things is refused without --force; a
/// previous export is replaced, its frames that this one lacks removed.
#[cfg(unix)]
#[test]
fn an_export_never_follows_links_and_keeps_to_its_own_folders() {
    let dir = tempfile::tempdir().unwrap();
    let export = |target: &Path, extra: &[&str]| {
        let mut cmd = glassdb();
        cmd.arg("view");
        atrium_inputs(&mut cmd)
            .arg("--export")
            .arg(target)
            .args(extra);
        cmd
    };
    // A folder someone else filled: refused, named, nothing written; --force writes.
    let site = dir.path().join("site");
    std::fs::create_dir(&site).unwrap();
    std::fs::write(site.join("index.html"), b"my site").unwrap();
    std::fs::write(site.join("notes.txt"), b"notes").unwrap();
    fails_naming(
        &mut export(&site, &[]),
        &["site", "not empty", "index.html, notes.txt", "--force"],
    );
    assert_eq!(std::fs::read(site.join("index.html")).unwrap(), b"my site");
    assert!(!site.join("data.js").exists());
    ok(&mut export(&site, &["--force"]));
    assert!(
        std::fs::read_to_string(site.join("index.html"))
            .unwrap()
            .contains("glassdb view")
    );
    assert_eq!(std::fs::read(site.join("notes.txt")).unwrap(), b"notes");

    // Links planted in a previous export: replaced, what they lead to untouched.
    let outside = dir.path().join("outside.css");
    std::fs::write(&outside, b"kept").unwrap();
    let css = site.join("viewer.css");
    std::fs::remove_file(&css).unwrap();
    std::os::unix::fs::symlink(&outside, &css).unwrap();
    let planted = dir.path().join("planted.html");
    std::fs::remove_file(site.join("index.html")).unwrap();
    std::os::unix::fs::symlink(&planted, site.join("index.html")).unwrap();
    ok(&mut export(&site, &[]));
    assert_eq!(std::fs::read(&outside).unwrap(), b"kept");
    assert!(
        !planted.exists(),
        "an export created a file through a dangling link"
    );
    for f in ["viewer.css", "index.html"] {
        assert!(
            std::fs::symlink_metadata(site.join(f)).unwrap().is_file(),
            "{f} is still a link"
        );
    }
    // A previous export's frame that this one lacks is removed; its marker names its files.
    let marker = site.join("glassdb-export.json");
    let mut listed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&marker).unwrap()).unwrap();
    listed["files"].as_array_mut().unwrap().extend([
        "frame-0007.js".into(),
        "../outside.css".into(),
        "notes.txt".into(),
    ]);
    std::fs::write(&marker, listed.to_string()).unwrap();
    std::fs::write(site.join("frame-0007.js"), b"old frame").unwrap();
    ok(&mut export(&site, &[]));
    assert!(!site.join("frame-0007.js").exists());
    assert!(site.join("frame-0000.js").is_file());
    assert_eq!(std::fs::read(&outside).unwrap(), b"kept");
    assert_eq!(std::fs::read(site.join("notes.txt")).unwrap(), b"notes");

    // An empty folder, a new one, and a link to a folder are written.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    ok(&mut export(&empty, &[]));
    ok(&mut export(&dir.path().join("new/deeper"), &[]));
    let link = dir.path().join("link-to-empty");
    let target = dir.path().join("empty-too");
    std::fs::create_dir(&target).unwrap();
    std::os::unix::fs::symlink(&target, &link).unwrap();
    ok(&mut export(&link, &[]));
    assert!(target.join("index.html").is_file());

    // The page's export folder is checked when the viewer starts.
    let mut cmd = glassdb();
    cmd.arg("view");
    atrium_inputs(&mut cmd)
        .arg("--export-dir")
        .arg(dir.path().join("new"));
    fails_naming(&mut cmd, &["--export-dir", "not empty", "deeper"]);
}

/// Frame 2 of a two-frame sequence whose second frame has other pixels (the atrium's plane-1
/// reflection as its transmission pass) and the float mask with coverage (`mask.exr`): the
/// fine-table interpolation and the coverage weights, after the frame slider moved.
#[test]
fn a_second_frame_with_a_float_mask_gives_composes_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let a = |f: &str| repo_path("fixtures/atrium").join(f);
    let copy = |from: &str, to: String| std::fs::copy(a(from), dir.path().join(to)).unwrap();
    for frame in [1, 2] {
        let trans = if frame == 1 {
            "trans.exr"
        } else {
            "refl_1.exr"
        };
        copy(trans, format!("trans.{frame:04}.exr"));
        copy("mask.exr", format!("mask.{frame:04}.exr"));
        for k in 0..3 {
            copy(&format!("refl_{k}.exr"), format!("refl_{k}.{frame:04}.exr"));
        }
    }
    let d = dir.path();
    let files = |cmd: &mut Command, frame: &str| {
        cmd.arg("--trans").arg(d.join(format!("trans.{frame}.exr")));
        for k in 0..3 {
            cmd.arg("--refl")
                .arg(d.join(format!("refl_{k}.{frame}.exr")));
        }
        cmd.arg("--mask")
            .arg(d.join(format!("mask.{frame}.exr")))
            .arg("--planes")
            .arg(a("virtual/planes.json"));
    };
    let out = d.join("frame2.png");
    let mut cmd = glassdb();
    cmd.arg("compose");
    files(&mut cmd, "0002");
    ok(cmd.args(["--dither", "none", "-o"]).arg(&out));
    let want = png_pixels(&out);

    let mut cmd = glassdb();
    cmd.arg("view");
    files(&mut cmd, "####");
    cmd.args(["--frames", "1-2"]);
    let served = spawn_viewer(&mut cmd);
    assert_page_shows(
        &format!("{}?frame=1", served.url),
        &d.join("f2.rgba"),
        &want,
        "frame 2 with the float mask vs compose",
    );
}

/// The viewer takes compose's input flags (one struct): one multi-part `--refl planes.exr`,
/// written by OpenEXR with every plane's pass cropped to its glass, gives the page the pixels
/// compose writes from the three separate passes.
#[test]
fn a_multi_part_reflection_file_gives_composes_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let a = |f: &str| repo_path("fixtures/atrium").join(f);
    let parts = atrium_planes_file(&dir.path().join("planes.exr"), None);
    let want = compose_png(dir.path(), None, "separate.png");

    let mut cmd = glassdb();
    cmd.arg("view")
        .arg("--trans")
        .arg(a("trans.exr"))
        .arg("--refl")
        .arg(&parts)
        .arg("--mask")
        .arg(a("mask.png"))
        .arg("--planes")
        .arg(a("virtual/planes.json"));
    let served = spawn_viewer(&mut cmd);
    assert_page_shows(
        &served.url,
        &dir.path().join("parts.rgba"),
        &want,
        "page from planes.exr vs compose",
    );
}

/// The unit the ghost test puts on the atrium's glass 5 (plane 1): two pane groups.
const GHOST_UNIT: &str = "Double clear: clear 6 | 12.7 air | clear 6";

/// Units and their ghosts (issue 27): with a pass for plane 1's pane group 1 (here the
/// transmission pass, a picture unlike the plane's own reflection), a product change on the
/// page between the monolithic glass and a double unit shows the inner pane's reflection: the
/// page matches `compose --refl-group` within 1 code value, in set A and in set B, and differs
/// from the one-pass (`--surfaces 1`) composite on the unit's pixels.
#[test]
fn a_unit_swapped_in_shows_its_ghost_as_compose_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = |f: &str| repo_path("fixtures/atrium").join(f);
    let registry = swapped_registry(&repo_path("data/registry.json"), d, SWAP_ID, GHOST_UNIT);
    let group = format!("1.1={}", a("trans.exr").display());
    let composed = |extra: &[&str], name: &str| {
        let out = d.join(name);
        let mut cmd = glassdb();
        cmd.arg("compose");
        atrium_inputs(&mut cmd)
            .args(["--dither", "none", "--registry"])
            .arg(&registry)
            .args(extra)
            .arg("-o")
            .arg(&out);
        ok(&mut cmd);
        png_pixels(&out)
    };
    let want = composed(&["--refl-group", &group], "ghost.png");
    let folded = composed(&["--surfaces", "1"], "folded.png");
    let bundled = compose_png(d, None, "bundled.png");

    let served = serve(&["--refl-group".as_ref(), group.as_ref()]);
    let max_diff = |a: &[[f64; 3]], b: &[[f64; 3]]| {
        a.iter()
            .zip(b)
            .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
            .fold(0.0f64, f64::max)
    };
    // Set A: the unit swapped in through the page's controls.
    let swap = format!("{SWAP_ID}:{GHOST_UNIT}");
    let (got, report) = canvas(&served.url, &[swap], &d.join("a.rgba"));
    assert_eq!(report["errors"], serde_json::json!([]), "{report}");
    assert_eq!(report["products"]["A"]["5"], GHOST_UNIT, "{report}");
    let diff = max_diff(&got, &want);
    assert!(
        diff <= 1.0,
        "page (set A) vs compose --refl-group: {diff} code values"
    );
    // The ghost is there: the one-pass composite differs on the unit's pixels.
    let ghost_pixels = got
        .iter()
        .zip(&folded)
        .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > 2.0))
        .count();
    assert!(
        ghost_pixels > 500,
        "only {ghost_pixels} pixels differ from --surfaces 1"
    );
    // Set B holds the unit, set A the bundled monolithic glass: B shows the ghost, A not.
    let ab = format!("{}?glassB=5:{}&ab=B", served.url, "Double clear");
    let (got, report) = canvas(&ab, &[], &d.join("b.rgba"));
    assert_eq!(report["products"]["B"]["5"], GHOST_UNIT, "{report}");
    let diff = max_diff(&got, &want);
    assert!(
        diff <= 1.0,
        "page (set B) vs compose --refl-group: {diff} code values"
    );
    let plain = format!("{}?glassB=5:{}&ab=A", served.url, "Double clear");
    let (got, _) = canvas(&plain, &[], &d.join("plain.rgba"));
    let diff = max_diff(&got, &bundled);
    assert!(
        diff <= 1.0,
        "page (set A, no unit) vs compose: {diff} code values"
    );
}

/// 8-bit codes of the linear RGB in `exr` (its beauty), as the page's standard view writes
/// them (sRGB transfer, clipped, rounded): what the canvas shows of a composite at 0 EV.
fn srgb_codes(exr: &Path) -> Vec<[f64; 3]> {
    srgb_codes_at(exr, 0.0)
}

/// [`srgb_codes`] at `ev` stops (the page's exposure).
fn srgb_codes_at(exr: &Path, ev: f64) -> Vec<[f64; 3]> {
    let p = crate::util::read_exr_planes(exr);
    let rgb = ["R", "G", "B"].map(|c| crate::blender_ghosts::channel(&p, c));
    let encode = |v: f64| {
        let v = (v * ev.exp2()).clamp(0.0, 1.0);
        let e = if v <= 0.0031308 {
            v * 12.92
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (e * 255.0).round()
    };
    (0..p.width * p.height)
        .map(|i| [0, 1, 2].map(|c| encode(rgb[c][i])))
        .collect()
}

/// `glassdb blender compose RUN` (with `registry`, else the bundled one): its composite of the
/// first frame as 8-bit codes ([`srgb_codes`]).
fn blender_composed(run: &Path, registry: Option<&Path>) -> Vec<[f64; 3]> {
    blender_composed_at(run, registry, 0.0)
}

/// [`blender_composed`] at `ev` stops.
fn blender_composed_at(run: &Path, registry: Option<&Path>, ev: f64) -> Vec<[f64; 3]> {
    let mut cmd = glassdb();
    cmd.args(["blender", "compose"]).arg(run);
    if let Some(r) = registry {
        cmd.arg("--registry").arg(r);
    }
    ok(&mut cmd);
    srgb_codes_at(&run.join("composite.0001.exr"), ev)
}

/// Pixels where `a` and `b` differ by more than `codes` in some channel.
fn pixels_apart(a: &[[f64; 3]], b: &[[f64; 3]], codes: f64) -> usize {
    assert_eq!(a.len(), b.len(), "image sizes differ");
    a.iter()
        .zip(b)
        .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > codes))
        .count()
}

/// The canvas's RGB, as a `layout` snippet returns it.
const READ_CANVAS: &str =
    "return Array.from(atob(window.glassdb.readPixels()), (c) => c.charCodeAt(0));";

fn canvas_of(result: &serde_json::Value) -> Vec<[f64; 3]> {
    let bytes: Vec<f64> = result
        .as_array()
        .unwrap_or_else(|| panic!("no canvas: {result}"))
        .iter()
        .map(num)
        .collect();
    bytes.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect()
}

/// A `glassdb blender render` run of the ghost scene's unit window with glass `unit` (the
/// light split on, the default) opened with `glassdb view RUN`: the page shows the units'
/// ghosts with the light parts, equal within 1 code value to `glassdb blender compose RUN`,
/// for the rendered product and after a product change on the page to `other` (compose with a
/// registry holding `other` under the unit's id); both differ from the one-pass composite
/// (`--surfaces 1`) on more than `min_ghost` pixels. Returns the page's frame description.
fn relit_ghosts_match_blender_compose(
    unit: u16,
    other: &str,
    min_ghost: usize,
) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (blend, _) = crate::blender_ghosts::ghost_scene(d, "unit");
    let run = d.join("run");
    crate::blender_ghosts::render(
        &blend,
        &format!("Unit={unit}"),
        &run,
        &["--samples", "8", "--resolution", "64x48"],
    );
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("glassdb-blender.json")).unwrap())
            .unwrap();
    let frame = &record["frames"][0];
    let parts = frame["light_parts"]
        .as_str()
        .unwrap_or_else(|| panic!("{record}"));
    assert!(
        frame["groups"].as_array().is_some_and(|g| !g.is_empty()),
        "{record}"
    );

    let want = blender_composed(&run, None);
    let registry = swapped_registry(&repo_path("data/registry.json"), d, unit, other);
    let want_other = blender_composed(&run, Some(&registry));
    // The ghosts are there: one pass per plane (the deeper groups folded) looks otherwise.
    let folded = d.join("folded.exr");
    let mut cmd = glassdb();
    cmd.arg("compose")
        .arg("--trans")
        .arg(run.join(frame["trans"].as_str().unwrap()))
        .arg("--refl")
        .arg(run.join(frame["refl"][0].as_str().unwrap()))
        .arg("--mask")
        .arg(run.join(frame["mask"].as_str().unwrap()))
        .arg("--light-parts")
        .arg(run.join(parts))
        .args(["--surfaces", "1", "-o"])
        .arg(&folded);
    ok(&mut cmd);
    let folded = srgb_codes(&folded);
    let ghost = pixels_apart(&want, &folded, 2.0);
    eprintln!("Unit={unit}: {ghost} pixels of blender compose apart from --surfaces 1");
    assert!(ghost >= min_ghost, "only {ghost} pixels show a ghost");

    let mut cmd = glassdb();
    cmd.arg("view").arg(&run);
    let served = spawn_viewer(&mut cmd);
    let choose = format!("window.glassdb.choose({unit}, {other:?}); {READ_CANVAS}");
    let report = layout(
        &served.url,
        &[
            READ_CANVAS,
            &choose,
            "return [window.glassdb.products().A, document.getElementById('status').textContent];",
            "return (await fetch('api/frame/0')).json();",
        ],
        None,
    );
    let results = &report["results"];
    assert_eq!(results[2][0][unit.to_string()], other, "{}", results[2]);
    let status = results[2][1].as_str().unwrap();
    assert!(!status.contains("one surface per plane"), "{status}");
    for (got, want, what) in [
        (canvas_of(&results[0]), &want, "the rendered product"),
        (canvas_of(&results[1]), &want_other, other),
    ] {
        let apart = pixels_apart(&got, want, 1.0);
        assert_eq!(
            apart, 0,
            "page vs glassdb blender compose, {what}: {apart} pixels apart"
        );
        let from_folded = pixels_apart(&got, &folded, 2.0);
        assert!(
            from_folded >= min_ghost,
            "{what}: {from_folded} pixels apart from --surfaces 1"
        );
    }
    results[3].clone()
}

/// Issue 27 with issue 28's light split (the default of `glassdb blender render`): a run of a
/// double unit opened with `glassdb view RUN` shows the inner pane's reflection, relit, as
/// `glassdb blender compose RUN` does, and after a change to another double unit.
#[test]
fn a_relit_double_unit_run_shows_its_ghost_as_blender_compose_does() {
    let frame = relit_ghosts_match_blender_compose(11, CATALOG_UNIT, 40);
    assert_eq!(
        frame["groups"],
        serde_json::json!([{"plane": 0, "group": 1}]),
        "{frame}"
    );
    assert_eq!(frame["parts"].as_array().map(Vec::len), Some(4), "{frame}");
}

/// The same with a triple unit (two ghosts, each pane group's pass relit), then a double unit
/// chosen on the page (the deepest pass unused).
#[test]
fn a_relit_triple_unit_run_shows_both_ghosts_as_blender_compose_does() {
    let frame = relit_ghosts_match_blender_compose(13, GHOST_UNIT, 40);
    assert_eq!(
        frame["groups"],
        serde_json::json!([{"plane": 0, "group": 1}, {"plane": 0, "group": 2}]),
        "{frame}"
    );
}

/// A run folder as `glassdb blender render` writes one, made by `scripts/bench_relight.py`: one
/// 64×48 frame, two windows (glass ids 1 and 5 on planes 0 and 1) and 7 light parts (sun and sky
/// through each window, and sun, sky and interior unglazed): `DIR/relit`.
fn two_window_run(d: &Path) -> PathBuf {
    let mut cmd = Command::new(crate::util::oracle_python());
    cmd.arg(repo_path("scripts/bench_relight.py"))
        .arg(d)
        .args(["64", "48", "7", "1", "5"]);
    ok(&mut cmd);
    d.join("relit")
}

/// The products the relit tests choose for the two windows' ids.
const WINDOW_PRODUCTS: [(u16, &str); 2] = [
    (1, SWAP_PRODUCT),
    (5, "AGC green-tinted float 4.8 mm (IGSDB 185)"),
];

/// Issue 28's relit swap on the page, glass id by glass id: a choice re-weights the chosen id's
/// light parts over the sums of the others (docs/viewer.md, "Relit swap"), which are drawn again
/// when another id is chosen and not for a second choice of the same id. After a product chosen
/// for each window the page gives `glassdb blender compose RUN --registry` with both, within 1
/// code value; set B (untouched) still gives the run's own products. At -3 EV, so that the room
/// is not clipped white.
#[test]
fn products_chosen_for_two_ids_relight_the_frame_as_blender_compose_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = two_window_run(d);
    const EV: f64 = -3.0;
    let start = blender_composed_at(&run, None, EV);
    let mut registry = repo_path("data/registry.json");
    for (id, product) in WINDOW_PRODUCTS {
        registry = swapped_registry(&registry, d, id, product);
    }
    let want = blender_composed_at(&run, Some(&registry), EV);
    // the whole frame changes, not only the windows (a third of it)
    let relit = pixels_apart(&start, &want, 2.0);
    assert!(relit > start.len() * 9 / 10, "only {relit} pixels relit");

    let mut cmd = glassdb();
    cmd.arg("view").arg(&run);
    let served = spawn_viewer(&mut cmd);
    let choose = |(id, product): (u16, &str)| {
        format!("window.glassdb.choose({id}, {product:?}); return window.glassdb.relitStats();")
    };
    let report = layout(
        &format!("{}?ev={EV}", served.url),
        &[
            READ_CANVAS,
            "return window.glassdb.relitStats();",
            &choose(WINDOW_PRODUCTS[0]),
            &choose(WINDOW_PRODUCTS[1]),
            &choose(WINDOW_PRODUCTS[1]),
            READ_CANVAS,
            &format!("window.glassdb.setAB('B'); {READ_CANVAS}"),
        ],
        None,
    );
    let r = &report["results"];
    let stats = |k: usize| (r[k]["active"].clone(), num(&r[k]["fixedDraws"]));
    let (_, loaded) = stats(1);
    assert_eq!(stats(2), (1.into(), loaded), "{report}");
    assert_eq!(stats(3), (5.into(), loaded + 1.0), "{report}");
    assert_eq!(stats(4), (5.into(), loaded + 1.0), "{report}");
    for (k, want, what) in [
        (0, &start, "the run's products"),
        (5, &want, "both windows swapped"),
        (6, &start, "set B"),
    ] {
        let apart = pixels_apart(&canvas_of(&r[k]), want, 1.0);
        assert_eq!(
            apart, 0,
            "page vs blender compose, {what}: {apart} pixels apart"
        );
    }
}

/// A run whose EXR mask has no plane channel (rendered before the masks always stored it) is
/// refused by `glassdb blender compose DIR` and `glassdb view DIR` with a hint to render it again.
#[test]
fn a_run_whose_masks_lack_the_plane_channel_says_to_render_it_again() {
    let dir = tempfile::tempdir().unwrap();
    let run = two_window_run(dir.path());
    let mask = run.join("mask.0001.exr");
    let mut cmd = Command::new(crate::util::oracle_python());
    cmd.arg("-c")
        .arg(
            "import sys, OpenEXR\n\
             f = OpenEXR.File(sys.argv[1])\n\
             ch = {k: c.pixels for k, c in f.channels().items() if k != 'plane'}\n\
             OpenEXR.File(f.header(), ch).write(sys.argv[1])",
        )
        .arg(&mask);
    ok(&mut cmd);
    let names = [
        "mask.0001.exr",
        "stores no plane per pixel",
        "render it again with glassdb blender render",
    ];
    fails_naming(glassdb().args(["blender", "compose"]).arg(&run), &names);
    fails_naming(
        glassdb()
            .arg("view")
            .arg(&run)
            .arg("--export")
            .arg(dir.path().join("export")),
        &names,
    );
}

/// A `.cube` view (a 1D shaper over 0–4, then a 3D table mixing channels), written here.
fn write_cube(path: &Path) {
    let mut text =
        String::from("# test view\nLUT_1D_SIZE 17\nLUT_1D_INPUT_RANGE 0 4\nLUT_3D_SIZE 9\n");
    for i in 0..17 {
        let y = (i as f64 / 16.0).powf(1.0 / 2.2);
        text += &format!("{y:.6} {:.6} {:.6}\n", y * 0.98, y.powf(1.1));
    }
    for b in 0..9 {
        for g in 0..9 {
            for r in 0..9 {
                let [r, g, b] = [r, g, b].map(|v| f64::from(v) / 8.0);
                let out = [0.9 * r + 0.1 * g, g * g.sqrt(), 0.6 * b + 0.4 * r * g];
                text += &format!("{:.6} {:.6} {:.6}\n", out[0], out[1], out[2]);
            }
        }
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn a_cube_view_on_the_page_gives_composes_pixels_through_it() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("look.cube");
    write_cube(&cube);
    let out = dir.path().join("look.png");
    let mut cmd = glassdb();
    cmd.arg("compose");
    atrium_inputs(&mut cmd)
        .args(["--dither", "none", "--view"])
        .arg(&cube)
        .arg("-o")
        .arg(&out);
    ok(&mut cmd);
    let want = png_pixels(&out);
    let standard = compose_png(dir.path(), None, "standard.png");
    assert!(
        psnr(&want, &standard) < 40.0,
        "the view changes the picture"
    );

    let served = serve(&["--view".as_ref(), cube.as_os_str()]);
    assert_page_shows(
        &format!("{}?view=look", served.url),
        &dir.path().join("look.rgba"),
        &want,
        "page through the .cube view vs compose",
    );
}

/// `--catalog`: the candidates are the catalog's products (here the atrium's two validation
/// glasses), built at start as `glassdb registry build` builds them; the exported page with
/// the tinted one on glass 1 gives compose's pixels with that registry and swap.
#[test]
fn candidates_built_from_a_catalog_give_composes_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let catalog = repo_path("fixtures/atrium/catalog.toml");
    let registry = dir.path().join("atrium.json");
    ok(&mut registry_build(
        &catalog,
        &registry,
        &["--space", "srgb,acescg,rec2020,aces2065-1"],
    ));
    let tinted = "thin dielectric n=1.5, green-grey tint (Mitsuba thindielectric)";
    let swapped = swapped_registry(&registry, dir.path(), 1, tinted);
    let want = compose_png(dir.path(), Some(&swapped), "want.png");

    let catalog_arg = catalog.to_str().unwrap();
    let (got, report) = exported_canvas(
        dir.path(),
        &["--catalog", catalog_arg, "--glass", "1:green-grey"],
    );
    assert_eq!(report["products"]["A"]["1"], tinted, "{report}");
    assert_eq!(
        report["products"]["A"].as_object().unwrap().len(),
        2,
        "{report}"
    );
    assert_composes_pixels(&got, &want, "page from the catalog vs compose");
}

/// The driver's `layout` report of `url` (the window `window`, default 1400×1000) after the JS
/// snippets `run`.
fn layout(url: &str, run: &[&str], window: Option<&str>) -> serde_json::Value {
    let mut args: Vec<&std::ffi::OsStr> = vec!["layout".as_ref(), url.as_ref()];
    for js in run {
        args.push("--run".as_ref());
        args.push(js.as_ref());
    }
    if let Some(w) = window {
        args.push("--window".as_ref());
        args.push(w.as_ref());
    }
    let report: serde_json::Value =
        serde_json::from_str(run_oracle("viewer_driver.py", &args).trim()).unwrap();
    assert_eq!(report["errors"], serde_json::json!([]), "{report}");
    assert!(report.get("error").is_none(), "{report}");
    report
}

fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Issue 31: the frame fits the window (it was shown 1:1, a 320×240 frame in a 1400-px window)
/// and zooms.
#[test]
fn the_frame_fits_the_window_and_zooms() {
    let served = serve(&[]);
    for window in [None, Some("800x600")] {
        let r = layout(&served.url, &[], window);
        let (stage, canvas) = (&r["stage"], &r["canvas"]);
        let (sw, sh) = (num(&stage["width"]), num(&stage["height"]));
        let (cw, ch) = (num(&canvas["width"]), num(&canvas["height"]));
        assert!(
            cw >= sw - 2.0 || ch >= sh - 2.0,
            "{window:?}: the frame does not fill the stage: {r}"
        );
        assert!(cw <= sw + 0.5 && ch <= sh + 0.5, "{window:?}: {r}");
        assert!((cw / ch - 320.0 / 240.0).abs() < 0.01, "{window:?}: {r}");
        assert_eq!(r["zoom"]["fit"], true, "{r}");
    }
    let big = layout(&served.url, &[], None);
    assert!(num(&big["canvas"]["width"]) > 640.0, "{big}");
    // Zoomed by the hook and by the URL: screen pixels per frame pixel.
    let r = layout(&served.url, &["window.glassdb.setZoom(2)"], None);
    assert_eq!(num(&r["canvas"]["width"]), 640.0, "{r}");
    assert_eq!(r["zoom"]["fit"], false, "{r}");
    let r = layout(&format!("{}?zoom=1", served.url), &[], None);
    assert_eq!(
        (num(&r["canvas"]["width"]), num(&r["canvas"]["height"])),
        (320.0, 240.0),
        "{r}"
    );
}

/// Issue 31: product names are readable, wrapped in their list and shown whole as tooltips
/// (they were cut at the list's edge), in a wide and a narrow window.
#[test]
fn product_names_are_readable_not_cut() {
    let served = serve(&[]);
    let products = glassdb_registry_names();
    for window in [None, Some("1000x700")] {
        let r = layout(&served.url, &[], window);
        let names = r["names"].as_array().unwrap();
        assert!(names.len() >= products.len() + 2, "{r}");
        for n in names {
            assert_eq!(n["cut"], false, "{window:?}: cut: {n}");
            assert_eq!(n["tooltip"], true, "{window:?}: no tooltip: {n}");
        }
    }
}

/// The product names of the bundled registry's default table.
fn glassdb_registry_names() -> Vec<String> {
    let reg: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(repo_path("data/registry.json")).unwrap())
            .unwrap();
    reg["tables"][0]["glasses"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g["name"].as_str().unwrap().to_string())
        .collect()
}

/// Issue 31: the A/B split line is visible on screen where the page switches from A to B, and
/// follows the split; it is an element over the canvas, so the canvas's pixels (compared with
/// compose's in the swap test) are untouched.
#[test]
fn the_split_line_is_visible_where_a_turns_to_b() {
    let served = serve(&[]);
    let r = layout(
        &format!("{}?glassB=5:Stopray&ab=split&split=0.3", served.url),
        &[],
        None,
    );
    let canvas = &r["canvas"];
    let line = &r["split_line"];
    assert_eq!(
        line["element"], "split-line",
        "nothing drawn at the split: {r}"
    );
    assert_eq!(line["visible"], true, "{r}");
    let want_x = num(&canvas["left"]) + 0.3 * num(&canvas["width"]);
    let b = &line["box"];
    let centre = num(&b["left"]) + num(&b["width"]) / 2.0;
    assert!(
        (centre - want_x).abs() <= 1.5,
        "line at {centre}, split at {want_x}: {r}"
    );
    assert!(num(&b["height"]) >= num(&canvas["height"]) - 0.5, "{r}");
    // It follows the split, and is gone when one set is shown.
    let r = layout(
        &served.url,
        &["window.glassdb.setAB('split', 0.7)"],
        Some("1000x700"),
    );
    let want_x = num(&r["canvas"]["left"]) + 0.7 * num(&r["canvas"]["width"]);
    assert_eq!(r["split_line"]["element"], "split-line", "{r}");
    assert!((num(&r["split_line"]["x"]) - want_x).abs() < 0.01);
    let r = layout(&format!("{}?ab=B", served.url), &[], None);
    assert!(r["split_line"].is_null(), "{r}");
    assert_eq!(num(&r["split_box"]["width"]), 0.0, "hidden: {r}");
}

/// The size a `wrote … (N files, X MB)` line says, in MB.
fn said_megabytes(out: &str) -> f64 {
    let mb = out
        .split_once(" files, ")
        .and_then(|(_, rest)| rest.split_once(" MB)"))
        .unwrap_or_else(|| panic!("no size in {out:?}"))
        .0;
    mb.parse().unwrap()
}

/// The bytes of every file in `dir`.
fn folder_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().metadata().unwrap().len())
        .sum()
}

/// Issue 31: the export stores its data compactly (it was 9.7 MB for the atrium: `f32` tables
/// and mask, base64) and says its size. Its pixels are checked in the swap test (from
/// `file://`, against compose).
#[test]
fn the_export_is_compact_and_says_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let export = dir.path().join("export");
    let mut cmd = glassdb();
    cmd.arg("view");
    atrium_inputs(&mut cmd).arg("--export").arg(&export);
    let out = ok(&mut cmd);
    let bytes = folder_bytes(&export);
    let said = said_megabytes(&out);
    assert!(
        (said - bytes as f64 / 1e6).abs() < 0.006,
        "said {said} MB, wrote {bytes} bytes: {out}"
    );
    assert!(out.contains("(6 files,"), "{out}");
    assert!(bytes < 4_000_000, "{bytes} bytes");
    let frame = std::fs::metadata(export.join("frame-0000.js"))
        .unwrap()
        .len();
    assert!(frame < 1_000_000, "frame-0000.js: {frame} bytes");
}

/// Issue 31: `glassdb view DIR` opens a `glassdb blender render` folder: its frames, passes,
/// masks and sides from its run record; the second frame on the page is compose's of the same
/// files and sides.
#[test]
fn a_blender_run_folder_opens_directly() {
    let run = &crate::blender::rendered().runs[0];
    let record: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("glassdb-blender.json")).unwrap())
            .unwrap();
    let frames = record["frames"].as_array().unwrap();
    assert!(frames.len() >= 2, "{record}");
    let f = &frames[1];
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frame2.png");
    let mut cmd = glassdb();
    cmd.arg("compose")
        .arg("--trans")
        .arg(run.join(f["trans"].as_str().unwrap()))
        .arg("--mask")
        .arg(run.join(f["mask"].as_str().unwrap()));
    for (k, refl) in f["refl"].as_array().unwrap().iter().enumerate() {
        cmd.arg("--refl").arg(run.join(refl.as_str().unwrap()));
        cmd.arg("--side")
            .arg(format!("{k}={}", f["sides"][k].as_str().unwrap()));
    }
    // a run split by the light's path is composited with its light parts, as the viewer does
    if let Some(parts) = f["light_parts"].as_str() {
        cmd.arg("--light-parts").arg(run.join(parts));
    }
    ok(cmd.args(["--dither", "none", "-o"]).arg(&out));
    let want = png_pixels(&out);

    let mut cmd = glassdb();
    cmd.arg("view").arg(run);
    let served = spawn_viewer(&mut cmd);
    assert_page_shows(
        &format!("{}?frame=1", served.url),
        &dir.path().join("f2.rgba"),
        &want,
        "frame 2 of the run vs compose",
    );
    let (code, scene) = get_as(&served.url, "/api/scene", host_of(&served.url));
    assert_eq!(code, 200);
    let scene: serde_json::Value = serde_json::from_str(&scene).unwrap();
    let labels: Vec<String> = frames.iter().map(|f| f["frame"].to_string()).collect();
    assert_eq!(scene["frames"], serde_json::json!(labels), "{scene}");

    // A folder without a run record, and passes given as well: refused, naming them.
    fails_naming(
        glassdb().arg("view").arg(dir.path()),
        &[
            "glassdb-blender.json",
            "not a `glassdb blender render` output folder",
        ],
    );
    fails_naming(
        glassdb()
            .arg("view")
            .arg(run)
            .arg("--trans")
            .arg(run.join("trans.0001.exr")),
        &["cannot be used with"],
    );
}

/// The catalog unit the page's builder makes in the tests: Solarban R67 (coating on #2), 12.7
/// mm argon, clear 6 mm; the bundled catalog has it as id 12.
const UNIT_PANES: &str = "6|12.7:argon|2";
/// `viewer_driver.py unit`: builds the unit `panes` in glass 5's place through the page's
/// controls (its canvas into `out` when given); the driver's report.
fn build_unit_on_page(url: &str, panes: &str, out: Option<&Path>) -> serde_json::Value {
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "unit".as_ref(),
        url.as_ref(),
        "--glass".as_ref(),
        "5".as_ref(),
        "--panes".as_ref(),
        panes.as_ref(),
    ];
    if let Some(out) = out {
        args.extend(["--out".as_ref(), out.as_os_str()]);
    }
    let said = run_oracle("viewer_driver.py", &args);
    serde_json::from_str(said.trim()).unwrap()
}

const CATALOG_UNIT: &str = "Solarban R67 #2 | 12.7 argon | clear 6";

/// Issue 26: a unit built on the page through its controls (outer pane, gap width and gas,
/// inner pane) reaches the screen as compose draws that unit (the bundled catalog's id 12,
/// put in glass 5's place in a registry written by the test); the picker shows a unit's
/// build-up and Tv/Rv; a gap width left empty is a clear message on the page.
#[test]
fn a_unit_built_on_the_page_gives_composes_pixels_of_that_unit() {
    let dir = tempfile::tempdir().unwrap();
    let want = compose_png_with_swap(dir.path(), CATALOG_UNIT, "unit.png");
    let served = serve(&[]);
    let out = dir.path().join("unit.rgba");
    let report = build_unit_on_page(&served.url, UNIT_PANES, Some(&out));
    assert_eq!(report["errors"], serde_json::json!([]), "{report}");
    assert_eq!(report["status_class"], "", "{report}");
    let name = report["products"]["A"]["5"].as_str().unwrap();
    assert!(
        name.contains("Solarban R67") && name.contains("12.7 mm argon"),
        "{report}"
    );
    assert_eq!(report["drawn"], 1, "{report}");
    let got = rgba_pixels(&out);
    assert_composes_pixels(&got, &want, "unit built on the page vs compose");

    // The width box left empty: the server's reason on the page, nothing drawn.
    let report = build_unit_on_page(&served.url, "6|nan:argon|2", None);
    assert_eq!(report["status_class"], "error", "{report}");
    let status = report["status"].as_str().unwrap();
    assert!(
        status.contains("element 2") && status.contains("finite number"),
        "{report}"
    );
    assert_eq!(report["drawn"], 0, "{report}");

    // Choices the controls cannot make, through the page's hook: each said, none drawn.
    let r = layout(
        &served.url,
        &[
            "return window.glassdb.buildUnit([{glass: 2}, {gap_mm: 12, gas: 'argon'}, {gap_mm: 12, gas: 'argon'}, {glass: 2}])",
            "return window.glassdb.buildUnit([{glass: 99}, {gap_mm: 12}, {glass: 2}])",
            "return window.glassdb.buildUnit([{glass: 2}, {gap_mm: -4}, {glass: 2}])",
        ],
        None,
    );
    let thrown: Vec<&str> = r["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["thrown"].as_str().unwrap_or_else(|| panic!("built: {r}")))
        .collect();
    assert!(thrown[0].contains("two gaps in a row"), "{thrown:?}");
    assert!(thrown[1].contains("no glass with id 99"), "{thrown:?}");
    assert!(thrown[2].contains("-4"), "{thrown:?}");
    let said = r["unit_status"].as_str().unwrap();
    assert!(
        said.starts_with("cannot build the unit") && said.contains("-4"),
        "{said}"
    );
    // The picker shows the catalog units' build-up: panes, gaps, coated surfaces, Tv/Rv.
    let unit = r["products_text"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|t| t.as_str())
        .find(|t| t.starts_with(CATALOG_UNIT))
        .unwrap_or_else(|| panic!("{r}"))
        .to_string();
    for part in ["coating on #2", "12.7 mm argon", "Tv ", "Rv out ", "Rv in "] {
        assert!(unit.contains(part), "{part:?} not in {unit:?}");
    }
}

/// A POST as the viewer's page sends it, its status and body.
fn post_reply(url: &str, path: &str, body: &[u8]) -> (u16, String) {
    let origin = format!("http://{}", host_of(url));
    let token = page_token(url);
    post_with_reply(
        url,
        path,
        body,
        &[("Origin", &origin), ("X-Glassdb-Session", &token)],
    )
}

/// A POST of `body` with the `Host` of `url` and the extra `headers`: status and body.
fn post_with_reply(url: &str, path: &str, body: &[u8], headers: &[(&str, &str)]) -> (u16, String) {
    let mut req = format!(
        "POST {path} HTTP/1.1\r\nHost: {}\r\nConnection: close\r\nContent-Length: {}\r\n",
        host_of(url),
        body.len()
    );
    for (name, value) in headers {
        req += &format!("{name}: {value}\r\n");
    }
    let mut req = format!("{req}\r\n").into_bytes();
    req.extend_from_slice(body);
    exchange(url, &req)
}

/// Issue 26 at the HTTP level: `POST /api/unit` builds a unit, answers bad choices with 400 or
/// 422 naming what is wrong, and, like the export, is refused from another site's page or
/// without the page's token; an export carries the units the page built.
#[test]
fn unit_requests_are_checked_and_only_the_page_may_send_them() {
    let dir = tempfile::tempdir().unwrap();
    let (served, export) = serve_exporting_into(dir.path());
    let u = &served.url;
    let good = br#"{"elements": [{"glass": 6}, {"gap_mm": 12.7, "gas": "argon"}, {"glass": 2}]}"#;
    let (code, body) = post_reply(u, "/api/unit", good);
    assert_eq!(code, 200, "{body:.300}");
    let built: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(built["format"], "glassdb-viewer-page/4");
    assert_eq!(
        built["product"]["unit"]["elements"][1]["gas"], "argon",
        "{body:.600}"
    );
    let name = built["product"]["name"].as_str().unwrap().to_string();
    for (request, code, says) in [
        (
            &br#"{"elements": [{"glass": 2}, {"gap_mm": 9}, {"gap_mm": 9}, {"glass": 2}]}"#[..],
            422,
            "two gaps in a row",
        ),
        (
            br#"{"elements": [{"glass": 77}, {"gap_mm": 9}, {"glass": 2}]}"#,
            422,
            "no glass with id 77",
        ),
        (
            br#"{"elements": [{"glass": 2}, {"gap_mm": null}, {"glass": 2}]}"#,
            400,
            "finite number",
        ),
        (
            br#"{"elements": [{"glass": 2}, {"gap_mm": 9, "gas": "neon"}, {"glass": 2}]}"#,
            400,
            "unknown gas",
        ),
        (b"not json", 400, "must be JSON"),
        (br#"{"elements": 5}"#, 400, "\\\"elements\\\""),
    ] {
        let (got, body) = post_reply(u, "/api/unit", request);
        assert_eq!(got, code, "{}: {body}", String::from_utf8_lossy(request));
        assert!(body.contains(says), "{says:?} not in {body}");
        assert!(body.len() < 2000, "{body}");
    }
    // Another site's page, a request without the page's token or with another: refused.
    let origin = format!("http://{}", host_of(u));
    let token = page_token(u);
    let wrong = "0".repeat(token.len());
    for headers in [
        vec![
            ("Origin", "http://rebound.example"),
            ("X-Glassdb-Session", token.as_str()),
        ],
        vec![("Origin", origin.as_str())],
        vec![
            ("Origin", origin.as_str()),
            ("X-Glassdb-Session", wrong.as_str()),
        ],
        vec![("X-Glassdb-Session", token.as_str())],
    ] {
        let (code, body) = post_with_reply(u, "/api/unit", good, &headers);
        assert_eq!(code, 403, "{headers:?}: {body}");
    }
    assert_eq!(get(u, "/api/unit"), 404);
    // An export with the unit on glass 5: the page's data holds it and starts with it.
    let request = serde_json::json!({
        "glass": format!("5:{name}"),
        "ev": 0,
        "units": [serde_json::from_slice::<serde_json::Value>(good).unwrap()],
    });
    let (code, body) = post_reply(u, "/api/export", request.to_string().as_bytes());
    assert_eq!(code, 200, "{body}");
    let reply: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(
        reply["bytes"].as_u64(),
        Some(folder_bytes(&export)),
        "{reply}"
    );
    assert_eq!(reply["files"], 6, "{reply}");
    let data = std::fs::read_to_string(export.join("data.js")).unwrap();
    assert!(
        data.contains(&format!("5:{name}")),
        "the export starts elsewhere"
    );
    let (_, report) = canvas(
        &format!("file://{}", export.join("index.html").display()),
        &[],
        &dir.path().join("export.rgba"),
    );
    assert_eq!(report["products"]["A"]["5"], name.as_str(), "{report}");
}
