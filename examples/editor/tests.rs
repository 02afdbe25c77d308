//! Server tests: every endpoint through [`Api::handle`] (no sockets), bad payloads
//! (malformed JSON, unknown ops and fields, unknown ids, NaN-like and huge numbers,
//! over-long texts, bodies over the limit), and real sockets: concurrent requests, a
//! body over the limit, an undo after a burst of edits.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use std::time::Duration;

use serde_json::{Value, json};

use crate::api::{Api, MAX_BODY_BYTES, Reply, Request};
use crate::session::Session;

/// A small Citygen city (fast in a debug build). The primary network and the Citygen
/// scale these tests were written against, not the `citygen` preset's tuning to the
/// US/Canada band (its grid-leaning highways and 26 m unit move nodes and cells that the
/// edits below aim at).
fn small_api() -> Api {
    let mut config = polis::CityConfig::preset("citygen").expect("preset");
    config.size_m = 1200.0;
    config.maps.pattern_weights.clear();
    config.citygen.unit_m = 9.0;
    config.citygen.road_width_factor = 1.5;
    config.citygen.preset_params.clear();
    Api::new(Session::new(config, false).expect("session"))
}

fn call(api: &Api, method: &str, url: &str, body: &str) -> Reply {
    api.handle(&Request {
        method,
        url,
        body: body.as_bytes(),
    })
}

fn json_of(r: &Reply) -> Value {
    serde_json::from_slice(&r.body).expect("JSON reply")
}

fn error_of(r: &Reply) -> String {
    json_of(r)["error"]
        .as_str()
        .expect("error message")
        .to_string()
}

/// A free point far from every primary road and node, inside the map.
fn free_point(scene: &Value) -> [f64; 2] {
    let roads = scene["roads"].as_array().expect("roads");
    let b = scene["bounds"].as_array().expect("bounds");
    let (x0, x1) = (b[0].as_f64().expect("x0"), b[2].as_f64().expect("x1"));
    let mut best = ([0.0, 0.0], -1.0);
    for i in 1..20 {
        for j in 1..20 {
            let p = [
                x0 + (x1 - x0) * f64::from(i) / 20.0,
                x0 + (x1 - x0) * f64::from(j) / 20.0,
            ];
            let d = roads
                .iter()
                .flat_map(|r| {
                    let pts: Vec<f64> = r["pts"]
                        .as_array()
                        .expect("pts")
                        .iter()
                        .map(|v| v.as_f64().expect("coordinate"))
                        .collect();
                    pts.chunks(2)
                        .map(|q| ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2)).sqrt())
                        .collect::<Vec<_>>()
                })
                .fold(f64::INFINITY, f64::min);
            if d > best.1 {
                best = (p, d);
            }
        }
    }
    best.0
}

