// Injected by tests/html.rs at the top of a copy of report.html. Records console errors and
// failed loads from the start, and after the load event (every image loaded or failed) checks
// the page and writes what it found into <pre id="rt-check">, one finding per line, which
// Chromium's --dump-dom prints.
(function () {
  "use strict";
  var problems = [];
  var notes = [];
  var oldError = console.error, oldWarn = console.warn;
  console.error = function () {
    problems.push("console.error: " + Array.prototype.join.call(arguments, " "));
    return oldError.apply(console, arguments);
  };
  console.warn = function () {
    problems.push("console.warn: " + Array.prototype.join.call(arguments, " "));
    return oldWarn.apply(console, arguments);
  };
  window.addEventListener("error", function (e) {
    var t = e.target;
    if (t && t !== window && (t.src || t.href)) problems.push("failed to load: " + (t.src || t.href));
    else problems.push("script error: " + e.message + " at " + e.filename + ":" + e.lineno);
  }, true);
  window.addEventListener("unhandledrejection", function (e) {
    problems.push("unhandled rejection: " + e.reason);
  });

  function shown(viewer) {
    var imgs = viewer.querySelectorAll(".stage img");
    var on = [];
    for (var i = 0; i < imgs.length; i++) {
      if (getComputedStyle(imgs[i]).display !== "none") on.push(imgs[i]);
    }
    return on;
  }
  function key(k) {
    document.dispatchEvent(new KeyboardEvent("keydown", { key: k, bubbles: true, cancelable: true }));
  }

  function check() {
    var imgs = document.images;
    notes.push("images " + imgs.length);
    for (var i = 0; i < imgs.length; i++) {
      var img = imgs[i];
      if (!img.complete || !(img.naturalWidth > 0)) {
        problems.push("image not shown (naturalWidth " + img.naturalWidth + "): " + img.getAttribute("src"));
      }
    }
    var viewers = document.querySelectorAll(".viewer");
    notes.push("viewers " + viewers.length);
    for (var v = 0; v < viewers.length; v++) {
      var root = viewers[v];
      var pics = root.querySelectorAll(".stage img");
      var name = "viewer " + (v + 1);
      root.dispatchEvent(new Event("pointerdown", { bubbles: true }));
      key("1");
      var first = shown(root);
      if (first.length !== 1 || first[0] !== pics[0]) {
        problems.push(name + ": key 1 shows " + first.length + " pictures, not the first alone");
        continue;
      }
      if (pics.length < 2) {
        problems.push(name + ": fewer than two pictures");
        continue;
      }
      // Zoom in about a point, then switch: the view must stay.
      var stage = root.querySelector(".stage");
      var layer = root.querySelector(".layer");
      var before = layer.style.transform;
      stage.dispatchEvent(new WheelEvent("wheel", { deltaY: -100, clientX: 10, clientY: 10, bubbles: true, cancelable: true }));
      var zoomed = layer.style.transform;
      if (zoomed === before) problems.push(name + ": the wheel did not zoom (" + before + ")");
      key("2");
      var second = shown(root);
      if (second.length !== 1 || second[0] !== pics[1]) {
        problems.push(name + ": key 2 did not show the second picture");
      }
      if (layer.style.transform !== zoomed) {
        problems.push(name + ": switching changed the view from " + zoomed + " to " + layer.style.transform);
      }
      key("ArrowRight");
      var third = shown(root);
      var want = pics[2 % pics.length];
      if (third.length !== 1 || third[0] !== want) problems.push(name + ": ArrowRight did not show the next picture");
      key("ArrowLeft");
      var back = shown(root);
      if (back.length !== 1 || back[0] !== pics[1]) problems.push(name + ": ArrowLeft did not go back");
      var buttons = root.querySelectorAll("button[data-show]");
      if (buttons.length !== pics.length) problems.push(name + ": " + buttons.length + " buttons for " + pics.length + " pictures");
      else {
        buttons[0].click();
        if (shown(root)[0] !== pics[0]) problems.push(name + ": clicking the first button did not show the first picture");
      }
      notes.push(name + " pictures " + pics.length);
    }
  }

  window.addEventListener("load", function () {
    try {
      check();
    } catch (e) {
      problems.push("check failed: " + e);
    }
    var pre = document.createElement("pre");
    pre.id = "rt-check";
    pre.textContent = notes.concat(problems.map(function (p) { return "PROBLEM " + p; })).join("\n") + "\nEND";
    document.body.appendChild(pre);
  });
})();
