// macrotree viewer page: wraps the MeshCat bundle (global `MeshCat`).
// Live: one websocket to the serving host; binary frames are MeshCat commands (msgpack), text
// frames are JSON for the tree panel ({type: "tree" | "status" | "time"}).
// Replay: base64 MeshCat commands fed synchronously, then play/pause/scrub over the animation.
(function () {
  "use strict";
  var mt = (window.macrotree = {});
  var viewer = null;
  var nodeEls = [];
  var nodeByPath = {};
  var MAX_EVENTS = 100;
  var TERMINAL = { success: true, failure: true, halted: true };
  // Per node: its last status, and the outcome it had before it was last reset to idle (the
  // previous attempt's), shown as a badge while the next attempt runs.
  var lastStatus = [];
  var badges = [];

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
    nodeByPath = {};
    lastStatus = [];
    badges = [];
    nodes.forEach(function (n, i) {
      var li = document.createElement("li");
      var row = document.createElement("div");
      row.className = "node idle";
      // The whole name (it may be cut with an ellipsis) and the path, on hover.
      row.title = n.name + " (" + n.kind + ")\n" + n.path;
      var dot = document.createElement("span");
      dot.className = "dot";
      var name = document.createElement("span");
      name.className = "name";
      name.textContent = n.name;
      var kind = document.createElement("span");
      kind.className = "kind";
      kind.textContent = n.kind;
      var badge = document.createElement("span");
      badge.className = "badge";
      var attempts = document.createElement("span");
      attempts.className = "attempts";
      row.appendChild(dot);
      row.appendChild(name);
      row.appendChild(kind);
      row.appendChild(badge);
      row.appendChild(attempts);
      nodeByPath[n.path] = i;
      lastStatus[i] = "idle";
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
      nodeEls[i] = { li: li, row: row, attempts: attempts, badge: badge, name: n.name };
    });
  }

  // A node reset to idle after it finished keeps that outcome as its badge.
  function noteStatus(i, s) {
    if (s === "idle" && TERMINAL[lastStatus[i]]) badges[i] = lastStatus[i];
    lastStatus[i] = s;
  }

  // Reset events (`from` a finished status `to` idle) set badges too, even when a status
  // snapshot in between was not seen.
  function noteEvents(events) {
    (events || []).forEach(function (ev) {
      if (ev && typeof ev === "object" && ev.to === "idle" && TERMINAL[ev.from]) {
        var i = nodeByPath[ev.path];
        if (i !== undefined) badges[i] = ev.from;
      }
    });
  }

  function applyStatuses(statuses, attempts) {
    (statuses || []).forEach(function (s, i) {
      var el = nodeEls[i];
      if (!el) return;
      noteStatus(i, s);
      el.row.className = "node " + s;
      el.row.dataset.status = s;
      var b = badges[i] || "";
      el.badge.textContent = b;
      el.badge.className = "badge " + b;
      el.badge.title = b ? "the previous attempt ended: " + b : "";
      var a = attempts && attempts[i];
      el.attempts.textContent = a > 0 ? "attempt " + a : "";
    });
  }

  // Numbers in events to the millisecond (sim times) or 4 decimals, never 17 digits.
  function num(x, digits) {
    return Number(x.toFixed(digits)).toString();
  }

  // One trace event as a line of text parts: [time, what, class].
  function describeEvent(ev) {
    if (typeof ev === "string") return { t: "", text: ev, cls: "" };
    if (!ev || typeof ev !== "object") return { t: "", text: String(ev), cls: "" };
    var t = typeof ev.t === "number" ? num(ev.t, 3) + " s  " : "";
    var i = nodeByPath[ev.path];
    var who = i !== undefined && nodeEls[i] ? nodeEls[i].name : (ev.path || "");
    if (ev.kind === "blackboard") {
      return { t: t, text: "{" + ev["var"] + "} = " + JSON.stringify(ev.value) + "  (" + who + ")", cls: "" };
    }
    if (ev.from !== undefined && ev.to !== undefined) {
      var text = who + ": " + ev.from + " → " + ev.to;
      if (ev.to === "idle") text += " (reset for the next attempt)";
      if (ev.attempt) text += "  attempt " + ev.attempt;
      if (ev.reason) text += " — " + ev.reason;
      return { t: t, text: text, cls: "to-" + ev.to };
    }
    var rounded = JSON.stringify(ev, function (k, v) {
      return typeof v === "number" && !Number.isInteger(v) ? Number(v.toFixed(4)) : v;
    });
    return { t: t, text: rounded, cls: "" };
  }

  function addEvents(events) {
    var list = $("events");
    (events || []).forEach(function (ev) {
      var d = describeEvent(ev);
      var li = document.createElement("li");
      if (d.t) {
        var ts = document.createElement("span");
        ts.className = "t";
        ts.textContent = d.t;
        li.appendChild(ts);
      }
      var what = document.createElement("span");
      what.className = d.cls;
      what.textContent = d.text;
      li.appendChild(what);
      list.insertBefore(li, list.firstChild);
    });
    while (list.childNodes.length > MAX_EVENTS) list.removeChild(list.lastChild);
  }

  function onPanel(msg) {
    if (msg.type === "tree") {
      renderTree(msg.nodes);
    } else if (msg.type === "status") {
      var events = (msg.events || []).map(function (e) { return e.event; });
      noteEvents(events);
      applyStatuses(msg.statuses, msg.attempts);
      addEvents(events);
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
    // `#t=3.5` opens at simulated time 3.5 s (the clock's time), `#t=3.5&paused` holds there:
    // screenshots and bug reports can point at an instant.
    function readHash() {
      var hash = {};
      location.hash.replace(/^#/, "").split("&").forEach(function (part) {
        if (!part) return;
        var kv = part.split("=");
        hash[decodeURIComponent(kv[0])] = kv.length > 1 ? decodeURIComponent(kv.slice(1).join("=")) : "";
      });
      var at = null;
      if (hash.t !== undefined && hash.t !== "" && isFinite(Number(hash.t))) {
        at = Math.min(Math.max(Number(hash.t) - start, 0), duration);
      }
      return { at: at, paused: hash.paused !== undefined };
    }
    var opened = readHash();
    var startAt = opened.at === null ? 0 : opened.at;
    var startPaused = opened.paused;
    // set_animation started playing; hold at the start until the first frame has rendered
    // (shader compilation can take a second), then play from there.
    var autoplay = a.actions.length > 0 && !startPaused;
    a.pause();
    a.seek(0);
    var bar = $("replay-bar");
    bar.hidden = false;
    var play = $("play");
    var scrub = $("scrub");
    var label = $("replay-time");
    scrub.max = String(duration);
    // Any instant (a URL may name one between two frames); the arrow keys step 0.1 s.
    scrub.step = "any";
    var shownEvent = -1;

    function showStatusAt(t) {
      // Latest timeline entry at or before sim time t; events up to t, newest first.
      var idx = -1;
      for (var k = 0; k < timeline.length && timeline[k].t <= t + 1e-9; k++) idx = k;
      if (idx === shownEvent) return;
      shownEvent = idx;
      $("events").textContent = "";
      // Badges depend on the history up to t: replay it (scrubbing may go backwards).
      lastStatus = lastStatus.map(function () { return "idle"; });
      badges = [];
      for (var h = 0; h < idx; h++) {
        noteEvents(timeline[h].events);
        (timeline[h].statuses || []).forEach(function (s, i) { noteStatus(i, s); });
      }
      if (idx >= 0) noteEvents(timeline[idx].events);
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
    mt.seek = function (t) { userPaused = true; if (a.playing) a.pause(); scrub.value = String(t); a.seek(t); };
    // The instant shown, in the URL, whenever the replay is paused (copy it into a bug report).
    function rememberInstant() {
      if (a.playing || !window.history || !history.replaceState) return;
      var t = start + Number(scrub.value);
      try { history.replaceState(null, "", "#t=" + num(t, 3) + "&paused"); } catch (e) { /* file: URLs may refuse */ }
    }
    play.addEventListener("click", function () { setTimeout(rememberInstant, 0); });
    scrub.addEventListener("change", rememberInstant);
    document.addEventListener("keydown", function (ev) {
      var onBody = ev.target === document.body || ev.target === play || ev.target === scrub;
      if (!onBody || ev.altKey || ev.ctrlKey || ev.metaKey) return;
      var step = ev.shiftKey ? 1 : 0.1;
      var now = a.playing ? current() : Number(scrub.value);
      if (ev.code === "Space") {
        ev.preventDefault();
        play.onclick();
        setTimeout(rememberInstant, 0);
      } else if (ev.code === "ArrowRight" || ev.code === "ArrowLeft") {
        ev.preventDefault();
        var to = now + (ev.code === "ArrowRight" ? step : -step);
        mt.seek(Math.min(Math.max(to, 0), duration));
        rememberInstant();
      } else if (ev.code === "Home" || ev.code === "End") {
        ev.preventDefault();
        mt.seek(ev.code === "Home" ? 0 : duration);
        rememberInstant();
      }
    });
    // Editing the URL's `#t=…` later jumps there too.
    window.addEventListener("hashchange", function () {
      var h = readHash();
      if (h.at === null) return;
      if (h.paused) {
        mt.seek(h.at);
      } else {
        scrub.value = String(h.at);
        a.play();
        a.seek(h.at);
      }
    });
    scrub.value = String(startAt);
    a.seek(startAt);
    requestAnimationFrame(function () {
      requestAnimationFrame(function () {
        if (autoplay) { a.play(); a.seek(startAt); } else { a.seek(startAt); }
        tick();
      });
    });
  };
})();
