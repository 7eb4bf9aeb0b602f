// report.html's image comparison (inlined by crates/experiment/src/html.rs). Each scene has one
// viewer: a stack of same-sized pictures of which one is shown, switched by its buttons, by the
// keys 1..9 and the left/right arrows (in the viewer last under the mouse or clicked), zoomed by
// the wheel (about the cursor), the +/- buttons and keys, panned by dragging; 0, "fit" or a
// double click fits the picture. The view (zoom and offset) belongs to the viewer, not to a
// picture, so switching compares the same region.
(function () {
  "use strict";
  var viewers = [];
  var active = null;
  var MIN_SCALE = 0.05, MAX_SCALE = 512, STEP = 1.25;

  function activate(v) {
    if (active === v) return;
    if (active) active.root.classList.remove("active");
    active = v;
    v.root.classList.add("active");
  }

  function makeViewer(root) {
    var stage = root.querySelector(".stage");
    var layer = root.querySelector(".layer");
    var shots = Array.prototype.slice.call(root.querySelectorAll(".layer img"));
    var tabs = Array.prototype.slice.call(root.querySelectorAll("button[data-show]"));
    var caption = root.querySelector(".caption");
    var level = root.querySelector(".zoom-level");
    var w = Number(root.getAttribute("data-width")) || 1;
    var h = Number(root.getAttribute("data-height")) || 1;
    var v = { root: root, index: 0, count: shots.length, s: 1, tx: 0, ty: 0, fitted: true };

    function apply() {
      layer.style.transform = "translate(" + v.tx + "px," + v.ty + "px) scale(" + v.s + ")";
      if (level) level.textContent = (v.s * 100).toFixed(v.s < 1 ? 1 : 0) + " %";
    }
    v.fit = function () {
      var r = stage.getBoundingClientRect();
      var s = Math.min(r.width / w, r.height / h);
      // Whole pixels when enlarging, so every pixel is the same size on screen.
      if (s >= 1) s = Math.floor(s);
      v.s = isFinite(s) && s > 0 ? s : 1;
      v.tx = Math.round((r.width - w * v.s) / 2);
      v.ty = Math.round((r.height - h * v.s) / 2);
      v.fitted = true;
      apply();
    };
    v.zoom = function (factor, cx, cy) {
      var r = stage.getBoundingClientRect();
      if (cx === undefined) { cx = r.width / 2; cy = r.height / 2; }
      var s = Math.min(MAX_SCALE, Math.max(MIN_SCALE, v.s * factor));
      var f = s / v.s;
      v.tx = cx - (cx - v.tx) * f;
      v.ty = cy - (cy - v.ty) * f;
      v.s = s;
      v.fitted = false;
      apply();
    };
    v.show = function (i) {
      if (i < 0 || i >= shots.length) return;
      v.index = i;
      for (var k = 0; k < shots.length; k++) {
        shots[k].classList.toggle("on", k === i);
      }
      for (var t = 0; t < tabs.length; t++) {
        tabs[t].classList.toggle("on", Number(tabs[t].getAttribute("data-show")) === i);
      }
      if (caption) caption.textContent = shots[i].getAttribute("data-caption") || shots[i].alt;
    };
    v.step = function (d) {
      v.show((v.index + d + shots.length) % shots.length);
    };

    tabs.forEach(function (b) {
      b.addEventListener("click", function () {
        activate(v);
        v.show(Number(b.getAttribute("data-show")));
      });
    });
    root.querySelectorAll("button[data-zoom]").forEach(function (b) {
      b.addEventListener("click", function () {
        activate(v);
        var z = b.getAttribute("data-zoom");
        if (z === "in") v.zoom(STEP);
        else if (z === "out") v.zoom(1 / STEP);
        else if (z === "one") v.zoom(1 / v.s);
        else v.fit();
      });
    });
    root.addEventListener("pointerenter", function () { activate(v); });
    root.addEventListener("pointerdown", function () { activate(v); });
    stage.addEventListener("wheel", function (e) {
      e.preventDefault();
      var r = stage.getBoundingClientRect();
      v.zoom(e.deltaY < 0 ? STEP : 1 / STEP, e.clientX - r.left, e.clientY - r.top);
    }, { passive: false });
    var drag = null;
    stage.addEventListener("pointerdown", function (e) {
      if (e.button !== 0) return;
      drag = { x: e.clientX, y: e.clientY, tx: v.tx, ty: v.ty };
      stage.setPointerCapture(e.pointerId);
      stage.classList.add("dragging");
    });
    stage.addEventListener("pointermove", function (e) {
      if (!drag) return;
      v.tx = drag.tx + e.clientX - drag.x;
      v.ty = drag.ty + e.clientY - drag.y;
      v.fitted = false;
      apply();
    });
    function endDrag() {
      drag = null;
      stage.classList.remove("dragging");
    }
    stage.addEventListener("pointerup", endDrag);
    stage.addEventListener("pointercancel", endDrag);
    stage.addEventListener("dblclick", function () { v.fit(); });
    v.show(0);
    v.fit();
    return v;
  }

  document.querySelectorAll(".viewer").forEach(function (root) {
    viewers.push(makeViewer(root));
  });
  if (viewers.length) activate(viewers[0]);

  window.addEventListener("resize", function () {
    viewers.forEach(function (v) { if (v.fitted) v.fit(); });
  });

  document.addEventListener("keydown", function (e) {
    if (!active || e.ctrlKey || e.metaKey || e.altKey) return;
    var tag = e.target && e.target.tagName;
    if (tag === "INPUT" || tag === "TEXTAREA" || tag === "SELECT") return;
    var k = e.key;
    if (k.length === 1 && k >= "1" && k <= "9") active.show(Number(k) - 1);
    else if (k === "ArrowRight") active.step(1);
    else if (k === "ArrowLeft") active.step(-1);
    else if (k === "+" || k === "=") active.zoom(STEP);
    else if (k === "-") active.zoom(1 / STEP);
    else if (k === "0") active.fit();
    else return;
    e.preventDefault();
  });
})();
