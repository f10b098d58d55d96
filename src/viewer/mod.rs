//! The live 3D view in the browser and self-contained replays, built on the MeshCat viewer
//! bundle (three.js r132) with our own page around it.
//!
//! * [`LiveViewer`] serves the page over HTTP and streams the scene over a websocket on the
//!   same port, from its own threads; the simulation thread only calls cheap, non-blocking
//!   publish methods (latest pose wins per client).
//! * [`Recorder`] samples an episode and writes one HTML file that plays offline.
//! * [`ViewObserver`] attaches either or both to an episode ([`crate::episode::run_episode`]).
//!
//! Wire format: each server→browser binary frame is one msgpack map (a MeshCat command); the
//! tree side panel uses JSON text frames. See `docs/viewer.md`.

mod guard;
mod http;
mod limits;
mod monitor;
mod observer;
mod page;
mod panel;
mod proto;
mod record;
mod scene;
mod server;
mod slots;
#[cfg(test)]
mod tests;
mod tree;

use std::net::{IpAddr, Ipv4Addr, SocketAddr, TcpListener};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use rmpv::Value;
use tungstenite::Bytes;

pub use limits::ServerLimits;
pub use monitor::{BreakSpec, BreakWhen, ForcedRecord, Monitor, MonitorCommand};
pub use observer::{PUBLISH_HZ, ViewObserver, tree_view};
pub use page::{BUNDLE_ENV, bundle_help, bundle_path, load_bundle};
pub use panel::{EVENT_HISTORY, TreeNodeView};
pub use record::Recorder;
pub use scene::SceneLayout;
pub use server::ClientStats;
pub use tree::SceneTree;

use proto::Mat4;
use server::{Hub, Site};

/// Default port of `--view`.
pub const DEFAULT_PORT: u16 = 7000;

/// Where the live server listens, and its limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ViewerOptions {
    /// TCP port; 0 picks a free one.
    pub port: u16,
    /// Address to bind (127.0.0.1 by default: the page is for this machine). Requests must
    /// name it, or `127.0.0.1`, `localhost` or `[::1]`, with the port (see `docs/security.md`).
    pub host: IpAddr,
    /// Connections, sizes and waits ([`ServerLimits::DEFAULT`]).
    pub limits: ServerLimits,
}

impl Default for ViewerOptions {
    fn default() -> Self {
        Self {
            port: DEFAULT_PORT,
            host: IpAddr::V4(Ipv4Addr::LOCALHOST),
            limits: ServerLimits::DEFAULT,
        }
    }
}

/// Why the viewer could not start.
#[derive(Debug)]
pub enum ViewerError {
    /// Another process listens on the port.
    PortInUse {
        /// The port asked for.
        port: u16,
    },
    /// The MeshCat bundle (`main.min.js`) is not where it should be.
    BundleMissing {
        /// Where it was looked for.
        path: PathBuf,
    },
    /// Any other I/O failure (binding, spawning threads).
    Io(std::io::Error),
    /// No browser answered a request in time (e.g. `capture_image`).
    NoClient(String),
}

impl std::fmt::Display for ViewerError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::PortInUse { port } => write!(
                f,
                "port {port} is already in use: stop the other program, choose another port with --port P, or use --port 0 to pick a free one"
            ),
            Self::BundleMissing { path } => f.write_str(&page::bundle_help(path)),
            Self::Io(e) => write!(f, "the viewer server failed: {e}"),
            Self::NoClient(why) => write!(f, "no browser answered: {why}"),
        }
    }
}

impl std::error::Error for ViewerError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl From<std::io::Error> for ViewerError {
    fn from(e: std::io::Error) -> Self {
        Self::Io(e)
    }
}

/// Where the default camera looks (Z-up world), metres: the middle of the table's work area,
/// where the scenes put their objects.
pub const CAMERA_TARGET: [f64; 3] = [0.38, -0.04, 0.06];
/// Default camera position relative to [`CAMERA_TARGET`] (Z-up world), metres: in front of the
/// work area (the robot behind it) and about 48° above the table, so that a container's rim or
/// the arm does not hide a block on the table.
pub const CAMERA_OFFSET: [f64; 3] = [0.62, -0.42, 0.84];

