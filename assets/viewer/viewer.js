// macrotree viewer page: wraps the MeshCat bundle (global `MeshCat`).
// Live: one websocket to the serving host; binary frames are MeshCat commands (msgpack), text
// frames are JSON for the tree panel ({type: "tree" | "status" | "time"}); the page sends
// monitor commands ({type: "monitor", op: "pause" | "resume" | "step" | "break" | "force"}).
// Replay: base64 MeshCat commands fed synchronously, then play/pause/scrub over the animation,
// the panel rebuilt from the recorded timeline at the instant shown.
(function () {
  "use strict";
  var mt = (window.macrotree = {});
  // Work counters (tests check that an update rewrites only the rows that changed), and the
  // wall time of the last panel update in milliseconds.
  mt.stats = { rowWrites: 0, lastUpdateMs: 0 };
  var viewer = null;
  var socket = null;
  var MAX_EVENTS = 100;
  var TERMINAL = { success: true, failure: true, halted: true };
  var LOOP_WORD = { retry: "attempt", repeat: "run", for_each: "iteration" };

  // The tree and everything the panel derives from it.
  var nodes = [];        // the node list (path, kind, name, parent, limit, var, leaf, source)
  var els = [];          // per node: its DOM parts
  var children = [];     // per node: child indices
  var byPath = {};       // path -> index
  var loopOf = [];       // per node: index of its nearest enclosing loop, or -1
  var status = [];       // per node: its current status
  var attempts = [];     // per node: loop counter (attempt / run / iteration)
  var badges = [];       // per node: {outcome, of} of its previous run, or null
  var endedIn = [];      // per node: the enclosing loop's counter when it last finished
  var since = [];        // per node: when it last started running (sim s)
  var forcedCount = [];  // per node: results forced on it
  var blackboard = {};   // var -> {value, path, t}
  var monitor = { paused: null, breakpoints: [], forced: [] };
  var breakAt = {};      // path -> "before" | "after"
  var lastShown = [];    // per node: the row state last written to the DOM
  var searchQuery = "";

  function $(id) { return document.getElementById(id); }
  function el(tag, cls, text) {
    var e = document.createElement(tag);
    if (cls) e.className = cls;
    if (text !== undefined) e.textContent = text;
    return e;
  }

  function makeViewer() {
    viewer = new MeshCat.Viewer($("meshcat-pane"));
    window.viewer = viewer;
    return viewer;
  }

  function setConn(text, ok) {
    var c = $("conn");
    c.textContent = text;
    c.className = "conn " + (ok ? "ok" : "bad");
  }

  function setClock(t) {
    $("clock").textContent = "t = " + Number(t).toFixed(2) + " s";
  }

  // Numbers in events to the millisecond (sim times) or 4 decimals, never 17 digits.
  function num(x, digits) {
    return Number(x.toFixed(digits)).toString();
  }

  // ---- the panel's width --------------------------------------------------------------------
  function setPanelWidth(px) {
    var w = Math.max(220, Math.min(px, Math.floor(window.innerWidth * 0.7)));
    document.documentElement.style.setProperty("--panel-width", w + "px");
    window.dispatchEvent(new Event("resize"));
    return w;
  }
  mt.setPanelWidth = setPanelWidth;

  function initResizer() {
    var saved = Number((window.localStorage && localStorage.getItem("macrotree.panelWidth")) || 0);
    if (saved > 0) setPanelWidth(saved);
    var r = $("resizer");
    r.addEventListener("mousedown", function (ev) {
      ev.preventDefault();
      r.classList.add("dragging");
      function move(e) { setPanelWidth(e.clientX); }
      function up(e) {
        r.classList.remove("dragging");
        document.removeEventListener("mousemove", move);
        document.removeEventListener("mouseup", up);
        var w = setPanelWidth(e.clientX);
        try { localStorage.setItem("macrotree.panelWidth", String(w)); } catch (err) { /* file: pages */ }
      }
      document.addEventListener("mousemove", move);
      document.addEventListener("mouseup", up);
    });
  }

  // ---- labels with the blackboard's values ---------------------------------------------------
  function resolve(label) {
    return String(label).replace(/\{([A-Za-z_][A-Za-z0-9_]*)\}/g, function (whole, name) {
      var entry = blackboard[name];
      if (!entry) return whole;
      return entry.value === null || entry.value === undefined ? whole + "=unset" : whole + "=" + JSON.stringify(entry.value);
    });
  }

  function displayName(i) {
    return nodes[i] ? resolve(nodes[i].name) : "";
  }

  // ---- the tree panel ----------------------------------------------------------------------
  function renderTree(list) {
    var root = $("tree");
    root.textContent = "";
    nodes = list || [];
    els = []; children = []; byPath = {}; loopOf = []; status = []; attempts = [];
    badges = []; endedIn = []; since = []; forcedCount = []; lastShown = []; blackboard = {};
    if (nodes.length === 0) {
      root.appendChild(el("li", "empty", "no tree"));
      return;
    }
    var lists = [];
    nodes.forEach(function (n, i) {
      children[i] = [];
      byPath[n.path] = i;
      status[i] = "idle";
      attempts[i] = 0;
      badges[i] = null;
      forcedCount[i] = 0;
      var p = n.parent;
      var hasParent = p !== null && p !== undefined && els[p];
      if (hasParent) children[p].push(i);
      loopOf[i] = hasParent ? (LOOP_WORD[nodes[p].kind] ? p : loopOf[p]) : -1;
      var li = el("li");
      var row = el("div", "node idle" + (n.leaf ? " leaf" : ""));
      row.title = n.name + " (" + n.kind + ")\n" + n.path + (n.source ? "\n" + n.source : "");
      row.dataset.path = n.path;
      var toggle = el("span", "toggle none", "");
      var bp = el("span", "bp");
      bp.title = "breakpoint: before this node starts; click again: after it ends; again: none";
      var dot = el("span", "dot");
      var name = el("span", "name", n.name);
      var kind = el("span", "kind", n.kind);
      var counter = el("span", "attempts");
      var hidden = el("span", "hidden-count");
      var badge = el("span", "badge");
      var badgeOf = el("span", "badge-of");
      var forced = el("span", "forced");
      // Markers in fixed columns; the text after them wraps as one block.
      var body = el("span", "body");
      [toggle, bp, dot, body].forEach(function (c) { row.appendChild(c); });
      [name, kind, counter, hidden, badge, badgeOf, forced].forEach(function (c) { body.appendChild(c); });
      if (n.leaf) {
        ["success", "failure"].forEach(function (result) {
          var b = el("button", "force", result === "success" ? "✓ succeed" : "✗ fail");
          b.type = "button";
          b.title = "force this leaf's next result to " + result + " (recorded as forced)";
          b.dataset.result = result;
          b.addEventListener("click", function (ev) {
            ev.stopPropagation();
            send({ type: "monitor", op: "force", path: n.path, result: result });
          });
          body.appendChild(b);
        });
      }
      bp.addEventListener("click", function (ev) {
        ev.stopPropagation();
        if (!socket) return;
        var now = breakAt[n.path];
        var next = now === undefined ? "before" : now === "before" ? "after" : null;
        send({ type: "monitor", op: "break", path: n.path, when: next });
      });
      toggle.addEventListener("click", function (ev) {
        ev.stopPropagation();
        setCollapsed(i, !li.classList.contains("collapsed"));
      });
      li.appendChild(row);
      var parentList = root;
      if (hasParent) {
        if (!lists[p]) {
          lists[p] = el("ul");
          els[p].li.appendChild(lists[p]);
          els[p].toggle.textContent = "▾";
          els[p].toggle.className = "toggle";
          els[p].toggle.title = "collapse / expand";
        }
        parentList = lists[p];
      }
      parentList.appendChild(li);
      els[i] = { li: li, row: row, toggle: toggle, bp: bp, name: name, counter: counter, hidden: hidden, badge: badge, badgeOf: badgeOf, forced: forced };
    });
    refreshAll();
  }

  function descendants(i, out) {
    children[i].forEach(function (c) { out.push(c); descendants(c, out); });
    return out;
  }

  function setCollapsed(i, collapsed) {
    if (!els[i] || children[i].length === 0) return;
    els[i].li.classList.toggle("collapsed", collapsed);
    els[i].toggle.textContent = collapsed ? "▸" : "▾";
    lastShown[i] = null;
    refreshRow(i);
  }
  mt.setCollapsed = function (path, collapsed) { setCollapsed(byPath[path], collapsed); };
  $("expand-all") && $("expand-all").addEventListener("click", function () {
    nodes.forEach(function (n, i) { setCollapsed(i, false); });
  });
  $("collapse-all") && $("collapse-all").addEventListener("click", function () {
    nodes.forEach(function (n, i) { if (i > 0) setCollapsed(i, true); });
  });

  // One row as it should look now; written to the DOM only when it changed.
  function refreshRow(i) {
    var n = nodes[i], e = els[i];
    if (!n || !e) return;
    var s = status[i];
    var word = LOOP_WORD[n.kind];
    var counter = "";
    if (word && attempts[i] > 0) {
      counter = word + " " + attempts[i];
      if (n.kind === "for_each") {
        if (n.limit) counter += " (at most " + n.limit + ")";
        var item = n["var"] && blackboard[n["var"]];
        if (item && item.value !== null && item.value !== undefined) counter += " · {" + n["var"] + "}=" + JSON.stringify(item.value);
      } else if (n.limit) {
        counter += " of " + n.limit;
      }
    }
    var b = badges[i];
    var collapsed = e.li.classList.contains("collapsed");
    var hiddenText = "";
    var runningInside = false;
    if (collapsed) {
      var d = descendants(i, []);
      hiddenText = "+" + d.length;
      runningInside = d.some(function (k) { return status[k] === "running"; });
      if (runningInside) hiddenText += " (running inside)";
    }
    var bp = breakAt[n.path] || "";
    var paused = monitor.paused && monitor.paused.path === n.path;
    var forced = forcedCount[i] ? "forced ×" + forcedCount[i] : "";
    var shown = [s, displayName(i), counter, b ? b.outcome + "|" + b.of : "", hiddenText, bp, paused, forced].join("\u0001");
    if (lastShown[i] === shown) return;
    lastShown[i] = shown;
    mt.stats.rowWrites += 1;
    e.row.className = "node " + s + (n.leaf ? " leaf" : "") + (paused ? " paused-here" : "") +
      (e.row.classList.contains("match") ? " match" : "") + (e.row.classList.contains("flash") ? " flash" : "");
    e.row.dataset.status = s;
    e.name.textContent = displayName(i);
    e.counter.textContent = counter;
    e.hidden.textContent = hiddenText;
    e.badge.textContent = b ? b.outcome : "";
    e.badge.className = "badge " + (b ? b.outcome : "");
    e.badgeOf.textContent = b && b.of ? "#" + b.of : "";
    e.badge.title = b ? "the previous run ended: " + b.outcome + (b.of ? " (" + b.ofWord + " " + b.of + ")" : "") : "";
    e.bp.className = "bp" + (bp ? " " + bp : "");
    e.forced.textContent = forced;
  }

  function refreshAll() {
    for (var i = 0; i < nodes.length; i++) refreshRow(i);
    refreshRunning();
    refreshBlackboard();
    applySearch();
  }

  // A node's status changes: a node reset to idle after it finished keeps that outcome as its
  // badge, marked with the attempt or iteration of its enclosing loop it belongs to.
  var endedByEvent = {};  // nodes whose end the current batch's events already placed
  function noteStatus(i, s, t) {
    var before = status[i];
    if (s === before) return;
    if (TERMINAL[s] && !endedByEvent[i]) {
      var loop = loopOf[i];
      endedIn[i] = loop >= 0 ? Math.max(attempts[loop], 1) : 0;
    }
    if (s === "idle" && TERMINAL[before]) setBadge(i, before);
    if (s === "running" && t !== undefined) since[i] = t;
    status[i] = s;
  }

  function setBadge(i, outcome) {
    var loop = loopOf[i];
    badges[i] = { outcome: outcome, of: endedIn[i] || 0, ofWord: loop >= 0 ? LOOP_WORD[nodes[loop].kind] : "" };
  }

  // Events: resets (`from` a finished status `to` idle) set badges even when a status snapshot
  // in between was not seen; blackboard writes update the table; forced results are counted.
  function noteEvents(events) {
    endedByEvent = {};
    (events || []).forEach(function (ev) {
      if (!ev || typeof ev !== "object") return;
      var i = byPath[ev.path];
      if (ev.kind === "blackboard" && typeof ev["var"] === "string") {
        blackboard[ev["var"]] = { value: ev.value === undefined ? null : ev.value, path: ev.path, t: ev.t, fresh: true };
      } else if (ev.kind === "forced") {
        if (i !== undefined) forcedCount[i] += 1;
      } else if (i !== undefined && ev.to !== undefined) {
        if (TERMINAL[ev.to]) {
          // The run ended in the loop's current attempt or iteration (a node inside a loop runs
          // in its first one at the earliest; a retry's attempt comes with the event).
          var loop = loopOf[i];
          var k = loop >= 0 ? Math.max(attempts[loop], 1) : 0;
          if (loop >= 0 && nodes[loop].kind === "retry" && ev.attempt) k = ev.attempt;
          endedIn[i] = k;
          endedByEvent[i] = true;
        }
        if (ev.to === "idle" && TERMINAL[ev.from]) setBadge(i, ev.from);
        if (ev.to === "running" && typeof ev.t === "number") since[i] = ev.t;
      }
    });
  }

  function applyStatuses(statuses, counters, t) {
    if (counters) counters.forEach(function (a, i) { attempts[i] = a || 0; });
    (statuses || []).forEach(function (s, i) { if (i < nodes.length) noteStatus(i, s, t); });
  }

  // ---- running now ------------------------------------------------------------------------
  function refreshRunning() {
    var list = $("running");
    var running = [];
    for (var i = 0; i < nodes.length; i++) {
      if (status[i] !== "running") continue;
      var busyChild = children[i].some(function (c) { return status[c] === "running"; });
      if (!busyChild) running.push(i);
    }
    var key = running.map(function (i) { return i + ":" + displayName(i) + "@" + since[i]; }).join(",");
    if (list.dataset.key === key) return;
    list.dataset.key = key;
    list.textContent = "";
    if (running.length === 0) {
      list.appendChild(el("li", "empty", "nothing"));
      return;
    }
    running.forEach(function (i) {
      var li = el("li");
      li.appendChild(el("span", "name", displayName(i)));
      li.appendChild(el("span", "kind", nodes[i].kind));
      if (since[i] !== undefined) li.appendChild(el("span", "since", "since " + num(since[i], 2) + " s"));
      li.title = nodes[i].path + "\nclick: show it in the tree";
      li.dataset.path = nodes[i].path;
      li.addEventListener("click", function () { reveal(i); });
      list.appendChild(li);
    });
  }

  // Expands a node's ancestors, scrolls to it and flashes it.
  function reveal(i) {
    for (var p = nodes[i].parent; p !== null && p !== undefined; p = nodes[p].parent) setCollapsed(p, false);
    var row = els[i].row;
    row.scrollIntoView({ block: "center" });
    row.classList.add("flash");
    setTimeout(function () { row.classList.remove("flash"); lastShown[i] = null; refreshRow(i); }, 900);
  }

  // ---- the blackboard table ----------------------------------------------------------------
  function refreshBlackboard() {
    var body = $("blackboard").tBodies[0];
    var names = Object.keys(blackboard).sort();
    var key = names.map(function (k) { var e = blackboard[k]; return k + "=" + JSON.stringify(e.value) + "@" + e.t + e.path; }).join("|");
    if (body.dataset.key === key) return;
    body.dataset.key = key;
    body.textContent = "";
    if (names.length === 0) {
      var tr0 = el("tr", "empty");
      var td0 = el("td", "", "nothing written yet");
      td0.colSpan = 5;
      tr0.appendChild(td0);
      body.appendChild(tr0);
      return;
    }
    names.forEach(function (name) {
      var e = blackboard[name];
      var tr = el("tr", e.fresh ? "changed" : "");
      e.fresh = false;
      tr.dataset["var"] = name;
      var unset = e.value === null || e.value === undefined;
      tr.appendChild(el("td", "var", "{" + name + "}"));
      tr.appendChild(el("td", "type", unset ? "unset" : typeof e.value));
      tr.appendChild(el("td", "value", unset ? "–" : JSON.stringify(e.value)));
      // The writer by its path's last segment (`for_each[each block on the table]`); the whole
      // label and path on hover.
      var i = byPath[e.path];
      var path = e.path || "";
      var who = el("td", "writer", path.split("/").pop());
      who.title = (i !== undefined ? displayName(i) + "\n" : "") + path;
      tr.appendChild(who);
      tr.appendChild(el("td", "t", typeof e.t === "number" ? num(e.t, 3) : ""));
      body.appendChild(tr);
    });
  }

  // ---- search ------------------------------------------------------------------------------
  function applySearch() {
    var q = searchQuery.trim().toLowerCase();
    var count = $("search-count");
    if (!q) {
      els.forEach(function (e) { e.li.classList.remove("search-hidden"); e.row.classList.remove("match"); });
      if (count) count.textContent = "";
      return;
    }
    var keep = [];
    var matches = 0;
    nodes.forEach(function (n, i) {
      var hit = (displayName(i) + "\n" + n.kind + "\n" + n.path).toLowerCase().indexOf(q) >= 0;
      els[i].row.classList.toggle("match", hit);
      if (!hit) return;
      matches += 1;
      for (var k = i; k !== null && k !== undefined; k = nodes[k].parent) {
        if (keep[k]) break;
        keep[k] = true;
      }
      // A match shows its ancestors expanded.
      for (var p = n.parent; p !== null && p !== undefined; p = nodes[p].parent) {
        if (els[p].li.classList.contains("collapsed")) setCollapsed(p, false);
      }
    });
    els.forEach(function (e, i) { e.li.classList.toggle("search-hidden", !keep[i]); });
    if (count) count.textContent = matches + (matches === 1 ? " match" : " matches");
  }
  $("search") && $("search").addEventListener("input", function (ev) {
    searchQuery = ev.target.value || "";
    applySearch();
  });

  // ---- trace events ------------------------------------------------------------------------
  // One trace event as a line of text parts: [time, what, class].
  function describeEvent(ev) {
    if (typeof ev === "string") return { t: "", text: ev, cls: "" };
    if (!ev || typeof ev !== "object") return { t: "", text: String(ev), cls: "" };
    var t = typeof ev.t === "number" ? num(ev.t, 3) + " s  " : "";
    var i = byPath[ev.path];
    var who = i !== undefined ? displayName(i) : (ev.path || "");
    if (ev.kind === "blackboard") {
      return { t: t, text: "{" + ev["var"] + "} = " + JSON.stringify(ev.value) + "  (" + who + ")", cls: "" };
    }
    if (ev.kind === "forced") {
      return { t: t, text: who + ": " + ev.result + " forced from the monitor", cls: "forced" };
    }
    if (ev.kind === "fault") {
      return { t: t, text: "fault " + ev.fault + ": " + ev.detail, cls: "fault" };
    }
    if (ev.kind === "collision") {
      return { t: t, text: "collision: " + ev.what + (ev.path ? "  (" + who + ")" : ""), cls: "fault" };
    }
    if (ev.kind === "note") {
      return { t: t, text: String(ev.text), cls: "forced" };
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

  var onEventClick = null;
  function addEvents(events) {
    var list = $("events");
    (events || []).forEach(function (ev) {
      var d = describeEvent(ev);
      var li = el("li");
      if (d.t) {
        li.appendChild(el("span", "t", d.t));
        li.dataset.t = String(ev.t);
      }
      li.appendChild(el("span", d.cls, d.text));
      list.insertBefore(li, list.firstChild);
    });
    while (list.childNodes.length > MAX_EVENTS) list.removeChild(list.lastChild);
  }
  $("events").addEventListener("click", function (ev) {
    var li = ev.target.closest ? ev.target.closest("li[data-t]") : null;
    if (li && onEventClick) onEventClick(Number(li.dataset.t));
  });

  // ---- the monitor (live) ------------------------------------------------------------------
  function send(msg) {
    if (socket && socket.readyState === 1) socket.send(JSON.stringify(msg));
  }
  mt.send = send;

  function applyMonitor(m) {
    monitor = m && typeof m === "object" ? m : { paused: null, breakpoints: [], forced: [] };
    breakAt = {};
    (monitor.breakpoints || []).forEach(function (b) { breakAt[b.path] = b.when; });
    var st = $("mon-state");
    var p = monitor.paused;
    document.body.classList.toggle("paused", !!p);
    if (st) {
      if (p) {
        var i = byPath[p.path];
        var where = p.path ? " " + p.reason + " “" + (i !== undefined ? displayName(i) : p.path) + "”" : p.reason === "step" ? " after a step" : "";
        st.textContent = "paused" + where + " at " + num(p.t, 3) + " s";
        st.className = "mon-state paused";
      } else {
        st.textContent = "running";
        st.className = "mon-state";
      }
    }
  }

  function initMonitorBar() {
    $("monitor-bar").hidden = false;
    $("mon-pause").onclick = function () { send({ type: "monitor", op: "pause" }); };
    $("mon-step").onclick = function () { send({ type: "monitor", op: "step" }); };
    $("mon-resume").onclick = function () { send({ type: "monitor", op: "resume" }); };
  }

  function onPanel(msg) {
    if (msg.type === "tree") {
      renderTree(msg.nodes);
    } else if (msg.type === "status") {
      var began = performance.now();
      var events = (msg.events || []).map(function (e) { return e.event; });
      noteEvents(events);
      applyStatuses(msg.statuses, msg.attempts);
      if (Array.isArray(msg.blackboard)) {
        var seen = {};
        msg.blackboard.forEach(function (b) {
          seen[b["var"]] = true;
          var old = blackboard[b["var"]];
          var fresh = !old || old.t !== b.t || old.value !== b.value;
          blackboard[b["var"]] = { value: b.value === undefined ? null : b.value, path: b.path, t: b.t, fresh: fresh || (old && old.fresh) };
        });
        Object.keys(blackboard).forEach(function (k) { if (!seen[k]) delete blackboard[k]; });
      }
      if (msg.monitor !== undefined) applyMonitor(msg.monitor);
      if (msg.monitor && Array.isArray(msg.monitor.forced)) {
        forcedCount = nodes.map(function () { return 0; });
        msg.monitor.forced.forEach(function (f) { var i = byPath[f.path]; if (i !== undefined) forcedCount[i] += 1; });
      }
      refreshAll();
      addEvents(events);
      mt.stats.lastUpdateMs = performance.now() - began;
    } else if (msg.type === "time") {
      setClock(msg.t);
    }
  }
  mt.onPanel = onPanel;

  // ---- live -------------------------------------------------------------------------------
  mt.live = function () {
    makeViewer();
    initResizer();
    initMonitorBar();
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
        socket = ws;
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
        socket = null;
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

  // What the markers above the scrubber show: failures, halts, retries, forced results, faults
  // and collisions.
  function markersOf(timeline) {
    var out = [];
    var prevAttempts = [];
    timeline.forEach(function (entry) {
      (entry.events || []).forEach(function (ev) {
        if (!ev || typeof ev !== "object" || typeof ev.t !== "number") return;
        var i = byPath[ev.path];
        var who = i !== undefined ? nodes[i].name : ev.path;
        if (ev.kind === "forced") out.push({ t: ev.t, cls: "forced", text: who + ": " + ev.result + " forced" });
        else if (ev.kind === "fault") out.push({ t: ev.t, cls: "fault", text: "fault " + ev.fault + ": " + ev.detail });
        else if (ev.kind === "collision") out.push({ t: ev.t, cls: "collision", text: "collision: " + ev.what });
        else if (ev.to === "failure") out.push({ t: ev.t, cls: "failure", text: who + " failed" + (ev.reason ? ": " + ev.reason : "") });
        else if (ev.to === "halted") out.push({ t: ev.t, cls: "halted", text: who + " halted" });
      });
      (entry.attempts || []).forEach(function (a, i) {
        if (nodes[i] && nodes[i].kind === "retry" && a > 1 && a !== prevAttempts[i]) {
          out.push({ t: entry.t, cls: "retry", text: nodes[i].name + ": attempt " + a });
        }
        prevAttempts[i] = a;
      });
    });
    return out;
  }

  mt.replay = function (commands, meta) {
    makeViewer();
    initResizer();
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
    // For tools and tests: the recorded timeline, and the sim time the replay starts at.
    mt.timeline = function () { return timeline; };
    mt.replayStart = function () { return start; };
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

    // Markers: positioned by sim time; a click seeks there.
    var markerBox = $("markers");
    markersOf(timeline).forEach(function (m) {
      var x = duration > 0 ? Math.min(Math.max((m.t - start) / duration, 0), 1) : 0;
      var mk = el("span", "marker " + m.cls);
      mk.style.left = (x * 100).toFixed(3) + "%";
      mk.title = num(m.t, 3) + " s  " + m.text;
      mk.dataset.t = String(m.t);
      mk.addEventListener("click", function () { mt.seek(Math.min(Math.max(m.t - start, 0), duration)); rememberInstant(); });
      markerBox.appendChild(mk);
    });

    function showStatusAt(t) {
      // Latest timeline entry at or before sim time t; events up to t, newest first.
      var idx = -1;
      for (var k = 0; k < timeline.length && timeline[k].t <= t + 1e-9; k++) idx = k;
      if (idx === shownEvent) return;
      // Everything depends on the history up to t: replay it from the start when going back,
      // only the new entries when going forward.
      var from = shownEvent + 1;
      if (idx < shownEvent) {
        from = 0;
        status = nodes.map(function () { return "idle"; });
        attempts = nodes.map(function () { return 0; });
        badges = []; endedIn = []; since = [];
        forcedCount = nodes.map(function () { return 0; });
        blackboard = {};
      }
      shownEvent = idx;
      $("events").textContent = "";
      for (var h = from; h <= idx; h++) {
        noteEvents(timeline[h].events);
        applyStatuses(timeline[h].statuses, timeline[h].attempts, timeline[h].t);
      }
      Object.keys(blackboard).forEach(function (k) {
        blackboard[k].fresh = idx >= 0 && (timeline[idx].events || []).some(function (ev) { return ev && ev["var"] === k; });
      });
      lastShown = [];
      refreshAll();
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
    // Transition to transition: the timeline's entries with a status change or an event.
    function stepTransition(dir) {
      var now = start + (a.playing ? current() : Number(scrub.value));
      var target = null;
      for (var k = 0; k < timeline.length; k++) {
        var tk = timeline[k].t;
        if (dir > 0 && tk > now + 1e-6) { target = tk; break; }
        if (dir < 0 && tk < now - 1e-6) target = tk;
      }
      if (target === null) target = dir > 0 ? start + duration : start;
      mt.seek(Math.min(Math.max(target - start, 0), duration));
      rememberInstant();
    }
    mt.stepTransition = stepTransition;
    $("prev").onclick = function () { stepTransition(-1); };
    $("next").onclick = function () { stepTransition(1); };
    onEventClick = function (t) {
      if (!isFinite(t)) return;
      mt.seek(Math.min(Math.max(t - start, 0), duration));
      rememberInstant();
    };
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
