// Perspectives (robotale.enhancement's Perspective JSON) drawn with plotly, shared by the
// Discover page (a clicked node's spatial figure) and the Perspectives page (all of them).
"use strict";

const robotalePerspective = (() => {
  const script = document.currentScript;
  // The activity / robot a node of a process graph stands for. An EKG class carries its key's
  // values; a DFG node is an activity, of one robot only when the graph was filtered to it.
  function focusOf(node, robotFilter = []) {
    if (!node || node.kind !== "activity") return null;
    const key = node.properties || {};
    const activity = key.activity !== undefined ? key.activity : node.label;
    let robot = key.robot !== undefined ? key.robot : null;
    if (robot === null && robotFilter.length === 1) robot = robotFilter[0];
    return { activity, robot };
  }

  function describe(focus) {
    if (!focus) return "the whole log";
    return focus.robot ? `${focus.activity} by ${focus.robot}` : focus.activity;
  }

  function query(log, focus) {
    const params = new URLSearchParams({ log });
    if (focus && focus.activity) params.set("activity", focus.activity);
    if (focus && focus.robot) params.set("robot", focus.robot);
    // the page's own delay threshold (seconds), if the user gave one
    const delay = new URLSearchParams(window.location.search).get("delay");
    if (delay) params.set("delay", delay);
    return params.toString();
  }

  function load(log, name, focus) {
    return robotale.api(`/api/perspectives/${name}?${query(log, focus)}`);
  }

  // The full plotly.js is 4.8 MB of script to parse; its partial bundles of the same version
  // draw the perspectives' figures from a third of that: cartesian (scatter, bar, box) and
  // gl3d (scatter3d). Each is fetched and parsed only when a figure first needs it, so it never
  // delays the process graph; a trace type neither has takes the full bundle.
  const BUNDLES = {
    cartesian: {
      url: script.dataset.plotlyCartesian,
      types: new Set(["bar", "box", "contour", "heatmap", "histogram", "histogram2d",
        "histogram2dcontour", "image", "pie", "scatter", "scatterternary", "violin"]),
    },
    gl3d: {
      url: script.dataset.plotlyGl3d,
      types: new Set(["scatter", "scatter3d", "surface", "mesh3d", "isosurface", "volume",
        "cone", "streamtube"]),
    },
    full: { url: script.dataset.plotly, types: null },
  };
  const loading = {};

  function bundleOf(figure) {
    const types = (figure.data || []).map((trace) => trace.type || "scatter");
    const fits = (name) => BUNDLES[name].url && types.every((t) => BUNDLES[name].types.has(t));
    return ["cartesian", "gl3d"].find(fits) || "full";
  }

  // Every bundle sets window.Plotly: each one's own is kept as it loads.
  function plotlyReady(name = "full") {
    loading[name] = loading[name] || new Promise((resolve, reject) => {
      const asked = performance.now();
      const tag = document.createElement("script");
      tag.src = BUNDLES[name].url;
      tag.onload = () => {
        performance.measure(`robotale-plotly.js ${name}`, { start: asked });
        resolve(window.Plotly);
      };
      tag.onerror = () => reject(new Error(`plotly.js (${name}) could not be loaded.`));
      document.head.append(tag);
    });
    return loading[name];
  }

  // Start fetching and parsing the bundle of the figures most pages draw, before any arrives.
  function preload() {
    plotlyReady(BUNDLES.cartesian.url ? "cartesian" : "full").catch(() => {});
  }

  async function plot(box, figure) {
    const Plotly = await plotlyReady(bundleOf(figure));
    // a box drawn by another bundle is that bundle's to clear
    if (box.robotalePlotly && box.robotalePlotly !== Plotly) box.robotalePlotly.purge(box);
    box.robotalePlotly = Plotly;
    const layout = { ...figure.layout, autosize: true, margin: { l: 40, r: 20, t: 40, b: 40 } };
    await Plotly.react(box, figure.data, layout, { responsive: true, displaylogo: false });
    box.dataset.plotted = String(figure.data.length);
  }

  // A figure drawn with WebGL (plotly's gl3d bundle: a 3D scatter): 1-2 s of the page's only
  // thread and of the compositor with software rendering, during which the page answers
  // nothing, not even a click on a link; such a figure is drawn only once it is in the window.
  function isHeavy(figure) {
    return bundleOf(figure) === "gl3d";
  }

  // Calls `draw` once at least `share` of `box` is in the window (at once if it is; of a box
  // taller than the window, `share` of the window), saying in an empty box meanwhile that it
  // is drawn when scrolled to; a later call for the same box replaces a draw not yet begun
  // (the newer data) and begins after one under way. Resolves with what `draw` resolves with.
  const waiting = new WeakMap();
  const underWay = new WeakMap();
  const STEPS = Array.from({ length: 21 }, (_, i) => i / 20);
  function whenShown(box, draw, share = 0) {
    const earlier = waiting.get(box);
    if (earlier) earlier.disconnect();
    return new Promise((resolve, reject) => {
      let note = box.querySelector(":scope > .placeholder");
      if (!note && !box.robotalePlotly) {
        note = robotale.el("p", { class: "placeholder hint", text: "drawn when scrolled into view" });
        box.prepend(note);
      }
      const enough = (entry) => entry.isIntersecting && entry.intersectionRect.height
        >= share * Math.min(entry.boundingClientRect.height, window.innerHeight);
      const observer = new IntersectionObserver((entries) => {
        if (!entries.some(enough)) return;
        observer.disconnect();
        waiting.delete(box);
        if (note) note.textContent = "drawing…";
        // the note goes once the figure is there (or could not be drawn)
        const done = (underWay.get(box) || Promise.resolve()).catch(() => {}).then(draw);
        underWay.set(box, done);
        done.then(resolve, reject).finally(() => note && note.remove());
      }, { threshold: STEPS });
      waiting.set(box, observer);
      observer.observe(box);
    });
  }

  function summaryText(summary) {
    return Object.entries(summary || {})
      .filter(([, value]) => value === null || typeof value !== "object")
      .map(([key, value]) => `${key.replace(/_/g, " ")}: ${typeof value === "number" && !Number.isInteger(value) ? value.toFixed(2) : value}`)
      .join(" · ");
  }

  return { focusOf, describe, query, load, preload, plot, isHeavy, whenShown, summaryText };
})();