/// The scene tree a browser starts from: view settings (camera, hidden grid) and one object per
/// drawn geom. Body transforms follow with the first poses.
pub fn initial_tree(layout: &SceneLayout) -> SceneTree {
    let mut tree = SceneTree::new();
    let mut prop = |path: &str, name: &str, value: Value| {
        tree.set_property(path, name, proto::encode(&proto::set_property(path, name, value)));
    };
    // The floor plane sits at z = 0 like the grid: hide the grid to avoid z-fighting.
    prop("/Grid", "visible", Value::Boolean(false));
    // The origin axes would poke through the floor; they can be switched on in the controls.
    prop("/Axes", "visible", Value::Boolean(false));
    // Camera position is in the Y-up frame of the rotated camera node: (x, y, z) -> (x, z, -y).
    let [x, y, z] = CAMERA_OFFSET;
    prop(
        "/Cameras/default/rotated/<object>",
        "position",
        proto::f64_array(&[x, z, -y]),
    );
    let mut target = proto::IDENTITY;
    target[12..15].copy_from_slice(&CAMERA_TARGET);
    let path = "/Cameras/default";
    tree.set_transform(path, proto::encode(&proto::set_transform(path, &target)));
    for (path, msg) in layout.object_messages() {
        tree.set_object(&path, msg);
    }
    tree
}

/// A body's world pose as MuJoCo gives it: `xpos` and row-major `xmat`.
type BodyPose = ([f64; 3], [f64; 9]);

/// Serves the page + websocket on its own threads; cheap to call from the sim loop.
pub struct LiveViewer {
    hub: Arc<Hub>,
    addr: SocketAddr,
    layout: SceneLayout,
    /// Last pose sent per body (`xpos`, `xmat`), to send only what changed.
    last_pose: Mutex<Vec<Option<BodyPose>>>,
}

impl std::fmt::Debug for LiveViewer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveViewer")
            .field("addr", &self.addr)
            .finish_non_exhaustive()
    }
}

impl LiveViewer {
    /// Binds the port, loads the bundle and the model's scene, and starts serving.
    pub fn start(model: &MjModel, opts: &ViewerOptions) -> Result<Self, ViewerError> {
        let bundle = page::load_bundle().map_err(|path| ViewerError::BundleMissing { path })?;
        let listener = TcpListener::bind((opts.host, opts.port)).map_err(|e| {
            if e.kind() == std::io::ErrorKind::AddrInUse {
                ViewerError::PortInUse { port: opts.port }
            } else {
                ViewerError::Io(e)
            }
        })?;
        let addr = listener.local_addr()?;
        let layout = SceneLayout::new(model);
        let hub = Arc::new(Hub::default());
        hub.lock().tree = initial_tree(&layout);
        let site = Arc::new(Site {
            page: Bytes::from(page::live_html()),
            bundle,
            script: Bytes::from_static(page::PAGE_JS.as_bytes()),
            style: Bytes::from_static(page::PAGE_CSS.as_bytes()),
            authority: guard::Authority::new(addr.ip(), addr.port()),
            limits: opts.limits,
        });
        server::spawn_acceptor(listener, hub.clone(), site)?;
        let nbody = layout.body_paths.len();
        Ok(Self {
            hub,
            addr,
            layout,
            last_pose: Mutex::new(vec![None; nbody]),
        })
    }

    /// The page's address, e.g. `http://127.0.0.1:7000/`.
    pub fn url(&self) -> String {
        let host = if self.addr.ip().is_unspecified() {
            IpAddr::V4(Ipv4Addr::LOCALHOST)
        } else {
            self.addr.ip()
        };
        format!("http://{}/", SocketAddr::new(host, self.addr.port()))
    }

    /// The bound address (the actual port when 0 was asked).
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// The scene paths of the model's bodies and geoms.
    pub fn layout(&self) -> &SceneLayout {
        &self.layout
    }

    /// Latest-wins push of all body poses (call at most ~30-60 Hz of sim or wall time; never
    /// blocks on slow clients). Only bodies whose pose changed since the last call are sent.
    pub fn publish_poses<M: ModelType>(&self, data: &MjData<M>, sim_time: f64) {
        let xpos = data.xpos();
        let xmat = data.xmat();
        let mut poses = Vec::new();
        {
            let mut last = self.last_pose.lock().unwrap_or_else(|e| e.into_inner());
            for (b, path) in self.layout.body_paths.iter().enumerate() {
                if !self.layout.body_drawn[b] {
                    continue;
                }
                let pose = (xpos[b], xmat[b]);
                if last[b] == Some(pose) {
                    continue;
                }
                last[b] = Some(pose);
                let m = proto::mat_from_pos_xmat(pose.0, pose.1);
                poses.push((b, path.as_str(), proto::encode_set_transform(path, &m)));
            }
        }
        self.hub.publish_poses(poses, sim_time);
    }

    /// The tree's node list (for the side panel), once: (path, kind, name, parent index) in
    /// preorder. Statuses reset to idle.
    pub fn set_tree(&self, nodes: Vec<TreeNodeView>) {
        let mut st = self.hub.lock();
        st.panel.set_tree(&nodes);
        Hub::panel_changed(&st, true);
    }

