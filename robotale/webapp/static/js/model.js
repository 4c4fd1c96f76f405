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

  function paint(overlay) {
    const registry = viewer.get("elementRegistry");
    const overlays = viewer.get("overlays");
    const max = Math.max(0, ...Object.values(overlay.elements).map((e) => e.count));
    for (const [id, facts] of Object.entries(overlay.elements)) {
      const element = registry.get(id);
      if (!element) continue;
      const shape = registry.getGraphics(element).querySelector(".djs-visual > :first-child");
      if (shape) shape.style.fill = shade(facts.count, max);
      const deviations = (facts.unexpected || 0) + (facts.missing || 0);
      if (deviations) {
        if (shape) { shape.style.stroke = "#b42318"; shape.style.strokeWidth = "4px"; }
        viewer.get("canvas").addMarker(id, "deviating");
      }
      const badge = document.createElement("div");
      badge.className = deviations ? "count-badge deviating" : "count-badge";
      badge.textContent = deviations ? `${facts.count} · ${deviations} off` : String(facts.count);
      badge.title = `${facts.count} times in the log` +
        (facts.unexpected ? `, ${facts.unexpected} unexpected` : "") +
        (facts.missing ? `, ${facts.missing} missing` : "");
      badge.dataset.element = id;
      overlays.add(id, { position: { top: -12, right: 12 }, html: badge });
    }
    canvasBox.dataset.painted = String(Object.keys(overlay.elements).length);
    if (overlay.robots && overlay.robots.length) {
      summary.replaceChildren(
        robotale.el("h2", { text: "Conformance per robot" }),
        robotale.table(["robot", "pool", "runs", "fitness", "fitting runs"],
          overlay.robots.map((r) => [r.robot, r.pool, r.runs,
            r.fitness === null ? null : Number(r.fitness.toFixed(3)), r.fitting_runs])));
    }
  }

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
      status.textContent = `comparing with ${log}…`;
      const overlay = await robotale.api(
        `/api/models/${modelId}/overlay?log=${encodeURIComponent(log)}`);
      paint(overlay);
      status.textContent = overlay.message || `coloured by log ${log}`;
    } catch (error) {
      status.textContent = "";
      robotale.showError(error);
    }
  }

  show();
})();
