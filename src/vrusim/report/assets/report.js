/* vrusim report: sortable and filterable tables, interactive SVG charts (hover read-out, synced crosshair,
   series toggles, a time cursor shared with the scene player). Plain ES2017, no libraries, nothing fetched. */
"use strict";
(function () {
  function cellValue(row, index) {
    var cell = row.children[index];
    if (!cell) return null;
    var raw = cell.getAttribute("data-value");
    if (raw !== null) {
      var parsed = JSON.parse(raw);
      if (typeof parsed === "number" || typeof parsed === "boolean") return Number(parsed);
      if (parsed === null) return null;
      return String(parsed);
    }
    return cell.textContent.trim();
  }

  function compare(a, b) {
    if (a === b) return 0;
    if (a === null) return 1;
    if (b === null) return -1;
    if (typeof a === "number" && typeof b === "number") return a - b;
    return String(a).localeCompare(String(b), undefined, { numeric: true });
  }

  function makeSortable(table) {
    var heads = table.querySelectorAll("thead th");
    heads.forEach(function (th, index) {
      th.classList.add("sortable");
      th.setAttribute("tabindex", "0");
      function sort() {
        var body = table.tBodies[0];
        var ascending = th.getAttribute("aria-sort") !== "ascending";
        heads.forEach(function (other) { other.removeAttribute("aria-sort"); });
        th.setAttribute("aria-sort", ascending ? "ascending" : "descending");
        var rows = Array.prototype.slice.call(body.rows).filter(function (r) { return !r.classList.contains("total"); });
        var totals = Array.prototype.slice.call(body.rows).filter(function (r) { return r.classList.contains("total"); });
        rows.sort(function (r1, r2) {
          var order = compare(cellValue(r1, index), cellValue(r2, index));
          return ascending ? order : -order;
        });
        rows.concat(totals).forEach(function (r) { body.appendChild(r); });
      }
      th.addEventListener("click", sort);
      th.addEventListener("keydown", function (e) { if (e.key === "Enter") sort(); });
    });
  }

  function makeFilter(input) {
    var table = document.getElementById(input.getAttribute("data-table"));
    if (!table) return;
    input.addEventListener("input", function () {
      var words = input.value.toLowerCase().split(/\s+/).filter(Boolean);
      Array.prototype.forEach.call(table.tBodies[0].rows, function (row) {
        var text = row.textContent.toLowerCase();
        row.hidden = !words.every(function (w) { return text.indexOf(w) >= 0; });
      });
    });
  }

  function nearest(xs, x) {
    var lo = 0, hi = xs.length - 1;
    while (hi - lo > 1) {
      var mid = (lo + hi) >> 1;
      if (xs[mid] <= x) lo = mid; else hi = mid;
    }
    return Math.abs(xs[hi] - x) < Math.abs(xs[lo] - x) ? hi : lo;
  }

  function format(value, digits) {
    if (value === null || value === undefined || !isFinite(value)) return "–";
    return Number(value).toFixed(digits);
  }

  var groups = {}, pinned = {}, pickers = {};

  // the scene player (player.js) pins a time cursor on a group's charts and hears where a chart is clicked
  window.vrusimCharts = {
    cursor: function (group, x) {
      pinned[group] = x;
      (groups[group] || []).forEach(function (show) { show(x); });
    },
    onPick: function (group, listener) { (pickers[group] = pickers[group] || []).push(listener); },
  };

  function makeChart(box) {
    var svg = box.querySelector("svg");
    var spec = JSON.parse(box.querySelector("script.chart-data").textContent);
    var readout = box.querySelector(".readout");
    var cross = svg.querySelector(".crosshair");
    var dots = svg.querySelectorAll(".dot");
    var hidden = {};
    var mx = spec.x_map, my = spec.y_map;
    function toPx(x) { return mx[2] + (x - mx[0]) / (mx[1] - mx[0]) * (mx[3] - mx[2]); }
    function toPy(y) { return my[2] + (y - my[0]) / (my[1] - my[0]) * (my[3] - my[2]); }
    function fromPx(px) { return mx[0] + (px - mx[2]) / (mx[3] - mx[2]) * (mx[1] - mx[0]); }

    function show(x) {
      if (x !== null && (x < Math.min(mx[0], mx[1]) || x > Math.max(mx[0], mx[1]))) x = null;  // off this chart
      if (x === null) {
        cross.setAttribute("visibility", "hidden");
        dots.forEach(function (d) { d.setAttribute("visibility", "hidden"); });
        readout.textContent = spec.hint;
        return;
      }
      var px = toPx(x);
      cross.setAttribute("x1", px); cross.setAttribute("x2", px);
      cross.setAttribute("visibility", "visible");
      var parts = [spec.x_label + " = " + format(x, spec.x_digits)];
      spec.series.forEach(function (s, i) {
        var dot = dots[i];
        if (hidden[i] || !s.x.length) { dot.setAttribute("visibility", "hidden"); return; }
        var k = nearest(s.x, x);
        var y = s.y[k];
        if (y === null || !isFinite(y) || Math.abs(s.x[k] - x) > spec.snap) {
          dot.setAttribute("visibility", "hidden");
          parts.push(s.name + " –");
          return;
        }
        dot.setAttribute("cx", toPx(s.x[k])); dot.setAttribute("cy", toPy(Math.min(Math.max(y, my[0]), my[1])));
        dot.setAttribute("visibility", "visible");
        var extra = s.labels ? " (" + s.labels[k] + ")" : "";
        parts.push(s.name + " " + format(y, s.digits) + (s.unit ? " " + s.unit : "") + extra);
      });
      readout.textContent = parts.join("  ·  ");
    }

    function pointer(event) {
      var point = svg.createSVGPoint();
      point.x = event.clientX; point.y = event.clientY;
      var local = point.matrixTransform(svg.getScreenCTM().inverse());
      if (local.x < Math.min(mx[2], mx[3]) || local.x > Math.max(mx[2], mx[3])) return null;
      return fromPx(local.x);
    }

    var members = spec.group ? (groups[spec.group] = groups[spec.group] || []) : [];
    members.push(show);
    function broadcast(x) { (spec.group ? members : [show]).forEach(function (f) { f(x); }); }
    svg.addEventListener("mousemove", function (e) { broadcast(pointer(e)); });
    svg.addEventListener("mouseleave", function () {
      broadcast(spec.group && pinned[spec.group] !== undefined ? pinned[spec.group] : null);
    });
    svg.addEventListener("click", function (e) {
      var x = pointer(e);
      if (x !== null && spec.group) (pickers[spec.group] || []).forEach(function (f) { f(x); });
    });

    box.querySelectorAll(".legend button").forEach(function (button) {
      button.addEventListener("click", function () {
        var i = Number(button.getAttribute("data-series"));
        hidden[i] = !hidden[i];
        button.setAttribute("aria-pressed", hidden[i] ? "false" : "true");
        svg.querySelectorAll('[data-series="' + i + '"]').forEach(function (el) {
          el.setAttribute("visibility", hidden[i] ? "hidden" : "visible");
        });
      });
    });
    show(spec.group && pinned[spec.group] !== undefined ? pinned[spec.group] : null);
    box.setAttribute("data-ready", "true");
  }

  document.querySelectorAll("table.data").forEach(makeSortable);
  document.querySelectorAll("input.filter").forEach(makeFilter);
  document.querySelectorAll("div.chart").forEach(makeChart);
  document.body.setAttribute("data-ready", "true");
})();