#[test]
fn the_page_and_every_endpoint_answer() {
    let api = small_api();
    for (path, kind) in [
        ("/", "text/html"),
        ("/index.html", "text/html"),
        ("/app.js", "text/javascript"),
        ("/plan.js", "text/javascript"),
        ("/view3d.js", "text/javascript"),
        ("/style.css", "text/css"),
    ] {
        let r = call(&api, "GET", path, "");
        assert_eq!(r.status, 200, "{path}");
        assert!(
            r.content_type.starts_with(kind),
            "{path}: {}",
            r.content_type
        );
        assert!(!r.body.is_empty());
    }
    // The scene: nodes, roads, cells with outlines, block groups with buildings.
    let r = call(&api, "GET", "/api/scene?x=1", "");
    assert_eq!(r.status, 200);
    let scene = json_of(&r);
    let nodes = scene["nodes"].as_array().expect("nodes");
    let cells = scene["cells"].as_array().expect("cells");
    let blocks = scene["blocks"].as_array().expect("blocks");
    assert!(!nodes.is_empty() && !cells.is_empty() && !blocks.is_empty());
    let buildings: usize = blocks
        .iter()
        .map(|b| b["buildings"].as_array().map_or(0, Vec::len))
        .sum();
    assert!(buildings > 0);
    for c in cells {
        assert!(c["ring"].as_array().expect("ring").len() >= 6);
    }
    // The cell inspector names Kelly's parameters, each with its deviance.
    let cell = cells[0]["id"].as_str().expect("cell id");
    let r = call(&api, "GET", &format!("/api/cell/{cell}"), "");
    assert_eq!(r.status, 200);
    let info = json_of(&r);
    let names: Vec<&str> = info["params"]
        .as_array()
        .expect("params")
        .iter()
        .map(|p| p["name"].as_str().expect("name"))
        .collect();
    for want in [
        "segment_size",
        "degree",
        "snap_size",
        "road_width",
        "connectivity",
        "lot_size",
        "building_height",
    ] {
        assert!(names.contains(&want), "{want} in {names:?}");
    }
    // Preview, apply, undo, redo, log.
    let node = nodes[0]["id"].as_u64().expect("node id");
    let (x, y) = (
        nodes[0]["x"].as_f64().expect("x"),
        nodes[0]["y"].as_f64().expect("y"),
    );
    let mv = json!({"op": "move_node", "node": node, "to": [x + 3.0, y + 2.0]}).to_string();
    let r = call(&api, "POST", "/api/preview", &mv);
    assert_eq!(r.status, 200);
    let p = json_of(&r);
    assert!(p["ok"].is_boolean());
    let r = call(&api, "POST", "/api/apply", &mv);
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    assert!(r.timing.is_some_and(|t| t.total_ms >= t.edit_ms));
    let d = json_of(&r);
    let moved = d["nodes"].as_array().expect("nodes");
    assert!(
        moved.iter().any(|n| n["id"] == node),
        "the moved node is in the delta"
    );
    // Incremental: far fewer cells than the scene has.
    assert!(d["cells"].as_array().expect("cells").len() < cells.len().max(2));
    assert_eq!(d["revision"], scene["revision"].as_u64().expect("rev") + 1);
    let r = call(&api, "POST", "/api/undo", "");
    assert_eq!(r.status, 200);
    let back = json_of(&r);
    let n = back["nodes"]
        .as_array()
        .expect("nodes")
        .iter()
        .find(|n| n["id"] == node)
        .expect("the node comes back");
    assert_eq!((n["x"].as_f64(), n["y"].as_f64()), (Some(x), Some(y)));
    assert_eq!(call(&api, "POST", "/api/redo", "").status, 200);
    assert_eq!(call(&api, "POST", "/api/undo", "").status, 200);
    let r = call(&api, "POST", "/api/undo", "");
    assert_eq!(r.status, 409, "nothing to undo: {}", error_of(&r));
    let log = json_of(&call(&api, "GET", "/api/log", ""));
    assert!(log.as_array().expect("log").len() >= 4);
}

