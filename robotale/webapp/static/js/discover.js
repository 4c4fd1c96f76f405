// The Discover page: the aggregated EKG (default) or the DFG of the chosen log, drawn as an
// interactive graph; a click on a node shows its figures and its spatial perspective.
"use strict";

(() => {
  const graphBox = document.getElementById("graph");
  const status = document.getElementById("graph-status");
  const labels = document.getElementById("labels");
  const edgeLimit = document.getElementById("edge-limit");
  // Above this many edges a graph is spaghetti to read and slow to lay out: draw the most
  // frequent ones and let the user ask for more.
  const DEFAULT_EDGES = 150;
  const ekgForm = document.getElementById("ekg-form");
  const dfgForm = document.getElementById("dfg-form");
  const aggregationForm = document.getElementById("aggregation-form");
  const levelBox = document.getElementById("aggregation-level");
  const state = { log: "", view: "ekg", graph: null, robotFilter: [], edges: DEFAULT_EDGES };

  function setView(view) {
    state.view = view;
    for (const tab of document.querySelectorAll(".tab")) tab.classList.toggle("active", tab.dataset.view === view);
    for (const form of document.querySelectorAll(".view-form")) form.hidden = form.dataset.view !== view;
  }

  function selected(name) {
    return [...dfgForm.elements[name].selectedOptions].map((option) => option.value);
  }

  function graphUrl() {
    const params = new URLSearchParams({ log: state.log });
    if (state.view === "aggregation") {
      params.append("level", levelBox.value);
      return `/api/aggregation/graph?${params}`;
    }
    if (state.view === "ekg") {
      for (const box of ekgForm.querySelectorAll("input[name=by]:checked")) params.append("by", box.value);
      for (const box of ekgForm.querySelectorAll("input[name=edges]:checked")) params.append("edges", box.value);
      return `/api/discover/ekg?${params}`;
    }
    for (const name of ["case", "robot", "robot_type", "activity"]) {
      for (const value of selected(name)) params.append(name, value);
    }
    return `/api/discover/dfg?${params}`;
  }

  // Each call numbers its request: an answer that arrives after a newer call (a slow first
  // graph, then a tab clicked) is dropped instead of drawing over what the user asked for last.
  let latest = 0;

  async function discover() {
    const mine = ++latest;
    robotale.clearError();
    if (state.view === "aggregation" && !levelBox.value) {
      status.textContent = "No aggregation steps yet: run a specification.";
      graphBox.replaceChildren();
      return;
    }
    status.textContent = "discovering…";
    state.robotFilter = state.view === "dfg" ? selected("robot") : [];
    let graph;
    try {
      graph = await robotale.api(graphUrl());
    } catch (error) {
      if (mine !== latest) return;
      status.textContent = "";
      robotale.showError(error);
      return;
    }
    if (mine !== latest) return;
    state.graph = graph;
    draw();
  }

  function draw() {
    const graph = state.graph;
    const activities = graph.nodes.filter((n) => n.kind === "activity").length;
    status.textContent = graph.kind === "aggregates"
      ? `Level ${graph.level}: ${graph.nodes.length} aggregates, ${graph.edges.length} edges`
      : `${graph.kind.toUpperCase()}: ${activities} activities, ${graph.edges.length} edges`;
    graphBox.dataset.kind = graph.kind;
    showNode(null);
    const total = graph.edges.length;
    edgeLimit.max = String(Math.max(10, Math.ceil(total / 10) * 10));
    edgeLimit.value = String(Math.min(state.edges, Number(edgeLimit.max)));
    const limit = state.edges >= total ? 0 : state.edges;
    document.getElementById("edge-limit-value").textContent =
      limit ? `the ${limit} most frequent of ${total}` : `all ${total}`;
    robotaleGraph.draw(graphBox, graph, {
      labels: labels.value,
      maxEdges: limit,
      legend: document.getElementById("legend"),
      onSelect: showNode,
    });
  }

  function showNode(node) {
    const details = document.getElementById("details");
    const figureBox = document.getElementById("node-figure");
    const focus = robotalePerspective.focusOf(node, state.robotFilter);
    if (!node || !focus) {
      details.hidden = true;
      figureBox.hidden = true;
      if (graphBox._cy) graphBox._cy.resize();
      return;
    }
    document.getElementById("details-title").textContent = robotalePerspective.describe(focus);
    const durations = node.durations || {};
    const rows = [["instances", node.count],
      ["robots", (node.robots || []).join(", ")]];
    if (durations.mean !== undefined && durations.mean !== null) {
      rows.push(["mean duration", robotaleGraph.seconds(durations.mean)],
        ["median duration", robotaleGraph.seconds(durations.median)]);
    }
    for (const [key, value] of Object.entries(node.properties || {})) {
      if (key !== "activity" && key !== "robot") rows.push([key, value]);
    }
    document.getElementById("details-table").replaceChildren(
      ...rows.map(([k, v]) => robotale.el("tr", {}, robotale.el("th", { text: k }), robotale.el("td", { text: String(v) }))));
    document.getElementById("details-link").href =
      `/perspectives?${robotalePerspective.query(state.log, focus)}`;
    details.hidden = false;
    showSpatial(focus); // shows the figure's panel at once, then loads the figure
    // Bring the node and its neighbours into view; "fit" shows the whole graph again.
    const cy = graphBox._cy;
    cy.animate({ fit: { eles: cy.getElementById(node.id).closedNeighborhood(), padding: 30 } },
      { duration: 250 });
  }

  async function showSpatial(focus) {
    const figureBox = document.getElementById("node-figure");
    const message = document.getElementById("node-figure-message");
    const plotBox = document.getElementById("spatial-figure");
    if (figureBox.hidden) {
      figureBox.hidden = false;
      graphBox._cy.resize(); // the graph just got narrower
    }
    document.getElementById("node-figure-title").textContent =
      `Where ${robotalePerspective.describe(focus)} happened`;
    message.textContent = "loading…";
    delete plotBox.dataset.plotted;
    try {
      const spatial = await robotalePerspective.load(state.log, "spatial", focus);
      const figure = Object.values(spatial.figures)[0];
      message.textContent = spatial.message || robotalePerspective.summaryText(spatial.summary);
      if (figure) await robotalePerspective.plot(plotBox, figure);
      else plotBox.replaceChildren();
    } catch (error) {
      message.textContent = "";
      robotale.showError(error);
    }
  }

  function fillSelectors(log, values) {
    const rows = document.querySelector("#aggregation tbody");
    for (const type of log.entityTypes || []) {
      const flow = robotale.el("input", { type: "checkbox", name: "edges", value: type, "aria-label": `flow of ${type}` });
      const by = robotale.el("input", { type: "checkbox", name: "by", value: type, "aria-label": `aggregate by ${type}` });
      flow.checked = true;
      by.checked = type === "robot";
      rows.append(robotale.el("tr", { "data-type": type }, robotale.el("td", { text: type }),
        robotale.el("td", {}, flow), robotale.el("td", {}, by)));
    }
    if (!values) return;
    for (const [name, options] of Object.entries(values.filters)) {
      const select = document.getElementById(`filter-${name}`);
      select.replaceChildren(...options.map((v) => robotale.el("option", { value: v, text: v })));
    }
  }

  // The steps stored for the log: a table, and the levels one can draw (the last by default).
  async function loadSteps() {
    const { steps } = await robotale.api(`/api/aggregation/steps?log=${encodeURIComponent(state.log)}`);
    document.getElementById("aggregation-steps").replaceChildren(...steps.map((step) =>
      robotale.el("tr", {}, robotale.el("th", { text: `step ${step.step}` }),
        robotale.el("td", { text: `${step.aggregates ?? 0} aggregates` }),
        robotale.el("td", { text: step.spec }))));
    levelBox.replaceChildren(...steps.map((step) =>
      robotale.el("option", { value: String(step.step), text: `after step ${step.step}` })));
    if (steps.length) levelBox.value = String(steps[steps.length - 1].step);
  }

  async function aggregation(path, body) {
    robotale.clearError();
    status.textContent = "aggregating…";
    try {
      await robotale.api(path, { method: "POST", body: { log: state.log, ...body } });
    } catch (error) {
      status.textContent = "";
      robotale.showError(error);
    }
    await loadSteps().catch(robotale.showError);
    discover();
  }

  async function start() {
    state.log = await robotale.currentLog().catch((error) => { robotale.showError(error); return ""; });
    if (!state.log) {
      status.textContent = "No log yet: upload one on the Logs page.";
      return;
    }
    const log = (await robotale.logs()).find((l) => l.name === state.log) || { entityTypes: [] };
    fillSelectors(log, null);
    loadSteps().catch(robotale.showError);
    await discover();
    robotale.api(`/api/discover/values?log=${encodeURIComponent(state.log)}`)
      .then((values) => fillSelectors({}, values))
      .catch(robotale.showError);
  }

  for (const tab of document.querySelectorAll(".tab")) {
    tab.addEventListener("click", () => { setView(tab.dataset.view); discover(); });
  }
  for (const form of [ekgForm, dfgForm]) {
    form.addEventListener("submit", (event) => { event.preventDefault(); discover(); });
  }
  aggregationForm.addEventListener("submit", (event) => {
    event.preventDefault();
    aggregation("/api/aggregation/run", { spec: document.getElementById("aggregation-spec").value });
  });
  document.getElementById("aggregation-undo").addEventListener("click",
    () => aggregation("/api/aggregation/undo", {}));
  levelBox.addEventListener("change", discover);
  dfgForm.addEventListener("reset", () => setTimeout(discover, 0));
  ekgForm.addEventListener("change", discover);
  labels.addEventListener("change", () => state.graph && draw());
  edgeLimit.addEventListener("change", () => {
    state.edges = Number(edgeLimit.value);
    if (state.graph) draw();
  });
  document.getElementById("zoom-in").addEventListener("click", () => robotaleGraph.zoom(graphBox, 1.25));
  document.getElementById("zoom-out").addEventListener("click", () => robotaleGraph.zoom(graphBox, 0.8));
  document.getElementById("fit").addEventListener("click", () => graphBox._cy && graphBox._cy.fit(undefined, 20));
  start();
})();
