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

  function summaryText(summary) {
    return Object.entries(summary || {})
      .filter(([, value]) => value === null || typeof value !== "object")
      .map(([key, value]) => `${key.replace(/_/g, " ")}: ${typeof value === "number" && !Number.isInteger(value) ? value.toFixed(2) : value}`)
      .join(" · ");
  }

  return { focusOf, describe, query, load, preload, plot, summaryText };
})();
