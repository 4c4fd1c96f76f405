// The Timeline page: the chosen run's lanes, messages and battery, drawn with plotly from the
// figure the server builds.
"use strict";

(() => {
  const box = document.getElementById("timeline");
  const picker = document.getElementById("run-picker");
  const status = document.getElementById("timeline-status");
  let log = "";

  function describe(data) {
    const parts = [`${data.robots.length} robots`, `${data.bars} activities`, `${data.messages} messages`];
    if (data.lost) parts.push(`${data.lost} lost`);
    parts.push(data.battery_samples ? `${data.battery_samples} battery readings` : "no battery data");
    return parts.join(" · ");
  }

  // the run's replay on the Mission page, from its start
  const replay = document.getElementById("mission-link");
  function showReplayLink(run, seconds) {
    const params = new URLSearchParams({ log, case: run, t: seconds.toFixed(2) });
    replay.href = `/mission?${params}`;
    replay.hidden = false;
  }

  async function show(run) {
    status.textContent = "loading…";
    box.dataset.state = "loading";
    try {
      const params = new URLSearchParams({ log });
      if (run) params.set("case", run);
      const data = await robotale.api(`/api/timeline?${params}`);
      picker.value = data.case;
      await robotalePerspective.plot(box, data.figure);
      status.textContent = describe(data);
      box.dataset.case = data.case;
      box.dataset.lost = String(data.lost);
      box.dataset.state = "shown";
      showReplayLink(data.case, 0);
      const url = new URL(window.location.href);
      url.search = params.toString();
      window.history.replaceState(null, "", url);
    } catch (error) {
      status.textContent = "";
      box.dataset.state = "failed";
      robotale.showError(error);
    }
  }

  async function start() {
    log = await robotale.currentLog().catch(() => "");
    if (!log) {
      status.textContent = "No log yet: upload one on the Logs page.";
      return;
    }
    // a log nobody prepared: wait for its preparation (its requests then say what is wrong)
    await robotale.prepared(log, "timeline").catch(() => {});
    try {
      const { runs } = await robotale.api(`/api/timeline/runs?log=${encodeURIComponent(log)}`);
      picker.replaceChildren(...runs.map((run) => robotale.el("option", { value: String(run.case), text: String(run.case) })));
    } catch (error) {
      robotale.showError(error);
      return;
    }
    picker.addEventListener("change", () => show(picker.value));
    await show(box.dataset.case);
  }

  start();
})();
