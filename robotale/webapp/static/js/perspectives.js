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
  // the page's only thread, and the figures below the fold would otherwise hold up the first
  // sight of the page. A 3D figure (WebGL) is drawn only when it is in the window, after the
  // first view: it takes the page's thread for seconds (robotalePerspective.isHeavy).
  const observer = new IntersectionObserver((entries) => {
    for (const entry of entries) if (entry.isIntersecting) draw(entry.target).catch(robotale.showError);
  });

  // the figure drawn, and its drawing time marked for the benchmark (robotale-plot SECTION)
  function plotTimed(box) {
    const started = performance.now();
    return robotalePerspective.plot(box, box.figure).then(() =>
      performance.measure(`robotale-plot ${box.dataset.section}`, { start: started }));
  }

  function draw(box) {
    if (!box.drawing) {
      observer.unobserve(box);
      box.drawing = plotTimed(box);
    }
    return box.drawing;
  }

  function onScreen(box) {
    const { top, bottom, left, right } = box.getBoundingClientRect();
    return bottom > 0 && top < window.innerHeight && right > 0 && left < window.innerWidth;
  }

  // the figures not drawn yet, but those drawn only in the window
  function pending() {
    return [...section.querySelectorAll(".figure")].filter((box) => !box.drawing && !box.heavy);
  }

  function drawWhenShown(box) {
    box.drawing = robotalePerspective.whenShown(box, () => plotTimed(box));
    box.drawing.catch(robotale.showError);
  }

  function drawVisible() {
    return Promise.all(pending().filter(onScreen).map(draw));
  }

  // The figures on screen of the sections above which every section is shown: where they
  // are will not move any more (one still loading would push what is below it down).
  function drawSettled() {
    const settled = [];
    for (const article of section.querySelectorAll("article.perspective")) {
      if (["waiting", "loading"].includes(article.dataset.state)) break;
      settled.push(...article.querySelectorAll(".figure"));
    }
    return Promise.all(settled.filter((box) => !box.drawing && !box.heavy && onScreen(box)).map(draw));
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
        box.heavy = robotalePerspective.isHeavy(figure);
        if (box.heavy) box.append(robotale.el("p", { class: "placeholder hint", text: "3D figure: drawn when scrolled into view" }));
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

  // A section whose heading is in the window: the first sight of the page includes it.
  function inView(article) {
    return article.getBoundingClientRect().top < window.innerHeight;
  }

  // The sections one after the other, in the page's order (the dashboard computes one result
  // of a log at a time, so asking for all at once only delays the first): those in the window
  // first, their figures drawn; resolves then with the promise of the others, which load
  // while the user looks (each says "loading…" until it is shown). A later call (another
  // focus) stops the loading of the sections an earlier one had not reached.
  let generation = 0;
  async function show(focus) {
    const mine = ++generation;
    focusLabel.textContent = robotalePerspective.describe(focus);
    wholeLog.hidden = !focus;
    const url = new URL(window.location.href);
    url.search = robotalePerspective.query(log, focus);
    window.history.replaceState(null, "", url);
    const articles = [...section.querySelectorAll("article.perspective")];
    for (const article of articles) {
      article.dataset.state = "waiting";
      article.querySelector(".summary").textContent = "loading…";
    }
    let next = 0;
    while (next < articles.length && inView(articles[next])) await showOne(articles[next++], focus);
    if (mine !== generation) return null;
    await drawVisible();
    const rest = (async () => {
      while (next < articles.length && mine === generation) await showOne(articles[next++], focus);
      if (mine !== generation) return;
      await drawVisible();
      pending().forEach((box) => observer.observe(box));
      section.querySelectorAll(".figure").forEach((box) => box.heavy && !box.drawing && drawWhenShown(box));
    })();
    return { rest };
  }

  async function start() {
    log = await robotale.currentLog().catch((error) => { robotale.showError(error); return ""; });
    if (!log) {
      focusLabel.textContent = "no log yet: upload one on the Logs page";
      return;
    }
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
        if (chosen) show(chosen).then(whole).then(drawRest).catch(robotale.showError);
      } });
      performance.measure("robotale-draw graph", { start: started });
    } catch (error) {
      robotale.showError(error);
    }
    const shown = await figures;
    // the sections in the window, their figures and the graph drawn (what
    // benchmarks/dashboard.py times); then the sections below it and their figures (a 3D
    // figure when it is scrolled into view)
    performance.mark("robotale-perspectives-drawn");
    await whole(shown);
    await drawRest();
    performance.mark("robotale-perspectives-all-drawn");
    // a log nobody prepared: its other pages' results are prepared now, in the dashboard
    // (asked once, not awaited: this page shows all it has)
    robotale.api(`/api/preparation?${new URLSearchParams({ log, page: "perspectives" })}`).catch(() => {});
  }

  // the sections below the window too, once they are loaded
  async function whole(shown) {
    if (shown && shown.rest) await shown.rest;
  }

  wholeLog.addEventListener("click", () => show(null).then(whole).then(drawRest).catch(robotale.showError));
  start();
})();
