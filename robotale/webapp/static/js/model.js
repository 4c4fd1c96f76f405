// The Model page: bpmn-js draws the collaboration; the log's overlay shades each element by how
// often it happened and outlines deviations in red.
"use strict";

(() => {
  const canvasBox = document.getElementById("canvas");
  const status = document.getElementById("model-status");
  const picker = document.getElementById("model-picker");
  const summary = document.getElementById("model-summary");
  const modelId = canvasBox.dataset.model;
  const viewer = new BpmnJS({ container: canvasBox });

  picker.addEventListener("change", () => {
    const url = new URL(window.location.href);
    url.searchParams.set("model", picker.value);
    window.location.assign(url);
  });

  function shade(count, max) {
    // white (never) to a strong blue (the most frequent element)
    const t = max > 0 ? Math.sqrt(count / max) : 0;
    const mix = (a, b) => Math.round(a + (b - a) * t);
    return `rgb(${mix(255, 66)}, ${mix(255, 133)}, ${mix(255, 244)})`;
  }

  function shapeOf(id) {
    const registry = viewer.get("elementRegistry");
    const element = registry.get(id);
    return element ? registry.getGraphics(element).querySelector(".djs-visual > :first-child") : null;
  }

  function isContainer(id) {
    // an expanded sub-process: shade it lightly so what it holds stays readable
    const element = viewer.get("elementRegistry").get(id);
    return Boolean(element && element.children && element.children.length);
  }

  function badge(id, text, title, deviating) {
    const box = document.createElement("div");
    box.className = deviating ? "count-badge deviating" : "count-badge";
    box.textContent = text;
    box.title = title;
    box.dataset.element = id;
    viewer.get("overlays").add(id, deviating ? "deviations" : "counts",
      { position: deviating ? { bottom: 8, right: 12 } : { top: -12, right: 12 }, html: box });
  }

  function paintFrequencies(elements) {
    const max = Math.max(0, ...Object.values(elements).map((e) => e.count));
    for (const [id, facts] of Object.entries(elements)) {
      const shape = shapeOf(id);
      if (shape) {
        shape.style.fill = shade(facts.count, max);
        if (isContainer(id)) shape.style.fillOpacity = "0.25";
      }
      if (facts.count) badge(id, String(facts.count), `${facts.count} times, by ${facts.robots.join(", ")}`, false);
    }
    canvasBox.dataset.painted = String(Object.values(elements).filter((e) => e.count).length);
  }

  function paintDeviations(result) {
    for (const [id, facts] of Object.entries(result.elements)) {
      const shape = shapeOf(id);
      if (shape) { shape.style.stroke = "#b42318"; shape.style.strokeWidth = "4px"; }
      viewer.get("canvas").addMarker(id, "deviating");
      const parts = [facts.unexpected ? `${facts.unexpected} unexpected` : "",
        facts.missing ? `${facts.missing} missing` : ""].filter(Boolean);
      badge(id, parts.join(", "), parts.join(", "), true);
    }
    canvasBox.dataset.deviations = String(Object.keys(result.elements).length);
    summary.replaceChildren(
      robotale.el("h2", { text: "Conformance per robot" }),
      robotale.table(["robot", "pool", "runs", "fitness", "fitting runs"],
        result.robots.map((r) => [r.robot, r.pool, r.runs,
          r.fitness === null ? null : Number(r.fitness.toFixed(3)), r.fitting_runs])));
  }

  // Verify: the model's findings (robotale fame verify); choosing one outlines the elements of
  // its counterexample and lists its trace as tags.
  let marked = [];
  function highlight(finding, item) {
    const canvas = viewer.get("canvas");
    const registry = viewer.get("elementRegistry");
    for (const id of marked) canvas.removeMarker(id, "counterexample");
    marked = finding.elements.filter((id) => registry.get(id));
    for (const id of marked) canvas.addMarker(id, "counterexample");
    for (const other of item.parentNode.children) other.classList.toggle("chosen", other === item);
    canvasBox.dataset.counterexample = marked.join(" ");
    const trace = document.getElementById("verify-trace");
    trace.replaceChildren(finding.trace.length
      ? robotale.table(["step", "robot", "activity", "lifecycle", "msg_id", "msg_role"],
        finding.trace.map((t) => [t.step, t.robot, t.activity, t.lifecycle, t.msg_id, t.msg_role]))
      : robotale.el("p", { text: "No trace: nothing leads there." }));
  }

  function listFindings(verdict) {
    const box = document.getElementById("verify-findings");
    const explored = `${verdict.states} states explored` +
      (verdict.complete ? "" : ` (stopped early: ${verdict.bound})`);
    const list = robotale.el("ul", { id: "verify-list" });
    for (const finding of verdict.findings) {
      const item = robotale.el("li", { text: `${finding.kind}: ${finding.sentence}` });
      item.dataset.kind = finding.kind;
      item.addEventListener("click", () => highlight(finding, item));
      list.append(item);
    }
    box.replaceChildren(
      robotale.el("h2", { text: `Verification: ${verdict.findings.length} findings` }),
      robotale.el("p", { class: "count", text: explored }), list,
      robotale.el("div", { id: "verify-trace" }));
  }

  document.getElementById("verify").addEventListener("click", async () => {
    status.textContent = "verifying…";
    try {
      listFindings(await robotale.api(`/api/models/${modelId}/verify`));
      status.textContent = "verified: choose a finding to outline its counterexample";
    } catch (error) {
      status.textContent = "";
      robotale.showError(error);
    }
  });

  // Diff: this model, which drove the robots, against a stored model discovered from their
  // runs (robotale discover diff); what the robots never used is outlined, dashed.
  function listDiff(found) {
    const canvas = viewer.get("canvas");
    const registry = viewer.get("elementRegistry");
    const unused = [...new Set(found.unused_elements.flatMap((row) => row.ids)
      .concat(found.unused_flows.flatMap((row) => row.flows)))].filter((id) => registry.get(id));
    for (const id of unused) canvas.addMarker(id, "unused");
    canvasBox.dataset.unused = unused.join(" ");
    const part = (title, rows, text) => [robotale.el("h3", { text: `${title}: ${rows.length}` }),
      robotale.el("ul", {}, ...rows.map((row) => robotale.el("li", { text: text(row) })))];
    const element = (row) => `${row.pool}: ${row.name}`;
    const flow = (row) => `${row.pool}: ${row.source} → ${row.target}`;
    document.getElementById("diff-findings").replaceChildren(
      robotale.el("h2", { text: "Against the discovered model" }),
      ...part("Never used by the robots", found.unused_elements, element),
      ...part("Shown by the robots, not in this model", found.extra_elements, element),
      ...part("Flows never taken", found.unused_flows, flow),
      ...part("Flows taken, not in this model", found.extra_flows, flow),
      ...part("Signals thrown but never caught", found.uncaught_signals, (name) => name));
  }

  document.getElementById("diff").addEventListener("click", async () => {
    const against = document.getElementById("diff-picker").value;
    status.textContent = "comparing…";
    try {
      listDiff(await robotale.api(`/api/models/${modelId}/diff?against=${encodeURIComponent(against)}`));
      status.textContent = "what the robots never used is outlined, dashed";
    } catch (error) {
      status.textContent = "";
      robotale.showError(error);
    }
  });

  async function show() {
    if (!modelId) return;
    try {
      const response = await fetch(`/api/models/${modelId}.bpmn`);
      if (!response.ok) throw new Error((await response.json()).error);
      await viewer.importXML(await response.text());
      viewer.get("canvas").zoom("fit-viewport", "auto");
      canvasBox.dataset.rendered = "1";
      const log = await robotale.currentLog().catch(() => "");
      if (!log) return;
      const query = `log=${encodeURIComponent(log)}`;
      status.textContent = `counting ${log}…`;
      paintFrequencies((await robotale.api(`/api/models/${modelId}/frequencies?${query}`)).elements);
      status.textContent = `shaded by log ${log}; checking conformance…`;
      paintDeviations(await robotale.api(`/api/models/${modelId}/deviations?${query}`));
      status.textContent = `shaded by log ${log}; deviations outlined in red`;
    } catch (error) {
      status.textContent = "";
      robotale.showError(error);
    }
  }

  show();
})();
