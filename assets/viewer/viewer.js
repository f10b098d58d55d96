// macrotree viewer page: wraps the MeshCat bundle (global `MeshCat`).
// Live: one websocket to the serving host; binary frames are MeshCat commands (msgpack), text
// frames are JSON for the tree panel ({type: "tree" | "status" | "time"}).
// Replay: base64 MeshCat commands fed synchronously, then play/pause/scrub over the animation.
(function () {
  "use strict";
  var mt = (window.macrotree = {});
  var viewer = null;
  var nodeEls = [];
  var MAX_EVENTS = 100;

  function $(id) { return document.getElementById(id); }

  function makeViewer() {
    viewer = new MeshCat.Viewer($("meshcat-pane"));
    window.viewer = viewer;
    return viewer;
  }

  function setConn(text, ok) {
    var el = $("conn");
    el.textContent = text;
    el.className = "conn " + (ok ? "ok" : "bad");
  }

  function setClock(t) {
    $("clock").textContent = "t = " + Number(t).toFixed(2) + " s";
  }

  // ---- tree panel -------------------------------------------------------------------------
  function renderTree(nodes) {
    var root = $("tree");
    root.textContent = "";
    nodeEls = [];
    var lists = [];
    if (!nodes || nodes.length === 0) {
      var li = document.createElement("li");
      li.className = "empty";
      li.textContent = "no tree";
      root.appendChild(li);
      return;
    }
    nodes.forEach(function (n, i) {
      var li = document.createElement("li");
      var row = document.createElement("div");
      row.className = "node idle";
      row.title = n.path;
      var dot = document.createElement("span");
      dot.className = "dot";
      var name = document.createElement("span");
      name.className = "name";
      name.textContent = n.name;
      var kind = document.createElement("span");
      kind.className = "kind";
      kind.textContent = n.kind;
      var attempts = document.createElement("span");
      attempts.className = "attempts";
      row.appendChild(dot);
      row.appendChild(name);
      row.appendChild(kind);
      row.appendChild(attempts);
      li.appendChild(row);
      var parentList = root;
      if (n.parent !== null && n.parent !== undefined && nodeEls[n.parent]) {
        if (!lists[n.parent]) {
          lists[n.parent] = document.createElement("ul");
          nodeEls[n.parent].li.appendChild(lists[n.parent]);
        }
        parentList = lists[n.parent];
      }
      parentList.appendChild(li);
      nodeEls[i] = { li: li, row: row, attempts: attempts };
    });
  }

  function applyStatuses(statuses, attempts) {
    (statuses || []).forEach(function (s, i) {
      var el = nodeEls[i];
      if (!el) return;
      el.row.className = "node " + s;
      el.row.dataset.status = s;
      var a = attempts && attempts[i];
      el.attempts.textContent = a > 0 ? "attempt " + a : "";
    });
  }

  function addEvents(events) {
    var list = $("events");
    (events || []).forEach(function (ev) {
      var li = document.createElement("li");
      li.textContent = typeof ev === "string" ? ev : JSON.stringify(ev);
      list.insertBefore(li, list.firstChild);
    });
    while (list.childNodes.length > MAX_EVENTS) list.removeChild(list.lastChild);
  }

  function onPanel(msg) {
    if (msg.type === "tree") {
      renderTree(msg.nodes);
    } else if (msg.type === "status") {
      applyStatuses(msg.statuses, msg.attempts);
      addEvents((msg.events || []).map(function (e) { return e.event; }));
    } else if (msg.type === "time") {
      setClock(msg.t);
    }
  }
  mt.onPanel = onPanel;

  // ---- live -------------------------------------------------------------------------------
  mt.live = function () {
    makeViewer();
    var url = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/";
    var connectedOnce = false;
    function connect() {
      var ws = new WebSocket(url);
      ws.binaryType = "arraybuffer";
      ws.onopen = function () {
        if (connectedOnce) {
          // A new server (or a restarted one): start from a clean page, never stale state.
          location.reload();
          return;
        }
        connectedOnce = true;
        setConn("live", true);
      };
      ws.onmessage = function (ev) {
        if (typeof ev.data === "string") {
          onPanel(JSON.parse(ev.data));
        } else {
          viewer.num_messages_received++;
          viewer.handle_command_bytearray(new Uint8Array(ev.data));
        }
      };
      ws.onclose = function () {
        setConn(connectedOnce ? "disconnected" : "no server", false);
        setTimeout(connect, 1000);
      };
      // capture_image answers through viewer.connection.
      viewer.connection = ws;
    }
    connect();
  };

  // ---- replay -----------------------------------------------------------------------------
  function b64bytes(s) {
    var bin = atob(s);
    var out = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out;
  }

  mt.replay = function (commands, meta) {
    makeViewer();
    meta = meta || {};
    for (var i = 0; i < commands.length; i++) {
      viewer.handle_command_bytearray(b64bytes(commands[i]));
    }
    setConn("replay", true);
    var start = meta.start || 0;
    var timeline = meta.timeline || [];
    if (meta.tree) renderTree(meta.tree);
    var a = viewer.animator;
    var duration = a.duration || meta.duration || 0;
    // set_animation started playing; hold at t = 0 until the first frame has rendered (shader
    // compilation can take a second), then play from the start.
    var autoplay = a.actions.length > 0;
    a.pause();
    a.seek(0);
    var bar = $("replay-bar");
    bar.hidden = false;
    var play = $("play");
    var scrub = $("scrub");
    var label = $("replay-time");
    scrub.max = String(duration);
    scrub.step = String(1 / (meta.fps || 30));
    var shownEvent = -1;

    function showStatusAt(t) {
      // Latest timeline entry at or before sim time t; events up to t, newest first.
      var idx = -1;
      for (var k = 0; k < timeline.length && timeline[k].t <= t + 1e-9; k++) idx = k;
      if (idx === shownEvent) return;
      shownEvent = idx;
      $("events").textContent = "";
      applyStatuses(idx >= 0 ? timeline[idx].statuses : (meta.tree || []).map(function () { return "idle"; }));
      for (var j = Math.max(0, idx - MAX_EVENTS); j <= idx; j++) addEvents(timeline[j].events);
    }

    function current() {
      return a.actions.length ? a.actions[0].time : 0;
    }

    var wasPlaying = false;
    var userPaused = false;
    function tick() {
      if (wasPlaying && !a.playing && !userPaused) {
        // Finished by itself (played once to the end).
        scrub.value = String(duration);
      }
      wasPlaying = a.playing;
      userPaused = false;
      var t = a.playing ? current() : Number(scrub.value);
      if (a.playing) scrub.value = String(t);
      label.textContent = t.toFixed(2) + " / " + duration.toFixed(2) + " s";
      play.textContent = a.playing ? "❚❚" : "▶";
      setClock(start + t);
      showStatusAt(start + t);
      requestAnimationFrame(tick);
    }

    play.onclick = function () {
      if (a.playing) {
        var t = current();
        userPaused = true;
        a.pause();
        scrub.value = String(t);
      } else {
        var from = Number(scrub.value);
        if (from >= duration - 1e-6) from = 0;
        a.play();
        a.seek(from);
      }
    };
    scrub.oninput = function () {
      userPaused = true;
      if (a.playing) a.pause();
      a.seek(Number(scrub.value));
    };
    document.addEventListener("keydown", function (ev) {
      if (ev.code === "Space" && ev.target === document.body) {
        ev.preventDefault();
        play.onclick();
      }
    });
    mt.seek = function (t) { userPaused = true; if (a.playing) a.pause(); scrub.value = String(t); a.seek(t); };
    requestAnimationFrame(function () {
      requestAnimationFrame(function () {
        if (autoplay) { a.play(); a.seek(0); }
        tick();
      });
    });
  };
})();
