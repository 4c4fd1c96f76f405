// The Perspectives page: the four perspectives for the whole log or for the node clicked in
// the process graph beside them (thesis figure 7.8).
"use strict";

(() => {
  const section = document.getElementById("perspectives");
  const graphBox = document.getElementById("graph");
  const focusLabel = document.getElementById("focus-label");
  const wholeLog = document.getElementById("whole-log");
  let log = "";

  function initialFocus() {
    const { activity, robot } = section.dataset;
    return activity ? { activity, robot: robot || null } : null;
  }

  function sentence(text) {
    return text.charAt(0).toUpperCase() + text.slice(1);
  }

  // What an analyst looks for first, shown open: the bottleneck ranking in words and the
  // variants (the rest stays in the tables below).
  function highlights(name, result) {
    const tables = result.tables || {};
    if (name === "bottlenecks" && tables.bottlenecks) {
      const items = tables.bottlenecks.slice(0, 10).map((row) => robotale.el("li", { text: sentence(row.explanation) }));
      return [robotale.el("ol", { class: "ranking" }, ...items)];
    }
    if (name === "performance" && tables.variants && tables.variants.length) {
      const columns = ["cases", "share", "median", "activities", "variant"];
      const rows = tables.variants.slice(0, 10).map((row) => columns.map((c) =>
        (c === "share" ? `${Math.round(row.share * 100)}%` : row[c])));
      return [robotale.el("h3", { text: "variants" }), robotale.table(columns, rows)];
    }
    return [];
  }

  // A figure whose traces hold no point would be empty axes (a flat line at 0, say): the
  // summary says what is missing instead.
  function hasPoints(figure) {
    return (figure.data || []).some((trace) => ["x", "y", "z", "lat", "values"].some((axis) => {
      const values = trace[axis];
      return values !== undefined && values !== null && (!Array.isArray(values) || values.length > 0);
    }));
  }

  async function showOne(article, focus) {
    const name = article.dataset.name;
    const summary = article.querySelector(".summary");
    const figures = article.querySelector(".figures");
    const tables = article.querySelector(".table-box");
    summary.textContent = "loading…";
    article.dataset.state = "loading";
    try {
      const result = await robotalePerspective.load(log, name, focus);
      summary.textContent = result.message
        ? sentence(result.message)
        : robotalePerspective.summaryText(result.summary);
      article.querySelector(".highlights").replaceChildren(...highlights(name, result));
      figures.replaceChildren();
      for (const figure of Object.values(result.figures).filter(hasPoints)) {
        const box = robotale.el("div", { class: "figure" });
        figures.append(box);
        await robotalePerspective.plot(box, figure);
      }
      tables.replaceChildren();
      for (const [title, rows] of Object.entries(result.tables)) {
        if (!rows.length) continue;
        const columns = Object.keys(rows[0]);
        tables.append(robotale.el("h3", { text: title.replace(/_/g, " ") }),
          robotale.table(columns, rows.slice(0, 50).map((row) => columns.map((c) => row[c]))));
      }
      article.dataset.state = result.message ? "empty" : "shown";
    } catch (error) {
      summary.textContent = "";
      article.dataset.state = "failed";
      robotale.showError(error);
    }
  }

  function show(focus) {
    focusLabel.textContent = robotalePerspective.describe(focus);
    wholeLog.hidden = !focus;
    const url = new URL(window.location.href);
    url.search = robotalePerspective.query(log, focus);
    window.history.replaceState(null, "", url);
    return Promise.all([...section.querySelectorAll("article.perspective")].map((a) => showOne(a, focus)));
  }

  async function start() {
    log = await robotale.currentLog().catch((error) => { robotale.showError(error); return ""; });
    if (!log) {
      focusLabel.textContent = "no log yet: upload one on the Logs page";
      return;
    }
    const info = (await robotale.logs()).find((l) => l.name === log) || { entityTypes: [] };
    const by = (info.entityTypes || []).includes("robot") ? "&by=robot" : "";
    const focus = initialFocus();
    const figures = show(focus);
    try {
      const graph = await robotale.api(`/api/discover/ekg?log=${encodeURIComponent(log)}${by}`);
      robotaleGraph.draw(graphBox, graph, { maxEdges: 150, onSelect: (node) => {
        const chosen = robotalePerspective.focusOf(node);
        if (chosen) show(chosen);
      } });
    } catch (error) {
      robotale.showError(error);
    }
    await figures;
    // every section and the graph on screen (what benchmarks/dashboard.py times)
    performance.mark("robotale-perspectives-drawn");
  }

  wholeLog.addEventListener("click", () => show(null));
  start();
})();