    /// Node statuses ("idle"|"running"|"success"|"failure"|"halted") by preorder index, plus
    /// the latest trace events (strings or JSON values). Latest wins; events are kept in a
    /// bounded history.
    pub fn publish_tree_status(&self, statuses: Vec<&'static str>, events: Vec<serde_json::Value>) {
        let mut st = self.hub.lock();
        st.panel.update(statuses, None, events);
        Hub::panel_changed(&st, false);
    }

    /// Like [`LiveViewer::publish_tree_status`] with the retry attempts per node (preorder).
    pub fn publish_tree_status_with_attempts(
        &self,
        statuses: Vec<&'static str>,
        attempts: Vec<u32>,
        events: Vec<serde_json::Value>,
    ) {
        let mut st = self.hub.lock();
        st.panel.update(statuses, Some(attempts), events);
        Hub::panel_changed(&st, false);
    }

    /// The monitor's state for the page (paused, breakpoints, forced results), replaced whole.
    pub fn publish_monitor(&self, monitor: serde_json::Value) {
        let mut st = self.hub.lock();
        st.panel.set_monitor(monitor);
        Hub::panel_changed(&st, false);
    }

    /// The oldest monitor command a page sent (pause, step, breakpoints, forced results),
    /// waiting up to `wait` for one (`Duration::ZERO`: do not wait).
    pub fn next_command(&self, wait: Duration) -> Option<MonitorCommand> {
        self.hub.next_command(wait)
    }

    /// Puts a three.js JSON object at `path` (replacing the previous one there).
    pub fn set_object(&self, path: &str, object: Value) {
        let msg = proto::encode(&proto::set_object(path, object));
        self.hub.broadcast(msg, |t, m| t.set_object(path, m));
    }

    /// Sets the transform of the group at `path` (column-major 4×4).
    pub fn set_transform(&self, path: &str, matrix: &Mat4) {
        let msg = proto::encode(&proto::set_transform(path, matrix));
        self.hub.broadcast(msg, |t, m| t.set_transform(path, m));
    }

    /// Sets a property (e.g. `visible`) of the node at `path`.
    pub fn set_property(&self, path: &str, property: &str, value: Value) {
        let msg = proto::encode(&proto::set_property(path, property, value));
        self.hub.broadcast(msg, |t, m| t.set_property(path, property, m));
    }

    /// Deletes the subtree at `path`.
    pub fn delete(&self, path: &str) {
        let msg = proto::encode(&proto::delete(path));
        self.hub.broadcast(msg, |t, _| t.delete(path));
    }

    /// Number of connected browsers (websocket clients).
    pub fn client_count(&self) -> usize {
        self.hub.client_count()
    }

    /// Number of open connections (HTTP requests being read or answered, and websocket clients).
    pub fn connection_count(&self) -> usize {
        self.hub.slots.len()
    }

    /// Waits until at least `n` browsers are connected; false on timeout.
    pub fn wait_for_clients(&self, n: usize, timeout: Duration) -> bool {
        let deadline = std::time::Instant::now() + timeout;
        while self.client_count() < n {
            if std::time::Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        true
    }

    /// Counters of each connected client.
    pub fn stats(&self) -> Vec<ClientStats> {
        self.hub.stats()
    }

    /// Pose frames published so far.
    pub fn frames_published(&self) -> u64 {
        self.hub.lock().frames_published
    }

    /// Bytes a late joiner receives as its snapshot.
    pub fn snapshot_bytes(&self) -> usize {
        self.hub.lock().tree.snapshot_bytes()
    }

    /// Asks the oldest connected browser to render and return a PNG of the 3D view.
    pub fn capture_image(&self, timeout: Duration) -> Result<Vec<u8>, ViewerError> {
        let rx = self
            .hub
            .request_capture(proto::encode(&proto::capture_image()))
            .ok_or_else(|| ViewerError::NoClient("no browser is connected".into()))?;
        match rx.recv_timeout(timeout) {
            Ok(Ok(png)) => Ok(png),
            Ok(Err(why)) => Err(ViewerError::NoClient(why)),
            Err(_) => Err(ViewerError::NoClient(format!("no image within {timeout:?}"))),
        }
    }

    /// Block until Ctrl-C (used after the episode with --view). The default SIGINT action ends
    /// the process; the server threads keep serving until then.
    pub fn serve_forever(self) {
        loop {
            std::thread::park();
        }
    }
}

impl Drop for LiveViewer {
    fn drop(&mut self) {
        self.hub.close_all();
        server::wake_acceptor(self.addr);
    }
}
