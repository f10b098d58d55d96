//! Test support: a headless Chromium (Debian's `chromium`) driven over the DevTools protocol,
//! PNG decoding and colour classes of the task scene. Shared by the real-browser tests.
#![allow(dead_code)]

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use macrotree::viewer::{bundle_help, load_bundle};
use tungstenite::{Message, WebSocket};

pub const CHROMIUM: &str = "/usr/bin/chromium";

/// Set to `1` to skip the real-browser tests on a machine without Chromium (they fail otherwise).
pub const SKIP_ENV: &str = "MACROTREE_SKIP_BROWSER_TESTS";

/// Whether a real-browser test runs: `Ok(true)` when `chromium` and the viewer bundle are
/// present, `Ok(false)` (skip) when one is missing and `skip` was asked for, else `Err` with
/// what to install or set.
pub fn browser_check(chromium: &Path, skip: bool) -> Result<bool, String> {
    let missing = if !chromium.exists() {
        format!(
            "{} is missing: install it (apt-get install chromium)",
            chromium.display()
        )
    } else if let Err(p) = load_bundle() {
        bundle_help(&p)
    } else {
        return Ok(true);
    };
    if skip {
        eprintln!("SKIPPED ({SKIP_ENV}=1): {missing}");
        Ok(false)
    } else {
        Err(format!(
            "{missing}; or set {SKIP_ENV}=1 to skip the real-browser tests"
        ))
    }
}

/// Whether the opt-out [`SKIP_ENV`] is set to `1`.
pub fn skip_requested() -> bool {
    std::env::var_os(SKIP_ENV).is_some_and(|v| v == "1")
}

/// Whether to run a real-browser test: a missing Chromium or bundle fails the test unless
/// [`SKIP_ENV`]`=1` (see [`browser_check`]).
pub fn browser_available() -> bool {
    browser_check(Path::new(CHROMIUM), skip_requested()).unwrap_or_else(|why| panic!("{why}"))
}