#[test]
fn chain_tool_closes_a_loop_into_a_new_cell_and_cells_take_presets() {
    let api = small_api();
    let scene = json_of(&call(&api, "GET", "/api/scene", ""));
    let cells_before = scene["cells"].as_array().expect("cells").len();
    let c = free_point(&scene);
    let r = 60.0;
    let pts: Vec<[f64; 2]> = (0..3)
        .map(|k| {
            let a = std::f64::consts::FRAC_PI_2 + f64::from(k) * 2.0 * std::f64::consts::PI / 3.0;
            [c[0] + r * a.cos(), c[1] + r * a.sin()]
        })
        .collect();
    let add = call(
        &api,
        "POST",
        "/api/apply",
        &json!({"op": "add_node", "at": pts[0]}).to_string(),
    );
    assert_eq!(add.status, 200, "{}", String::from_utf8_lossy(&add.body));
    let first = json_of(&add)["end_node"].as_u64().expect("the new node");
    let mut from = first;
    for p in [pts[1], pts[2], pts[0]] {
        let e = json!({"op": "chain", "from": from, "to": p}).to_string();
        let pv = json_of(&call(&api, "POST", "/api/preview", &e));
        assert_eq!(pv["ok"], true, "{pv}");
        assert_eq!(pv["proposed"].as_array().expect("red").len(), 1);
        assert!(!pv["roads"].as_array().expect("green").is_empty());
        let r = call(&api, "POST", "/api/apply", &e);
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
        from = json_of(&r)["end_node"].as_u64().expect("chain continues");
    }
    assert_eq!(from, first, "the closing click snapped to the first node");
    let scene = json_of(&call(&api, "GET", "/api/scene", ""));
    let cells = scene["cells"].as_array().expect("cells");
    assert!(cells.len() > cells_before, "the loop made a cell");
    // The triangle's cell: the smallest cell whose ring has a vertex at each corner.
    let tri = cells
        .iter()
        .find(|cell| {
            let ring: Vec<f64> = cell["ring"]
                .as_array()
                .expect("ring")
                .iter()
                .map(|v| v.as_f64().expect("coordinate"))
                .collect();
            pts.iter().all(|p| {
                ring.chunks(2)
                    .any(|q| (q[0] - p[0]).abs() < 1.0 && (q[1] - p[1]).abs() < 1.0)
            })
        })
        .expect("a cell bounded by the loop");
    let id = tri["id"].as_str().expect("id");
    let r = call(
        &api,
        "POST",
        "/api/apply",
        &json!({"op": "set_cell_pattern", "cell": id, "pattern": "suburbia"}).to_string(),
    );
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let d = json_of(&r);
    let changed = d["cells"].as_array().expect("cells");
    assert!(
        changed
            .iter()
            .any(|c| c["id"] == id && c["pattern"] == "suburbia")
    );
    assert_eq!(
        json_of(&call(&api, "GET", &format!("/api/cell/{id}"), ""))["pattern"],
        "suburbia"
    );
    // A parameter with its deviance.
    let e = json!({"op": "set_cell_param", "cell": id,
                   "param": {"building_height": {"value": 9.0, "deviance": 0.2}}});
    let r = call(&api, "POST", "/api/apply", &e.to_string());
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let info = json_of(&call(&api, "GET", &format!("/api/cell/{id}"), ""));
    let h = info["params"]
        .as_array()
        .expect("params")
        .iter()
        .find(|p| p["name"] == "building_height")
        .expect("building height")
        .clone();
    assert_eq!(
        (h["value"].as_f64(), h["deviance"].as_f64()),
        (Some(9.0), Some(0.2))
    );
    // The seed in effect (text), then the cell's own after a seed edit.
    assert!(
        info["seed"]
            .as_str()
            .is_some_and(|s| s.parse::<u64>().is_ok())
    );
    assert!(info["own_seed"].is_null());
    let e = json!({"op": "set_cell_seed", "cell": id, "seed": 42});
    let r = call(&api, "POST", "/api/apply", &e.to_string());
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let info = json_of(&call(&api, "GET", &format!("/api/cell/{id}"), ""));
    assert_eq!(info["own_seed"], "42");
    assert_eq!(info["traits_apply"], true);
}

#[test]
fn road_and_node_tools_edit_the_primary_network() {
    let api = small_api();
    let scene = json_of(&call(&api, "GET", "/api/scene", ""));
    let roads = scene["roads"].as_array().expect("roads").len();
    let nodes = scene["nodes"].as_array().expect("nodes").len();
    let c = free_point(&scene);
    let apply = |e: Value| {
        let r = call(&api, "POST", "/api/apply", &e.to_string());
        assert_eq!(r.status, 200, "{e}: {}", String::from_utf8_lossy(&r.body));
        json_of(&r)
    };
    // Two free nodes, then Add Road between them (the road tool).
    let a = apply(json!({"op": "add_node", "at": [c[0] - 50.0, c[1]]}))["end_node"].clone();
    let b = apply(json!({"op": "add_node", "at": [c[0] + 50.0, c[1]]}))["end_node"].clone();
    let d = apply(json!({"op": "add_road", "from": {"node": a}, "to": {"node": b}}));
    let road = d["roads"][0].clone();
    assert_eq!(
        (road["a"].clone(), road["b"].clone()),
        (a.clone(), b.clone())
    );
    // The road inspector: a narrower road, re-plotted with the straight strategy.
    let mut spec = road["spec"].clone();
    spec["width_m"] = json!(7.5);
    spec["params"]["strategy"] = json!("Straight");
    let d = apply(json!({"op": "set_road", "road": road["id"], "spec": spec}));
    assert_eq!(d["roads"][0]["w"], json!(7.5));
    assert_eq!(d["roads"][0]["spec"]["params"]["strategy"], "Straight");
    // A label, then Delete Road and Delete Node.
    let d = apply(json!({"op": "set_node_label", "node": a, "label": "north gate"}));
    assert_eq!(d["nodes"][0]["label"], "north gate");
    let d = apply(json!({"op": "delete_road", "road": road["id"]}));
    assert_eq!(d["roads_removed"][0], road["id"]);
    apply(json!({"op": "delete_node", "node": a}));
    apply(json!({"op": "delete_node", "node": b}));
    let after = json_of(&call(&api, "GET", "/api/scene", ""));
    assert_eq!(after["roads"].as_array().expect("roads").len(), roads);
    assert_eq!(after["nodes"].as_array().expect("nodes").len(), nodes);
}

