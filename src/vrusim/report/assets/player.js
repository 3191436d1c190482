/* vrusim scene player: a top-down SVG view of recorded runs (report/player.py makes the data). Plain ES2017, no
   libraries, nothing fetched. World frame in metres, y up; each panel's world group has the transform
   matrix(s, 0, 0, -s, tx, ty), so a point (x, y) m is drawn at (tx + s·x, ty − s·y) viewBox px, and the svg
   carries data-scale-px-per-m, data-tx-px and data-ty-px. window.vrusimPlayer.players[id] is the script API. */
"use strict";
(function () {
  var SVGNS = "http://www.w3.org/2000/svg";
  var FULL_WIDTH_PX = 860, RAY_STEP_DEG = 1, FOLLOW_AHEAD = 0.25;

  function el(name, attrs, parent) {
    var node = document.createElementNS(SVGNS, name);
    for (var key in attrs) if (attrs[key] !== null && attrs[key] !== undefined) node.setAttribute(key, attrs[key]);
    if (parent) parent.appendChild(node);
    return node;
  }
  function html(name, attrs, parent, text) {
    var node = document.createElement(name);
    for (var key in attrs) node.setAttribute(key, attrs[key]);
    if (text !== undefined) node.textContent = text;
    if (parent) parent.appendChild(node);
    return node;
  }
  function points(list) {
    return list.map(function (p) { return p[0] + "," + p[1]; }).join(" ");
  }
  function lastAtOrBefore(ts, t) {
    var lo = 0, hi = ts.length - 1;
    if (t >= ts[hi]) return hi;
    if (t <= ts[0]) return 0;
    while (hi - lo > 1) {
      var mid = (lo + hi) >> 1;
      if (ts[mid] <= t) lo = mid; else hi = mid;
    }
    return lo;
  }
  function clamp(v, lo, hi) { return lo > hi ? (lo + hi) / 2 : Math.min(Math.max(v, lo), hi); }
  function fmt(v, d) { return v === null || v === undefined || !isFinite(v) ? "–" : Number(v).toFixed(d); }

  // distance along a unit ray from (ax, ay) to where it first meets box b = [cx, cy, hx, hy, half l, half w]
  function rayBox(ax, ay, dx, dy, b) {
    var ox = ax - b[0], oy = ay - b[1];
    var o = [ox * b[2] + oy * b[3], oy * b[2] - ox * b[3]];
    var l = [dx * b[2] + dy * b[3], dy * b[2] - dx * b[3]];
    var half = [b[4], b[5]], near = -Infinity, far = Infinity;
    for (var k = 0; k < 2; k++) {
      if (l[k] === 0) {
        if (Math.abs(o[k]) > half[k]) return Infinity;
        continue;
      }
      var t1 = (-half[k] - o[k]) / l[k], t2 = (half[k] - o[k]) / l[k];
      near = Math.max(near, Math.min(t1, t2));
      far = Math.min(far, Math.max(t1, t2));
    }
    return far >= near && far >= 0 ? Math.max(near, 0) : Infinity;
  }

  // the visible sector [apex, rays...] and its occlusion shadow (cut points, then the full arc back)
  function sector(ax, ay, headingDeg, fovDeg, range, boxes) {
    var count = Math.max(2, Math.ceil(fovDeg / RAY_STEP_DEG) + 1), full = fovDeg >= 360;
    var seen = full ? [] : [[ax, ay]], cut = [], arc = [], shaded = false;
    for (var i = 0; i < count; i++) {
      var a = (headingDeg - fovDeg / 2 + fovDeg * i / (count - 1)) * Math.PI / 180;
      var dx = Math.cos(a), dy = Math.sin(a), reach = range;
      boxes.forEach(function (b) { reach = Math.min(reach, rayBox(ax, ay, dx, dy, b)); });
      if (reach < range - 1e-9) shaded = true;
      var p = [ax + dx * reach, ay + dy * reach];
      seen.push(p); cut.push(p); arc.push([ax + dx * range, ay + dy * range]);
    }
    return { seen: seen, shadow: shaded ? cut.concat(arc.reverse()) : [] };
  }

  function star(x, y, r) {
    var out = [];
    for (var i = 0; i < 10; i++) {
      var a = Math.PI / 2 + i * Math.PI / 5, rr = i % 2 ? r * 0.45 : r;
      out.push([x + rr * Math.cos(a), y + rr * Math.sin(a)]);
    }
    return out;
  }

  // state of run `run` at time t: positions interpolated between frames, states from the frame at or before t
  function at(run, t) {
    var f = run.frames, ts = f.t_s, i = lastAtOrBefore(ts, t), j = Math.min(i + 1, ts.length - 1);
    var w = j > i && t > ts[i] ? Math.min((t - ts[i]) / (ts[j] - ts[i]), 1) : 0;
    function mix(col) { return col[i] + (col[j] - col[i]) * w; }
    return {
      i: i, w: w, t: Math.min(t, ts[ts.length - 1]),
      x: mix(f.x_m), y: mix(f.y_m), h: mix(f.heading_deg), speed: mix(f.speed_mps),
      mode: run.modes[f.mode[i]] || "",
      vx: f.vru_x_m.map(mix), vy: f.vru_y_m.map(mix),
      src: f.vru_source.map(function (col) { return col[i]; }),
      age: (f.vru_v2x_age_s || []).map(function (col) { return col[i]; }),  // V2X message age, s (null: none)
    };
  }

  function Player(box) {
    if (box.getAttribute("data-ready")) return;  // started already (a notebook page holds several outputs)
    var data = JSON.parse(box.querySelector("script.player-data").textContent);
    var runs = data.runs, colours = data.colours;
    var groups = (box.getAttribute("data-group") || "").split(/\s+/).filter(Boolean);  // linked chart groups
    var state = { t: 0, playing: false, speed: 1, follow: data.follow, zoom: 1, panX: 0, panY: 0,
                  overlay: runs.length === 1, hidden: {} };
    var panels = [], last = null, api;

    // ------------------------------------------------------------------------------------------- controls
    var bar = html("div", { class: "player-bar" }, box);
    var play = html("button", { type: "button", class: "play", "aria-pressed": "false", title: "Play / pause (space)" },
                    bar, "▶ Play");
    var back = html("button", { type: "button", class: "step-back", title: "Previous frame (←)" }, bar, "◀▮");
    var forward = html("button", { type: "button", class: "step-forward", title: "Next frame (→)" }, bar, "▮▶");
    var scrub = html("input", { type: "range", class: "scrub", min: "0", max: String(data.t_end_s), step: "any",
                                value: "0", "aria-label": "time (s)" }, bar);
    var clock = html("span", { class: "clock" }, bar, "");
    var speed = html("select", { class: "speed", "aria-label": "playback speed" }, bar);
    data.speeds.forEach(function (s) {
      var option = html("option", { value: String(s) }, speed, s + "×");
      if (s === 1) option.selected = true;
    });
    var followLabel = html("label", { class: "follow" }, bar);
    var follow = html("input", { type: "checkbox", class: "follow" }, followLabel);
    followLabel.appendChild(document.createTextNode(" follow ego"));
    follow.checked = state.follow;
    var zoomIn = html("button", { type: "button", class: "zoom-in", title: "Zoom in" }, bar, "+");
    var zoomOut = html("button", { type: "button", class: "zoom-out", title: "Zoom out" }, bar, "−");
    var reset = html("button", { type: "button", class: "reset-view", title: "Reset zoom and pan" }, bar, "reset view");
    var layout = null;
    if (runs.length > 1) {
      layout = html("select", { class: "layout", "aria-label": "layout" }, bar);
      html("option", { value: "side" }, layout, "side by side");
      html("option", { value: "overlay" }, layout, "overlaid");
    }
    var jumps = html("div", { class: "player-events" }, box);
    var seenEvents = {};
    runs.forEach(function (run) {
      run.events.forEach(function (e) {
        var key = e.label + "@" + e.t_s.toFixed(2);
        if (seenEvents[key]) return;
        seenEvents[key] = true;
        var b = html("button", { type: "button", "data-t": String(e.t_s) }, jumps,
                     (runs.length > 1 ? run.label + ": " : "") + e.label + " " + e.t_s.toFixed(2) + " s");
        b.addEventListener("click", function () { pause(); seek(e.t_s); });
      });
    });
    var layers = html("div", { class: "player-layers" }, box);
    data.layers.forEach(function (layer) {
      var label = html("label", {}, layers);
      var box_ = html("input", { type: "checkbox", "data-layer": layer.key }, label);
      box_.checked = true;
      label.appendChild(document.createTextNode(" " + layer.label));
      box_.addEventListener("change", function () {
        state.hidden[layer.key] = !box_.checked;
        applyLayers();
      });
    });
    var stage = html("div", { class: "player-panels" }, box);
    var status = html("div", { class: "player-status", "aria-live": "off" }, box);
    var statusLines = runs.map(function (run) { return html("div", { "data-run": String(runs.indexOf(run)) }, status); });

    // ------------------------------------------------------------------------------------------- panels
    function viewSize() {
      var b = data.box_m;
      return state.follow ? data.follow_size_m : [b[1] - b[0], b[3] - b[2]];
    }

    function buildPanels() {
      stage.textContent = "";
      panels = [];
      var lists = state.overlay ? [runs.map(function (r, i) { return i; })] : runs.map(function (r, i) { return [i]; });
      var width = lists.length === 1 ? FULL_WIDTH_PX : FULL_WIDTH_PX / 2;
      lists.forEach(function (members, p) {
        var size = viewSize();
        var height = Math.round(clamp(width * size[1] / size[0], 160, 520));
        var svg = el("svg", { viewBox: "0 0 " + width + " " + height, class: "scene", "data-panel": String(p),
                              role: "img", "aria-label": "scene: " + members.map(function (i) { return runs[i].label; })
                              .join(", ") }, null);
        stage.appendChild(svg);
        el("rect", { width: width, height: height, fill: colours.ground }, svg);
        var world = el("g", { class: "world" }, svg);
        var g = {};
        data.layers.forEach(function (layer) { g[layer.key] = el("g", { "data-layer": layer.key }, world); });
        var base = runs[members[0]];
        base.road.surfaces.forEach(function (s) { el("polygon", { points: points(s), fill: colours.road }, g.road); });
        base.road.lines.forEach(function (line) {
          var width_m = line.kind === "edge" ? 0.15 : line.kind === "stop" ? 0.3 : 0.12;
          el("polyline", { points: points(line.points), fill: "none", stroke: base.road.marking,
                           "stroke-width": width_m, "stroke-dasharray": line.style === "broken" ? "3 3" : null },
             g.road);
        });
        base.obstacles.forEach(function (b) {
          var c = [b[0], b[1]], u = [b[2] * b[4], b[3] * b[4]], v = [-b[3] * b[5], b[2] * b[5]];
          var corners = [[c[0] - u[0] - v[0], c[1] - u[1] - v[1]], [c[0] + u[0] - v[0], c[1] + u[1] - v[1]],
                         [c[0] + u[0] + v[0], c[1] + u[1] + v[1]], [c[0] - u[0] + v[0], c[1] - u[1] + v[1]]];
          el("polygon", { points: points(corners), fill: colours.obstacle_face, stroke: colours.obstacle_edge,
                          "stroke-width": 0.08 }, g.obstacles);
        });
        var actors = members.map(function (r) {
          var run = runs[r], a = { run: r };
          var ghost = state.overlay && members.length > 1 && r !== members[0] ? 0.55 : 1;
          if (run.rsu) {
            el("circle", { cx: run.rsu.x_m, cy: run.rsu.y_m, r: run.rsu.comm_m, fill: colours.v2x,
                           "fill-opacity": 0.04, stroke: colours.v2x, "stroke-width": 0.12, "stroke-dasharray": "1 0.7",
                           class: "rsu-comm" }, g.v2x);
            el("circle", { cx: run.rsu.x_m, cy: run.rsu.y_m, r: run.rsu.coverage_m, fill: "none", stroke: colours.v2x,
                           "stroke-width": 0.1, "stroke-dasharray": "0.3 0.4", class: "rsu-coverage" }, g.v2x);
            el("polygon", { points: points([[run.rsu.x_m, run.rsu.y_m + 1.1], [run.rsu.x_m - 0.9, run.rsu.y_m - 0.6],
                                             [run.rsu.x_m + 0.9, run.rsu.y_m - 0.6]]),
                            fill: colours.v2x, stroke: "#fff", "stroke-width": 0.1, class: "rsu" }, g.v2x);
            a.link = el("line", { stroke: colours.v2x, "stroke-width": 0.35, "stroke-dasharray": "1.2 0.6",
                                  visibility: "hidden", class: "v2x-message" }, g.v2x);
          }
          el("polyline", { points: points(run.route), fill: "none", stroke: colours.planned, "stroke-width": 0.1,
                           "stroke-dasharray": "0.8 0.6", opacity: ghost }, g.paths);
          run.vrus.forEach(function (v) {
            el("polyline", { points: points(v.path), fill: "none", stroke: v.colour, "stroke-width": 0.1,
                             "stroke-dasharray": "0.8 0.6", opacity: ghost }, g.paths);
          });
          a.trail = el("polyline", { fill: "none", stroke: run.colour, "stroke-width": 0.22, opacity: 0.8 * ghost },
                       g.trails);
          a.vruTrails = run.vrus.map(function (v) {
            return el("polyline", { fill: "none", stroke: v.colour, "stroke-width": 0.2, opacity: 0.9 * ghost },
                      g.trails);
          });
          a.shadow = el("polygon", { fill: colours.shadow, stroke: "none", class: "shadow" }, g.shadows);
          a.sector = el("polygon", { fill: colours.sensor_face, stroke: colours.sensor_edge, "stroke-width": 0.08,
                                     class: "sector", opacity: ghost }, g.sensor);
          if (!run.sensor.enabled) { a.sector.setAttribute("display", "none"); a.shadow.setAttribute("display", "none"); }
          a.vrus = run.vrus.map(function (v) {
            var vg = el("g", { class: "vru", opacity: ghost }, g.vrus);
            return {
              body: el("circle", { r: v.footprint_m, fill: v.colour, stroke: "#000", "stroke-width": 0.06 }, vg),
              sensor: el("circle", { r: v.footprint_m + 0.35, fill: "none", stroke: colours.detected_sensor,
                                     "stroke-width": 0.14, class: "seen-sensor" }, vg),
              v2x: el("circle", { r: v.footprint_m + 0.8, fill: "none", stroke: colours.v2x, "stroke-width": 0.12,
                                  "stroke-dasharray": "0.3 0.2", class: "seen-v2x" }, vg),
            };
          });
          var L = run.ego.length_m, W = run.ego.width_m, nose = Math.min(1.2, 0.4 * L);
          a.ego = el("g", { class: "ego", "data-run": String(r), opacity: ghost }, g.ego);
          el("rect", { x: -L / 2, y: -W / 2, width: L, height: W, fill: run.colour, stroke: colours.ego_edge,
                       "stroke-width": 0.08, class: "ego-body" }, a.ego);
          el("polygon", { points: points([[L / 2 - 0.15, 0], [L / 2 - nose, 0.3 * W], [L / 2 - nose, -0.3 * W]]),
                          fill: "#fff" }, a.ego);
          if (run.impact) {
            a.impact = el("polygon", { points: points(star(run.impact.x_m, run.impact.y_m, 0.9)), fill: colours.impact,
                                       stroke: "#000", "stroke-width": 0.06, class: "impact", visibility: "hidden" },
                          g.impact);
          }
          return a;
        });
        var hud = el("text", { x: 8, y: 18, class: "hud" }, svg);
        svg.addEventListener("wheel", function (e) {
          e.preventDefault();
          zoomBy(e.deltaY < 0 ? 1.2 : 1 / 1.2);
        }, { passive: false });
        svg.addEventListener("pointerdown", function (e) {
          var start = [e.clientX, e.clientY, state.panX, state.panY], panel = panels[p];
          var ratio = svg.viewBox.baseVal.width / svg.getBoundingClientRect().width;
          svg.setPointerCapture(e.pointerId);
          function move(m) {
            state.panX = start[2] - (m.clientX - start[0]) * ratio / panel.scale;
            state.panY = start[3] + (m.clientY - start[1]) * ratio / panel.scale;
            draw();
          }
          function up() { svg.removeEventListener("pointermove", move); svg.removeEventListener("pointerup", up); }
          svg.addEventListener("pointermove", move);
          svg.addEventListener("pointerup", up);
        });
        panels.push({ svg: svg, world: world, actors: actors, members: members, width: width, height: height,
                      hud: hud, scale: 1, tx: 0, ty: 0 });
      });
      applyLayers();
      draw();
    }

    function applyLayers() {
      data.layers.forEach(function (layer) {
        box.querySelectorAll('g[data-layer="' + layer.key + '"]').forEach(function (node) {
          if (state.hidden[layer.key]) node.setAttribute("display", "none"); else node.removeAttribute("display");
        });
      });
    }

    // ------------------------------------------------------------------------------------------- drawing
    function place(panel, states) {
      var size = viewSize(), b = data.box_m;
      var s = Math.min(panel.width / size[0], panel.height / size[1]) * state.zoom, cx, cy;
      if (state.follow) {
        var lead = states[panel.members[0]], h = lead.h * Math.PI / 180;
        cx = clamp(lead.x + FOLLOW_AHEAD * size[0] * Math.cos(h), b[0] + size[0] / 2, b[1] - size[0] / 2);
        cy = clamp(lead.y + FOLLOW_AHEAD * size[1] * Math.sin(h), b[2] + size[1] / 2, b[3] - size[1] / 2);
      } else {
        cx = (b[0] + b[1]) / 2; cy = (b[2] + b[3]) / 2;
      }
      cx += state.panX; cy += state.panY;
      panel.scale = s;
      panel.tx = panel.width / 2 - s * cx;
      panel.ty = panel.height / 2 + s * cy;
      panel.world.setAttribute("transform", "matrix(" + [s, 0, 0, -s, panel.tx, panel.ty].join(" ") + ")");
      panel.svg.setAttribute("data-scale-px-per-m", String(s));
      panel.svg.setAttribute("data-tx-px", String(panel.tx));
      panel.svg.setAttribute("data-ty-px", String(panel.ty));
    }

    function trail(xs, ys, i, x, y) {
      var out = [];
      for (var k = 0; k <= i; k++) out.push(xs[k] + "," + ys[k]);
      out.push(x + "," + y);
      return out.join(" ");
    }

    function draw() {
      var t = state.t;
      var states = runs.map(function (run) { return at(run, t); });
      panels.forEach(function (panel) {
        place(panel, states);
        var lines = [];
        panel.actors.forEach(function (a) {
          var run = runs[a.run], st = states[a.run], f = run.frames, h = st.h * Math.PI / 180;
          var L = run.ego.length_m;
          a.ego.setAttribute("transform", "translate(" + st.x + " " + st.y + ") rotate(" + st.h + ")");
          a.trail.setAttribute("points", trail(f.x_m, f.y_m, st.i, st.x, st.y));
          var front = [st.x + Math.cos(h) * L / 2, st.y + Math.sin(h) * L / 2];
          var cut = sector(front[0], front[1], st.h, run.sensor.fov_deg, run.sensor.range_m, run.obstacles);
          a.sector.setAttribute("points", points(cut.seen));
          a.shadow.setAttribute("points", points(cut.shadow));
          var byV2x = false;
          a.vrus.forEach(function (v, k) {
            var x = st.vx[k], y = st.vy[k], src = st.src[k];
            [v.body, v.sensor, v.v2x].forEach(function (c) { c.setAttribute("cx", x); c.setAttribute("cy", y); });
            v.sensor.setAttribute("visibility", src & data.source_bits.sensor ? "visible" : "hidden");
            v.v2x.setAttribute("visibility", src & data.source_bits.v2x ? "visible" : "hidden");
            if (src & data.source_bits.v2x) byV2x = true;
            a.vruTrails[k].setAttribute("points", trail(f.vru_x_m[k], f.vru_y_m[k], st.i, x, y));
          });
          if (a.link) {
            a.link.setAttribute("x1", run.rsu.x_m); a.link.setAttribute("y1", run.rsu.y_m);
            a.link.setAttribute("x2", front[0]); a.link.setAttribute("y2", front[1]);
            a.link.setAttribute("visibility", byV2x ? "visible" : "hidden");
          }
          if (a.impact) a.impact.setAttribute("visibility", t >= run.impact.t_s - 1e-9 ? "visible" : "hidden");
          lines.push((panel.actors.length > 1 || runs.length > 1 ? run.label + ": " : "") + fmt(st.speed, 1) +
                     " m/s · " + st.mode.replace(/_/g, " "));
        });
        panel.hud.textContent = "t = " + fmt(t, 2) + " s · " + lines.join(" | ");
      });
      runs.forEach(function (run, r) {
        var st = states[r], parts = [];
        parts.push("ego " + fmt(st.speed, 2) + " m/s");
        var swatch = run.mode_colours[st.mode] || "#ddd";
        var v2x = "";
        if (run.v2x && run.first_v2x_message_s !== null && t >= run.first_v2x_message_s) {
          var known = st.src.some(function (s) { return s & data.source_bits.v2x; });
          v2x = " · V2X: first message at " + fmt(run.first_v2x_message_s, 2) + " s" +
                (known ? "" : " (no VRU known via V2X now)");
        } else if (run.v2x) {
          v2x = " · V2X: no message yet";
        }
        var seen = st.src.map(function (s, k) {
          var age = st.age[k];
          return "VRU " + (k + 1) + (s & data.source_bits.sensor ? " seen" : "") +
                 (s & data.source_bits.v2x ? " V2X" + (age === null || age === undefined ? "" :
                                                       " (message " + fmt(age, 2) + " s old)") : "");
        }).join(", ");
        var impact = run.impact && t >= run.impact.t_s - 1e-9 ? " · impact at " + fmt(run.impact.t_s, 2) + " s" : "";
        var line = statusLines[r];
        line.textContent = "";
        html("b", {}, line, run.label + ": ");
        html("span", { class: "mode", style: "background:" + swatch }, line, st.mode.replace(/_/g, " "));
        line.appendChild(document.createTextNode(" " + parts.join(" ") + " · " + seen + v2x + impact));
      });
      clock.textContent = "t = " + fmt(t, 2) + " / " + fmt(data.t_end_s, 2) + " s";
      if (document.activeElement !== scrub || !scrubbing) scrub.value = String(t);
      box.setAttribute("data-time-s", String(t));
      if (window.vrusimCharts) groups.forEach(function (g) { window.vrusimCharts.cursor(g, t); });
    }

    // ------------------------------------------------------------------------------------------- time
    var scrubbing = false;
    function seek(t) {
      state.t = clamp(Number(t), 0, data.t_end_s);
      draw();
    }
    function tick(now) {
      if (!state.playing) return;
      if (last !== null) state.t += (now - last) / 1000 * state.speed;
      last = now;
      if (state.t >= data.t_end_s) { state.t = data.t_end_s; draw(); pause(); return; }
      draw();
      window.requestAnimationFrame(tick);
    }
    function start() {
      if (state.playing) return;
      if (state.t >= data.t_end_s) state.t = 0;
      state.playing = true; last = null;
      play.textContent = "❚❚ Pause"; play.setAttribute("aria-pressed", "true");
      window.requestAnimationFrame(tick);
    }
    function pause() {
      state.playing = false;
      play.textContent = "▶ Play"; play.setAttribute("aria-pressed", "false");
    }
    function step(direction) {
      pause();
      var ts = runs[0].frames.t_s, t = state.t, eps = 1e-9;
      var i = lastAtOrBefore(ts, t);
      if (direction > 0) seek(ts[i] > t + eps ? ts[i] : ts[Math.min(i + 1, ts.length - 1)]);
      else seek(ts[i] < t - eps ? ts[i] : ts[Math.max(i - 1, 0)]);
    }
    function zoomBy(factor) { state.zoom = clamp(state.zoom * factor, 0.2, 40); draw(); }

    play.addEventListener("click", function () { if (state.playing) pause(); else start(); });
    back.addEventListener("click", function () { step(-1); });
    forward.addEventListener("click", function () { step(1); });
    scrub.addEventListener("input", function () { scrubbing = true; pause(); seek(scrub.value); scrubbing = false; });
    speed.addEventListener("change", function () { state.speed = Number(speed.value); });
    follow.addEventListener("change", function () {
      state.follow = follow.checked; state.panX = state.panY = 0; buildPanels();
    });
    zoomIn.addEventListener("click", function () { zoomBy(1.25); });
    zoomOut.addEventListener("click", function () { zoomBy(1 / 1.25); });
    reset.addEventListener("click", function () { state.zoom = 1; state.panX = state.panY = 0; draw(); });
    if (layout) layout.addEventListener("change", function () { state.overlay = layout.value === "overlay"; buildPanels(); });
    box.setAttribute("tabindex", "0");
    box.addEventListener("keydown", function (e) {
      if (e.target !== box) return;
      if (e.key === " ") { e.preventDefault(); if (state.playing) pause(); else start(); }
      else if (e.key === "ArrowRight") step(1);
      else if (e.key === "ArrowLeft") step(-1);
    });
    if (window.vrusimCharts) {
      groups.forEach(function (g) { window.vrusimCharts.onPick(g, function (x) { pause(); seek(x); }); });
    }

    buildPanels();
    api = {
      time: function () { return state.t; },
      seek: seek,
      play: start,
      pause: pause,
      playing: function () { return state.playing; },
      view: function (p) {
        var panel = panels[p || 0];
        return { scale_px_per_m: panel.scale, tx_px: panel.tx, ty_px: panel.ty, width_px: panel.width,
                 height_px: panel.height };
      },
      data: data,
    };
    window.vrusimPlayer.players[box.id] = api;
    box.setAttribute("data-ready", "true");
  }

  window.vrusimPlayer = window.vrusimPlayer || { players: {} };
  document.querySelectorAll("div.player").forEach(Player);
})();
