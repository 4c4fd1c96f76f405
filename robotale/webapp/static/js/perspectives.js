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

  // A figure is drawn when its box is on screen; the others when they scroll into view or,
  // once everything on screen is drawn, one by one while the browser is idle: plotly draws on
  // the page's only thread, and the figures below the fold (a 3D scatter among them) would
  // otherwise hold up the first sight of the page.
  const observer = new IntersectionObserver((entries) => {
    for (const entry of entries) if (entry.isIntersecting) draw(entry.target).catch(robotale.showError);
  });

  function draw(box) {
    if (!box.drawing) {
      observer.unobserve(box);
      const started = performance.now();
      box.drawing = robotalePerspective.plot(box, box.figure).then(() =>
        performance.measure(`robotale-plot ${box.dataset.section}`, { start: started }));
    }
    return box.drawing;
  }

  function onScreen(box) {
    const { top, bottom, left, right } = box.getBoundingClientRect();
    return bottom > 0 && top < window.innerHeight && right > 0 && left < window.innerWidth;
  }

  function pending() {
    return [...section.querySelectorAll(".figure")].filter((box) => !box.drawing);
  }

  function drawVisible() {
    return Promise.all(pending().filter(onScreen).map(draw));
  }

  // The figures on screen of the sections above which every section is shown: where they
  // are will not move any more (one still loading would push what is below it down).
  function drawSettled() {
    const settled = [];
    for (const article of section.querySelectorAll("article.perspective")) {
      if (article.dataset.state === "loading") break;
      settled.push(...article.querySelectorAll(".figure"));
    }
    return Promise.all(settled.filter((box) => !box.drawing && onScreen(box)).map(draw));
  }

  function idle() {
    return new Promise((resolve) => (window.requestIdleCallback || setTimeout)(resolve));
  }

  async function drawRest() {
    for (const box of pending()) {
      await idle();
      if (box.isConnected) await draw(box);
    }
  }

  async function showOne(article, focus) {
    const name = article.dataset.name;
    const summary = article.querySelector(".summary");
    const figures = article.querySelector(".figures");
    const tables = article.querySelector(".table-box");
    summary.textContent = "loading…";
    article.dataset.state = "loading";
    try {
      const asked = performance.now();
      const result = await robotalePerspective.load(log, name, focus);
      performance.measure(`robotale-fetch ${name}`, { start: asked });
      summary.textContent = result.message
        ? sentence(result.message)
        : robotalePerspective.summaryText(result.summary);
      article.querySelector(".highlights").replaceChildren(...highlights(name, result));
      for (const old of figures.children) observer.unobserve(old);
      figures.replaceChildren();
      const boxes = Object.values(result.figures).filter(hasPoints).map((figure) => {
        const box = robotale.el("div", { class: "figure", "data-section": name });
        box.figure = figure;
        return box;
      });
      figures.append(...boxes);
      tables.replaceChildren();
      for (const [title, rows] of Object.entries(result.tables)) {
        if (!rows.length) continue;
        const columns = Object.keys(rows[0]);
        tables.append(robotale.el("h3", { text: title.replace(/_/g, " ") }),
          robotale.table(columns, rows.slice(0, 50).map((row) => columns.map((c) => row[c]))));
      }
      article.dataset.state = result.message ? "empty" : "shown";
      await drawSettled();
    } catch (error) {
      summary.textContent = "";
      article.dataset.state = "failed";
      robotale.showError(error);
    }
  }

  // Every section shown, and every figure on screen once they all are.
  async function show(focus) {
    focusLabel.textContent = robotalePerspective.describe(focus);
    wholeLog.hidden = !focus;
    const url = new URL(window.location.href);
    url.search = robotalePerspective.query(log, focus);
    window.history.replaceState(null, "", url);
    await Promise.all([...section.querySelectorAll("article.perspective")].map((a) => showOne(a, focus)));
    await drawVisible();
    pending().forEach((box) => observer.observe(box));
  }

  async function start() {
    log = await robotale.currentLog().catch((error) => { robotale.showError(error); return ""; });
    if (!log) {
      focusLabel.textContent = "no log yet: upload one on the Logs page";
      return;
    }
    // a log nobody prepared: wait for its preparation (its requests then say what is wrong)
    await robotale.prepared(log, "perspectives").catch(() => {});
    const info = (await robotale.logs()).find((l) => l.name === log) || { entityTypes: [] };
    const by = (info.entityTypes || []).includes("robot") ? "&by=robot" : "";
    robotalePerspective.preload();
    const focus = initialFocus();
    const figures = show(focus);
    try {
      const asked = performance.now();
      const graph = await robotale.api(`/api/discover/ekg?log=${encodeURIComponent(log)}${by}`);
      performance.measure("robotale-fetch graph", { start: asked });
      const started = performance.now();
      robotaleGraph.draw(graphBox, graph, { maxEdges: 150, onSelect: (node) => {
        const chosen = robotalePerspective.focusOf(node);
        if (chosen) show(chosen).then(drawRest).catch(robotale.showError);
      } });
      performance.measure("robotale-draw graph", { start: started });
    } catch (error) {
      robotale.showError(error);
    }
    await figures;
    // every section, the figures on screen and the graph drawn (what benchmarks/dashboard.py
    // times); then the figures below the fold
    performance.mark("robotale-perspectives-drawn");
    await drawRest();
    performance.mark("robotale-perspectives-all-drawn");
  }

  wholeLog.addEventListener("click", () => show(null).then(drawRest).catch(robotale.showError));
  start();
})();
