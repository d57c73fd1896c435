// The 3-D views of reports/index.html: each div.view3d holds a canvas, its controls and
// the decimated geometry of both formulations (harness/src/view3d.rs) as JSON. Canvas 2-D with a
// perspective camera orbiting the model: drag to rotate, wheel to zoom, play/pause and a time
// slider. No network, no library: works from file://.
(function () {
  "use strict";
  var COLORS = { ancf: [0, 114, 178], gebf: [213, 94, 0] };
  var errors = [];
  function report(msg) {
    errors.push(String(msg));
    var box = document.getElementById("js-errors");
    if (box) { box.textContent = errors.join("\n"); box.hidden = false; }
    document.documentElement.setAttribute("data-js-errors", String(errors.length));
  }
  window.addEventListener("error", function (e) { report(e.message || e); });
  window.addEventListener("unhandledrejection", function (e) { report(e.reason || "unhandled rejection"); });

  function rgba(c, a) { return "rgba(" + c[0] + "," + c[1] + "," + c[2] + "," + a + ")"; }

  function View(root) {
    this.root = root;
    this.canvas = root.querySelector("canvas");
    this.ctx = this.canvas.getContext("2d");
    this.data = JSON.parse(root.querySelector("script.view-data").textContent);
    this.runs = [];
    var self = this;
    ["ancf", "gebf"].forEach(function (f) {
      var d = self.data[f];
      if (d && d.frames && d.frames.length) { self.runs.push({ f: f, d: d }); }
    });
    this.t0 = Infinity; this.t1 = -Infinity;
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    this.runs.forEach(function (r) {
      var s = r.d.scale;
      r.d.frames.forEach(function (fr) {
        self.t0 = Math.min(self.t0, fr.t); self.t1 = Math.max(self.t1, fr.t);
        var grow = function (a) {
          for (var i = 0; i + 2 < a.length; i += 3) {
            for (var k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], a[i + k] * s); hi[k] = Math.max(hi[k], a[i + k] * s); }
          }
        };
        fr.beams.forEach(grow); surfacesOf(fr).forEach(function (sf) { grow(sf.le); grow(sf.te); });
      });
    });
    if (!isFinite(this.t0)) { this.t0 = 0; this.t1 = 1; }
    this.center = [0, 1, 2].map(function (k) { return isFinite(lo[k]) ? 0.5 * (lo[k] + hi[k]) : 0; });
    var diag = 0;
    for (var k = 0; k < 3; k++) { if (isFinite(lo[k])) { diag += (hi[k] - lo[k]) * (hi[k] - lo[k]); } }
    this.radius = Math.max(Math.sqrt(diag) / 2, 1e-3);
    this.hasAero = this.runs.some(function (r) { return r.d.frames[0].le.length > 0; });
    this.reset();
    // Open on the last frame: the deformed structure and its whole wake; Play starts from t0.
    this.t = this.t1;
    this.playing = false;
    this.show = { ancf: true, gebf: true };
    this.bind();
    this.slider.value = "1000";
    this.draw();
  }

  View.prototype.reset = function () {
    this.yaw = -0.5; this.pitch = 0.6; this.zoom = 1;
  };

  View.prototype.bind = function () {
    var self = this, c = this.canvas, drag = null;
    c.addEventListener("pointerdown", function (e) { drag = [e.clientX, e.clientY]; c.setPointerCapture(e.pointerId); });
    c.addEventListener("pointermove", function (e) {
      if (!drag) { return; }
      self.yaw += 0.01 * (e.clientX - drag[0]);
      self.pitch = Math.max(-1.5, Math.min(1.5, self.pitch + 0.01 * (e.clientY - drag[1])));
      drag = [e.clientX, e.clientY];
      self.draw();
    });
    c.addEventListener("pointerup", function () { drag = null; });
    c.addEventListener("wheel", function (e) {
      e.preventDefault();
      self.zoom = Math.max(0.2, Math.min(20, self.zoom * Math.exp(-0.001 * e.deltaY)));
      self.draw();
    }, { passive: false });
    var slider = this.root.querySelector("input.time");
    slider.addEventListener("input", function () {
      self.t = self.t0 + (self.t1 - self.t0) * slider.value / 1000;
      self.draw();
    });
    this.slider = slider;
    var play = this.root.querySelector("button.play");
    play.addEventListener("click", function () {
      self.playing = !self.playing;
      play.textContent = self.playing ? "Pause" : "Play";
      if (self.playing) {
        if (self.t >= self.t1) { self.t = self.t0; }
        self.last = null;
        requestAnimationFrame(function (ts) { self.tick(ts); });
      }
    });
    this.playButton = play;
    ["ancf", "gebf"].forEach(function (f) {
      var box = self.root.querySelector("input.show-" + f);
      if (box) { box.addEventListener("change", function () { self.show[f] = box.checked; self.draw(); }); }
    });
    this.root.querySelector("button.reset").addEventListener("click", function () { self.reset(); self.draw(); });
  };

  // Plays the run in about 8 s of screen time, whatever its length.
  View.prototype.tick = function (ts) {
    if (!this.playing) { return; }
    if (this.last !== null) {
      this.t += (this.t1 - this.t0) * (ts - this.last) / 8000;
    }
    this.last = ts;
    if (this.t >= this.t1) {
      this.t = this.t1; this.playing = false; this.playButton.textContent = "Play";
    }
    this.slider.value = String(Math.round(1000 * (this.t - this.t0) / Math.max(this.t1 - this.t0, 1e-12)));
    this.draw();
    var self = this;
    if (this.playing) { requestAnimationFrame(function (t2) { self.tick(t2); }); }
  };

  // The last frame at or before t.
  // The lifting surfaces of a frame: the first one's fields sit on the frame itself.
  function surfacesOf(fr) {
    return [fr].concat(fr.more_surfaces || []);
  }

  function frameAt(frames, t) {
    var lo = 0, hi = frames.length - 1;
    if (t <= frames[0].t) { return frames[0]; }
    while (lo < hi) {
      var mid = (lo + hi + 1) >> 1;
      if (frames[mid].t <= t + 1e-12) { lo = mid; } else { hi = mid - 1; }
    }
    return frames[lo];
  }

  View.prototype.project = function (x, y, z) {
    var px = x - this.center[0], py = y - this.center[1], pz = z - this.center[2];
    var cy = Math.cos(this.yaw), sy = Math.sin(this.yaw), cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    var xr = cy * px + sy * py, yr = -sy * px + cy * py;
    var depth = cp * yr + sp * pz, up = -sp * yr + cp * pz;
    var dist = 3.2 * this.radius;
    var w = this.canvas.width, h = this.canvas.height;
    var f = this.zoom * 1.1 * Math.min(w, h) / (2 * this.radius) * dist / Math.max(dist - depth, 0.05 * dist);
    return [w / 2 + f * xr, h / 2 - f * up, depth];
  };

  View.prototype.points = function (a, s) {
    var out = [];
    for (var i = 0; i + 2 < a.length; i += 3) { out.push(this.project(a[i] * s, a[i + 1] * s, a[i + 2] * s)); }
    return out;
  };

  View.prototype.line = function (pts, color, width) {
    if (pts.length < 2) { return; }
    var g = this.ctx;
    g.strokeStyle = color; g.lineWidth = width;
    g.beginPath(); g.moveTo(pts[0][0], pts[0][1]);
    for (var i = 1; i < pts.length; i++) { g.lineTo(pts[i][0], pts[i][1]); }
    g.stroke();
  };

  View.prototype.axes = function () {
    var g = this.ctx, o = this.project(this.center[0], this.center[1], this.center[2]);
    var len = 0.15 * this.radius, names = ["X", "Y", "Z"], cols = ["#c00", "#080", "#00c"];
    var ox = 40 - o[0], oy = this.canvas.height - 40 - o[1];
    for (var k = 0; k < 3; k++) {
      var p = this.center.slice(); p[k] += len;
      var q = this.project(p[0], p[1], p[2]);
      g.strokeStyle = cols[k]; g.lineWidth = 2;
      g.beginPath(); g.moveTo(o[0] + ox, o[1] + oy); g.lineTo(q[0] + ox, q[1] + oy); g.stroke();
      g.fillStyle = cols[k]; g.font = "12px sans-serif";
      g.fillText(names[k], q[0] + ox + 3, q[1] + oy + 3);
    }
  };

  View.prototype.draw = function () {
    var g = this.ctx, self = this;
    g.fillStyle = "#fff"; g.fillRect(0, 0, this.canvas.width, this.canvas.height);
    this.runs.forEach(function (r) {
      if (!self.show[r.f]) { return; }
      var fr = frameAt(r.d.frames, self.t), s = r.d.scale, col = COLORS[r.f] || [0, 0, 0];
      surfacesOf(fr).forEach(function (sf) {
        // Wake: a grid of lines.
        if (sf.wake_rows > 0) {
          var w = self.points(sf.wake, s), nr = sf.wake_rows, nc = sf.wake_cols, i, j, row;
          for (i = 0; i < nr; i++) { self.line(w.slice(i * nc, (i + 1) * nc), rgba(col, 0.35), 1); }
          for (j = 0; j < nc; j++) {
            row = [];
            for (i = 0; i < nr; i++) { row.push(w[i * nc + j]); }
            self.line(row, rgba(col, 0.35), 1);
          }
        }
        // Wing: translucent panels between leading and trailing edge, and both edges.
        if (sf.le.length > 0) {
          var le = self.points(sf.le, s), te = self.points(sf.te, s);
          g.fillStyle = rgba(col, 0.18);
          for (var k = 0; k + 1 < le.length; k++) {
            g.beginPath(); g.moveTo(le[k][0], le[k][1]); g.lineTo(le[k + 1][0], le[k + 1][1]);
            g.lineTo(te[k + 1][0], te[k + 1][1]); g.lineTo(te[k][0], te[k][1]); g.closePath(); g.fill();
          }
          self.line(le, rgba(col, 0.9), 1.5); self.line(te, rgba(col, 0.9), 1.5);
          // Control surfaces: the flap between its hinge line and the deflected trailing edge.
          (sf.flaps || []).forEach(function (f) {
            var pts = self.points(f, s), h = pts.slice(0, pts.length / 2), e = pts.slice(pts.length / 2);
            g.fillStyle = rgba(col, 0.4);
            for (var k = 0; k + 1 < h.length; k++) {
              g.beginPath(); g.moveTo(h[k][0], h[k][1]); g.lineTo(h[k + 1][0], h[k + 1][1]);
              g.lineTo(e[k + 1][0], e[k + 1][1]); g.lineTo(e[k][0], e[k][1]); g.closePath(); g.fill();
            }
            self.line(h, rgba(col, 0.9), 1);
            self.line([h[0], e[0]], rgba(col, 0.9), 1); self.line([h[h.length - 1], e[e.length - 1]], rgba(col, 0.9), 1);
          });
        }
      });
      // Beams, and the chord direction of each section for structures without a lattice.
      var tick = 0.06 * self.radius;
      fr.beams.forEach(function (b, bi) {
        var p = self.points(b, s);
        self.line(p, rgba(col, 1), 3);
        if (!self.hasAero) {
          var e = fr.e2[bi];
          for (var n = 0; n < p.length; n++) {
            var x = b[3 * n] * s, y = b[3 * n + 1] * s, z = b[3 * n + 2] * s;
            var q = self.project(x + tick * e[3 * n] / 100, y + tick * e[3 * n + 1] / 100, z + tick * e[3 * n + 2] / 100);
            self.line([p[n], q], rgba(col, 0.8), 1.5);
          }
        }
        if (p.length) {
          g.fillStyle = rgba(col, 1);
          g.beginPath(); g.arc(p[p.length - 1][0], p[p.length - 1][1], 3.5, 0, 2 * Math.PI); g.fill();
        }
      });
    });
    this.axes();
    g.fillStyle = "#000"; g.font = "13px sans-serif";
    var label = "t = " + this.t.toFixed(3) + " s";
    g.fillText(label, 10, 18);
    var x = 10;
    this.runs.forEach(function (r) {
      g.fillStyle = rgba(COLORS[r.f] || [0, 0, 0], 1);
      g.fillText(r.f.toUpperCase(), x, 36); x += 50;
    });
    var tl = this.root.querySelector(".tlabel");
    if (tl) { tl.textContent = label; }
  };

  // How many pixels of the canvas are not background: the browser test reads it from the DOM.
  View.prototype.inked = function () {
    var img = this.ctx.getImageData(0, 0, this.canvas.width, this.canvas.height).data, n = 0;
    for (var i = 0; i < img.length; i += 4) {
      if (img[i] < 250 || img[i + 1] < 250 || img[i + 2] < 250) { n++; }
    }
    return n;
  };

  function init() {
    var views = document.querySelectorAll("div.view3d"), drawn = 0;
    for (var i = 0; i < views.length; i++) {
      try {
        var v = new View(views[i]);
        views[i].setAttribute("data-inked", String(v.inked()));
        drawn++;
      } catch (e) {
        report("3-D view " + views[i].getAttribute("data-view") + ": " + e);
      }
    }
    document.documentElement.setAttribute("data-views-drawn", String(drawn));
  }
  if (document.readyState === "loading") { document.addEventListener("DOMContentLoaded", init); } else { init(); }
})();
