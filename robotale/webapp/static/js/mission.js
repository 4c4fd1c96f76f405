// The Mission page: one time cursor over the map, the model, the timeline, a plot and the
// findings near the cursor. The server says where every robot was and what it was doing at the
// cursor (/api/mission/<log>/<case>/state); the page draws it.
"use strict";

(() => {
  const root = document.getElementById("mission");
  const slider = document.getElementById("cursor");
  const clock = document.getElementById("clock");
  const runPicker = document.getElementById("run-picker");
  const missing = document.getElementById("mission-missing");
  const map = document.getElementById("map");
  const canvasBox = document.getElementById("canvas");
  const timelineBox = document.getElementById("mission-timeline");
  const plotBox = document.getElementById("plot");
  const fieldPicker = document.getElementById("field");
  const momentList = document.getElementById("moments");
  const robotsBox = document.getElementById("robots");
  const SVG = "http://www.w3.org/2000/svg";
  // seconds a message stays drawn after it was sent, and a lost one's mark
  const MESSAGE_SHOWN = 2, LOST_SHOWN = 5;
  // findings this many seconds either side of the cursor are listed
  const SPAN = 30;
  const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"];
  document.getElementById("window-span").textContent = String(SPAN);

  let log = "", run = "", summary = null, whole = null, startMs = 0;
  let t = 0, playing = false, asked = 0, inFlight = false, again = false;
  let viewer = null, marked = [], markedFlows = [], markedWaits = [], markedDeviations = [];
  let series = null;

  const colour = (robot) => COLOURS[Math.max(0, summary.robots.indexOf(robot)) % COLOURS.length];
  const base = () => `/api/mission/${encodeURIComponent(log)}/${encodeURIComponent(run)}`;
  const plotly = () => timelineBox.robotalePlotly || plotBox.robotalePlotly;
  // plotly's dates carry no zone: the server's are UTC
  const plotDate = (seconds) => new Date(startMs + seconds * 1000).toISOString().replace("T", " ").replace("Z", "");
  const fromPlotDate = (text) => {
    const iso = String(text).replace(" ", "T");
    return (Date.parse(/[zZ]|[+-]\d\d:\d\d$/.test(iso) ? iso : `${iso}Z`) - startMs) / 1000;
  };

  function svg(tag, attributes = {}) {
    const node = document.createElementNS(SVG, tag);
    for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, String(value));
    return node;
  }

  function say(text) {
    missing.textContent = text;
    missing.hidden = !text;
  }

  // ---- the map: world units, y up ----------------------------------------------------------

  let extent = null, unit = 1;
  function mapExtent(site) {
    const xs = [], ys = [];
    if (site.field) { xs.push(0, site.field[0]); ys.push(0, site.field[1]); }
    for (const b of site.bases || []) { xs.push(b.x - b.radius, b.x + b.radius); ys.push(b.y - b.radius, b.y + b.radius); }
    // the positions' extent the server sent, until the positions themselves come
    if (site.source === "positions" && site.extent) { xs.push(site.extent[0], site.extent[2]); ys.push(site.extent[1], site.extent[3]); }
    for (const rows of Object.values(whole.positions)) for (const [, x, y] of rows) { xs.push(x); ys.push(y); }
    if (!xs.length) return null;
    const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
    const pad = Math.max(x1 - x0, y1 - y0, 1) * 0.06;
    return [x0 - pad, y0 - pad, x1 + pad, y1 + pad];
  }

  function drawSite(site) {
    map.replaceChildren();
    extent = mapExtent(site);
    if (!extent) {
      map.setAttribute("viewBox", "0 0 100 20");
      map.append(Object.assign(svg("text", { x: 2, y: 12, "font-size": 4 }), { textContent: "no positions in this run" }));
      map.dataset.extent = "";
      return;
    }
    const [x0, y0, x1, y1] = extent;
    unit = Math.max(x1 - x0, y1 - y0) / 100;
    map.setAttribute("viewBox", `${x0} ${-y1} ${x1 - x0} ${y1 - y0}`);
    map.dataset.extent = extent.join(" ");
    map.dataset.source = site.source || "";
    const places = svg("g", { class: "places" });
    if (site.field) {
      places.append(svg("rect", { x: 0, y: -site.field[1], width: site.field[0], height: site.field[1],
        fill: "#e8f3dc", stroke: "#7a9a5a", "vector-effect": "non-scaling-stroke", class: "field" }));
    }
    for (const b of site.bases || []) {
      const group = svg("g", { class: "base", "data-name": b.name });
      group.append(svg("circle", { cx: b.x, cy: -b.y, r: b.radius, fill: "#dde6f6", stroke: "#5a7ab4", "vector-effect": "non-scaling-stroke" }));
      group.append(Object.assign(svg("text", { x: b.x, y: -b.y + b.radius + 2.5 * unit, "font-size": 2.4 * unit, "text-anchor": "middle" }), { textContent: b.name }));
      places.append(group);
    }
    for (const o of site.obstacles || []) {
      places.append(svg("rect", { x: o.x - o.width / 2, y: -o.y - o.depth / 2, width: o.width, height: o.depth,
        fill: "#999", transform: `rotate(${-o.yaw} ${o.x} ${-o.y})`, class: "obstacle" }));
    }
    for (const o of site.objects || []) {
      places.append(svg("circle", { cx: o.x, cy: -o.y, r: 0.8 * unit, fill: "#2ca02c", class: "object", "data-kind": o.kind || "" }));
    }
    map.append(places, svg("g", { id: "trails" }), svg("g", { id: "messages" }), svg("g", { id: "robots-layer" }));
  }

  // the last recorded position of a robot at or before s (as the server's state computes it)
  function positionAt(robot, s) {
    const rows = whole.positions[robot] || [];
    let lo = 0, hi = rows.length - 1, found = null;
    while (lo <= hi) {
      const mid = (lo + hi) >> 1;
      if (rows[mid][0] <= s) { found = rows[mid]; lo = mid + 1; } else hi = mid - 1;
    }
    return found;
  }

  function drawTrails() {
    const layer = document.getElementById("trails");
    if (!layer) return;
    layer.replaceChildren(...Object.entries(whole.positions).map(([robot, rows]) => {
      const points = rows.filter((r) => r[0] <= t).map((r) => `${r[1]},${-r[2]}`).join(" ");
      return svg("polyline", { points, fill: "none", stroke: colour(robot), "stroke-width": 1.5, "stroke-opacity": 0.6,
        "vector-effect": "non-scaling-stroke", "data-robot": robot, class: "trail" });
    }));
  }

  function drawMessages() {
    const layer = document.getElementById("messages");
    if (!layer) return;
    const shapes = [];
    for (const m of whole.messages) {
      if (m.sent === null || m.sent > t) continue;
      const from = positionAt(m.sender, t);
      if (m.lost && t < m.sent + LOST_SHOWN) {
        const at = positionAt(m.sender, m.sent);
        if (at) {
          const d = 1.5 * unit, [x, y] = [at[1], -at[2]];
          const cross = svg("path", { d: `M${x - d},${y - d}L${x + d},${y + d}M${x - d},${y + d}L${x + d},${y - d}`,
            stroke: "#d62728", "stroke-width": 3, "vector-effect": "non-scaling-stroke", class: "lost", "data-msg": m.msg_id });
          shapes.push(cross);
        }
      } else if (!m.lost && t < m.sent + MESSAGE_SHOWN && from) {
        for (const receiver of String(m.receiver || "").split(", ")) {
          const to = positionAt(receiver, t);
          if (!to || receiver === m.sender) continue;
          shapes.push(svg("line", { x1: from[1], y1: -from[2], x2: to[1], y2: -to[2], stroke: "#555", "stroke-dasharray": "4 3",
            "stroke-width": 1.5, "vector-effect": "non-scaling-stroke", class: "message", "data-msg": m.msg_id }));
        }
      }
    }
    layer.replaceChildren(...shapes);
  }

  function drawRobots(state) {
    const layer = document.getElementById("robots-layer");
    if (!layer) return;
    const marks = [];
    for (const [robot, facts] of Object.entries(state.robots)) {
      if (!facts.pose) continue;
      const { x, y, z } = facts.pose;
      const group = svg("g", { class: "robot", "data-robot": robot, "data-x": x, "data-y": y, "data-z": z ?? "",
        "data-activity": facts.activities.join(", ") });
      group.append(svg("circle", { cx: x, cy: -y, r: 1.6 * unit, fill: colour(robot), stroke: "white", "vector-effect": "non-scaling-stroke" }));
      if (facts.heading !== null) {
        const length = 3.5 * unit;
        group.append(svg("line", { x1: x, y1: -y, x2: x + length * Math.cos(facts.heading), y2: -y - length * Math.sin(facts.heading),
          stroke: colour(robot), "stroke-width": 2.5, "vector-effect": "non-scaling-stroke", class: "heading" }));
      }
      const flying = z !== null && z > 0.05 ? ` ↑${z.toFixed(1)} m` : "";
      const label = `${robot}${flying}${facts.activities.length ? `: ${facts.activities.join(", ")}` : ""}`;
      group.append(Object.assign(svg("text", { x: x + 2 * unit, y: -y - 2 * unit, "font-size": 2.6 * unit }), { textContent: label }));
      marks.push(group);
    }
    layer.replaceChildren(...marks);
  }

  // ---- the model ---------------------------------------------------------------------------

  async function loadModel(modelId) {
    if (!modelId) {
      canvasBox.replaceChildren(robotale.el("p", { class: "hint", text: "No model: link one to this log on the Model page." }));
      canvasBox.dataset.rendered = "none";
      return;
    }
    viewer = new BpmnJS({ container: canvasBox });
    const response = await fetch(`/api/models/${modelId}.bpmn`);
    if (!response.ok) throw new Error((await response.json()).error);
    await viewer.importXML(await response.text());
    viewer.get("canvas").zoom("fit-viewport", "auto");
    canvasBox.dataset.rendered = "1";
  }

  function paintModel(state) {
    if (!viewer || !state.elements) return;
    const canvas = viewer.get("canvas");
    const registry = viewer.get("elementRegistry");
    for (const id of marked) canvas.removeMarker(id, "active");
    for (const id of markedFlows) canvas.removeMarker(id, "taken");
    for (const id of markedWaits) canvas.removeMarker(id, "waiting");
    for (const id of markedDeviations) canvas.removeMarker(id, "deviation");
    const active = [...new Set(Object.values(state.elements).flat())].filter((id) => registry.get(id)).sort();
    const flows = Object.keys(state.flows || {}).filter((id) => registry.get(id)).sort();
    for (const id of active) canvas.addMarker(id, "active");
    for (const id of flows) canvas.addMarker(id, "taken");
    // catch events a robot waits at: the flows brought it there, the event has not come yet
    const waits = [...new Set(Object.values(state.waiting || {}).flat())].filter((id) => registry.get(id)).sort();
    for (const id of waits) canvas.addMarker(id, "waiting");
    marked = active;
    markedFlows = flows;
    markedWaits = waits;
    canvasBox.dataset.waiting = waits.join(" ");
    // elements a robot started, by the cursor, where its pool's model did not allow it
    const deviated = [...new Set(Object.values(state.deviations || {}).flat())].filter((id) => registry.get(id)).sort();
    for (const id of deviated) canvas.addMarker(id, "deviation");
    markedDeviations = deviated;
    canvasBox.dataset.deviations = deviated.join(" ");
    canvasBox.dataset.active = active.join(" ");
    canvasBox.dataset.taken = flows.map((id) => `${id}:${state.flows[id]}`).join(" ");
  }

  // ---- the timeline and the plot -----------------------------------------------------------

  function cursorShape(x) {
    return { type: "line", xref: "x", yref: "paper", x0: x, x1: x, y0: 0, y1: 1, line: { color: "#111", width: 2 } };
  }

  // The timeline and the plot are drawn once a quarter of each is in the window (at once if it
  // is): plotly draws a run's thousands of bars and message arrows in one go of the page's only
  // thread (about a second), during which the page would answer nothing; below the first view
  // they wait until scrolled to. Their data is there before: the values at the cursor, the
  // page's `loaded`. Resolves when the answer is there (the drawing is `timelineBox.drawing`).
  const SHOWN_SHARE = 0.25;
  async function loadTimeline() {
    const data = await robotale.api(`/api/timeline?${new URLSearchParams({ log, case: run })}`);
    timelineBox.drawing = robotalePerspective.whenShown(timelineBox, async () => {
      const first = !timelineBox.dataset.drawn;
      await robotalePerspective.plot(timelineBox, data.figure);
      timelineBox.dataset.drawn = "1";
      if (first) timelineBox.on("plotly_click", (event) => {
        const point = event.points[0];
        if (!point) return;
        const at = point.base !== undefined ? point.base : point.x;
        setCursor(fromPlotDate(at));
      });
      moveLines(); // the cursor may have moved since the answer came
    }, SHOWN_SHARE);
    timelineBox.drawing.catch(robotale.showError);
  }

  async function loadSeries(field) {
    if (!field) return;
    const data = await robotale.api(`${base()}/series?${new URLSearchParams({ field })}`);
    series = data;
    showValues();
    plotBox.drawing = robotalePerspective.whenShown(plotBox, async () => {
      const traces = Object.entries(data.robots).map(([robot, rows]) => ({
        type: "scatter", mode: "lines", name: robot, x: rows.map((r) => r[0]), y: rows.map((r) => r[1]),
        line: { color: colour(robot), shape: "hv" },
      }));
      const layout = { xaxis: { title: "seconds" }, yaxis: { title: field }, shapes: [cursorShape(t)], height: 320,
        legend: { orientation: "h" } };
      await robotalePerspective.plot(plotBox, { data: traces, layout });
      plotBox.dataset.field = field;
      plotBox.on("plotly_click", (event) => event.points[0] && setCursor(event.points[0].x));
    }, SHOWN_SHARE);
    plotBox.drawing.catch(robotale.showError);
  }

  // each robot's plotted value at the cursor: its last sample at or before it
  function showValues() {
    if (!series) return;
    const rows = Object.entries(series.robots).map(([robot, points]) => {
      let value = null;
      for (const [s, v] of points) { if (s <= t) value = v; else break; }
      return [robot, value];
    });
    const table = robotale.table(["robot", series.field], rows.map(([r, v]) => [r, v === null ? null : Number(v.toFixed(4))]));
    table.id = "plot-values";
    rows.forEach(([robot, value], i) => {
      const row = table.tBodies[0].rows[i];
      row.dataset.robot = robot;
      row.dataset.value = value === null ? "" : String(value);
    });
    const old = document.getElementById("plot-values");
    if (old) old.replaceWith(table); else plotBox.after(table);
  }

  function moveLines() {
    const Plotly = plotly();
    if (!Plotly) return;
    if (timelineBox.dataset.drawn) Plotly.relayout(timelineBox, { shapes: [cursorShape(plotDate(t))] });
    if (plotBox.dataset.field) Plotly.relayout(plotBox, { shapes: [cursorShape(t)] });
  }

  // ---- the findings near the cursor and the robots' table ----------------------------------

  function listMoments() {
    const near = summary.moments.filter((m) => Math.abs(m.s - t) <= SPAN);
    momentList.replaceChildren(...near.map((m) => {
      const item = robotale.el("li", { text: `${m.s.toFixed(1)} s · ${m.kind}: ${m.text}` });
      item.dataset.s = String(m.s);
      item.dataset.kind = m.kind;
      item.addEventListener("click", () => setCursor(m.s));
      return item;
    }));
    if (!near.length) momentList.replaceChildren(robotale.el("li", { class: "hint", text: "nothing here" }));
  }

  function listRobots(state) {
    const number = (v, digits = 2) => (v === null || v === undefined ? null : Number(v.toFixed(digits)));
    robotsBox.replaceChildren(robotale.table(["robot", "x", "y", "z", "heading °", "battery", "doing", "last message"],
      Object.entries(state.robots).map(([robot, f]) => [robot, number(f.pose && f.pose.x), number(f.pose && f.pose.y),
        number(f.pose && f.pose.z), f.heading === null ? null : Math.round((f.heading * 180) / Math.PI), number(f.battery, 1),
        f.activities.join(", "), f.last_message ? `${f.last_message.msg_id} ${f.last_message.role} ${f.last_message.with || ""}${f.last_message.lost ? " (lost)" : ""}` : ""])));
  }

  // ---- the cursor --------------------------------------------------------------------------

  async function fetchState() {
    if (inFlight) { again = true; return; }
    inFlight = true;
    const at = t;
    try {
      const state = await robotale.api(`${base()}/state?t=${encodeURIComponent(at)}${held()}`);
      if (at === t || !again) {
        drawRobots(state);
        paintModel(state);
        listRobots(state);
        if (!performance.getEntriesByName("robotale-mission-shown").length) {
          performance.mark("robotale-mission-shown"); // the first state drawn (benchmarks/live.py)
        }
        if (root.dataset.loaded) { // every view is there: the page is shown at `at`
          root.dataset.shown = String(at);
          root.dataset.state = "shown";
        }
      }
    } catch (error) {
      robotale.showError(error);
    } finally {
      inFlight = false;
      if (again) { again = false; fetchState(); }
    }
  }

  function setCursor(seconds, options = {}) {
    if (!summary) return;
    t = Math.min(Math.max(Number(seconds) || 0, 0), summary.duration);
    slider.value = String(t);
    clock.textContent = `${t.toFixed(2)} s of ${summary.duration.toFixed(1)} s · ${plotDate(t)} UTC`;
    root.dataset.t = String(t);
    drawTrails();
    drawMessages();
    listMoments();
    showValues();
    if (!options.playing) {
      moveLines();
      const url = new URL(window.location.href);
      url.searchParams.set("t", t.toFixed(2));
      window.history.replaceState(null, "", url);
    }
    fetchState();
  }

  function step(direction) {
    const times = summary.event_times;
    const found = direction > 0 ? times.find((s) => s > t + 1e-6) : [...times].reverse().find((s) => s < t - 1e-6);
    if (found !== undefined) setCursor(found);
  }

  let last = 0, lastLines = 0;
  function frame(now) {
    if (!playing) return;
    const speed = Number(document.getElementById("speed").value);
    t = Math.min(t + ((now - last) / 1000) * speed, summary.duration);
    last = now;
    setCursor(t, { playing: true });
    if (now - lastLines > 250) { moveLines(); lastLines = now; }
    if (t >= summary.duration) { pause(); return; }
    requestAnimationFrame(frame);
  }

  function play() {
    if (t >= summary.duration) t = 0;
    playing = true;
    document.getElementById("play").textContent = "pause";
    last = performance.now();
    requestAnimationFrame(frame);
  }

  function pause() {
    playing = false;
    document.getElementById("play").textContent = "play";
    setCursor(t);
  }

  function wire() {
    slider.addEventListener("input", () => setCursor(Number(slider.value)));
    document.getElementById("play").addEventListener("click", () => (playing ? pause() : play()));
    document.getElementById("previous").addEventListener("click", () => step(-1));
    document.getElementById("next").addEventListener("click", () => step(1));
    fieldPicker.addEventListener("change", () => loadSeries(fieldPicker.value).catch(robotale.showError));
    runPicker.addEventListener("change", () => {
      const url = new URL(window.location.href);
      url.searchParams.set("case", runPicker.value);
      url.searchParams.delete("t");
      window.location.assign(url);
    });
    document.addEventListener("keydown", (event) => {
      if (event.target.closest("input:not([type=range]), select, textarea")) return;
      if (event.key === " ") { event.preventDefault(); playing ? pause() : play(); }
      else if (event.key === "ArrowRight") { event.preventDefault(); step(1); }
      else if (event.key === "ArrowLeft") { event.preventDefault(); step(-1); }
      else if (event.key === "Home") setCursor(0);
      else if (event.key === "End") setCursor(summary.duration);
    });
  }

  // ---- a live run: the page follows now -----------------------------------------------------

  // a look at a live run waits on the server until the run grows (at most LIVE_WAIT seconds), so
  // a tag shows as soon as it is stored rather than at the next of looks a fixed time apart; the
  // timeline is redrawn at most every TIMELINE_EVERY seconds, after an error the next look waits
  const LIVE_WAIT = 10, TIMELINE_EVERY = 5, AFTER_ERROR = 1;
  let timelineDrawn = 0;
  // the cursor follows the run's end while it is there; moved back, it stays where it was put
  const following = () => summary.duration - t < 1e-6;
  // a live run's state asked of the run the page's summary was made of, kept on the server
  const held = () => (root.dataset.live === "1" && summary && Number.isInteger(summary.events) ? `&events=${summary.events}` : "");

  async function followLive() {
    const since = Math.max(0, summary.duration - OVERLAP);
    let fresh = await robotale.api(`${base()}?since=${since}&known=${summary.events}&wait=${LIVE_WAIT}`);
    // only what may have changed from `since` on came: the rest is what the page holds, unless
    // a late tag changed it (then the whole summary is asked again)
    const kept = summary.event_times.filter((s) => s < since);
    if (kept.length !== fresh.times_before) fresh = await robotale.api(base());
    else {
      fresh.event_times = kept.concat(fresh.event_times);
      fresh.instances = summary.instances
        .filter((i) => i.end !== null && i.end < since)
        .concat(fresh.instances)
        .sort((a, b) => a.start - b.start || (a.robot < b.robot ? -1 : a.robot > b.robot ? 1 : 0));
    }
    if (fresh.events === summary.events) return;
    const stay = !following();
    await growWhole(since, fresh.duration, fresh.events);
    summary = fresh;
    slider.max = String(summary.duration);
    root.dataset.duration = String(summary.duration);
    root.dataset.following = stay ? "0" : "1";
    if (!playing) setCursor(stay ? t : summary.duration);
    if (performance.now() - timelineDrawn > TIMELINE_EVERY * 1000) {
      timelineDrawn = performance.now();
      await loadTimeline();
    }
  }

  // seconds before the last look's end the next look asks again from: samples stored a little
  // after the tags of their time (odometry is stored beside the tags) are not missed
  const OVERLAP = 5;
  // the run's positions and messages from `from` to `to` seconds merged into what the page
  // holds, instead of the whole run again at every look
  // holding `events`: the run the summary showing them was made of, kept on the server (not
  // made again of the tags stored since: the next look reads them)
  async function growWhole(from, to, events) {
    const fresh = await robotale.api(`${base()}/window?from=${from}&to=${to}&events=${events}`);
    for (const [robot, rows] of Object.entries(fresh.positions)) {
      whole.positions[robot] = (whole.positions[robot] || []).filter((r) => r[0] < from).concat(rows);
    }
    const ids = new Set(fresh.messages.map((m) => m.msg_id));
    whole.messages = whole.messages.filter((m) => !ids.has(m.msg_id)).concat(fresh.messages);
  }

  function watchLive() {
    root.dataset.live = "1";
    const look = () => followLive().then(look, (error) => {
      robotale.showError(error);
      setTimeout(look, AFTER_ERROR * 1000);
    });
    timelineDrawn = performance.now();
    look();
  }

  // the first moment is drawn from a small answer (the run's head and its state at the cursor);
  // the run's event times, findings, positions, timeline, model and plot come after it
  async function start() {
    log = await robotale.currentLog().catch(() => "");
    if (!log) { say("No log yet: upload one on the Logs page."); root.dataset.state = "empty"; return; }
    try {
      const runsAsked = robotale.api(`/api/timeline/runs?log=${encodeURIComponent(log)}`);
      run = root.dataset.case || "";
      if (!run) { const { runs } = await runsAsked; run = runs.length ? String(runs[0].case) : ""; }
      const listed = runsAsked.then(({ runs }) => {
        runPicker.replaceChildren(...runs.map((r) => robotale.el("option", { value: String(r.case), text: String(r.case) })));
        runPicker.value = run;
      });
      summary = { ...(await robotale.api(`${base()}/head`)), event_times: [], moments: [] };
      whole = { positions: {}, messages: [] };
      startMs = Date.parse(summary.start);
      slider.max = String(summary.duration);
      const notes = [];
      if (!summary.has_positions) notes.push("This run records no positions, so the map is empty.");
      else if (summary.site.source === "positions") notes.push("No world file for this run: the map spans the positions it records.");
      if (!summary.model) notes.push("No model is linked to this log, so no elements are shown: link one on the Model page.");
      say(notes.join(" "));
      root.dataset.missing = [summary.has_positions ? "" : "positions", summary.model ? "" : "model"].filter(Boolean).join(" ");
      drawSite(summary.site);
      fieldPicker.replaceChildren(...summary.signals.map((f) => robotale.el("option", { value: f, text: f })));
      if (summary.signals.includes("battery")) fieldPicker.value = "battery";
      wire();
      const asked = root.dataset.t === "" ? (summary.live ? summary.duration : 0) : Number(root.dataset.t);
      setCursor(asked || 0);
      const [full, positions] = await Promise.all([robotale.api(base()), robotale.api(`${base()}/window?from=0&to=${summary.duration}`)]);
      summary = full;
      whole = positions;
      drawSite(summary.site);
      setCursor(t);
      await Promise.all([listed, loadModel(summary.model), loadTimeline(), loadSeries(fieldPicker.value)]);
      root.dataset.loaded = "1";
      setCursor(t);
      if (summary.live) watchLive();
    } catch (error) {
      root.dataset.state = "failed";
      robotale.showError(error);
    }
  }

  start();
})();
