// Perspectives (robotale.enhancement's Perspective JSON) drawn with plotly, shared by the
// Discover page (a clicked node's spatial figure) and the Perspectives page (all of them).
"use strict";

const robotalePerspective = (() => {
  const plotlyUrl = document.currentScript.dataset.plotly;
  let plotlyPromise = null;
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
    return params.toString();
  }

  function load(log, name, focus) {
    return robotale.api(`/api/perspectives/${name}?${query(log, focus)}`);
  }

  // plotly.js is 4.6 MB: fetched and parsed only when a figure is first drawn, so it never
  // delays the process graph.
  function plotlyReady() {
    plotlyPromise = plotlyPromise || new Promise((resolve, reject) => {
      const script = document.createElement("script");
      script.src = plotlyUrl;
      script.onload = () => resolve(window.Plotly);
      script.onerror = () => reject(new Error("plotly.js could not be loaded."));
      document.head.append(script);
    });
    return plotlyPromise;
  }

  async function plot(box, figure) {
    const Plotly = await plotlyReady();
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

  return { focusOf, describe, query, load, plot, summaryText };
})();