#[test]
fn bad_requests_get_4xx_with_a_message_and_change_nothing() {
    let api = small_api();
    let scene = call(&api, "GET", "/api/scene", "").body;
    let node = json_of(&call(&api, "GET", "/api/scene", ""))["nodes"][0]["id"]
        .as_u64()
        .expect("node");
    let bad: Vec<(&str, &str, String, u16)> = vec![
        ("POST", "/api/apply", String::new(), 400),
        ("POST", "/api/apply", "{".into(), 400),
        ("POST", "/api/apply", "[1, 2]".into(), 400),
        ("POST", "/api/apply", "\"move_node\"".into(), 400),
        ("POST", "/api/apply", r#"{"node": 1}"#.into(), 400),
        ("POST", "/api/apply", r#"{"op": "explode"}"#.into(), 400),
        (
            "POST",
            "/api/apply",
            format!(r#"{{"op": "move_node", "node": {node}, "to": [1, 2], "extra": 1}}"#),
            400,
        ),
        (
            "POST",
            "/api/apply",
            format!(r#"{{"op": "move_node", "node": {node}, "to": [NaN, 2]}}"#),
            400,
        ),
        (
            "POST",
            "/api/apply",
            format!(r#"{{"op": "move_node", "node": {node}, "to": [null, 2]}}"#),
            400,
        ),
        (
            "POST",
            "/api/apply",
            format!(r#"{{"op": "move_node", "node": {node}, "to": [1e999, 2]}}"#),
            400,
        ),
        (
            "POST",
            "/api/apply",
            format!(r#"{{"op": "move_node", "node": {node}, "to": [1e300, 2]}}"#),
            400,
        ),
        (
            "POST",
            "/api/apply",
            format!(r#"{{"op": "move_node", "node": {node}, "to": [1e7, 2]}}"#),
            422,
        ),
        (
            "POST",
            "/api/apply",
            format!(r#"{{"op": "move_node", "node": {node}, "to": ["1", 2]}}"#),
            400,
        ),
        (
            "POST",
            "/api/apply",
            r#"{"op": "move_node", "node": -1, "to": [1, 2]}"#.to_string(),
            400,
        ),
        (
            "POST",
            "/api/apply",
            r#"{"op": "move_node", "node": 987654321, "to": [1, 2]}"#.into(),
            404,
        ),
        (
            "POST",
            "/api/apply",
            r#"{"op": "delete_road", "road": 987654321}"#.into(),
            404,
        ),
        (
            "POST",
            "/api/apply",
            r#"{"op": "set_cell_pattern", "cell": 5, "pattern": "suburbia"}"#.into(),
            404,
        ),
        (
            "POST",
            "/api/apply",
            r#"{"op": "set_cell_pattern", "cell": "5", "pattern": "suburbia"}"#.into(),
            404,
        ),
        (
            "POST",
            "/api/apply",
            r#"{"op": "set_cell_pattern", "cell": "5x", "pattern": "suburbia"}"#.into(),
            400,
        ),
        (
            "POST",
            "/api/apply",
            r#"{"op": "set_cell_pattern", "cell": 5, "pattern": "atlantis"}"#.into(),
            400,
        ),
        (
            "POST",
            "/api/apply",
            format!(
                r#"{{"op": "set_node_label", "node": {node}, "label": "{}"}}"#,
                "x".repeat(5000)
            ),
            400,
        ),
        ("POST", "/api/preview", "{".into(), 400),
        ("POST", "/api/redo", String::new(), 409),
        ("POST", "/api/undo", String::new(), 409),
        ("GET", "/api/cell/abc", String::new(), 400),
        ("GET", "/api/cell/123", String::new(), 404),
        ("GET", "/api/export/pdf", String::new(), 404),
        ("GET", "/nope", String::new(), 404),
        ("GET", "/../../etc/passwd", String::new(), 404),
        ("DELETE", "/api/scene", String::new(), 405),
        ("GET", "/api/apply", String::new(), 405),
        ("POST", "/", String::new(), 405),
    ];
    for (method, url, body, status) in bad {
        let r = call(&api, method, url, &body);
        let short: String = body.chars().take(80).collect();
        assert_eq!(
            r.status,
            status,
            "{method} {url} {short}: {}",
            String::from_utf8_lossy(&r.body)
        );
        assert!(!error_of(&r).is_empty());
    }
    // Nothing changed: the scene is the same bytes (its log aside: refusals are logged).
    let after = call(&api, "GET", "/api/scene", "").body;
    let strip = |b: &[u8]| {
        let mut v: Value = serde_json::from_slice(b).expect("scene");
        v["log"] = Value::Null;
        v
    };
    assert_eq!(strip(&scene), strip(&after));
}

#[test]
fn exports_are_files_in_their_formats() {
    let api = small_api();
    for (f, kind, magic) in [
        ("glb", "model/gltf-binary", &b"glTF"[..]),
        ("obj", "text/plain", &b"#"[..]),
        ("mtl", "text/plain", &b""[..]),
        ("svg", "image/svg+xml", &b"<"[..]),
        ("geojson", "application/geo+json", &b"{"[..]),
        ("stats", "application/json", &b"{"[..]),
    ] {
        let r = call(&api, "GET", &format!("/api/export/{f}"), "");
        assert_eq!(r.status, 200, "{f}: {}", String::from_utf8_lossy(&r.body));
        assert!(r.content_type.starts_with(kind), "{f}");
        assert!(r.download.is_some(), "{f}");
        assert!(
            r.body.len() > 50 && r.body.starts_with(magic),
            "{f}: {} bytes",
            r.body.len()
        );
    }
}

// ---- real sockets ----

fn http(addr: SocketAddr, method: &str, path: &str, body: &[u8]) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect(addr).expect("connect");
    s.set_read_timeout(Some(Duration::from_secs(120)))
        .expect("timeout");
    let head = format!(
        "{method} {path} HTTP/1.1\r\nHost: test\r\nContent-Type: application/json\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    );
    s.write_all(head.as_bytes()).expect("write head");
    // A refused body may be cut off by the server: ignore a failed write.
    let _ = s.write_all(body);
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let text = String::from_utf8_lossy(&out);
    let status = text
        .split_whitespace()
        .nth(1)
        .and_then(|t| t.parse().ok())
        .expect("a status line");
    let at = out
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .map_or(out.len(), |i| i + 4);
    (status, out[at..].to_vec())
}

#[test]
fn sockets_serve_concurrent_requests_and_refuse_huge_bodies() {
    let api = Arc::new(small_api());
    let running =
        crate::http::serve(Arc::clone(&api), "127.0.0.1:0".parse().expect("addr")).expect("bind");
    let addr = running.addr;
    assert!(addr.ip().is_loopback());
    let (status, body) = http(addr, "GET", "/api/scene", b"");
    assert_eq!(status, 200);
    let scene: Value = serde_json::from_slice(&body).expect("scene");
    let node = scene["nodes"][0].clone();
    let id = node["id"].as_u64().expect("id");
    let (x, y) = (
        node["x"].as_f64().expect("x"),
        node["y"].as_f64().expect("y"),
    );
    // Eight clients at once: reads, previews and edits interleave; every edit lands.
    let threads: Vec<_> = (0..8)
        .map(|k| {
            std::thread::spawn(move || {
                let mut statuses = Vec::new();
                for i in 0..3 {
                    let dx = f64::from(k * 3 + i) * 0.25;
                    let e = json!({"op": "move_node", "node": id, "to": [x + dx, y]}).to_string();
                    let (path, body) = match (k + i) % 3 {
                        0 => ("/api/apply", e.into_bytes()),
                        1 => ("/api/preview", e.into_bytes()),
                        _ => ("/app.js", Vec::new()),
                    };
                    let method = if body.is_empty() { "GET" } else { "POST" };
                    statuses.push(http(addr, method, path, &body).0);
                }
                statuses
            })
        })
        .collect();
    let mut applied = 0;
    for t in threads {
        for s in t.join().expect("client thread") {
            assert!(s == 200 || s == 422, "status {s}");
            applied += usize::from(s == 200);
        }
    }
    assert!(applied > 0);
    // A body over the limit is refused before it is read whole.
    let huge = vec![b' '; MAX_BODY_BYTES + 10];
    let (status, body) = http(addr, "POST", "/api/apply", &huge);
    assert_eq!(status, 413, "{}", String::from_utf8_lossy(&body));
    // The server still answers, and its state is consistent: undo works.
    let (status, _) = http(addr, "POST", "/api/undo", b"");
    assert_eq!(status, 200);
    running.stop();
}