pub fn temp_dir(tag: &str) -> PathBuf {
    static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let dir = std::env::temp_dir().join(format!("macrotree-viewer-{tag}-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A headless Chromium started by this test; killed (with its process group) on drop.
pub struct Chromium {
    pub child: Child,
    pub profile: PathBuf,
}

impl Chromium {
    pub fn command(profile: &Path, width: u32, height: u32) -> Command {
        let mut cmd = Command::new(CHROMIUM);
        cmd.args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--enable-unsafe-swiftshader",
            "--disable-quic",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-extensions",
            "--no-first-run",
            "--no-default-browser-check",
            "--hide-scrollbars",
            "--mute-audio",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--window-size={width},{height}"))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .process_group(0);
        cmd
    }

    /// Opens `url` and keeps running, with a DevTools port for screenshots.
    pub fn open(url: &str, width: u32, height: u32) -> Self {
        let profile = temp_dir("chromium");
        let child = Self::command(&profile, width, height)
            .arg("--remote-debugging-port=0")
            .arg(url)
            .spawn()
            .expect("start chromium");
        Self { child, profile }
    }

    /// The DevTools websocket of the first page.
    pub fn devtools(&self) -> Devtools {
        let file = self.profile.join("DevToolsActivePort");
        let deadline = Instant::now() + Duration::from_secs(30);
        let port: u16 = loop {
            if let Some(port) = std::fs::read_to_string(&file)
                .ok()
                .and_then(|s| s.lines().next().and_then(|l| l.trim().parse().ok()))
            {
                break port;
            }
            assert!(Instant::now() < deadline, "chromium wrote no DevToolsActivePort");
            std::thread::sleep(Duration::from_millis(50));
        };
        let addr = SocketAddr::from(([127, 0, 0, 1], port));
        let list = loop {
            let body = http_get(addr, "/json/list");
            let list: serde_json::Value = serde_json::from_slice(&body).unwrap_or_default();
            if list
                .as_array()
                .is_some_and(|l| l.iter().any(|t| t["type"] == "page"))
            {
                break list;
            }
            assert!(Instant::now() < deadline, "no page target");
            std::thread::sleep(Duration::from_millis(50));
        };
        let target = list
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["type"] == "page")
            .unwrap();
        let url = target["webSocketDebuggerUrl"].as_str().unwrap().to_owned();
        let stream = TcpStream::connect(addr).unwrap();
        stream.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
        let (ws, _) = tungstenite::client(url, stream).unwrap();
        Devtools { ws, next_id: 1 }
    }
}

impl Drop for Chromium {
    fn drop(&mut self) {
        let pgid = self.child.id();
        let _ = self.child.kill();
        let _ = self.child.wait();
        // Helpers (zygote, GPU, renderer) share the group we created for this browser.
        let _ = Command::new("kill")
            .args(["-KILL", "--", &format!("-{pgid}")])
            .stderr(Stdio::null())
            .status();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}

/// A minimal DevTools protocol client.
pub struct Devtools {
    pub ws: WebSocket<TcpStream>,
    pub next_id: u64,
}

impl Devtools {
    pub fn call(&mut self, method: &str, params: serde_json::Value) -> serde_json::Value {
        let id = self.next_id;
        self.next_id += 1;
        let msg = serde_json::json!({ "id": id, "method": method, "params": params });
        self.ws.send(Message::text(msg.to_string())).unwrap();
        // Each read has the socket's timeout; events arriving in between must not extend it.
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            assert!(Instant::now() < deadline, "{method}: no answer from chromium");
            if let Message::Text(t) = self.ws.read().unwrap() {
                let v: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
                if v["id"] == id {
                    assert!(v.get("error").is_none(), "{method}: {v}");
                    return v["result"].clone();
                }
            }
        }
    }

    pub fn eval(&mut self, js: &str) -> serde_json::Value {
        let r = self.call(
            "Runtime.evaluate",
            serde_json::json!({ "expression": js, "returnByValue": true }),
        );
        r["result"]["value"].clone()
    }

    /// Evaluates `js` every 100 ms until `done` accepts its value; panics with the last value
    /// after `timeout`.
    pub fn wait_until(
        &mut self,
        js: &str,
        timeout: Duration,
        done: impl Fn(&serde_json::Value) -> bool,
    ) -> serde_json::Value {
        let deadline = Instant::now() + timeout;
        loop {
            let v = self.eval(js);
            if done(&v) {
                return v;
            }
            assert!(Instant::now() < deadline, "after {timeout:?}, {js} is {v}");
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    pub fn screenshot(&mut self) -> Vec<u8> {
        use base64::Engine as _;
        let r = self.call("Page.captureScreenshot", serde_json::json!({ "format": "png" }));
        base64::engine::general_purpose::STANDARD
            .decode(r["data"].as_str().unwrap())
            .unwrap()
    }
}

pub fn http_get(addr: SocketAddr, path: &str) -> Vec<u8> {
    let Ok(mut s) = TcpStream::connect(addr) else {
        return Vec::new();
    };
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let _ = write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    );
    let mut buf = Vec::new();
    let _ = s.read_to_end(&mut buf);
    match buf.windows(4).position(|w| w == b"\r\n\r\n") {
        Some(i) => buf[i + 4..].to_vec(),
        None => Vec::new(),
    }
}

/// An RGB image.
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
}

pub fn decode_png(bytes: &[u8]) -> Image {
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let rgb = buf[..info.buffer_size()]
        .chunks(channels)
        .flat_map(|px| {
            if channels >= 3 {
                [px[0], px[1], px[2]]
            } else {
                [px[0]; 3]
            }
        })
        .collect();
    Image {
        width: info.width as usize,
        height: info.height as usize,
        rgb,
    }
}

/// Pixel counts of the colour classes the scene should show.
#[derive(Debug, Default, Clone, Copy)]
pub struct Classes {
    /// The orange cube (material 0.95, 0.35, 0.15).
    pub cube: usize,
    /// The teal bowl (0.25, 0.65, 0.55).
    pub bowl: usize,
    /// The robot's near-black parts (UR5e 0.033 grey, 2F-85 0.149 grey).
    pub robot_dark: usize,
    /// Distinct colours (quantised), a guard against blank images.
    pub distinct: usize,
}

pub fn classify(img: &Image) -> Classes {
    let mut c = Classes::default();
    let mut seen = std::collections::HashSet::new();
    for px in img.rgb.chunks(3) {
        let (r, g, b) = (i32::from(px[0]), i32::from(px[1]), i32::from(px[2]));
        seen.insert((r >> 3, g >> 3, b >> 3));
        if r > 110 && r - g > 60 && g - b > 15 && b < 110 {
            c.cube += 1;
        }
        if g > r + 35 && g >= b && b > r + 10 {
            c.bowl += 1;
        }
        let (max, min) = (r.max(g).max(b), r.min(g).min(b));
        if max < 75 && max - min < 18 {
            c.robot_dark += 1;
        }
    }
    c.distinct = seen.len();
    c
}

pub fn assert_scene_visible(c: Classes, what: &str) {
    assert!(c.distinct > 30, "{what}: blank image {c:?}");
    assert!(c.cube > 15, "{what}: no cube pixels {c:?}");
    assert!(c.bowl > 60, "{what}: no bowl pixels {c:?}");
    assert!(c.robot_dark > 100, "{what}: no robot pixels {c:?}");
}
